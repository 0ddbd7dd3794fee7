//! Closed forms for real cameras and two eyes: the frontal pixel error of ignoring radial
//! distortion, and the vergence mismatch of a flat display.
//!
//! Geometry (obstacle frame, docs/DESIGN.md §2): the frontal camera at the display centre
//! looking down −z (the paper's case), the eye at `eye`, the model plane `z = −d2`.

use glam::{DVec2, DVec3};

/// Undistorted normalised coordinates (OpenCV's frame: x right, y down) in the frontal camera
/// of the model point of a display point `on_display` (z = 0) seen from `eye` (z = d1 > 0);
/// `d2 = None` for d2 → ∞.
pub fn model_point_normalised(eye: DVec3, on_display: DVec3, d2: Option<f64>) -> DVec2 {
    let d1 = eye.z;
    let (x, y) = match d2 {
        Some(d2) => {
            let p = eye + (on_display - eye) * (d1 + d2) / d1;
            (p.x / d2, p.y / d2)
        }
        None => {
            let dir = on_display - eye;
            (dir.x / d1, dir.y / d1)
        }
    };
    DVec2::new(x, -y)
}

/// Pixel error of believing the radial coefficients `believed` where the lens has `truth`
/// (each [k1, k2, k3], Brown–Conrady), at undistorted normalised radius `r`, for a focal
/// length `f_px`: `f · r · |Σ (k_i − k_i') r^{2i}|`. Ignoring k1 alone: `f |k1| r³`.
pub fn radial_error_px(f_px: f64, truth: [f64; 3], believed: [f64; 3], r: f64) -> f64 {
    let r2 = r * r;
    let dk: Vec<f64> = truth.iter().zip(believed).map(|(t, b)| t - b).collect();
    f_px * r * (r2 * (dk[0] + r2 * (dk[1] + r2 * dk[2]))).abs()
}

/// The display's corners (D × H metres) in the obstacle frame: TL, TR, BR, BL.
pub fn display_corners(width: f64, height: f64) -> [DVec3; 4] {
    let (w, h) = (width / 2.0, height / 2.0);
    [(-w, h), (w, h), (w, -h), (-w, -h)].map(|(x, y)| DVec3::new(x, y, 0.0))
}

/// The disparity mismatch of a flat display, radians: the vergence of a point on the display
/// (`d1` away) minus that of the scene point it stands for (`d1 + d2` away), for eyes `ipd`
/// apart, straight ahead and small angles: `ipd · (1/d1 − 1/(d1 + d2))`. `d2 = ∞` gives
/// `ipd / d1`.
pub fn disparity_mismatch(ipd: f64, d1: f64, d2: f64) -> f64 {
    ipd * (1.0 / d1 - 1.0 / (d1 + d2))
}

/// [`disparity_mismatch`] along a line of sight `alpha` radians off the display normal in the
/// plane of the eyes (the eyes' baseline parallel to the display): the vergence of a point
/// at depth z and that angle is `(ipd / z) cos² α`, so the mismatch is
/// `ipd cos² α (1/d1 − 1/(d1 + d2))`.
pub fn disparity_mismatch_off_axis(ipd: f64, d1: f64, d2: f64, alpha: f64) -> f64 {
    disparity_mismatch(ipd, d1, d2) * alpha.cos().powi(2)
}

/// Vergence of a point: the angle at `point` between the two eyes, radians.
pub fn vergence(left: DVec3, right: DVec3, point: DVec3) -> f64 {
    (left - point).angle_between(right - point)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_small_angle_mismatch_is_the_vergence_difference_straight_ahead() {
        let (ipd, d1, d2) = (0.064, 0.9, 12.0);
        let (l, r) = (
            DVec3::new(-ipd / 2.0, 0.0, d1),
            DVec3::new(ipd / 2.0, 0.0, d1),
        );
        let exact = vergence(l, r, DVec3::ZERO) - vergence(l, r, DVec3::new(0.0, 0.0, -d2));
        let closed = disparity_mismatch(ipd, d1, d2);
        // 2 atan(e/2d) = (e/d)(1 − e²/(12 d²) …): 4e-4 relative here.
        assert!((exact - closed).abs() < 1e-3 * closed, "{exact} {closed}");
    }

    #[test]
    fn off_axis_the_vergence_falls_as_cos_squared() {
        let (ipd, d1, d2, alpha) = (0.064, 0.75, 12.0, 25f64.to_radians());
        let (l, r) = (
            DVec3::new(-ipd / 2.0, 0.0, d1),
            DVec3::new(ipd / 2.0, 0.0, d1),
        );
        let at = |z: f64| DVec3::new(-alpha.tan() * (d1 - z), 0.0, z);
        let exact = vergence(l, r, at(0.0)) - vergence(l, r, at(-d2));
        let closed = disparity_mismatch_off_axis(ipd, d1, d2, alpha);
        assert!((exact - closed).abs() < 2e-3 * closed, "{exact} {closed}");
    }

    #[test]
    fn radial_error_of_k1_alone_is_cubic() {
        assert!(
            (radial_error_px(500.0, [-0.2, 0.05, 0.0], [0.0, 0.05, 0.0], 0.5) - 12.5).abs() < 1e-12
        );
    }
}
