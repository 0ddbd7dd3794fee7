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

/// [`disparity_mismatch`] along any line of sight: for eyes `baseline` apart (the vector
/// from the left eye to the right, m), a unit `sight` direction from the cyclopean eye and the
/// display's unit `normal`, the vergence of a point at distance ρ is `|b⊥| / ρ` (b⊥ the part of
/// the baseline across the sight line), and the display point and the scene point lie at
/// ρ = d1 / cos α and (d1 + d2) / cos α: `|b⊥| cos α (1/d1 − 1/(d1 + d2))`. A baseline
/// parallel to the display in the plane of the sight line gives `ipd cos² α (…)`, one across
/// the sight line `ipd cos α (…)`.
pub fn disparity_mismatch_along(
    baseline: DVec3,
    sight: DVec3,
    normal: DVec3,
    d1: f64,
    d2: f64,
) -> f64 {
    let across = baseline - sight * baseline.dot(sight);
    let cos_alpha = sight.dot(normal).abs();
    disparity_mismatch(across.length(), d1, d2) * cos_alpha
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
    fn off_axis_the_mismatch_follows_the_baseline_across_the_sight_line() {
        let (ipd, d1, d2, alpha) = (0.064, 0.75, 12.0, 25f64.to_radians());
        let sight = DVec3::new(-alpha.sin(), 0.0, -alpha.cos());
        let eye = DVec3::new(0.0, 0.0, d1);
        // The point at depth z (display plane z = 0) on the sight line.
        let at = |z: f64| eye + sight * ((d1 - z) / alpha.cos());
        // Baseline along the display (cos²) and across the sight line (cos).
        for baseline in [
            DVec3::X * ipd,
            DVec3::new(alpha.cos(), 0.0, -alpha.sin()) * ipd,
        ] {
            let (l, r) = (eye - baseline / 2.0, eye + baseline / 2.0);
            let exact = vergence(l, r, at(0.0)) - vergence(l, r, at(-d2));
            let closed = disparity_mismatch_along(baseline, sight, DVec3::Z, d1, d2);
            assert!((exact - closed).abs() < 2e-3 * closed, "{exact} {closed}");
        }
        let parallel = disparity_mismatch_along(DVec3::X * ipd, sight, DVec3::Z, d1, d2);
        let straight = disparity_mismatch(ipd, d1, d2);
        assert!((parallel - straight * alpha.cos().powi(2)).abs() < 1e-12);
    }

    #[test]
    fn radial_error_of_k1_alone_is_cubic() {
        assert!(
            (radial_error_px(500.0, [-0.2, 0.05, 0.0], [0.0, 0.05, 0.0], 0.5) - 12.5).abs() < 1e-12
        );
    }
}
