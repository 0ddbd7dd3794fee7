//! The binocular mismatch of a display (`run --eyes both`): for each display pixel, the
//! vergence of the point shown — the pixel's centre on the display's surface, the flat face
//! or a curved display's point at the pixel's UV — minus the vergence the scene
//! point it shows has (the display frame's world point, what the frontal camera sees there;
//! a sky direction has vergence 0), for the true left and right eyes, in arc-minutes. And a
//! red–cyan anaglyph of the two `seethru` views.

use std::path::Path;

use anyhow::Result;
use exr::prelude::{AnyChannel, FlatSamples};
use glam::DVec3;
use serde_json::json;

use crate::analysis::binocular::{disparity_mismatch, disparity_mismatch_along, vergence};
use crate::analysis::physical::ARCMIN_PER_RAD;
use crate::io::atomic::write_text;
use crate::io::frame_files::{write_exr_channels, write_png};
use crate::measure::maps::heat_color;
use crate::render::frame::Frame;
use crate::scene::Obstacle;
use crate::system::display::MISSING_ID;
use crate::system::surface_map::display_points;
use crate::util::color::encode_srgb8;

/// The mismatch per display pixel, arc-minutes; NaN where the pixel shows nothing.
pub struct BinocularMap {
    pub width: u32,
    pub height: u32,
    pub mismatch_arcmin: Vec<f32>,
    /// Distance of the scene point each pixel shows from the display plane, metres (∞ for
    /// sky, NaN for missing).
    pub scene_depth: Vec<f32>,
}

/// The mismatch map of the display frame `display` for eyes at `left` and `right` (world).
pub fn binocular_map(
    display: &Frame,
    obstacle: &Obstacle,
    left: DVec3,
    right: DVec3,
) -> BinocularMap {
    assert_eq!(
        [display.width, display.height],
        obstacle.display_resolution,
        "a display frame of the obstacle's resolution"
    );
    // Each pixel's centre on the display's surface: the flat face, or a curved display's
    // point at the pixel's UV.
    let points = display_points(obstacle);
    let mut mismatch = Vec::with_capacity(display.color.len());
    let mut depth = Vec::with_capacity(display.color.len());
    for y in 0..display.height {
        for x in 0..display.width {
            let i = display.index(x, y);
            let point = points[(y * display.width + x) as usize];
            let Some(point) = point.filter(|_| display.object_id[i] != MISSING_ID) else {
                mismatch.push(f32::NAN);
                depth.push(f32::NAN);
                continue;
            };
            let on_display = vergence(left, right, point);
            let p = display.position[i];
            let (shown, d) = if p.is_finite() {
                let p = p.as_dvec3();
                (vergence(left, right, p), -obstacle.in_obstacle_frame(p).z)
            } else {
                (0.0, f64::INFINITY)
            };
            mismatch.push(((on_display - shown) * ARCMIN_PER_RAD) as f32);
            depth.push(d as f32);
        }
    }
    BinocularMap {
        width: display.width,
        height: display.height,
        mismatch_arcmin: mismatch,
        scene_depth: depth,
    }
}

fn percentile(sorted: &[f32], q: f64) -> Option<f32> {
    (!sorted.is_empty()).then(|| sorted[((sorted.len() - 1) as f64 * q).round() as usize])
}

