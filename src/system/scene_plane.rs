//! Planar scene models that need not face the display: the known road plane (`ground`) and a
//! plane fitted to the depth sensor's points (`plane-fit`), tilted freely. Each display point
//! shows what the frontal camera sees towards the point where the eye's ray through it meets
//! the plane; a ray that never meets the plane beyond the display (above the horizon, for the
//! ground) falls back to d2 → ∞: its direction.

use anyhow::{Result, bail};
use glam::{DVec2, DVec3};

use crate::geometry::camera::Camera;
use crate::scene::{Scene, Shape};
use crate::system::depth_sensor::DepthMap;
use crate::util::sampling::hash_words;

/// The plane `normal · p = offset`, world frame (`normal` a unit vector, `offset` metres).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ScenePlane {
    pub normal: DVec3,
    pub offset: f64,
}

impl ScenePlane {
    /// Where the frontal camera must look for the display point `on_display` (world) seen
    /// from `eye`: the eye's ray meets the plane beyond the display, or (never meeting it)
    /// its direction at infinity. Pixel coordinates through the frontal camera's lens;
    /// `None` behind the camera or outside its lens's domain
    /// ([`Camera::project_camera_in_domain`]).
    pub fn frontal_point(&self, eye: DVec3, on_display: DVec3, frontal: &Camera) -> Option<DVec2> {
        let dir = on_display - eye;
        let along = self.normal.dot(dir);
        let t = (self.offset - self.normal.dot(eye)) / along;
        if t.is_finite() && t > 1.0 {
            frontal.project_point_in_domain(eye + dir * t)
        } else {
            frontal.project_direction_in_domain(dir)
        }
    }

    /// The angle between the plane's normal and the world's +y, degrees.
    pub fn tilt_from_horizontal_deg(&self) -> f64 {
        self.normal.dot(DVec3::Y).abs().min(1.0).acos().to_degrees()
    }
}

/// The road: the highest `kind = "plane"` object that lies below the frontal camera (plane
/// objects are horizontal rectangles in their own frame; a turned one counts if its normal is
/// within 10° of vertical). Unbounded: the model is the plane, not the rectangle.
pub fn ground_plane(scene: &Scene) -> Result<ScenePlane> {
    let camera = scene.frontal.position();
    let best = scene
        .objects
        .iter()
        .filter(|o| matches!(o.shape, Shape::Plane { .. }))
        .map(|o| {
            let normal = o.world_from_object.matrix3.y_axis.normalize();
            let normal = if normal.y < 0.0 { -normal } else { normal };
            let point = o.world_from_object.translation;
            ScenePlane {
                normal,
                offset: normal.dot(point),
            }
        })
        .filter(|p| p.normal.y >= 10f64.to_radians().cos() && p.normal.dot(camera) > p.offset)
        .max_by(|a, b| a.offset.total_cmp(&b.offset));
    match best {
        Some(p) => Ok(p),
        None => bail!(
            "option `method` ground: the scene {} has no ground plane (an [[object]] of kind = \"plane\", horizontal within 10°, below the frontal camera)",
            scene.path.display()
        ),
    }
}

/// RANSAC hypotheses drawn for a plane fit.
const RANSAC_ROUNDS: u32 = 256;

