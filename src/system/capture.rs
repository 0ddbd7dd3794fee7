//! Bring your own method: what a real see-through system's algorithm receives (a capture),
//! and the measurement of a display that an outside method made from it (a score).
//!
//! A [`Capture`] holds the frontal and back images, the depth sensor's image when one is
//! asked for, the head tracker's output, the rig's calibration (`calibration.json`) and a
//! fingerprint; its [`CaptureTruth`] holds what a method must not see (the truth view, the
//! true eye). A method answers with a [`DisplayMap`] (per display pixel, the frontal pixel it
//! shows, OpenCV's `remap` convention) and/or a [`DisplayImage`]; [`score`] shows that on the
//! display and measures the driver's view exactly as `run` does, through the same pipeline
//! (`pipeline::run_given`) and the same metrics (`measure::metrics::measure`, called by the
//! caller). Files are the command's concern (cli/capture.rs, cli/score.rs).

use anyhow::{Result, bail};
use glam::{DVec2, DVec3, Vec3};
use rayon::prelude::*;
use serde_json::{Value, json};

use crate::geometry::camera::Camera;
use crate::geometry::opencv::camera_json;
use crate::render::frame::{Frame, Pixel};
use crate::render::integrator::RenderContext;
use crate::render::render_job::RenderJob;
use crate::render::settings::{RenderSettings, check_spp};
use crate::render::views::View;
use crate::system::calibration_json::calibration_json;
use crate::system::depth_sensor::{DepthMap, SensorModel, sense_from};
use crate::system::display::{MISSING_ID, sample};
use crate::system::head::FaceDetection;
use crate::system::options::{HeadSource, RunOptions};
use crate::system::pipeline::{Given, RunResult, driver_camera, eye_for_compensation, run_given};
use crate::util::hash::Fnv64;

/// The head tracker's output, as the system's algorithm receives it.
#[derive(Clone, Debug, serde::Serialize)]
pub struct HeadEstimate {
    /// `oracle` (the true eye handed over) or `estimated` (the back camera's detector).
    pub source: HeadSource,
    /// The estimated eye the compensation should serve, world frame, metres (with the
    /// capture's injected bias and jitter, as a real tracker's error).
    pub eye_world_m: [f64; 3],
    /// The same eye in the obstacle (display) frame, metres.
    pub eye_obstacle_m: [f64; 3],
    /// What the detector found in the back image (`None` with the oracle): every field of
    /// `system::head::FaceDetection`, serialised as it is.
    pub detection: Option<FaceDetection>,
    /// The yaw fit of the mesh face ([`crate::scene::DriverFace::Mesh`]): the fitted eye,
    /// yaw, outline residual and margin; absent for the ellipsoid face and the oracle.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub pose: Option<crate::system::head_pose::HeadPose>,
}

/// What a method must not read: the driver's true eye and the truth view from it.
#[derive(Clone, Debug)]
pub struct CaptureTruth {
    /// The eye the driver's views are rendered from, world frame, metres.
    pub eye_world_m: DVec3,
    /// The truth view (the scene without the obstacle) from that eye, at the run's size.
    pub truth: Frame,
    /// The true cameras and the driver's camera, OpenCV's conventions (for `truth/`).
    pub cameras: Value,
}

/// Everything a real system's algorithm receives, and its truth kept apart.
#[derive(Clone, Debug)]
pub struct Capture {
    /// The frontal camera's image (colour is the input; the other AOVs serve `score` only).
    pub frontal: Frame,
    /// The back camera's image.
    pub back: Frame,
    /// The depth sensor's image as `--method depth` models it, when one was asked for.
    pub depth: Option<DepthMap>,
    pub head: HeadEstimate,
    /// `calibration.json`: the calibrated cameras, display and obstacle frame.
    pub calibration: Value,
    /// 16 hex digits over the frontal and back images, the head estimate, the calibration and
    /// the driver's view size (not the depth image, which follows from the same settings): a
    /// map made for another capture is refused by it.
    pub fingerprint: String,
    pub truth: CaptureTruth,
}

