//! Lens models in OpenCV's conventions: pinhole intrinsics (fx, fy, cx, cy in pixels) with
//! Brown–Conrady (`cv::projectPoints`: k1, k2, k3, p1, p2) or Kannala–Brandt fisheye
//! (`cv::fisheye`: k1..k4) distortion, so that a calibration from OpenCV can be pasted in.
//!
//! The mapping to seethru's frames (docs/DESIGN.md §2):
//! - OpenCV's camera looks down +z with +y down; seethru's looks down −z with +y up, so
//!   OpenCV's (x, y, z) = seethru's (x, −y, −z), and the normalised coordinates are
//!   `a = x / −z`, `b = −y / −z`.
//! - OpenCV's integer pixel coordinates are pixel *centres*; seethru's pixel (i, j) has its
//!   centre at (i + 0.5, j + 0.5). So seethru's continuous `(px, py) = (u + 0.5, v + 0.5)` with
//!   OpenCV's `u = fx · a_d + cx`, `v = fy · b_d + cy`.
//! - A pinhole of horizontal half angle θ on a W × H image is `fx = fy = W / (2 tan θ)`,
//!   `cx = W/2 − 0.5`, `cy = H/2 − 0.5`.
//!
//! The inverse (pixel → ray) is Newton's method: at most [`NEWTON_ITERATIONS`] steps, stopped
//! when a step is below 1e-15 (normalised units); the forward map is checked to be monotonic
//! over the image (`Lens::check`, geometry/lens_check.rs), so the root is unique and Newton converges in a few steps.

use glam::{DMat2, DVec2, DVec3};

/// Most Newton steps of the inverse map; 5–8 suffice for the lenses `Lens::check` admits.
pub const NEWTON_ITERATIONS: usize = 30;

/// Distortion, in OpenCV's coefficients (dimensionless, on normalised coordinates).
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
#[serde(tag = "model", rename_all = "lowercase")]
pub enum Distortion {
    None,
    /// Brown–Conrady: radial `1 + k1 r² + k2 r⁴ + k3 r⁶`, tangential p1, p2.
    Brown {
        k1: f64,
        k2: f64,
        k3: f64,
        p1: f64,
        p2: f64,
    },
    /// Kannala–Brandt: `θ_d = θ (1 + k1 θ² + k2 θ⁴ + k3 θ⁶ + k4 θ⁸)`, θ the angle off the axis.
    Fisheye {
        k1: f64,
        k2: f64,
        k3: f64,
        k4: f64,
    },
}

impl Distortion {
    /// The scene-file name of the model.
    pub fn model_name(&self) -> &'static str {
        match self {
            Distortion::None => "pinhole",
            Distortion::Brown { .. } => "brown",
            Distortion::Fisheye { .. } => "fisheye",
        }
    }

    pub(crate) fn coefficients(&self) -> Vec<f64> {
        match *self {
            Distortion::None => vec![],
            Distortion::Brown { k1, k2, k3, p1, p2 } => vec![k1, k2, k3, p1, p2],
            Distortion::Fisheye { k1, k2, k3, k4 } => vec![k1, k2, k3, k4],
        }
    }
}

/// Intrinsics and distortion of a camera, OpenCV's conventions (see the module comment).
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
pub struct Lens {
    /// Focal lengths, pixels, > 0.
    pub fx: f64,
    pub fy: f64,
    /// Principal point, OpenCV pixel coordinates (seethru's minus 0.5), finite.
    pub cx: f64,
    pub cy: f64,
    pub distortion: Distortion,
}

impl Lens {
    /// The ideal pinhole of horizontal half angle `half_angle_x` (radians) on a W × H image.
    pub fn pinhole(half_angle_x: f64, width: u32, height: u32) -> Self {
        let f = width as f64 / (2.0 * half_angle_x.tan());
        Lens {
            fx: f,
            fy: f,
            cx: width as f64 / 2.0 - 0.5,
            cy: height as f64 / 2.0 - 0.5,
            distortion: Distortion::None,
        }
    }

    /// The same lens on an image scaled by `sx`, `sy` (pixel coordinates scale, the
    /// pixel-centre offset of OpenCV's convention kept).
    pub fn scaled(&self, sx: f64, sy: f64) -> Self {
        Lens {
            fx: self.fx * sx,
            fy: self.fy * sy,
            cx: (self.cx + 0.5) * sx - 0.5,
            cy: (self.cy + 0.5) * sy - 0.5,
            distortion: self.distortion,
        }
    }

    /// The pinhole with the same intrinsics and no distortion.
    pub fn undistorted(&self) -> Self {
        Lens {
            distortion: Distortion::None,
            ..*self
        }
    }

