//! The misregistration budget of a sequence (measure/sequence_budget.rs) against the ages the
//! geometry gives: on a wall at the model's distance, turning at ω, each effect of time makes
//! what a display pixel shows older by a known amount, and adds ω times it.

mod common;

use seethru::analysis::physical::ARCMIN_PER_RAD;
use seethru::measure::image_metrics::Flip;
use seethru::measure::sequence::run_sequence;
use seethru::measure::sequence_budget::{Effect, run_budget};
use seethru::system::options::{RunOptions, WorkingDistance};
use seethru::system::sequence::system_loop::SequenceOptions;

const OMEGA_DEG_S: f64 = 20.0;
const LATENCY_S: f64 = 0.05;
const READOUT_S: f64 = 0.06;
const EXPOSURE_S: f64 = 0.012;
const DISPLAY_HZ: f64 = 30.0;
const WALL_M: f64 = 3000.0;

/// A wall 3 km ahead, the model's plane at infinity, so that a turn about the eye leaves the
/// model right at every instant (a wall near by would tilt away from the model's plane as the
/// vehicle turns), with the frontal camera's keys `frontal` and the display's `obstacle`,
/// turning at 20°/s, the image 50 ms old, a 30 Hz display looked at 8 times per refresh for
/// 4 refreshes.
fn wall(frontal: &str, obstacle: &str) -> (seethru::scene::Scene, SequenceOptions) {
    let far = common::WallScene {
        wall: WALL_M,
        ..Default::default()
    };
    let text = far
        .text()
        .replace("size = [80.0, 60.0]", "size = [80000.0, 60000.0]")
        .replace("[camera.frontal]", &format!("[camera.frontal]\n{frontal}"))
        .replace("[obstacle]", &format!("[obstacle]\n{obstacle}"));
    let scene = common::parse_in(&common::repo_path("scenes"), "wall.toml", &text).unwrap();
    let run = RunOptions {
        d2: WorkingDistance::Infinity,
        spp: 1,
        yaw_rate_deg_s: OMEGA_DEG_S,
        ..RunOptions::default()
    };
    let mut o = common::still_sequence(run, 4.0 / DISPLAY_HZ, 8.0 * DISPLAY_HZ, LATENCY_S);
    o.timeline.display_hz = DISPLAY_HZ;
    (scene, o)
}

/// Each step adds ω times the age its effect gives the display's pixels: the latency; the
/// mean time since the refresh over the frames (the hold); the mean age of the frontal rows
/// the display shows (the readout, rows found by casting the eye's rays onto the wall); half
/// the exposure (its middle, where the pixel-centre sample is); and, for a rolling scan-out,
/// the period times the share of rows still showing the refresh before (in the first refresh
/// too: the display ran before the sequence). The baseline has no age: it is the still
/// vehicle's error.
#[test]
fn each_step_of_the_budget_adds_the_turn_over_its_effects_age() {
    let frontal = format!(
        "shutter = \"rolling\"\nreadout_ms = {}\nexposure_ms = {}",
        READOUT_S * 1e3,
        EXPOSURE_S * 1e3
    );
    let (scene, options) = wall(&frontal, "scanout = \"rolling\"");
    let how = common::measuring(Flip::Skipped);
    let whole = run_sequence(&scene, options.clone(), how, &mut |_| Ok(())).unwrap();
    let budget = run_budget(&scene, &options, how, &whole, "test").unwrap();

    let per_s = OMEGA_DEG_S.to_radians() * ARCMIN_PER_RAD;
    let period = 1.0 / DISPLAY_HZ;
    let frames = &whole.records;
    let mean = |f: &dyn Fn(&seethru::measure::sequence_records::FrameRecord) -> f64| {
        frames.iter().map(f).sum::<f64>() / frames.len() as f64
    };
    let hold = mean(&|r| r.times.display - r.times.refresh_time);
    let waiting = mean(&|r| {
        let since = r.times.display - r.times.refresh_time;
        let reached = ((since / period * 100.0 + 1e-9).floor() + 1.0).min(100.0);
        period * (1.0 - reached / 100.0)
    });
    let ages = [
        LATENCY_S,
        hold,
        common::readout_age(&scene, READOUT_S, WALL_M),
        EXPOSURE_S / 2.0,
        waiting,
    ];
    // Without the effects of time the turn changes nothing: the baseline is the vehicle's
    // standing still, the resampling's error (a display pixel is 9.8′).
    let mut still = options.clone();
    still.run.yaw_rate_deg_s = 0.0;
    let still = run_sequence(&scene, still, how, &mut |_| Ok(())).unwrap();
    let still_mean = seethru::measure::sequence_files::mean_of_frame_stats(&still)[0];
    let baseline = budget.steps[0].mean_arcmin;
    assert!(
        (baseline / still_mean - 1.0).abs() < 0.02,
        "baseline {baseline:.2}′, still {still_mean:.2}′"
    );
    // Past the resampling's error, each step is ω times the ages so far, and so each change
    // is ω times its effect's age.
    let changes = budget.changes();
    assert_eq!(budget.steps.len(), 6);
    let mut so_far = 0.0;
    for (k, (effect, age)) in Effect::ALL.iter().zip(ages).enumerate() {
        let step = &budget.steps[k + 1];
        assert_eq!(step.added, Some(*effect));
        assert!(step.present, "{effect:?}");
        so_far += age;
        let predicted = per_s * so_far;
        assert!(
            (step.mean_arcmin / predicted - 1.0).abs() < 0.02,
            "{effect:?}: {:.2}′, ω × the ages so far {predicted:.2}′",
            step.mean_arcmin
        );
        if k > 0 {
            assert!(
                (changes[k + 1] / (per_s * age) - 1.0).abs() < 0.03,
                "{effect:?}: {:+.2}′, ω × its age {:.2}′",
                changes[k + 1],
                per_s * age
            );
        }
    }
    // The last step is the sequence as asked, whose mean the changes sum to.
    let sum: f64 = changes.iter().sum();
    let whole_mean = seethru::measure::sequence_files::mean_of_frame_stats(&whole)[0];
    assert!((sum - whole_mean).abs() < 1e-9 * whole_mean);
}