/// A plane fitted to the sensor's points inside the sensor-pixel rectangle `[min, max)`:
/// RANSAC over triples (seeded, so deterministic) and a least-squares refit on the inliers.
/// Over a plane not through the camera, inverse depth is affine in the camera's tangent-plane
/// coordinates (u, v): w = αu + βv + γ. The fit is linear in (α, β, γ), and its residual,
/// divided by w, is the relative depth error; a point is an inlier within 2 % of its depth
/// plus three σ of the sensor's noise there.
pub fn fit_plane(map: &DepthMap, min: DVec2, max: DVec2, seed: u32) -> Result<(ScenePlane, usize)> {
    let camera = &map.camera;
    let x0 = min.x.floor().max(0.0) as u32;
    let y0 = min.y.floor().max(0.0) as u32;
    let x1 = (max.x.ceil().max(0.0) as u32).min(camera.width);
    let y1 = (max.y.ceil().max(0.0) as u32).min(camera.height);
    // (u, v, w) of every return in the rectangle.
    let mut points: Vec<[f64; 3]> = Vec::new();
    for y in y0..y1 {
        for x in x0..x1 {
            let w = map.at(x, y) as f64;
            if w > 0.0 {
                let d = camera.camera_direction(DVec2::new(x as f64 + 0.5, y as f64 + 0.5));
                points.push([d.x, d.y, w]);
            }
        }
    }
    if points.len() < 3 {
        bail!(
            "option `method` plane-fit: the depth sensor has {} returns where the display is; at least 3 are needed (is it all sky or past option `depth_range`?)",
            points.len()
        );
    }
    let tolerance = |w: f64| 0.02 + 3.0 * map.model.sigma(1.0 / w) * w;
    let inliers = |abc: [f64; 3]| {
        points
            .iter()
            .filter(|p| {
                ((abc[0] * p[0] + abc[1] * p[1] + abc[2] - p[2]) / p[2]).abs() <= tolerance(p[2])
            })
            .count()
    };
    let n = points.len() as u32;
    let mut best: Option<([f64; 3], usize)> = None;
    for round in 0..RANSAC_ROUNDS {
        let pick = |k: u32| points[(hash_words(&[seed, round, k]) % n) as usize];
        let Some(abc) = least_squares(&[pick(0), pick(1), pick(2)], false) else {
            continue;
        };
        let count = inliers(abc);
        if best.is_none_or(|(_, c)| count > c) {
            best = Some((abc, count));
        }
    }
    let Some((mut abc, _)) = best else {
        bail!(
            "option `method` plane-fit: the depth sensor's points where the display is lie on a line"
        );
    };
    // Refit on the inliers, twice (the second round with the refined plane's inliers).
    let mut count = 0;
    for _ in 0..2 {
        let chosen: Vec<[f64; 3]> = points
            .iter()
            .copied()
            .filter(|p| {
                ((abc[0] * p[0] + abc[1] * p[1] + abc[2] - p[2]) / p[2]).abs() <= tolerance(p[2])
            })
            .collect();
        count = chosen.len();
        if let Some(refit) = least_squares(&chosen, true) {
            abc = refit;
        }
    }
    // 1 = αx + βy + γ·depth over camera-frame points (x, y, z) with depth = −z.
    let n_camera = DVec3::new(abc[0], abc[1], -abc[2]);
    let normal_world = camera.world_from_camera.matrix3 * n_camera;
    let scale = normal_world.length();
    if !(scale > 0.0 && scale.is_finite()) {
        bail!("option `method` plane-fit: the fitted plane passes through the camera");
    }
    let offset = 1.0 + normal_world.dot(camera.position());
    Ok((
        ScenePlane {
            normal: normal_world / scale,
            offset: offset / scale,
        },
        count,
    ))
}