    /// Distorted normalised coordinates of undistorted ones (a, b) = (x/z, y/z) in OpenCV's
    /// frame. For the fisheye, `theta` is the angle off the axis (so that it is exact at any
    /// angle); `None` computes it from (a, b).
    pub(crate) fn distort(&self, ab: DVec2, theta: Option<f64>) -> DVec2 {
        match self.distortion {
            Distortion::None => ab,
            Distortion::Brown { k1, k2, k3, p1, p2 } => {
                let (a, b) = (ab.x, ab.y);
                let r2 = a * a + b * b;
                let radial = 1.0 + r2 * (k1 + r2 * (k2 + r2 * k3));
                DVec2::new(
                    a * radial + 2.0 * p1 * a * b + p2 * (r2 + 2.0 * a * a),
                    b * radial + p1 * (r2 + 2.0 * b * b) + 2.0 * p2 * a * b,
                )
            }
            Distortion::Fisheye { .. } => {
                let r = ab.length();
                let theta = theta.unwrap_or_else(|| r.atan());
                if r < 1e-300 {
                    return ab;
                }
                ab * (self.fisheye_theta_d(theta) / r)
            }
        }
    }

    pub(crate) fn fisheye_theta_d(&self, theta: f64) -> f64 {
        match self.distortion {
            Distortion::Fisheye { k1, k2, k3, k4 } => {
                let t2 = theta * theta;
                theta * (1.0 + t2 * (k1 + t2 * (k2 + t2 * (k3 + t2 * k4))))
            }
            _ => theta,
        }
    }

    pub(crate) fn fisheye_theta_d_slope(&self, theta: f64) -> f64 {
        match self.distortion {
            Distortion::Fisheye { k1, k2, k3, k4 } => {
                let t2 = theta * theta;
                1.0 + t2 * (3.0 * k1 + t2 * (5.0 * k2 + t2 * (7.0 * k3 + t2 * 9.0 * k4)))
            }
            _ => 1.0,
        }
    }

    /// Jacobian of the Brown–Conrady map at (a, b).
    pub(crate) fn brown_jacobian(&self, ab: DVec2) -> DMat2 {
        let Distortion::Brown { k1, k2, k3, p1, p2 } = self.distortion else {
            return DMat2::IDENTITY;
        };
        let (a, b) = (ab.x, ab.y);
        let r2 = a * a + b * b;
        let radial = 1.0 + r2 * (k1 + r2 * (k2 + r2 * k3));
        // d(radial)/d(r²)
        let dradial = k1 + r2 * (2.0 * k2 + 3.0 * r2 * k3);
        let daa = radial + a * dradial * 2.0 * a + 2.0 * p1 * b + p2 * 6.0 * a;
        let dab = a * dradial * 2.0 * b + 2.0 * p1 * a + p2 * 2.0 * b;
        let dba = b * dradial * 2.0 * a + p1 * 2.0 * a + 2.0 * p2 * b;
        let dbb = radial + b * dradial * 2.0 * b + p1 * 6.0 * b + 2.0 * p2 * a;
        DMat2::from_cols(DVec2::new(daa, dba), DVec2::new(dab, dbb))
    }

    /// Undistorted normalised coordinates of distorted ones, by Newton's method (Brown), or
    /// the fisheye angle off the axis and the unit direction in the image plane.
    fn undistort_brown(&self, target: DVec2) -> DVec2 {
        let mut ab = target;
        for _ in 0..NEWTON_ITERATIONS {
            let residual = self.distort(ab, None) - target;
            let step = self.brown_jacobian(ab).inverse() * residual;
            if !step.is_finite() {
                break;
            }
            ab -= step;
            if step.length() < 1e-15 {
                break;
            }
        }
        ab
    }

    /// The angle off the axis θ with `θ_d(θ) = theta_d` (fisheye), by Newton from θ = θ_d.
    fn undistort_fisheye(&self, theta_d: f64) -> f64 {
        let mut theta = theta_d;
        for _ in 0..NEWTON_ITERATIONS {
            let step = (self.fisheye_theta_d(theta) - theta_d) / self.fisheye_theta_d_slope(theta);
            if !step.is_finite() {
                break;
            }
            theta -= step;
            if step.abs() < 1e-15 {
                break;
            }
        }
        theta
    }

    /// Continuous seethru pixel coordinates of a camera-space direction or point (seethru's
    /// camera frame: looking down −z, +y up); `None` behind the camera (z ≥ 0).
    pub fn project(&self, p: DVec3) -> Option<DVec2> {
        if p.z >= 0.0 {
            return None;
        }
        let ab = DVec2::new(p.x / -p.z, -p.y / -p.z);
        let theta = match self.distortion {
            Distortion::Fisheye { .. } => Some(DVec2::new(p.x, p.y).length().atan2(-p.z)),
            _ => None,
        };
        let d = self.distort(ab, theta);
        Some(DVec2::new(
            self.fx * d.x + self.cx + 0.5,
            self.fy * d.y + self.cy + 0.5,
        ))
    }

    /// Distorted normalised coordinates (OpenCV's frame) of seethru pixel coordinates.
    pub(crate) fn normalised(&self, pixel: DVec2) -> DVec2 {
        DVec2::new(
            (pixel.x - 0.5 - self.cx) / self.fx,
            (pixel.y - 0.5 - self.cy) / self.fy,
        )
    }

