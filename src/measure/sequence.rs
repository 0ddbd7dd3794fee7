//! A sequence measured frame by frame: at every displayed frame the truth is rendered at that
//! instant from the true eye, and the `seethru` view (what the system shows then, made from
//! the late capture and head estimate, [`SystemLoop`]) is measured against it with the
//! metrics of `run` (coverage beside every mean).
//!
//! What each frame records is measure/sequence_records.rs's; which driver-view pixels are
//! rendered (the window, the truth and occluded views where they change) is
//! measure/sequence_regions.rs's.

use std::time::Instant;

use anyhow::Result;

use crate::geometry::opencv::camera_json;
use crate::measure::hazard::{HAZARD_BOUND_ARCMIN, hazard_seen};
use crate::measure::image_metrics::Flip;
use crate::measure::metrics::{MetricMaps, measure_with};
use crate::measure::metrics_json::Metrics;
use crate::measure::sequence_records::{FrameMetrics, FrameRecord};
use crate::measure::sequence_regions::{
    NOTHING, copy_rect, render_truth_and_occluded, union, window,
};
use crate::render::footprint::PixelRect;
use crate::render::frame::Frame;
use crate::render::frame_over::FrameView;
use crate::render::settings::RenderSettings;
use crate::scene::Scene;
use crate::system::capture::{Capture, CaptureTruth};
use crate::system::head_estimate::true_yaw_from_camera_deg;
use crate::system::sequence::system_loop::{SequenceOptions, StageSeconds, SystemLoop};
use crate::system::sequence::timeline::FrameTimes;
use crate::util::progress::Progress;

/// The images of one measured frame, for the caller to write or collect.
pub struct FrameImages<'a> {
    pub record: &'a FrameRecord,
    pub truth: &'a Frame,
    pub seethru: &'a Frame,
    pub maps: &'a MetricMaps,
    /// The frame's metrics: `run`'s metrics.json for this instant.
    pub metrics: &'a Metrics,
    /// The driver-view pixels rendered for every frame (the display's neighbourhood over the
    /// whole sequence), where previews are cut.
    pub window: PixelRect,
    /// With `byo.capture`, at the first frame showing a refresh: that refresh's inputs, and
    /// as its truth this frame's whole truth view and true eye.
    pub capture: Option<Capture>,
}

/// What a sequence produced besides its frames.
pub struct SequenceRun {
    pub records: Vec<FrameRecord>,
    /// The system's stages.
    pub system: StageSeconds,
    /// Truth, `occluded` and metrics, seconds.
    pub truth_seconds: f64,
    pub metrics_seconds: f64,
    /// Wall time of making and measuring the frames ([`SequenceStepper::step`]): the
    /// setup and what the caller does with each frame (writing files) excluded, seconds.
    pub stepping_seconds: f64,
    pub total_seconds: f64,
    pub window: PixelRect,
    /// Frontal pixels rendered per refresh, on average.
    pub frontal_pixels_per_refresh: f64,
}

/// How a sequence is measured.
#[derive(Clone, Copy, Debug)]
pub struct Measuring {
    /// Render the truth and compute the metrics (else only the system's loop runs).
    pub metrics: bool,
    /// Render whole driver views (else only the window around the display).
    pub full_frames: bool,
    /// Border band, display pixels.
    pub band: u32,
    pub progress: bool,
    /// FLIP for every frame (else its column is NaN): a third of the metrics' time.
    pub flip: Flip,
}

/// Runs and measures a sequence; `on_frame` gets every measured frame's images in order.
pub fn run_sequence(
    scene: &Scene,
    options: SequenceOptions,
    how: Measuring,
    on_frame: &mut dyn FnMut(FrameImages) -> Result<()>,
) -> Result<SequenceRun> {
    run_sequence_labelled(scene, options, how, "sequence", on_frame)
}

/// As [`run_sequence`], its progress bar labelled `label` (which of several sequences runs).
pub fn run_sequence_labelled(
    scene: &Scene,
    options: SequenceOptions,
    how: Measuring,
    label: &str,
    on_frame: &mut dyn FnMut(FrameImages) -> Result<()>,
) -> Result<SequenceRun> {
    run_sequence_hazards(scene, options, how, HAZARD_BOUND_ARCMIN, label, on_frame)
}

/// As [`run_sequence_labelled`], hazard visibility scored within `hazard_bound_arcmin`.
pub fn run_sequence_hazards(
    scene: &Scene,
    options: SequenceOptions,
    how: Measuring,
    hazard_bound_arcmin: f64,
    label: &str,
    on_frame: &mut dyn FnMut(FrameImages) -> Result<()>,
) -> Result<SequenceRun> {
    let mut stepper = SequenceStepper::new(scene, options, how, hazard_bound_arcmin)?;
    let progress = Progress::new(label, stepper.frames(), how.progress);
    while let Some(step) = stepper.step()? {
        if let Some(images) = step.images {
            on_frame(images)?;
        }
        progress.advance(1);
    }
    progress.finish();
    Ok(stepper.finish())
}

