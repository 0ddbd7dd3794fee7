//! Which pixels of a camera can see a world box: the footprint outside of which two views
//! that differ only by the primitives in that box are the same image.

use glam::{DVec2, DVec3};
use obvhs::aabb::Aabb;

use crate::geometry::camera::Camera;

/// A rectangle of whole pixels, `x0..x1` × `y0..y1` (half-open).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct PixelRect {
    pub x0: u32,
    pub y0: u32,
    pub x1: u32,
    pub y1: u32,
}

impl PixelRect {
    /// The rectangle grown on each side by its size / `divisor` plus `extra` pixels (each
    /// axis on its own), within the image of `camera`.
    pub fn grown(self, divisor: u32, extra: u32, camera: &Camera) -> PixelRect {
        let (gx, gy) = (
            (self.x1 - self.x0) / divisor + extra,
            (self.y1 - self.y0) / divisor + extra,
        );
        PixelRect {
            x0: self.x0.saturating_sub(gx),
            y0: self.y0.saturating_sub(gy),
            x1: (self.x1 + gx).min(camera.width),
            y1: (self.y1 + gy).min(camera.height),
        }
    }

    /// Every pixel of `camera`.
    pub fn full(camera: &Camera) -> PixelRect {
        PixelRect {
            x0: 0,
            y0: 0,
            x1: camera.width,
            y1: camera.height,
        }
    }

    pub fn is_empty(&self) -> bool {
        self.x0 >= self.x1 || self.y0 >= self.y1
    }

    pub fn pixels(&self) -> u64 {
        if self.is_empty() {
            0
        } else {
            u64::from(self.x1 - self.x0) * u64::from(self.y1 - self.y0)
        }
    }
}

/// Pixels of `camera` whose samples (anywhere in the pixel) can meet `bounds`: the bounding
/// rectangle of the box's projected corners, grown by a pixel on each side for the rounding
/// of f32 rays. The whole image when a corner is not in front of the camera.
pub fn footprint(camera: &Camera, bounds: &Aabb) -> PixelRect {
    let (lo, hi) = (bounds.min.as_dvec3(), bounds.max.as_dvec3());
    let mut min = DVec2::splat(f64::INFINITY);
    let mut max = DVec2::splat(f64::NEG_INFINITY);
    for corner in 0..8 {
        let pick = |bit: u32, l: f64, h: f64| if corner & bit == 0 { l } else { h };
        let p = DVec3::new(
            pick(1, lo.x, hi.x),
            pick(2, lo.y, hi.y),
            pick(4, lo.z, hi.z),
        );
        // A corner on or behind the eye's plane projects nowhere useful: take everything.
        let in_camera = camera.world_from_camera.inverse().transform_point3(p);
        if in_camera.z > -1e-6 {
            return PixelRect::full(camera);
        }
        let Some(q) = camera.project_camera(in_camera) else {
            return PixelRect::full(camera);
        };
        min = min.min(q);
        max = max.max(q);
    }
    let clamp_x = |v: f64| v.clamp(0.0, camera.width as f64) as u32;
    let clamp_y = |v: f64| v.clamp(0.0, camera.height as f64) as u32;
    PixelRect {
        x0: clamp_x(min.x.floor() - 1.0),
        y0: clamp_y(min.y.floor() - 1.0),
        x1: clamp_x(max.x.ceil() + 1.0),
        y1: clamp_y(max.y.ceil() + 1.0),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::Vec3A;

    fn camera() -> Camera {
        Camera::look_at(DVec3::ZERO, DVec3::NEG_Z, DVec3::Y, 0.7, 200, 100).unwrap()
    }

    #[test]
    fn a_box_ahead_covers_its_projection_and_a_margin() {
        let cam = camera();
        let b = Aabb::new(Vec3A::new(-0.1, -0.1, -2.1), Vec3A::new(0.1, 0.1, -1.9));
        let rect = footprint(&cam, &b);
        // Every ray through the rectangle's outside misses the box; every corner is inside.
        let near = cam.project_point(DVec3::new(0.1, 0.1, -1.9)).unwrap();
        assert!(f64::from(rect.x1) > near.x && f64::from(rect.y0) < near.y);
        assert!(
            rect.pixels() > 0 && rect.pixels() < 200 * 100 / 4,
            "{rect:?}"
        );
        for y in 0..cam.height {
            for x in 0..cam.width {
                let inside = (rect.x0..rect.x1).contains(&x) && (rect.y0..rect.y1).contains(&y);
                if inside {
                    continue;
                }
                for (dx, dy) in [(0.0, 0.0), (0.999, 0.0), (0.0, 0.999), (0.999, 0.999)] {
                    let (o, d) = cam.world_ray(DVec2::new(x as f64 + dx, y as f64 + dy));
                    // Slab test against the box.
                    let t = |l: f64, h: f64, o: f64, d: f64| {
                        let (a, b) = ((l - o) / d, (h - o) / d);
                        (a.min(b), a.max(b))
                    };
                    let (x0, x1) = t(-0.1, 0.1, o.x, d.x);
                    let (y0, y1) = t(-0.1, 0.1, o.y, d.y);
                    let (z0, z1) = t(-2.1, -1.9, o.z, d.z);
                    assert!(x0.max(y0).max(z0) > x1.min(y1).min(z1), "pixel {x},{y}");
                }
            }
        }
    }

    #[test]
    fn a_box_around_or_behind_the_eye_covers_everything() {
        let cam = camera();
        let around = Aabb::new(Vec3A::splat(-1.0), Vec3A::splat(1.0));
        assert_eq!(footprint(&cam, &around), PixelRect::full(&cam));
        let behind = Aabb::new(Vec3A::new(-1.0, -1.0, 1.0), Vec3A::new(1.0, 1.0, 2.0));
        assert_eq!(footprint(&cam, &behind), PixelRect::full(&cam));
    }
}
