//! `seethru capture`: what a real see-through system's algorithm receives, written to a
//! folder — the frontal and back images, the depth sensor's image when asked for, the head
//! tracker's output, calibration.json and a fingerprint — with the truth kept apart in
//! `truth/` (a method must not read it; `seethru score` does).

use std::path::{Path, PathBuf};

use anyhow::{Result, bail};
use exr::prelude::{AnyChannel, FlatSamples};
use seethru::io::atomic::write_text;
use seethru::io::capture_folder::{COMMAND_FILE, MANIFEST_FILE, command_json};
use seethru::io::display_map::write_npy_f32;
use seethru::io::frame_files::{ExrContent, write_color_png, write_exr_channels, write_view_exr};
use seethru::io::output_paths::{Input, Output, check_paths};
use seethru::io::staged::StagedDir;
use seethru::render::frame::Frame;
use seethru::render::integrator::RenderContext;
use seethru::scene::Scene;
use seethru::scene::lens_keys::read_calibration_file;
use seethru::system::capture::{Capture, capture};
use seethru::system::eyes::{Eye, Eyes, MAX_IPD};
use seethru::system::memory::{check_memory, run_estimate};
use seethru::system::options::{HeadSource, RunOptions};
use seethru::system::reads::capture_reads;
use serde_json::json;

use crate::cli::args::{
    HeadErrorArgs, RenderArgs, choice, pixels, positive, refuse_ignored, with_threads,
};
use crate::cli::run_eyes::EyesFlag;
use crate::cli::scene_model_args::SceneModelArgs;

/// The capture's flags parsed alone (what `score` reads back from `truth/`).
#[derive(clap::Parser)]
#[command(name = "seethru capture", allow_negative_numbers = true)]
pub struct CaptureCommand {
    #[command(flatten)]
    pub args: CaptureArgs,
}

/// The flags of a capture (run's flags that decide what the system receives).
#[derive(clap::Args)]
#[command(allow_negative_numbers = true)]
pub struct CaptureArgs {
    /// Scene file (TOML).
    pub scene: PathBuf,
    /// Output directory: the system's inputs, with the truth in OUT/truth/.
    #[arg(long)]
    pub out: PathBuf,
    /// A TOML file with a [calibration] table (as in a scene file) that replaces the scene's:
    /// the cameras calibration.json states.
    #[arg(long, value_name = "FILE")]
    pub calibration: Option<PathBuf>,
    /// oracle: the true eye; estimated: face detection on the back camera's image.
    #[arg(long, value_enum, value_parser = choice::<HeadSource>(), default_value_t = HeadSource::Oracle)]
    pub head: HeadSource,
    /// Head-tracking errors and the detector's feature width.
    #[command(flatten)]
    pub head_errors: HeadErrorArgs,
    /// Frontal camera width, pixels in [1, 16384] (aspect ratio kept; default: the scene's).
    #[arg(long = "frontal-width", value_parser = pixels)]
    pub frontal_width: Option<u32>,
    /// Back camera width, pixels in [1, 16384] (aspect ratio kept; default: the scene's).
    #[arg(long = "back-width", value_parser = pixels)]
    pub back_width: Option<u32>,
    /// The eye the driver's views are rendered from: mono, left or right (not both).
    #[arg(long, value_enum, value_parser = choice::<EyesFlag>(), default_value_t = EyesFlag::Mono)]
    pub eyes: EyesFlag,
    /// Interpupillary distance, metres in [1e-6, 0.1].
    #[arg(long, default_value_t = 0.064, value_parser = positive(MAX_IPD))]
    pub ipd: f64,
    /// The eye the head estimate is for.
    #[arg(long = "target-eye", value_enum, value_parser = choice::<Eye>(), default_value_t = Eye::Cyclopean)]
    pub target_eye: Eye,
    /// Write the depth sensor's image (depth.npy, depth.exr), as --method depth models it
    /// with --depth-sensor and its settings.
    #[arg(long)]
    pub depth: bool,
    /// The depth sensor (with --depth).
    #[command(flatten)]
    pub scene_model: SceneModelArgs,
    /// Which EXRs the capture writes: all (frontal.exr and back.exr in colour, depth.exr with
    /// --depth, truth/truth.exr with every AOV), lean (as all, truth/truth.exr with R, G, B,
    /// Z, N and the ids), colour (the colour EXRs only: truth/truth.exr is R, G, B, A, no
    /// depth.exr) or none (PNGs, depth.npy and the JSON files only).
    #[arg(long, value_enum, value_parser = choice::<ExrContent>(), default_value_t = ExrContent::All)]
    pub exr: ExrContent,
    /// Sizes of the driver's view (the truth), samples, threads.
    #[command(flatten)]
    pub render: RenderArgs,
}

