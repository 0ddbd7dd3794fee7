//! `--head model`: a head tracker as a statistical model instead of an image to detect in —
//! the true eye, late by the tracker's latency, plus its bias and Gaussian noise, with a
//! share of samples dropped (the system then keeps the last estimate). It lets a sweep ask
//! what tracker accuracy a pillar needs without rendering the back camera.
//!
//! The one class modelled is a monocular RGB face-landmark tracker of the MediaPipe Iris
//! kind; where each figure comes from, and which are not published, is in
//! docs/guide/hazards.md.

use glam::DVec3;
use serde::Serialize;

use crate::system::head::gaussian;
use crate::util::sampling::{hash_words, unit_float};

/// The tracker's error model, obstacle frame (x across, y up, z the distance from the display
/// plane towards the driver: about the back camera's depth axis).
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct TrackerModel {
    /// The tracker class, in words.
    pub class: &'static str,
    /// Constant error added to every estimate, obstacle frame, metres.
    pub bias_m: [f64; 3],
    /// Standard deviation of the noise across and up (x, y), metres, ≥ 0.
    pub sigma_lateral_m: f64,
    /// Standard deviation of the noise in depth (z) as a fraction of the eye's depth, ≥ 0.
    pub sigma_depth_fraction: f64,
    /// Probability that a sample is dropped (no estimate), [0, 1).
    pub dropout: f64,
    /// Age of an estimate when it is delivered, seconds, ≥ 0 (`sequence` only: a single `run`
    /// has a still head).
    pub latency_s: f64,
}

/// A monocular RGB webcam face-landmark tracker (MediaPipe Iris class), 30 frames/s.
pub const WEBCAM_LANDMARKS: TrackerModel = TrackerModel {
    class: "monocular RGB face-landmark tracker (MediaPipe Iris class), 30 frames/s",
    bias_m: [0.0; 3],
    sigma_lateral_m: 0.002,
    sigma_depth_fraction: 0.05,
    dropout: 0.05,
    latency_s: 1.0 / 30.0,
};

/// Seed salts, so that the model's draws are independent of `--head-jitter-cm`'s.
const NOISE_SALT: u32 = 0x6d6f_6465;
const DROP_SALT: u32 = 0x6472_6f70;

impl TrackerModel {
    /// Sample `index` of the tracker looking at the eye `eye` (obstacle frame, m): `None`
    /// when the sample is dropped. Deterministic in (seed, index).
    pub fn sample(&self, eye: DVec3, seed: u32, index: u32) -> Option<DVec3> {
        if (unit_float(hash_words(&[seed, index, DROP_SALT])) as f64) < self.dropout {
            return None;
        }
        let s = seed ^ NOISE_SALT;
        let i = index.wrapping_mul(3);
        let noise = DVec3::new(
            gaussian(s, i) * self.sigma_lateral_m,
            gaussian(s, i.wrapping_add(1)) * self.sigma_lateral_m,
            gaussian(s, i.wrapping_add(2)) * self.sigma_depth_fraction * eye.z.abs(),
        );
        Some(eye + DVec3::from_array(self.bias_m) + noise)
    }

    /// Sample `index`, or where it is dropped the `last` estimate; with no last one (the
    /// first sample dropped), the next sample that is not. Returns it and whether `index`
    /// was dropped.
    pub fn sample_or_hold(
        &self,
        eye: DVec3,
        seed: u32,
        index: u32,
        last: Option<DVec3>,
    ) -> (DVec3, bool) {
        if let Some(e) = self.sample(eye, seed, index) {
            return (e, false);
        }
        if let Some(e) = last {
            return (e, true);
        }
        // Dropout < 1: a sample that is kept comes within a few draws (P(64 drops) < 1e-6
        // at 80%); the last resort is the noiseless eye.
        let kept = (1..=64)
            .find_map(|k| self.sample(eye, seed, index.wrapping_add(k)))
            .unwrap_or(eye + DVec3::from_array(self.bias_m));
        (kept, true)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_noise_has_the_stated_standard_deviation_and_bias() {
        let model = TrackerModel {
            bias_m: [0.01, -0.02, 0.0],
            dropout: 0.0,
            ..WEBCAM_LANDMARKS
        };
        let eye = DVec3::new(0.1, 0.0, 0.8);
        let n = 20_000;
        let errors: Vec<DVec3> = (0..n)
            .map(|i| model.sample(eye, 11, i).unwrap() - eye)
            .collect();
        let mean = errors.iter().sum::<DVec3>() / n as f64;
        let sd = (errors
            .iter()
            .map(|e| (*e - mean) * (*e - mean))
            .sum::<DVec3>()
            / n as f64)
            .powf(0.5);
        let expected = DVec3::new(0.002, 0.002, 0.05 * 0.8);
        // Sampling errors: σ/√n for the mean, σ/√(2n) (0.5%) for the deviation; 5 of them.
        let se_mean = expected / (n as f64).sqrt();
        assert!(
            ((mean - DVec3::from_array(model.bias_m)).abs())
                .cmple(5.0 * se_mean)
                .all(),
            "{mean}"
        );
        assert!(
            ((sd - expected).abs())
                .cmple(expected * 5.0 / (2.0 * n as f64).sqrt())
                .all(),
            "{sd} vs {expected}"
        );
        // Seeded: the same draws for the same seed, others for another.
        assert_eq!(model.sample(eye, 11, 5), model.sample(eye, 11, 5));
        assert_ne!(model.sample(eye, 11, 5), model.sample(eye, 12, 5));
    }

    #[test]
    fn samples_drop_at_the_stated_rate_and_the_last_estimate_is_held() {
        let eye = DVec3::new(0.0, 0.0, 0.8);
        let n = 40_000;
        let dropped = (0..n)
            .filter(|&i| WEBCAM_LANDMARKS.sample(eye, 3, i).is_none())
            .count() as f64
            / n as f64;
        let p = WEBCAM_LANDMARKS.dropout;
        let se = (p * (1.0 - p) / n as f64).sqrt();
        assert!((dropped - p).abs() < 5.0 * se, "{dropped} vs {p}");
        let i = (0..n)
            .find(|&i| WEBCAM_LANDMARKS.sample(eye, 3, i).is_none())
            .unwrap();
        let last = DVec3::new(1.0, 2.0, 3.0);
        assert_eq!(
            WEBCAM_LANDMARKS.sample_or_hold(eye, 3, i, Some(last)),
            (last, true)
        );
        let (first, dropped) = WEBCAM_LANDMARKS.sample_or_hold(eye, 3, i, None);
        assert!(dropped && (first - eye).length() < 0.3, "{first}");
    }
}
