//! The system's work for each displayed frame of a sequence, at the instants it happens:
//! the frontal camera's capture, the back camera's head estimate, the prediction, the
//! compensation and the display image; and the `seethru` view at display time.
//!
//! The static world and its hierarchy are built once; what moves (the obstacle, what rides
//! with the vehicle or the head, objects on keyframed paths) is a small world of its own whose
//! hierarchy is refitted for each instant ([`MovingParts::at`]).
//!
//! The frontal pixels a refresh renders are system/sequence/frontal_region.rs's; the back
//! camera's tracking of the face, system/sequence/back_tracker.rs's.

use std::sync::Arc;
use std::time::Instant;

use anyhow::{Context, Result, bail};
use glam::DVec3;

use crate::geometry::camera::Camera;
use crate::geometry::lens::Lens;
use crate::geometry::shutter::Scanout;
use crate::render::accel::Accel;
use crate::render::exposure::Adapting;
use crate::render::footprint::PixelRect;
use crate::render::frame::Frame;
use crate::render::in_time::render_in_time;
use crate::render::integrator::RenderContext;
use crate::render::moving::MovingParts;
use crate::render::render_job::RenderJob;
use crate::render::sensor_image::record_metering;
use crate::render::settings::{RenderSettings, check_spp};
use crate::render::sky::SkyModel;
use crate::scene::Scene;
use crate::scene::world::{World, view_bit};
use crate::system::calibration_json::calibration_json;
use crate::system::capture::{HeadEstimate, check_display_input, display_from, fingerprint};
use crate::system::compensation::Crop;
use crate::system::display::{
    DisplayModel, DisplayPlacement, DisplaySurface, IdealMap, ScannedRows, resample_through,
};
use crate::system::head::gaussian;
use crate::system::head_estimate::{FACING_FORWARD, fix_from};
use crate::system::head_pose::HeadPose;
use crate::system::options::{HeadSource, Method, RunOptions, WorkingDistance};
use crate::system::pipeline::{
    check_crop_in_view, crop_for, driver_camera, frontal_map, ideal_map,
};
use crate::system::sequence::back_tracker::BackTracker;
use crate::system::sequence::byo::{Byo, RefreshInputs};
use crate::system::sequence::frontal_region::{crop_rect, curved_rect};
use crate::system::sequence::head_motion::HeadMotion;
use crate::system::sequence::predict::{Prediction, Predictor};
use crate::system::sequence::timeline::{FrameTimes, Rig, Timeline};
use crate::system::tracker_model::WEBCAM_LANDMARKS;
use crate::util::number::short;

/// Fewest samples per pixel of the back camera's image.
pub const BACK_MIN_SPP: u32 = 4;

/// Everything a sequence is asked for.
#[derive(Clone, Debug)]
pub struct SequenceOptions {
    /// The system's choices (method, d2, head source and its errors, sizes, spp, display) and
    /// the vehicle's speed and yaw rate.
    pub run: RunOptions,
    pub timeline: Timeline,
    pub head: HeadMotion,
    pub predict: Prediction,
    /// Re-project the frontal image by the vehicle's known motion from capture to display.
    pub reproject: bool,
    /// Each refresh's inputs kept, or outside display maps shown (`--capture`, `--maps`).
    pub byo: Byo,
}