impl CaptureArgs {
    /// The run options of the capture (the method's choices left at their defaults).
    pub fn options(&self) -> Result<RunOptions> {
        if self.eyes == EyesFlag::Both {
            bail!("--eyes both: a capture is for one eye (mono, left or right)");
        }
        let options = RunOptions {
            head: self.head,
            head_bias_cm: self.head_errors.head_bias_cm,
            head_jitter_cm: self.head_errors.head_jitter_cm,
            seed: self.head_errors.seed,
            feature_width: self.head_errors.feature_width,
            require_confident_head: self.head_errors.require_confident_head,
            width: self.render.width,
            height: self.render.height,
            frontal_width: self.frontal_width,
            back_width: self.back_width,
            spp: self.render.spp,
            eyes: Eyes {
                view: self.eyes.view(),
                target: self.target_eye,
                ipd: self.ipd,
            },
            scene_model: self.scene_model.options(),
            progress: true,
            ..RunOptions::default()
        };
        refuse_ignored(&capture_reads(&options, self.depth))?;
        Ok(options)
    }

    /// The scene with the capture's calibration file, if any.
    pub fn scene(&self) -> Result<Scene> {
        let mut scene = Scene::load(&self.scene)?;
        if let Some(path) = &self.calibration {
            scene.calibration = read_calibration_file(path, &scene.frontal, &scene.back)?;
        }
        Ok(scene)
    }

    pub fn run(self) -> Result<()> {
        let mut inputs = vec![Input::file("SCENE", &self.scene)];
        inputs.extend(
            self.calibration
                .as_deref()
                .map(|c| Input::file("--calibration", c)),
        );
        check_paths(&inputs, &[Output::folder("--out", &self.out)])?;
        let options = self.options()?;
        with_threads(self.render.threads, || {
            let scene = self.scene()?;
            check_memory(&run_estimate(&scene, &options)?, self.render.max_memory)?;
            let ctx = RenderContext::new(scene)?;
            let captured = capture(&ctx, &options, self.depth)?;
            let staged = StagedDir::new(&self.out)?;
            write_capture(staged.path(), &captured, &self.command_json()?, self.exr)?;
            staged.commit()?;
            seethru::util::progress::summary(format!(
                "captured {} (fingerprint {}): frontal {}×{}, back {}×{}{}, head.json, calibration.json; the truth in {}",
                self.out.display(),
                captured.fingerprint,
                captured.frontal.width,
                captured.frontal.height,
                captured.back.width,
                captured.back.height,
                captured.depth.as_ref().map_or(String::new(), |d| format!(
                    ", depth {}×{}",
                    d.camera.width, d.camera.height
                )),
                self.out.join("truth").display()
            ));
            Ok(())
        })?
    }

    /// The command line and folder that `score` captures again from.
    fn command_json(&self) -> Result<serde_json::Value> {
        let args: Vec<String> = std::env::args_os()
            .skip_while(|a| a != "capture")
            .skip(1)
            .filter(|a| a != "--quiet")
            .map(|a| a.to_string_lossy().into_owned())
            .collect();
        Ok(command_json(&std::env::current_dir()?, &args))
    }
}

/// Only the colour of a frame (the rest of its AOVs is the renderer's truth).
fn write_colour_exr(frame: &Frame, path: &Path) -> Result<()> {
    let channels = ["R", "G", "B"]
        .iter()
        .enumerate()
        .map(|(k, name)| {
            AnyChannel::new(
                *name,
                FlatSamples::F32(frame.color.iter().map(|c| c[k]).collect()),
            )
        })
        .collect();
    write_exr_channels(path, frame.width, frame.height, channels)
}

