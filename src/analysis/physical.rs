//! Physical-unit sensitivities: the misregistration, as a visual angle at the driver's eye,
//! between what the display shows and what the truth has there, for a scene on the model
//! plane. In these units neither `θ_F` nor the frontal resolution appears: the paper's
//! sensitivities are fractions of the frontal image's width, which spans more scene per unit
//! as `θ_F` grows, hence their `1/tan θ_F` (see docs/reference/equations-errata.md, "Notes on the paper").

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

/// The exact misregistration (radians, the angle at the true eye) at display point `x` when
/// the compensation's eye is off by `error_x` across and `error_d` along the display normal
/// (metres), for a scene that is the model plane at `d2` (`f64::INFINITY`: a scene at
/// infinity, shown by directions). Top view of the paper's configuration: the eye at lateral
/// `eye_x`, `d1` in front of the display; the frontal camera at the display centre. Exact
/// geometry, no linearisation: the display point shows the model point of the erroneous
/// eye's ray through it; the truth there is the true eye's.
pub fn head_error_angle(eye_x: f64, d1: f64, error_x: f64, error_d: f64, x: f64, d2: f64) -> f64 {
    let (model_x, model_d1) = (eye_x + error_x, d1 + error_d);
    // Directions from the true eye, as (lateral, depth beyond the display) pairs.
    let (shown, truth) = if d2.is_infinite() {
        ((x - model_x, model_d1), (x - eye_x, d1))
    } else {
        let shown_x = model_x + (x - model_x) * (model_d1 + d2) / model_d1;
        let truth_x = eye_x + (x - eye_x) * (d1 + d2) / d1;
        ((shown_x - eye_x, d1 + d2), (truth_x - eye_x, d1 + d2))
    };
    let cross = shown.0 * truth.1 - shown.1 * truth.0;
    let dot = shown.0 * truth.0 + shown.1 * truth.1;
    cross.abs().atan2(dot)
}

/// The largest [`head_error_angle`] over a display of width `width` centred on the camera
/// axis (sampled at 201 points across it), in arc-minutes: what 1 cm of head error costs.
pub fn head_error_arcmin_per_cm(eye_x: f64, d1: f64, width: f64, d2: f64, lateral: bool) -> f64 {
    let (error_x, error_d) = if lateral { (0.01, 0.0) } else { (0.0, 0.01) };
    (0..=200)
        .map(|k| width * (k as f64 / 200.0 - 0.5))
        .map(|x| head_error_angle(eye_x, d1, error_x, error_d, x, d2))
        .fold(0.0, f64::max)
        * ARCMIN_PER_RAD
}