/// What the display shows from one refresh on.
#[derive(Clone, Debug)]
pub struct Shown {
    pub times: FrameTimes,
    /// The head estimate (of time `times.head`), obstacle frame, m.
    pub eye_estimated: DVec3,
    /// The image-based estimate's confidence, [0, 1] (`None` for other head sources).
    pub head_confidence: Option<f64>,
    /// The yaw fit of the image-based estimate on the mesh face (`None`: the ellipsoid face,
    /// or another head source).
    pub head_pose: Option<HeadPose>,
    /// The eye the compensation used (predicted to the refresh time), obstacle frame, m.
    pub eye_used: DVec3,
    pub crop: Crop,
    /// The model plane's distance, m (`None`: d2 → ∞ or no model).
    pub d2_used: Option<f64>,
    /// The frontal camera at the capture time.
    pub frontal: Camera,
    /// The frontal image's exposure (`None`: a camera without a sensor).
    pub frontal_exposure: Option<crate::geometry::sensor::Exposure>,
    /// The believed frontal lens the display image went through (`None`: a pinhole).
    pub lens: Option<Lens>,
    /// How the ideal display maps its points: through `crop` and `lens` on a flat display,
    /// per surface point on a curved one.
    pub ideal: IdealMap,
}

/// Wall time spent in each stage, seconds, summed over the frames.
#[derive(Clone, Copy, Debug, Default, serde::Serialize)]
pub struct StageSeconds {
    /// Placing the moving part and building its hierarchy.
    pub moving: f64,
    pub frontal: f64,
    pub head: f64,
    pub compensation: f64,
    pub seethru: f64,
}

impl StageSeconds {
    pub fn total(&self) -> f64 {
        self.moving + self.frontal + self.head + self.compensation + self.seethru
    }
}

pub struct SystemLoop {
    pub options: SequenceOptions,
    pub rig: Rig,
    world: Arc<World>,
    accel: Arc<Accel>,
    sky: Arc<SkyModel>,
    parts: MovingParts,
    predictor: Predictor,
    frontal: Frame,
    shown: Option<Shown>,
    /// The display showing the image of the last refresh.
    surface: Option<DisplaySurface>,
    /// The image of the refresh before the last, and its index: what a rolling scan-out
    /// still shows below its scan line.
    previous: Option<(i64, Arc<Frame>)>,
    pub seconds: StageSeconds,
    /// Frontal pixels rendered, summed over the refreshes.
    pub frontal_pixels: u64,
    /// `--head-source model`: the last estimate, held over a dropped sample.
    model_last: Option<DVec3>,
    /// The last refresh's inputs, until taken ([`SystemLoop::take_inputs`]).
    inputs: Option<RefreshInputs>,
    /// An eye supplied from outside (a Python predictor), obstacle frame, m: the next refresh
    /// [`SystemLoop::show`] makes compensates for it instead of the predicted estimate.
    pub eye_given: Option<DVec3>,
    /// The back camera's image and where the face was in it.
    back_tracker: BackTracker,
    /// Whether the back camera renders and searches only around the last face
    /// ([`BackTracker`]); `false`: the whole image every time (the twin the tests compare).
    pub track_face: bool,
    /// Back camera pixels rendered for the head estimates, summed over the refreshes.
    pub back_pixels: u64,
    /// The frontal and the back camera's automatic exposures.
    exposures: [Adapting; 2],
}