/// Renders what the system receives under `options` (its sizes, head source and errors,
/// eyes, calibration, and the depth sensor of `options.scene_model` when `with_depth`).
/// Deterministic: the same capture for any thread count.
pub fn capture(ctx: &RenderContext, options: &RunOptions, with_depth: bool) -> Result<Capture> {
    let mut scene = ctx.scene.clone();
    scene.frontal = options.sized_frontal(scene.frontal)?;
    scene.back = options.sized_back(scene.back)?;
    let scene = &scene;
    check_spp(options.spp)?;
    options.eyes.check().map_err(anyhow::Error::msg)?;
    let settings = RenderSettings {
        spp: options.spp,
        progress: options.progress,
    };
    let captured = crate::system::pipeline::frontal_capture(scene, options)?;
    let render =
        |job: RenderJob, view: View| ctx.render(job.settings(settings).label(view.name())).0;
    let back = render(RenderJob::new(&scene.back, View::Back.bit()), View::Back);
    let frontal = render(captured.job(View::Frontal.bit()), View::Frontal);
    let (eye, fix) = eye_for_compensation(scene, &back, options)?;
    let depth = if with_depth {
        let model = SensorModel::resolve(&options.scene_model.sensor, &scene.frontal)?;
        Some(sense_from(
            ctx,
            &captured.camera,
            &scene.frontal,
            &frontal,
            model,
            options.seed,
        ))
    } else {
        None
    };
    let head = HeadEstimate {
        source: options.head,
        eye_world_m: eye.to_array(),
        eye_obstacle_m: scene.obstacle.in_obstacle_frame(eye).to_array(),
        detection: fix.map(|f| f.detection),
        pose: fix.and_then(|f| f.pose),
    };
    let mut calibration = calibration_json(scene)?;
    // Before the depth sensor is added: a map made from a capture with depth fits the same
    // capture without (compare's), the sensor being a function of the same settings.
    let driver = driver_camera(scene, options)?;
    let fingerprint = fingerprint(&frontal, &back, &head, &calibration, &driver)?;
    if let Some(d) = &depth {
        let mut sensor = camera_json(&d.camera);
        sensor["model"] = json!(d.model);
        sensor["note"] = json!(
            "the depth sensor shares the calibrated frontal camera's pose and field of view at its own resolution"
        );
        calibration["depth_sensor"] = sensor;
    }
    let truth = render(RenderJob::new(&driver, View::Truth.bit()), View::Truth);
    let true_cameras = json!({
        "frontal": camera_json(&scene.frontal),
        "back": camera_json(&scene.back),
        "driver_view": camera_json(&driver),
        "note": "the true cameras (the renderer's) and the driver's view camera, OpenCV's conventions as in calibration.json",
    });
    Ok(Capture {
        frontal,
        back,
        depth,
        head,
        calibration,
        fingerprint,
        truth: CaptureTruth {
            eye_world_m: driver.position(),
            truth,
            cameras: true_cameras,
        },
    })
}

/// 16 hex digits over the images, the head estimate, the calibration and the size of the
/// driver's view the capture is scored in ([`Capture::fingerprint`]).
pub fn fingerprint(
    frontal: &Frame,
    back: &Frame,
    head: &HeadEstimate,
    calibration: &Value,
    driver: &Camera,
) -> Result<String> {
    let mut h = Fnv64::default();
    // The driver's view is not an input of the method, but a map is scored in it: captures
    // at `--width 160` and `161` give the method the same images and are still two captures.
    h.bytes(&driver.width.to_le_bytes())
        .bytes(&driver.height.to_le_bytes());
    for frame in [frontal, back] {
        h.bytes(&frame.width.to_le_bytes())
            .bytes(&frame.height.to_le_bytes());
        for c in &frame.color {
            for v in c.to_array() {
                h.bytes(&v.to_le_bytes());
            }
        }
    }
    h.bytes(serde_json::to_string(head)?.as_bytes())
        .bytes(calibration.to_string().as_bytes());
    Ok(format!("{:016x}", h.finish()))
}

/// A method's display map: for display pixel (column i, row j), the frontal pixel it shows,
/// OpenCV's `remap` convention (pixel centres at integers: seethru's continuous pixel is the
/// map's + 0.5). NaN, or a point outside the frontal image, shows nothing (counted missing).
#[derive(Clone, Debug, PartialEq)]
pub struct DisplayMap {
    /// Display width and height, pixels (must equal the display's resolution).
    pub width: u32,
    pub height: u32,
    /// Row-major (x, y) per display pixel, frontal pixels, OpenCV's convention.
    pub xy: Vec<[f32; 2]>,
    /// The capture fingerprint the map says it was made for (`None`: not stated, not checked).
    pub fingerprint: Option<String>,
}

