//! The paper's closed forms (§3–§4), as the geometry has them.
//!
//! Top-view (2-D) configuration of the paper: the frontal camera sits on the display plane,
//! its axis perpendicular to the display and through the display centre; lateral positions
//! are measured across the axis. All lengths in metres, angles in radians.
//!
//! **Sign convention** (that of eqs. paralax2/RATIO1 and OCLUSION): `b_h > 0` puts the eye at
//! lateral position `−b_h`, i.e. on the side of the *left* crop `K1`/`R1`. Each function
//! below is tested against ray–plane intersections of its setup (tests/analysis.rs); where a
//! printed formula disagrees with the geometry, the code follows the geometry and
//! docs/reference/equations-errata.md lists the erratum (the `*_as_printed` functions keep the paper's text for comparison).

/// Which crop border: the paper's left (`K1`, `R1`, upper signs) or right (`K2`, `R2`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Side {
    Left,
    Right,
}

impl Side {
    /// The paper's `∓`: −1 for the left border, +1 for the right.
    fn sign(self) -> f64 {
        match self {
            Side::Left => -1.0,
            Side::Right => 1.0,
        }
    }
}

/// Parameters of the crop (paper §3.2).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CropParams {
    /// Eye distance from the display plane `d1`, m, > 0.
    pub d1: f64,
    /// Scene (model plane) distance from the display plane `d2`, m, > 0; `f64::INFINITY` for
    /// the paper's `d2 → ∞`.
    pub d2: f64,
    /// Lateral offset of the eye from the frontal camera's axis `b_h`, m (sign: see module doc).
    pub b_h: f64,
    /// Display width `D`, m, > 0.
    pub width: f64,
    /// Frontal camera's half angle of view `θ_F`, rad, in (0, π/2).
    pub theta_f: f64,
}

impl CropParams {
    /// Discarded width `K` at the scene plane, m (eq. paralax2). Undefined for `d2 = ∞`.
    pub fn discarded_width(&self, side: Side) -> f64 {
        let s = side.sign();
        let Self {
            d1,
            d2,
            b_h,
            width,
            theta_f,
        } = *self;
        d2 * theta_f.tan() - (d1 + d2) * (0.5 * width + s * b_h) / d1 + s * b_h
    }

    /// Cutting ratio `R = K / (2 d2 tan θ_F)`: the fraction of the frontal image's width to
    /// discard on `side` (eq. RATIO1); its limit `R(∞)` when `d2` is infinite.
    pub fn cutting_ratio(&self, side: Side) -> f64 {
        let s = side.sign();
        let Self {
            d1,
            d2,
            b_h,
            width,
            theta_f,
        } = *self;
        let t = theta_f.tan();
        // RATIO1 rearranged: R = 1/2 − D/(4 d2 t) − (D/2 ± b_h)/(2 d1 t); the middle term
        // vanishes for d2 → ∞.
        let plane_term = if d2.is_infinite() {
            0.0
        } else {
            width / (4.0 * d2 * t)
        };
        0.5 - plane_term - (0.5 * width + s * b_h) / (2.0 * d1 * t)
    }

    /// `R(∞)`, the ratio of the paper's `d2 → ∞` approximation.
    pub fn cutting_ratio_at_infinity(&self, side: Side) -> f64 {
        Self {
            d2: f64::INFINITY,
            ..*self
        }
        .cutting_ratio(side)
    }

    /// `φ_d1 = ∂R/∂d1` (eq. ANALYSIS_USR1).
    pub fn phi_d1(&self, side: Side) -> f64 {
        (0.5 * self.width + side.sign() * self.b_h) / (2.0 * self.theta_f.tan() * self.d1 * self.d1)
    }

    /// `φ_bh = ∂R/∂b_h` (eq. ANALYSIS_USR2).
    pub fn phi_bh(&self, side: Side) -> f64 {
        -side.sign() / (2.0 * self.d1 * self.theta_f.tan())
    }

    /// `φ_d2 = ∂R/∂d2 = +D / (4 d2² tan θ_F)`: positive — R grows with d2, as the paper's
    /// own Fig. 3 shows. Eq. ANALYSIS_D2 prints it with a minus sign (erratum 1).
    pub fn phi_d2(&self) -> f64 {
        self.width / (4.0 * self.d2 * self.d2 * self.theta_f.tan())
    }

    /// Eq. ANALYSIS_D2 as printed: `−0.5 D / (2 d2² tan θ_F)`.
    pub fn phi_d2_as_printed(&self) -> f64 {
        -self.phi_d2()
    }

    /// `∂φ_d2/∂d2 = −D / (2 d2³ tan θ_F)` < 0: |φ_d2| falls monotonically with d2. Eq.
    /// ANALYSIS_D2_MONOTONE prints `+D/(2 d2³ tan θ_F) > 0`, the derivative of the mis-signed
    /// φ_d2; the paper's conclusion (the error shrinks with distance) stands.
    pub fn dphi_d2_dd2(&self) -> f64 {
        -self.width / (2.0 * self.d2.powi(3) * self.theta_f.tan())
    }