/// Statistics of the map beside the closed form at the display centre
/// ([`disparity_mismatch`] with d1 of the cyclopean eye and d2 the median scene depth).
pub fn binocular_stats(
    map: &BinocularMap,
    obstacle: &Obstacle,
    left: DVec3,
    right: DVec3,
) -> serde_json::Value {
    let mut values: Vec<f32> = map
        .mismatch_arcmin
        .iter()
        .copied()
        .filter(|v| v.is_finite())
        .collect();
    values.sort_by(f32::total_cmp);
    let mut depths: Vec<f32> = map
        .scene_depth
        .iter()
        .copied()
        .filter(|v| !v.is_nan())
        .collect();
    depths.sort_by(f32::total_cmp);
    let total = map.mismatch_arcmin.len();
    let mean = values.iter().map(|&v| v as f64).sum::<f64>() / values.len().max(1) as f64;
    let ipd = (right - left).length();
    let d1 = obstacle.in_obstacle_frame((left + right) / 2.0).z;
    let median_d2 = percentile(&depths, 0.5).map(f64::from);
    // The cyclopean line of sight to the display centre.
    let centre = obstacle.world_from_obstacle.translation;
    let sight = (centre - (left + right) / 2.0).normalize();
    let normal = obstacle.normal();
    json!({
        "ipd_m": ipd,
        "d1_m": d1,
        "display_pixels": total,
        "measured_pixels": values.len(),
        "missing_pixels": total - values.len(),
        "mismatch_arcmin": {
            "mean": (!values.is_empty()).then_some(mean),
            "min": values.first(), "p5": percentile(&values, 0.05), "median": percentile(&values, 0.5),
            "p95": percentile(&values, 0.95), "max": values.last(),
        },
        "scene_depth_median_m": median_d2.map(|d| if d.is_finite() { json!(d) } else { json!("inf") }),
        "closed_form_arcmin": median_d2.map(|d2| disparity_mismatch(ipd, d1, d2) * ARCMIN_PER_RAD),
        "closed_form_off_axis_arcmin": median_d2.map(|d2| disparity_mismatch_along(right - left, sight, normal, d1, d2) * ARCMIN_PER_RAD),
        "display_centre_off_axis_deg": sight.angle_between(-normal).to_degrees(),
        "notes": "per display pixel: vergence (angle at the point between the two eyes) of the display point minus that of the scene point the pixel shows (sky: 0), arc-minutes; > 0: the display is seen nearer than what it shows. Missing pixels (outside the frontal view) are counted, not measured. closed_form: ipd (1/d1 − 1/(d1 + d2)) with d1 of the cyclopean eye and d2 the median scene depth shown, straight ahead; closed_form_off_axis: along the cyclopean line of sight to the display centre, |b⊥| cos α (1/d1 − 1/(d1 + d2)) with b⊥ the eyes' baseline across it and α its angle off the display normal (analysis/binocular.rs)",
    })
}

/// Red–cyan anaglyph: red from the left view, green and blue from the right (sRGB 8-bit).
pub fn anaglyph_rgb(left: &Frame, right: &Frame) -> Vec<u8> {
    left.color
        .iter()
        .zip(&right.color)
        .flat_map(|(&l, &r)| {
            let (l, r) = (encode_srgb8(l), encode_srgb8(r));
            [l[0], r[1], r[2]]
        })
        .collect()
}

/// The mismatch heatmap beside its colour bar: blue at the map's smallest value, red at its
/// largest, black where the pixel has no value.
fn mismatch_heatmap_rgb(map: &BinocularMap) -> Result<(u32, u32, Vec<u8>)> {
    let finite = map
        .mismatch_arcmin
        .iter()
        .copied()
        .filter(|v| v.is_finite());
    let (lo, hi) = finite.fold((f32::INFINITY, f32::NEG_INFINITY), |(a, b), v| {
        (a.min(v), b.max(v))
    });
    let span = (hi - lo).max(1e-6);
    let rgb: Vec<u8> = map
        .mismatch_arcmin
        .iter()
        .flat_map(|&v| {
            if v.is_finite() {
                heat_color((v - lo) / span)
            } else {
                [0, 0, 0]
            }
        })
        .collect();
    let bar = crate::io::colour_bar::ColourBar {
        colours: heat_color,
        // A map without a value (no display pixel seen by both eyes) has a scale of 0.
        bottom: if lo.is_finite() { lo as f64 } else { 0.0 },
        top: if hi.is_finite() { hi as f64 } else { 0.0 },
        unit: "′",
        title: "mismatch, arcmin (min to max)".into(),
        legend: vec![([0, 0, 0], "no value".into())],
        clipped: false,
    };
    crate::io::colour_bar::with_colour_bar(map.width, map.height, &rgb, &bar)
}