impl SystemLoop {
    /// Checks the options, sizes the cameras and builds the static world's hierarchy.
    pub fn new(scene: &Scene, options: SequenceOptions) -> Result<SystemLoop> {
        let run = &options.run;
        check_spp(run.spp)?;
        options.timeline.validate()?;
        if run.method.models_the_scene() {
            bail!(
                "sequence: option `method` ground, plane-fit and depth are not modelled over time; use option `method` planar or none"
            );
        }
        if !(run.feature_width > 0.0 && run.feature_width.is_finite()) {
            bail!(
                "option `feature_width` must be > 0 m, got {}",
                run.feature_width
            );
        }
        if run.require_confident_head && run.head != HeadSource::Estimated {
            bail!(
                "option `require_confident_head` needs option `head_source` estimated (only the image-based estimate has a confidence)"
            );
        }
        let scanout = scene.obstacle.scanout;
        if scanout != Scanout::default() && run.display == DisplayModel::Ideal {
            bail!(
                "the display's scanout and persistence_ms are its pixels' timing: not with option `display` ideal (use pixels)"
            );
        }
        let timeline = options.timeline;
        if scanout.rolling && timeline.fps < timeline.display_hz {
            bail!(
                "a rolling scanout shows two refreshes at once: option `fps` ({}) must be at least option `display_hz` ({}), so that every refresh is made",
                short(timeline.fps),
                short(timeline.display_hz)
            );
        }
        let mut base = scene.clone();
        base.frontal = run.sized_frontal(base.frontal)?;
        base.back = run.sized_back(base.back)?;
        base.driver = driver_camera(&base, run)?;
        let vehicle = options.run.vehicle_motion(&base)?;
        let rig = Rig::new(base, vehicle, options.head.clone());
        let tl = options.timeline;
        let before = scene
            .obstacle
            .scanout
            .rolling
            .then(|| tl.refresh_times(-1).head);
        rig.check_eye(
            (0..tl.frames())
                .flat_map(|k| {
                    let t = tl.times(k);
                    [t.display, t.head]
                })
                .chain(before),
        )?;
        let moves = |i: usize| scene.objects[i].motion.moves();
        let world = World::build_part(scene, &|i| !moves(i), false)?;
        let accel = Accel::build(&world)?;
        let parts = MovingParts::new(scene, &moves)?;
        let sigma = match run.head {
            HeadSource::Oracle => run.head_jitter_cm / 100.0,
            // About the tracker's error on das at 640×480 (docs/guide/pipeline.md).
            HeadSource::Estimated => (run.head_jitter_cm / 100.0).max(0.005),
            HeadSource::Model => (run.head_jitter_cm / 100.0).max(WEBCAM_LANDMARKS.sigma_lateral_m),
        };
        let frontal = Frame::new(rig.base.frontal.width, rig.base.frontal.height);
        let rig_back = rig.base.back;
        Ok(SystemLoop {
            predictor: Predictor::new(options.predict, sigma),
            sky: Arc::new(SkyModel::new(
                &scene.sky,
                &scene.sun,
                scene.photometry.as_ref(),
            )),
            world: Arc::new(world),
            accel: Arc::new(accel),
            parts,
            rig,
            options,
            frontal,
            shown: None,
            surface: None,
            previous: None,
            seconds: StageSeconds::default(),
            frontal_pixels: 0,
            model_last: None,
            inputs: None,
            eye_given: None,
            back_tracker: BackTracker::new(&rig_back),
            track_face: true,
            back_pixels: 0,
            exposures: [Adapting::default(); 2],
        })
    }

    fn settings(&self) -> RenderSettings {
        RenderSettings {
            spp: self.options.run.spp,
            progress: false,
        }
    }

    /// The scene at `t`, ready to render: the static hierarchy shared, the moving part
    /// placed and its hierarchy refitted.
    pub fn context_at(&mut self, t: f64) -> Result<RenderContext> {
        let start = Instant::now();
        let rig = &self.rig;
        let layer = self.parts.at(&|id| rig.object_motion(t, id))?;
        self.seconds.moving += start.elapsed().as_secs_f64();
        let scene = self.rig.scene_at(t);
        Ok(RenderContext {
            lamps: crate::render::integrator::lamps_of(&scene),
            lamp_sampling: crate::render::integrator::lamp_sampling_of(&scene),
            scene,
            world: self.world.clone(),
            accel: self.accel.clone(),
            sky: self.sky.clone(),
            moving: Some(Arc::new(layer)),
        })
    }

