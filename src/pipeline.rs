//! The see-through system end to end (paper §3): the back camera finds the head, the planar
//! model crops the frontal render, the display shows it, and the driver's view with the
//! display in it is rendered beside the ground truth.

use std::path::Path;
use std::time::Instant;

use anyhow::{Context, Result, bail};
use glam::{DVec2, DVec3};
use serde_json::json;

use crate::analysis::k_px;
use crate::camera::Camera;
use crate::compensation::{Crop, ModelPlane, compute_crop, homography};
use crate::display::{
    DisplayModel, DisplayPlacement, DisplaySurface, Filter, MISSING_ID, resample,
};
use crate::frame::Frame;
use crate::head::{FaceDetection, detect, eye_from_detection, gaussian};
use crate::options::resized;
use crate::output::{write_frame, write_text};
use crate::render::{RenderContext, RenderSettings};
use crate::scene::{Obstacle, Scene};
use crate::views::View;

/// How the display image is made.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum, serde::Serialize)]
#[serde(rename_all = "lowercase")]
pub enum Method {
    /// The whole frontal image scaled into the display: the naive baseline.
    None,
    /// The paper's planar compensation at working distance `d2`.
    Planar,
}

/// The working distance of the planar model.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum WorkingDistance {
    /// `d2 → ∞`, the paper's proposal.
    Infinity,
    /// A fixed distance from the display plane, metres, > 0.
    Metres(f64),
    /// The median frontal depth of the region the display covers (a range sensor's answer).
    Auto,
}

impl std::str::FromStr for WorkingDistance {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        match s {
            "inf" | "infinity" => Ok(WorkingDistance::Infinity),
            "auto" => Ok(WorkingDistance::Auto),
            _ => match s.parse::<f64>() {
                Ok(v) if v.is_finite() && v > 0.0 => Ok(WorkingDistance::Metres(v)),
                _ => Err(format!(
                    "`{s}`: expected inf, auto or a distance in metres > 0"
                )),
            },
        }
    }
}

/// Where the head position comes from.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum, serde::Serialize)]
#[serde(rename_all = "lowercase")]
pub enum HeadSource {
    /// The true eye position.
    Oracle,
    /// The back camera's image through the face detector and eqs. d1, b_h.
    Estimated,
}

/// What to do when the crop needs more than the frontal camera sees.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum, serde::Serialize)]
#[serde(rename_all = "lowercase")]
pub enum Outside {
    /// Stop with an error naming the side, the amount and the admissible head region.
    Error,
    /// Show the outside part black and count it as missing.
    Black,
}

#[derive(Clone, Debug)]
pub struct RunOptions {
    pub method: Method,
    pub d2: WorkingDistance,
    pub head: HeadSource,
    /// Head-tracking bias added to the eye, obstacle frame, centimetres.
    pub head_bias_cm: [f64; 3],
    /// Standard deviation of Gaussian head-tracking jitter per axis, centimetres.
    pub head_jitter_cm: f64,
    /// Seed of the jitter.
    pub seed: u32,
    /// Feature width `A` the detector measures (interpupillary distance), metres.
    pub feature_width: f64,
    /// Driver-view resolution overrides (truth, occluded, seethru).
    pub width: Option<u32>,
    pub height: Option<u32>,
    /// Frontal and back camera width overrides (their aspect ratios are kept).
    pub frontal_width: Option<u32>,
    pub back_width: Option<u32>,
    pub spp: u32,
    pub outside: Outside,
    pub filter: Filter,
    /// How the `seethru` view models the display.
    pub display: DisplayModel,
    pub progress: bool,
}

impl Default for RunOptions {
    fn default() -> Self {
        Self {
            method: Method::Planar,
            d2: WorkingDistance::Infinity,
            head: HeadSource::Oracle,
            head_bias_cm: [0.0; 3],
            head_jitter_cm: 0.0,
            seed: 1,
            feature_width: 0.064,
            width: None,
            height: None,
            frontal_width: None,
            back_width: None,
            spp: 4,
            outside: Outside::Error,
            filter: Filter::Bilinear,
            display: DisplayModel::Pixels,
            progress: false,
        }
    }
}

