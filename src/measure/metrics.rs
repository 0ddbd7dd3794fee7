//! Metrics of a `seethru` frame against the `truth` (DESIGN.md §5), inside the display
//! region: misregistration, border mismatch, PSNR/SSIM, missing pixels.

use glam::DVec3;
use serde_json::json;

use crate::analysis::physical::ARCMIN_PER_RAD;
use crate::render::frame::Frame;
use crate::render::integrator::RenderContext;
use crate::scene::Scene;
use crate::scene::shapes::box_face;
use crate::scene::world::view_bit;
use crate::system::display::MISSING_ID;
use crate::util::color::encode_srgb8;

/// Per-pixel results over the driver's view (NaN / false outside the display region).
pub struct MetricMaps {
    pub width: u32,
    pub height: u32,
    /// Angle at the eye between the shown and the true world point, arc-minutes.
    pub misregistration: Vec<f32>,
    /// Display pixels whose truth point the frontal camera cannot see.
    pub missing: Vec<bool>,
    /// Pixels where the driver sees the display.
    pub display: Vec<bool>,
    /// Display pixels that show nothing (their crop point is outside the frontal image).
    pub blank: Vec<bool>,
}

/// Summary statistics of a set of values.
fn stats(values: &mut [f64]) -> serde_json::Value {
    if values.is_empty() {
        return json!({"count": 0});
    }
    values.sort_by(f64::total_cmp);
    let n = values.len();
    let mean = values.iter().sum::<f64>() / n as f64;
    let p95 = values[((0.95 * n as f64).ceil() as usize).clamp(1, n) - 1];
    json!({"count": n, "mean": mean, "p95": p95, "max": values[n - 1]})
}

fn luminance(c: [u8; 3]) -> f64 {
    0.2126 * c[0] as f64 + 0.7152 * c[1] as f64 + 0.0722 * c[2] as f64
}

