//! `seethru sequence`: the see-through system over time — vehicle motion, head motion and
//! latency — measured frame by frame against the truth at the same instant.

use crate::cli::load_scene;
use crate::cli::with_flags;
use seethru::util::option_words::as_flags;
use std::path::{Path, PathBuf};

use anyhow::{Context, Result, bail};
use seethru::io::atomic::write_text;
use seethru::io::frame_files::{ExrContent, write_color_png, write_view_exr};
use seethru::io::output_paths::{Input, Output, check_paths};
use seethru::io::staged::StagedDir;
use seethru::measure::headline::{RunKind, summary_text};
use seethru::measure::image_metrics::Flip;
use seethru::measure::option_table::MAX_LATENCY_MS;
use seethru::measure::run_spec::RunSpec;
use seethru::measure::sequence::{Measuring, SequenceRun, run_sequence_hazards};
use seethru::measure::sequence_budget::{has_effects_of_time, run_budget};
use seethru::measure::sequence_files::{
    Preview, frames_csv, hazard_figure, latency_figure, mean_of_frame_stats, over_time_figure,
    summary,
};
use seethru::measure::sequence_records::head_warning;
use seethru::scene::head_path::HeadPath;
use seethru::system::memory::{check_memory, sequence_estimate};
use seethru::system::options::{HeadSource, RunOptions};
use seethru::system::reads::{hazard_bound_reads, sequence_reads};
use seethru::system::sequence::head_motion::{HeadMotion, HeadPreset};
use seethru::system::sequence::predict::Prediction;
use seethru::system::sequence::system_loop::SequenceOptions;
use seethru::system::sequence::timeline::Timeline;
use seethru::util::progress::summary as say;
use serde_json::json;

use crate::cli::args::{ReadWhen, choice, positive, real, refuse_ignored, threads, with_threads};
use crate::cli::option_args::{self, OptionArgs};

/// Longest latency, ms.
/// Most latencies in one `--latency-camera` list.
const MAX_LATENCIES: usize = 64;

/// Camera latencies, ms: one sequence each.
#[derive(Clone, Debug)]
struct Latencies(Vec<f64>);

