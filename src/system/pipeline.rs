//! The see-through system end to end (paper §3): the back camera finds the head, the planar
//! model crops the frontal render, the display shows it, and the driver's view with the
//! display in it is rendered beside the ground truth.

use std::sync::{Arc, OnceLock};
use std::time::Instant;

use anyhow::{Context, Result, bail};
use glam::{DVec2, DVec3};
use serde_json::json;

use crate::geometry::camera::Camera;
use crate::geometry::homography::homography;
use crate::render::frame::Frame;
use crate::render::frame_over::{FrameOver, FrameView};
use crate::render::integrator::RenderContext;
use crate::render::render_job::RenderJob;
use crate::render::settings::{RenderSettings, check_spp};
use crate::render::views::View;
use crate::scene::world::view_bit;
use crate::scene::{Obstacle, Scene};
use crate::system::compensation::{Crop, ModelPlane, compute_crop};
use crate::system::display::{
    DisplayModel, DisplayPlacement, DisplaySurface, IdealMap, MISSING_ID, resample_through,
};
use crate::system::frontal_map::FrontalMap;
use crate::system::head::{FaceDetection, gaussian};
use crate::system::head_estimate::{HeadFix, estimate};
use crate::system::head_pose::HeadPose;
use crate::system::options::{HeadSource, Method, Outside, RunOptions, WorkingDistance};
use crate::system::report::report;
use crate::system::scene_model::{check_scene_model, scene_model_display};
use crate::system::tracker_model::WEBCAM_LANDMARKS;
use crate::util::memory::peak_rss_bytes;
use crate::util::number::short;

/// Everything a run produces.
pub struct RunResult {
    /// Shared with `occluded` and `seethru`, which are it outside the obstacle's footprint.
    pub truth: Arc<Frame>,
    pub occluded: FrameOver,
    pub frontal: Frame,
    pub back: Frame,
    pub display: Frame,
    pub seethru: FrameOver,
    pub crop: Crop,
    /// The eye the compensation used, world frame.
    pub eye_used: DVec3,
    pub detection: Option<FaceDetection>,
    /// The yaw fit of `--head estimated` on the mesh face ([`crate::scene::DriverFace`]).
    pub head_pose: Option<HeadPose>,
    /// Display pixels (row-major) that are disocclusion holes: `--method depth` only.
    pub holes: Option<Vec<bool>>,
    /// Fraction of the display's pixels that show nothing (their crop point is outside the
    /// frontal image), [0, 1]: run.json's `missing_fraction`.
    pub missing_fraction: f64,
    /// `run.json`.
    pub report: serde_json::Value,
}

impl RunResult {
    /// The driver's views `truth`, `seethru` and `occluded`, in the metrics' order.
    pub fn measured_views(&self) -> [FrameView<'_>; 3] {
        [
            FrameView::Whole(&self.truth),
            FrameView::Over(&self.seethru),
            FrameView::Over(&self.occluded),
        ]
    }
}

/// The eye the system believes in: true, or estimated from the back image; plus errors.
pub fn eye_for_compensation(
    scene: &Scene,
    back: &Frame,
    options: &RunOptions,
) -> Result<(DVec3, Option<HeadFix>)> {
    let eyes = &options.eyes;
    let (eye, fix) = match options.head {
        HeadSource::Oracle => (eyes.position(&scene.driver, eyes.target), None),
        HeadSource::Estimated => {
            // The believed back camera ([calibration]), not the true one; the tracker the
            // scene's face calls for.
            let believed = scene.calibration.back.apply(&scene.back)?;
            let fix = estimate(scene.face, back, &believed, options.feature_width)?;
            let confidence = &fix.detection.confidence;
            if options.require_confident_head
                && !confidence.is_confident_at(options.min_head_confidence)
            {
                bail!(
                    "option `require_confident_head`: {}",
                    confidence.warning_at("", options.min_head_confidence)
                );
            }
            (
                eyes.target_from_estimate(fix.eye, &scene.obstacle),
                Some(fix),
            )
        }
        HeadSource::Model => {
            // A still head: a dropped sample holds the last estimate, which is of the same
            // eye; latency has nothing to act on.
            let o = &scene.obstacle;
            let eye = o.in_obstacle_frame(eyes.position(&scene.driver, eyes.target));
            let (estimate, _) = WEBCAM_LANDMARKS.sample_or_hold(eye, options.seed, 0, None);
            (o.world_from_obstacle.transform_point3(estimate), None)
        }
    };
    let jitter = DVec3::new(
        gaussian(options.seed, 0),
        gaussian(options.seed, 1),
        gaussian(options.seed, 2),
    ) * options.head_jitter_cm;
    let error_obstacle = (DVec3::from_array(options.head_bias_cm) + jitter) / 100.0;
    Ok((
        eye + scene
            .obstacle
            .world_from_obstacle
            .transform_vector3(error_obstacle),
        fix,
    ))
}

