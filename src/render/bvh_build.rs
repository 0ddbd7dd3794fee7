//! The binary hierarchy that the wide BVH (`bvh.rs`) collapses into wide nodes, built in time
//! near-linear in the boxes and to a bounded depth for any arrangement of them.
//!
//! obvhs' PLOC builder (with reinsertion) makes the best trees, fast, for ordinary scenes. It
//! merges neighbours (in Morton order) that choose each other, and when the costs of
//! neighbouring pairs tie — identical or concentric primitives (a mesh exported twice, every
//! object of a script placed at the origin), boxes evenly spaced in a row — few neighbours do,
//! so it merges a pair or two per pass: quadratic time (50 000 copies of a triangle ran for
//! minutes) and a chain as deep as the boxes are many. So PLOC is first tried on windows of
//! consecutive boxes in Morton order, at a few sampling strides (degeneracy among single
//! boxes, among objects of many boxes, among groups of those); it runs on the whole set only
//! if it merges every window in few passes. Otherwise, or if its tree comes out deeper than
//! [`MAX_DEPTH`], a top-down binned-SAH build takes over: it splits at the median, by position
//! or by order where centroids coincide, below a fixed depth, so its depth is bounded by
//! 24 + log2(boxes) and its time by that many linear passes.

use glam::Vec3A;
use obvhs::BvhBuildParams;
use obvhs::aabb::Aabb;
use obvhs::bvh2::node::Bvh2Node;
use obvhs::bvh2::reinsertion::ReinsertionOptimizer;
use obvhs::bvh2::{Bvh2, DEFAULT_MAX_STACK_DEPTH};
use obvhs::ploc::PlocBuilder;
use rayon::prelude::*;

/// Deepest binary hierarchy handed on: the wide hierarchy is at most as deep.
pub const MAX_DEPTH: usize = 120;
/// Boxes per probe window; sets at most this big go to PLOC directly (its worst case on
/// them is a few tens of milliseconds).
const WINDOW: usize = 1024;
/// A window that takes more PLOC passes than this is degenerate (ordinary windows take a few
/// dozen; tied ones about half their boxes or more).
const MAX_PASSES: usize = WINDOW / 4;
/// Sampling strides of the probe, in Morton order.
const STRIDES: [usize; 6] = [1, 4, 16, 64, 256, 1024];
/// Depth from which the top-down build splits at the median only.
const SAH_DEPTH: usize = 24;
/// Bins of the SAH split search, per axis.
const BINS: usize = 16;

/// Which builder made a hierarchy.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Builder {
    Ploc,
    TopDown,
    /// Binned SAH straight into wide nodes (`bvh_binned.rs`), for large inputs.
    Binned,
}

/// Builds a binary hierarchy over `boxes` (box i refers to primitive `prims[i]`, part of
/// object `owners[i]`): every leaf holds one box, with `first_index` its primitive.
pub fn build(boxes: &[Aabb], prims: Vec<u32>, owners: &[u32]) -> (Bvh2, Builder) {
    assert_eq!(boxes.len(), prims.len());
    assert_eq!(boxes.len(), owners.len());
    if boxes.len() <= WINDOW || !(degenerate(boxes) || degenerate(&object_boxes(boxes, owners))) {
        let bvh2 = ploc(boxes, prims.clone(), true);
        if depth(&bvh2) <= MAX_DEPTH {
            return (bvh2, Builder::Ploc);
        }
    }
    (top_down(boxes, &prims), Builder::TopDown)
}

/// PLOC with obvhs' medium parameters, optionally followed by reinsertion.
fn ploc(boxes: &[Aabb], prims: Vec<u32>, reinsert: bool) -> Bvh2 {
    let params = BvhBuildParams::medium_build();
    let mut bvh2 = PlocBuilder::with_capacity(boxes.len()).build(
        params.ploc_search_distance,
        boxes,
        prims,
        params.sort_precision,
        params.search_depth_threshold,
    );
    if reinsert {
        bvh2.uses_spatial_splits = true;
        ReinsertionOptimizer::default().run(&mut bvh2, params.reinsertion_batch_ratio, None);
    }
    bvh2
}