/// `--latency-camera`: milliseconds in [0, 10000], one value or a comma-separated list.
fn latency_list(text: &str) -> Result<Latencies, String> {
    let parts: Vec<&str> = text.split(',').collect();
    let range = format!(
        "must be milliseconds in [0, {MAX_LATENCY_MS}], one value or up to {MAX_LATENCIES} separated by commas"
    );
    if parts.len() > MAX_LATENCIES {
        return Err(range);
    }
    parts
        .iter()
        .map(|p| real(0.0, MAX_LATENCY_MS)(p).map_err(|_| range.clone()))
        .collect::<Result<Vec<f64>, String>>()
        .and_then(|values| {
            // Each latency has a folder of its own, named by its short value.
            let mut seen = std::collections::HashMap::new();
            for &ms in &values {
                if let Some(first) = seen.insert(latency_dir(ms), ms) {
                    return Err(format!(
                        "latencies {} and {} ms are the same to 6 digits (folder {}): give each once",
                        first,
                        ms,
                        latency_dir(ms)
                    ));
                }
            }
            Ok(Latencies(values))
        })
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
enum FramesFormat {
    /// No per-frame images.
    None,
    /// truth_NNNNN.png and seethru_NNNNN.png (colour, sRGB).
    Png,
    /// truth_NNNNN.exr and seethru_NNNNN.exr (every AOV).
    Exr,
}

#[derive(clap::Args)]
#[command(allow_negative_numbers = true)]
pub struct Sequence {
    /// Scene file (TOML).
    scene: PathBuf,
    /// Output directory.
    #[arg(long)]
    out: PathBuf,
    /// Length of the sequence, seconds in [1e-6, 3600].
    #[arg(long, default_value_t = 4.0, value_parser = positive(3600.0))]
    duration: f64,
    /// Frames measured per second, Hz in [1e-6, 1000].
    #[arg(long, default_value_t = 60.0, value_parser = positive(1000.0))]
    fps: f64,
    /// Display refresh rate, Hz in [1e-6, 1000] (sample and hold; default: --fps).
    #[arg(long = "display-hz", value_parser = positive(1000.0))]
    display_hz: Option<f64>,
    /// Head motion relative to the vehicle: still, sway (lateral sinusoid) or lean (towards
    /// the pillar to look around it).
    #[arg(long, value_enum, value_parser = choice::<HeadPreset>(), default_value_t = HeadPreset::Still)]
    head: HeadPreset,
    /// A recorded head path instead of --head: CSV of t,x,y,z (seconds; the eye in the
    /// obstacle frame, metres), times increasing.
    #[arg(long = "head-path", value_name = "CSV", conflicts_with = "head")]
    head_path: Option<PathBuf>,
    /// Sway amplitude, centimetres in [0, 50].
    #[arg(long = "sway-cm", default_value_t = 3.0, value_parser = real(0.0, 50.0))]
    sway_cm: f64,
    /// Sway frequency, Hz in [1e-6, 20].
    #[arg(long = "sway-hz", default_value_t = 0.5, value_parser = positive(20.0))]
    sway_hz: f64,
    /// Lean distance, centimetres in [0, 50].
    #[arg(long = "lean-cm", default_value_t = 10.0, value_parser = real(0.0, 50.0))]
    lean_cm: f64,
    /// Lean duration, seconds in [1e-6, 10].
    #[arg(long = "lean-s", default_value_t = 0.3, value_parser = positive(10.0))]
    lean_s: f64,
    /// When the lean starts, seconds in [0, 3600].
    #[arg(long = "lean-at", default_value_t = 0.5, value_parser = real(0.0, 3600.0))]
    lean_at: f64,
    /// Frontal capture to display latency, ms in [0, 10000]; a list (0,16,33,50,100,200)
    /// runs one sequence per value.
    #[arg(long = "latency-camera", value_name = "MS[,MS...]", default_value = "0", value_parser = latency_list)]
    latency_camera: Latencies,
    /// Back camera to head estimate latency, ms in [0, 10000].
    #[arg(long = "latency-tracking", default_value_t = 0.0, value_parser = real(0.0, MAX_LATENCY_MS))]
    latency_tracking: f64,
    /// Head prediction to display time.
    #[arg(long, value_enum, value_parser = choice::<Prediction>(), default_value_t = Prediction::None)]
    predict: Prediction,
    /// Re-project the frontal image by the vehicle's known motion from capture to display.
    #[arg(long)]
    reproject: bool,
    /// Split the misregistration into what each effect of time adds (latency, sample and
    /// hold, readout skew, exposure blur, scan-out) by running the sequence again with them
    /// added one by one: budget.csv, budget_over_time.png and summary.json's `budget` (up to 5
    /// more sequences).
    #[arg(long, conflicts_with_all = ["capture", "maps"])]
    budget: bool,
    /// Write every frame's truth and seethru views (whole driver views) as PNG or EXR.
    #[arg(long, value_enum, value_parser = choice::<FramesFormat>(), default_value_t = FramesFormat::None)]
    frames: FramesFormat,
    /// Compute FLIP for every frame (frames.csv's `flip` column; NaN without it): about a
    /// third of the per-frame metrics' time.
    #[arg(long)]
    flip: bool,
    /// What the EXRs of --frames exr and of --capture's folders hold, as `capture --exr`:
    /// all (every AOV), lean (R, G, B, Z, N and the ids), colour (R, G, B, A only) or none
    /// (--capture: PNGs and JSON only).
    #[arg(long, value_enum, value_parser = choice::<ExrContent>(), default_value_t = ExrContent::All)]
    exr: ExrContent,
    /// oracle: the true eye (late by the tracking latency); estimated: face detection on the
    /// back camera's image of its time.
    #[arg(long = "head-source", value_enum, value_parser = choice::<HeadSource>(), default_value_t = HeadSource::Oracle)]
    head_source: HeadSource,
    /// The options a sequence shares with a run, from the option table.
    #[command(flatten)]
    run_options: OptionArgs<option_args::Sequence>,
    /// Worker threads in [1, 1024] (default: all cores). Output is identical for any value.
    #[arg(long, value_parser = threads)]
    threads: Option<usize>,
    /// Top of preview.png's misregistration scale, arc-minutes in [1e-6, 10000], so that
    /// previews compare (default: the 99th percentile of every frame's values, labelled).
    #[arg(long = "heatmap-max", value_name = "ARCMIN", value_parser = positive(1e4))]
    heatmap_max: Option<f64>,
    /// Write every refresh's inputs (seethru capture's files, one frame_NNNNN/ folder each)
    /// and frames.json, the index of their times, to this folder.
    #[arg(long, value_name = "DIR", conflicts_with = "maps")]
    capture: Option<PathBuf>,
    /// Show an outside method's maps instead of the built-in compensation: DIR/frame_NNNNN.npy
    /// (or .exr), one per folder of --capture, scored as the sequence scores its own.
    #[arg(long, value_name = "DIR")]
    maps: Option<PathBuf>,
}

impl Sequence {
    fn head_motion(&self) -> Result<HeadMotion> {
        Ok(match (&self.head_path, self.head) {
            (Some(path), _) => HeadMotion::Path(HeadPath::load(path)?),
            (None, HeadPreset::Still) => HeadMotion::Still,
            (None, HeadPreset::Sway) => HeadMotion::Sway {
                amplitude: self.sway_cm / 100.0,
                frequency: self.sway_hz,
            },
            (None, HeadPreset::Lean) => HeadMotion::Lean {
                distance: self.lean_cm / 100.0,
                duration: self.lean_s,
                start: self.lean_at,
            },
        })
    }

    /// The options of the sequence at camera latency `latency_ms`, its run's as `spec` has
    /// them.
    fn options(&self, spec: &RunSpec, head: &HeadMotion, latency_ms: f64) -> SequenceOptions {
        SequenceOptions {
            run: RunOptions {
                head: self.head_source,
                // One eye, the scene's driver camera; the scene-model methods are refused.
                eyes: Default::default(),
                scene_model: Default::default(),
                ..spec.options.clone()
            },
            timeline: Timeline {
                duration: self.duration,
                fps: self.fps,
                display_hz: self.display_hz.unwrap_or(self.fps),
                latency_camera: latency_ms / 1e3,
                latency_tracking: self.latency_tracking / 1e3,
            },
            head: head.clone(),
            predict: self.predict,
            reproject: self.reproject,
            byo: seethru::system::sequence::byo::Byo {
                capture: self.capture.is_some(),
                maps: None,
            },
        }
    }

    pub fn run(self) -> Result<()> {
        let mut inputs = vec![Input::file("SCENE", &self.scene)];
        inputs.extend(
            self.head_path
                .as_deref()
                .map(|p| Input::file("--head-path", p)),
        );
        inputs.extend(
            self.capture
                .as_deref()
                .map(|p| Input::folder("--capture", p)),
        );
        inputs.extend(self.maps.as_deref().map(|p| Input::folder("--maps", p)));
        check_paths(&inputs, &[Output::folder("--out", &self.out)])?;
        let threads = self.threads;
        with_threads(threads, || self.run_all())?
    }

    /// Refuses the flags these settings would ignore ([`refuse_ignored`]).
    fn refuse_ignored(&self, spec: &RunSpec) -> Result<()> {
        let preset = self.head_path.is_none().then_some(self.head);
        let run = self.options(spec, &HeadMotion::Still, 0.0).run;
        let mut rules = sequence_reads(&run, preset, self.maps.is_some());
        rules.push(ReadWhen {
            option: "exr",
            read: self.capture.is_some() || self.frames == FramesFormat::Exr,
            when: "with --capture or --frames exr (nothing else is written as EXR)",
        });
        refuse_ignored(&rules)?;
        if self.frames == FramesFormat::Exr && self.exr == ExrContent::None {
            bail!(
                "--frames exr writes each frame as EXR and --exr none writes no EXR: give --frames png, or --exr colour or all"
            );
        }
        Ok(())
    }

    fn run_all(&self) -> Result<()> {
        let spec = self.run_options.spec()?;
        self.refuse_ignored(&spec)?;
        let head = self.head_motion()?;
        let scene = load_scene(&self.scene)?;
        refuse_ignored(&[hazard_bound_reads(&scene)])?;
        if let HeadMotion::Path(path) = &head {
            path.check_in_world(&scene.obstacle.world_from_obstacle)?;
        }
        // Every latency's timeline is checked before anything is rendered or written.
        let all: Vec<SequenceOptions> = self
            .latency_camera
            .0
            .iter()
            .map(|&ms| self.options(&spec, &head, ms))
            .collect();
        for o in &all {
            o.timeline.validate()?;
        }
        if self.budget && !all.iter().any(|o| has_effects_of_time(&scene, o)) {
            bail!(
                "--budget splits the misregistration among the effects of time, and this sequence has none: give --latency-camera or --latency-tracking, a --display-hz below --fps, or set the scene's shutter, readout_ms, exposure_ms or scanout keys"
            );
        }
        if (self.capture.is_some() || self.maps.is_some()) && all.len() > 1 {
            bail!(
                "--capture and --maps take one --latency-camera value, got {}",
                all.len()
            );
        }
        let mut all = all;
        if let Some(dir) = &self.maps {
            let t = all[0].timeline;
            all[0].byo.maps = Some(crate::cli::sequence_byo::load_maps(
                dir,
                &t,
                scene.obstacle.display_resolution,
            )?);
        }
        // Before anything is allocated: a size the machine cannot hold is refused with numbers.
        let first = &all[0];
        check_memory(
            &sequence_estimate(
                &scene,
                &first.run,
                first.timeline.frames() as u64,
                first.timeline.fps,
                all.len() as u64,
            )?,
            spec.max_memory_gib,
        )?;
        // Written whole or not at all: a failure at any latency leaves `--out` as it was.
        let staged = StagedDir::new(&self.out)?;
        let out = staged.path().to_path_buf();
        let captured = self.capture.as_deref().map(StagedDir::new).transpose()?;
        let command = json!({
            "command": "sequence",
            "args": std::env::args().skip(2).collect::<Vec<_>>(),
            "note": "the sequence that wrote this folder (seethru score reads a single capture's folder, not this one: score a sequence with sequence --maps)",
        });
        let (mut index, mut shown_folder) = (Vec::new(), String::new());
        let mut runs: Vec<(f64, SequenceRun, Option<serde_json::Value>)> = Vec::new();
        let count = all.len();
        let mut headlines: Vec<String> = Vec::new();
        for (k, (options, &ms)) in all.into_iter().zip(&self.latency_camera.0).enumerate() {
            let dir = out.join(latency_dir(ms));
            let timeline = options.timeline;
            let mut preview = Preview::new(timeline.fps)
                .labelled(format!("latency {ms} ms"))
                .heat_max(self.heatmap_max.map(|v| v as f32));
            let label = format!("latency {}/{count}: {ms} ms", k + 1);
            let frames = self.frames;
            let how = Measuring {
                metrics: true,
                full_frames: frames != FramesFormat::None,
                band: spec.measure.band,
                progress: true,
                flip: Flip::asked(self.flip),
            };
            let bound = spec.measure.hazard_bound_arcmin;
            let asked = options.clone();
            let run = run_sequence_hazards(&scene, options, how, bound, &label, &mut |f| {
                preview.add(&f);
                if let Some(c) = &captured {
                    index.push(crate::cli::sequence_byo::write_frame(
                        c.path(),
                        &f,
                        &command,
                        &mut shown_folder,
                        self.exr,
                    )?);
                }
                let name = |view: &str, ext: &str| {
                    dir.join("frames")
                        .join(format!("{view}_{:05}.{ext}", f.record.frame))
                };
                match frames {
                    FramesFormat::None => Ok(()),
                    FramesFormat::Png => {
                        write_color_png(f.truth, &name("truth", "png"))?;
                        write_color_png(f.seethru, &name("seethru", "png"))
                    }
                    FramesFormat::Exr => {
                        write_view_exr(f.truth, &name("truth", "exr"), self.exr)?;
                        write_view_exr(f.seethru, &name("seethru", "exr"), self.exr)
                    }
                }
            })?;
            if let Some(w) = head_warning(&run.records) {
                eprintln!("warning: {}", as_flags(&w));
            }
            write_text(
                &dir.join("frames.csv"),
                &frames_csv(&run.records, &timeline)?,
            )?;
            let (scale, chosen) = preview.write(&dir.join("preview.png"))?;
            over_time_figure(&[(format!("{ms} ms"), &run.records)], timeline.duration)
                .write(&dir, "misregistration_over_time")?;
            if run.records.first().is_some_and(|r| !r.hazards.is_empty()) {
                hazard_figure(&run.records, timeline.duration).write(&dir, "hazard_visibility")?;
            }
            let mut s = summary(&run, &timeline);
            let mut budget_json = None;
            let mut headline = format!("{ms} ms: {}", summary_text(RunKind::Sequence, &s));
            if self.budget {
                let how = Measuring {
                    full_frames: false,
                    flip: Flip::Skipped,
                    ..how
                };
                let budget = run_budget(&scene, &asked, how, &run, &label)?;
                write_text(&dir.join("budget.csv"), &budget.csv())?;
                budget
                    .figure(timeline.duration)
                    .write(&dir, "budget_over_time")?;
                s["budget"] = budget.json();
                budget_json = Some(s["budget"].clone());
                headline = format!("{headline}; {}", budget.headline());
            }
            headlines.push(headline);
            s["preview_heat_scale_arcmin"] = json!(scale);
            s["preview_heat_scale"] = json!(chosen);
            write_text(
                &dir.join("summary.json"),
                &serde_json::to_string_pretty(&with_flags(&s))?,
            )?;
            runs.push((ms, run, budget_json));
        }
        self.write_overview(&spec, &runs, &out)?;
        if let Some(c) = captured {
            crate::cli::sequence_byo::write_index(c.path(), std::mem::take(&mut index))?;
            c.commit()?;
        }
        seethru::measure::viewer::write_sequence_view(&out)?;
        staged.commit()?;
        say(format!(
            "{}; wrote {} sequence(s) of {} frames (frames.csv, summary.json, plots, preview.png, view.html) to {}",
            headlines.join("; "),
            runs.len(),
            runs.first().map_or(0, |r| r.1.records.len()),
            self.out.display()
        ));
        Ok(())
    }

    /// The top-level summary and plots: misregistration over time for every latency, and
    /// mean and p95 against latency when there are several.
    fn write_overview(
        &self,
        spec: &RunSpec,
        runs: &[(f64, SequenceRun, Option<serde_json::Value>)],
        out: &Path,
    ) -> Result<()> {
        let labelled: Vec<(String, &[_])> = runs
            .iter()
            .map(|(ms, r, _)| (format!("{ms} ms"), r.records.as_slice()))
            .collect();
        over_time_figure(&labelled, self.duration).write(out, "misregistration_over_time")?;
        let mut per_latency = Vec::new();
        let mut points = Vec::new();
        for (ms, run, budget) in runs {
            let timeline = self.options(spec, &HeadMotion::Still, *ms).timeline;
            let mut s = summary(run, &timeline);
            if let Some(budget) = budget {
                s["budget"] = budget.clone();
            }
            let [mean, p95] = mean_of_frame_stats(run);
            points.push((*ms, mean, p95));
            per_latency
                .push(json!({"latency_camera_ms": ms, "dir": latency_dir(*ms), "summary": s}));
        }
        if runs.len() > 1 {
            latency_figure(&points).write(out, "latency")?;
        }
        let overview = json!({
            "scene": self.scene.display().to_string(),
            "duration_s": self.duration,
            "fps": self.fps,
            "display_hz": self.display_hz.unwrap_or(self.fps),
            "speed_kmh": spec.options.speed_kmh,
            "yaw_rate_deg_s": spec.options.yaw_rate_deg_s,
            "head": self.head_motion()?.name(),
            "latency_tracking_ms": self.latency_tracking,
            "predict": self.predict,
            "reproject": self.reproject,
            "budget": self.budget,
            "method": spec.options.method,
            "maps": self.maps.as_ref().map(|m| m.display().to_string()),
            "d2": format!("{:?}", spec.options.d2),
            "head_source": self.head_source,
            "width": spec.options.width,
            "spp": spec.options.spp,
            "sequences": per_latency,
        });
        // Last: a directory with summary.json holds finished sequences.
        write_text(
            &out.join("summary.json"),
            &serde_json::to_string_pretty(&with_flags(&overview))?,
        )
        .with_context(|| format!("writing {}", self.out.display()))
    }
}

/// The folder of one latency's sequence: `latency_<ms>ms`.
fn latency_dir(ms: f64) -> String {
    format!("latency_{}ms", seethru::util::number::short(ms))
}
