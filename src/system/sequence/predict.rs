//! Head prediction: the head estimate (old by the tracking and camera latencies) carried
//! forward to the time its frame is shown — the thing a product would add.

use glam::DVec3;

/// How the head estimate is carried to display time.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum, serde::Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum Prediction {
    /// The latest estimate as it is.
    None,
    /// The latest estimate plus the velocity of the last two, times the age.
    ConstantVelocity,
    /// A constant-velocity Kalman filter per axis over every estimate, extrapolated.
    Kalman,
}

/// Process noise of the Kalman filter: white acceleration of this spectral density,
/// m²/s³ (a lean of 10 cm in 0.3 s peaks near 5 m/s²).
pub const KALMAN_ACCELERATION_DENSITY: f64 = 4.0;

/// One axis of the constant-velocity Kalman filter: state (position, velocity) and its
/// covariance.
#[derive(Clone, Copy, Debug)]
struct Axis {
    x: [f64; 2],
    p: [[f64; 2]; 2],
}

impl Axis {
    fn new(z: f64, r: f64) -> Axis {
        Axis {
            x: [z, 0.0],
            p: [[r, 0.0], [0.0, 1.0]],
        }
    }

    fn step(&mut self, dt: f64, z: f64, r: f64) {
        let q = KALMAN_ACCELERATION_DENSITY;
        let [p, v] = self.x;
        let [[a, b], [c, d]] = self.p;
        // Predict: F = [[1, dt], [0, 1]], Q = q [[dt³/3, dt²/2], [dt²/2, dt]].
        let x = [p + v * dt, v];
        let p00 = a + dt * (b + c) + dt * dt * d + q * dt.powi(3) / 3.0;
        let p01 = b + dt * d + q * dt * dt / 2.0;
        let p10 = c + dt * d + q * dt * dt / 2.0;
        let p11 = d + q * dt;
        // Update with a position measurement of variance r.
        let s = p00 + r;
        let (k0, k1) = (p00 / s, p10 / s);
        let y = z - x[0];
        self.x = [x[0] + k0 * y, x[1] + k1 * y];
        self.p = [
            [(1.0 - k0) * p00, (1.0 - k0) * p01],
            [p10 - k1 * p00, p11 - k1 * p01],
        ];
    }
}

/// Head estimates in, predictions out. Estimates must come in increasing time.
pub struct Predictor {
    kind: Prediction,
    /// Standard deviation of one estimate, m (the filter's measurement noise).
    sigma: f64,
    last: Option<(f64, DVec3)>,
    previous: Option<(f64, DVec3)>,
    kalman: Option<[Axis; 3]>,
}

impl Predictor {
    pub fn new(kind: Prediction, sigma: f64) -> Predictor {
        Predictor {
            kind,
            sigma: sigma.max(1e-4),
            last: None,
            previous: None,
            kalman: None,
        }
    }

    /// A head estimate `eye` (obstacle frame, m) of time `t` (s).
    pub fn observe(&mut self, t: f64, eye: DVec3) {
        if let Some((t0, _)) = self.last
            && t <= t0
        {
            return;
        }
        let r = self.sigma * self.sigma;
        let dt = self.last.map_or(0.0, |(t0, _)| t - t0);
        self.previous = self.last;
        self.last = Some((t, eye));
        match &mut self.kalman {
            None => self.kalman = Some(eye.to_array().map(|z| Axis::new(z, r))),
            Some(axes) => {
                for (axis, z) in axes.iter_mut().zip(eye.to_array()) {
                    axis.step(dt, z, r);
                }
            }
        }
    }

