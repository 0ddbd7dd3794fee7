//! Every command on every bundled scene, with every choice its `--help` lists, at tiny sizes.
//!
//! A case passes when it exits 0, or exits non-zero with exactly one `error:` line on stderr;
//! it fails on a panic, a hang, a signal, or a failure that does not say why. The choices are
//! read from the commands' own `--help` (each value of each option that lists "Possible
//! values", each sweep parameter the help names), so an option or command added to the CLI
//! joins the matrix by itself; a command the matrix does not know how to call fails the test
//! until it is given a base invocation here.

mod common;

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::sync::Mutex;
use std::time::{Duration, Instant};

use common::{repo_path, seethru};

/// Longest a case may run before it counts as a hang.
const HANG: Duration = Duration::from_secs(90);

/// One invocation: a label for the report, its words.
struct Case {
    label: String,
    args: Vec<String>,
    /// The matrix's own calls (each command's smallest call, the calls a later one reads):
    /// an error there would leave the cases after it testing nothing.
    must_succeed: bool,
}

/// What a case did, when it did not pass.
fn failure(args: &[String], must_succeed: bool) -> Option<String> {
    let mut child = Command::new(env!("CARGO_BIN_EXE_seethru"))
        .args(args)
        .env("RUST_BACKTRACE", "0")
        .stdin(Stdio::null())
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let stderr = child.stderr.take().unwrap();
    let reader = std::thread::spawn(move || std::io::read_to_string(stderr).unwrap_or_default());
    let start = Instant::now();
    let status = loop {
        if let Some(status) = child.try_wait().unwrap() {
            break Some(status);
        }
        if start.elapsed() > HANG {
            child.kill().ok();
            child.wait().ok();
            break None;
        }
        std::thread::sleep(Duration::from_millis(5));
    };
    let err = reader.join().unwrap();
    let Some(status) = status else {
        return Some(format!("HANG (over {HANG:?})"));
    };
    if err.contains("panicked at") {
        let line = err.lines().find(|l| l.contains("panicked at")).unwrap();
        let why = err
            .lines()
            .skip_while(|l| !l.contains("panicked at"))
            .nth(1);
        return Some(format!("PANIC {line} {}", why.unwrap_or("")));
    }
    if status.success() {
        return None;
    }
    if must_succeed {
        return Some(format!(
            "exit {status}, where this call must succeed: {err}"
        ));
    }
    let errors = err.lines().filter(|l| l.starts_with("error:")).count();
    match status.code() {
        None => Some(format!("killed by a signal ({status}); stderr: {err}")),
        Some(_) if errors == 1 => None,
        Some(code) => Some(format!(
            "exit {code} with {errors} `error:` lines (one expected): {err}"
        )),
    }
}

/// Each option of `seethru WORDS --help` that lists possible values, with its values.
fn choices(words: &[&str]) -> BTreeMap<String, Vec<String>> {
    let mut args = words.to_vec();
    args.push("--help");
    let (ok, help, err) = seethru(&args);
    assert!(ok, "{args:?}: {err}");
    let mut options = BTreeMap::new();
    let mut flag: Option<String> = None;
    let mut in_values = false;
    for line in help.lines() {
        let trimmed = line.trim_start();
        if trimmed.starts_with("--") || trimmed.starts_with("-h,") {
            flag = trimmed
                .split([' ', '='])
                .next()
                .filter(|f| f.starts_with("--"))
                .map(str::to_string);
            in_values = false;
        } else if trimmed.starts_with("Possible values:") {
            in_values = true;
        } else if in_values && let Some(value) = trimmed.strip_prefix("- ") {
            let value = value.split([':', ' ']).next().unwrap().to_string();
            if let Some(flag) = &flag {
                options
                    .entry(flag.clone())
                    .or_insert_with(Vec::new)
                    .push(value);
            }
        } else if in_values && !trimmed.is_empty() && !trimmed.starts_with("- ") {
            in_values = false;
        }
    }
    options
}