/// The display → frontal map of `crop`: through the believed frontal lens ([calibration]),
/// except for `--method none`, which shows the whole frontal image as it is.
pub fn frontal_map(scene: &Scene, crop: Crop, options: &RunOptions) -> Result<FrontalMap> {
    Ok(FrontalMap {
        crop,
        lens: match options.method {
            Method::None => None,
            _ => scene.calibration.frontal.apply(&scene.frontal)?.lens,
        },
        display_size: scene.obstacle.display_resolution,
    })
}

/// The crop that `method` asks for; `frontal` serves the `auto` working distance.
pub fn crop_for(
    scene: &Scene,
    eye: DVec3,
    frontal: &Frame,
    options: &RunOptions,
) -> Result<(Crop, Option<f64>)> {
    let display_size = scene.obstacle.display_resolution;
    if options.method == Method::None {
        let [w, h] = [scene.frontal.width as f64, scene.frontal.height as f64];
        let [dw, dh] = display_size.map(f64::from);
        let corners = [
            DVec2::ZERO,
            DVec2::new(w, 0.0),
            DVec2::new(w, h),
            DVec2::new(0.0, h),
        ];
        let display = [
            DVec2::ZERO,
            DVec2::new(dw, 0.0),
            DVec2::new(dw, dh),
            DVec2::new(0.0, dh),
        ];
        let crop = Crop {
            corners,
            frontal_from_display: homography(display, corners),
            frontal_size: [scene.frontal.width, scene.frontal.height],
        };
        return Ok((crop, None));
    }
    let plane = |d2: WorkingDistance| match d2 {
        WorkingDistance::Metres(m) => ModelPlane::At(m),
        _ => ModelPlane::Infinity,
    };
    // The believed frontal camera ([calibration]) without its distortion: the crop is a
    // homography into its undistorted pixels (the lens follows in the FrontalMap).
    let believed = scene.calibration.frontal.apply(&scene.frontal)?;
    let believed_pinhole = believed.undistorted();
    let mut crop = compute_crop(
        eye,
        &scene.obstacle,
        &believed_pinhole,
        plane(options.d2),
        display_size,
    )?;
    let mut d2_used = match options.d2 {
        WorkingDistance::Metres(m) => Some(m),
        _ => None,
    };
    if options.d2 == WorkingDistance::Auto {
        // Two rounds: the region under the d2 = ∞ crop, then under the crop at its median.
        for _ in 0..2 {
            let map = FrontalMap {
                crop,
                lens: believed.lens,
                display_size,
            };
            let d2 = median_depth_in_crop(frontal, &map, &scene.obstacle)
                .context("d2 auto: the frontal camera sees no surface where the display is")?;
            crop = compute_crop(
                eye,
                &scene.obstacle,
                &believed_pinhole,
                ModelPlane::At(d2),
                display_size,
            )?;
            d2_used = Some(d2);
        }
    }
    Ok((crop, d2_used))
}

/// Median distance from the display plane of the surfaces the frontal camera sees inside the
/// crop's bounding box.
fn median_depth_in_crop(frontal: &Frame, map: &FrontalMap, obstacle: &Obstacle) -> Option<f64> {
    let (min, max) = map.bounds();
    let mut depths: Vec<f64> = Vec::new();
    for y in (min.y.max(0.0) as u32)..(max.y.min(frontal.height as f64) as u32) {
        for x in (min.x.max(0.0) as u32)..(max.x.min(frontal.width as f64) as u32) {
            let p = frontal.position[frontal.index(x, y)];
            if p.is_finite() {
                depths.push(-obstacle.in_obstacle_frame(p.as_dvec3()).z);
            }
        }
    }
    depths.sort_by(f64::total_cmp);
    depths.get(depths.len() / 2).copied().filter(|d| *d > 0.0)
}