    /// The head estimate of time `t` (obstacle frame) for refresh `refresh`, and the
    /// image-based estimate's confidence and yaw fit.
    fn estimate_head(
        &mut self,
        t: f64,
        refresh: i64,
    ) -> Result<(DVec3, Option<f64>, Option<HeadPose>)> {
        let run = self.options.run.clone();
        let mut confidence = None;
        let mut pose = None;
        let eye = match run.head {
            HeadSource::Oracle => self.rig.eye_in_obstacle(t),
            HeadSource::Model => {
                // The estimate delivered at `t` is of the eye one latency earlier; a dropped
                // sample holds the last estimate.
                let model = WEBCAM_LANDMARKS;
                let eye = self.rig.eye_in_obstacle(t - model.latency_s);
                let index = refresh.max(0) as u32;
                let (estimate, _) = model.sample_or_hold(eye, run.seed, index, self.model_last);
                self.model_last = Some(estimate);
                estimate
            }
            HeadSource::Estimated => {
                let ctx = self.context_at(t)?;
                let start = Instant::now();
                let back = ctx.scene.back;
                // A camera's image is anti-aliased: the detector mistakes the aliased edge
                // of a shadow for a pupil at 1 sample per pixel (das, leaning).
                let settings = RenderSettings {
                    spp: self.options.run.spp.max(BACK_MIN_SPP),
                    progress: false,
                };
                if !self.track_face {
                    self.back_tracker.region = None;
                }
                let face = ctx.scene.face;
                let mut tracker = std::mem::take(&mut self.back_tracker);
                let found = tracker.detect(&back, face, &mut |frame, region| {
                    let job = RenderJob::new(&back, view_bit::BACK)
                        .settings(settings)
                        .region(region)
                        .label("back");
                    self.render_carried(&ctx, t, self.rig.base.back, job, frame)
                });
                self.back_tracker = tracker;
                let (detection, pixels) = found?;
                self.back_pixels += pixels;
                let detection =
                    detection.with_context(|| format!("head estimate at t = {} s", short(t)))?;
                // The believed back camera ([calibration]), not the true one; the tracker the
                // scene's face calls for.
                let believed = ctx.scene.calibration.back.apply(&back)?;
                // The driver faces the vehicle's forward, which turns with the vehicle.
                let world_from_face = self.rig.world_from_rig(t).matrix3 * FACING_FORWARD;
                let fix = fix_from(
                    face,
                    detection,
                    &believed,
                    run.feature_width,
                    world_from_face,
                );
                if run.require_confident_head
                    && !fix
                        .detection
                        .confidence
                        .is_confident_at(run.min_head_confidence)
                {
                    bail!(
                        "option `require_confident_head`: {}",
                        fix.detection
                            .confidence
                            .warning(&format!("at t = {} s: ", short(t)))
                    );
                }
                confidence = Some(fix.detection.confidence.value);
                pose = fix.pose;
                self.seconds.head += start.elapsed().as_secs_f64();
                ctx.scene.obstacle.in_obstacle_frame(fix.eye)
            }
        };
        let index = (refresh.max(0) as u32).wrapping_mul(3);
        let jitter = DVec3::new(
            gaussian(run.seed, index),
            gaussian(run.seed, index.wrapping_add(1)),
            gaussian(run.seed, index.wrapping_add(2)),
        ) * run.head_jitter_cm;
        Ok((
            eye + (DVec3::from_array(run.head_bias_cm) + jitter) / 100.0,
            confidence,
            pose,
        ))
    }

    /// What the display shows at displayed frame `frame`: the image of the latest refresh,
    /// made once per refresh.
    pub fn show(&mut self, frame: usize) -> Result<&Shown> {
        let times = self.options.timeline.times(frame);
        if self
            .shown
            .as_ref()
            .is_some_and(|s| s.times.refresh == times.refresh)
        {
            return Ok(self.shown.as_ref().expect("just checked"));
        }
        if self.shown.is_none() && self.shows_refresh_before() {
            // The display has been running before the sequence: below its first refresh's
            // scan line it shows the refresh before, made as every refresh is. Outside maps
            // have none (their rows stay dark until scanned).
            let given = self.eye_given.take();
            let before = self.options.timeline.refresh_times(times.refresh - 1);
            self.make_refresh(before)?;
            self.eye_given = given;
        }
        self.make_refresh(times)
    }

