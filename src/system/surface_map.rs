//! The planar compensation per display pixel, for a curved display (one that is not the
//! obstacle's flat face): the eye's ray through each display pixel's point on the surface meets
//! the model plane (z = −d2 in the obstacle frame, or d2 → ∞) and is projected into the
//! believed frontal camera ([`PointModel`]). On a flat display this is the crop's homography,
//! pixel by pixel (tested); the homography stays the fast path there.

use glam::DVec3;

use crate::render::frame::{Frame, Pixel};
use crate::scene::Obstacle;
use crate::scene::display_keys::pixel_uv;
use crate::system::display::{Filter, MISSING_ID, sample};
use crate::system::point_model::PointModel;

/// The world point of every display pixel's centre (row-major); `None` where a curved
/// display's UVs do not cover the pixel.
pub fn display_points(obstacle: &Obstacle) -> Vec<Option<DVec3>> {
    let [w, h] = obstacle.display_resolution;
    let size = [w, h];
    (0..h)
        .flat_map(|y| (0..w).map(move |x| (x, y)))
        .map(|(x, y)| {
            let uv = pixel_uv(x as f64 + 0.5, y as f64 + 0.5, size);
            let local = match obstacle.display_shape.curved() {
                None => Some(DVec3::new(
                    (uv.x - 0.5) * obstacle.width,
                    (0.5 - uv.y) * obstacle.height,
                    0.0,
                )),
                Some(surface) => surface.point_at_uv(uv),
            };
            local.map(|p| obstacle.world_from_obstacle.transform_point3(p))
        })
        .collect()
}

/// The display image of a curved display: every pixel's point through `model` into the
/// frontal frame. Returns it and the number of display pixels that show nothing (the model
/// point outside the frontal image or behind the camera, or the pixel outside the UVs).
pub fn curved_display(
    frontal: &Frame,
    obstacle: &Obstacle,
    model: &PointModel,
    filter: Filter,
) -> (Frame, usize) {
    use rayon::prelude::*;
    let points = display_points(obstacle);
    let pixels: Vec<Pixel> = points
        .par_iter()
        .map(|p| match p.and_then(|p| model.frontal_point(p)) {
            Some(f) => sample(frontal, f, filter),
            None => Pixel {
                object_id: MISSING_ID,
                ..Pixel::SKY
            },
        })
        .collect();
    let missing = pixels.iter().filter(|p| p.object_id == MISSING_ID).count();
    let [w, h] = obstacle.display_resolution;
    (Frame::from_pixels(w, h, &pixels), missing)
}
