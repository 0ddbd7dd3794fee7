//! Disocclusion holes of `--method depth` in the driver's view: their fraction and mask, and
//! the metrics over the pixels the display shows from what the frontal camera saw ("seen")
//! apart from those over the holes it filled ("filled"), so that a fill cannot pass for a
//! measurement.

use std::path::Path;

use anyhow::Result;
use serde_json::json;

use crate::measure::image_metrics::psnr;
use crate::measure::maps::write_mask_png;
use crate::measure::metrics::MetricMaps;
use crate::measure::metrics_json::{Metrics, Stats};
use crate::render::frame::Frame;
use crate::render::frame_over::FrameView;
use crate::scene::Obstacle;
use crate::system::display::MISSING_ID;
use crate::util::color::encode_srgb8;

/// The driver-view mask of pixels whose display pixel is a hole: each display-region pixel
/// of the driver's view is mapped to the display pixel it sees (through the `occluded`
/// frame's point on the display face), as the metrics map it.
pub fn driver_hole_mask(
    obstacle: &Obstacle,
    occluded: &Frame,
    maps: &MetricMaps,
    display_holes: &[bool],
) -> Vec<bool> {
    let [dw, dh] = obstacle.display_resolution;
    let obstacle_from_world = obstacle.world_from_obstacle.inverse();
    (0..maps.display.len())
        .map(|i| {
            if !maps.display[i] {
                return false;
            }
            let p = obstacle_from_world.transform_point3(occluded.position[i].as_dvec3());
            let u = ((p.x / obstacle.width + 0.5) * dw as f64).floor();
            let v = ((0.5 - p.y / obstacle.height) * dh as f64).floor();
            let (u, v) = (
                (u.max(0.0) as u32).min(dw - 1),
                (v.max(0.0) as u32).min(dh - 1),
            );
            display_holes[(v * dw + u) as usize]
        })
        .collect()
}

/// `metrics.json`'s `holes`: the fraction of display pixels of the driver's view that are
/// holes, and the metrics over seen and over filled (hole) pixels apart.
pub fn hole_metrics(
    holes: &[bool],
    maps: &MetricMaps,
    truth: &Frame,
    seethru: &Frame,
    fill: impl serde::Serialize,
) -> serde_json::Value {
    let n = maps.display.len();
    let display = maps.display.iter().filter(|&&d| d).count();
    let hole_count = holes.iter().filter(|&&h| h).count();
    let srgb_t: Vec<[u8; 3]> = truth.color.iter().map(|&c| encode_srgb8(c)).collect();
    let srgb_s: Vec<[u8; 3]> = seethru.color.iter().map(|&c| encode_srgb8(c)).collect();
    let region = |keep: &dyn Fn(usize) -> bool| {
        let mask: Vec<bool> = (0..n).map(|i| maps.display[i] && keep(i)).collect();
        let pixels = mask.iter().filter(|&&m| m).count();
        let blank = (0..n)
            .filter(|&i| mask[i] && seethru.object_id[i] == MISSING_ID)
            .count();
        let mut values: Vec<f64> = (0..n)
            .filter(|&i| mask[i] && maps.misregistration[i].is_finite())
            .map(|i| maps.misregistration[i] as f64)
            .collect();
        let mean_over = |map: &[f64]| {
            let v: Vec<f64> = (0..n).filter(|&i| mask[i]).map(|i| map[i]).collect();
            if v.is_empty() {
                f64::NAN
            } else {
                v.iter().sum::<f64>() / v.len() as f64
            }
        };
        json!({
            "pixels": pixels,
            "coverage": if pixels == 0 { f64::NAN } else { 1.0 - blank as f64 / pixels as f64 },
            "misregistration_arcmin": Stats::of(&mut values),
            "psnr_db": psnr(&srgb_t, &srgb_s, &mask),
            "ssim": mean_over(&maps.ssim),
            "flip_mean": mean_over(&maps.flip),
        })
    };
    json!({
        "fraction": if display == 0 { 0.0 } else { hole_count as f64 / display as f64 },
        "pixels": hole_count,
        "fill": fill,
        "seen": region(&|i| !holes[i]),
        "filled": region(&|i| holes[i]),
        "notes": "holes: display pixels whose line of sight passes behind a silhouette of the depth sensor's image (a disocclusion: what the eye sees there the frontal camera does not); seen: the other display pixels; filled: the holes as `fill` shows them (none: black, counted blank). The totals in `display` include both",
    })
}