    /// The eye predicted for time `t`.
    pub fn predict(&self, t: f64) -> DVec3 {
        let Some((t1, e1)) = self.last else {
            return DVec3::NAN;
        };
        match (self.kind, self.previous) {
            (Prediction::None, _) => e1,
            (Prediction::ConstantVelocity, Some((t0, e0))) => e1 + (e1 - e0) / (t1 - t0) * (t - t1),
            (Prediction::ConstantVelocity, None) => e1,
            (Prediction::Kalman, _) => {
                let axes = self.kalman.expect("observed");
                DVec3::from_array(axes.map(|a| a.x[0] + a.x[1] * (t - t1)))
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn predictions_of_a_constant_velocity_eye_are_exact() {
        let eye = |t: f64| DVec3::new(0.3 + 0.2 * t, 0.0, 0.7 - 0.1 * t);
        for kind in [Prediction::ConstantVelocity, Prediction::Kalman] {
            let mut p = Predictor::new(kind, 1e-4);
            for k in 0..200 {
                p.observe(k as f64 / 60.0, eye(k as f64 / 60.0));
            }
            let t = 199.0 / 60.0 + 0.1;
            assert!((p.predict(t) - eye(t)).length() < 1e-4, "{kind:?}");
        }
        let mut none = Predictor::new(Prediction::None, 1e-3);
        none.observe(0.0, eye(0.0));
        none.observe(1.0, eye(1.0));
        assert_eq!(none.predict(2.0), eye(1.0));
    }

    type M = [[f64; 2]; 2];

    /// One step of the textbook Kalman recursion in 2 × 2 matrices: predict x = F x,
    /// P = F P Fᵀ + Q; update with H = [1, 0], K = P Hᵀ / (H P Hᵀ + r), P = (I − K H) P.
    fn textbook_step(x: [f64; 2], p: M, dt: f64, z: f64, r: f64) -> ([f64; 2], M) {
        let mul = |a: M, b: M| -> M {
            std::array::from_fn(|i| std::array::from_fn(|j| a[i][0] * b[0][j] + a[i][1] * b[1][j]))
        };
        let transpose = |a: M| -> M { [[a[0][0], a[1][0]], [a[0][1], a[1][1]]] };
        let f: M = [[1.0, dt], [0.0, 1.0]];
        let q = KALMAN_ACCELERATION_DENSITY;
        let noise: M = [
            [q * dt.powi(3) / 3.0, q * dt * dt / 2.0],
            [q * dt * dt / 2.0, q * dt],
        ];
        let spread = mul(mul(f, p), transpose(f));
        let predicted: M =
            std::array::from_fn(|i| std::array::from_fn(|j| spread[i][j] + noise[i][j]));
        let ahead = [x[0] + dt * x[1], x[1]];
        let s = predicted[0][0] + r;
        let gain = [predicted[0][0] / s, predicted[1][0] / s];
        let innovation = z - ahead[0];
        (
            [
                ahead[0] + gain[0] * innovation,
                ahead[1] + gain[1] * innovation,
            ],
            mul([[1.0 - gain[0], 0.0], [-gain[1], 1.0]], predicted),
        )
    }

    /// Uneven steps (10–90 ms) and noisy positions, so that every term matters.
    fn noisy_track(k: usize) -> (f64, f64) {
        let t: f64 = (1..=k).map(|i| 0.01 + 0.02 * ((i * 7) % 5) as f64).sum();
        let z = 0.5 + 0.1 * (3.0 * t).sin() + 0.002 * ((k * 13 % 7) as f64 - 3.0);
        (t, z)
    }

    fn close(a: f64, b: f64) -> bool {
        (a - b).abs() <= 1e-12 * (1.0 + b.abs())
    }

    /// The filter's step against the textbook recursion: state and covariance, every step.
    #[test]
    fn a_kalman_step_is_the_textbook_recursion() {
        let r = 0.003f64.powi(2);
        let mut axis = Axis::new(0.5, r);
        let (mut x, mut p): ([f64; 2], M) = ([0.5, 0.0], [[r, 0.0], [0.0, 1.0]]);
        for k in 1..40 {
            let ((t, z), (t_before, _)) = (noisy_track(k), noisy_track(k - 1));
            let dt = t - t_before;
            axis.step(dt, z, r);
            (x, p) = textbook_step(x, p, dt, z, r);
            for i in 0..2 {
                assert!(close(axis.x[i], x[i]), "step {k}: x {:?} vs {x:?}", axis.x);
                for j in 0..2 {
                    assert!(
                        close(axis.p[i][j], p[i][j]),
                        "step {k}: P {:?} vs {p:?}",
                        axis.p
                    );
                }
            }
        }
    }

    /// The Kalman predictor is the textbook filter on each axis with the measurement variance
    /// σ², extrapolated by its velocity; a repeated or older estimate is ignored.
    #[test]
    fn the_kalman_predictor_filters_each_axis_with_variance_sigma_squared() {
        let sigma = 0.004;
        let mut predictor = Predictor::new(Prediction::Kalman, sigma);
        let (t0, z0) = noisy_track(0);
        let (mut x, mut p): ([f64; 2], M) = ([z0, 0.0], [[sigma * sigma, 0.0], [0.0, 1.0]]);
        predictor.observe(t0, DVec3::new(z0, 0.7, -z0));
        for k in 1..30 {
            let (t, z) = noisy_track(k);
            predictor.observe(t, DVec3::new(z, 0.7, -z));
            predictor.observe(t, DVec3::new(9.0, 9.0, 9.0));
            predictor.observe(t - 1e-3, DVec3::new(9.0, 9.0, 9.0));
            (x, p) = textbook_step(x, p, t - noisy_track(k - 1).0, z, sigma * sigma);
            let ahead = t + 0.05;
            let predicted = predictor.predict(ahead);
            let expected = x[0] + x[1] * 0.05;
            assert!(
                close(predicted.x, expected),
                "step {k}: {predicted} vs {expected}"
            );
            assert!(close(predicted.z, -expected), "step {k}: {predicted}");
        }
    }
}