/// How far the crop leaves the frontal image on each side, pixels (0 inside).
fn overflow(map: &FrontalMap) -> [(&'static str, f64); 4] {
    let [w, h] = map.crop.frontal_size.map(f64::from);
    let (min, max) = map.bounds();
    [
        ("left", (-min.x).max(0.0)),
        ("right", (max.x - w).max(0.0)),
        ("top", (-min.y).max(0.0)),
        ("bottom", (max.y - h).max(0.0)),
    ]
}

/// With `--method planar` on a flat display and `--outside error`: an error when the crop
/// (`map`, for the eye at `eye`, world, and the model plane at `d2_used`) leaves the frontal
/// camera's view, naming the side, by how much, and where the eye may be instead.
pub fn check_crop_in_view(
    scene: &Scene,
    eye: DVec3,
    d2_used: Option<f64>,
    map: &FrontalMap,
    options: &RunOptions,
) -> Result<()> {
    // A curved display is compensated per pixel; its crop is only its reference rectangle's.
    let curved = scene.obstacle.display_shape.curved().is_some();
    if options.method != Method::Planar || curved || options.outside != Outside::Error {
        return Ok(());
    }
    let Some((side, px)) = overflow(map).into_iter().find(|(_, px)| *px > 1e-9) else {
        return Ok(());
    };
    let d1 = scene.obstacle.in_obstacle_frame(eye).z;
    let (ax, ay) = admissible_offsets(&scene.frontal, &scene.obstacle, d1, d2_used);
    let axis = scene.obstacle.in_obstacle_frame(scene.frontal.position());
    let extent = if side == "left" || side == "right" {
        map.crop.frontal_size[0]
    } else {
        map.crop.frontal_size[1]
    };
    let share = 100.0 * px / extent as f64;
    let region = if ax < 0.0 || ay < 0.0 {
        // The range would print high to low: no eye position is admissible.
        "no eye position keeps the whole crop inside the frontal view there (its field of view is too narrow for the display at this d2)".to_string()
    } else {
        format!(
            "the eye must stay within x ∈ [{}, {}] m, y ∈ [{}, {}] m of the obstacle frame",
            short(axis.x - ax),
            short(axis.x + ax),
            short(axis.y - ay),
            short(axis.y + ay)
        )
    };
    bail!(
        "the crop leaves the frontal camera's view on the {side} by {} px ({}% of the image); at d1 = {} m {region} (use option `outside` black to show the rest black)",
        short(px),
        short(share),
        short(d1),
    );
}

/// The admissible eye offsets across and up the display (obstacle frame, relative to the
/// frontal camera's axis) at eye distance `d1`, for a frontal camera perpendicular to the
/// display: |x| ≤ d1 (tan θx − D/(2 d2)) − D/2, and likewise vertically (from eq. RATIO1 ≥ 0).
fn admissible_offsets(
    frontal: &Camera,
    obstacle: &Obstacle,
    d1: f64,
    d2: Option<f64>,
) -> (f64, f64) {
    let reach =
        |tan: f64, size: f64| d1 * (tan - d2.map_or(0.0, |d2| size / (2.0 * d2))) - size / 2.0;
    (
        reach(frontal.tan_half_x(), obstacle.width),
        reach(frontal.tan_half_y(), obstacle.height),
    )
}

/// The display image of `--method planar` on a curved display, per pixel; with `--outside
/// error`, a display pixel whose model point the frontal camera does not see is an error.
pub fn curved_planar_display(
    scene: &Scene,
    eye: DVec3,
    d2: Option<f64>,
    frontal: &Frame,
    options: &RunOptions,
) -> Result<Frame> {
    use crate::system::point_model::PointModel;
    use crate::system::surface_map::curved_display;
    let plane = d2.map_or(ModelPlane::Infinity, ModelPlane::At);
    let model = PointModel::new(scene, eye, plane)?;
    let (display, missing) = curved_display(frontal, &scene.obstacle, &model, options.filter);
    if missing > 0 && options.outside == Outside::Error {
        bail!(
            "{missing} of the curved display's {} pixels show a model point the frontal camera does not see (or lie outside its UVs); use option `outside` black to show them black and count them",
            display.object_id.len()
        );
    }
    Ok(display)
}

/// How the ideal display of the planar compensation (or none) maps its points into the
/// frontal camera: a curved display per point of its surface, a flat one through the crop.
pub fn ideal_map(
    scene: &Scene,
    eye: DVec3,
    d2: Option<f64>,
    curved: bool,
    crop: Crop,
    map: &FrontalMap,
) -> Result<IdealMap> {
    use crate::system::point_model::PointModel;
    Ok(if curved {
        let plane = d2.map_or(ModelPlane::Infinity, ModelPlane::At);
        IdealMap::Surface(PointModel::new(scene, eye, plane)?)
    } else {
        IdealMap::Crop {
            crop,
            lens: map.lens,
        }
    })
}

/// Runs the system on a loaded scene; renders every view. A display that covers no pixel of
/// the driver's view is an error: every metric of the run would be undefined.
pub fn run(ctx: &RenderContext, options: &RunOptions) -> Result<RunResult> {
    let result = run_with_truth(ctx, options, None)?;
    check_display_seen(ctx, &result.occluded)?;
    Ok(result)
}

/// Refuses a run whose display covers no pixel of the driver's view (`occluded`): nothing to
/// measure. (A sweep keeps such a configuration as a row of undefined metrics.)
pub fn check_display_seen<'a>(
    ctx: &RenderContext,
    occluded: impl Into<FrameView<'a>>,
) -> Result<()> {
    let occluded = occluded.into();
    let display_face = |(&o, &p): (&u32, &u32)| ctx.world.is_display(o, p);
    let seen = (0..occluded.height()).any(|y| {
        let parts = occluded.row(|f| &f.part_id, y);
        let ids = occluded.row(|f| &f.object_id, y);
        ids.iter()
            .zip(parts)
            .any(|(ids, parts)| ids.iter().zip(parts).any(display_face))
    });
    if !seen {
        bail!(
            "the display covers no pixel of the driver's {}×{} view: the driver looks away from it, or it is too small or too far to cover a pixel; nothing to measure",
            occluded.width(),
            occluded.height()
        );
    }
    Ok(())
}