/// `holes.png`: holes magenta, the rest of the display dark grey, outside black.
pub fn write_hole_mask(path: &Path, maps: &MetricMaps, holes: &[bool]) -> Result<()> {
    write_mask_png(path, maps, holes)
}

/// The `holes` metrics of a run's display holes seen in its `truth`, `occluded` and `seethru`
/// views, attached to `metrics`; the driver-view hole mask, if the run has holes.
pub fn attach_view_holes(
    metrics: &mut Metrics,
    maps: &MetricMaps,
    display_holes: Option<&[bool]>,
    [truth, occluded, seethru]: [FrameView<'_>; 3],
    obstacle: &Obstacle,
    fill: impl serde::Serialize,
) -> Option<Vec<bool>> {
    let display_holes = display_holes?;
    // Only a run with holes (`--method depth`) reads the whole frames.
    let [truth, occluded, seethru] = [truth, occluded, seethru].map(FrameView::whole);
    let mask = driver_hole_mask(obstacle, occluded, maps, display_holes);
    metrics.holes = Some(hole_metrics(&mask, maps, truth, seethru, fill));
    Some(mask)
}

/// The driver-view hole mask of a run directory's `holes.png` (magenta pixels), if it has
/// one, for `seethru measure`; it must be `width`×`height`.
pub fn read_hole_mask(path: &Path, width: u32, height: u32) -> Result<Option<Vec<bool>>> {
    if !path.exists() {
        return Ok(None);
    }
    let image = image::open(path)
        .map_err(|e| anyhow::anyhow!("{}: {e}", path.display()))?
        .to_rgb8();
    if image.dimensions() != (width, height) {
        anyhow::bail!(
            "{}: {}×{} pixels, the run's views are {width}×{height}",
            path.display(),
            image.width(),
            image.height()
        );
    }
    Ok(Some(image.pixels().map(|p| p.0 == [255, 0, 255]).collect()))
}

#[cfg(test)]
mod tests {
    use glam::{DAffine3, DVec3, Vec3};

    use super::*;
    use crate::scene::display_surface::DisplayShape;

    /// A driver-view pixel that sees the display's edge (a float's rounding from outside it)
    /// belongs to the edge column or row, not to the next row's first pixel or past the end.
    #[test]
    fn hole_mask_maps_edge_points_to_the_edge_pixels() {
        let (dw, dh) = (4, 3);
        let obstacle = Obstacle {
            world_from_obstacle: DAffine3::from_translation(DVec3::new(1.0, 2.0, -3.0)),
            width: 0.4,
            height: 0.3,
            thickness: 0.01,
            display_resolution: [dw, dh],
            display_off_color: [0.0; 3],
            body_color: [0.2; 3],
            display_shape: DisplayShape::Flat,
            scanout: crate::geometry::shutter::Scanout::default(),
            display_light: None,
        };
        // Driver-view pixels at the display's top-right, bottom-right and top-left corners,
        // a hair outside (as float rounding puts them), in world coordinates.
        let at = |x: f64, y: f64| {
            let p = obstacle
                .world_from_obstacle
                .transform_point3(DVec3::new(x, y, 0.0));
            p.as_vec3()
        };
        let e = 1e-5;
        let positions = [
            at(0.2 + e, 0.15 + e),
            at(0.2 + e, -0.15 - e),
            at(-0.2 - e, 0.15 + e),
        ];
        let mut occluded = Frame::new(positions.len() as u32, 1);
        occluded.position = positions.to_vec();
        let n = positions.len();
        let maps = MetricMaps {
            width: n as u32,
            height: 1,
            misregistration: vec![0.0; n],
            missing: vec![false; n],
            display: vec![true; n],
            blank: vec![false; n],
            ssim: vec![1.0; n],
            flip: vec![0.0; n],
        };
        let pixel = |u: u32, v: u32| (v * dw + u) as usize;
        // Only the right column's top and bottom pixels are holes.
        let mut holes = vec![false; (dw * dh) as usize];
        holes[pixel(dw - 1, 0)] = true;
        holes[pixel(dw - 1, dh - 1)] = true;
        assert_eq!(
            driver_hole_mask(&obstacle, &occluded, &maps, &holes),
            [true, true, false]
        );
        // The top-left corner's pixel, alone a hole.
        let mut holes = vec![false; (dw * dh) as usize];
        holes[pixel(0, 0)] = true;
        assert_eq!(
            driver_hole_mask(&obstacle, &occluded, &maps, &holes),
            [false, false, true]
        );
    }

    /// `holes` in metrics.json: each figure of the seen and filled parts against sums done
    /// by hand on six pixels (one outside the display, one filled hole left blank).
    #[test]
    fn hole_metrics_split_the_display_into_seen_and_filled() {
        let n = 6;
        let display = [true, true, true, true, true, false];
        let holes = [false, false, true, true, false, false];
        let maps = MetricMaps {
            width: n as u32,
            height: 1,
            misregistration: vec![1.0, 3.0, 7.0, f32::NAN, 5.0, f32::NAN],
            missing: vec![false; n],
            display: display.to_vec(),
            blank: vec![false, false, false, true, false, false],
            ssim: vec![0.9, 0.7, 0.5, 0.1, 0.8, f64::NAN],
            flip: vec![0.1, 0.3, 0.2, 0.6, 0.5, f64::NAN],
        };
        let mut truth = Frame::new(n as u32, 1);
        truth.color = vec![Vec3::ONE; n];
        let mut seethru = truth.clone();
        // One seen pixel and one filled one black where the truth is white.
        seethru.color[4] = Vec3::ZERO;
        seethru.color[2] = Vec3::ZERO;
        seethru.object_id[3] = MISSING_ID;
        let m = hole_metrics(&holes, &maps, &truth, &seethru, "none");
        let close = |v: &serde_json::Value, expected: f64| {
            let v = v.as_f64().expect("a number");
            assert!(
                (v - expected).abs() <= 1e-12 * expected.abs(),
                "{v} against {expected}"
            );
        };
        close(&m["fraction"], 2.0 / 5.0);
        assert_eq!(m["pixels"], 2);
        let (seen, filled) = (&m["seen"], &m["filled"]);
        assert_eq!(seen["pixels"], 3);
        close(&seen["coverage"], 1.0);
        assert_eq!(seen["misregistration_arcmin"]["count"], 3);
        close(&seen["misregistration_arcmin"]["mean"], 3.0);
        close(&seen["misregistration_arcmin"]["max"], 5.0);
        // One of three pixels off by 255 in each channel: MSE 255²/3.
        close(&seen["psnr_db"], 10.0 * 3f64.log10());
        close(&seen["ssim"], (0.9 + 0.7 + 0.8) / 3.0);
        close(&seen["flip_mean"], (0.1 + 0.3 + 0.5) / 3.0);
        assert_eq!(filled["pixels"], 2);
        close(&filled["coverage"], 0.5);
        assert_eq!(filled["misregistration_arcmin"]["count"], 1);
        close(&filled["misregistration_arcmin"]["mean"], 7.0);
        close(&filled["psnr_db"], 10.0 * 2f64.log10());
        close(&filled["ssim"], (0.5 + 0.1) / 2.0);
        close(&filled["flip_mean"], (0.2 + 0.6) / 2.0);
        assert_eq!(m["fill"], "none");
    }
}
