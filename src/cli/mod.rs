//! The commands: each file holds one command's arguments and runs it through the library.

mod analyze;
mod args;
mod bench;
mod bench_methods;
mod bench_run;
mod bench_sequence;
mod capture;
mod check;
mod compare;
mod compare_methods;
mod dataset;
mod diff;
mod export;
mod figures;
pub mod given;
mod head_poses;
mod measure;
mod option_args;
mod ratio;
mod render;
mod reproduce;
mod run;
mod run_eyes;
mod score;
mod sequence;
mod sequence_byo;
mod spec;
mod sweep;
pub mod verdict;
mod view;

use anyhow::Result;
use clap::{CommandFactory, FromArgMatches, Parser, Subcommand};

#[derive(Parser)]
#[command(
    name = "seethru",
    version,
    about = "Simulates video see-through displays for driver assistance and measures how well they work"
)]
pub struct Cli {
    /// No progress bars and no summary lines (errors are still printed).
    #[arg(long, global = true)]
    pub quiet: bool,
    #[command(subcommand)]
    pub command: Command,
}

#[derive(Subcommand)]
pub enum Command {
    /// Render views of a scene: colour PNG, id PNG and an EXR with every AOV per view.
    Render(render::Render),
    /// Run the see-through system: truth, occluded, frontal, back, display and seethru views,
    /// each as PNG, ids PNG and EXR, and run.json with every parameter and the crop.
    Run(run::Run),
    /// Observed p_cam/p_user of the paper's occlusion or foreshortening setup: predicted,
    /// observed and the uncertainty pixel quantisation leaves.
    Ratio(ratio::Ratio),
    /// Reproduce the paper's §5: report.md, a self-contained report.html and report.json.
    Reproduce(reproduce::Reproduce),
    /// Metrics for every combination of parameter values, as CSV and a plot; resumable.
    /// Parameters: theta_f, d2, display_width, eye_x, eye_z, head_bias_x_cm, frontal_width, and
    /// eye=eyellipse (drivers' eyes drawn from the scene's [eyellipse]).
    Sweep(sweep::Sweep),
    /// Join the CSVs of a sweep run in parts (`sweep --shard K/N`) into one CSV and its plot.
    SweepMerge(sweep::SweepMerge),
    /// Recompute metrics.json and the misregistration maps of a `run` directory from its EXRs.
    Measure(measure::Measure),
    /// Export the scene for other renderers: glTF (.glb), OBJ or Mitsuba 3 (.xml), with its
    /// materials, cameras, display and ids, and the cameras as <name>.cameras.json.
    Export(export::Export),
    /// Regenerate the paper's Fig. 3–5 and the physical-unit sensitivity figure (PNG, SVG and CSV).
    Figures(figures::Figures),
    /// The paper's numerical claims beside seethru's values; every closed form at a parameter set.
    Analyze(analyze::Analyze),
    /// Compensation methods side by side on one scene: one table (Markdown, JSON, HTML) of
    /// misregistration, coverage, holes, image metrics and cost, and one image strip each.
    Compare(compare::Compare),
    /// Benchmark: BVH build time, rays per second, frame times; ends with one JSON line.
    Bench(bench::Bench),
    /// The head tracker against the true eye over a grid of head poses: its error table.
    HeadPoses(head_poses::HeadPoses),
    /// The system over time: vehicle and head motion, latencies and prediction, measured frame
    /// by frame against the truth (frames.csv, summary.json, plots, an animated preview).
    Sequence(Box<sequence::Sequence>),
    /// Differences of two images (PNG, EXR layers) or two run folders: FLIP, PSNR, SSIM,
    /// absolute errors, metrics.json; thresholds give exit 1 when exceeded, 2 on bad input.
    Diff(diff::Diff),
    /// Run the cases of an expectations file and check their metrics' bounds: a PASS/FAIL
    /// table, JUnit XML, diff images of failures; --bless rewrites goldens and recordings.
    Check(check::Check),
    /// What a see-through system's algorithm receives (frontal, back and depth images, the
    /// head estimate, calibration.json), with the truth apart in OUT/truth/: for your method.
    Capture(capture::CaptureArgs),
    /// Score your method's display map (or image) for a capture, measured exactly as `run`.
    Score(score::Score),
    /// The run specification `run`, `capture` or `compare` would make of these options (JSON),
    /// every option checked, nothing rendered: the option table's values and defaults.
    #[command(subcommand)]
    Spec(spec::Spec),
    /// Ground-truth / see-through pairs by the thousand: one run per sample of a spec's draws,
    /// resumable and sharded (--shard K/N), with a manifest (CSV) and a grid viewer.
    Dataset(dataset::Dataset),
    /// Write the viewer of an output folder (run, score, measure, sequence, compare): one
    /// self-contained view.html to flick, wipe and read pixels in a browser.
    View(view::View),
}

/// The scene at `path`, what reading it doubted (an OpenDRIVE map's skipped features)
/// printed as `warning:` lines on stderr.
pub fn load_scene(path: &std::path::Path) -> Result<seethru::scene::Scene> {
    let scene = seethru::scene::Scene::load(path)?;
    print_warnings(&scene);
    Ok(scene)
}

/// What reading `scene` doubted, one `warning:` line each on stderr.
pub fn print_warnings(scene: &seethru::scene::Scene) {
    for warning in &scene.warnings {
        eprintln!("warning: {warning}");
    }
}