/// The commands `seethru --help` lists (without `help`).
fn commands() -> Vec<String> {
    let (ok, help, err) = seethru(&["--help"]);
    assert!(ok, "{err}");
    help.lines()
        .skip_while(|l| !l.starts_with("Commands:"))
        .skip(1)
        .take_while(|l| l.starts_with("  "))
        .map(|l| l.split_whitespace().next().unwrap().to_string())
        .filter(|c| c != "help")
        .collect()
}

/// The sweep parameters `seethru --help` names in sweep's line, each with a value inside its
/// range (a parameter the table lacks fails the test: give it one).
fn sweep_params() -> Vec<String> {
    let (_, help, _) = seethru(&["--help"]);
    let line = help
        .lines()
        .find(|l| l.trim_start().starts_with("sweep "))
        .unwrap();
    let listed = line.split("Parameters:").nth(1).unwrap();
    let value = |name: &str| match name {
        "theta_f" => "40",
        "d2" => "inf",
        "display_width" => "0.2",
        "eye_x" => "1.4",
        "eye_z" => "0.02",
        "head_bias_x_cm" => "1",
        "frontal_width" => "320",
        other => panic!("sweep parameter `{other}` has no value in the matrix: add one"),
    };
    listed
        .split(',')
        .filter_map(|p| {
            let name = p
                .trim()
                .trim_start_matches("and ")
                .split_whitespace()
                .next()?;
            Some(if name.contains('=') {
                name.to_string()
            } else {
                format!("{name}={}", value(name))
            })
        })
        .collect()
}

fn words(items: &[&str]) -> Vec<String> {
    items.iter().map(|s| s.to_string()).collect()
}

