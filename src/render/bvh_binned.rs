//! The builder: binned SAH straight into wide nodes, as Embree's.
//!
//! The builder before (`bvh_build.rs`: PLOC, reinsertion; then the collapse in `bvh.rs`)
//! passes many times over a binary hierarchy of twice as many nodes as boxes, which
//! reinsertion has scattered in memory: on a million triangles it took four times Embree's
//! build. Here a wide node is filled by splitting the range of boxes it covers, the child of
//! largest area first, until it has [`WIDTH`] children. Each split bins the boxes' centres
//! into up to [`BINS`] slabs per axis and cuts where the surface-area cost is least, counting
//! whole packets of [`TRI_LANES`] triangles (so leaves come out full); ranges of at most
//! [`SMALL`] boxes are cut by the exact sweep instead. A child of up to [`LARGE_LEAF`]
//! triangles stays one leaf of several packets where that costs less than a node over its
//! best split, as in Embree ([`NODE_COST`]). No binary hierarchy is kept: each box is touched
//! a few times per wide level. Its trees are also tighter than PLOC's (on das:
//! 3–10 % faster rays, 16 % less memory; docs/notebook/benchmark-history.md).
//!
//! Both cores from the first split, and the same tree on any thread count: ranges of
//! [`PARALLEL_BINNING`] boxes or more are binned in chunks side by side (bins merge by
//! minima, maxima and counts: the same in any order), and those of [`PARALLEL_PARTITION`] or
//! more partitioned in fixed blocks side by side ([`partition_blocks`]); a node over [`PARALLEL_SPLITS`] boxes
//! is filled by three levels of halves, each half split side by side; subtrees of [`TASK`]
//! boxes or more are built apart, side by side, and concatenated in preorder. The tree and
//! its layout depend only on the boxes.

use anyhow::{Result, bail};
use glam::Vec3A;
use obvhs::aabb::Aabb;
use rayon::prelude::*;

use crate::render::bvh::{Bvh, Draft, MAX_LEAF_PACKETS, Node, STACK, WIDTH};
use crate::render::bvh_build::Builder as Made;
use crate::render::packets::TRI_LANES;
use crate::scene::world::World;

/// Slabs per axis of a split's search.
const BINS: usize = 32;
/// Boxes from which a range is binned in chunks side by side.
const PARALLEL_BINNING: usize = 1 << 15;
/// Ranges of this many boxes or more fill their node by halves side by side.
const PARALLEL_SPLITS: usize = 1 << 17;
/// Ranges of this many boxes or more are partitioned in blocks side by side.
const PARALLEL_PARTITION: usize = 1 << 18;
/// Items per block of a partition side by side.
const PARTITION_BLOCK: usize = 1 << 15;
/// Subtrees of this many boxes or more are built apart, side by side.
const TASK: usize = 1 << 14;
/// Ranges of at most this many items are split by the exact sweep, not binned.
const SMALL: usize = 16;
/// Most items in a leaf of several packets (as many as its reference can count).
const LARGE_LEAF: usize = MAX_LEAF_PACKETS * TRI_LANES;
/// A node's cost, in packets of triangles tested: Embree's `travCost` over its `intCost`.
/// Leaves of several packets where cheaper: the 1 M scene's hierarchy 9 % smaller, its rays
/// as fast (docs/notebook/benchmark-history.md).
const NODE_COST: f32 = 1.0;
/// Wide depth from which ranges split at the median (bounding the depth on any input).
const SAH_DEPTH: usize = 24;

/// The items being built over, as two arrays reordered together: each item's box (world
/// frame, metres) and its primitive; `offset` is the index of the first among all items
/// (ranges index all items).
struct Items<'a> {
    boxes: &'a mut [Aabb],
    prims: &'a mut [u32],
    offset: usize,
    /// Primitives below this are triangles, the others ellipsoids.
    triangles: usize,
}

impl<'a> Items<'a> {
    /// The items before `at` (an index of all items) and the rest, apart.
    fn split_off(self, at: usize) -> (Items<'a>, Items<'a>) {
        let (boxes, boxes_tail) = self.boxes.split_at_mut(at - self.offset);
        let (prims, prims_tail) = self.prims.split_at_mut(at - self.offset);
        let head = Items {
            boxes,
            prims,
            ..self
        };
        let tail = Items {
            boxes: boxes_tail,
            prims: prims_tail,
            offset: at,
            triangles: self.triangles,
        };
        (head, tail)
    }

