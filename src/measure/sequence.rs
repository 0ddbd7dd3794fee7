//! A sequence measured frame by frame: at every displayed frame the truth is rendered at that
//! instant from the true eye, and the `seethru` view (what the system shows then, made from
//! the late capture and head estimate, [`SystemLoop`]) is measured against it with the
//! metrics of `run` (coverage beside every mean).

use std::time::Instant;

use anyhow::Result;
use glam::DVec3;
use obvhs::aabb::Aabb;

use crate::geometry::opencv::camera_json;
use crate::measure::hazard::{HAZARD_BOUND_ARCMIN, HazardSeen, hazard_seen};
use crate::measure::image_metrics::Flip;
use crate::measure::metrics::{MetricMaps, measure_with};
use crate::render::footprint::{PixelRect, footprint};
use crate::render::frame::Frame;
use crate::render::frame_over::FrameView;
use crate::render::integrator::RenderContext;
use crate::render::render_job::RenderJob;
use crate::render::settings::RenderSettings;
use crate::scene::world::view_bit;
use crate::scene::{Obstacle, Scene};
use crate::system::capture::{Capture, CaptureTruth};
use crate::system::head::CONFIDENT_HEAD;
use crate::system::head_estimate::true_yaw_from_camera_deg;
use crate::system::head_pose::HeadPose;
use crate::system::sequence::system_loop::{SequenceOptions, StageSeconds, SystemLoop};
use crate::system::sequence::timeline::FrameTimes;
use crate::util::number::short;
use crate::util::progress::Progress;

/// The metrics of one frame (from `measure`'s JSON).
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
    fn from_json(j: &serde_json::Value) -> FrameMetrics {
        let f = |v: &serde_json::Value| v.as_f64().unwrap_or(f64::NAN);
        let d = &j["display"];
        FrameMetrics {
            display_pixels: j["display_pixels"].as_u64().unwrap_or(0),
            coverage: f(&j["coverage"]),
            mean_arcmin: f(&d["misregistration_arcmin"]["mean"]),
            p95_arcmin: f(&d["misregistration_arcmin"]["p95"]),
            max_arcmin: f(&d["misregistration_arcmin"]["max"]),
            border_mean_arcmin: f(&j["border"]["misregistration_arcmin"]["mean"]),
            psnr_db: f(&d["psnr_db"]),
            ssim: f(&d["ssim"]),
            flip: f(&d["flip_mean"]),
            missing_fraction: f(&j["missing"]["fraction"]),
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
            "head estimate unreliable in {low} of {} frames (confidence < {CONFIDENT_HEAD}; lowest {worst:.2}, head sampled at t = {} s): frames.csv's head_confidence column has each (--require-confident-head makes this an error)",
            scored.len(),
            short(at)
        )
    })
}

/// The images of one measured frame, for the caller to write or collect.
pub struct FrameImages<'a> {
    pub record: &'a FrameRecord,
    pub truth: &'a Frame,
    pub seethru: &'a Frame,
    pub maps: &'a MetricMaps,
    /// The frame's metrics: `run`'s metrics.json content for this instant.
    pub metrics_json: &'a serde_json::Value,
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

/// The world box of the obstacle's body.
fn obstacle_box(o: &Obstacle) -> Aabb {
    let (lo, hi) = o.body_bounds();
    let mut b = Aabb::empty();
    for k in 0..8 {
        let pick = |bit: usize, l: f64, h: f64| if k & bit == 0 { l } else { h };
        let p = DVec3::new(
            pick(1, lo.x, hi.x),
            pick(2, lo.y, hi.y),
            pick(4, lo.z, hi.z),
        );
        b.extend(o.world_from_obstacle.transform_point3(p).as_vec3().into());
    }
    b
}

