//! Per-pixel reprojection with scene depth (`--method depth`): each display pixel's line of
//! sight from the eye is intersected with the scene as the depth sensor's image describes
//! it, and the frontal colour found there is shown.
//!
//! **Backward search**, not forward warping. Forward warping (splatting every frontal pixel
//! into the display with a z-buffer) leaves cracks where the surface is stretched and needs
//! a splat size; the search asks, for each display pixel, exactly the question the display
//! must answer, so every display pixel gets one answer, holes are found where they are (not
//! as gaps between splats), and the cost is per display pixel, independent of the frontal
//! resolution. Along the eye's ray the frontal image point is affine in inverse depth w (the
//! epipolar line, from the ray's near end to its vanishing point), so the search walks that
//! line in half-pixel steps of the sensor image, comparing the ray's w with the sensor's:
//! the first step where the ray passes behind the surface brackets the hit, solved exactly
//! inside the sensor pixel's cell (each sensor pixel a fronto-parallel tile at its depth).
//!
//! **Holes** (disocclusions): a crossing where the sensor's depth jumps nearer by more than
//! [`DISCONTINUITY`] between the two steps — or from no return to a return — means the ray
//! went behind a foreground silhouette: what it meets there the frontal camera does not see.
//! The background fill takes the farther surface just before the jump on the epipolar line.
//! A ray that meets nothing up to its vanishing point looks at infinity (sky, or past the
//! sensor's range: d2 → ∞); one that leaves the sensor's view first shows nothing.
//!
//! **Through a lens**: the sensor is a pinhole (`depth_sensor::sensor_camera`), so the walk
//! is along a straight line; only the point found is carried into the frontal image, through
//! the frontal camera's lens, and one outside the lens's domain is [`Found::BeyondLens`].

use glam::{DVec2, DVec3};

use crate::geometry::camera::Camera;
use crate::system::depth_sensor::DepthMap;

/// The sensor's inverse depth jumping by more than this factor between neighbouring steps
/// is a depth discontinuity (a silhouette), not a steep surface: 25 % in depth. A road seen
/// from 1.2 m by a 720-row, 45° camera changes this much per pixel only at about 190 m.
pub const DISCONTINUITY: f32 = 1.25;

/// Nearest depth the search considers, metres of axial depth (a depth sensor's minimum
/// range; the frontal camera's own housing is nearer).
pub const NEAREST: f64 = 0.1;

/// What a display pixel's line of sight finds, in frontal-camera pixel coordinates.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Found {
    /// A surface the sensor sees, or (nothing met before the vanishing point) a direction.
    Seen(DVec2),
    /// A disocclusion; the point is the nearest farther surface on the epipolar line.
    Hole(DVec2),
    /// The ray leaves the sensor's view before meeting anything.
    Outside,
    /// The point found is outside the frontal lens's domain
    /// ([`Camera::project_camera_in_domain`]): behind it, 89° or more off its axis, or past
    /// a fold of its distortion. A hole with no frontal pixel to fill it from.
    BeyondLens,
}

/// The search for one line of sight from `eye` through `on_display` (world).
pub fn search(map: &DepthMap, frontal: &Camera, eye: DVec3, on_display: DVec3) -> Found {
    let camera = &map.camera;
    // The sensor is a pinhole (its epipolar lines are straight, so the walk below is one
    // line); the frontal image is read through the frontal camera's own lens.
    let to_frontal = |p: DVec2| frontal.project_camera_in_domain(camera.camera_direction(p));
    let seen = |p: DVec2| to_frontal(p).map_or(Found::BeyondLens, Found::Seen);
    let hole = |p: DVec2| to_frontal(p).map_or(Found::BeyondLens, Found::Hole);
    let camera_from_world = camera.world_from_camera.inverse();
    let origin = camera_from_world.transform_point3(on_display);
    let dir = camera_from_world.transform_vector3(on_display - eye);
    let rate = -dir.z;
    if rate <= 1e-12 {
        // The ray does not go deeper: it looks at infinity (or behind the camera).
        return match camera.project_camera(dir) {
            Some(p) if inside(camera, p) => seen(p),
            _ => Found::Outside,
        };
    }
    // Nothing is nearer than the nearest return: the walk starts there (for a street scene
    // that skips most of the epipolar line's length, which lies at the nearest depths).
    // (A hair nearer, so that the first step is in front of the nearest surface itself.)
    let nearest_return = 0.999 / map.max_inverse_depth().max(1e-12) as f64;
    let start_depth = (-origin.z).max(NEAREST).max(nearest_return);
    let start = origin + dir * ((start_depth - -origin.z) / rate);
    let (Some(near), Some(far)) = (camera.project_camera(start), camera.project_camera(dir)) else {
        return Found::Outside;
    };
    let w_start = 1.0 / start_depth;
    // pixel(s) = far + (near − far)·s, s = w / w_start ∈ [0, 1].
    let at = |s: f64| far + (near - far) * s;
    let Some((s_lo, s_hi)) = clip(near, far, camera) else {
        return Found::Outside;
    };
    let length = (near - far).length() * (s_hi - s_lo);
    let steps = (2.0 * length).ceil().max(1.0) as usize;
    let tap = |p: DVec2| {
        let x = (p.x.max(0.0) as u32).min(camera.width - 1);
        let y = (p.y.max(0.0) as u32).min(camera.height - 1);
        ((x, y), map.at(x, y))
    };
    let mut previous: Option<(f64, (u32, u32), f32)> = None;
    for k in 0..=steps {
        let s = s_hi - (s_hi - s_lo) * k as f64 / steps as f64;
        let (cell, w_map) = tap(at(s));
        let w_ray = s * w_start;
        if w_ray > w_map as f64 {
            previous = Some((s, cell, w_map));
            continue;
        }
        // The ray is at or behind the surface of this cell.
        let Some((s_prev, prev_cell, w_prev)) = previous else {
            // Behind a surface from where it enters the view: nothing known in front.
            return hole(at(s));
        };
        if prev_cell != cell && w_map > DISCONTINUITY * w_prev {
            return hole(at(s_prev));
        }
        let s_hit = (w_map as f64 / w_start).clamp(s, s_prev);
        return seen(at(s_hit));
    }
    if s_lo == 0.0 {
        seen(far)
    } else {
        Found::Outside
    }
}