    /// The items of `range`, apart from the others.
    fn take(self, range: &Range) -> Items<'a> {
        self.split_off(range.start).1.split_off(range.end).0
    }

    fn reborrow(&mut self) -> Items<'_> {
        Items {
            boxes: self.boxes,
            prims: self.prims,
            ..*self
        }
    }

    fn boxes(&self, range: &Range) -> &[Aabb] {
        &self.boxes[range.start - self.offset..range.end - self.offset]
    }

    fn prims(&self, range: &Range) -> &[u32] {
        &self.prims[range.start - self.offset..range.end - self.offset]
    }

    /// Reorders the items of `range` to `order` (their places in it).
    fn reorder(&mut self, range: &Range, order: &[usize]) {
        let boxes: Vec<Aabb> = order.iter().map(|&k| self.boxes(range)[k]).collect();
        let prims: Vec<u32> = order.iter().map(|&k| self.prims(range)[k]).collect();
        let (start, end) = (range.start - self.offset, range.end - self.offset);
        self.boxes[start..end].copy_from_slice(&boxes);
        self.prims[start..end].copy_from_slice(&prims);
    }

    /// The kind of leaf `range` becomes (triangles: true), or None if it must be split: one
    /// packet of triangles, or one ellipsoid.
    fn leaf_kind(&self, range: &Range) -> Option<bool> {
        if range.len() > TRI_LANES {
            return None;
        }
        let triangles = self.all_triangles(range);
        (range.len() == 1 || triangles).then_some(triangles)
    }

    /// Whether `range` holds triangles only (no ellipsoid).
    fn all_triangles(&self, range: &Range) -> bool {
        self.prims(range)
            .iter()
            .all(|&prim| (prim as usize) < self.triangles)
    }

    /// Splits `range` into at most 2^`levels` ranges that are not leaves, by halves side by
    /// side, and appends them to `out` in order.
    fn split_levels(mut self, range: Range, depth: usize, levels: u32, out: &mut Vec<Range>) {
        if levels == 0 || self.leaf_kind(&range).is_some() {
            out.push(range);
            return;
        }
        let (left, right) = self.split(range, depth);
        let (head, tail) = self.split_off(right.start);
        let (mut a, mut b) = (Vec::new(), Vec::new());
        rayon::join(
            || head.split_levels(left, depth, levels - 1, &mut a),
            || tail.split_levels(right, depth, levels - 1, &mut b),
        );
        out.extend(a);
        out.extend(b);
    }

    /// Splits `range` (two or more items, not one leaf) into two non-empty ranges.
    fn split(&mut self, range: Range, depth: usize) -> (Range, Range) {
        let (cut, _) = self.plan(&range, depth);
        self.apply(range, cut)
    }

    /// How to split `range` (two or more items, not one leaf) into two non-empty ranges, and
    /// that split's cost (each part's half-area times its packets; infinite where not chosen
    /// by cost): apart by kind where that makes leaves, else by the surface-area heuristic
    /// (below [`SAH_DEPTH`]), else at the median. May reorder the range's items.
    fn plan(&mut self, range: &Range, depth: usize) -> (Cut, f32) {
        if range.len() <= TRI_LANES {
            // A leaf but for its kinds (triangles and ellipsoids, or several ellipsoids).
            let triangles = self
                .prims(range)
                .iter()
                .filter(|&&prim| (prim as usize) < self.triangles)
                .count();
            if triangles > 0 && triangles < range.len() {
                return (Cut::Kinds, f32::INFINITY);
            }
        }
        if depth >= SAH_DEPTH {
            return (self.median_order(range), f32::INFINITY);
        }
        if range.len() <= SMALL {
            return self.small_order(range);
        }
        let extent = range.centres.diagonal();
        if extent.cmpgt(Vec3A::ZERO).any() {
            let map = BinMap::new(&range.centres, range.len());
            let boxes = self.boxes(range);
            let best = match map.bins {
                8 => Bins::<8>::best_split_of(boxes, &map),
                16 => Bins::<16>::best_split_of(boxes, &map),
                _ => Bins::<BINS>::best_split_of(boxes, &map),
            };
            if let Some((cost, axis, slab)) = best {
                let threshold = map.threshold(axis, slab, &range.centres);
                return (Cut::Centre { axis, threshold }, cost);
            }
        }
        (self.median_order(range), f32::INFINITY)
    }

    /// `range` split as `cut` says (planned for it, its items unchanged since).
    fn apply(&mut self, range: Range, cut: Cut) -> (Range, Range) {
        match cut {
            Cut::At(at) => self.halves(range, at),
            Cut::Kinds => {
                let triangles = self.triangles;
                self.partition(range, |_, prim| (prim as usize) < triangles)
            }
            // Centres are finite (the world's vertices are), so none is NaN.
            Cut::Centre { axis: 0, threshold } => {
                self.partition(range, |b, _| b.min.x + b.max.x <= threshold)
            }
            Cut::Centre { axis: 1, threshold } => {
                self.partition(range, |b, _| b.min.y + b.max.y <= threshold)
            }
            Cut::Centre { threshold, .. } => {
                self.partition(range, |b, _| b.min.z + b.max.z <= threshold)
            }
        }
    }

    /// Whether `range` (not a leaf by count) is cheaper as one leaf of several packets than
    /// as a node over the split `cost` costs, as Embree decides (`leafSAH <= splitSAH`): its
    /// half-area times its packets, against its half-area times [`NODE_COST`] plus `cost`.
    fn cheaper_as_leaf(&self, range: &Range, cost: f32) -> bool {
        let area = range.aabb.half_area();
        let leaf = area * range.len().div_ceil(TRI_LANES) as f32;
        leaf <= area * NODE_COST + cost
    }

    /// Orders a small range (at most [`SMALL`] items) by centre along the axis where the
    /// centres spread most (ties by place) and cuts it where the surface-area cost is least:
    /// the exact sweep, cheaper than binning so few.
    fn small_order(&mut self, range: &Range) -> (Cut, f32) {
        let boxes = self.boxes(range);
        let n = boxes.len();
        let axis = range.centres.largest_axis();
        // Sort keys: the centre's bits in an order that sorts as the floats do, above the
        // item's place.
        let mut order = [u64::MAX; SMALL];
        for (k, o) in order[..n].iter_mut().enumerate() {
            *o = u64::from(ordered(centre2(&boxes[k])[axis])) << 32 | k as u64;
        }
        order[..n].sort_unstable();
        let place = |k: usize| order[k] as u32 as usize;
        let packets = |count: usize| count.div_ceil(TRI_LANES) as f32;
        let mut right = [0.0f32; SMALL];
        let mut acc = Aabb::INVALID;
        for k in (1..n).rev() {
            acc = acc.union(&boxes[place(k)]);
            right[k] = acc.half_area() * packets(n - k);
        }
        let (mut acc, mut best) = (Aabb::INVALID, (f32::INFINITY, 1));
        for k in 1..n {
            acc = acc.union(&boxes[place(k - 1)]);
            let cost = acc.half_area() * packets(k) + right[k];
            if cost < best.0 {
                best = (cost, k);
            }
        }
        let (mut boxes_sorted, mut prims_sorted) = ([Aabb::INVALID; SMALL], [0; SMALL]);
        for k in 0..n {
            boxes_sorted[k] = boxes[place(k)];
            prims_sorted[k] = self.prims(range)[place(k)];
        }
        let (start, end) = (range.start - self.offset, range.end - self.offset);
        self.boxes[start..end].copy_from_slice(&boxes_sorted[..n]);
        self.prims[start..end].copy_from_slice(&prims_sorted[..n]);
        (Cut::At(range.start + best.1), best.0)
    }

    /// `range` cut at `split`, with the bounds of both parts.
    fn halves(&self, range: Range, split: usize) -> (Range, Range) {
        let (left, right) = (
            Range {
                end: split,
                ..range
            },
            Range {
                start: split,
                ..range
            },
        );
        (
            Bounds::of(self.boxes(&left)).range(range.start, split),
            Bounds::of(self.boxes(&right)).range(split, range.end),
        )
    }

    /// Orders `range` about its median along the axis where its centres spread most (by
    /// order where they coincide) and cuts it there.
    fn median_order(&mut self, range: &Range) -> Cut {
        let mid = range.len() / 2;
        let axis = range.centres.largest_axis();
        if range.centres.diagonal()[axis] > 0.0 {
            let (boxes, prims) = (self.boxes(range), self.prims(range));
            let mut order: Vec<usize> = (0..range.len()).collect();
            order.select_nth_unstable_by(mid, |&a, &b| {
                centre2(&boxes[a])[axis]
                    .total_cmp(&centre2(&boxes[b])[axis])
                    .then(prims[a].cmp(&prims[b]))
                    .then(a.cmp(&b))
            });
            self.reorder(range, &order);
        }
        Cut::At(range.start + mid)
    }

    /// Reorders `range` so that the items for which `left` holds come first; returns both
    /// parts with their bounds. Big ranges are partitioned in blocks side by side
    /// ([`partition_blocks`]).
    fn partition(
        &mut self,
        range: Range,
        left: impl Fn(&Aabb, u32) -> bool + Sync,
    ) -> (Range, Range) {
        let (start, end) = (range.start - self.offset, range.end - self.offset);
        let (boxes, prims) = (&mut self.boxes[start..end], &mut self.prims[start..end]);
        let (count, lb, rb) = if range.len() >= PARALLEL_PARTITION {
            partition_blocks(boxes, prims, &left)
        } else {
            partition_slice(boxes, prims, &left)
        };
        let split = range.start + count;
        (lb.range(range.start, split), rb.range(split, range.end))
    }
}