/// The union over the sequence of the driver-view pixels that can see the obstacle, grown by
/// a fifth of its size on each side.
fn window(system: &SystemLoop) -> PixelRect {
    let tl = system.options.timeline;
    let mut r: Option<PixelRect> = None;
    for k in 0..tl.frames() {
        let s = system.rig.scene_at(tl.times(k).display);
        let f = footprint(&s.driver, &obstacle_box(&s.obstacle));
        r = Some(r.map_or(f, |r| PixelRect {
            x0: r.x0.min(f.x0),
            y0: r.y0.min(f.y0),
            x1: r.x1.max(f.x1),
            y1: r.y1.max(f.y1),
        }));
    }
    let camera = system.rig.base.driver;
    r.unwrap_or(PixelRect::full(&camera)).grown(5, 2, &camera)
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
    metrics_json: serde_json::Value,
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
            metrics_json: serde_json::Value::Null,
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
        let images = self.maps.as_ref().map(|maps| FrameImages {
            record,
            truth: &self.truth,
            seethru: &self.seethru,
            maps,
            metrics_json: &self.metrics_json,
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
            vehicle_yaw_deg: (system.rig.vehicle.yaw_rate * times.display).to_degrees(),
            d2_used: shown.d2_used,
            metrics: None,
            hazards: Vec::new(),
        };
        if !self.how.metrics {
            system.render_seethru(&ctx, &mut self.seethru);
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
        self.seethru_region = system.render_seethru(&ctx, &mut self.seethru);
        let occluded = &self.occluded;
        let t1 = Instant::now();
        // Missing pixels are those the frontal camera, where it was at capture, cannot see.
        let mut measured = ctx.scene.clone();
        measured.frontal = shown.frontal;
        let (truth, seethru) = (&self.truth, &self.seethru);
        let (maps, json) = measure_with(
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
        record.metrics = Some(FrameMetrics::from_json(&json));
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
        self.metrics_json = json;
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

/// Renders the driver's truth view into `truth` within `region`, and the occluded view into
/// `occluded`: the truth with the pixels the obstacle and display change rendered again. The
/// measured sequence and the Python package's stepped sequence both make their frames so.
/// `occluded` holds the last frame's occluded view, and `last` is what this function
/// returned then (its re-rendered pixels): only `region` and `last` are copied from the
/// truth, since elsewhere neither view changed. Returns the pixels re-rendered this time.
pub fn render_truth_and_occluded(
    ctx: &RenderContext,
    settings: RenderSettings,
    region: PixelRect,
    truth: &mut Frame,
    occluded: &mut Frame,
    last: PixelRect,
) -> PixelRect {
    let driver = ctx.scene.driver;
    ctx.render_into(
        RenderJob::new(&driver, view_bit::TRUTH)
            .settings(settings)
            .region(region)
            .label("truth"),
        truth,
    );
    copy_rect(truth, occluded, union(region, last));
    let around = ctx.difference_region(&driver, view_bit::TRUTH, view_bit::OCCLUDED);
    ctx.render_into(
        RenderJob::new(&driver, view_bit::OCCLUDED)
            .settings(settings)
            .region(around)
            .label("occluded"),
        occluded,
    );
    around
}

/// No pixel.
const NOTHING: PixelRect = PixelRect {
    x0: 0,
    y0: 0,
    x1: 0,
    y1: 0,
};

/// The smallest rectangle holding `a` and `b` (an empty one holds nothing).
fn union(a: PixelRect, b: PixelRect) -> PixelRect {
    match (a.is_empty(), b.is_empty()) {
        (true, _) => b,
        (_, true) => a,
        _ => PixelRect {
            x0: a.x0.min(b.x0),
            y0: a.y0.min(b.y0),
            x1: a.x1.max(b.x1),
            y1: a.y1.max(b.y1),
        },
    }
}

/// Every AOV of the pixels of `rect` from `from` into `to` (frames of one size).
fn copy_rect(from: &Frame, to: &mut Frame, rect: PixelRect) {
    assert_eq!((from.width, from.height), (to.width, to.height));
    let (w, rect) = (from.width as usize, clip(rect, from));
    if rect.is_empty() {
        return;
    }
    for y in rect.y0 as usize..rect.y1 as usize {
        let at = y * w + rect.x0 as usize;
        to.copy_pixels(at, from, at, (rect.x1 - rect.x0) as usize);
    }
}

/// `rect` within `frame`.
fn clip(rect: PixelRect, frame: &Frame) -> PixelRect {
    PixelRect {
        x0: rect.x0.min(frame.width),
        y0: rect.y0.min(frame.height),
        x1: rect.x1.min(frame.width),
        y1: rect.y1.min(frame.height),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::render::frame::Pixel;

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

    /// The obstacle's body bounds are those of its triangles in the world the renderer
    /// traces (in the obstacle frame, where they are tight), for a flat display and for the
    /// cabin's curved one, whose surface bulges out of the flat box; and its world box holds
    /// every traced triangle (the cabin's pillar is turned about all three axes).
    #[test]
    fn the_obstacle_box_holds_the_traced_obstacle() {
        for name in ["das.toml", "cabin.toml"] {
            let scene = Scene::bundled(name);
            let world = crate::scene::world::World::build(&scene).unwrap();
            let (mut lo, mut hi) = (DVec3::INFINITY, DVec3::NEG_INFINITY);
            let mut traced = Aabb::empty();
            for (prim, t) in world.triangles.iter().enumerate() {
                if world.object_of(prim) != world.obstacle_id {
                    continue;
                }
                traced = traced.union(&t.aabb());
                let v0 = t.v0.as_dvec3();
                for v in [v0, v0 - t.e1.as_dvec3(), v0 + t.e2.as_dvec3()] {
                    let p = scene.obstacle.in_obstacle_frame(v);
                    (lo, hi) = (lo.min(p), hi.max(p));
                }
            }
            let (body_lo, body_hi) = scene.obstacle.body_bounds();
            let gap = (body_lo - lo).abs().max((body_hi - hi).abs());
            assert!(
                gap.max_element() < 1e-5,
                "{name}: {body_lo}..{body_hi} against {lo}..{hi}"
            );
            let b = obstacle_box(&scene.obstacle);
            let outside = (b.min - traced.min).max(traced.max - b.max);
            assert!(
                outside.max_element() < 1e-5,
                "{name}: {b:?} against {traced:?}"
            );
        }
    }

    /// The union of two rectangles, and of one with nothing.
    #[test]
    fn union_holds_both_rectangles_and_nothing_adds_nothing() {
        let a = PixelRect {
            x0: 4,
            y0: 5,
            x1: 9,
            y1: 7,
        };
        let b = PixelRect {
            x0: 2,
            y0: 6,
            x1: 6,
            y1: 11,
        };
        assert_eq!(
            union(a, b),
            PixelRect {
                x0: 2,
                y0: 5,
                x1: 9,
                y1: 11
            }
        );
        assert_eq!(union(NOTHING, a), a);
        assert_eq!(union(a, NOTHING), a);
        let empty_elsewhere = PixelRect {
            x0: 20,
            y0: 20,
            x1: 20,
            y1: 30,
        };
        assert_eq!(union(empty_elsewhere, b), b);
        assert_eq!(union(b, empty_elsewhere), b);
    }

    /// Every AOV of the rectangle's pixels is copied, and no other pixel, also when the
    /// rectangle runs past the frame.
    #[test]
    fn copy_rect_copies_the_rectangle_and_nothing_else() {
        let (w, h) = (7u32, 5u32);
        let pixels: Vec<Pixel> = (0..w * h)
            .map(|i| {
                let v = i as f32 + 1.0;
                Pixel {
                    color: glam::Vec3::splat(v),
                    depth: v,
                    camera_z: -v,
                    position: glam::Vec3::new(v, 0.0, 0.0),
                    normal: glam::Vec3::new(0.0, v, 0.0),
                    object_id: i + 1,
                    part_id: i + 2,
                }
            })
            .collect();
        let from = Frame::from_pixels(w, h, &pixels);
        for rect in [
            PixelRect {
                x0: 2,
                y0: 1,
                x1: 5,
                y1: 4,
            },
            PixelRect {
                x0: 5,
                y0: 3,
                x1: 100,
                y1: 100,
            },
        ] {
            let mut to = Frame::new(w, h);
            copy_rect(&from, &mut to, rect);
            for y in 0..h {
                for x in 0..w {
                    let inside = (rect.x0..rect.x1).contains(&x) && (rect.y0..rect.y1).contains(&y);
                    let want = if inside { from.pixel(x, y) } else { Pixel::SKY };
                    // Debug strings, since the sky's position is NaN.
                    let (got, want) = (format!("{:?}", to.pixel(x, y)), format!("{want:?}"));
                    assert_eq!(got, want, "({x}, {y}) of {rect:?}");
                }
            }
        }
    }
}