/// Everything a run produces.
pub struct RunResult {
    pub truth: Frame,
    pub occluded: Frame,
    pub frontal: Frame,
    pub back: Frame,
    pub display: Frame,
    pub seethru: Frame,
    pub crop: Crop,
    /// The eye the compensation used, world frame.
    pub eye_used: DVec3,
    pub detection: Option<FaceDetection>,
    /// `run.json`.
    pub report: serde_json::Value,
}

fn obstacle_frame(obstacle: &Obstacle, world: DVec3) -> DVec3 {
    obstacle
        .world_from_obstacle
        .inverse()
        .transform_point3(world)
}

/// The eye the system believes in: true, or estimated from the back image; plus errors.
fn eye_for_compensation(
    scene: &Scene,
    back: &Frame,
    options: &RunOptions,
) -> Result<(DVec3, Option<FaceDetection>)> {
    let (eye, detection) = match options.head {
        HeadSource::Oracle => (scene.eye(), None),
        HeadSource::Estimated => {
            let detection = detect(back)?;
            (
                eye_from_detection(&detection, &scene.back, options.feature_width),
                Some(detection),
            )
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
        detection,
    ))
}

/// The crop that `method` asks for; `frontal` serves the `auto` working distance.
fn crop_for(
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
    let mut crop = compute_crop(
        eye,
        &scene.obstacle,
        &scene.frontal,
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
            let d2 = median_depth_in_crop(frontal, &crop, &scene.obstacle)
                .context("d2 auto: the frontal camera sees no surface where the display is")?;
            crop = compute_crop(
                eye,
                &scene.obstacle,
                &scene.frontal,
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
fn median_depth_in_crop(frontal: &Frame, crop: &Crop, obstacle: &Obstacle) -> Option<f64> {
    let (min, max) = crop.bounds();
    let mut depths: Vec<f64> = Vec::new();
    for y in (min.y.max(0.0) as u32)..(max.y.min(frontal.height as f64) as u32) {
        for x in (min.x.max(0.0) as u32)..(max.x.min(frontal.width as f64) as u32) {
            let p = frontal.position[frontal.index(x, y)];
            if p.is_finite() {
                depths.push(-obstacle_frame(obstacle, p.as_dvec3()).z);
            }
        }
    }
    depths.sort_by(f64::total_cmp);
    depths.get(depths.len() / 2).copied().filter(|d| *d > 0.0)
}

/// How far the crop leaves the frontal image on each side, pixels (0 inside).
fn overflow(crop: &Crop) -> [(&'static str, f64); 4] {
    let [w, h] = crop.frontal_size.map(f64::from);
    let (min, max) = crop.bounds();
    [
        ("left", (-min.x).max(0.0)),
        ("right", (max.x - w).max(0.0)),
        ("top", (-min.y).max(0.0)),
        ("bottom", (max.y - h).max(0.0)),
    ]
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

/// Runs the system on a loaded scene; renders every view.
pub fn run(ctx: &RenderContext, options: &RunOptions) -> Result<RunResult> {
    let mut scene = ctx.scene.clone();
    scene.frontal = resized(scene.frontal, options.frontal_width, None)?;
    scene.back = resized(scene.back, options.back_width, None)?;
    let scene = &scene;
    crate::options::check_spp(options.spp)?;
    if !(options.feature_width > 0.0 && options.feature_width.is_finite()) {
        bail!(
            "--feature-width must be > 0 m, got {}",
            options.feature_width
        );
    }
    if !(options.head_jitter_cm >= 0.0 && options.head_jitter_cm.is_finite())
        || options.head_bias_cm.iter().any(|v| !v.is_finite())
    {
        bail!("head bias must be finite and jitter ≥ 0");
    }
    let driver = resized(scene.driver, options.width, options.height)?;
    let settings = RenderSettings {
        spp: options.spp,
        progress: options.progress,
    };
    let mut timings = serde_json::Map::new();
    let timed =
        |timings: &mut serde_json::Map<String, serde_json::Value>, camera: &Camera, view: View| {
            let (frame, stats) = ctx.render(camera, view.bit(), settings, view.name());
            timings.insert(view.name().into(), json!(stats.seconds));
            frame
        };
    let back = timed(&mut timings, &scene.back, View::Back);
    let frontal = timed(&mut timings, &scene.frontal, View::Frontal);
    let (eye_used, detection) = eye_for_compensation(scene, &back, options)?;
    let (crop, d2_used) = crop_for(scene, eye_used, &frontal, options)?;

    let out = overflow(&crop);
    if options.method == Method::Planar
        && options.outside == Outside::Error
        && let Some((side, px)) = out.iter().copied().find(|(_, px)| *px > 1e-9)
    {
        let d1 = obstacle_frame(&scene.obstacle, eye_used).z;
        let (ax, ay) = admissible_offsets(&scene.frontal, &scene.obstacle, d1, d2_used);
        let axis = obstacle_frame(&scene.obstacle, scene.frontal.position());
        bail!(
            "the crop leaves the frontal camera's view on the {side} by {px:.1} px ({:.1}% of the image); at d1 = {d1:.3} m the eye must stay within x ∈ [{:.3}, {:.3}] m, y ∈ [{:.3}, {:.3}] m of the obstacle frame (use --outside black to show the rest black)",
            100.0 * px
                / if side == "left" || side == "right" {
                    crop.frontal_size[0]
                } else {
                    crop.frontal_size[1]
                } as f64,
            axis.x - ax,
            axis.x + ax,
            axis.y - ay,
            axis.y + ay
        );
    }

    let start = Instant::now();
    let display = resample(
        &frontal,
        &crop,
        scene.obstacle.display_resolution,
        options.filter,
    );
    timings.insert("display".into(), json!(start.elapsed().as_secs_f64()));
    let missing = display
        .object_id
        .iter()
        .filter(|&&i| i == MISSING_ID)
        .count() as f64
        / display.object_id.len() as f64;
    let truth = timed(&mut timings, &driver, View::Truth);
    let occluded = timed(&mut timings, &driver, View::Occluded);
    let placement = DisplayPlacement::new(&scene.obstacle);
    let surface = match options.display {
        DisplayModel::Pixels => DisplaySurface::Pixels {
            image: display.clone(),
            placement,
        },
        DisplayModel::Ideal => DisplaySurface::Ideal {
            crop,
            frontal: scene.frontal,
            placement,
        },
    };
    let (seethru, stats) = ctx.render_seethru(&driver, &surface, settings);
    timings.insert("seethru".into(), json!(stats.seconds));

    let report = report(
        scene,
        options,
        &crop,
        eye_used,
        detection.as_ref(),
        d2_used,
        missing,
        &out,
        timings,
    );
    Ok(RunResult {
        truth,
        occluded,
        frontal,
        back,
        display,
        seethru,
        crop,
        eye_used,
        detection,
        report,
    })
}

#[allow(clippy::too_many_arguments)]
fn report(
    scene: &Scene,
    options: &RunOptions,
    crop: &Crop,
    eye_used: DVec3,
    detection: Option<&FaceDetection>,
    d2_used: Option<f64>,
    missing: f64,
    overflow: &[(&str, f64); 4],
    timings: serde_json::Map<String, serde_json::Value>,
) -> serde_json::Value {
    let eye_o = |e: DVec3| obstacle_frame(&scene.obstacle, e);
    let (true_o, used_o) = (eye_o(scene.eye()), eye_o(eye_used));
    let paper = |o: DVec3| json!({"d1_m": o.z, "b_h_m": -o.x, "b_v_m": o.y});
    let ratios = crop.ratios();
    let [fw, fh] = crop.frontal_size;
    json!({
        "scene": scene.path.display().to_string(),
        "options": {
            "method": options.method,
            "d2": match options.d2 { WorkingDistance::Infinity => json!("inf"), WorkingDistance::Auto => json!("auto"), WorkingDistance::Metres(m) => json!(m) },
            "head": options.head,
            "head_bias_cm": options.head_bias_cm,
            "head_jitter_cm": options.head_jitter_cm,
            "seed": options.seed,
            "feature_width_m": options.feature_width,
            "spp": options.spp,
            "outside": options.outside,
            "filter": options.filter,
            "display": options.display,
        },
        "conventions": "obstacle frame: origin at the display centre, +z towards the driver; paper's b_h = −x (eye on the side of R1 for b_h > 0), b_v = y",
        "eye_true": {"world_m": scene.eye().to_array(), "obstacle_m": true_o.to_array(), "paper": paper(true_o)},
        "eye_used": {"world_m": eye_used.to_array(), "obstacle_m": used_o.to_array(), "paper": paper(used_o), "error_m": (eye_used - scene.eye()).length()},
        "head_detection": detection.map(|d| json!({"face_box_px": d.face_box, "pupils_px": d.pupils, "feature_px": d.feature_px()})),
        "d2_m": d2_used.map_or(json!("inf"), |d| json!(d)),
        "frontal_half_angle_deg": scene.frontal.half_angle_x.to_degrees(),
        "crop": {
            "corners_frontal_px_tl_tr_br_bl": crop.corners.map(|c| c.to_array()),
            "axis_aligned": crop.is_axis_aligned(1e-6),
            "R1_left": ratios.left, "R2_right": ratios.right, "R_top": ratios.top, "R_bottom": ratios.bottom,
            "K_px": {"left": k_px(ratios.left, fw), "right": k_px(ratios.right, fw), "top": k_px(ratios.top, fh), "bottom": k_px(ratios.bottom, fh)},
            "outside_frontal_view_px": overflow.iter().map(|(s, px)| (s.to_string(), json!(px))).collect::<serde_json::Map<_, _>>(),
        },
        "display_resolution": scene.obstacle.display_resolution,
        "missing_fraction": missing,
        "timings_s": timings,
    })
}

/// `seethru run`: renders the six views into `out` with `run.json` and the metrics.
pub fn run_command(
    scene_path: &Path,
    out: &Path,
    options: &RunOptions,
    band: u32,
    bvh: crate::accel::BvhKind,
) -> Result<()> {
    let scene = crate::scene::Scene::load(scene_path)?;
    let ctx = RenderContext::new(scene, bvh)?;
    let result = run(&ctx, options)?;
    std::fs::create_dir_all(out)
        .with_context(|| format!("cannot create output directory {}", out.display()))?;
    for (name, frame) in [
        ("truth", &result.truth),
        ("occluded", &result.occluded),
        ("frontal", &result.frontal),
        ("back", &result.back),
        ("display", &result.display),
        ("seethru", &result.seethru),
    ] {
        write_frame(frame, out, name)?;
    }
    write_text(
        &out.join("run.json"),
        &serde_json::to_string_pretty(&result.report)?,
    )?;
    let frames = [&result.truth, &result.seethru, &result.occluded];
    let (maps, metrics) = crate::metrics::measure(&ctx, &ctx.scene, ctx.scene.eye(), frames, band);
    crate::metrics::write_metrics(out, &maps, &result.truth, &metrics)?;
    eprintln!(
        "wrote the six views (PNG, ids PNG, EXR), run.json and the metrics to {}",
        out.display()
    );
    Ok(())
}

/// `seethru measure`: the metrics of a run directory, from its saved EXRs.
pub fn measure_command(
    dir: &Path,
    band: u32,
    bvh: crate::accel::BvhKind,
) -> Result<serde_json::Value> {
    let text = std::fs::read_to_string(dir.join("run.json")).with_context(|| {
        format!(
            "{}: no run.json (not a `seethru run` directory?)",
            dir.display()
        )
    })?;
    let run_json: serde_json::Value = serde_json::from_str(&text)?;
    let scene_path = run_json["scene"]
        .as_str()
        .context("run.json has no scene path")?;
    let ctx = RenderContext::new(crate::scene::Scene::load(Path::new(scene_path))?, bvh)?;
    let read = |name: &str| crate::output::read_exr(&dir.join(format!("{name}.exr")));
    let (truth, seethru, occluded) = (read("truth")?, read("seethru")?, read("occluded")?);
    let (maps, metrics) = crate::metrics::measure(
        &ctx,
        &ctx.scene,
        ctx.scene.eye(),
        [&truth, &seethru, &occluded],
        band,
    );
    crate::metrics::write_metrics(dir, &maps, &truth, &metrics)?;
    Ok(metrics)
}