fn inside(camera: &Camera, p: DVec2) -> bool {
    p.x >= 0.0 && p.y >= 0.0 && p.x < camera.width as f64 && p.y < camera.height as f64
}

/// The part `[s_lo, s_hi]` of the segment far + (near − far)·s, s ∈ [0, 1], inside the image
/// (Liang–Barsky), shrunk by a hair so that its ends map to pixels; `None` when it misses.
fn clip(near: DVec2, far: DVec2, camera: &Camera) -> Option<(f64, f64)> {
    let d = near - far;
    let (mut lo, mut hi) = (0.0f64, 1.0f64);
    let eps = 1e-9;
    let limits = [
        (-d.x, far.x - eps),
        (d.x, camera.width as f64 - eps - far.x),
        (-d.y, far.y - eps),
        (d.y, camera.height as f64 - eps - far.y),
    ];
    for (p, q) in limits {
        if p == 0.0 {
            if q < 0.0 {
                return None;
            }
        } else {
            let r = q / p;
            if p < 0.0 {
                lo = lo.max(r);
            } else {
                hi = hi.min(r);
            }
        }
    }
    (lo <= hi).then_some((lo, hi))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::system::depth_sensor::{SensorKind, SensorModel};

    /// A sensor looking down −z at a wall at depth 5 m with a square at 2 m in its middle.
    fn wall_with_square() -> (DepthMap, Camera) {
        let camera = Camera::look_at(DVec3::ZERO, -DVec3::Z, DVec3::Y, 0.6, 120, 90).unwrap();
        let mut inverse_depth = vec![0.2f32; 120 * 90];
        for y in 35..55 {
            for x in 50..70 {
                inverse_depth[y * 120 + x] = 0.5;
            }
        }
        let model = SensorModel {
            kind: SensorKind::Ideal,
            width: 120,
            height: 90,
            range_m: f64::INFINITY,
            noise_1m: 0.0,
            quantum_1m: 0.0,
        };
        (DepthMap::new(camera, inverse_depth, model), camera)
    }

    #[test]
    fn a_ray_finds_the_wall_where_it_meets_it() {
        let (map, camera) = wall_with_square();
        let eye = DVec3::new(0.3, 0.1, 0.7);
        let on_display = DVec3::new(0.1, 0.05, 0.0);
        let hit = eye + (on_display - eye) * ((5.0 + 0.7) / 0.7);
        let Found::Seen(p) = search(&map, &camera, eye, on_display) else {
            panic!("no hit");
        };
        let expected = camera.project_point(hit).unwrap();
        assert!((p - expected).length() < 1e-6, "{p} vs {expected}");
    }

    #[test]
    fn a_ray_behind_the_square_s_silhouette_is_a_hole() {
        // The camera at the origin sees the square hide the wall for |x| ≤ 0.57 m (at 5 m).
        // The eye, 1 m to the right, sees the middle of that part of the wall past the
        // square's right edge: a hole. A wall point the camera sees is found.
        let (map, camera) = wall_with_square();
        let eye = DVec3::new(1.0, 0.0, 0.7);
        let through = |target: DVec3| eye + (target - eye) * (0.7 / 5.7);
        let found = search(&map, &camera, eye, through(DVec3::new(0.0, 0.0, -5.0)));
        assert!(matches!(found, Found::Hole(_)), "{found:?}");
        let target = DVec3::new(1.5, 0.2, -5.0);
        let Found::Seen(p) = search(&map, &camera, eye, through(target)) else {
            panic!("the wall beside the square is seen");
        };
        assert!((p - camera.project_point(target).unwrap()).length() < 1e-6);
    }
}