    /// Whether the first refresh shows the one before it (a rolling scan-out, the loop's own
    /// compensation).
    fn shows_refresh_before(&self) -> bool {
        self.rig.base.obstacle.scanout.rolling && self.options.byo.maps.is_none()
    }

    /// Makes the image of the refresh of `times` and what it shows.
    fn make_refresh(&mut self, times: FrameTimes) -> Result<&Shown> {
        let (eye_estimated, head_confidence, head_pose) =
            self.estimate_head(times.head, times.refresh)?;
        self.predictor.observe(times.head, eye_estimated);
        let eye_used = match (self.eye_given.take(), self.options.predict) {
            (Some(given), _) => given,
            (None, Prediction::None) => eye_estimated,
            (None, _) => self.predictor.predict(times.refresh_time),
        };
        let capture = self.context_at(times.capture)?;
        let start = Instant::now();
        // The compensation's geometry: the display where it is when the image is shown (with
        // re-projection by the known vehicle motion) or where it was at capture.
        let mut geometry = capture.scene.clone();
        if self.options.reproject {
            geometry.obstacle = self.rig.scene_at(times.refresh_time).obstacle;
        }
        let eye_world = geometry
            .obstacle
            .world_from_obstacle
            .transform_point3(eye_used);
        let run = &self.options.run.clone();
        let at = || format!("at t = {} s", short(times.refresh_time));
        let curved =
            run.method == Method::Planar && geometry.obstacle.display_shape.curved().is_some();
        // A curved display's pixels may look beyond its reference rectangle's crop.
        let byo = self.options.byo.clone();
        if byo.maps.is_some() && (curved || run.display == DisplayModel::Ideal) {
            bail!(
                "option `maps` shows a map on a flat display's pixels: not with a curved display or option `display` ideal"
            );
        }
        // A curved display renders only the frontal pixels its model points read, as a flat
        // display renders only its crop's.
        let full =
            run.method == Method::None || run.d2 == WorkingDistance::Auto || byo.needs_inputs();
        let frontal_camera = capture.scene.frontal;
        // The frontal render is its own stage, not part of the compensation's time.
        let frontal_seconds;
        let (crop, d2_used) = if full {
            let f = Instant::now();
            self.capture_frontal(&capture, times.capture, None)?;
            frontal_seconds = f.elapsed().as_secs_f64();
            self.frontal_pixels +=
                u64::from(frontal_camera.width) * u64::from(frontal_camera.height);
            crop_for(&geometry, eye_world, &self.frontal, run).with_context(at)?
        } else {
            let crop = crop_for(&geometry, eye_world, &self.frontal, run).with_context(at)?;
            let rect = if curved {
                curved_rect(&geometry, eye_world, crop.1, &frontal_camera).with_context(at)?
            } else {
                crop_rect(&frontal_map(&geometry, crop.0, run)?, &frontal_camera)
            };
            let f = Instant::now();
            self.capture_frontal(&capture, times.capture, Some(rect))?;
            frontal_seconds = f.elapsed().as_secs_f64();
            self.frontal_pixels += rect.pixels();
            crop
        };
        let map = frontal_map(&geometry, crop, run)?;
        check_crop_in_view(&geometry, eye_world, d2_used, &map, run).with_context(at)?;
        let mut inputs = None;
        if byo.needs_inputs() {
            let b = self.context_at(times.head)?;
            let back_true = b.scene.back;
            let back_settings = RenderSettings {
                spp: run.spp.max(BACK_MIN_SPP),
                progress: false,
            };
            let job = RenderJob::new(&back_true, view_bit::BACK)
                .settings(back_settings)
                .label("back");
            let (camera, metered) = self.exposure_of(view_bit::BACK).exposed(
                &back_true,
                |m| b.meter(&job, m),
                times.head,
            );
            let (mut back, _) = b.render(job.of_camera(&camera));
            record_metering(&mut back, metered);
            let head = HeadEstimate {
                source: run.head,
                eye_world_m: eye_world.to_array(),
                eye_obstacle_m: eye_used.to_array(),
                detection: None,
                pose: None,
            };
            let calibration = calibration_json(&geometry)?;
            let fingerprint =
                fingerprint(&self.frontal, &back, &head, &calibration, &geometry.driver)?;
            inputs = Some(RefreshInputs {
                frontal: self.frontal.clone(),
                back,
                head,
                calibration,
                fingerprint,
                back_true,
            });
        }
        let external = byo.maps.as_ref().map(|maps| maps.get(&times.refresh));
        let mut display = if let Some(named) = external {
            let named = named.with_context(|| {
                format!(
                    "option `maps`: no map for refresh {} (at t = {} s)",
                    times.refresh,
                    short(times.refresh_time)
                )
            })?;
            let size = geometry.obstacle.display_resolution;
            let given = inputs.as_ref().expect("made for the maps");
            check_display_input(
                size,
                Some([self.frontal.width, self.frontal.height]),
                &given.fingerprint,
                Some(&named.map),
                None,
            )
            .map_err(|e| anyhow::anyhow!("{} (frame {}): {e}", named.file, named.frame))?;
            display_from(&self.frontal, size, run, Some(&named.map), None)
        } else if curved {
            crate::system::pipeline::curved_planar_display(
                &geometry,
                eye_world,
                d2_used,
                &self.frontal,
                run,
            )
            .with_context(at)?
        } else {
            resample_through(&self.frontal, &map, run.filter)
        };
        // Made from the frontal image: the display shows it by its codes.
        display.exposure = self.frontal.exposure;
        self.seconds.frontal += frontal_seconds;
        self.seconds.compensation += start.elapsed().as_secs_f64() - frontal_seconds;
        self.inputs = inputs;
        // The image this refresh replaces: a rolling scan-out shows it below its scan line.
        if let (Some(DisplaySurface::Pixels { image, .. }), Some(last)) =
            (self.surface.take(), &self.shown)
        {
            self.previous = Some((last.times.refresh, Arc::new(image)));
        }
        self.surface = Some(DisplaySurface::Pixels {
            image: display,
            placement: DisplayPlacement::new(&capture.scene.obstacle),
            scan: None,
        });
        let ideal = ideal_map(&geometry, eye_world, d2_used, curved, crop, &map)?;
        self.shown = Some(Shown {
            times,
            eye_estimated,
            head_confidence,
            head_pose,
            eye_used,
            crop,
            d2_used,
            frontal: frontal_camera,
            frontal_exposure: self.frontal.exposure,
            lens: map.lens,
            ideal,
        });
        Ok(self.shown.as_ref().expect("just set"))
    }