    /// Camera-space direction (seethru's frame, z = −1) of the ray through continuous seethru
    /// pixel coordinates.
    pub fn camera_direction(&self, pixel: DVec2) -> DVec3 {
        let ab = self.undistort(self.normalised(pixel));
        DVec3::new(ab.x, -ab.y, -1.0)
    }

    /// Undistorted normalised coordinates (a, b) of distorted ones.
    fn undistort(&self, d: DVec2) -> DVec2 {
        match self.distortion {
            Distortion::None => d,
            Distortion::Brown { .. } => self.undistort_brown(d),
            Distortion::Fisheye { .. } => {
                let theta_d = d.length();
                if theta_d < 1e-300 {
                    return d;
                }
                d * (self.undistort_fisheye(theta_d).tan() / theta_d)
            }
        }
    }

    /// The distorted seethru pixel of an undistorted one: `pixel` is where this lens's
    /// [`Lens::undistorted`] pinhole sees a ray; the result is where this lens sees it.
    pub fn distort_pixel(&self, pixel: DVec2) -> DVec2 {
        let d = self.distort(self.normalised(pixel), None);
        DVec2::new(self.fx * d.x + self.cx + 0.5, self.fy * d.y + self.cy + 0.5)
    }

    /// Horizontal half angle of the pinhole with the same fx on a `width`-pixel image:
    /// `atan(W / (2 fx))`. What eqs. d1 and b_h use after undistortion.
    pub fn equivalent_half_angle(&self, width: u32) -> f64 {
        (width as f64 / (2.0 * self.fx)).atan()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn lenses(w: u32, h: u32) -> Vec<Lens> {
        let base = Lens {
            fx: 300.0,
            fy: 310.0,
            cx: w as f64 / 2.0 - 3.2,
            cy: h as f64 / 2.0 + 2.1,
            distortion: Distortion::None,
        };
        vec![
            base,
            Lens {
                distortion: Distortion::Brown {
                    k1: -0.28,
                    k2: 0.07,
                    k3: 0.0,
                    p1: 0.001,
                    p2: -0.0015,
                },
                ..base
            },
            Lens {
                distortion: Distortion::Brown {
                    k1: 0.12,
                    k2: -0.01,
                    k3: 0.002,
                    p1: 0.0,
                    p2: 0.0,
                },
                ..base
            },
            Lens {
                distortion: Distortion::Fisheye {
                    k1: -0.02,
                    k2: 0.004,
                    k3: -0.001,
                    k4: 0.0002,
                },
                ..base
            },
        ]
    }

    #[test]
    fn pixel_to_ray_to_pixel_round_trips_over_the_whole_image() {
        let (w, h) = (640, 480);
        for lens in lenses(w, h) {
            lens.check(w, h).unwrap();
            let mut worst = 0.0f64;
            // Every pixel centre, and the image's border and corners.
            let points = (0..=h).flat_map(|y| (0..=w).map(move |x| (x, y)));
            for (x, y) in points {
                for offset in [0.0, 0.5] {
                    let p = DVec2::new(x as f64 + offset, y as f64 + offset);
                    let back = lens.project(lens.camera_direction(p) * 3.7).unwrap();
                    worst = worst.max((back - p).length());
                }
            }
            assert!(worst < 1e-6, "{lens:?}: {worst} px");
        }
    }

    #[test]
    fn pinhole_lens_is_the_half_angle_camera() {
        let lens = Lens::pinhole(0.7, 320, 200);
        // The image's left edge at the half angle, its centre on the axis.
        let left = lens.camera_direction(DVec2::new(0.0, 100.0));
        assert!((left.x.atan2(-left.z) + 0.7).abs() < 1e-12);
        let centre = lens.camera_direction(DVec2::new(160.0, 100.0));
        assert!(centre.x.abs() < 1e-12 && centre.y.abs() < 1e-12);
        // Scaling the image keeps the view: the same ray at the scaled pixel.
        let half = lens.scaled(0.5, 0.5);
        let a = lens.camera_direction(DVec2::new(40.0, 30.0));
        let b = half.camera_direction(DVec2::new(20.0, 15.0));
        assert!((a - b).length() < 1e-12);
    }

    #[test]
    fn fisheye_maps_angle_linearly_without_coefficients() {
        // Equidistant fisheye: the radius in pixels is fx · θ, not fx · tan θ.
        let lens = Lens {
            distortion: Distortion::Fisheye {
                k1: 0.0,
                k2: 0.0,
                k3: 0.0,
                k4: 0.0,
            },
            ..Lens::pinhole(0.6, 400, 400)
        };
        let theta = 1.2f64;
        let p = lens
            .project(DVec3::new(theta.sin(), 0.0, -theta.cos()))
            .unwrap();
        assert!((p.x - 200.0 - lens.fx * theta).abs() < 1e-9);
    }
}
