//! Which lenses seethru accepts on an image: finite intrinsics and coefficients, positive
//! focal lengths, less than a hemisphere, and a forward map that does not fold inside the
//! image (so that pixel → ray has one answer and Newton's method finds it).

use glam::DVec2;

use crate::geometry::lens::{Distortion, Lens};
use crate::util::number::short;

/// Largest angle off the axis any pixel may see, radians (89°): seethru's cameras see less
/// than a hemisphere, so every ray they see has camera z < 0.
pub const MAX_OFF_AXIS: f64 = 89.0 * std::f64::consts::PI / 180.0;

/// Why a lens cannot be used on an image.
#[derive(Clone, Debug, PartialEq)]
pub enum LensError {
    /// A coefficient or intrinsic is NaN or infinite.
    NotFinite(&'static str),
    /// A focal length ≤ 0.
    FocalNotPositive(&'static str, f64),
    /// The forward map folds (is not invertible) inside the image.
    Folds {
        /// Normalised undistorted radius (fisheye: angle, radians) where it folds.
        radius: f64,
        /// The distorted radius there, pixels from the principal point (along x).
        pixels: f64,
        /// The distorted radius the image needs, pixels.
        needed: f64,
    },
    /// Some pixel of the image would see 89° or more off the axis.
    TooWide { needed: f64 },
}

impl std::fmt::Display for LensError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            LensError::NotFinite(key) => write!(f, "{key} must be a finite number"),
            LensError::FocalNotPositive(key, v) => {
                write!(f, "{key} must be > 0 pixels, got {}", short(*v))
            }
            LensError::Folds {
                radius,
                pixels,
                needed,
            } => write!(
                f,
                "the distortion folds (the lens map is not invertible) at undistorted radius {} ({} px from the principal point), inside the image, which reaches {} px: the coefficients are not a lens",
                short(*radius),
                short(*pixels),
                short(*needed)
            ),
            LensError::TooWide { needed } => write!(
                f,
                "the image reaches {} px from the principal point, where the lens sees 89° or more off its axis; seethru's cameras must see less than a hemisphere (raise fx, fy, or bring cx, cy nearer the image centre)",
                short(*needed)
            ),
        }
    }
}

impl std::error::Error for LensError {}