/// An effect the sequence does not have is a step equal to the one before, marked absent;
/// the steps run again give their own numbers (a rolling shutter alone: no hold, exposure or
/// scan-out).
#[test]
fn an_effect_the_sequence_lacks_adds_nothing() {
    let (scene, mut options) = wall("shutter = \"rolling\"\nreadout_ms = 60.0", "");
    options.timeline.display_hz = options.timeline.fps;
    let how = common::measuring(Flip::Skipped);
    let whole = run_sequence(&scene, options.clone(), how, &mut |_| Ok(())).unwrap();
    let budget = run_budget(&scene, &options, how, &whole, "test").unwrap();
    let present: Vec<bool> = budget.steps.iter().map(|s| s.present).collect();
    assert_eq!(present, [true, true, false, true, false, false]);
    let means: Vec<f64> = budget.steps.iter().map(|s| s.mean_arcmin).collect();
    assert_eq!(means[2], means[1]);
    assert_eq!(means[5], means[3]);
    assert!(means[1] > means[0] && means[3] > means[1], "{means:?}");
}

/// `seethru sequence --budget`: per latency, budget.csv's steps end at the sequence's own mean
/// (summary.json's), and a latency of 0 with nothing else of time is one step, the rest
/// absent; a sequence without any effect of time, or one that writes or reads outside maps,
/// is refused.
#[test]
fn the_command_writes_each_latencys_budget_and_refuses_what_it_cannot_split() {
    let dir = tempfile::tempdir().unwrap();
    let scene = common::WallScene::default().file_in(dir.path());
    let scene = scene.to_str().unwrap();
    let out = dir.path().join("out");
    let args = |out: &str, extra: &[&str]| -> Vec<String> {
        let mut a = vec![
            "sequence",
            scene,
            "--out",
            out,
            "--duration",
            "0.1",
            "--fps",
            "30",
            "--yaw-rate",
            "20",
            "--d2",
            "6",
            "--spp",
            "1",
        ];
        a.extend_from_slice(extra);
        a.into_iter().map(String::from).collect()
    };
    let at = out.to_str().unwrap();
    let (ok, _, err) = common::seethru(&args(at, &["--latency-camera", "50,0", "--budget"]));
    assert!(ok, "{err}");
    for (folder, present) in [
        ("latency_50ms", [true, true, false, false, false, false]),
        ("latency_0ms", [true, false, false, false, false, false]),
    ] {
        let csv = std::fs::read_to_string(out.join(folder).join("budget.csv")).unwrap();
        let rows: Vec<Vec<&str>> = csv
            .lines()
            .skip(1)
            .map(|l| l.split(',').collect())
            .collect();
        let flags: Vec<bool> = rows.iter().map(|r| r[2] == "true").collect();
        assert_eq!(flags, present, "{folder}: {csv}");
        let summary: serde_json::Value = serde_json::from_str(
            &std::fs::read_to_string(out.join(folder).join("summary.json")).unwrap(),
        )
        .unwrap();
        let mean = summary["misregistration_arcmin"]["mean_of_frame_means"]
            .as_f64()
            .unwrap();
        let last: f64 = rows[5][3].parse().unwrap();
        assert!((last - mean).abs() < 1e-5, "{folder}: {last} vs {mean}");
        let steps = summary["budget"]["steps"].as_array().unwrap();
        assert_eq!(steps.len(), 6, "{folder}");
        assert!(out.join(folder).join("budget_over_time.png").is_file());
    }
    // 50 ms of latency at 20°/s adds about ω × 50 ms (60′) past the resampling's error.
    let csv = std::fs::read_to_string(out.join("latency_50ms/budget.csv")).unwrap();
    let latency: f64 = csv
        .lines()
        .nth(2)
        .unwrap()
        .split(',')
        .nth(4)
        .unwrap()
        .parse()
        .unwrap();
    assert!(latency > 45.0 && latency < 62.0, "{csv}");

    // Refused before anything is written.
    let refused = |extra: &[&str], code: i32, words: &[&str]| {
        let empty = tempfile::tempdir().unwrap();
        let given = args("refused", extra);
        let given: Vec<&str> = given.iter().map(String::as_str).collect();
        common::refusal::refused(empty.path(), &given, code, words);
        assert_eq!(common::refusal::listing(empty.path()), Vec::<String>::new());
    };
    refused(
        &["--budget"],
        1,
        &["--budget", "has none", "--latency-camera"],
    );
    refused(
        &["--budget", "--capture", "cap"],
        2,
        &["--budget", "--capture"],
    );
}