/// A display image a method made itself (blending, inpainting): linear RGB per display pixel.
#[derive(Clone, Debug, PartialEq)]
pub struct DisplayImage {
    pub width: u32,
    pub height: u32,
    /// Row-major linear RGB, ≥ 0 (1.0 is display white); with `codes`, the display's codes
    /// in [0, 1].
    pub color: Vec<Vec3>,
    /// Whether `color` holds the display's codes (what its transfer curve turns into light,
    /// as a coded camera's image is shown) rather than linear light.
    pub codes: bool,
}

impl DisplayImage {
    /// The values the display is driven with ([`crate::scene::DisplayTransfer`]): codes as
    /// they are; linear light through the inverse of the display's transfer, so that it gives
    /// off that light. Refused: codes for a display that makes no light of codes (an ideal
    /// display, which shows radiance).
    pub fn drive(&self, display: Option<&crate::scene::DisplayLight>) -> Result<Vec<Vec3>> {
        match (display, self.codes) {
            (None, true) => bail!(
                "a display image of codes needs a display that turns codes into light: the scene's [obstacle] has no display_peak_cd_m2 (its display is ideal and shows linear light)"
            ),
            (Some(d), false) => Ok(self
                .color
                .iter()
                .map(|c| c.map(|v| d.transfer.code(v)))
                .collect()),
            _ => Ok(self.color.clone()),
        }
    }
}

/// A method's display with how it was made: the frames of `run` and a note for the metrics.
pub struct Scored {
    /// The run's frames (truth, occluded, frontal, back, display, seethru) and run.json.
    pub run: RunResult,
    /// Display pixels the map leaves blank: NaN, or outside the frontal image.
    pub blank_map_pixels: usize,
    /// Whether the display carries geometry (a map was given): misregistration needs one.
    pub has_map: bool,
}

/// Checks a map and an image against the capture's display (and, where it is known, its
/// `frontal_size`: width, height in pixels); one message per fault, naming what is wrong and
/// what is expected.
pub fn check_display_input(
    display_size: [u32; 2],
    frontal_size: Option<[u32; 2]>,
    fingerprint: &str,
    map: Option<&DisplayMap>,
    image: Option<&DisplayImage>,
) -> Result<()> {
    let [dw, dh] = display_size;
    if map.is_none() && image.is_none() {
        bail!(
            "a display map or a display image is needed (option `map` FILE, option `display_image` FILE)"
        );
    }
    if let Some(m) = map {
        if (m.width, m.height) != (dw, dh) {
            bail!(
                "the map is {}×{} display pixels (width × height), the capture's display is {dw}×{dh}: a map has shape (height, width, 2) = ({dh}, {dw}, 2)",
                m.width,
                m.height
            );
        }
        if m.xy.len() != (dw * dh) as usize {
            bail!("the map has {} entries, {dw}×{dh} expected", m.xy.len());
        }
        if m.xy.iter().all(|p| p[0].is_nan() || p[1].is_nan()) {
            bail!("every entry of the map is NaN: it shows nothing on the display");
        }
        // A map for another frontal size (one made for a capture at the scene's frontal width,
        // shown by a sequence at the driver view's) shows nothing: say so instead of scoring
        // a blank display.
        if let Some([fw, fh]) = frontal_size {
            let inside = |p: &[f32; 2]| {
                (-0.5..fw as f32 - 0.5).contains(&p[0]) && (-0.5..fh as f32 - 0.5).contains(&p[1])
            };
            if !m.xy.iter().any(inside) {
                let reach =
                    m.xy.iter()
                        .filter(|p| p[0].is_finite() && p[1].is_finite())
                        .fold([f32::MIN; 2], |r, p| [r[0].max(p[0]), r[1].max(p[1])]);
                bail!(
                    "no point of the map lies inside the {fw}×{fh} frontal image (its points reach x = {}, y = {}): it was made for another frontal size (the frontal width must be the capture's)",
                    reach[0],
                    reach[1]
                );
            }
        }
        if let Some(f) = &m.fingerprint
            && f != fingerprint
        {
            bail!(
                "the map was made for capture {f}, not for this capture ({fingerprint}): capture again or score it against its own capture"
            );
        }
    }
    if let Some(i) = image {
        if (i.width, i.height) != (dw, dh) {
            bail!(
                "the display image is {}×{} pixels, the capture's display is {dw}×{dh}",
                i.width,
                i.height
            );
        }
        if i.color.len() != (dw * dh) as usize {
            bail!(
                "the display image has {} pixels, {dw}×{dh} expected",
                i.color.len()
            );
        }
    }
    Ok(())
}