    /// The frontal camera's image at capture time `t` (`capture`, the scene then), the
    /// pixels of `region` (`None`: all), into the loop's frontal frame.
    fn capture_frontal(
        &mut self,
        capture: &RenderContext,
        t: f64,
        region: Option<PixelRect>,
    ) -> Result<()> {
        let camera = capture.scene.frontal;
        let mut job = RenderJob::new(&camera, view_bit::FRONTAL)
            .settings(self.settings())
            .label("frontal");
        if let Some(region) = region {
            job = job.region(region);
        }
        let mut frame = std::mem::take(&mut self.frontal);
        let rendered = self.render_carried(capture, t, self.rig.base.frontal, job, &mut frame);
        self.frontal = frame;
        rendered
    }

    /// Renders `job` of a camera the vehicle carries (`base`, where it is at t = 0) at `t`
    /// (`ctx`, the scene then) into `frame`, over the camera's shutter: each sample from where
    /// the vehicle has carried the camera at its instant, over the world of that instant
    /// where the camera sees what moves (render/in_time.rs).
    fn render_carried(
        &mut self,
        ctx: &RenderContext,
        t: f64,
        base: Camera,
        job: RenderJob,
        frame: &mut Frame,
    ) -> Result<()> {
        let vehicle = self.rig.vehicle.clone();
        let pose_at = move |dt: f64| vehicle.world_from_rig(t + dt) * base.world_from_camera;
        let job = job.moving(&pose_at);
        let (camera, metered) =
            self.exposure_of(job.view())
                .exposed(job.camera(), |m| ctx.meter(&job, m), t);
        let job = job.of_camera(&camera);
        render_in_time(ctx, &mut |at| self.context_at(at), t, job, frame)?;
        record_metering(frame, metered);
        Ok(())
    }