/// Passes PLOC took over its boxes (it records them as its stack depth, when above obvhs'
/// default).
fn passes(bvh2: &Bvh2) -> usize {
    if bvh2.max_depth > DEFAULT_MAX_STACK_DEPTH {
        bvh2.max_depth - 1
    } else {
        0
    }
}

/// The box of each object, in the order of their first boxes: PLOC merges an object's own
/// boxes first, then the objects, which can tie (a row of identical posts) where no sample
/// of single boxes does.
fn object_boxes(boxes: &[Aabb], owners: &[u32]) -> Vec<Aabb> {
    let mut index: std::collections::HashMap<u32, usize> = std::collections::HashMap::new();
    let mut out: Vec<Aabb> = Vec::new();
    for (b, &owner) in boxes.iter().zip(owners) {
        let i = *index.entry(owner).or_insert_with(|| {
            out.push(Aabb::empty());
            out.len() - 1
        });
        out[i] = out[i].union(b);
    }
    out
}

/// Whether PLOC degenerates on some probe window of `boxes`.
fn degenerate(boxes: &[Aabb]) -> bool {
    let order = morton_order(boxes);
    // The windows are independent: probed side by side (the answer is the same whichever
    // finds a degenerate one first).
    let window_degenerates = |chunk: &[u32]| {
        let window: Vec<Aabb> = chunk.iter().map(|&i| boxes[i as usize]).collect();
        let indices = (0..window.len() as u32).collect();
        passes(&ploc(&window, indices, false)) > MAX_PASSES
    };
    for stride in STRIDES {
        let sampled: Vec<u32> = order.iter().copied().step_by(stride).collect();
        if sampled.len() < WINDOW {
            break;
        }
        if sampled.par_chunks(WINDOW).any(window_degenerates) {
            return true;
        }
    }
    false
}

/// Box indices sorted by the Morton code of their centres (21 bits per axis over the
/// centres' bounds), ties by index.
fn morton_order(boxes: &[Aabb]) -> Vec<u32> {
    let mut bounds = Aabb::empty();
    for b in boxes {
        bounds.extend(b.center());
    }
    let extent = bounds.diagonal();
    let scale = Vec3A::select(
        extent.cmpgt(Vec3A::ZERO),
        Vec3A::splat(((1u32 << 21) - 1) as f32) / extent,
        Vec3A::ZERO,
    );
    let mut keyed: Vec<(u64, u32)> = boxes
        .par_iter()
        .enumerate()
        .map(|(i, b)| {
            let q = ((b.center() - bounds.min) * scale).max(Vec3A::ZERO);
            let code = spread(q.x as u32) | (spread(q.y as u32) << 1) | (spread(q.z as u32) << 2);
            (code, i as u32)
        })
        .collect();
    keyed.par_sort_unstable();
    keyed.into_iter().map(|(_, i)| i).collect()
}

/// The low 21 bits of `v`, two zero bits after each.
fn spread(v: u32) -> u64 {
    let mut out = 0u64;
    for bit in 0..21 {
        out |= u64::from((v >> bit) & 1) << (3 * bit);
    }
    out
}

/// Depth of the hierarchy (a lone root is depth 1).
pub fn depth(bvh2: &Bvh2) -> usize {
    if bvh2.nodes.is_empty() {
        return 0;
    }
    let mut deepest = 0;
    let mut todo = vec![(0usize, 1usize)];
    while let Some((i, d)) = todo.pop() {
        deepest = deepest.max(d);
        let node = &bvh2.nodes[i];
        if !node.is_leaf() {
            todo.push((node.first_index as usize, d + 1));
            todo.push((node.first_index as usize + 1, d + 1));
        }
    }
    deepest
}

/// A range of `items` to split, the node it becomes, and its depth.
struct Task {
    start: usize,
    end: usize,
    node: usize,
    depth: usize,
}