/// The capture's files into `out` (a staging folder): inputs at the top, the truth apart;
/// `exr` says which EXRs ([`CaptureArgs::exr`]).
pub fn write_capture(
    out: &Path,
    c: &Capture,
    command: &serde_json::Value,
    exr: ExrContent,
) -> Result<()> {
    let mut files = Vec::new();
    for (name, frame) in [("frontal", &c.frontal), ("back", &c.back)] {
        write_color_png(frame, &out.join(format!("{name}.png")))?;
        files.push(format!("{name}.png"));
        if exr != ExrContent::None {
            write_colour_exr(frame, &out.join(format!("{name}.exr")))?;
            files.push(format!("{name}.exr"));
        }
    }
    files.extend(["head.json".to_string(), "calibration.json".to_string()]);
    if let Some(d) = &c.depth {
        // Axial depth, metres; NaN where the sensor has no return (sky, past its range).
        let depth: Vec<f32> = d
            .inverse_depth
            .iter()
            .map(|&v| if v > 0.0 { 1.0 / v } else { f32::NAN })
            .collect();
        let [w, h] = [d.camera.width, d.camera.height];
        write_npy_f32(&out.join("depth.npy"), &[h as usize, w as usize], &depth)?;
        // depth.exr is no colour: only `--exr lean` and `all` write it (depth.npy holds the
        // same).
        if matches!(exr, ExrContent::Lean | ExrContent::All) {
            write_exr_channels(
                &out.join("depth.exr"),
                w,
                h,
                vec![
                    AnyChannel::new("Z", FlatSamples::F32(depth)),
                    AnyChannel::new("inverse_depth", FlatSamples::F32(d.inverse_depth.clone())),
                ],
            )?;
        }
    }
    write_text(
        &out.join("head.json"),
        &serde_json::to_string_pretty(&json!({
            "head": c.head,
            "conventions": "eye_world_m: seethru's world frame; eye_obstacle_m: the obstacle (display) frame of calibration.json; detection: back-camera pixels, seethru's continuous convention (OpenCV's + 0.5)",
        }))?,
    )?;
    write_text(
        &out.join("calibration.json"),
        &serde_json::to_string_pretty(&c.calibration)?,
    )?;
    let truth = out.join("truth");
    write_view_exr(&c.truth.truth, &truth.join("truth.exr"), exr)?;
    write_color_png(&c.truth.truth, &truth.join("truth.png"))?;
    write_text(
        &truth.join("truth.json"),
        &serde_json::to_string_pretty(&json!({
            "eye_world_m": c.truth.eye_world_m.to_array(),
            "cameras": c.truth.cameras,
            "note": "a method must not read this folder",
        }))?,
    )?;
    write_text(
        &truth.join(COMMAND_FILE),
        &serde_json::to_string_pretty(command)?,
    )?;
    // Last: a folder with capture.json holds a finished capture.
    write_text(
        &out.join(MANIFEST_FILE),
        &serde_json::to_string_pretty(&json!({
            "fingerprint": c.fingerprint,
            "display_resolution_px": [c.calibration["display"]["resolution_px"][0], c.calibration["display"]["resolution_px"][1]],
            "frontal_size_px": [c.frontal.width, c.frontal.height],
            "back_size_px": [c.back.width, c.back.height],
            "depth": c.depth.as_ref().map(|d| json!({"file": "depth.npy", "size_px": [d.camera.width, d.camera.height], "sensor": d.model, "units": "axial depth along the frontal camera's axis, metres, float32, shape (height, width); NaN: no return"})),
            "files": files,
            "map_format": "a display map: .npy float32 of shape (display height, display width, 2), [..., 0] = x and [..., 1] = y frontal pixels in OpenCV's remap convention (pixel centres at integers), NaN shows nothing; or EXR with channels x, y. State the capture it was made for in <map>.json: {\"capture_fingerprint\": \"...\"}",
            "truth": "truth/ holds the truth view and the true eye: a method must not read it",
        }))?,
    )?;
    Ok(())
}