    /// The automatic exposure of the camera of `view` (a [`view_bit`]: frontal or back).
    fn exposure_of(&mut self, view: u8) -> &mut Adapting {
        &mut self.exposures[usize::from(view != view_bit::FRONTAL)]
    }

    /// The inputs of the refresh [`SystemLoop::show`] last made, once (`None` after, or
    /// without `byo.capture`).
    pub fn take_inputs(&mut self) -> Option<RefreshInputs> {
        self.inputs.take()
    }

    /// The `seethru` view at display time `t` (`ctx`, the scene then) into `frame` (the truth
    /// of the same instant, or any frame of the driver camera's size: only the pixels where
    /// the display can be seen are rendered), with what [`SystemLoop::show`] last made, each
    /// display row as the scan-out shows it at `t`. Returns the pixels rendered.
    pub fn render_seethru(&mut self, ctx: &RenderContext, t: f64, frame: &mut Frame) -> PixelRect {
        let start = Instant::now();
        let shown = self.shown.as_ref().expect("show() before render_seethru()");
        let driver = ctx.scene.driver;
        // The display where it is now, showing the image of its last refresh.
        let placement = DisplayPlacement::new(&ctx.scene.obstacle);
        let mut surface = self.surface.take().unwrap_or(DisplaySurface::Pixels {
            image: Frame::new(0, 0),
            placement: placement.clone(),
            scan: None,
        });
        let scanout = ctx.scene.obstacle.scanout;
        let period = 1.0 / self.options.timeline.display_hz;
        let since = (t - shown.times.refresh_time).max(0.0);
        let previous = self
            .previous
            .as_ref()
            .filter(|(refresh, _)| *refresh == shown.times.refresh - 1)
            .map(|(_, image)| image.clone());
        surface = match (self.options.run.display, surface) {
            (DisplayModel::Pixels, DisplaySurface::Pixels { image, .. }) => {
                let scan = (scanout != Scanout::default()).then(|| {
                    let rows = image.height;
                    ScannedRows {
                        rows: (0..rows)
                            .map(|r| scanout.row_shows(r, rows, since, period, previous.is_some()))
                            .collect(),
                        previous,
                    }
                });
                DisplaySurface::Pixels {
                    image,
                    placement,
                    scan,
                }
            }
            _ => DisplaySurface::Ideal {
                map: shown.ideal.clone(),
                frontal: shown.frontal,
                placement,
            },
        };
        let region = ctx.difference_region(&driver, view_bit::TRUTH, view_bit::SEETHRU);
        let settings = self.settings();
        ctx.render_into(
            RenderJob::seethru(&driver, &surface)
                .settings(settings)
                .region(region),
            frame,
        );
        self.surface = Some(surface);
        self.seconds.seethru += start.elapsed().as_secs_f64();
        region
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Each stage counts once: distinct powers of two, so a stage left out, counted twice or
    /// subtracted gives another sum.
    #[test]
    fn the_total_is_the_sum_of_every_stage() {
        let seconds = StageSeconds {
            moving: 1.0,
            frontal: 2.0,
            head: 4.0,
            compensation: 8.0,
            seethru: 16.0,
        };
        assert_eq!(seconds.total(), 31.0);
    }
}