/// Top-down build: binned SAH over the centres, at the median below [`SAH_DEPTH`] or where
/// SAH finds no split; by order where the centres coincide.
fn top_down(boxes: &[Aabb], prims: &[u32]) -> Bvh2 {
    let n = boxes.len();
    let mut nodes = vec![Bvh2Node::default(); (2 * n).saturating_sub(1)];
    let mut items: Vec<u32> = (0..n as u32).collect();
    let centres: Vec<Vec3A> = boxes.iter().map(Aabb::center).collect();
    let mut next = 1;
    let mut todo = vec![Task {
        start: 0,
        end: n,
        node: 0,
        depth: 1,
    }];
    while let Some(task) = todo.pop() {
        let slice = &mut items[task.start..task.end];
        let mut bounds = Aabb::empty();
        for &i in slice.iter() {
            bounds = bounds.union(&boxes[i as usize]);
        }
        if slice.len() == 1 {
            nodes[task.node] = Bvh2Node::new(bounds, 1, prims[slice[0] as usize]);
            continue;
        }
        let mid = split(slice, boxes, &centres, task.depth);
        nodes[task.node] = Bvh2Node::new(bounds, 0, next as u32);
        let (left, right) = (next, next + 1);
        next += 2;
        todo.push(Task {
            start: task.start,
            end: task.start + mid,
            node: left,
            depth: task.depth + 1,
        });
        todo.push(Task {
            start: task.start + mid,
            end: task.end,
            node: right,
            depth: task.depth + 1,
        });
    }
    debug_assert_eq!(next, nodes.len().max(1));
    Bvh2 {
        nodes,
        primitive_indices: prims.to_vec(),
        max_depth: DEFAULT_MAX_STACK_DEPTH.max(SAH_DEPTH + n.ilog2() as usize + 2),
        ..Bvh2::default()
    }
}

/// Reorders `slice` (two or more box indices) into two non-empty parts and returns the
/// length of the first.
fn split(slice: &mut [u32], boxes: &[Aabb], centres: &[Vec3A], depth: usize) -> usize {
    let mut cb = Aabb::empty();
    for &i in slice.iter() {
        cb.extend(centres[i as usize]);
    }
    let extent = cb.diagonal();
    let axis = cb.largest_axis();
    if extent[axis] <= 0.0 {
        // Every centre coincides: by order.
        return slice.len() / 2;
    }
    if depth < SAH_DEPTH
        && let Some((axis, position)) = sah_split(slice, boxes, centres, &cb)
    {
        let mut left = 0;
        for k in 0..slice.len() {
            if centres[slice[k] as usize][axis] < position {
                slice.swap(k, left);
                left += 1;
            }
        }
        if left > 0 && left < slice.len() {
            return left;
        }
    }
    let mid = slice.len() / 2;
    slice.select_nth_unstable_by(mid, |&a, &b| {
        centres[a as usize][axis]
            .total_cmp(&centres[b as usize][axis])
            .then(a.cmp(&b))
    });
    mid
}

/// The axis and position of the cheapest binned SAH split of `slice` (None where every
/// centre falls in one bin).
fn sah_split(slice: &[u32], boxes: &[Aabb], centres: &[Vec3A], cb: &Aabb) -> Option<(usize, f32)> {
    let mut best: Option<(f32, usize, f32)> = None;
    for axis in 0..3 {
        let (lo, width) = (cb.min[axis], cb.max[axis] - cb.min[axis]);
        if width <= 0.0 {
            continue;
        }
        let bin_of = |c: f32| (((c - lo) / width * BINS as f32) as usize).min(BINS - 1);
        let mut bins = [(Aabb::empty(), 0usize); BINS];
        for &i in slice {
            let b = &mut bins[bin_of(centres[i as usize][axis])];
            b.0 = b.0.union(&boxes[i as usize]);
            b.1 += 1;
        }
        // Costs of the left part ending at each bin boundary, then the right part.
        let mut left_cost = [0.0f32; BINS];
        let (mut acc, mut count) = (Aabb::empty(), 0);
        for k in 0..BINS - 1 {
            acc = acc.union(&bins[k].0);
            count += bins[k].1;
            left_cost[k] = if count > 0 {
                acc.half_area() * count as f32
            } else {
                f32::INFINITY
            };
        }
        let (mut acc, mut count) = (Aabb::empty(), 0);
        for k in (1..BINS).rev() {
            acc = acc.union(&bins[k].0);
            count += bins[k].1;
            if count == 0 || count == slice.len() {
                continue;
            }
            let cost = left_cost[k - 1] + acc.half_area() * count as f32;
            if cost.is_finite() && best.is_none_or(|(c, _, _)| cost < c) {
                best = Some((cost, axis, lo + width * k as f32 / BINS as f32));
            }
        }
    }
    best.map(|(_, axis, position)| (axis, position))
}
