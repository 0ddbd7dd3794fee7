//! Physical-unit sensitivities: the misregistration, as a visual angle at the driver's eye,
//! between what the display shows and what the truth has there, for a scene on the model
//! plane. In these units neither `θ_F` nor the frontal resolution appears: the paper's
//! sensitivities are fractions of the frontal image's width, which spans more scene per unit
//! as `θ_F` grows, hence their `1/tan θ_F` (see README, "Notes on the paper").

/// Radians of misregistration per metre of lateral head-position error:
/// `d2 / (d1 (d1 + d2))` (→ `1/d1` for `d2 → ∞`). Same at every display point.
pub fn per_lateral_head_error(d1: f64, d2: f64) -> f64 {
    if d2.is_infinite() {
        1.0 / d1
    } else {
        d2 / (d1 * (d1 + d2))
    }
}

/// Radians per metre of eye-distance (`d1`) error, at a display point `x` metres across
/// from the eye's foot on the display: `x d2 / (d1² (d1 + d2))`.
pub fn per_head_distance_error(x: f64, d1: f64, d2: f64) -> f64 {
    if d2.is_infinite() {
        x / (d1 * d1)
    } else {
        x * d2 / (d1 * d1 * (d1 + d2))
    }
}

/// Radians per metre of working-distance (`d2`) error, at a display point `x` metres from
/// the frontal camera's axis: `x / (d2 (d1 + d2))`.
pub fn per_d2_error(x: f64, d1: f64, d2: f64) -> f64 {
    x / (d2 * (d1 + d2))
}

/// Misregistration of the `d2 → ∞` model for a scene actually at `d2`, at a display
/// point `x` from the camera axis: `atan(x / (d1 + d2))` — the parallax of the baseline
/// between the camera and the display point.
pub fn infinite_plane_error(x: f64, d1: f64, d2: f64) -> f64 {
    (x / (d1 + d2)).atan()
}

/// Visual angle at the eye of one frontal-camera pixel of a scene at `d2` near the axis:
/// `2 d2 tan θ_F / (E_px (d1 + d2))`. This, and the rounding of `K_px` to it, is where a
/// wide frontal camera costs accuracy.
pub fn frontal_pixel_angle(theta_f: f64, image_px: u32, d1: f64, d2: f64) -> f64 {
    let d2_over = if d2.is_infinite() {
        1.0
    } else {
        d2 / (d1 + d2)
    };
    2.0 * theta_f.tan() * d2_over / image_px as f64
}

pub const ARCMIN_PER_RAD: f64 = 60.0 * 180.0 / std::f64::consts::PI;