/// Reorders `boxes` and `prims` together so that the items for which `left` holds come
/// first (Hoare's scheme); returns how many they are, and the bounds of both parts.
fn partition_slice(
    boxes: &mut [Aabb],
    prims: &mut [u32],
    left: &impl Fn(&Aabb, u32) -> bool,
) -> (usize, Bounds, Bounds) {
    let (mut lb, mut rb) = (Bounds::EMPTY, Bounds::EMPTY);
    let (mut i, mut j) = (0, boxes.len());
    loop {
        while i < j && left(&boxes[i], prims[i]) {
            lb.add(&boxes[i]);
            i += 1;
        }
        while i < j && !left(&boxes[j - 1], prims[j - 1]) {
            rb.add(&boxes[j - 1]);
            j -= 1;
        }
        if i == j {
            break;
        }
        boxes.swap(i, j - 1);
        prims.swap(i, j - 1);
    }
    (i, lb, rb)
}

/// [`partition_slice`] on both cores: each block of [`PARTITION_BLOCK`] items is partitioned
/// on its own, side by side; then the right items that lie before the left ones' total and
/// the left items after it, as many of each, are swapped pair by pair, in pieces side by
/// side. The blocks are fixed, so the order is the same on any thread count.
fn partition_blocks(
    boxes: &mut [Aabb],
    prims: &mut [u32],
    left: &(impl Fn(&Aabb, u32) -> bool + Sync),
) -> (usize, Bounds, Bounds) {
    let n = boxes.len();
    let blocks: Vec<(usize, Bounds, Bounds)> = boxes
        .par_chunks_mut(PARTITION_BLOCK)
        .zip(prims.par_chunks_mut(PARTITION_BLOCK))
        .map(|(boxes, prims)| partition_slice(boxes, prims, left))
        .collect();
    let count: usize = blocks.iter().map(|b| b.0).sum();
    let (lb, rb) = blocks
        .iter()
        .fold((Bounds::EMPTY, Bounds::EMPTY), |(l, r), b| {
            (l.union(b.1), r.union(b.2))
        });
    // Where the misplaced items lie: right ones before `count`, left ones from it on.
    let (mut rights, mut lefts) = (Vec::new(), Vec::new());
    for (k, &(in_block, _, _)) in blocks.iter().enumerate() {
        let start = k * PARTITION_BLOCK;
        let (mid, end) = (start + in_block, (start + PARTITION_BLOCK).min(n));
        if mid < end.min(count) {
            rights.push((mid, end.min(count)));
        }
        if start.max(count) < mid {
            lefts.push((start.max(count), mid));
        }
    }
    // Paired in order, in pieces of at most PARTITION_BLOCK pairs: (right at, left at, length).
    let mut pairs = Vec::new();
    let (mut r, mut l) = (rights.iter().copied(), lefts.iter().copied());
    let (mut a, mut b) = (r.next(), l.next());
    while let (Some((a0, a1)), Some((b0, b1))) = (a, b) {
        let len = (a1 - a0).min(b1 - b0).min(PARTITION_BLOCK);
        pairs.push((a0, b0, len));
        a = if a0 + len == a1 {
            r.next()
        } else {
            Some((a0 + len, a1))
        };
        b = if b0 + len == b1 {
            l.next()
        } else {
            Some((b0 + len, b1))
        };
    }
    debug_assert!(
        a.is_none() && b.is_none(),
        "as many misplaced on either side"
    );
    let (box_rights, box_lefts) = boxes.split_at_mut(count);
    let (prim_rights, prim_lefts) = prims.split_at_mut(count);
    let segments = |pairs: &[(usize, usize, usize)]| {
        let rights: Vec<(usize, usize)> = pairs.iter().map(|&(a, _, len)| (a, len)).collect();
        let lefts: Vec<(usize, usize)> =
            pairs.iter().map(|&(_, b, len)| (b - count, len)).collect();
        (rights, lefts)
    };
    let (at_rights, at_lefts) = segments(&pairs);
    cut(box_rights, &at_rights)
        .into_par_iter()
        .zip(cut(box_lefts, &at_lefts))
        .zip(
            cut(prim_rights, &at_rights)
                .into_par_iter()
                .zip(cut(prim_lefts, &at_lefts)),
        )
        .for_each(|((a, b), (pa, pb))| {
            a.swap_with_slice(b);
            pa.swap_with_slice(pb);
        });
    (count, lb, rb)
}