/// The frontal camera as it captures a run's image: where the vehicle's motion (option
/// `speed`, option `yaw_rate`, about the driver's eye) had carried it option `latency_camera`
/// before the run's instant, moving on through its readout and exposure. The system does not
/// know of the motion: it compensates with the camera where it is mounted (the scene's, through
/// its calibration). (The back camera and the head ride the vehicle together: it films them
/// still.)
pub struct FrontalCapture {
    /// The camera at the capture's instant.
    pub camera: Camera,
    /// Its pose `dt` seconds after that instant while the vehicle moves (`None`: still).
    pub pose_at: Option<Box<dyn Fn(f64) -> glam::DAffine3 + Sync>>,
}

impl FrontalCapture {
    /// A render job of the frontal view as captured.
    pub fn job<'a>(&'a self, mask: u8) -> RenderJob<'a> {
        let job = RenderJob::new(&self.camera, mask);
        match &self.pose_at {
            Some(pose) => job.moving(pose.as_ref()),
            None => job,
        }
    }
}

/// [`FrontalCapture`] of `scene`'s frontal camera under `options`. A motion nothing would see
/// (a frontal shutter that is an instant, no latency) and a latency with a still vehicle are
/// refused: the option would change nothing.
pub fn frontal_capture(scene: &Scene, options: &RunOptions) -> Result<FrontalCapture> {
    let latency = options.latency_camera_ms / 1e3;
    if options.speed_kmh == 0.0 && options.yaw_rate_deg_s == 0.0 {
        if latency > 0.0 {
            bail!(
                "option `latency_camera` ({} ms) changes nothing while the vehicle stands still: give option `speed` or option `yaw_rate`, or leave it out",
                short(options.latency_camera_ms)
            );
        }
        return Ok(FrontalCapture {
            camera: scene.frontal,
            pose_at: None,
        });
    }
    let motion = options.vehicle_motion(scene)?;
    if scene.frontal.shutter.is_instant() && latency == 0.0 {
        let given = if options.speed_kmh != 0.0 {
            "speed"
        } else {
            "yaw_rate"
        };
        bail!(
            "option `{given}` moves the frontal camera during its readout and exposure, but its shutter is an instant (a global shutter, exposure_ms 0) and option `latency_camera` is 0: set shutter = \"rolling\" or exposure_ms in [camera.frontal], give a latency, or leave the option out"
        );
    }
    let base = scene.frontal.world_from_camera;
    let pose_at = move |dt: f64| motion.world_from_rig(dt - latency) * base;
    Ok(FrontalCapture {
        camera: Camera {
            world_from_camera: pose_at(0.0),
            ..scene.frontal
        },
        pose_at: Some(Box::new(pose_at)),
    })
}

