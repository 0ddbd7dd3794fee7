//! Misregistration in motion: what latency costs when the vehicle drives and turns and the
//! head moves (see docs/guide/sequences.md).
//!
//! The frame shown at time t was captured at t − L (L: capture to display, with the display's
//! hold), and compensated for the head estimate of its own time, which itself is L_t older
//! (tracking latency). Within the vehicle's frame everything the system used is consistent at
//! the capture instant; what it gets wrong at t is what changed since, to first order in L:
//!
//! - the scene turned relative to the vehicle. A static point at distance z and bearing α
//!   (from the direction of travel, positive to the left) seen from an eye moving at speed v
//!   while the vehicle yaws at ω (positive to the left) turns, relative to the vehicle, at
//!   `v sin α / z − ω` rad/s (translation parallax minus yaw; the yaw pivot is the eye);
//! - the eye moved: at eye speed u across the display (relative to the vehicle) the
//!   compensation's eye is `u (L + L_t)` off, which costs [`per_lateral_head_error`] per metre
//!   (for a scene on the model plane).
//!
//! Both are horizontal angles; their signed sum is the misregistration.

use crate::analysis::physical::{
    ARCMIN_PER_RAD, infinite_plane_error, per_d2_error, per_lateral_head_error,
};

/// Rate (rad/s) at which the direction from the eye to a static point turns relative to the
/// vehicle: `v sin α / z − ω`. `z`: distance of the point from the eye, m (> 0); `bearing`:
/// α, radians from the direction of travel, positive to the left; `speed`: v, m/s;
/// `yaw_rate`: ω, rad/s, positive turning left.
pub fn relative_bearing_rate(z: f64, bearing: f64, speed: f64, yaw_rate: f64) -> f64 {
    speed * bearing.sin() / z - yaw_rate
}

/// What moves, and how late the system is.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Motion {
    /// Vehicle speed, m/s.
    pub speed: f64,
    /// Yaw rate, rad/s, positive to the left.
    pub yaw_rate: f64,
    /// Eye speed across the display relative to the vehicle (obstacle x), m/s.
    pub eye_speed: f64,
    /// Capture to display, including the display's hold, s.
    pub latency: f64,
    /// Back camera to head estimate, s.
    pub tracking_latency: f64,
}

/// The dynamic misregistration (radians, signed, horizontal) of a static point at distance
/// `z` and bearing `bearing` (see [`relative_bearing_rate`]), for an eye `d1` in front of the
/// display and the model plane at `d2` (`f64::INFINITY` for d2 → ∞).
pub fn dynamic_misregistration(z: f64, bearing: f64, d1: f64, d2: f64, m: &Motion) -> f64 {
    relative_bearing_rate(z, bearing, m.speed, m.yaw_rate) * m.latency
        - m.eye_speed * (m.latency + m.tracking_latency) * per_lateral_head_error(d1, d2)
}

/// The geometry an error budget is taken at (`analysis/examples.rs` has das's).
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
pub struct BudgetGeometry {
    /// Eye distance from the display, m.
    pub d1: f64,
    /// Distance of the scene behind the display from the display plane, m.
    pub scene_depth: f64,
    /// Bearing of the display centre from the direction of travel, radians (left > 0).
    pub bearing: f64,
    /// Display half width (the largest offset of a display point from the frontal camera's
    /// axis), m.
    pub half_width: f64,
}

impl BudgetGeometry {
    /// Distance from the eye of the scene point seen through the display centre, m.
    pub fn scene_distance(&self) -> f64 {
        (self.d1 + self.scene_depth) / self.bearing.cos()
    }
}

/// Arc-minutes of misregistration per unit of each error source, and the latency at which
/// motion costs as much as the static planar error.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
pub struct ErrorBudget {
    pub geometry: BudgetGeometry,
    /// Per millimetre of lateral head-position error (d2 → ∞).
    pub arcmin_per_mm_head: f64,
    /// Per millisecond of latency at 50 km/h straight ahead.
    pub arcmin_per_ms_at_50_kmh: f64,
    /// Per millisecond of latency at 20 °/s of yaw, standing.
    pub arcmin_per_ms_at_20_deg_s: f64,
    /// Per metre of working-distance error, at the display's edge, for a model plane at the
    /// scene's depth.
    pub arcmin_per_m_d2: f64,
    /// The d2 → ∞ model's error for the scene at its depth, at the display's edge.
    pub static_planar_arcmin: f64,
    /// Latency at which the dynamic error equals the static planar error, ms: at 50 km/h and
    /// at 20 °/s.
    pub break_even_ms_at_50_kmh: f64,
    pub break_even_ms_at_20_deg_s: f64,
}