/// The disjoint pieces (start, length) of `items`, in ascending order, as slices apart.
fn cut<'s, T>(mut items: &'s mut [T], pieces: &[(usize, usize)]) -> Vec<&'s mut [T]> {
    let mut out = Vec::with_capacity(pieces.len());
    let mut taken = 0;
    for &(start, len) in pieces {
        let rest = std::mem::take(&mut items);
        let (piece, tail) = rest[start - taken..].split_at_mut(len);
        out.push(piece);
        items = tail;
        taken = start + len;
    }
    out
}

/// Twice the box's centre (the halving cancels in every comparison).
#[inline(always)]
fn centre2(aabb: &Aabb) -> Vec3A {
    aabb.min + aabb.max
}

/// A range of items with the union of their boxes and the bounds of their centres (doubled).
#[derive(Clone, Copy)]
struct Range {
    start: usize,
    end: usize,
    aabb: Aabb,
    centres: Aabb,
}

impl Range {
    fn len(&self) -> usize {
        self.end - self.start
    }
}

/// How a range is split in two.
#[derive(Clone, Copy)]
enum Cut {
    /// At this index of all items (the range's items ordered for it).
    At(usize),
    /// The items whose doubled centre on `axis` is at most `threshold` first.
    Centre { axis: usize, threshold: f32 },
    /// Triangles first, then ellipsoids.
    Kinds,
}

/// Box and centre bounds, grown item by item.
#[derive(Clone, Copy)]
struct Bounds {
    aabb: Aabb,
    centres: Aabb,
}

impl Bounds {
    const EMPTY: Bounds = Bounds {
        aabb: Aabb::INVALID,
        centres: Aabb::INVALID,
    };

    #[inline(always)]
    fn add(&mut self, aabb: &Aabb) {
        self.aabb = self.aabb.union(aabb);
        self.centres.extend(centre2(aabb));
    }

    fn of(boxes: &[Aabb]) -> Bounds {
        let mut bounds = Bounds::EMPTY;
        for aabb in boxes {
            bounds.add(aabb);
        }
        bounds
    }

    fn union(self, other: Bounds) -> Bounds {
        Bounds {
            aabb: self.aabb.union(&other.aabb),
            centres: self.centres.union(&other.centres),
        }
    }

    fn range(self, start: usize, end: usize) -> Range {
        Range {
            start,
            end,
            aabb: self.aabb,
            centres: self.centres,
        }
    }
}

/// Which slab of each axis a centre falls in.
struct BinMap {
    lo: Vec3A,
    scale: Vec3A,
    /// Slabs per axis, at most [`BINS`].
    bins: usize,
}