/// The display frame of a method's output: the frontal frame sampled at the map (colour by
/// the options' filter, the other AOVs from the nearest pixel, as `run`'s display), with the
/// image's colours where an image is given. An image alone carries no geometry: its pixels
/// have no position, so misregistration is undefined there (counted, not dropped).
pub fn display_from(
    frontal: &Frame,
    display_size: [u32; 2],
    options: &RunOptions,
    map: Option<&DisplayMap>,
    image: Option<&DisplayImage>,
) -> Frame {
    let [dw, dh] = display_size;
    let n = (dw * dh) as usize;
    let mut pixels: Vec<Pixel> = match map {
        Some(m) => {
            m.xy.par_iter()
                .map(|&[x, y]| {
                    // OpenCV's pixel centres are at integers; seethru's at +0.5.
                    let p = DVec2::new(x as f64 + 0.5, y as f64 + 0.5);
                    sample(frontal, p, options.filter)
                })
                .collect()
        }
        None => vec![
            Pixel {
                normal: Vec3::ZERO,
                ..Pixel::SKY
            };
            n
        ],
    };
    if let Some(i) = image {
        for (p, &c) in pixels.iter_mut().zip(&i.color) {
            // What the image shows where the map shows nothing is still shown.
            if p.object_id == MISSING_ID {
                *p = Pixel::SKY;
            }
            p.color = c;
        }
    }
    Frame::from_pixels(dw, dh, &pixels)
}

/// Shows a method's map and/or image on the capture's display and renders the driver's view
/// with it, exactly as `run` would with a built-in method (`options` are the capture's; the
/// method, working distance and display model are not used). The caller measures the frames
/// with `measure::metrics::measure`, as `run` does.
pub fn score(
    ctx: &RenderContext,
    options: &RunOptions,
    capture: &Capture,
    map: Option<&DisplayMap>,
    image: Option<&DisplayImage>,
) -> Result<Scored> {
    let display_size = ctx.scene.obstacle.display_resolution;
    let frontal_size = Some([capture.frontal.width, capture.frontal.height]);
    check_display_input(display_size, frontal_size, &capture.fingerprint, map, image)?;
    let driven = image
        .map(|i| -> Result<DisplayImage> {
            Ok(DisplayImage {
                color: i.drive(ctx.scene.obstacle.display_light.as_ref())?,
                ..i.clone()
            })
        })
        .transpose()?;
    let mut display = display_from(
        &capture.frontal,
        display_size,
        options,
        map,
        driven.as_ref(),
    );
    if image.is_none() {
        // The frontal image's colours: shown by their codes, as `run` shows them.
        display.exposure = capture.frontal.exposure;
    }
    let blank_map_pixels = match map {
        Some(_) => display
            .object_id
            .iter()
            .filter(|&&i| i == MISSING_ID)
            .count(),
        None => 0,
    };
    let mut run = run_given(
        ctx,
        options,
        Given {
            truth: Some(&capture.truth.truth),
            back: Some(&capture.back),
            frontal: Some(&capture.frontal),
            display: Some(display),
        },
    )?;
    crate::system::pipeline::check_display_seen(ctx, &run.occluded)?;
    let source = match (map.is_some(), image.is_some()) {
        (true, true) => "map and image",
        (true, false) => "map",
        _ => "image",
    };
    run.report["options"]["method"] = json!("external");
    run.report["external_method"] = json!({
        "display_from": source,
        "capture_fingerprint": capture.fingerprint,
        "map_fingerprint_checked": map.is_some_and(|m| m.fingerprint.is_some()),
        "blank_map_pixels": blank_map_pixels,
        "note": "the crop and d2 of this report are the capture's planar d2 = ∞ crop, for reference only: the display came from the method",
    });
    Ok(Scored {
        run,
        blank_map_pixels,
        has_map: map.is_some(),
    })
}