/// The cases of one scene; `dir` is its scratch folder.
fn scene_cases(scene: &Path, dir: &Path, run_choices: &Choices) -> Vec<Vec<Case>> {
    let s = scene.to_str().unwrap().to_string();
    let name = scene.file_stem().unwrap().to_str().unwrap().to_string();
    let out = |leaf: &str| dir.join(leaf).to_str().unwrap().to_string();
    let case = |label: String, args: Vec<String>| Case {
        label: format!("{name} {label}"),
        args,
        must_succeed: false,
    };
    let sure = |label: String, args: Vec<String>| Case {
        must_succeed: true,
        ..case(label, args)
    };
    let tiny = words(&["--width", "32", "--spp", "1", "--quiet"]);
    // Independent cases are groups of one; a group runs in order (a score after its capture).
    let mut groups: Vec<Vec<Case>> = Vec::new();
    // The command's smallest call, writing into `leaf`.
    let base = |command: &str, leaf: &str| {
        let mut a = words(&[command, &s, "--width", "32", "--quiet", "--out", &out(leaf)]);
        match command {
            "sequence" => a.extend(words(&["--duration", "0.1", "--fps", "10"])),
            _ => a.extend(words(&["--spp", "1"])),
        }
        a
    };
    for (command, options) in run_choices {
        groups.push(vec![sure(command.clone(), base(command, command))]);
        for (flag, values) in options {
            for value in values {
                // Each choice in a folder of its own: a case never reads another's output.
                let leaf = format!("{command}{flag}={value}");
                let mut a = base(command, &leaf);
                a.extend(words(&[flag, value]));
                groups.push(vec![case(format!("{command} {flag} {value}"), a.clone())]);
                // Options read only with a scene-modelling method or an estimated head are
                // tried there too (where the option is not itself one of those).
                let head = if command == "sequence" {
                    "--head-source"
                } else {
                    "--head"
                };
                if command == "render" || flag == "--method" || flag == head {
                    continue;
                }
                let mut b = base(command, &format!("{leaf}-modelled"));
                b.extend(words(&[
                    flag,
                    value,
                    "--method",
                    "depth",
                    head,
                    "estimated",
                ]));
                groups.push(vec![case(
                    format!("{command} {flag} {value} --method depth {head} estimated"),
                    b,
                )]);
            }
        }
    }
    for extra in [
        &["--d2", "auto"][..],
        &["--d2", "inf"],
        &["--d2", "0.5"],
        &["--head-bias-cm", "2,0,0"],
        &["--eyes", "both", "--method", "depth", "--head", "estimated"],
        &[
            "--outside",
            "black",
            "--head",
            "estimated",
            "--method",
            "ground",
        ],
    ] {
        let mut a = words(&["run", &s]);
        a.extend(tiny.iter().cloned());
        a.extend(words(&["--out", &out(&format!("run{}", extra.join("")))]));
        a.extend(words(extra));
        groups.push(vec![case(format!("run {}", extra.join(" ")), a)]);
    }
    // A scene that places the vehicle in a lane of a map drives it along the lane, and
    // refuses a yaw rate (tests/road.rs): it moves without one.
    let follows_lane = seethru::scene::Scene::load(scene).is_ok_and(|s| s.ego_route.is_some());
    let turn: &[&str] = if follows_lane {
        &[]
    } else {
        &["--yaw-rate", "10"]
    };
    let mut moving = words(&[
        "sequence",
        &s,
        "--width",
        "32",
        "--duration",
        "0.2",
        "--fps",
        "10",
        "--speed",
        "50",
    ]);
    moving.extend(words(turn));
    moving.extend(words(&[
        "--head",
        "sway",
        "--latency-camera",
        "0,50",
        "--quiet",
        "--out",
        &out("seq_moving"),
    ]));
    groups.push(vec![
        sure("sequence moving".into(), moving),
        sure(
            "view sequence".into(),
            words(&["view", &out("seq_moving"), "--quiet"]),
        ),
    ]);
    for param in sweep_params() {
        let mut a = words(&["sweep", &s, "--param", &param]);
        if param == "eye=eyellipse" {
            a.extend(words(&["--samples", "2"]));
        }
        a.extend(words(&["--width", "16", "--spp", "1", "--quiet", "--out"]));
        a.push(out(&format!("sweep_{}.csv", param.replace('=', "_"))));
        groups.push(vec![case(format!("sweep {param}"), a)]);
    }
    // Sharded sweep, then its merge.
    let shard = |k: &str| {
        words(&[
            "sweep",
            &s,
            "--param",
            "eye_x=0,0.05",
            "--width",
            "16",
            "--spp",
            "1",
            "--quiet",
            "--shard",
            k,
            "--out",
        ])
        .into_iter()
        .chain([out(&format!("part{}.csv", &k[..1]))])
        .collect::<Vec<_>>()
    };
    groups.push(vec![
        sure("sweep --shard 0/2".into(), shard("0/2")),
        sure("sweep --shard 1/2".into(), shard("1/2")),
        sure(
            "sweep-merge".into(),
            words(&[
                "sweep-merge",
                &out("part0.csv"),
                &out("part1.csv"),
                "--quiet",
                "--out",
            ])
            .into_iter()
            .chain([out("merged.csv")])
            .collect(),
        ),
    ]);
    // A run, then everything that reads a run folder or its images.
    let mut run_a = words(&["run", &s]);
    run_a.extend(tiny.iter().cloned());
    run_a.extend(words(&["--exr", "all", "--out", &out("ra")]));
    let mut run_b = run_a.clone();
    *run_b.last_mut().unwrap() = out("rb");
    run_b.extend(words(&["--method", "none"]));
    groups.push(vec![
        sure("run --exr all".into(), run_a),
        sure("run --method none".into(), run_b),
        sure("measure".into(), words(&["measure", &out("ra"), "--quiet"])),
        sure("view run".into(), words(&["view", &out("ra"), "--quiet"])),
        // A run folder against itself: `diff` exits 1 where a metric moved (a verdict).
        sure(
            "diff runs".into(),
            words(&["diff", &out("ra"), &out("ra"), "--quiet"]),
        ),
        sure(
            "diff images".into(),
            words(&[
                "diff",
                &format!("{}/truth.png", out("ra")),
                &format!("{}/seethru.png", out("rb")),
                "--quiet",
            ]),
        ),
        sure(
            "diff exr layer".into(),
            words(&[
                "diff",
                &format!("{}/truth.exr", out("ra")),
                &format!("{}/seethru.exr", out("rb")),
                "--layer",
                "Z",
                "--quiet",
            ]),
        ),
        sure(
            "capture".into(),
            words(&[
                "capture",
                &s,
                "--width",
                "32",
                "--quiet",
                "--out",
                &out("cap"),
            ]),
        ),
        sure(
            "score --display-image".into(),
            words(&[
                "score",
                &out("cap"),
                "--display-image",
                &format!("{}/display.png", out("ra")),
                "--quiet",
                "--out",
                &out("scored"),
            ]),
        ),
        sure(
            "capture --depth".into(),
            words(&[
                "capture",
                &s,
                "--depth",
                "--width",
                "32",
                "--quiet",
                "--out",
                &out("capd"),
            ]),
        ),
    ]);
    // A dataset of the scene: two samples whose frontal camera's angle is drawn, resumed
    // once (nothing left to make), then its grid viewer rewritten.
    let spec = dir.join("dataset.toml");
    std::fs::create_dir_all(dir).unwrap();
    std::fs::write(
        &spec,
        format!("scene = {s:?}\nsamples = 2\n[options]\nwidth = 24\nspp = 1\n[draw]\ntheta_f = {{ uniform = [40, 60] }}\n"),
    )
    .unwrap();
    let dataset = words(&[
        "dataset",
        spec.to_str().unwrap(),
        "--quiet",
        "--out",
        &out("dataset"),
    ]);
    groups.push(vec![
        sure("dataset".into(), dataset.clone()),
        sure("dataset resumed".into(), dataset),
        sure(
            "view dataset".into(),
            words(&["view", &out("dataset"), "--quiet"]),
        ),
    ]);
    groups.push(vec![
        sure(
            "compare".into(),
            words(&[
                "compare",
                &s,
                "--width",
                "32",
                "--spp",
                "1",
                "--quiet",
                "--out",
                &out("cmp"),
            ]),
        ),
        sure(
            "view compare".into(),
            words(&["view", &out("cmp"), "--quiet"]),
        ),
    ]);
    groups.push(vec![case(
        "head-poses".into(),
        words(&[
            "head-poses",
            &s,
            "--yaw",
            "0,20",
            "--pitch",
            "0",
            "--back-width",
            "96",
            "--quiet",
        ]),
    )]);
    for ext in ["glb", "obj", "xml"] {
        groups.push(vec![sure(
            format!("export {ext}"),
            words(&[
                "export",
                &s,
                "--quiet",
                "--out",
                &format!("{}/scene.{ext}", out("x")),
            ]),
        )]);
    }
    // The tracer's part on every scene; the other parts time fixed-size work (the methods,
    // a sequence, full-size runs) that the cases above cover at tiny sizes, so they run on
    // das alone: they took 15–30 s a scene, half the matrix's time.
    let mut bench = words(&[
        "bench", &s, "--width", "32", "--height", "18", "--repeat", "1", "--quiet",
    ]);
    if name != "das" {
        bench.extend(words(&["--parts", "trace"]));
    }
    groups.push(vec![sure("bench".into(), bench)]);
    groups
}