impl BinMap {
    /// The slabs of a range of `count` items with centres in `centres`: fewer for fewer
    /// items (the sweep over them costs as much as binning a few items).
    fn new(centres: &Aabb, count: usize) -> BinMap {
        let bins = match count {
            ..64 => 8,
            64..128 => 16,
            _ => BINS,
        };
        let extent = centres.diagonal();
        let scale = Vec3A::select(
            extent.cmpgt(Vec3A::ZERO),
            Vec3A::splat((bins - 1) as f32) / extent,
            Vec3A::ZERO,
        );
        BinMap {
            lo: centres.min,
            scale,
            bins,
        }
    }

    /// The slab of each axis: the centre's place in [0, bins − 1] rounded to the nearest
    /// (the end slabs are half as wide), by adding 2²³, whose float has no fraction bits:
    /// a float→integer conversion without the range checks of `as`.
    #[inline(always)]
    fn slabs(&self, centre2: Vec3A) -> [u32; 3] {
        let place = ((centre2 - self.lo) * self.scale)
            .clamp(Vec3A::ZERO, Vec3A::splat((self.bins - 1) as f32))
            + Vec3A::splat(MAGIC);
        place.to_array().map(|f| f.to_bits() & 0xff)
    }

    /// [`BinMap::slabs`] of one axis (the same operations: the same slab).
    #[inline(always)]
    fn slab(&self, axis: usize, centre2: f32) -> u32 {
        // SSE's max and min (the vector clamp's), NaN to 0 as there.
        let place = (centre2 - self.lo[axis]) * self.scale[axis];
        let place = if place > 0.0 { place } else { 0.0 };
        let last = (self.bins - 1) as f32;
        let place = if place < last { place } else { last };
        (place + MAGIC).to_bits() & 0xff
    }

    /// The largest doubled centre whose slab on `axis` is at most `slab` (below the last),
    /// for a range of centres `centres`: `slab` is monotone (each of its rounded steps is),
    /// so an item lies in the first `slab` + 1 slabs exactly when its centre is at most this
    /// (tested against [`BinMap::slab`] in `tests`). One comparison per item where the slab
    /// took nine operations and a branch on the axis.
    fn threshold(&self, axis: usize, slab: u32, centres: &Aabb) -> f32 {
        let left = |key: u32| self.slab(axis, from_ordered(key)) <= slab;
        // The cut between the slabs lies half a slab after `slab`'s middle: search a few
        // ulps around it, or the whole range where rounding put it outside.
        let guess = self.lo[axis] + (slab as f32 + 0.5) / self.scale[axis];
        let (mut low, mut high) = if guess.is_finite() {
            let key = ordered(guess);
            (key.saturating_sub(16), key.saturating_add(16))
        } else {
            (0, u32::MAX)
        };
        if !left(low) {
            low = ordered(centres.min[axis]);
        }
        if left(high) {
            high = ordered(centres.max[axis]);
        }
        debug_assert!(left(low) && !left(high));
        while high - low > 1 {
            let mid = low + (high - low) / 2;
            if left(mid) {
                low = mid;
            } else {
                high = mid;
            }
        }
        from_ordered(low)
    }
}

/// The floats' order as unsigned integers' (NaN aside; −0 just below +0).
fn ordered(x: f32) -> u32 {
    let bits = x.to_bits();
    if bits >> 31 == 1 {
        !bits
    } else {
        bits | 1 << 31
    }
}

/// The float of an [`ordered`] key.
fn from_ordered(key: u32) -> f32 {
    f32::from_bits(if key >> 31 == 1 {
        key & !(1 << 31)
    } else {
        !key
    })
}

/// 2²³: the floats from it to 2²⁴ are the integers, in their low mantissa bits.
const MAGIC: f32 = 8_388_608.0;

/// Per axis and slab: the union of the boxes whose centres fall in it, and their count.
/// `N` slabs: as many as the map's (their initialisation is a copy of all of them).
#[derive(Clone, Copy)]
struct Bins<const N: usize> {
    boxes: [[Aabb; N]; 3],
    counts: [[u32; N]; 3],
}

impl<const N: usize> Bins<N> {
    const EMPTY: Bins<N> = Bins {
        boxes: [[Aabb::INVALID; N]; 3],
        counts: [[0; N]; 3],
    };

    /// The cheapest split of the boxes of a range, binned by `map` (of `N` slabs), side by
    /// side in chunks where they are many.
    fn best_split_of(boxes: &[Aabb], map: &BinMap) -> Option<(f32, usize, u32)> {
        debug_assert_eq!(map.bins, N);
        let bins = if boxes.len() >= PARALLEL_BINNING {
            boxes
                .par_chunks(PARALLEL_BINNING / 4)
                .map(|chunk| Bins::<N>::of(chunk, map))
                .reduce(|| Bins::EMPTY, Bins::merged)
        } else {
            Bins::<N>::of(boxes, map)
        };
        bins.best_split()
    }

    fn of(boxes: &[Aabb], map: &BinMap) -> Bins<N> {
        // Two sets of bins, for the even and the odd boxes: consecutive boxes often fall in
        // the same slab, and one set would make each update wait for the last.
        let (mut even, mut odd) = (Bins::EMPTY, Bins::EMPTY);
        let mut pairs = boxes.chunks_exact(2);
        for pair in &mut pairs {
            even.add(&pair[0], map);
            odd.add(&pair[1], map);
        }
        for aabb in pairs.remainder() {
            even.add(aabb, map);
        }
        even.merged(odd)
    }