/// A sequence made and measured one displayed frame at a time ([`SequenceStepper::step`]):
/// what [`run_sequence`] drives for the command line, and the Python package's iterator,
/// which may give the system the eye to compensate for before each refresh
/// ([`SystemLoop::eye_given`] of [`SequenceStepper::system`]).
pub struct SequenceStepper {
    /// The system's loop; its timeline and rig tell the next frame's times and eyes.
    pub system: SystemLoop,
    /// The scene's hazard objects are scored from it.
    scene: Scene,
    how: Measuring,
    hazard_bound_arcmin: f64,
    settings: RenderSettings,
    window: PixelRect,
    /// The driver-view pixels rendered for the truth: the window, or the whole view.
    region: PixelRect,
    truth: Frame,
    seethru: Frame,
    /// The occluded view, kept between frames: only what changes is copied and rendered.
    occluded: Frame,
    /// The pixels of `seethru` and `occluded` rendered over the truth at the last frame.
    seethru_region: PixelRect,
    occluded_region: PixelRect,
    /// The capture of the last frame made, until [`SequenceStepper::step`] hands it out.
    capture: Option<Capture>,
    maps: Option<MetricMaps>,
    metrics: Option<Metrics>,
    records: Vec<FrameRecord>,
    refreshes: std::collections::BTreeSet<i64>,
    truth_seconds: f64,
    metrics_seconds: f64,
    stepping_seconds: f64,
    start: Instant,
}

/// One frame from [`SequenceStepper::step`].
pub struct FrameStep<'a> {
    pub record: &'a FrameRecord,
    /// The frame's images and maps (`None` when the sequence runs without truth and metrics).
    pub images: Option<FrameImages<'a>>,
}

impl SequenceStepper {
    /// The system's loop for `options` on `scene`, nothing rendered yet.
    pub fn new(
        scene: &Scene,
        options: SequenceOptions,
        how: Measuring,
        hazard_bound_arcmin: f64,
    ) -> Result<SequenceStepper> {
        let start = Instant::now();
        let system = SystemLoop::new(scene, options)?;
        let settings = RenderSettings {
            spp: system.options.run.spp,
            progress: false,
        };
        let window = window(&system);
        let camera = system.rig.base.driver;
        // A captured frame's truth is the whole view, as `seethru capture`'s.
        let region = if how.full_frames || system.options.byo.capture {
            PixelRect::full(&camera)
        } else {
            window
        };
        let truth = Frame::new(camera.width, camera.height);
        let frames = system.options.timeline.frames();
        Ok(SequenceStepper {
            seethru: truth.clone(),
            occluded: truth.clone(),
            seethru_region: NOTHING,
            occluded_region: NOTHING,
            capture: None,
            truth,
            system,
            scene: scene.clone(),
            how,
            hazard_bound_arcmin,
            settings,
            window,
            region,
            maps: None,
            metrics: None,
            records: Vec::with_capacity(frames),
            refreshes: Default::default(),
            truth_seconds: 0.0,
            metrics_seconds: 0.0,
            stepping_seconds: 0.0,
            start,
        })
    }

    /// Frames displayed in all.
    pub fn frames(&self) -> usize {
        self.system.options.timeline.frames()
    }

    /// The index of the frame the next [`SequenceStepper::step`] makes, `None` after the last.
    pub fn next_frame(&self) -> Option<usize> {
        let k = self.records.len();
        (k < self.frames()).then_some(k)
    }

    /// The frames made so far.
    pub fn records(&self) -> &[FrameRecord] {
        &self.records
    }