/// The driver's camera a run renders at: the scene's, resized by the options.
pub fn driver_camera(scene: &Scene, options: &RunOptions) -> Result<Camera> {
    options.sized_driver(options.eyes.view_camera(&scene.driver))
}

/// [`run`], given the `truth` frame when it is already rendered (a sweep renders it once for
/// all configurations that share the eye): it must be what [`run`] would render, the
/// [`driver_camera`]'s `truth` view at the options' samples per pixel.
pub fn run_with_truth(
    ctx: &RenderContext,
    options: &RunOptions,
    truth: Option<&Frame>,
) -> Result<RunResult> {
    run_given(
        ctx,
        options,
        Given {
            truth,
            ..Given::default()
        },
    )
}

/// What a run is handed instead of making it itself: a truth frame already rendered (a
/// sweep's), the captured back and frontal frames (they must be what the run would render),
/// and a display image made elsewhere (a method's map or image, `seethru score`): with one,
/// the method's own display and its crop checks are skipped and the display is physical.
#[derive(Default)]
pub struct Given<'a> {
    pub truth: Option<&'a Frame>,
    pub back: Option<&'a Frame>,
    pub frontal: Option<&'a Frame>,
    pub display: Option<Frame>,
}

/// [`run_with_truth`] with whatever [`Given`] holds.
pub fn run_given(ctx: &RenderContext, options: &RunOptions, given: Given) -> Result<RunResult> {
    let views = RunViews::default();
    let rest = run_staged(ctx, options, given, &views, &|_| {})?;
    Ok(rest.with_views(views))
}

/// The six views of a run, each set once, as [`run_staged`] makes it.
#[derive(Default)]
pub struct RunViews {
    pub truth: OnceLock<Arc<Frame>>,
    pub occluded: OnceLock<FrameOver>,
    pub frontal: OnceLock<Frame>,
    pub back: OnceLock<Frame>,
    pub display: OnceLock<Frame>,
    pub seethru: OnceLock<FrameOver>,
}

/// What a run tells a caller as each view is made: the view's file name (the caller reads
/// the view from the [`RunViews`], for as long as they live).
pub type Ready<'a> = dyn Fn(&'static str) + Sync + 'a;

impl RunViews {
    /// View `name` (`truth`, `occluded`, `frontal`, `back`, `display`, `seethru`), once set.
    pub fn get(&self, name: &str) -> Option<FrameView<'_>> {
        fn whole(slot: &OnceLock<Frame>) -> Option<FrameView<'_>> {
            slot.get().map(FrameView::Whole)
        }
        match name {
            "truth" => self.truth.get().map(|f| FrameView::Whole(f)),
            "occluded" => self.occluded.get().map(FrameView::Over),
            "seethru" => self.seethru.get().map(FrameView::Over),
            "frontal" => whole(&self.frontal),
            "back" => whole(&self.back),
            "display" => whole(&self.display),
            _ => None,
        }
    }

    /// Sets `slot`, view `name`'s, to `frame` and tells `ready`.
    fn set<'v, F>(name: &'static str, slot: &'v OnceLock<F>, frame: F, ready: &Ready<'_>) -> &'v F {
        assert!(slot.set(frame).is_ok(), "the {name} view is made once");
        ready(name);
        slot.get().expect("just set")
    }
}