    #[inline(always)]
    fn add(&mut self, aabb: &Aabb, map: &BinMap) {
        let slabs = map.slabs(centre2(aabb));
        for (axis, &k) in slabs.iter().enumerate() {
            let k = k as usize;
            self.boxes[axis][k] = self.boxes[axis][k].union(aabb);
            self.counts[axis][k] += 1;
        }
    }

    fn merged(mut self, other: Bins<N>) -> Bins<N> {
        for axis in 0..3 {
            for k in 0..N {
                self.boxes[axis][k] = self.boxes[axis][k].union(&other.boxes[axis][k]);
                self.counts[axis][k] += other.counts[axis][k];
            }
        }
        self
    }

    /// The cheapest split, (axis, last slab of the left part), where one leaves both parts
    /// non-empty. Cost: each part's half-area times its packets of [`TRI_LANES`].
    fn best_split(&self) -> Option<(f32, usize, u32)> {
        let packets = |count: u32| count.div_ceil(TRI_LANES as u32) as f32;
        let mut best: Option<(f32, usize, u32)> = None;
        for axis in 0..3 {
            let (boxes, counts) = (&self.boxes[axis], &self.counts[axis]);
            let mut right_cost = [f32::INFINITY; N];
            let (mut acc, mut count) = (Aabb::INVALID, 0);
            for k in (1..N).rev() {
                acc = acc.union(&boxes[k]);
                count += counts[k];
                if count > 0 {
                    right_cost[k] = acc.half_area() * packets(count);
                }
            }
            let (mut acc, mut count) = (Aabb::INVALID, 0);
            for k in 0..N - 1 {
                acc = acc.union(&boxes[k]);
                count += counts[k];
                if count == 0 {
                    continue;
                }
                let cost = acc.half_area() * packets(count) + right_cost[k + 1];
                if cost.is_finite() && best.is_none_or(|(c, _, _)| cost < c) {
                    best = Some((cost, axis, k as u32));
                }
            }
        }
        best
    }
}

/// A subtree left to build apart: its range, its depth, and the child slot that will refer
/// to it.
struct Deferred {
    range: Range,
    depth: usize,
    node: usize,
    slot: usize,
}

struct Builder<'a> {
    /// The items of this part; ranges index into them.
    items: Items<'a>,
    world: &'a World,
    out: Draft,
    /// Subtrees of [`TASK`] boxes or more, left to build apart.
    deferred: Vec<Deferred>,
    /// A leaf's primitives (kept to spare an allocation per leaf).
    leaf: Vec<u32>,
}

/// A subtree built apart: its hierarchy (its root first), and the subtrees built apart below
/// it, each with the node and slot that refers to it.
struct Part {
    bvh: Draft,
    links: Vec<(usize, usize, Part)>,
}

impl Part {
    /// Builds the subtree of `range` (all of `items`), its subtrees of [`TASK`] boxes or
    /// more side by side.
    fn build(items: Items, range: Range, depth: usize, world: &World) -> Result<Part> {
        let mut builder = Builder {
            items,
            world,
            out: Draft::with_room(range.len()),
            deferred: Vec::new(),
            leaf: Vec::with_capacity(TRI_LANES),
        };
        let root = builder.out.reserve();
        builder.fill(root, range, depth, None)?;
        let Builder {
            items,
            out,
            mut deferred,
            ..
        } = builder;
        // The deferred ranges are disjoint: cut the items into their slices, in order.
        deferred.sort_by_key(|d| d.range.start);
        let mut slices = Vec::with_capacity(deferred.len());
        let mut rest = items;
        for d in &deferred {
            let (slice, tail) = rest.split_off(d.range.start).1.split_off(d.range.end);
            slices.push(slice);
            rest = tail;
        }
        let parts: Vec<Result<Part>> = deferred
            .par_iter()
            .zip(slices)
            .map(|(d, items)| Part::build(items, d.range, d.depth, world))
            .collect();
        let mut links = Vec::with_capacity(parts.len());
        for (d, part) in deferred.iter().zip(parts) {
            links.push((d.node, d.slot, part?));
        }
        Ok(Part { bvh: out, links })
    }

    /// This part and those below it in preorder, with each link as (its part's index, node,
    /// slot, the linked part's index).
    fn flatten<'a>(&'a self, parts: &mut Vec<&'a Draft>, links: &mut Vec<[usize; 4]>) -> usize {
        let me = parts.len();
        parts.push(&self.bvh);
        for (node, slot, part) in &self.links {
            let linked = part.flatten(parts, links);
            links.push([me, *node, *slot, linked]);
        }
        me
    }
}

/// Builds the wide hierarchy over `boxes` (box i refers to primitive `prims[i]` of `world`),
/// reordering both.
pub fn build(world: &World, boxes: &mut [Aabb], prims: &mut [u32]) -> Result<Bvh> {
    if boxes.is_empty() {
        return Ok(Bvh::empty());
    }
    // Chunks side by side: minima and maxima are the same in any order.
    let bounds = boxes
        .par_chunks(PARALLEL_BINNING)
        .map(Bounds::of)
        .reduce(|| Bounds::EMPTY, Bounds::union)
        .range(0, boxes.len());
    let items = Items {
        boxes,
        prims,
        offset: 0,
        triangles: world.triangles.len(),
    };
    let root = Part::build(items, bounds, 1, world)?;
    let (mut parts, mut links) = (Vec::new(), Vec::new());
    root.flatten(&mut parts, &mut links);
    let mut bvh = Draft::concatenate(&parts, &links, world)?;
    bvh.builder = Some(Made::Binned);
    Ok(bvh)
}