/// The commands whose choices are multiplied per scene, with their options' values.
type Choices = Vec<(String, BTreeMap<String, Vec<String>>)>;

#[test]
fn every_command_on_every_bundled_scene_exits_cleanly_or_with_one_error_line() {
    let dir = tempfile::tempdir().unwrap();
    // The commands each case below calls; a command the CLI gains fails here until the matrix
    // knows how to call it.
    let known = [
        "render",
        "run",
        "ratio",
        "reproduce",
        "sweep",
        "sweep-merge",
        "measure",
        "export",
        "figures",
        "analyze",
        "compare",
        "bench",
        "head-poses",
        "sequence",
        "diff",
        "check",
        "capture",
        "score",
        "spec",
        "view",
        "dataset",
    ];
    for command in commands() {
        assert!(
            known.contains(&command.as_str()),
            "`seethru {command}` is not in the matrix: give it cases here"
        );
    }
    // Options dropped from the per-choice multiplication: those that only name files or
    // threads, which the other tests walk.
    let per_choice = |command: &str| {
        let mut options = choices(&[command]);
        options.retain(|flag, _| flag != "--help");
        (command.to_string(), options)
    };
    let run_choices: Choices = vec![
        per_choice("render"),
        per_choice("run"),
        per_choice("sequence"),
    ];
    let mut scenes: Vec<PathBuf> = std::fs::read_dir(repo_path("scenes"))
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|e| e == "toml"))
        .collect();
    scenes.sort();
    assert!(scenes.len() >= 5, "{scenes:?}");
    let mut groups: Vec<Vec<Case>> = Vec::new();
    for scene in &scenes {
        let scratch = dir.path().join(scene.file_stem().unwrap());
        std::fs::create_dir_all(&scratch).unwrap();
        groups.extend(scene_cases(scene, &scratch, &run_choices));
    }
    let out = |leaf: &str| dir.path().join(leaf).to_str().unwrap().to_string();
    let once = |label: &str, args: Vec<String>| {
        vec![Case {
            label: label.into(),
            args,
            must_succeed: true,
        }]
    };
    groups.push(once("analyze", words(&["analyze", "--quiet"])));
    for command in ["run", "capture", "compare", "sequence", "render"] {
        groups.push(once(
            &format!("spec {command}"),
            words(&["spec", command, "--quiet"]),
        ));
    }
    groups.push(once(
        "figures",
        words(&["figures", "--quiet", "--out", &out("fig")]),
    ));
    groups.push(once(
        "reproduce --quick",
        words(&["reproduce", "--quick", "--quiet", "--out", &out("rep")]),
    ));
    groups.push(once(
        "ratio occlusion",
        words(&[
            "ratio",
            "occlusion",
            "--L",
            "5",
            "--b1",
            "-0.35",
            "--d2",
            "6.3",
            "--d1",
            "2.5",
            "--bh",
            "1.75",
            "--quiet",
        ]),
    ));
    groups.push(once(
        "ratio foreshortening",
        words(&[
            "ratio",
            "foreshortening",
            "--l",
            "5",
            "--b1",
            "-1.5",
            "--d2",
            "1.3",
            "--d1",
            "2",
            "--bh",
            "0.7",
            "--gamma",
            "90",
            "--quiet",
        ]),
    ));
    groups.push(once(
        "check",
        words(&[
            "check",
            repo_path("examples/ci/expectations.toml").to_str().unwrap(),
            "--quiet",
            "--out",
            &out("chk"),
            "--junit",
            &out("chk.xml"),
        ]),
    ));
    let total: usize = groups.iter().map(Vec::len).sum();
    let queue = Mutex::new(groups.into_iter());
    let failures = Mutex::new(Vec::new());
    // Each case's wall time, so the slowest (what sets CI's length) are printed at the end.
    let timings = Mutex::new(Vec::new());
    let workers = std::thread::available_parallelism().map_or(2, |n| n.get());
    std::thread::scope(|scope| {
        for _ in 0..workers {
            scope.spawn(|| {
                loop {
                    let Some(group) = queue.lock().unwrap().next() else {
                        return;
                    };
                    for case in group {
                        let start = Instant::now();
                        let failed = failure(&case.args, case.must_succeed);
                        timings
                            .lock()
                            .unwrap()
                            .push((start.elapsed(), case.label.clone()));
                        if let Some(why) = failed {
                            failures.lock().unwrap().push(format!(
                                "{}: seethru {}\n    {why}",
                                case.label,
                                case.args.join(" ")
                            ));
                        }
                    }
                }
            });
        }
    });
    let failures = failures.into_inner().unwrap();
    let mut timings = timings.into_inner().unwrap();
    timings.sort_by_key(|t| std::cmp::Reverse(t.0));
    let all: Duration = timings.iter().map(|t| t.0).sum();
    eprintln!("every command: {all:.1?} of case time in all; the slowest cases:");
    for (took, label) in timings.iter().take(25) {
        eprintln!("  {took:>10.2?}  {label}");
    }
    assert!(
        failures.is_empty(),
        "{} of {total} cases failed:\n{}",
        failures.len(),
        failures.join("\n")
    );
    eprintln!("every command: {total} cases, all passed");
}
