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
use crate::render::accel::{Hit, make_ray};
use crate::render::frame::Frame;
use crate::render::integrator::RenderContext;
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

/// The bounding box of `mask` as (x0, y0, x1, y1), exclusive ends; `None` when it is empty.
fn bounding_box(mask: &[bool], w: usize) -> Option<(usize, usize, usize, usize)> {
    mask.iter()
        .enumerate()
        .filter(|(_, m)| **m)
        .fold(None, |b, (i, _)| {
            let (x, y) = (i % w, i / w);
            Some(b.map_or((x, y, x + 1, y + 1), |(x0, y0, x1, y1)| {
                (x0.min(x), y0.min(y), x1.max(x + 1), y1.max(y + 1))
            }))
        })
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

/// FLIP map (NVIDIA's ꟻLIP, via nv-flip) of the pixels of `mask` only, at `ppd` pixels per
/// degree. FLIP filters each image spatially before comparing, so a whole-frame FLIP lets
/// what lies outside the display leak into the display's border. Here both images are cut to
/// the mask's bounding box and every pixel outside the mask is set to the same mid grey in
/// both: the filters see the display's content and a shared, featureless surround, never
/// anything outside the display. NaN outside the mask.
fn masked_flip_map(
    truth: &[[u8; 3]],
    shown: &[[u8; 3]],
    mask: &[bool],
    w: usize,
    ppd: f32,
) -> Vec<f64> {
    let mut out = vec![f64::NAN; mask.len()];
    let Some((x0, y0, x1, y1)) = bounding_box(mask, w) else {
        return out;
    };
    let (bw, bh) = (x1 - x0, y1 - y0);
    let cut = |image: &[[u8; 3]]| -> Vec<u8> {
        (0..bw * bh)
            .flat_map(|k| {
                let i = (y0 + k / bw) * w + x0 + k % bw;
                if mask[i] { image[i] } else { [128; 3] }
            })
            .collect()
    };
    let flip = nv_flip::flip(
        nv_flip::FlipImageRgb8::with_data(bw as u32, bh as u32, &cut(truth)),
        nv_flip::FlipImageRgb8::with_data(bw as u32, bh as u32, &cut(shown)),
        ppd,
    )
    .to_vec();
    for (k, v) in flip.iter().enumerate() {
        let i = (y0 + k / bw) * w + x0 + k % bw;
        if mask[i] {
            out[i] = *v as f64;
        }
    }
    out
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

/// Whether the closest surface the frontal camera sees along the ray from `origin` (unit
/// `dir`) is nearer than `reach` m: exactly `ctx.trace(origin, dir, view_bit::FRONTAL)`'s
/// hit at `t < reach`, but the traversal stops a little beyond `reach` and nothing is shaded.
fn nearer_than(ctx: &RenderContext, origin: Vec3, dir: Vec3, reach: f64) -> bool {
    // Every f32 below `reach` is at most `reach as f32`, below this bound.
    let tmax = if reach.is_finite() {
        (reach as f32).max(0.0).next_up().next_up()
    } else {
        f32::INFINITY
    };
    let ray = make_ray(origin, dir, 0.0, tmax);
    let near = |hit: Option<Hit>| hit.is_some_and(|h| (h.t as f64) < reach);
    near(ctx.accel.closest(&ray, view_bit::FRONTAL))
        || ctx
            .moving
            .as_ref()
            .is_some_and(|m| near(m.accel.closest(&ray, view_bit::FRONTAL)))
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
    frames: [&Frame; 3],
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
    frames: [&Frame; 3],
    band: u32,
    flip: Flip,
) -> (MetricMaps, serde_json::Value) {
    let [truth, seethru, occluded] = frames;
    let (w, h) = (truth.width as usize, truth.height as usize);
    let obstacle = &scene.obstacle;
    let placement = DisplayPlacement::new(obstacle);
    let [dw, dh] = obstacle.display_resolution;
    let display: Vec<bool> = occluded
        .object_id
        .iter()
        .zip(&occluded.part_id)
        .map(|(&o, &p)| ctx.world.is_display(o, p))
        .collect();
    // Every statistic is over display pixels, taken in index order (row by row): the same
    // sums as a pass over the whole frame, without visiting the rest of it.
    let on_display: Vec<usize> = (0..w * h).filter(|&i| display[i]).collect();
    let mut misregistration = vec![f32::NAN; w * h];
    let mut missing = vec![false; w * h];
    let mut class = vec![PixelClass::default(); w * h];
    // Which side bands each pixel is in: left, right, top, bottom.
    let mut sides = vec![[false; 4]; w * h];
    let frontal = &scene.frontal;
    let in_frontal_image = |q: Option<DVec2>| {
        q.is_some_and(|q| {
            q.x >= 0.0 && q.y >= 0.0 && q.x < frontal.width as f64 && q.y < frontal.height as f64
        })
    };
    let frontal_origin = frontal.position();
    // Each display pixel on its own (one ray towards the frontal camera each), in parallel.
    let per_pixel = |i: usize| {
        let mut out = Measured {
            misregistration: f32::NAN,
            missing: None,
            class: PixelClass::default(),
            sides: [false; 4],
        };
        // The display pixel coordinates of the point: a curved display's from its UVs.
        let uv = placement.pixel_coords(occluded.position[i]);
        let (u, v) = (uv.x, uv.y);
        out.sides = [
            u < band as f64,
            u >= (dw - band) as f64,
            v < band as f64,
            v >= (dh - band) as f64,
        ];
        let t = truth.position[i];
        let true_dir = shown_direction(t, truth.normal[i], driver_eye);
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
                let origin = frontal_origin.as_vec3();
                if nearer_than(ctx, origin, to.normalize().as_vec3(), reach) {
                    out.missing = Some(Missing::Hidden);
                }
            }
        }
        if seethru.object_id[i] == MISSING_ID {
            out.class.blank = true;
            return out;
        }
        let shown_dir = shown_direction(seethru.position[i], seethru.normal[i], driver_eye);
        match (shown_dir, true_dir) {
            (Some(a), Some(b)) => {
                out.misregistration = (angle_between(a, b) * ARCMIN_PER_RAD) as f32;
                out.class.truth_sky = !t.is_finite();
                out.class.shown_sky = !seethru.position[i].is_finite();
            }
            _ => out.class.undefined = true,
        }
        out
    };
    let measured: Vec<Measured> = {
        use rayon::prelude::*;
        on_display.par_iter().map(|&i| per_pixel(i)).collect()
    };
    let (mut out_of_view, mut hidden) = (0usize, 0usize);
    for (&i, m) in on_display.iter().zip(&measured) {
        misregistration[i] = m.misregistration;
        missing[i] = m.missing.is_some();
        out_of_view += usize::from(m.missing == Some(Missing::OutOfView));
        hidden += usize::from(m.missing == Some(Missing::Hidden));
        class[i] = m.class;
        sides[i] = m.sides;
    }
    let count = on_display.len();
    let count_where =
        |keep: &dyn Fn(usize) -> bool| on_display.iter().filter(|&&i| keep(i)).count();
    let driver_pixel_arcmin = (2.0 * scene.driver.tan_half_x() / w as f64).atan() * ARCMIN_PER_RAD;
    // Colours of the display's pixels only (nothing else is read; black elsewhere).
    let (mut srgb_t, mut srgb_s) = (vec![[0u8; 3]; w * h], vec![[0u8; 3]; w * h]);
    let (mut lum_t, mut lum_s) = (vec![0.0; w * h], vec![0.0; w * h]);
    for &i in &on_display {
        srgb_t[i] = encode_srgb8(truth.color[i]);
        srgb_s[i] = encode_srgb8(seethru.color[i]);
        lum_t[i] = luma(srgb_t[i]);
        lum_s[i] = luma(srgb_s[i]);
    }
    let ssim = masked_ssim_map(&lum_t, &lum_s, &display, w, h);
    // FLIP with the driver's eye as the observer: pixels per degree of the driver's camera.
    let ppd = w as f32 / (2.0 * scene.driver.half_angle_x.to_degrees() as f32);
    let flip_skipped = flip == Flip::Skipped;
    let flip = match flip {
        Flip::Computed => masked_flip_map(&srgb_t, &srgb_s, &display, w, ppd),
        Flip::Skipped => vec![f64::NAN; w * h],
    };
    let region = |keep: &dyn Fn(usize) -> bool| {
        let pixels_in: Vec<usize> = on_display.iter().copied().filter(|&i| keep(i)).collect();
        let pixels = pixels_in.len();
        let blank = pixels_in.iter().filter(|&&i| class[i].blank).count();
        let mut values: Vec<f64> = pixels_in
            .iter()
            .filter(|&&i| misregistration[i].is_finite())
            .map(|&i| misregistration[i] as f64)
            .collect();
        let over = |map: &[f64]| mean(pixels_in.iter().map(|&i| map[i]));
        let colour_error = mean(pixels_in.iter().map(|&i| {
            (0..3)
                .map(|c| (srgb_t[i][c] as f64 - srgb_s[i][c] as f64).abs())
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
    let in_band = |i: usize| display[i] && sides[i].iter().any(|&s| s);
    let per_side: serde_json::Map<String, serde_json::Value> = ["left", "right", "top", "bottom"]
        .iter()
        .enumerate()
        .map(|(k, name)| {
            (
                name.to_string(),
                region(&|i: usize| display[i] && sides[i][k]),
            )
        })
        .collect();
    let blank = count_where(&|i| display[i] && class[i].blank);
    let mean_px = mean(
        on_display
            .iter()
            .map(|&i| misregistration[i])
            .filter(|v| v.is_finite())
            .map(|v| v as f64),
    ) / driver_pixel_arcmin;
    let sky = |truth_sky: bool, shown_sky: bool| {
        count_where(&|i| {
            display[i]
                && misregistration[i].is_finite()
                && class[i].truth_sky == truth_sky
                && class[i].shown_sky == shown_sky
        })
    };
    let mut json = json!({
        "display_pixels": count,
        "coverage": if count == 0 { f64::NAN } else { 1.0 - blank as f64 / count as f64 },
        "blank_pixels": blank,
        "sky_pixels_included": {
            "truth_only": sky(true, false),
            "seethru_only": sky(false, true),
            "both": sky(true, true),
        },
        "undefined_pixels": count_where(&|i| display[i] && class[i].undefined),
        "driver_pixel_arcmin": driver_pixel_arcmin,
        "display": region(&|i| display[i]),
        "misregistration_mean_driver_px": mean_px,
        "border_band_display_px": band,
        "border": region(&in_band),
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
    let blank = (0..w * h).map(|i| class[i].blank).collect();
    (
        MetricMaps {
            width: w as u32,
            height: h as u32,
            misregistration,
            missing,
            display,
            blank,
            ssim,
            flip,
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

    #[test]
    fn the_bounding_box_of_a_mask() {
        let mut mask = vec![false; 5 * 4];
        assert_eq!(bounding_box(&mask, 5), None);
        mask[5 + 1] = true;
        mask[2 * 5 + 3] = true;
        assert_eq!(bounding_box(&mask, 5), Some((1, 1, 4, 3)));
        // The first pixel in index order is the rightmost and the bottom row's only one: its
        // own box must end one past it.
        let mut mask = vec![false; 5 * 4];
        mask[5 + 3] = true;
        mask[2 * 5 + 1] = true;
        assert_eq!(bounding_box(&mask, 5), Some((1, 1, 4, 3)));
        let mut one = vec![false; 5 * 4];
        one[2 * 5 + 2] = true;
        assert_eq!(bounding_box(&one, 5), Some((2, 2, 3, 3)));
    }
}