impl Builder<'_> {
    /// Fills wide node `at` with the subtrees of `range`, split largest first until there
    /// are [`WIDTH`].
    /// `planned`: the split of `range`, where its parent planned it.
    fn fill(&mut self, at: usize, range: Range, depth: usize, planned: Option<Cut>) -> Result<()> {
        // A closest-hit query stacks at most WIDTH − 1 entries per level, an any-hit WIDTH.
        // Below SAH_DEPTH every node halves its largest range at least: this cannot fail.
        if depth * WIDTH > STACK {
            bail!(
                "internal error: the scene's hierarchy is deeper than {} levels",
                STACK / WIDTH
            );
        }
        // The children, each with the kind of leaf it makes (None: an inner node) and its
        // split where already planned.
        let mut children = [(range, self.items.leaf_kind(&range), planned); WIDTH];
        let mut count = 1;
        if range.len() >= PARALLEL_SPLITS {
            // Big: three levels of halves, side by side (largest first would split one
            // after the other).
            let mut ranges = Vec::with_capacity(WIDTH);
            let items = self.items.reborrow().take(&range);
            items.split_levels(range, depth, WIDTH.ilog2(), &mut ranges);
            count = ranges.len();
            for (child, r) in children.iter_mut().zip(ranges) {
                *child = (r, self.items.leaf_kind(&r), None);
            }
        }
        while count < WIDTH {
            let open = children[..count]
                .iter()
                .enumerate()
                .filter(|(_, (_, kind, _))| kind.is_none())
                .max_by(|a, b| a.1.0.aabb.half_area().total_cmp(&b.1.0.aabb.half_area()));
            let Some((i, &(c, _, cut))) = open else { break };
            let cut = cut.unwrap_or_else(|| self.items.plan(&c, depth).0);
            let (left, right) = self.items.apply(c, cut);
            children.copy_within(i + 1..count, i + 2);
            children[i] = (left, self.items.leaf_kind(&left), None);
            children[i + 1] = (right, self.items.leaf_kind(&right), None);
            count += 1;
        }
        // Small children of triangles: one leaf of several packets where that is cheaper than
        // a node (whose first split is then planned already).
        for child in &mut children[..count] {
            let (c, kind, cut) = child;
            if kind.is_none() && c.len() <= LARGE_LEAF && self.items.all_triangles(c) {
                let (planned, cost) = self.items.plan(c, depth + 1);
                if self.items.cheaper_as_leaf(c, cost) {
                    *kind = Some(true);
                } else {
                    *cut = Some(planned);
                }
            }
        }
        let mut node = Node::EMPTY;
        let mut reserved = [(0, range, None); WIDTH];
        let mut inner = 0;
        for (slot, &(c, kind, cut)) in children[..count].iter().enumerate() {
            node.set_child_box(slot, &c.aabb);
            if let Some(triangles) = kind {
                self.leaf.clear();
                self.leaf.extend_from_slice(self.items.prims(&c));
                node.children[slot] = self.out.push_leaf(self.world, &mut self.leaf, triangles)?;
            } else if c.len() >= TASK {
                self.deferred.push(Deferred {
                    range: c,
                    depth: depth + 1,
                    node: at,
                    slot,
                });
            } else {
                let index = self.out.reserve();
                node.children[slot] = index as u32;
                reserved[inner] = (index, c, cut);
                inner += 1;
            }
        }
        self.out.nodes[at] = node;
        for &(index, c, cut) in &reserved[..inner] {
            self.fill(index, c, depth + 1, cut)?;
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    type Predicate<'a> = dyn Fn(&Aabb, u32) -> bool + Sync + 'a;

    /// `n` boxes of pseudo-random centres and sizes (a fixed generator), box i for prim i.
    fn boxes(n: usize) -> Vec<Aabb> {
        let mut state = 0x2545_f491_4f6c_dd1du64;
        let mut next = move || {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            (state >> 40) as f32 / (1u64 << 24) as f32
        };
        (0..n)
            .map(|_| {
                let c = Vec3A::new(next(), next(), next()) * 100.0;
                let h = Vec3A::new(next(), next(), next());
                Aabb::new(c - h, c + h)
            })
            .collect()
    }

    /// Eight clusters of eight triangles, 100 m apart: the root's eight children. Four are
    /// fans of nearly the same triangle (split, each half covers almost the whole: a leaf
    /// of two packets is cheaper), four are two fours 10 m apart (a node over two leaves
    /// is cheaper).
    #[test]
    fn a_small_child_is_one_leaf_of_several_packets_where_that_is_cheaper_than_a_node() {
        use obvhs::rt_triangle::RtTriangle;
        let mut triangles = Vec::new();
        for cluster in 0..8 {
            for k in 0..8 {
                let x = 100.0 * cluster as f32
                    + if cluster < 4 {
                        0.01 * k as f32
                    } else {
                        10.0 * (k / 4) as f32
                    };
                let v = |dx: f32, dy: f32| Vec3A::new(x + dx, dy, 0.0);
                triangles.push(RtTriangle::new(v(0.0, 0.0), v(1.0, 0.0), v(0.0, 1.0)));
            }
        }
        let world = World::of_triangles(triangles, Vec::new());
        let (mut boxes, mut prims) =
            crate::render::bvh::primitive_boxes(&world, &(0..64).collect::<Vec<u32>>());
        let bvh = build(&world, &mut boxes, &mut prims).unwrap();
        let root = &bvh.nodes[0];
        let mut kinds: Vec<(f32, &str)> = (0..WIDTH)
            .map(|slot| {
                let child = root.children[slot];
                let kind = if child & crate::render::bvh::LEAF == 0 {
                    "node"
                } else if crate::render::bvh::packets_of(child).1 == 2 {
                    "leaf of 2"
                } else {
                    "other"
                };
                (root.bounds[0][slot], kind)
            })
            .collect();
        kinds.sort_by(|a, b| a.0.total_cmp(&b.0));
        let kinds: Vec<&str> = kinds.iter().map(|k| k.1).collect();
        assert_eq!(kinds, [["leaf of 2"; 4], ["node"; 4]].concat());
    }

    /// The cut's threshold against the slab it stands for: over drawn ranges of centres (of
    /// every number of slabs, spans from under a millimetre to a hundred kilometres, as far
    /// as 300 km from the origin, where a float's step is 3 cm), every slab's threshold is in
    /// that slab or one before, the float after it in a slab after, and drawn centres fall
    /// on its side as their slab says.
    #[test]
    fn a_cuts_threshold_parts_the_centres_as_their_slabs_do() {
        let drawn = boxes(300);
        for (k, b) in drawn.iter().enumerate() {
            let scale = [1e-3, 1.0, 1e3][k % 3];
            let offset = [0.0, -5e4, 3e5][k / 3 % 3];
            let centres = Aabb::new(b.min * scale + offset, b.max * scale + offset);
            let count = [40, 100, 1000][k / 9 % 3];
            let map = BinMap::new(&centres, count);
            // An axis where the centres do not spread is never cut (all in slab 0).
            for axis in (0..3).filter(|&axis| map.scale[axis] > 0.0) {
                for slab in 0..map.bins as u32 - 1 {
                    let t = map.threshold(axis, slab, &centres);
                    assert!(map.slab(axis, t) <= slab, "{k} {axis} {slab}: {t}");
                    assert!(map.slab(axis, t.next_up()) > slab, "{k} {axis} {slab}: {t}");
                    for c in drawn.iter().take(50) {
                        let (lo, hi) = (centres.min[axis], centres.max[axis]);
                        let x = lo + (hi - lo) * (c.min.x / 100.0).clamp(0.0, 1.0);
                        assert_eq!(
                            map.slab(axis, x) <= slab,
                            x <= t,
                            "{k} {axis} {slab}: {x} against {t}"
                        );
                    }
                }
            }
        }
    }

    /// The block partition against Hoare's on one thread: the same items on each side, each
    /// box still with its primitive, and the same bounds.
    #[test]
    fn a_partition_in_blocks_side_by_side_equals_the_partition_on_one_thread() {
        // Not a multiple of the block; predicates that leave few, half and most items on the
        // left, and one whose blocks hold runs of uneven length on either side.
        let n = 9 * PARTITION_BLOCK + 1234;
        let original = boxes(n);
        let predicates: [&Predicate<'_>; 4] = [
            &|b, _| b.min.x < 10.0,
            &|b, _| centre2(b).y < 100.0,
            &|b, _| b.max.z > 5.0,
            &|_, p| (p as usize / 1000) % 7 < 3 || p as usize > n - 50_000,
        ];
        for (k, left) in predicates.iter().enumerate() {
            let (mut boxes, mut prims) = (original.clone(), (0..n as u32).collect::<Vec<_>>());
            let (count, lb, rb) = partition_blocks(&mut boxes, &mut prims, left);
            let (mut twin_boxes, mut twin_prims) = (original.clone(), prims.clone());
            twin_prims.sort_unstable();
            assert_eq!(
                twin_prims,
                (0..n as u32).collect::<Vec<_>>(),
                "{k}: a permutation"
            );
            let (twin_count, twin_lb, twin_rb) =
                partition_slice(&mut twin_boxes, &mut twin_prims, left);
            assert_eq!(count, twin_count, "{k}");
            assert!(count > 0 && count < n, "{k}: {count} of {n} on the left");
            for (i, (b, &p)) in boxes.iter().zip(&prims).enumerate() {
                assert_eq!(
                    *b, original[p as usize],
                    "{k}: item {i} parted from its box"
                );
                assert_eq!(left(b, p), i < count, "{k}: item {i} on the wrong side");
            }
            for (bounds, twin) in [(lb, twin_lb), (rb, twin_rb)] {
                assert_eq!(bounds.aabb, twin.aabb, "{k}");
                assert_eq!(bounds.centres, twin.centres, "{k}");
            }
            let exact = Bounds::of(&boxes[count..]);
            assert_eq!((rb.aabb, rb.centres), (exact.aabb, exact.centres), "{k}");
        }
    }
}
