//! Metrics of a `seethru` frame against the `truth` (docs/DESIGN.md §6), over every pixel of the
//! driver's view where the display is: misregistration, border mismatch, PSNR/SSIM/FLIP and
//! missing pixels, each mean beside the coverage it was taken over.
//!
//! Every display pixel counts. A pixel that shows sky (in the truth, in `seethru`, or both)
//! has a misregistration like any other: the angle at the eye between the direction shown
//! and the direction the truth has (a direction at infinity is as well defined as a point).
//! Only blank pixels — display pixels whose crop point is outside the frontal view — have
//! none; they are counted, and every region reports its `coverage` beside its means. The
//! image metrics see them as the black they show.

use glam::{DVec2, DVec3, Vec3};
use serde_json::json;

use crate::analysis::physical::ARCMIN_PER_RAD;
#[cfg(test)]
use crate::render::accel::Hit;
use crate::render::accel::make_ray;
use crate::render::bvh_packet::{PACKET, PacketStack, RayPacket};
use crate::render::frame_over::FrameView;
use crate::render::integrator::RenderContext;
use crate::render::ray::TraceRay;
use crate::render::simd::Isa;
use crate::scene::Scene;
use crate::scene::world::view_bit;
use crate::system::display::{DisplayPlacement, MISSING_ID};
use crate::util::color::{encode_srgb8, luma};
use crate::util::quantile::nearest_rank;

/// Per-pixel results over the driver's view (NaN / false outside the display region).
pub struct MetricMaps {
    pub width: u32,
    pub height: u32,
    /// Angle at the eye between what `seethru` shows and what the truth has, arc-minutes; NaN
    /// outside the display and on blank pixels.
    pub misregistration: Vec<f32>,
    /// Display pixels whose truth point (or sky direction) the frontal camera cannot see.
    pub missing: Vec<bool>,
    /// Pixels where the driver sees the display.
    pub display: Vec<bool>,
    /// Display pixels that show nothing (their crop point is outside the frontal image).
    pub blank: Vec<bool>,
    /// SSIM and FLIP per pixel (NaN outside the display), for statistics over parts of it.
    pub ssim: Vec<f64>,
    pub flip: Vec<f64>,
}

#[cfg(test)]
impl MetricMaps {
    /// Maps for the tests of what reads them: the given misregistration and masks, no pixel
    /// missing, SSIM and FLIP not computed (NaN).
    pub(crate) fn of_masks(
        [width, height]: [u32; 2],
        misregistration: Vec<f32>,
        display: Vec<bool>,
        blank: Vec<bool>,
    ) -> MetricMaps {
        let n = misregistration.len();
        assert_eq!(n, width as usize * height as usize);
        MetricMaps {
            width,
            height,
            misregistration,
            missing: vec![false; n],
            display,
            blank,
            ssim: vec![f64::NAN; n],
            flip: vec![f64::NAN; n],
        }
    }
}

/// Summary statistics of a set of values.
pub fn stats(values: &mut [f64]) -> serde_json::Value {
    if values.is_empty() {
        return json!({"count": 0});
    }
    values.sort_by(f64::total_cmp);
    let n = values.len();
    let mean = values.iter().sum::<f64>() / n as f64;
    let p95 = nearest_rank(values, 0.95);
    json!({"count": n, "mean": mean, "p95": p95, "max": values[n - 1]})
}

fn mean(values: impl Iterator<Item = f64>) -> f64 {
    let (sum, n) = values.fold((0.0, 0usize), |(s, n), v| (s + v, n + 1));
    if n == 0 { f64::NAN } else { sum / n as f64 }
}

/// The direction from `eye` that a pixel shows: towards its world point, or its sky
/// direction (carried in the normal, see [`Frame::normal`]); `None` where nothing is shown.
fn shown_direction(position: Vec3, normal: Vec3, eye: DVec3) -> Option<DVec3> {
    if position.is_finite() {
        Some(position.as_dvec3() - eye)
    } else if normal.is_finite() && normal != Vec3::ZERO {
        Some(-normal.as_dvec3())
    } else {
        None
    }
}

/// The angle between two directions, radians, accurate at small angles.
fn angle_between(a: DVec3, b: DVec3) -> f64 {
    a.cross(b).length().atan2(a.dot(b))
}