impl Lens {
    /// Checks that the lens is a lens on a `width` × `height` image: finite, positive focal
    /// lengths, less than a hemisphere, and no fold inside the image (radially, and for
    /// Brown's tangential terms a positive Jacobian along 64 rays from the centre).
    pub fn check(&self, width: u32, height: u32) -> Result<(), LensError> {
        for (key, v) in [
            ("fx", self.fx),
            ("fy", self.fy),
            ("cx", self.cx),
            ("cy", self.cy),
        ] {
            if !v.is_finite() {
                return Err(LensError::NotFinite(key));
            }
        }
        let names: &[&'static str] = match self.distortion {
            Distortion::Fisheye { .. } => &["k1", "k2", "k3", "k4"],
            _ => &["k1", "k2", "k3", "p1", "p2"],
        };
        for (key, v) in names.iter().zip(self.distortion.coefficients()) {
            if !v.is_finite() {
                return Err(LensError::NotFinite(key));
            }
        }
        for (key, v) in [("fx", self.fx), ("fy", self.fy)] {
            if v <= 0.0 {
                return Err(LensError::FocalNotPositive(key, v));
            }
        }
        // The largest distorted normalised radius the image needs: its farthest corner.
        let corners = [(0.0, 0.0), (width as f64, 0.0), (0.0, height as f64)]
            .into_iter()
            .chain([(width as f64, height as f64)]);
        let needed = corners
            .map(|(x, y)| self.normalised(DVec2::new(x, y)).length())
            .fold(0.0, f64::max);
        let needed_px = needed * self.fx;
        match self.distortion {
            Distortion::None => {
                if needed.atan() >= MAX_OFF_AXIS {
                    return Err(LensError::TooWide { needed: needed_px });
                }
            }
            Distortion::Fisheye { .. } => {
                // θ_d(θ) must rise from 0 until it covers the image, before 89°.
                let steps = 20_000;
                for i in 1..=steps {
                    let theta = MAX_OFF_AXIS * i as f64 / steps as f64;
                    if self.fisheye_theta_d_slope(theta) <= 0.0 {
                        return Err(LensError::Folds {
                            radius: theta,
                            pixels: self.fisheye_theta_d(theta) * self.fx,
                            needed: needed_px,
                        });
                    }
                    if self.fisheye_theta_d(theta) >= needed {
                        return Ok(());
                    }
                }
                return Err(LensError::TooWide { needed: needed_px });
            }
            Distortion::Brown { .. } => {
                // Along rays from the axis, the Jacobian must stay positive until the
                // distorted point has left the image's farthest radius; the fold reported is
                // the nearest over the rays, bisected to 1e-9.
                let r_max = MAX_OFF_AXIS.tan();
                let steps = 4_000;
                let mut fold: Option<f64> = None;
                let mut reached_all = true;
                for ray in 0..64 {
                    let angle = std::f64::consts::TAU * ray as f64 / 64.0;
                    let dir = DVec2::new(angle.cos(), angle.sin());
                    let folded = |r: f64| {
                        self.brown_jacobian(dir * r).determinant() <= 0.0
                            || self.distort(dir * r, None).dot(dir) <= 0.0
                    };
                    let mut reached = false;
                    let mut previous = 0.0;
                    for i in 1..=steps {
                        // Finer steps near the axis, where images are.
                        let r = r_max * (i as f64 / steps as f64).powi(3);
                        if folded(r) {
                            let (mut lo, mut hi) = (previous, r);
                            while hi - lo > 1e-9 {
                                let mid = 0.5 * (lo + hi);
                                if folded(mid) { hi = mid } else { lo = mid }
                            }
                            fold = Some(fold.map_or(hi, |f: f64| f.min(hi)));
                            reached = true;
                            break;
                        }
                        if self.distort(dir * r, None).length() >= needed {
                            reached = true;
                            break;
                        }
                        previous = r;
                    }
                    reached_all &= reached;
                }
                if let Some(radius) = fold {
                    let d = self.distort(DVec2::new(radius, 0.0), None).length();
                    return Err(LensError::Folds {
                        radius,
                        pixels: d * self.fx,
                        needed: needed_px,
                    });
                }
                if !reached_all {
                    return Err(LensError::TooWide { needed: needed_px });
                }
            }
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn folding_and_broken_coefficients_are_refused() {
        let base = Lens::pinhole(0.5, 640, 480);
        let folding = Lens {
            distortion: Distortion::Brown {
                k1: -0.9,
                k2: 0.0,
                k3: 0.0,
                p1: 0.0,
                p2: 0.0,
            },
            ..base
        };
        // r (1 − 0.9 r²) has its maximum at r = 1/sqrt(2.7) = 0.6086.
        match folding.check(640, 480) {
            Err(LensError::Folds { radius, .. }) => {
                assert!((radius - 0.6086).abs() < 0.002, "{radius}")
            }
            other => panic!("{other:?}"),
        }
        // A milder k1 folds (at r = 1.29, 0.86 distorted) outside the image (0.68): admitted.
        let mild = Lens {
            distortion: Distortion::Brown {
                k1: -0.2,
                k2: 0.0,
                k3: 0.0,
                p1: 0.0,
                p2: 0.0,
            },
            ..base
        };
        assert_eq!(mild.check(640, 480), Ok(()));
        let nan = Lens {
            distortion: Distortion::Fisheye {
                k1: 0.0,
                k2: f64::NAN,
                k3: 0.0,
                k4: 0.0,
            },
            ..base
        };
        assert_eq!(nan.check(640, 480), Err(LensError::NotFinite("k2")));
        let flat = Lens { fy: 0.0, ..base };
        assert_eq!(
            flat.check(640, 480),
            Err(LensError::FocalNotPositive("fy", 0.0))
        );
        let fold_fisheye = Lens {
            distortion: Distortion::Fisheye {
                k1: -0.5,
                k2: 0.0,
                k3: 0.0,
                k4: 0.0,
            },
            fx: 150.0,
            fy: 150.0,
            ..base
        };
        // 1 − 1.5 θ² = 0 at θ = 0.8165.
        match fold_fisheye.check(640, 480) {
            Err(LensError::Folds { radius, .. }) => assert!((radius - 0.8165).abs() < 1e-3),
            other => panic!("{other:?}"),
        }
    }
}
