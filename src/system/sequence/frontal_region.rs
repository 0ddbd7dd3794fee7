//! The frontal pixels a refresh renders: those the crop (or a curved display's planar model)
//! reads, with the filters' margin, within the image. Apart from the loop
//! (system/sequence/system_loop.rs), which renders them: the region is plain geometry, tested
//! on its own.

use anyhow::Result;
use glam::{DVec2, DVec3};

use crate::geometry::camera::Camera;
use crate::render::footprint::PixelRect;
use crate::scene::Scene;
use crate::system::compensation::ModelPlane;
use crate::system::frontal_map::FrontalMap;
use crate::system::point_model::PointModel;
use crate::system::surface_map::display_points;

/// Frontal pixels rendered around the crop: the bicubic filter reads two beyond it.
const CROP_MARGIN_PX: f64 = 3.0;

/// The frontal pixels a crop reads, with a margin for the filters, within the image.
pub(crate) fn crop_rect(map: &FrontalMap, camera: &Camera) -> PixelRect {
    let (min, max) = map.bounds();
    rect_around(min, max, camera)
}

/// The frontal pixels a curved display's planar model reads (every display pixel's model
/// point for the eye at `eye`, world, and the model plane at `d2`), with a margin for the
/// filters, within the image; empty when the camera sees none of them.
pub(crate) fn curved_rect(
    scene: &Scene,
    eye: DVec3,
    d2: Option<f64>,
    camera: &Camera,
) -> Result<PixelRect> {
    let plane = d2.map_or(ModelPlane::Infinity, ModelPlane::At);
    let model = PointModel::new(scene, eye, plane)?;
    let (min, max) = display_points(&scene.obstacle)
        .into_iter()
        .flatten()
        .filter_map(|p| model.frontal_point(p))
        .filter(|p| p.is_finite())
        .fold(
            (DVec2::splat(f64::INFINITY), DVec2::splat(f64::NEG_INFINITY)),
            |(lo, hi), p| (lo.min(p), hi.max(p)),
        );
    if min.x > max.x {
        return Ok(PixelRect {
            x0: 0,
            y0: 0,
            x1: 0,
            y1: 0,
        });
    }
    Ok(rect_around(min, max, camera))
}

/// The pixels of `camera` from `min` to `max` (continuous), with the filters' margin.
fn rect_around(min: DVec2, max: DVec2, camera: &Camera) -> PixelRect {
    let lo = (min - DVec2::splat(CROP_MARGIN_PX)).floor();
    let hi = (max + DVec2::splat(CROP_MARGIN_PX)).ceil();
    let clamp = |v: f64, size: u32| v.clamp(0.0, size as f64) as u32;
    PixelRect {
        x0: clamp(lo.x, camera.width),
        y0: clamp(lo.y, camera.height),
        x1: clamp(hi.x, camera.width),
        y1: clamp(hi.y, camera.height),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The pixels from `min` to `max` with the filters' 3 pixels on each side, whole pixels
    /// outwards, clamped to the image.
    #[test]
    fn a_rect_around_points_holds_the_filters_margin_within_the_image() {
        let camera = Camera::new(glam::DAffine3::IDENTITY, 0.5, 640, 480).unwrap();
        let rect = rect_around(DVec2::new(10.2, 20.7), DVec2::new(30.1, 40.0), &camera);
        assert_eq!((rect.x0, rect.y0, rect.x1, rect.y1), (7, 17, 34, 43));
        let rect = rect_around(DVec2::new(-5.0, 2.5), DVec2::new(700.0, 477.5), &camera);
        assert_eq!((rect.x0, rect.y0, rect.x1, rect.y1), (0, 0, 640, 480));
    }
}