/// The error budget at `g`.
pub fn error_budget(g: &BudgetGeometry) -> ErrorBudget {
    let per_ms = |speed: f64, yaw_rate: f64| {
        relative_bearing_rate(g.scene_distance(), g.bearing, speed, yaw_rate).abs()
            * 1e-3
            * ARCMIN_PER_RAD
    };
    let at_50 = per_ms(50.0 / 3.6, 0.0);
    let at_20 = per_ms(0.0, 20f64.to_radians());
    let static_planar = infinite_plane_error(g.half_width, g.d1, g.scene_depth) * ARCMIN_PER_RAD;
    ErrorBudget {
        geometry: *g,
        arcmin_per_mm_head: per_lateral_head_error(g.d1, f64::INFINITY) * 1e-3 * ARCMIN_PER_RAD,
        arcmin_per_ms_at_50_kmh: at_50,
        arcmin_per_ms_at_20_deg_s: at_20,
        arcmin_per_m_d2: per_d2_error(g.half_width, g.d1, g.scene_depth) * ARCMIN_PER_RAD,
        static_planar_arcmin: static_planar,
        break_even_ms_at_50_kmh: static_planar / at_50,
        break_even_ms_at_20_deg_s: static_planar / at_20,
    }
}

/// The budget as a table for `analyze`.
pub fn budget_text(b: &ErrorBudget) -> String {
    let g = &b.geometry;
    format!(
        "Error budget at the das geometry (d1 = {:.2} m, scene {:.1} m behind the display at a bearing of {:.0}°, display half width {:.3} m, d2 → ∞):\n\
         | error source | arc-minutes |\n|---|---|\n\
         | 1 mm of lateral head error | {:.2} |\n\
         | 1 ms of latency at 50 km/h | {:.2} |\n\
         | 1 ms of latency at 20 °/s of yaw | {:.2} |\n\
         | 1 m of d2 error (model plane at the scene) | {:.2} |\n\
         | static planar error (d2 → ∞, display edge) | {:.1} |\n\
         Latency at which motion costs the static planar error: {:.1} ms at 50 km/h, {:.1} ms at 20 °/s.\n",
        g.d1,
        g.scene_depth,
        g.bearing.to_degrees(),
        g.half_width,
        b.arcmin_per_mm_head,
        b.arcmin_per_ms_at_50_kmh,
        b.arcmin_per_ms_at_20_deg_s,
        b.arcmin_per_m_d2,
        b.static_planar_arcmin,
        b.break_even_ms_at_50_kmh,
        b.break_even_ms_at_20_deg_s,
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The bearing rate against the finite difference of the bearing of a point passed by a
    /// moving, turning eye.
    #[test]
    fn the_bearing_rate_is_the_derivative_of_the_relative_bearing() {
        let (z, alpha, v, w): (f64, f64, f64, f64) = (7.0, 0.4, 13.0, 0.3);
        // Eye at the origin heading −z at t = 0; the point at bearing α (left of −z: −x).
        let point = glam::DVec2::new(-z * alpha.sin(), -z * alpha.cos());
        let bearing_at = |t: f64| {
            let heading = w * t;
            // Pivot position (∫ v (−sin ωs, −cos ωs) ds) and the point's bearing from the
            // vehicle's heading.
            let eye = glam::DVec2::new(v / w * (heading.cos() - 1.0), -v / w * heading.sin());
            let d = point - eye;
            let forward = glam::DVec2::new(-heading.sin(), -heading.cos());
            let left = glam::DVec2::new(-heading.cos(), heading.sin());
            d.dot(left).atan2(d.dot(forward))
        };
        let h = 1e-5;
        let numeric = (bearing_at(h) - bearing_at(-h)) / (2.0 * h);
        assert!((numeric - relative_bearing_rate(z, alpha, v, w)).abs() < 1e-7);
    }
}
