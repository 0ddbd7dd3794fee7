//! What a measured sequence records of each displayed frame: its times, eyes, vehicle pose,
//! metrics and hazards ([`FrameRecord`], [`FrameMetrics`]), and the head warning read from
//! them. Apart from the stepping that makes them (measure/sequence.rs): frames.csv, the
//! summary and the Python package read records without it.

use glam::DVec3;

use crate::measure::hazard::HazardSeen;
use crate::measure::metrics_json::Metrics;
use crate::system::head::CONFIDENT_HEAD;
use crate::system::head_pose::HeadPose;
use crate::system::sequence::timeline::FrameTimes;
use crate::util::number::short;

/// The metrics of one frame (of `measure`'s [`Metrics`]).
#[derive(Clone, Copy, Debug, Default, PartialEq, serde::Serialize)]
pub struct FrameMetrics {
    pub display_pixels: u64,
    /// Fraction of the display's pixels that show the scene.
    pub coverage: f64,
    /// Misregistration over the covered display pixels, arc-minutes.
    pub mean_arcmin: f64,
    pub p95_arcmin: f64,
    pub max_arcmin: f64,
    /// Mean misregistration in the border band, arc-minutes.
    pub border_mean_arcmin: f64,
    pub psnr_db: f64,
    pub ssim: f64,
    pub flip: f64,
    /// Fraction of display pixels whose truth point the frontal camera cannot see.
    pub missing_fraction: f64,
}

impl FrameMetrics {
    /// The frame's figures of its `metrics`.
    pub(crate) fn of(metrics: &Metrics) -> FrameMetrics {
        let d = &metrics.display;
        FrameMetrics {
            display_pixels: metrics.display_pixels as u64,
            coverage: metrics.coverage,
            mean_arcmin: d.misregistration_arcmin.mean,
            p95_arcmin: d.misregistration_arcmin.p95,
            max_arcmin: d.misregistration_arcmin.max,
            border_mean_arcmin: metrics.border.misregistration_arcmin.mean,
            psnr_db: d.psnr_db,
            ssim: d.ssim,
            flip: d.flip_mean,
            missing_fraction: metrics.missing.fraction,
        }
    }
}

/// One displayed frame.
#[derive(Clone, Debug)]
pub struct FrameRecord {
    pub frame: usize,
    pub times: FrameTimes,
    /// The true eye at display time, obstacle frame, m.
    pub eye_true: DVec3,
    /// The head estimate behind the image shown (of time `times.head`), obstacle frame, m.
    pub eye_estimated: DVec3,
    /// The eye the compensation used (predicted), obstacle frame, m.
    pub eye_used: DVec3,
    /// The image-based head estimate's confidence, [0, 1] (`None`: another head source).
    pub head_confidence: Option<f64>,
    /// The exposure of the frontal image shown (`None`: a camera without a sensor).
    pub frontal_exposure: Option<crate::geometry::sensor::Exposure>,
    /// The yaw fit of the image-based estimate on the mesh face: the fitted yaw from facing
    /// the back camera (degrees, positive towards the driver's left) and its margin, [0, 0.05]
    /// (`None`: the ellipsoid face or another head source).
    pub head_pose: Option<HeadPose>,
    /// The mesh face's true yaw from facing the back camera at the head sample's time,
    /// degrees, the convention of `head_pose` (`None`: the ellipsoid face).
    pub head_yaw_true_deg: Option<f64>,
    /// The vehicle's pivot (the eye at t = 0 carried along), world, m; its yaw, degrees.
    pub vehicle_position: DVec3,
    pub vehicle_yaw_deg: f64,
    pub d2_used: Option<f64>,
    /// `None` when the sequence runs without truth and metrics.
    pub metrics: Option<FrameMetrics>,
    /// Every `hazard = true` object, in scene order (empty without metrics).
    pub hazards: Vec<HazardSeen>,
}

/// The one-line warning when some frames' image-based head estimates were unreliable
/// (confidence below [`CONFIDENT_HEAD`]), else `None`.
pub fn head_warning(records: &[FrameRecord]) -> Option<String> {
    let scored: Vec<(f64, f64)> = records
        .iter()
        .filter_map(|r| r.head_confidence.map(|c| (c, r.times.head)))
        .collect();
    let low = scored.iter().filter(|(c, _)| *c < CONFIDENT_HEAD).count();
    let (worst, at) = scored.iter().copied().min_by(|a, b| a.0.total_cmp(&b.0))?;
    (low > 0).then(|| {
        format!(
            "head estimate unreliable in {low} of {} frames (confidence < {CONFIDENT_HEAD}; lowest {worst:.2}, head sampled at t = {} s): frames.csv's head_confidence column has each (option `require_confident_head` makes this an error)",
            scored.len(),
            short(at)
        )
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A frame whose head was sampled at `head_s` with confidence `confidence`.
    fn record(frame: usize, head_s: f64, confidence: Option<f64>) -> FrameRecord {
        FrameRecord {
            frame,
            times: FrameTimes {
                display: head_s,
                refresh: 0,
                refresh_time: head_s,
                capture: head_s,
                head: head_s,
            },
            eye_true: DVec3::ZERO,
            eye_estimated: DVec3::ZERO,
            eye_used: DVec3::ZERO,
            head_confidence: confidence,
            frontal_exposure: None,
            head_pose: None,
            head_yaw_true_deg: None,
            vehicle_position: DVec3::ZERO,
            vehicle_yaw_deg: 0.0,
            d2_used: None,
            metrics: None,
            hazards: Vec::new(),
        }
    }

    #[test]
    fn the_head_warning_counts_the_doubtful_frames_and_names_the_worst() {
        let c = CONFIDENT_HEAD;
        // Oracle frames (no confidence) are not scored; a confidence at the threshold is
        // confident.
        let records = [
            record(0, 0.0, None),
            record(1, 0.1, Some(c)),
            record(2, 0.2, Some(c - 0.2)),
            record(3, 0.3, Some(c - 0.1)),
            record(4, 0.4, Some(1.0)),
        ];
        let warning = head_warning(&records).unwrap();
        assert!(
            warning.starts_with(&format!(
                "head estimate unreliable in 2 of 4 frames (confidence < {c}; lowest {:.2}, head sampled at t = 0.2 s)",
                c - 0.2
            )),
            "{warning}"
        );
        // Every frame confident, or none scored: no warning.
        assert_eq!(head_warning(&records[..2]), None);
        assert_eq!(
            head_warning(&[records[4].clone(), records[1].clone()]),
            None
        );
        assert_eq!(head_warning(&records[..1]), None);
    }
}