/// Pixels of a frame `frame_width` wide (indices in increasing order) and their bounding box:
/// SSIM's masked windows read nothing outside it, so its map over the box is its map over the
/// frame there; FLIP is taken over the box itself.
struct DisplayBox<'a> {
    pixels: &'a [usize],
    frame_width: usize,
    /// The box's first column and row in the frame, and its size, pixels (0 × 0 without pixels).
    x0: usize,
    y0: usize,
    width: usize,
    height: usize,
}

impl<'a> DisplayBox<'a> {
    fn of(pixels: &'a [usize], frame_width: usize) -> DisplayBox<'a> {
        let (Some(&first), Some(&last)) = (pixels.first(), pixels.last()) else {
            return DisplayBox {
                pixels,
                frame_width,
                x0: 0,
                y0: 0,
                width: 0,
                height: 0,
            };
        };
        let (x0, x1) = pixels.iter().fold((usize::MAX, 0), |(x0, x1), &i| {
            (x0.min(i % frame_width), x1.max(i % frame_width + 1))
        });
        let (y0, y1) = (first / frame_width, last / frame_width + 1);
        DisplayBox {
            pixels,
            frame_width,
            x0,
            y0,
            width: x1 - x0,
            height: y1 - y0,
        }
    }

    /// The box's index of the frame's pixel `i` (one of the box's pixels).
    fn in_box(&self, i: usize) -> usize {
        (i / self.frame_width - self.y0) * self.width + i % self.frame_width - self.x0
    }

    /// A box-sized image: `values` (one per pixel, in order) at the pixels, `fill` elsewhere.
    fn spread<T: Copy>(&self, values: impl Iterator<Item = T>, fill: T) -> Vec<T> {
        let mut out = vec![fill; self.width * self.height];
        for (&i, v) in self.pixels.iter().zip(values) {
            out[self.in_box(i)] = v;
        }
        out
    }

    /// Which pixels of the box are the pixels.
    fn mask(&self) -> Vec<bool> {
        self.spread(std::iter::repeat(true), false)
    }

    /// A box-sized image's values at the pixels, in order.
    fn gather<T: Copy>(&self, boxed: &[T]) -> Vec<T> {
        self.pixels.iter().map(|&i| boxed[self.in_box(i)]).collect()
    }

    /// A frame of `len` pixels with `values` (one per pixel, in order) at the pixels, NaN
    /// elsewhere.
    fn scatter(&self, values: &[f64], len: usize) -> Vec<f64> {
        let mut out = vec![f64::NAN; len];
        for (&i, &v) in self.pixels.iter().zip(values) {
            out[i] = v;
        }
        out
    }
}

/// SSIM map on 8-bit luminance with 7×7 windows (Wang et al. 2004 constants) that see only
/// pixels of `mask`: near the mask's edge a window averages over its pixels inside the mask,
/// so nothing outside the mask reaches any score. NaN outside the mask.
pub fn masked_ssim_map(a: &[f64], b: &[f64], mask: &[bool], w: usize, h: usize) -> Vec<f64> {
    use rayon::prelude::*;
    let (c1, c2) = ((0.01f64 * 255.0).powi(2), (0.03f64 * 255.0).powi(2));
    let r = 3i64;
    let mut out = vec![f64::NAN; w * h];
    let inside: Vec<usize> = (0..w * h).filter(|&i| mask[i]).collect();
    // Each pixel's window on its own, in parallel: the same map for any number of threads.
    let score = |i: usize| {
        let (x, y) = ((i % w) as i64, (i / w) as i64);
        let (mut sa, mut sb, mut saa, mut sbb, mut sab, mut n) = (0.0, 0.0, 0.0, 0.0, 0.0, 0.0);
        for yy in (y - r).max(0)..=(y + r).min(h as i64 - 1) {
            for xx in (x - r).max(0)..=(x + r).min(w as i64 - 1) {
                let j = yy as usize * w + xx as usize;
                if !mask[j] {
                    continue;
                }
                let (va, vb) = (a[j], b[j]);
                sa += va;
                sb += vb;
                saa += va * va;
                sbb += vb * vb;
                sab += va * vb;
                n += 1.0;
            }
        }
        let (ma, mb) = (sa / n, sb / n);
        let (va, vb, cov) = (saa / n - ma * ma, sbb / n - mb * mb, sab / n - ma * mb);
        ((2.0 * ma * mb + c1) * (2.0 * cov + c2)) / ((ma * ma + mb * mb + c1) * (va + vb + c2))
    };
    let scores: Vec<f64> = inside.par_iter().map(|&i| score(i)).collect();
    for (&i, v) in inside.iter().zip(scores) {
        out[i] = v;
    }
    out
}

/// FLIP map (NVIDIA's ꟻLIP, via nv-flip) over the box of `bounds`, of its pixels' colours
/// `truth` and `shown` (one per pixel, in order), at `ppd` pixels per degree. FLIP filters each
/// image spatially before comparing, so a whole-frame FLIP lets what lies outside the display
/// leak into the display's border. Here both images are cut to the pixels' bounding box and
/// every other pixel of it is set to the same mid grey in both: the filters see the display's
/// content and a shared, featureless surround, never anything outside the display.
fn boxed_flip_map(truth: &[[u8; 3]], shown: &[[u8; 3]], bounds: &DisplayBox, ppd: f32) -> Vec<f64> {
    let cut = |colours: &[[u8; 3]]| -> Vec<u8> {
        bounds.spread(colours.iter().copied(), [128; 3]).concat()
    };
    let image = |colours| {
        nv_flip::FlipImageRgb8::with_data(bounds.width as u32, bounds.height as u32, &cut(colours))
    };
    nv_flip::flip(image(truth), image(shown), ppd)
        .to_vec()
        .into_iter()
        .map(f64::from)
        .collect()
}

/// PSNR (dB) of 8-bit sRGB colours over the pixels of `mask`.
pub fn psnr(a: &[[u8; 3]], b: &[[u8; 3]], mask: &[bool]) -> f64 {
    let pixels: Vec<usize> = (0..mask.len()).filter(|&i| mask[i]).collect();
    psnr_over(a, b, &pixels)
}

/// PSNR (dB) of 8-bit sRGB colours over the pixels `pixels` (indices, summed in this order).
fn psnr_over(a: &[[u8; 3]], b: &[[u8; 3]], pixels: &[usize]) -> f64 {
    let (mut sum, mut n) = (0.0, 0usize);
    for &i in pixels {
        let (x, y) = (a[i], b[i]);
        for c in 0..3 {
            sum += (x[c] as f64 - y[c] as f64).powi(2);
        }
        n += 3;
    }
    if n == 0 {
        return f64::NAN;
    }
    let mse = sum / n as f64;
    if mse == 0.0 {
        f64::INFINITY
    } else {
        10.0 * (255.0 * 255.0 / mse).log10()
    }
}

/// The ray from `origin` along unit `dir` of [`nearer_than`]: the traversal stops a little
/// beyond `reach` (every f32 below `reach` is at most `reach as f32`, below this bound).
fn reach_ray(origin: Vec3, dir: Vec3, reach: f64) -> TraceRay {
    let tmax = if reach.is_finite() {
        (reach as f32).max(0.0).next_up().next_up()
    } else {
        f32::INFINITY
    };
    make_ray(origin, dir, 0.0, tmax)
}

/// Whether the closest surface the frontal camera sees along the ray from `origin` (unit
/// `dir`) is nearer than `reach` m: exactly `ctx.trace(origin, dir, view_bit::FRONTAL)`'s
/// hit at `t < reach`, but the traversal stops a little beyond `reach` and nothing is shaded.
/// One ray at a time: the twin of [`nearer_than_packet`].
#[cfg(test)]
fn nearer_than(ctx: &RenderContext, origin: Vec3, dir: Vec3, reach: f64) -> bool {
    let ray = reach_ray(origin, dir, reach);
    let near = |hit: Option<Hit>| hit.is_some_and(|h| (h.t as f64) < reach);
    near(ctx.accel.closest(&ray, view_bit::FRONTAL))
        || ctx
            .moving
            .as_ref()
            .is_some_and(|m| near(m.accel.closest(&ray, view_bit::FRONTAL)))
}

/// [`nearer_than`] for the rays from `origin` of the lanes of `lanes` (bit i for lane i),
/// lane i along `queries[i].0` to `queries[i].1` m, traced as one packet on `isa`'s kernels:
/// bit i of the answer is lane i's. The rays of neighbouring display pixels from one camera
/// are coherent, and the packet kernels give the per-ray hits bit for bit.
fn nearer_than_packet(
    ctx: &RenderContext,
    origin: Vec3,
    queries: &[(Vec3, f64); PACKET],
    lanes: u32,
    isa: Isa,
    stack: &mut PacketStack,
) -> u32 {
    if lanes == 0 {
        return 0;
    }
    let mut packet = RayPacket::new();
    for (lane, &(dir, reach)) in queries.iter().enumerate() {
        if lanes >> lane & 1 != 0 {
            packet.set(lane, &reach_ray(origin, dir, reach));
        }
    }
    let rays = packet;
    // A lane never set, or left out of `rest` (already near), holds no hit.
    let near_in = |packet: &RayPacket| {
        (0..PACKET)
            .filter(|&lane| {
                packet
                    .hit(lane)
                    .is_some_and(|h| (h.t as f64) < queries[lane].1)
            })
            .fold(0u32, |bits, lane| bits | 1 << lane)
    };
    ctx.accel
        .closest_packet(&mut packet, view_bit::FRONTAL, isa, stack);
    let mut near = near_in(&packet);
    if let Some(m) = &ctx.moving {
        let mut rest = rays;
        rest.active &= !near;
        if rest.active != 0 {
            m.accel
                .closest_packet(&mut rest, view_bit::FRONTAL, isa, stack);
            near |= near_in(&rest);
        }
    }
    near
}

/// Why the frontal camera cannot see a display pixel's truth point.
#[derive(Clone, Copy, PartialEq, Eq)]
enum Missing {
    OutOfView,
    Hidden,
}

/// One display pixel's measurements.
struct Measured {
    misregistration: f32,
    missing: Option<Missing>,
    class: PixelClass,
    sides: [bool; 4],
}

/// What one display pixel shows, for the statistics.
#[derive(Clone, Copy, Default)]
struct PixelClass {
    blank: bool,
    /// Whether the truth / `seethru` shows sky here (the pixel has a misregistration).
    truth_sky: bool,
    shown_sky: bool,
    /// Neither a point nor a direction (a frame without sky directions).
    undefined: bool,
}

/// Computes the maps and the metrics JSON. `truth`, `seethru` and `occluded` are frames of the
/// driver's camera at `driver_eye` (as rendered by `run`); `band` is the border band width in
/// display pixels.
pub fn measure(
    ctx: &RenderContext,
    scene: &Scene,
    driver_eye: DVec3,
    frames: [FrameView<'_>; 3],
    band: u32,
) -> (MetricMaps, serde_json::Value) {
    measure_with(ctx, scene, driver_eye, frames, band, Flip::Computed)
}

/// Whether [`measure_with`] computes FLIP, the costliest of its image metrics.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Flip {
    Computed,
    /// Every FLIP figure NaN (null in the JSON, which says so): a sequence's frames without
    /// `--flip`, where FLIP was a third of the metrics' time.
    Skipped,
}

impl Flip {
    /// FLIP computed when `asked` (a command's `--flip`), else skipped.
    pub fn asked(asked: bool) -> Flip {
        if asked { Flip::Computed } else { Flip::Skipped }
    }
}

/// [`measure`], with FLIP computed or not.
pub fn measure_with(
    ctx: &RenderContext,
    scene: &Scene,
    driver_eye: DVec3,
    frames: [FrameView<'_>; 3],
    band: u32,
    flip: Flip,
) -> (MetricMaps, serde_json::Value) {
    let [truth, seethru, occluded] = frames;
    let (w, h) = (truth.width() as usize, truth.height() as usize);
    let obstacle = &scene.obstacle;
    let placement = DisplayPlacement::new(obstacle);
    let [dw, dh] = obstacle.display_resolution;
    let mut display: Vec<bool> = Vec::with_capacity(w * h);
    for y in 0..h as u32 {
        let parts = occluded.row(|f| &f.part_id, y);
        for (ids, parts) in occluded.row(|f| &f.object_id, y).iter().zip(parts) {
            let shown = ids.iter().zip(parts);
            display.extend(shown.map(|(&o, &p)| ctx.world.is_display(o, p)));
        }
    }
    // Every statistic is over display pixels, taken in index order (row by row): the same
    // sums as a pass over the whole frame, without visiting the rest of it. What is kept per
    // display pixel is kept in that order (index k of `on_display`), not over the frame.
    let on_display: Vec<usize> = (0..w * h).filter(|&i| display[i]).collect();
    let count = on_display.len();
    let frontal = &scene.frontal;
    let in_frontal_image = |q: Option<DVec2>| {
        q.is_some_and(|q| {
            q.x >= 0.0 && q.y >= 0.0 && q.x < frontal.width as f64 && q.y < frontal.height as f64
        })
    };
    let frontal_origin = frontal.position();
    // One display pixel's measurements, and the ray towards the frontal camera that decides
    // whether its truth point is hidden from it (direction, reach), where one is needed.
    let per_pixel = |i: usize| -> (Measured, Option<(Vec3, f64)>) {
        let mut out = Measured {
            misregistration: f32::NAN,
            missing: None,
            class: PixelClass::default(),
            sides: [false; 4],
        };
        let mut hidden_query = None;
        // The display pixel coordinates of the point: a curved display's from its UVs.
        let uv = placement.pixel_coords(occluded.get(|f| &f.position, i));
        let (u, v) = (uv.x, uv.y);
        out.sides = [
            u < band as f64,
            u >= (dw - band) as f64,
            v < band as f64,
            v >= (dh - band) as f64,
        ];
        let t = truth.get(|f| &f.position, i);
        let true_dir = shown_direction(t, truth.get(|f| &f.normal, i), driver_eye);
        // Can the frontal camera see the truth's point, or its sky direction?
        if let Some(d) = true_dir {
            let (inside, to, distance) = if t.is_finite() {
                let to = t.as_dvec3() - frontal_origin;
                (
                    in_frontal_image(frontal.project_point(t.as_dvec3())),
                    to,
                    to.length(),
                )
            } else {
                (
                    in_frontal_image(frontal.project_direction(d)),
                    d,
                    f64::INFINITY,
                )
            };
            if !inside {
                out.missing = Some(Missing::OutOfView);
            } else {
                // A surface short of the point (any surface, towards a sky direction).
                let reach = if distance.is_finite() {
                    distance - 1e-3 * distance.max(1.0)
                } else {
                    f64::INFINITY
                };
                hidden_query = Some((to.normalize().as_vec3(), reach));
            }
        }
        if seethru.get(|f| &f.object_id, i) == MISSING_ID {
            out.class.blank = true;
            return (out, hidden_query);
        }
        let shown = seethru.get(|f| &f.position, i);
        let shown_dir = shown_direction(shown, seethru.get(|f| &f.normal, i), driver_eye);
        match (shown_dir, true_dir) {
            (Some(a), Some(b)) => {
                out.misregistration = (angle_between(a, b) * ARCMIN_PER_RAD) as f32;
                out.class.truth_sky = !t.is_finite();
                out.class.shown_sky = !shown.is_finite();
            }
            _ => out.class.undefined = true,
        }
        (out, hidden_query)
    };
    // Runs of PACKET display pixels in parallel, their rays to the frontal camera traced as
    // one packet: the same answers for any number of threads.
    let isa = Isa::best();
    let measured: Vec<Measured> = {
        use rayon::prelude::*;
        on_display
            .par_chunks(PACKET)
            .map(|run| {
                PacketStack::with_thread_stack(|stack| {
                    let mut queries = [(Vec3::X, 0.0); PACKET];
                    let mut asked = 0u32;
                    let mut out: Vec<Measured> = Vec::with_capacity(run.len());
                    for (lane, &i) in run.iter().enumerate() {
                        let (m, query) = per_pixel(i);
                        if let Some(q) = query {
                            queries[lane] = q;
                            asked |= 1 << lane;
                        }
                        out.push(m);
                    }
                    let origin = frontal_origin.as_vec3();
                    let hidden = nearer_than_packet(ctx, origin, &queries, asked, isa, stack);
                    for (lane, m) in out.iter_mut().enumerate() {
                        if hidden >> lane & 1 != 0 {
                            m.missing = Some(Missing::Hidden);
                        }
                    }
                    out
                })
            })
            .flatten_iter()
            .collect()
    };
    let mut misregistration = vec![f32::NAN; w * h];
    let mut missing = vec![false; w * h];
    let mut blank = vec![false; w * h];
    let (mut out_of_view, mut hidden) = (0usize, 0usize);
    for (&i, m) in on_display.iter().zip(&measured) {
        misregistration[i] = m.misregistration;
        missing[i] = m.missing.is_some();
        blank[i] = m.class.blank;
        out_of_view += usize::from(m.missing == Some(Missing::OutOfView));
        hidden += usize::from(m.missing == Some(Missing::Hidden));
    }
    let count_where =
        |keep: &dyn Fn(&Measured) -> bool| measured.iter().filter(|m| keep(m)).count();
    let driver_pixel_arcmin = (2.0 * scene.driver.tan_half_x() / w as f64).atan() * ARCMIN_PER_RAD;
    // Colours of the display's pixels only.
    let srgb_t: Vec<[u8; 3]> = on_display
        .iter()
        .map(|&i| encode_srgb8(truth.get(|f| &f.color, i)))
        .collect();
    let srgb_s: Vec<[u8; 3]> = on_display
        .iter()
        .map(|&i| encode_srgb8(seethru.get(|f| &f.color, i)))
        .collect();
    // SSIM's windows and FLIP's filters see the display pixels in their bounding box, which
    // holds every pixel a window or filter of theirs would read.
    let bounds = DisplayBox::of(&on_display, w);
    let lum = |srgb: &[[u8; 3]]| bounds.spread(srgb.iter().map(|&c| luma(c)), 0.0);
    // FLIP with the driver's eye as the observer: pixels per degree of the driver's camera.
    let ppd = w as f32 / (2.0 * scene.driver.half_angle_x.to_degrees() as f32);
    let flip_skipped = flip == Flip::Skipped;
    // SSIM and FLIP side by side: FLIP (one thread's C++) was a third of the metrics' time.
    let (ssim, flip): (Vec<f64>, Vec<f64>) = rayon::join(
        || {
            let ssim_box = masked_ssim_map(
                &lum(&srgb_t),
                &lum(&srgb_s),
                &bounds.mask(),
                bounds.width,
                bounds.height,
            );
            bounds.gather(&ssim_box)
        },
        || match flip {
            Flip::Computed if count > 0 => {
                bounds.gather(&boxed_flip_map(&srgb_t, &srgb_s, &bounds, ppd))
            }
            _ => vec![f64::NAN; count],
        },
    );
    let region = |keep: &dyn Fn(&Measured) -> bool| {
        let pixels_in: Vec<usize> = (0..count).filter(|&k| keep(&measured[k])).collect();
        let pixels = pixels_in.len();
        let blank = pixels_in
            .iter()
            .filter(|&&k| measured[k].class.blank)
            .count();
        let mut values: Vec<f64> = pixels_in
            .iter()
            .map(|&k| measured[k].misregistration)
            .filter(|v| v.is_finite())
            .map(f64::from)
            .collect();
        let over = |map: &[f64]| mean(pixels_in.iter().map(|&k| map[k]));
        let colour_error = mean(pixels_in.iter().map(|&k| {
            (0..3)
                .map(|c| (srgb_t[k][c] as f64 - srgb_s[k][c] as f64).abs())
                .sum::<f64>()
                / 3.0
        }));
        json!({
            "pixels": pixels,
            "coverage": if pixels == 0 { f64::NAN } else { 1.0 - blank as f64 / pixels as f64 },
            "blank_pixels": blank,
            "misregistration_arcmin": stats(&mut values),
            "mean_abs_colour_error_8bit": colour_error,
            "psnr_db": psnr_over(&srgb_t, &srgb_s, &pixels_in),
            "ssim": over(&ssim),
            "flip_mean": over(&flip),
        })
    };
    let per_side: serde_json::Map<String, serde_json::Value> = ["left", "right", "top", "bottom"]
        .iter()
        .enumerate()
        .map(|(k, name)| (name.to_string(), region(&|m| m.sides[k])))
        .collect();
    let blank_count = count_where(&|m| m.class.blank);
    let mean_px = mean(
        measured
            .iter()
            .map(|m| m.misregistration)
            .filter(|v| v.is_finite())
            .map(f64::from),
    ) / driver_pixel_arcmin;
    let sky = |truth_sky: bool, shown_sky: bool| {
        count_where(&|m| {
            m.misregistration.is_finite()
                && m.class.truth_sky == truth_sky
                && m.class.shown_sky == shown_sky
        })
    };
    let mut json = json!({
        "display_pixels": count,
        "coverage": if count == 0 { f64::NAN } else { 1.0 - blank_count as f64 / count as f64 },
        "blank_pixels": blank_count,
        "sky_pixels_included": {
            "truth_only": sky(true, false),
            "seethru_only": sky(false, true),
            "both": sky(true, true),
        },
        "undefined_pixels": count_where(&|m| m.class.undefined),
        "driver_pixel_arcmin": driver_pixel_arcmin,
        "display": region(&|_| true),
        "misregistration_mean_driver_px": mean_px,
        "border_band_display_px": band,
        "border": region(&|m| m.sides.iter().any(|&s| s)),
        "border_per_side": per_side,
        "missing": {
            "fraction": if count == 0 { 0.0 } else { (out_of_view + hidden) as f64 / count as f64 },
            "outside_frontal_view": out_of_view,
            "hidden_from_frontal": hidden,
        },
        "flip_pixels_per_degree": ppd,
        "notes": "every display pixel counts. misregistration: angle at the eye between the direction seethru shows and the truth's (towards a world point, or a sky direction), over the covered pixels; coverage: fraction of the region's pixels that show the scene (blank pixels, outside the frontal view, have no misregistration and count in the image metrics as the black they show); undefined_pixels: neither a point nor a direction (0 for frames of this version). Colour metrics on 8-bit sRGB; SSIM on luminance with 7×7 windows inside the display mask; FLIP (NVIDIA, via nv-flip) with the driver's camera as observer, on the display's bounding box with everything outside the display mask set to the same grey in both images",
    });
    if flip_skipped {
        json["flip_not_computed"] =
            json!("FLIP was not computed (a sequence without --flip): every flip_mean is null");
    }
    (
        MetricMaps {
            width: w as u32,
            height: h as u32,
            misregistration,
            missing,
            display,
            blank,
            ssim: bounds.scatter(&ssim, w * h),
            flip: bounds.scatter(&flip, w * h),
        },
        json,
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn statistics_of_one_to_a_hundred() {
        let mut values: Vec<f64> = (1..=100).rev().map(f64::from).collect();
        let s = stats(&mut values);
        assert_eq!(s["count"], 100);
        assert_eq!(s["mean"], 50.5);
        // The 95th percentile: the smallest value with 95 % of the values at or below it.
        assert_eq!(s["p95"], 95.0);
        assert_eq!(s["max"], 100.0);
        assert_eq!(stats(&mut [7.0])["p95"], 7.0);
        assert_eq!(stats(&mut [])["count"], 0);
    }

    /// The packet query against its per-ray twin, on das seen from the frontal camera, with
    /// a moving layer (the car and the ball, carried 3 m towards the camera and 1 m left) that
    /// alone decides some lanes: every reach from the camera's near field to infinity.
    #[test]
    fn the_packet_query_answers_as_the_per_ray_one() {
        use crate::render::moving::MovingParts;
        use std::sync::Arc;
        let scene = Scene::bundled("das.toml");
        let mut ctx = RenderContext::new(scene.clone()).unwrap();
        let movers = |i: usize| ["car", "ball"].contains(&scene.objects[i].name.as_str());
        let moved = glam::DAffine3::from_translation(DVec3::new(-1.0, 0.0, 3.0));
        let layer = MovingParts::new(&scene, &movers)
            .unwrap()
            .at(&|_| Some(moved))
            .unwrap();
        ctx.moving = Some(Arc::new(layer));
        let camera = &scene.frontal;
        let origin = camera.position().as_vec3();
        let mut stack = PacketStack::new();
        let (mut rays, mut near, mut by_moving) = (0, 0, 0);
        for (k, isa) in Isa::ALL.into_iter().filter(|i| i.available()).enumerate() {
            for y in (0..camera.height).step_by(9) {
                for x0 in (0..camera.width).step_by(4 * PACKET) {
                    let mut queries = [(Vec3::X, 0.0); PACKET];
                    let mut lanes = 0u32;
                    for (lane, query) in queries.iter_mut().enumerate() {
                        let x = x0 + 3 * lane as u32;
                        // Every third lane idle; reaches 0.5 m to 154 m and infinity.
                        if x >= camera.width || lane % 3 == 2 {
                            continue;
                        }
                        let pixel = DVec2::new(f64::from(x) + 0.5, f64::from(y) + 0.5);
                        let (_, dir) = camera.world_ray(pixel);
                        let reach = match (x + y) % 8 {
                            0 => f64::INFINITY,
                            // Exactly the static surface's distance: it is not nearer.
                            7 => ctx
                                .accel
                                .closest(
                                    &reach_ray(origin, dir.as_vec3(), f64::INFINITY),
                                    view_bit::FRONTAL,
                                )
                                .map_or(1.0, |h| f64::from(h.t)),
                            r => 0.5 * 2.6f64.powi(r as i32),
                        };
                        *query = (dir.as_vec3(), reach);
                        lanes |= 1 << lane;
                    }
                    let got = nearer_than_packet(&ctx, origin, &queries, lanes, isa, &mut stack);
                    for (lane, &(dir, reach)) in queries.iter().enumerate() {
                        let asked = lanes >> lane & 1 != 0;
                        let want = asked && nearer_than(&ctx, origin, dir, reach);
                        assert_eq!(got >> lane & 1 != 0, want, "{isa:?} ({x0}+3·{lane}, {y})");
                        if k == 0 && asked {
                            rays += 1;
                            near += usize::from(want);
                            let alone = ctx
                                .accel
                                .closest(&reach_ray(origin, dir, reach), view_bit::FRONTAL);
                            let by_static = alone.is_some_and(|h| (h.t as f64) < reach);
                            by_moving += usize::from(want && !by_static);
                        }
                    }
                }
            }
        }
        // Both answers, and the moving layer's, in numbers.
        assert!(near > rays / 5 && near < rays * 4 / 5, "{near} of {rays}");
        assert!(by_moving > 20, "{by_moving}");
    }

    #[test]
    fn the_box_of_display_pixels() {
        let corners = |b: DisplayBox| (b.x0, b.y0, b.x0 + b.width, b.y0 + b.height);
        assert_eq!(corners(DisplayBox::of(&[], 5)), (0, 0, 0, 0));
        assert_eq!(
            corners(DisplayBox::of(&[5 + 1, 2 * 5 + 3], 5)),
            (1, 1, 4, 3)
        );
        // The first pixel in index order is the rightmost and the bottom row's only one is the
        // leftmost: the box spans both.
        assert_eq!(
            corners(DisplayBox::of(&[5 + 3, 2 * 5 + 1], 5)),
            (1, 1, 4, 3)
        );
        assert_eq!(corners(DisplayBox::of(&[2 * 5 + 2], 5)), (2, 2, 3, 3));
    }

    #[test]
    fn a_box_spreads_gathers_and_scatters_its_pixels_in_place() {
        // Pixels (3, 1), (1, 2) and (2, 2) of a 5 × 4 frame: a box 3 wide and 2 high at (1, 1).
        let pixels = [5 + 3, 2 * 5 + 1, 2 * 5 + 2];
        let b = DisplayBox::of(&pixels, 5);
        let boxed = b.spread([1.0, 2.0, 3.0].into_iter(), 0.0);
        assert_eq!(boxed, vec![0.0, 0.0, 1.0, 2.0, 3.0, 0.0]);
        assert_eq!(b.mask(), vec![false, false, true, true, true, false]);
        assert_eq!(b.gather(&boxed), vec![1.0, 2.0, 3.0]);
        let frame = b.scatter(&[1.0, 2.0, 3.0], 20);
        let set: Vec<(usize, f64)> = (0..20)
            .filter(|&i| !frame[i].is_nan())
            .map(|i| (i, frame[i]))
            .collect();
        assert_eq!(set, vec![(8, 1.0), (11, 2.0), (12, 3.0)]);
    }
}