/// Least-squares (α, β, γ) of w = αu + βv + γ over points (u, v, w), each residual weighted
/// by 1/w when `relative` (so that it is a relative depth error); `None` when degenerate.
fn least_squares(points: &[[f64; 3]], relative: bool) -> Option<[f64; 3]> {
    let mut m = [[0.0f64; 3]; 3];
    let mut r = [0.0f64; 3];
    for p in points {
        let weight = if relative { 1.0 / (p[2] * p[2]) } else { 1.0 };
        let row = [p[0], p[1], 1.0];
        for i in 0..3 {
            for j in 0..3 {
                m[i][j] += weight * row[i] * row[j];
            }
            r[i] += weight * row[i] * p[2];
        }
    }
    let m = glam::DMat3::from_cols_array_2d(&m).transpose();
    let det = m.determinant();
    let scale = m.x_axis.length() * m.y_axis.length() * m.z_axis.length();
    if det.is_nan() || det.abs() <= 1e-12 * scale {
        return None;
    }
    let x = m.inverse() * DVec3::from_array(r);
    x.is_finite().then(|| x.to_array())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn least_squares_recovers_an_affine_inverse_depth() {
        let points: Vec<[f64; 3]> = (0..20)
            .map(|i| {
                let (u, v) = (i as f64 * 0.05 - 0.5, ((i * 7) % 11) as f64 * 0.04 - 0.2);
                [u, v, 0.3 * u - 0.1 * v + 0.2]
            })
            .collect();
        let abc = least_squares(&points, true).unwrap();
        assert!((abc[0] - 0.3).abs() < 1e-9 && (abc[1] + 0.1).abs() < 1e-9);
        assert!((abc[2] - 0.2).abs() < 1e-9);
        // Three points on a line are degenerate.
        assert!(
            least_squares(&[[0.0, 0.0, 1.0], [1.0, 1.0, 1.0], [2.0, 2.0, 1.0]], false).is_none()
        );
    }

    #[test]
    fn a_ray_that_never_meets_the_plane_looks_at_infinity() {
        let frontal = Camera::look_at(DVec3::ZERO, -DVec3::Z, DVec3::Y, 0.7, 64, 48).unwrap();
        let ground = ScenePlane {
            normal: DVec3::Y,
            offset: -1.2,
        };
        let eye = DVec3::new(0.0, 0.0, 0.7);
        // Upwards: the direction's vanishing point.
        let up = DVec3::new(0.0, 0.1, 0.0);
        let p = ground.frontal_point(eye, up, &frontal).unwrap();
        let q = frontal.project_direction(up - eye).unwrap();
        assert!((p - q).length() < 1e-9);
        // Downwards: the ground point, which the frontal camera sees lower than the direction.
        let down = DVec3::new(0.0, -0.1, 0.0);
        let p = ground.frontal_point(eye, down, &frontal).unwrap();
        let hit = eye + (down - eye) * ((-1.2 - eye.y) / (down.y - eye.y));
        assert!((p - frontal.project_point(hit).unwrap()).length() < 1e-9);
        assert!((ground.tilt_from_horizontal_deg()).abs() < 1e-9);
    }

    /// The ground's frontal point through a lens, against its brute-force twin: the ray the
    /// lens sees at that pixel (pixel → ray, Newton's inverse) cast to the plane meets the eye's
    /// ray there (or, above the horizon, runs parallel to it). A projection that skipped the
    /// distortion would miss by many pixels' worth of rays.
    #[test]
    fn the_frontal_point_through_a_lens_is_where_the_lens_sees_the_eye_s_ground_point() {
        use crate::geometry::lens::{Distortion, Lens};
        let pose = Camera::look_at(
            DVec3::ZERO,
            DVec3::new(0.2, -0.1, -1.0),
            DVec3::Y,
            0.7,
            1,
            1,
        )
        .unwrap()
        .world_from_camera;
        let fisheye = Lens {
            fx: 200.0,
            fy: 200.0,
            cx: 255.5,
            cy: 143.5,
            distortion: Distortion::Fisheye {
                k1: -0.012,
                k2: 0.003,
                k3: -0.0005,
                k4: 0.0,
            },
        };
        let brown = Lens {
            fx: 260.0,
            fy: 255.0,
            cx: 250.0,
            cy: 150.0,
            distortion: Distortion::Brown {
                k1: -0.1,
                k2: 0.01,
                k3: 0.0,
                p1: 0.001,
                p2: -0.0005,
            },
        };
        let ground = ScenePlane {
            normal: DVec3::Y,
            offset: -1.2,
        };
        let eye = DVec3::new(0.3, 0.0, 0.7);
        for lens in [fisheye, brown] {
            let frontal = Camera::with_lens(pose, lens, 512, 288).unwrap();
            let mut checked = [0, 0];
            for i in 0..15 {
                for j in 0..15 {
                    // A display 0.8 m ahead of the eye, 0.6 × 0.6 m: rays below and above
                    // the horizon.
                    let on_display =
                        DVec3::new(-0.3 + 0.04 * i as f64, -0.3 + 0.04 * j as f64, -0.1);
                    let Some(pixel) = ground.frontal_point(eye, on_display, &frontal) else {
                        continue;
                    };
                    let (origin, dir) = frontal.world_ray(pixel);
                    let sight = (on_display - eye).normalize();
                    let t_eye = (ground.offset - eye.y) / sight.y;
                    if sight.y < 0.0 && t_eye > (on_display - eye).length() {
                        let hit = eye + sight * t_eye;
                        let t = (ground.offset - origin.y) / dir.y;
                        let error = (origin + dir * t - hit).length() / hit.length();
                        assert!(error < 1e-9, "{lens:?} {on_display}: {error}");
                        checked[0] += 1;
                    } else {
                        // |a × b| for unit vectors: exact at small angles (acos loses half the digits).
                        let angle = dir.cross(sight).length();
                        assert!(
                            dir.dot(sight) > 0.0 && angle < 1e-9,
                            "{lens:?} {on_display}: {angle}"
                        );
                        checked[1] += 1;
                    }
                }
            }
            assert!(checked[0] > 50 && checked[1] > 10, "{checked:?}");
        }
    }
}
