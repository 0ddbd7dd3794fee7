//! The SAE J941 driver eyellipse (Class A vehicles, adjustable seat, seat track travel over
//! 133 mm, 95th percentile): its centre from the seat package, its axes and side-view tilt, and
//! seeded samples of driver eyes drawn from it.
//!
//! Numbers: SAE J941 as revised in 2002 and reissued without technical change in 2010-03
//! (J941_201003). Axis lengths (full lengths, 95th percentile, seat travel > 133 mm):
//! x 206.4 mm, y 60.3 mm, z 93.4 mm; plan-view and rear-view axes parallel to the vehicle grid;
//! side-view x axis tipped down at the front by [`TILT_DEG`]. Centre (cyclopean, vehicle grid,
//! mm): X = L1 + 664 + 0.587·L6 − 0.176·H30 − 12.5·t, Y = W20, Z = H8 + 638, with L1 the ball of
//! foot's X, L6 the steering-wheel centre's X distance from the ball of foot, H30 the SgRP's
//! height above the heel, t = 1 with a clutch pedal, W20 and H8 the SgRP's Y and Z.
//! The standard's text was not available here. Checked against public sources (listed in
//! docs/guide/cabin-pillar.md): the 2010 edition's "editorial changes only", the
//! tangent-cutoff meaning, the axes parallel to the grid in plan and rear view, and the 2002
//! axis-length changes (x +7.5, y −44.6, z +7.4 mm) that lead to the lengths used. The centre
//! coefficients and the 12° tilt are as commonly quoted and unverified against the standard
//! (the 2002 revision makes the tilt depend on seat height, which is not modelled).
//!
//! Sampling: the standard's ellipse is a tangent-cutoff ellipse: 95 % of eyes lie on the near
//! side of any one of its tangent planes. For a trivariate normal that fixes σ along each axis
//! at semi-axis / z₀.₉₅ = semi-axis / 1.645 (the 95th percentile of the normal's projection on
//! any direction is the ellipse's support there), which is what the samples use. (A 95 %
//! contour, σ = semi-axis / √χ²₃(0.95) = semi-axis / 2.795, is not the standard's meaning and
//! understates the spread of drivers 1.7 times; only 56 % of the samples lie inside the
//! ellipse itself, P(χ²₃ ≤ 1.645²).) Frames: vehicle grid x rearward, y to the driver's right, z up; the world
//! has +y up and the car facing −z, so world_from_vehicle maps (x, y, z) to (y, z, x).

use glam::{DMat3, DVec3};

/// Full axis lengths of the 95th-percentile eyellipse for seat travel over 133 mm, metres,
/// along the ellipse's own x (fore-aft), y (lateral), z (vertical).
pub const AXIS_LENGTHS_M: [f64; 3] = [0.2064, 0.0603, 0.0934];
/// Side-view tilt of the ellipse's x axis, degrees, front end down.
pub const TILT_DEG: f64 = 12.0;
/// The standard normal's 95th percentile: a tangent-cutoff 95th-percentile ellipse's semi-axis
/// in standard deviations.
pub const Z_95: f64 = 1.644_853_626_951_472_2;

/// The standard's inputs, in the world frame (metres) where they are points.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SeatPackage {
    /// Seating reference point, world metres: its lateral position is W20, its height H8.
    pub sgrp: DVec3,
    /// World z (fore-aft, the car facing −z) of the ball of foot on the accelerator, metres:
    /// L1, the ball of foot's X.
    pub ball_of_foot_z: f64,
    /// L6: steering-wheel centre's fore-aft distance from the ball of foot, metres in [0, 1.5].
    pub steering_l6: f64,
    /// H30: the SgRP's height above the heel point, metres in [0.127, 0.405] (Class A).
    pub seat_height_h30: f64,
    /// A clutch pedal (t = 1) moves the centre 12.5 mm forward.
    pub clutch: bool,
}

/// A 95th-percentile eyellipse placed in the world.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Eyellipse {
    /// Cyclopean eye centroid, world metres.
    pub centre: DVec3,
    /// Columns: the ellipse's x (rearward, tilted), y (driver's right), z (up, tilted) axes as
    /// world unit vectors.
    pub world_from_ellipse: DMat3,
    /// Semi-axis lengths along the ellipse's x, y, z, metres.
    pub semi_axes: DVec3,
}