/// Writes `binocular.json`, `binocular.exr` (`Y`: mismatch, arcmin, NaN where missing),
/// `binocular.png` (heatmap, blue = smallest, red = largest of the map) and `anaglyph.png`.
pub fn write_binocular(
    dir: &Path,
    map: &BinocularMap,
    stats: &serde_json::Value,
    seethru: [&Frame; 2],
) -> Result<()> {
    write_text(
        &dir.join("binocular.json"),
        &serde_json::to_string_pretty(stats)?,
    )?;
    let channels = vec![
        AnyChannel::new("Y", FlatSamples::F32(map.mismatch_arcmin.clone())),
        AnyChannel::new("scene_depth.Z", FlatSamples::F32(map.scene_depth.clone())),
    ];
    write_exr_channels(&dir.join("binocular.exr"), map.width, map.height, channels)?;
    let (w, h, rgb) = mismatch_heatmap_rgb(map)?;
    write_png(&dir.join("binocular.png"), w, h, rgb)?;
    let [l, r] = seethru;
    write_png(
        &dir.join("anaglyph.png"),
        l.width,
        l.height,
        anaglyph_rgb(l, r),
    )
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::Vec3;

    #[test]
    fn anaglyph_takes_red_from_the_left_and_cyan_from_the_right() {
        let mut l = Frame::new(1, 1);
        let mut r = Frame::new(1, 1);
        l.color[0] = Vec3::new(1.0, 0.0, 0.0);
        r.color[0] = Vec3::new(0.0, 1.0, 1.0);
        assert_eq!(anaglyph_rgb(&l, &r), vec![255, 255, 255]);
        assert_eq!(anaglyph_rgb(&r, &l), vec![0, 0, 0]);
    }

    /// Five display pixels, one missing: mismatch 4, –, 1, 3, 2 arcmin over scene depths 2,
    /// –, 6, 4 m and sky.
    fn five_pixels() -> BinocularMap {
        BinocularMap {
            width: 5,
            height: 1,
            mismatch_arcmin: vec![4.0, f32::NAN, 1.0, 3.0, 2.0],
            scene_depth: vec![2.0, f32::NAN, 6.0, 4.0, f32::INFINITY],
        }
    }

    /// The statistics by hand: the missing pixel counted, the percentiles at the rounded
    /// rank (n − 1) q of the sorted values, the median depth, and the geometry of a cyclopean
    /// eye 0.6 m from a display centre at 30° off its normal.
    #[test]
    fn the_stats_count_rank_and_place_the_eyes() {
        let mut obstacle = crate::scene::Scene::bundled("das.toml").obstacle;
        let centre = DVec3::new(1.0, 2.0, 3.0);
        obstacle.world_from_obstacle = glam::DAffine3::from_translation(centre);
        let (sin, cos) = 30f64.to_radians().sin_cos();
        let cyclopean = centre + 0.6 * DVec3::new(sin, 0.0, cos);
        let half_ipd = DVec3::new(0.032, 0.0, 0.0);
        let stats = binocular_stats(
            &five_pixels(),
            &obstacle,
            cyclopean - half_ipd,
            cyclopean + half_ipd,
        );
        let number = |key: &str| stats.pointer(key).and_then(|v| v.as_f64()).unwrap();
        assert_eq!(number("/display_pixels"), 5.0);
        assert_eq!(number("/measured_pixels"), 4.0);
        assert_eq!(number("/missing_pixels"), 1.0);
        let m = "/mismatch_arcmin";
        assert_eq!(number(&format!("{m}/mean")), 2.5);
        // Ranks 0.15, 1.5 and 2.85 of [1, 2, 3, 4] round to 0, 2 and 3.
        for (key, want) in [
            ("min", 1.0),
            ("p5", 1.0),
            ("median", 3.0),
            ("p95", 4.0),
            ("max", 4.0),
        ] {
            assert_eq!(number(&format!("{m}/{key}")), want, "{key}");
        }
        // Depths [2, 4, 6, ∞]: rank 1.5 rounds to 2.
        assert_eq!(number("/scene_depth_median_m"), 6.0);
        assert!((number("/d1_m") - 0.6 * cos).abs() < 1e-12);
        assert!((number("/ipd_m") - 0.064).abs() < 1e-12);
        assert!((number("/display_centre_off_axis_deg") - 30.0).abs() < 1e-9);
    }

    /// Each pixel's colour: blue at the smallest value, red at the largest, the rest at
    /// their place between; black where missing.
    #[test]
    fn the_heatmap_spans_the_maps_smallest_to_largest_value() {
        let (w, h, rgb) = mismatch_heatmap_rgb(&five_pixels()).unwrap();
        assert!(w > 5 && h >= 1);
        let pixel = |x: usize| [rgb[3 * x], rgb[3 * x + 1], rgb[3 * x + 2]];
        let want = [heat_color(1.0), [0, 0, 0], heat_color(0.0)];
        assert_eq!([pixel(0), pixel(1), pixel(2)], want);
        assert_eq!(
            [pixel(3), pixel(4)],
            [heat_color(2.0 / 3.0), heat_color(1.0 / 3.0)]
        );
        assert_ne!(heat_color(1.0 / 3.0), heat_color(0.5));
    }
}