/// The command line with every negative number that follows an option joined to it
/// (`--b1 -0.35` → `--b1=-0.35`, `--width -inf` → `--width=-inf`): clap takes `-0.35` or
/// `-inf` for an option of its own and says "unexpected argument '-i'", naming neither the
/// flag nor its range. No option's name starts with a digit, `inf` or `nan`, so nothing else
/// changes.
pub fn with_negative_values_joined(
    args: impl IntoIterator<Item = std::ffi::OsString>,
) -> Vec<std::ffi::OsString> {
    let negative_number = |text: &str| {
        let rest = text
            .strip_prefix('-')
            .unwrap_or_default()
            .to_ascii_lowercase();
        rest.starts_with(|c: char| c.is_ascii_digit() || c == '.')
            || ["inf", "infinity", "nan"].contains(&rest.as_str())
    };
    let mut out: Vec<std::ffi::OsString> = Vec::new();
    for arg in args {
        let joined = match (out.last().and_then(|a| a.to_str()), arg.to_str()) {
            (Some(option), Some(value))
                if option.starts_with("--") && !option.contains('=') && option.len() > 2 =>
            {
                negative_number(value).then(|| format!("{option}={value}"))
            }
            _ => None,
        };
        match joined {
            Some(j) => *out.last_mut().expect("an option precedes") = j.into(),
            None => out.push(arg),
        }
    }
    out
}

/// Parses the command line, recording which flags were given ([`given`]).
pub fn parse(args: Vec<std::ffi::OsString>) -> Result<Cli, clap::Error> {
    let command = Cli::command();
    let matches = match command.clone().try_get_matches_from(&args) {
        Ok(m) => m,
        Err(e) if e.kind() == clap::error::ErrorKind::UnknownArgument => {
            return Err(spaced_triple(&command, &args).map_or(e, |message| {
                clap::Error::raw(clap::error::ErrorKind::ValueValidation, message)
            }));
        }
        Err(e) => return Err(e),
    };
    given::record(&command, &matches);
    Cli::from_arg_matches(&matches).map_err(|e| e.format(&mut Cli::command()))
}

/// `--head-bias-cm 1 0 0`: a flag whose value is `X,Y,Z` given three words. clap takes the
/// first for the value and calls the second an unexpected argument, naming neither the flag
/// nor its form; this says both.
fn spaced_triple(command: &clap::Command, args: &[std::ffi::OsString]) -> Option<String> {
    let mut triples = Vec::new();
    let mut stack = vec![command];
    while let Some(c) = stack.pop() {
        for arg in c.get_arguments() {
            let xyz = arg
                .get_value_names()
                .is_some_and(|names| names.iter().any(|n| n.as_str() == "X,Y,Z"));
            if xyz && let Some(long) = arg.get_long() {
                triples.push(format!("--{long}"));
            }
        }
        stack.extend(c.get_subcommands());
    }
    let words: Vec<String> = args.iter().map(|a| a.to_string_lossy().into()).collect();
    words.windows(3).find_map(|w| {
        let (flag, first) = match w[0].split_once('=') {
            Some((flag, value)) => (flag, value),
            None => (w[0].as_str(), w[1].as_str()),
        };
        let next = if w[0].contains('=') { &w[1] } else { &w[2] };
        let looks_spaced = !first.contains(',') && !next.starts_with("--");
        (triples.iter().any(|t| t == flag) && looks_spaced).then(|| {
            format!(
                "{flag} takes x,y,z in one word, the three numbers separated by commas (e.g. `{flag} 1,0,0`), got `{first} {next} …`"
            )
        })
    })
}

/// The library's JSON (a report, metrics) as the command line writes it: every option its
/// words name ("option `fill`") spelled as the flag (`--fill`).
pub fn with_flags(value: &serde_json::Value) -> serde_json::Value {
    let mut value = value.clone();
    seethru::util::option_words::spell_json(&mut value, &seethru::util::option_words::flag_of);
    value
}

/// A clap error as one line starting `error:`: the message and its tip, without the usage
/// block and the pointer to `--help`, so that scripts and logs get one line per failure. A
/// value parser's message from the library names options as flags.
pub fn one_line(error: &clap::Error) -> String {
    let text = seethru::util::option_words::as_flags(&error.render().to_string());
    let parts: Vec<&str> = text
        .lines()
        .map(str::trim)
        .filter(|l| {
            !l.is_empty() && !l.starts_with("Usage:") && !l.starts_with("For more information")
        })
        .collect();
    let mut line = String::new();
    for part in parts {
        if !line.is_empty() {
            line.push_str(if line.ends_with(':') { " " } else { "; " });
        }
        line.push_str(part);
    }
    if line.starts_with("error:") {
        line
    } else {
        format!("error: {line}")
    }
}

impl Command {
    pub fn run(self) -> Result<()> {
        match self {
            Command::Render(c) => c.run(),
            Command::Run(c) => c.run(),
            Command::Capture(c) => c.run(),
            Command::Score(c) => c.run(),
            Command::Spec(c) => c.run(),
            Command::Ratio(c) => c.run(),
            Command::Reproduce(c) => c.run(),
            Command::Sweep(c) => c.run(),
            Command::SweepMerge(c) => c.run(),
            Command::Measure(c) => c.run(),
            Command::Export(c) => c.run(),
            Command::Figures(c) => c.run(),
            Command::Analyze(c) => c.run(),
            Command::Bench(c) => c.run(),
            Command::HeadPoses(c) => c.run(),
            Command::Compare(c) => c.run(),
            Command::Sequence(c) => c.run(),
            Command::Diff(c) => c.run(),
            Command::Check(c) => c.run(),
            Command::View(c) => c.run(),
            Command::Dataset(c) => c.run(),
        }
    }

    /// The exit status of an error: 2 for `diff` and `check`, whose 1 means "a threshold
    /// was exceeded" ([`verdict::ChecksFailed`]), 1 for every other command.
    pub fn error_status(&self) -> u8 {
        match self {
            Command::Diff(_) | Command::Check(_) => 2,
            _ => 1,
        }
    }
}