/// World direction of a vehicle-grid vector (x rearward, y right, z up).
fn world_from_vehicle(v: DVec3) -> DVec3 {
    DVec3::new(v.y, v.z, v.x)
}

impl Eyellipse {
    /// The J941 95th-percentile eyellipse of a seat package.
    pub fn j941_95(seat: &SeatPackage) -> Eyellipse {
        let t = if seat.clutch { 1.0 } else { 0.0 };
        // Rearward offset from the ball of foot, mm (J941 centroid X formula).
        let x_mm = 664.0 + 0.587 * seat.steering_l6 * 1000.0
            - 0.176 * seat.seat_height_h30 * 1000.0
            - 12.5 * t;
        // World z is vehicle rearward, world y up, world x the driver's right.
        // Summed in millimetres, the standard's unit, so that round seat packages give round
        // eyes (0.562 m + 0.638 m is not 1.2 in binary, 562 mm + 638 mm is).
        let centre = DVec3::new(
            seat.sgrp.x,
            (seat.sgrp.y * 1000.0 + 638.0) / 1000.0,
            (seat.ball_of_foot_z * 1000.0 + x_mm) / 1000.0,
        );
        let beta = TILT_DEG.to_radians();
        // Rearward end up = front end down.
        let ex = world_from_vehicle(DVec3::new(beta.cos(), 0.0, beta.sin()));
        let ey = world_from_vehicle(DVec3::Y);
        let ez = world_from_vehicle(DVec3::new(-beta.sin(), 0.0, beta.cos()));
        Eyellipse {
            centre,
            world_from_ellipse: DMat3::from_cols(ex, ey, ez),
            semi_axes: DVec3::from(AXIS_LENGTHS_M) / 2.0,
        }
    }

    /// Standard deviations along the ellipse's axes, metres: the tangent-cutoff reading.
    pub fn sigmas(&self) -> DVec3 {
        self.semi_axes / Z_95
    }

    /// Distance from the centre to the tangent plane whose outward normal is `normal` (a world
    /// unit vector), metres: the ellipse's support function √(nᵀ R diag(a²) Rᵀ n).
    pub fn tangent_distance(&self, normal: DVec3) -> f64 {
        let local = self.world_from_ellipse.transpose() * normal;
        (local * self.semi_axes).length()
    }

    /// Covariance of the sampled eyes, world m²: R·diag(σ²)·Rᵀ.
    pub fn covariance(&self) -> DMat3 {
        let s = self.sigmas();
        let r = self.world_from_ellipse;
        r * DMat3::from_diagonal(s * s) * r.transpose()
    }

    /// Eye `index` of the sample seeded by `seed`: a function of (seed, index) only, so any
    /// subset is the same whatever order or thread computes it.
    pub fn sample(&self, seed: u64, index: u64) -> DVec3 {
        let mut state = seed ^ index.wrapping_mul(0x9E37_79B9_7F4A_7C15);
        let mut u = || {
            state = splitmix64(state);
            // 53 random bits in (0, 1]: never 0, so ln is finite.
            ((state >> 11) as f64 + 1.0) / (1u64 << 53) as f64
        };
        let (u1, u2, u3, u4) = (u(), u(), u(), u());
        let r1 = (-2.0 * u1.ln()).sqrt();
        let r2 = (-2.0 * u3.ln()).sqrt();
        let tau = std::f64::consts::TAU;
        let z = DVec3::new(
            r1 * (tau * u2).cos(),
            r1 * (tau * u2).sin(),
            r2 * (tau * u4).cos(),
        );
        self.centre + self.world_from_ellipse * (z * self.sigmas())
    }

    /// `n` eyes of the sample seeded by `seed`.
    pub fn samples(&self, seed: u64, n: usize) -> Vec<DVec3> {
        (0..n as u64).map(|i| self.sample(seed, i)).collect()
    }

    /// Squared normalised radius of `point`: 1 on the ellipse's surface.
    pub fn radius_squared(&self, point: DVec3) -> f64 {
        let local = self.world_from_ellipse.transpose() * (point - self.centre);
        (local / self.semi_axes).length_squared()
    }
}

/// SplitMix64's step: a well-mixed 64-bit hash of the state.
fn splitmix64(x: u64) -> u64 {
    let mut z = x.wrapping_add(0x9E37_79B9_7F4A_7C15);
    z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    z ^ (z >> 31)
}