    /// Makes and measures the next displayed frame; `None` after the last.
    pub fn step(&mut self) -> Result<Option<FrameStep<'_>>> {
        let start = Instant::now();
        let made = self.make_step()?;
        self.stepping_seconds += start.elapsed().as_secs_f64();
        Ok(if made { Some(self.last_step()) } else { None })
    }

    /// The frame [`SequenceStepper::make_step`] made last.
    fn last_step(&mut self) -> FrameStep<'_> {
        let capture = self.capture.take();
        let record = self.records.last().expect("a frame was made");
        let measured = self.maps.as_ref().zip(self.metrics.as_ref());
        let images = measured.map(|(maps, metrics)| FrameImages {
            record,
            truth: &self.truth,
            seethru: &self.seethru,
            maps,
            metrics,
            window: self.window,
            capture,
        });
        FrameStep { record, images }
    }

    /// Makes and measures the next displayed frame; false after the last.
    fn make_step(&mut self) -> Result<bool> {
        let Some(k) = self.next_frame() else {
            return Ok(false);
        };
        let system = &mut self.system;
        let times = system.options.timeline.times(k);
        let shown = system.show(k)?.clone();
        self.refreshes.insert(shown.times.refresh);
        let ctx = system.context_at(times.display)?;
        let rig = system.rig.world_from_rig(times.display);
        let mut record = FrameRecord {
            frame: k,
            times: FrameTimes {
                display: times.display,
                ..shown.times
            },
            eye_true: system.rig.eye_in_obstacle(times.display),
            eye_estimated: shown.eye_estimated,
            eye_used: shown.eye_used,
            head_confidence: shown.head_confidence,
            frontal_exposure: shown.frontal_exposure,
            head_pose: shown.head_pose,
            head_yaw_true_deg: {
                let base = &system.rig.base;
                let eye = system.rig.eye_in_obstacle(shown.times.head);
                true_yaw_from_camera_deg(
                    base.face,
                    base.obstacle.world_from_obstacle.transform_point3(eye),
                    base.back.position(),
                )
            },
            vehicle_position: rig.transform_point3(system.rig.vehicle.pivot),
            vehicle_yaw_deg: system.rig.vehicle.yaw_at(times.display).to_degrees(),
            d2_used: shown.d2_used,
            metrics: None,
            hazards: Vec::new(),
        };
        if !self.how.metrics {
            system.render_seethru(&ctx, times.display, &mut self.seethru);
            self.records.push(record);
            return Ok(true);
        }
        let t0 = Instant::now();
        let driver = ctx.scene.driver;
        self.occluded_region = render_truth_and_occluded(
            &ctx,
            self.settings,
            self.region,
            &mut self.truth,
            &mut self.occluded,
            self.occluded_region,
        );
        self.truth_seconds += t0.elapsed().as_secs_f64();
        // `seethru` is the truth but where the display and the obstacle can be: the pixels
        // the truth or the last `seethru` changed are copied, the rest already are the truth.
        copy_rect(
            &self.truth,
            &mut self.seethru,
            union(self.region, self.seethru_region),
        );
        self.seethru_region = system.render_seethru(&ctx, times.display, &mut self.seethru);
        let occluded = &self.occluded;
        let t1 = Instant::now();
        // Missing pixels are those the frontal camera, where it was at capture, cannot see.
        let mut measured = ctx.scene.clone();
        measured.frontal = shown.frontal;
        let (truth, seethru) = (&self.truth, &self.seethru);
        let (maps, metrics) = measure_with(
            &ctx,
            &measured,
            driver.position(),
            [truth, seethru, occluded].map(FrameView::from),
            self.how.band,
            self.how.flip,
        );
        record.hazards = hazard_seen(
            &self.scene,
            [truth, seethru, occluded],
            &maps,
            self.hazard_bound_arcmin,
            driver.central_pixel_arcmin(),
        );
        self.metrics_seconds += t1.elapsed().as_secs_f64();
        record.metrics = Some(FrameMetrics::of(&metrics));
        let capture = system.take_inputs().map(|i| Capture {
            frontal: i.frontal,
            back: i.back,
            depth: None,
            head: i.head,
            calibration: i.calibration,
            fingerprint: i.fingerprint,
            truth: CaptureTruth {
                eye_world_m: driver.position(),
                truth: truth.clone(),
                cameras: serde_json::json!({
                    "frontal": camera_json(&shown.frontal),
                    "back": camera_json(&i.back_true),
                    "driver_view": camera_json(&driver),
                    "note": "the true frontal camera at the capture time, back camera at the head-sample time and the driver's view camera at the display time, OpenCV's conventions as in calibration.json",
                }),
            },
        });
        self.records.push(record);
        self.maps = Some(maps);
        self.metrics = Some(metrics);
        self.capture = capture;
        Ok(true)
    }

    /// What the sequence produced besides its frames, once every frame is made.
    pub fn finish(self) -> SequenceRun {
        let refreshes = self.refreshes.len().max(1);
        SequenceRun {
            records: self.records,
            system: self.system.seconds,
            truth_seconds: self.truth_seconds,
            metrics_seconds: self.metrics_seconds,
            stepping_seconds: self.stepping_seconds,
            total_seconds: self.start.elapsed().as_secs_f64(),
            window: self.window,
            frontal_pixels_per_refresh: self.system.frontal_pixels as f64 / refreshes as f64,
        }
    }
}
