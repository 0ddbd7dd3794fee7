//! What a depth error costs the per-pixel reprojection (`--method depth`): the closed form
//! the depth-noise test holds the pipeline to.
//!
//! Frontal-camera frame: the camera at the origin, depth along its axis. The eye's ray
//! through a display point crosses the camera's plane (depth 0) at the lateral point `c`
//! and runs on as `P(z) = c + z·ũ` (ũ: the ray's direction scaled to unit depth). It meets a
//! surface fronto-parallel to the camera at depth `Z` in `P(Z)`. A sensor that reads the depth
//! there as `Z + δ` makes the search stop at `P(Z + δ)`, and the display shows what the camera
//! sees towards that point: on the surface, `Q = P(Z + δ)·Z/(Z + δ)`. Then
//!
//! ```text
//! Q − P(Z) = c·(Z/(Z + δ) − 1) = −c·δ/(Z + δ)
//! ```
//!
//! exactly, for any eye: the shown point slides along the surface towards (δ > 0) or away from
//! the camera's axis by the display point's lateral offset scaled by the relative depth error.
//! Seen from the eye at distance r = |P − E|, that is an angle of |c × û|·|δ|/((Z + δ)·r) to
//! first order (û the unit ray direction). With Gaussian noise of σ at depth Z, the mean
//! angle is E|δ/(Z + δ)|·|c × û|/r, and E|δ/(Z + δ)| = √(2/π)·σ/Z·(1 + 2(σ/Z)² + …); the
//! expectation is integrated numerically here, so that no series is truncated.

use glam::DVec3;

/// Where the display shows the surface point `P(Z)` as, when the depth reads `Z + delta`:
/// the shift `Q − P(Z)` on the surface, metres, for the ray's crossing `c` of the camera's
/// plane (camera frame, lateral, metres). `z + delta` must be > 0.
pub fn surface_shift(c: DVec3, z: f64, delta: f64) -> DVec3 {
    -c * (delta / (z + delta))
}

/// E|δ/(Z + δ)| for δ ~ N(0, σ²) at relative noise `s = σ/Z` (< 0.25, so that Z + δ > 0 but
/// for a negligible tail beyond four σ), by Simpson's rule over ±8 σ.
pub fn mean_abs_relative_shift(s: f64) -> f64 {
    let n = 4000;
    let (lo, hi) = (-8.0f64.min(0.999 / s), 8.0);
    let h = (hi - lo) / n as f64;
    let f = |g: f64| {
        let x = g * s;
        (x / (1.0 + x)).abs() * (-0.5 * g * g).exp() / (2.0 * std::f64::consts::PI).sqrt()
    };
    let mut sum = f(lo) + f(hi);
    for k in 1..n {
        sum += f(lo + k as f64 * h) * if k % 2 == 1 { 4.0 } else { 2.0 };
    }
    sum * h / 3.0
}

/// The mean misregistration (radians) at the eye of a display point whose ray crosses the
/// camera's plane at `c` (lateral, camera frame) and meets the surface at distance `range`
/// from the eye along unit direction `u`, when the sensor's depth there has relative noise
/// `s = σ/Z` (first order in the angle, exact in the noise).
pub fn mean_misregistration(c: DVec3, u: DVec3, range: f64, s: f64) -> f64 {
    mean_abs_relative_shift(s) * c.cross(u).length() / range
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_mean_relative_shift_follows_its_series_for_small_noise() {
        for s in [0.01, 0.03, 0.05] {
            let series = (2.0 / std::f64::consts::PI).sqrt() * s * (1.0 + 2.0 * s * s);
            let got = mean_abs_relative_shift(s);
            assert!(
                (got - series).abs() < 2e-3 * series,
                "{s}: {got} vs {series}"
            );
        }
    }

    /// Against a twin that integrates each side of the kink at δ = 0 apart (a smooth
    /// integrand on each, so its Simpson sums converge to 1e-12): within the rule's own error
    /// at the kink, for a small noise and for one whose lower limit is cut at Z + δ > 0.
    #[test]
    fn the_mean_relative_shift_equals_a_finer_integration() {
        let density = |g: f64| (-0.5 * g * g).exp() / (2.0 * std::f64::consts::PI).sqrt();
        let simpson = |f: &dyn Fn(f64) -> f64, a: f64, b: f64| {
            let n = 40_000;
            let h = (b - a) / n as f64;
            let inner: f64 = (1..n)
                .map(|k| f(a + k as f64 * h) * if k % 2 == 1 { 4.0 } else { 2.0 })
                .sum();
            (f(a) + f(b) + inner) * h / 3.0
        };
        for s in [0.05, 0.2] {
            let shift = |g: f64| (g * s / (1.0 + g * s)).abs() * density(g);
            let lo = -(0.999 / s).min(8.0);
            let twin = simpson(&shift, lo, 0.0) + simpson(&shift, 0.0, 8.0);
            let got = mean_abs_relative_shift(s);
            assert!(
                (got - twin).abs() < 1.5e-6 * twin,
                "{s}: {got} against {twin}"
            );
        }
    }
}