/// SSIM map on 8-bit luminance with 7×7 windows (Wang et al. 2004 constants).
fn ssim_map(a: &[f64], b: &[f64], w: usize, h: usize) -> Vec<f64> {
    let (c1, c2) = ((0.01f64 * 255.0).powi(2), (0.03f64 * 255.0).powi(2));
    let r = 3i64;
    let mut out = vec![f64::NAN; w * h];
    for y in 0..h as i64 {
        for x in 0..w as i64 {
            let (mut sa, mut sb, mut saa, mut sbb, mut sab, mut n) = (0.0, 0.0, 0.0, 0.0, 0.0, 0.0);
            for dy in -r..=r {
                for dx in -r..=r {
                    let (xx, yy) = (
                        (x + dx).clamp(0, w as i64 - 1) as usize,
                        (y + dy).clamp(0, h as i64 - 1) as usize,
                    );
                    let (va, vb) = (a[yy * w + xx], b[yy * w + xx]);
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
            out[y as usize * w + x as usize] = ((2.0 * ma * mb + c1) * (2.0 * cov + c2))
                / ((ma * ma + mb * mb + c1) * (va + vb + c2));
        }
    }
    out
}

/// PSNR (dB) of 8-bit sRGB colours over the pixels of `mask`.
fn psnr(a: &[[u8; 3]], b: &[[u8; 3]], mask: &[bool]) -> f64 {
    let (mut sum, mut n) = (0.0, 0usize);
    for ((x, y), _) in a.iter().zip(b).zip(mask).filter(|(_, m)| **m) {
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

/// Computes the maps and the metrics JSON. `truth`, `seethru` and `occluded` are frames of the
/// driver's camera `driver` (as rendered by `run`); `band` is the border band width in display
/// pixels.
pub fn measure(
    ctx: &RenderContext,
    scene: &Scene,
    driver_eye: DVec3,
    frames: [&Frame; 3],
    band: u32,
) -> (MetricMaps, serde_json::Value) {
    let [truth, seethru, occluded] = frames;
    let (w, h) = (truth.width as usize, truth.height as usize);
    let obstacle = &scene.obstacle;
    let obstacle_from_world = obstacle.world_from_obstacle.inverse();
    let [dw, dh] = obstacle.display_resolution;
    let display: Vec<bool> = occluded
        .object_id
        .iter()
        .zip(&occluded.part_id)
        .map(|(&o, &p)| o == ctx.world.obstacle_id && p == box_face::POS_Z)
        .collect();
    let mut misregistration = vec![f32::NAN; w * h];
    let mut missing = vec![false; w * h];
    let (mut out_of_view, mut hidden, mut sky) = (0usize, 0usize, 0usize);
    // Which side bands each pixel is in: left, right, top, bottom.
    let mut sides = vec![[false; 4]; w * h];
    let frontal = &scene.frontal;
    for i in (0..w * h).filter(|&i| display[i]) {
        let on_display = obstacle_from_world.transform_point3(occluded.position[i].as_dvec3());
        let u = (on_display.x / obstacle.width + 0.5) * dw as f64;
        let v = (0.5 - on_display.y / obstacle.height) * dh as f64;
        sides[i] = [
            u < band as f64,
            u >= (dw - band) as f64,
            v < band as f64,
            v >= (dh - band) as f64,
        ];
        let (t, s) = (truth.position[i], seethru.position[i]);
        if !t.is_finite() {
            sky += 1;
            continue;
        }
        // Can the frontal camera see the truth's point?
        let p = t.as_dvec3();
        let inside = frontal.project_point(p).is_some_and(|q| {
            q.x >= 0.0 && q.y >= 0.0 && q.x < frontal.width as f64 && q.y < frontal.height as f64
        });
        if !inside {
            missing[i] = true;
            out_of_view += 1;
        } else {
            let origin = frontal.position().as_vec3();
            let to = t - origin;
            let distance = to.length();
            let hit = ctx.trace(origin, to / distance, view_bit::FRONTAL);
            if hit.is_some_and(|h| h.t < distance - 1e-3 * distance.max(1.0)) {
                missing[i] = true;
                hidden += 1;
            }
        }
        if s.is_finite() {
            let (a, b) = ((s.as_dvec3() - driver_eye), (p - driver_eye));
            misregistration[i] = (a.cross(b).length().atan2(a.dot(b)) * ARCMIN_PER_RAD) as f32;
        }
    }
    let count = display.iter().filter(|&&m| m).count();
    let driver_pixel_arcmin = (2.0 * scene.driver.tan_half_x() / w as f64).atan() * ARCMIN_PER_RAD;
    let collect = |keep: &dyn Fn(usize) -> bool| -> Vec<f64> {
        (0..w * h)
            .filter(|&i| keep(i) && misregistration[i].is_finite())
            .map(|i| misregistration[i] as f64)
            .collect()
    };
    let srgb_t: Vec<[u8; 3]> = truth.color.iter().map(|&c| encode_srgb8(c)).collect();
    let srgb_s: Vec<[u8; 3]> = seethru.color.iter().map(|&c| encode_srgb8(c)).collect();
    let colour_error = |keep: &dyn Fn(usize) -> bool| {
        let (mut sum, mut n) = (0.0, 0usize);
        for i in (0..w * h).filter(|&i| keep(i)) {
            sum += (0..3)
                .map(|c| (srgb_t[i][c] as f64 - srgb_s[i][c] as f64).abs())
                .sum::<f64>()
                / 3.0;
            n += 1;
        }
        if n == 0 { f64::NAN } else { sum / n as f64 }
    };
    let lum_t: Vec<f64> = srgb_t.iter().map(|&c| luminance(c)).collect();
    let lum_s: Vec<f64> = srgb_s.iter().map(|&c| luminance(c)).collect();
    let ssim = ssim_map(&lum_t, &lum_s, w, h);
    let mean_over = |mask: &dyn Fn(usize) -> bool| {
        let v: Vec<f64> = (0..w * h).filter(|&i| mask(i)).map(|i| ssim[i]).collect();
        if v.is_empty() {
            f64::NAN
        } else {
            v.iter().sum::<f64>() / v.len() as f64
        }
    };
    // FLIP with the driver's eye as the observer: pixels per degree of the driver's camera.
    let ppd = w as f32 / (2.0 * scene.driver.half_angle_x.to_degrees() as f32);
    let flat = |c: &[[u8; 3]]| c.iter().flatten().copied().collect::<Vec<u8>>();
    let flip = nv_flip::flip(
        nv_flip::FlipImageRgb8::with_data(w as u32, h as u32, &flat(&srgb_t)),
        nv_flip::FlipImageRgb8::with_data(w as u32, h as u32, &flat(&srgb_s)),
        ppd,
    )
    .to_vec();
    let flip_mean = |keep: &dyn Fn(usize) -> bool| {
        let v: Vec<f64> = (0..w * h)
            .filter(|&i| keep(i))
            .map(|i| flip[i] as f64)
            .collect();
        if v.is_empty() {
            f64::NAN
        } else {
            v.iter().sum::<f64>() / v.len() as f64
        }
    };
    let region = |keep: &dyn Fn(usize) -> bool| {
        let mask: Vec<bool> = (0..w * h).map(keep).collect();
        let mut values = collect(keep);
        json!({
            "misregistration_arcmin": stats(&mut values),
            "mean_abs_colour_error_8bit": colour_error(keep),
            "psnr_db": psnr(&srgb_t, &srgb_s, &mask),
            "ssim": mean_over(keep),
            "flip_mean": flip_mean(keep),
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
    let all = collect(&|i| display[i]);
    let mean_px = if all.is_empty() {
        f64::NAN
    } else {
        all.iter().sum::<f64>() / all.len() as f64 / driver_pixel_arcmin
    };
    let json = json!({
        "display_pixels": count,
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
        "sky_pixels_excluded": sky,
        "blank_display_fraction": if count == 0 { 0.0 } else { (0..w * h).filter(|&i| display[i] && seethru.object_id[i] == MISSING_ID).count() as f64 / count as f64 },
        "flip_pixels_per_degree": ppd,
        "notes": "misregistration: angle at the eye between the world point seethru shows and the truth's, over display pixels where both are surfaces; colour metrics on 8-bit sRGB; SSIM on luminance, 7×7 windows; FLIP (NVIDIA, via nv-flip) with the driver's camera as observer, averaged inside the masks",
    });
    let blank = (0..w * h)
        .map(|i| display[i] && seethru.object_id[i] == MISSING_ID)
        .collect();
    (
        MetricMaps {
            width: w as u32,
            height: h as u32,
            misregistration,
            missing,
            display,
            blank,
        },
        json,
    )
}