    /// Smallest working distance with `R(d2) ≥ (1 − tolerance) R(∞)`, m: closed form
    /// `D / (4 · tolerance · tan θ_F · R(∞))` (R increases monotonically towards R(∞)).
    /// `None` when `R(∞) ≤ 0` (the display then exceeds the frontal camera's view).
    pub fn d2_min(&self, side: Side, tolerance: f64) -> Option<f64> {
        let r_inf = self.cutting_ratio_at_infinity(side);
        (r_inf > 0.0 && tolerance > 0.0)
            .then(|| self.width / (4.0 * tolerance * self.theta_f.tan() * r_inf))
    }
}

/// Number of frontal-image columns to discard, `K_px = ⌊R · E_px⌉` (nearest integer).
pub fn k_px(ratio: f64, image_width_px: u32) -> i64 {
    (ratio * image_width_px as f64).round() as i64
}

/// Eye distance from the back camera, eq. d1: `A / (2 (A_px / E_px) tan θ_user)`.
/// `face_width` A in m, `face_px` and `image_px` in pixels, `half_angle` θ_user in rad.
pub fn head_distance(face_width: f64, face_px: f64, image_px: f64, half_angle: f64) -> f64 {
    face_width / (2.0 * (face_px / image_px) * half_angle.tan())
}

/// Lateral eye offset from the back camera's axis, eq. b_h: `2 (b_px / E_px) d1 tan θ_user`,
/// where `offset_px` is the face centre's signed distance from the image centre.
pub fn head_offset(offset_px: f64, image_px: f64, d1: f64, half_angle: f64) -> f64 {
    2.0 * (offset_px / image_px) * d1 * half_angle.tan()
}

/// The paper's occlusion setup (§4.2): a box of depth `L` standing on the scene plane at
/// distance `d2`; its near vertical edge at lateral `b1`; the eye at `d1` in front of the
/// display, at lateral `−b_h`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct OcclusionParams {
    pub l: f64,
    pub b1: f64,
    pub d2: f64,
    pub d1: f64,
    pub b_h: f64,
}

impl OcclusionParams {
    /// Width of the scene plane hidden behind the box's side, as seen by the frontal camera
    /// (signed; negative when the camera sees the box's side face instead).
    pub fn p_cam(&self) -> f64 {
        self.l * self.b1 / (self.d2 - self.l)
    }

    /// The same width as seen from the eye.
    pub fn p_user(&self) -> f64 {
        self.l * (self.b_h + self.b1) / (self.d1 + self.d2 - self.l)
    }

    /// Eq. OCLUSION: `b1 (d1 + d2 − L) / ((d2 − L)(b_h + b1))`.
    pub fn ratio(&self) -> f64 {
        let Self { l, b1, d2, d1, b_h } = *self;
        b1 * (d1 + d2 - l) / ((d2 - l) * (b_h + b1))
    }

    /// Eq. OCLUSION2, for `d2 ≫ L` and `d2 ≫ d1`: `b1 / (b_h + b1)`.
    pub fn ratio_far(&self) -> f64 {
        self.b1 / (self.b_h + self.b1)
    }

    /// Eq. OCLUSION3, for `b_h → 0`: `1 + d1 / (d2 − L)`. The paper's middle expression is
    /// this; its final form `1 − d1/(d2 − L)` has the wrong sign (erratum 3).
    pub fn ratio_small_bh(&self) -> f64 {
        1.0 + self.d1 / (self.d2 - self.l)
    }

    /// Eq. OCLUSION3's final form as printed.
    pub fn ratio_small_bh_as_printed(&self) -> f64 {
        1.0 - self.d1 / (self.d2 - self.l)
    }
}

/// The paper's foreshortening setup (§4.2): a flat surface of length `l` from its corner at
/// lateral `b1` on the scene plane (`d2`) away from the viewer at angle `γ` to the plane;
/// widths are projected onto the plane through the corner.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ForeshorteningParams {
    pub l: f64,
    pub b1: f64,
    pub d2: f64,
    pub d1: f64,
    pub b_h: f64,
    /// Angle between the surface and the scene plane, rad.
    pub gamma: f64,
}

impl ForeshorteningParams {
    /// Projected width seen by the frontal camera: `l (d2 cos γ − b1 sin γ) / (d2 + l sin γ)`.
    pub fn p_cam(&self) -> f64 {
        let (s, c) = self.gamma.sin_cos();
        self.l * (self.d2 * c - self.b1 * s) / (self.d2 + self.l * s)
    }

    /// Projected width seen from the eye.
    pub fn p_user(&self) -> f64 {
        let (s, c) = self.gamma.sin_cos();
        let d = self.d1 + self.d2;
        self.l * (d * c - (self.b_h + self.b1) * s) / (d + self.l * s)
    }

    /// The ratio's limit for `d2 → ∞`: 1 — except for a surface perpendicular to the plane
    /// (`γ = 90°`, the paper's own example), where the cosine terms vanish and the limit is
    /// `b1 / (b1 + b_h)`, the occlusion ratio's (erratum 4).
    pub fn ratio_far_limit(&self) -> f64 {
        if self.gamma.cos().abs() < 1e-12 {
            self.b1 / (self.b1 + self.b_h)
        } else {
            1.0
        }
    }

    /// Eq. FORESH1.
    pub fn ratio(&self) -> f64 {
        let Self {
            l,
            b1,
            d2,
            d1,
            b_h,
            gamma,
        } = *self;
        let (s, c) = gamma.sin_cos();
        (d1 + d2 + l * s) / (d2 + l * s) * (d2 * c - b1 * s) / ((d1 + d2) * c - (b_h + b1) * s)
    }
}