/// A run's results but its views: what [`run_staged`] returns beside the [`RunViews`] it fills.
pub struct RunRest {
    pub crop: Crop,
    pub eye_used: DVec3,
    pub detection: Option<FaceDetection>,
    pub head_pose: Option<HeadPose>,
    pub holes: Option<Vec<bool>>,
    pub missing_fraction: f64,
    pub report: serde_json::Value,
}

impl RunRest {
    /// The whole [`RunResult`], with the views [`run_staged`] filled.
    pub fn with_views(self, views: RunViews) -> RunResult {
        fn take<F>(slot: OnceLock<F>) -> F {
            slot.into_inner().expect("a finished run set every view")
        }
        RunResult {
            truth: take(views.truth),
            occluded: take(views.occluded),
            frontal: take(views.frontal),
            back: take(views.back),
            display: take(views.display),
            seethru: take(views.seethru),
            crop: self.crop,
            eye_used: self.eye_used,
            detection: self.detection,
            head_pose: self.head_pose,
            holes: self.holes,
            missing_fraction: self.missing_fraction,
            report: self.report,
        }
    }
}

/// [`run_given`], setting each view in `views` as soon as it is made and telling `ready`
/// (its file name: `truth`, `occluded`, `frontal`, `back`, `display`, `seethru`),
/// so that a caller can write it while the next one renders. On success every view is set.
pub fn run_staged(
    ctx: &RenderContext,
    options: &RunOptions,
    given: Given,
    views: &RunViews,
    ready: &Ready<'_>,
) -> Result<RunRest> {
    let truth = given.truth;
    let mut scene = ctx.scene.clone();
    scene.frontal = options.sized_frontal(scene.frontal)?;
    scene.back = options.sized_back(scene.back)?;
    let scene = &scene;
    check_spp(options.spp)?;
    if !(options.feature_width > 0.0 && options.feature_width.is_finite()) {
        bail!(
            "option `feature_width` must be > 0 m, got {}",
            options.feature_width
        );
    }
    if !(options.head_jitter_cm >= 0.0 && options.head_jitter_cm.is_finite())
        || options.head_bias_cm.iter().any(|v| !v.is_finite())
    {
        bail!("head bias must be finite and jitter ≥ 0");
    }
    options.eyes.check().map_err(anyhow::Error::msg)?;
    if options.require_confident_head && options.head != HeadSource::Estimated {
        bail!(
            "option `require_confident_head` needs option `head` estimated (only the image-based estimate has a confidence)"
        );
    }
    if options.method.models_the_scene() && given.display.is_none() {
        // Bad sensor flags, an ideal display and a scene without a road fail before anything
        // is rendered.
        check_scene_model(scene, options)?;
    }
    let driver = driver_camera(scene, options)?;
    let settings = RenderSettings {
        spp: options.spp,
        progress: options.progress,
    };
    let capture = frontal_capture(scene, options)?;
    let mut timings = serde_json::Map::new();
    let timed = |timings: &mut serde_json::Map<String, serde_json::Value>, view: View| {
        let job = match view {
            View::Frontal => capture.job(view.bit()),
            View::Back => RenderJob::new(&scene.back, view.bit()),
            _ => RenderJob::new(&driver, view.bit()),
        };
        let (frame, stats) = ctx.render(job.settings(settings).label(view.name()));
        timings.insert(view.name().into(), json!(stats.seconds));
        frame
    };
    let back = match given.back {
        Some(b) => b.clone(),
        None => timed(&mut timings, View::Back),
    };
    let back = RunViews::set("back", &views.back, back, ready);
    let frontal = match given.frontal {
        Some(f) => f.clone(),
        None => timed(&mut timings, View::Frontal),
    };
    let frontal = RunViews::set("frontal", &views.frontal, frontal, ready);
    let (eye_used, head_fix) = eye_for_compensation(scene, back, options)?;
    let (crop, d2_used) = crop_for(scene, eye_used, frontal, options)?;
    let map = frontal_map(scene, crop, options)?;

    let out = overflow(&map);
    // A curved display is compensated per pixel; its crop is only its reference rectangle's.
    let curved =
        options.method == Method::Planar && scene.obstacle.display_shape.curved().is_some();
    if given.display.is_none() {
        check_crop_in_view(scene, eye_used, d2_used, &map, options)?;
    }

    let start = Instant::now();
    let given_display = given.display.is_some();
    let (display, scene_model) = if let Some(d) = given.display {
        (d, None)
    } else if options.method.models_the_scene() {
        let m = scene_model_display(
            ctx,
            scene,
            eye_used,
            frontal,
            &crop,
            options,
            &capture.camera,
        )?;
        (m.display.clone(), Some(m))
    } else if curved {
        (
            curved_planar_display(scene, eye_used, d2_used, frontal, options)?,
            None,
        )
    } else {
        (resample_through(frontal, &map, options.filter), None)
    };
    let mut display = display;
    if !given_display {
        // Made from the frontal image: the display shows it by its codes.
        display.exposure = frontal.exposure;
    }
    timings.insert("display".into(), json!(start.elapsed().as_secs_f64()));
    let missing = display
        .object_id
        .iter()
        .filter(|&&i| i == MISSING_ID)
        .count() as f64
        / display.object_id.len() as f64;
    let display = RunViews::set("display", &views.display, display, ready);
    // `occluded` and `seethru` differ from `truth` only where the obstacle can be seen:
    // only those pixels are traced again.
    let truth = match truth {
        Some(t) => {
            assert_eq!((t.width, t.height), (driver.width, driver.height));
            Arc::new(t.clone())
        }
        None => Arc::new(timed(&mut timings, View::Truth)),
    };
    let truth = RunViews::set("truth", &views.truth, truth, ready);
    let (occluded, stats) = ctx.render_over(
        RenderJob::new(&driver, view_bit::OCCLUDED)
            .settings(settings)
            .label("occluded"),
        truth,
        view_bit::TRUTH,
    );
    timings.insert("occluded".into(), json!(stats.seconds));
    RunViews::set("occluded", &views.occluded, occluded, ready);
    let placement = DisplayPlacement::new(&scene.obstacle);
    let surface = match options.display {
        _ if given_display => DisplaySurface::Pixels {
            image: display.clone(),
            placement,
            scan: None,
        },
        DisplayModel::Pixels => DisplaySurface::Pixels {
            image: display.clone(),
            placement,
            scan: None,
        },
        DisplayModel::Ideal => DisplaySurface::Ideal {
            map: ideal_map(scene, eye_used, d2_used, curved, crop, &map)?,
            frontal: scene.frontal,
            placement,
        },
    };
    let (seethru, stats) = ctx.render_over(
        RenderJob::seethru(&driver, &surface).settings(settings),
        truth,
        view_bit::TRUTH,
    );
    timings.insert("seethru".into(), json!(stats.seconds));
    RunViews::set("seethru", &views.seethru, seethru, ready);

    let mut report = report(
        scene,
        options,
        &crop,
        eye_used,
        head_fix.as_ref(),
        d2_used,
        missing,
        &out,
        timings,
    );
    if let Some(m) = &scene_model {
        report["scene_model"] = m.report.clone();
    }
    // The renders are the run's memory peak.
    report["peak_rss_bytes"] = json!(peak_rss_bytes());
    report["exposure"] = json!({
        "frontal": crate::system::report::exposure_json(frontal),
        "back": crate::system::report::exposure_json(back),
    });
    report["eyes"] = json!({"options": options.eyes, "view_world_m": driver.position().to_array()});
    report["lenses"] = crate::system::frontal_map::lenses_json(scene)?;
    report["calibration"] = crate::system::calibration_json::calibration_json(scene)?;
    let seen = crate::system::obstruction::obstruction_json(ctx, &driver, options.eyes.ipd);
    report["obstruction_deg"] = seen["obstruction_deg"].clone();
    report["display_seen"] = seen["display_seen"].clone();
    // What the ids in the views name: `id.object` i + 1 is object i (0 is sky).
    report["object_names"] = json!(
        ctx.world
            .objects
            .iter()
            .map(|o| &o.name)
            .collect::<Vec<_>>()
    );
    Ok(RunRest {
        crop,
        eye_used,
        detection: head_fix.map(|f| f.detection),
        head_pose: head_fix.and_then(|f| f.pose),
        holes: scene_model.map(|m| m.holes),
        missing_fraction: missing,
        report,
    })
}
