//! The command line as a user meets it: exit codes, one-line errors, no partial outputs.

mod common;

use std::process::Command;

use common::{seethru, seethru_in};

#[test]
fn render_writes_png_ids_and_exr_per_view() {
    let dir = tempfile::tempdir().unwrap();
    let scene = dir.path().join("scene.toml");
    std::fs::write(&scene, common::MINIMAL).unwrap();
    let out = dir.path().join("out");
    let (ok, _, err) = seethru(&[
        "render",
        scene.to_str().unwrap(),
        "--view",
        "truth",
        "--view",
        "back",
        "--out",
        out.to_str().unwrap(),
        "--width",
        "40",
        "--threads",
        "1",
    ]);
    assert!(ok, "{err}");
    let mut files: Vec<String> = std::fs::read_dir(&out)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into())
        .collect();
    files.sort();
    assert_eq!(
        files,
        [
            "back.exr",
            "back.png",
            "back_ids.png",
            "truth.exr",
            "truth.png",
            "truth_ids.png"
        ]
    );
    // --width alone keeps the aspect ratio (64×36 → 40×23).
    let png = image::open(out.join("truth.png")).unwrap();
    assert_eq!((png.width(), png.height()), (40, 23));
}

#[test]
fn bad_input_gives_one_line_and_no_output() {
    let dir = tempfile::tempdir().unwrap();
    let scene = dir.path().join("bad.toml");
    let text = common::MINIMAL.replace("radius = 1.0", "radius = 0");
    let line = text.lines().position(|l| l == "radius = 0").unwrap() + 1;
    std::fs::write(&scene, text).unwrap();
    let out = dir.path().join("out");
    let scene_arg = scene.to_str().unwrap();
    let out_arg = out.to_str().unwrap();
    let cases: Vec<(Vec<&str>, String)> = vec![
        (
            vec!["render", scene_arg, "--out", out_arg],
            format!(
                "error: {scene_arg}:{line}:10: key `object[1].radius`: must be in [1e-6, 100000], got 0"
            ),
        ),
        (
            vec!["render", "nowhere.toml", "--out", out_arg],
            "error: nowhere.toml: cannot read the file: no such file".into(),
        ),
        (
            vec![
                "render",
                "scenes/das.toml",
                "--out",
                out_arg,
                "--width",
                "0",
            ],
            "error: invalid value '0' for '--width <PIXELS>': must be an integer in [1, 16384]"
                .into(),
        ),
        (
            vec!["render", "scenes/das.toml", "--out", out_arg, "--spp", "0"],
            "error: invalid value '0' for '--spp <SPP>': must be an integer in [1, 4096]".into(),
        ),
        (
            vec![
                "render",
                "scenes/das.toml",
                "--out",
                out_arg,
                "--threads",
                "0",
            ],
            "error: invalid value '0' for '--threads <THREADS>': must be an integer in [1, 1024]"
                .into(),
        ),
        (
            vec!["bench", "scenes/das.toml", "--width", "99999"],
            "error: invalid value '99999' for '--width <WIDTH>': must be an integer in [1, 16384]"
                .into(),
        ),
        (
            vec!["export", "scenes/das.toml", "--out", "x.stl"],
            "error: export writes .obj or .glb".into(),
        ),
    ];
    for (args, expected) in cases {
        let (ok, _, err) = seethru(&args);
        assert!(!ok, "{args:?} must fail");
        assert!(
            err.starts_with(&expected),
            "{args:?}: `{err}` should start with `{expected}`"
        );
        assert_eq!(
            err.trim_end().lines().count(),
            1,
            "{args:?}: one line: {err}"
        );
        assert!(!err.contains("panicked"), "{err}");
        assert!(!out.exists(), "{args:?} left output behind");
    }
}

#[test]
fn analyze_reports_the_papers_claims_and_any_parameter_set() {
    let (ok, out, err) = seethru(&[
        "analyze",
        "--json",
        "--d1",
        "0.8",
        "--d2",
        "10",
        "--bh",
        "-0.05",
        "--theta-f",
        "30",
    ]);
    assert!(ok, "{err}");
    let v: serde_json::Value = serde_json::from_str(&out).unwrap();
    let claims = v["claims"].as_array().unwrap();
    let find = |prefix: &str| {
        claims
            .iter()
            .find(|c| c["claim"].as_str().unwrap().contains(prefix))
            .unwrap()["seethru"]
            .as_f64()
            .unwrap()
    };
    assert!((find("occlusion p_cam/p_user") - (-0.7308)).abs() < 1e-4);
    assert!((find("foreshortening p_cam/p_user") - 2.4702).abs() < 1e-4);
    assert!((find("Fig. 3") - 0.9015).abs() < 1e-3);
    // The evaluation uses the given parameters: R1 from eq. RATIO1 by hand.
    let t = 30f64.to_radians().tan();
    let r1 = (10.0 * t - 10.8 * (0.25 + 0.05) / 0.8 + 0.05) / (20.0 * t);
    assert!((v["evaluation"]["left"]["R"].as_f64().unwrap() - r1).abs() < 1e-12);
    let (ok, _, err) = seethru(&["analyze", "--d1", "0"]);
    assert!(
        !ok && err
            .starts_with("error: invalid value '0' for '--d1 <D1>': must be a number in [1e-6,"),
        "{err}"
    );
}

#[test]
fn run_writes_six_views_run_json_and_metrics_and_measure_recomputes_them() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("run");
    let out_arg = out.to_str().unwrap();
    let (ok, _, err) = seethru(&[
        "run",
        "scenes/das.toml",
        "--out",
        out_arg,
        "--width",
        "96",
        "--frontal-width",
        "320",
        "--back-width",
        "160",
        "--spp",
        "1",
        "--head",
        "oracle",
        "--exr",
        "all",
    ]);
    assert!(ok, "{err}");
    for view in ["truth", "occluded", "frontal", "back", "display", "seethru"] {
        for ext in [".png", "_ids.png", ".exr"] {
            assert!(out.join(format!("{view}{ext}")).is_file(), "{view}{ext}");
        }
    }
    let run: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("run.json")).unwrap()).unwrap();
    assert_eq!(run["eye_true"]["paper"]["d1_m"].as_f64().unwrap(), 0.75);
    let metrics = std::fs::read_to_string(out.join("metrics.json")).unwrap();
    let m: serde_json::Value = serde_json::from_str(&metrics).unwrap();
    assert!(
        m["display"]["misregistration_arcmin"]["mean"]
            .as_f64()
            .unwrap()
            > 0.0
    );
    assert!(
        m["border_per_side"]["left"]["misregistration_arcmin"]["count"]
            .as_u64()
            .unwrap()
            > 0
    );
    let heat = image::open(out.join("misregistration.png")).unwrap();
    assert!(heat.width() > 96);
    // `measure` on the saved EXRs gives the same metrics.
    std::fs::remove_file(out.join("metrics.json")).unwrap();
    let (ok, _, err) = seethru(&["measure", out_arg]);
    assert!(ok, "{err}");
    assert_eq!(
        std::fs::read_to_string(out.join("metrics.json")).unwrap(),
        metrics
    );
}

/// One option that takes a value: the command's words, `--flag`, its value name and its help.
struct ValueOption {
    words: Vec<&'static str>,
    flag: String,
    value: String,
    help: String,
}

/// Every option that takes a value, per command, read from the command's own `--help`, so
/// that a flag added later is walked too.
fn options_with_values() -> Vec<ValueOption> {
    let commands: [&[&str]; 17] = [
        &["render"],
        &["run"],
        &["ratio", "occlusion"],
        &["ratio", "foreshortening"],
        &["reproduce"],
        &["sweep"],
        &["sweep-merge"],
        &["measure"],
        &["export"],
        &["figures"],
        &["analyze"],
        &["bench"],
        &["compare"],
        &["sequence"],
        &["diff"],
        &["check"],
        &["head-poses"],
    ];
    let mut found = Vec::new();
    for words in commands {
        let mut args = words.to_vec();
        args.push("--help");
        let (ok, help, err) = seethru(&args);
        assert!(ok, "{args:?}: {err}");
        let lines: Vec<&str> = help.lines().collect();
        for (i, line) in lines.iter().enumerate() {
            let line = line.trim();
            let Some(rest) = line.strip_prefix("--") else {
                continue;
            };
            let Some((flag, value)) = rest.split_once(" <") else {
                continue;
            };
            let (value, same_line) = value.split_once('>').unwrap_or((value, ""));
            // The description: the rest of the line (short help) or the lines up to the next
            // option (long help).
            let below: Vec<&str> = lines[i + 1..]
                .iter()
                .map(|l| l.trim())
                .take_while(|l| !l.starts_with("--") && !l.starts_with("-h,"))
                .collect();
            // Options with a fixed list of values (clap checks the names) are not numbers.
            if below.iter().any(|l| l.contains("Possible values")) {
                continue;
            }
            found.push(ValueOption {
                words: words.to_vec(),
                flag: format!("--{flag}"),
                value: value.to_string(),
                help: [same_line.trim(), &below.join(" ")].join(" "),
            });
        }
    }
    found
}

/// Options whose values are paths, names or free-form specs, not numbers.
const NOT_NUMBERS: [&str; 11] = [
    "OUT",
    "SCENE",
    "DIR",
    "PARAMS",
    "FILE",
    "CSV",
    "K/N",
    "NAME=VALUE",
    "LAYER",
    "CASE",
    "METHOD",
];

/// A range as help texts and errors write it: `[a, b]`, `(a, b]`, `[a, b)` or `(a, b)`, the
/// first such group in `text` (other parentheses, like `(default: …)`, are skipped).
#[derive(Debug, Clone, Copy, PartialEq)]
struct Range {
    low: f64,
    high: f64,
    low_closed: bool,
    high_closed: bool,
}

impl Range {
    fn first_in(text: &str) -> Option<Range> {
        let number = |s: &str| -> Option<f64> {
            let s = s.trim().replace('−', "-");
            match s.as_str() {
                "∞" | "inf" => Some(f64::INFINITY),
                "-∞" | "-inf" => Some(f64::NEG_INFINITY),
                _ => s.parse().ok(),
            }
        };
        for (open_at, open) in text.char_indices().filter(|(_, c)| *c == '[' || *c == '(') {
            let inner = &text[open_at + 1..];
            let Some(close_at) = inner.find([']', ')']) else {
                continue;
            };
            let Some((low, high)) = inner[..close_at].split_once(", ") else {
                continue;
            };
            let (Some(low), Some(high)) = (number(low), number(high)) else {
                continue;
            };
            return Some(Range {
                low,
                high,
                low_closed: open == '[',
                high_closed: inner[close_at..].starts_with(']'),
            });
        }
        None
    }

    fn contains(&self, v: f64) -> bool {
        let above = if self.low_closed {
            v >= self.low
        } else {
            v > self.low
        };
        let below = if self.high_closed {
            v <= self.high
        } else {
            v < self.high
        };
        v.is_finite() && above && below
    }
}

#[test]
fn every_numeric_flag_accepts_exactly_the_range_its_help_documents() {
    // For every numeric option: its help names a range; the range's ends, its middle, one
    // past each end, 0, −1, a huge number, NaN and the infinities are accepted exactly when
    // the documented range holds them (`inf` too where the value name offers it); each
    // refusal is one line naming the flag and the same range. `--flag=v --help` parses the
    // value and then prints the help, so no command runs.
    let options = options_with_values();
    assert!(options.len() > 40, "{} options", options.len());
    let scratch = tempfile::tempdir().unwrap();
    let mut walked = 0;
    let mut wrong = Vec::new();
    for option in options {
        if NOT_NUMBERS.contains(&option.value.as_str()) {
            continue;
        }
        let context = format!("{:?} {}", option.words, option.flag);
        let Some(range) = Range::first_in(&option.help) else {
            wrong.push(format!("{context}: no range in its help: {}", option.help));
            continue;
        };
        let mid = ((range.low.max(-1e6) + range.high.min(1e6)) / 2.0).floor();
        let mut probes: Vec<(String, f64)> = [range.low, range.high, mid]
            .into_iter()
            .chain([range.low - 1.0, range.high + 1.0, 0.0, -1.0])
            .filter(|v| v.is_finite())
            .map(|v| (format!("{v}"), v))
            .collect();
        for (text, v) in [
            ("1e300", 1e300),
            ("nan", f64::NAN),
            ("inf", f64::INFINITY),
            ("-inf", f64::NEG_INFINITY),
            ("99999999999999999999999", 1e23),
            ("x", f64::NAN),
        ] {
            probes.push((text.to_string(), v));
        }
        let takes_inf = option.value.contains("inf");
        for (text, v) in probes {
            // X,Y,Z options document the range of each axis.
            let given = if option.value == "X,Y,Z" {
                format!("{text},0,0")
            } else {
                text.clone()
            };
            // `--flag=v` and `--flag v` alike (clap took `-inf` after a space for an option).
            for joined in [true, false] {
                let mut args: Vec<String> = option.words.iter().map(|w| w.to_string()).collect();
                if joined {
                    args.push(format!("{}={given}", option.flag));
                } else {
                    args.extend([option.flag.clone(), given.clone()]);
                }
                args.push("--help".into());
                let args: Vec<&str> = args.iter().map(String::as_str).collect();
                let (ok, _, err) = seethru_in(scratch.path(), &args);
                let documented = range.contains(v) || (takes_inf && v == f64::INFINITY);
                let err = err.trim_end();
                if ok != documented {
                    wrong.push(format!(
                        "{context}={given}: accepted {ok}, but its help says {range:?}: {err}"
                    ));
                } else if !ok
                    && (err.lines().count() != 1
                        || !err.starts_with("error: invalid value")
                        || !err.contains(&option.flag)
                        || Range::first_in(err) != Some(range))
                {
                    wrong.push(format!(
                        "{context}={given}: not one line naming the flag and {range:?}: {err}"
                    ));
                }
            }
        }
        walked += 1;
    }
    assert!(wrong.is_empty(), "{}", wrong.join("\n"));
    assert!(walked > 30, "{walked}");
}

#[test]
fn logs_get_one_summary_line_and_quiet_gets_none() {
    // stderr is a pipe here, as in CI logs: no bar, no carriage returns.
    let dir = tempfile::tempdir().unwrap();
    let scene = dir.path().join("scene.toml");
    std::fs::write(&scene, common::MINIMAL).unwrap();
    let out = dir.path().join("out");
    let args = [
        "render",
        scene.to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
    ];
    let (ok, _, err) = seethru(&args);
    assert!(ok, "{err}");
    assert_eq!(err.lines().count(), 1, "{err}");
    assert!(!err.contains('\r'), "{err:?}");
    let (ok, stdout, err) = seethru(&[&args[..], &["--quiet"]].concat());
    assert!(ok && err.is_empty() && stdout.is_empty(), "{stdout}{err}");
}

#[test]
fn a_run_the_memory_limit_cannot_hold_is_refused_before_it_starts() {
    // das at 2560 px estimates about 1.4 GiB (1.18 GiB measured with /usr/bin/time): a
    // limit of 0.3 GiB refuses it at once, naming the estimate; nothing is written.
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("out");
    let args = |limit: &'static str| {
        vec![
            "run".to_string(),
            "scenes/das.toml".into(),
            "--out".into(),
            out.to_str().unwrap().into(),
            "--width".into(),
            "2560".into(),
            "--frontal-width".into(),
            "2560".into(),
            "--max-memory".into(),
            limit.into(),
        ]
    };
    let refused: Vec<String> = args("0.3");
    let refused: Vec<&str> = refused.iter().map(String::as_str).collect();
    let (ok, _, err) = seethru(&refused);
    assert!(!ok && err.lines().count() == 1, "{err}");
    assert!(
        err.starts_with("error: this needs about 1.") && err.contains("--max-memory 0.3 GiB"),
        "{err}"
    );
    assert!(!out.exists());
}

/// Files under `dir` whose names mark them as temporaries of an atomic write.
fn temporaries(dir: &std::path::Path) -> Vec<String> {
    std::fs::read_dir(dir)
        .map(|entries| {
            entries
                .flatten()
                .map(|e| e.file_name().to_string_lossy().to_string())
                .filter(|n| n.contains(".tmp-"))
                .collect()
        })
        .unwrap_or_default()
}

#[test]
#[cfg(unix)]
fn an_interrupted_run_leaves_no_partial_file() {
    // SIGINT at several moments of a run (rendering, writing the views, the metrics): the
    // process ends with 130 and one line, and no temporary stays behind; whatever it
    // finished is whole.
    let scratch = tempfile::tempdir().unwrap();
    let mut interrupted = 0;
    for (k, delay_ms) in [150u64, 500, 900, 1300, 1700].into_iter().enumerate() {
        let out = scratch.path().join(format!("out{k}"));
        let child = Command::new(env!("CARGO_BIN_EXE_seethru"))
            .args(["run", "scenes/das.toml", "--out", out.to_str().unwrap()])
            .stderr(std::process::Stdio::piped())
            .spawn()
            .unwrap();
        std::thread::sleep(std::time::Duration::from_millis(delay_ms));
        let _ = Command::new("kill")
            .args(["-INT", &child.id().to_string()])
            .status();
        let output = child.wait_with_output().unwrap();
        let err = String::from_utf8_lossy(&output.stderr);
        if output.status.code() == Some(130) {
            interrupted += 1;
            // (A summary line may precede it when the signal lands as the run ends.)
            let last = err.lines().last().unwrap_or_default();
            assert!(last.starts_with("error: interrupted;"), "{err}");
        }
        assert_eq!(
            temporaries(&out),
            Vec::<String>::new(),
            "after {delay_ms} ms"
        );
    }
    assert!(interrupted > 0, "no run was interrupted");
}

#[test]
#[cfg(target_os = "linux")]
fn temporaries_of_killed_processes_are_removed_by_the_next_write() {
    let dir = tempfile::tempdir().unwrap();
    let scene = dir.path().join("scene.toml");
    std::fs::write(&scene, common::MINIMAL).unwrap();
    let out = dir.path().join("out");
    std::fs::create_dir_all(&out).unwrap();
    // A process id above the kernel's maximum (2²²) never runs.
    let stale = out.join(".truth.png.tmp-4194305");
    std::fs::write(&stale, b"half a png").unwrap();
    let (ok, _, err) = seethru(&[
        "render",
        scene.to_str().unwrap(),
        "--view",
        "truth",
        "--out",
        out.to_str().unwrap(),
    ]);
    assert!(ok, "{err}");
    assert!(!stale.exists());
    assert!(out.join("truth.png").exists());
}

#[test]
fn bench_times_only_the_parts_asked_for() {
    let json = |parts: &str| -> serde_json::Value {
        let (ok, out, err) = seethru(&[
            "bench",
            "scenes/das.toml",
            "--width",
            "16",
            "--height",
            "9",
            "--repeat",
            "1",
            "--parts",
            parts,
            "--json",
        ]);
        assert!(ok, "--parts {parts}: {err}");
        serde_json::from_str(out.lines().last().unwrap()).unwrap()
    };
    let has = |v: &serde_json::Value, key: &str| v.get(key).is_some_and(|x| !x.is_null());
    let trace = json("trace");
    assert!(has(&trace, "bvh_build_ms") && has(&trace, "rays") && has(&trace, "frame"));
    for absent in ["methods", "sequence", "run"] {
        assert!(
            !has(&trace, absent),
            "--parts trace timed `{absent}`: {trace}"
        );
    }
    // Every report names its scene and memory, whatever it timed (and a choice may have
    // spaces around it).
    let sequence = json(" sequence");
    assert!(has(&sequence, "sequence") && has(&sequence, "peak_rss_bytes"));
    assert!(has(&sequence, "scene") && has(&sequence, "triangles"));
    for absent in ["bvh_build_ms", "rays", "frame", "methods", "run"] {
        assert!(
            !has(&sequence, absent),
            "--parts sequence timed `{absent}`: {sequence}"
        );
    }
}

#[test]
fn bench_times_the_kernels_named_by_isa_or_says_the_cpu_lacks_them() {
    // Every part runs on the kernels asked for (the JSON names them), and bench's own check
    // of its packets against the per-ray path holds on each; an ISA this CPU lacks is one
    // error line. The portable kernels run everywhere.
    let mut ran = Vec::new();
    for isa in ["avx512", "avx2", "portable"] {
        let (ok, out, err) = seethru(&[
            "bench",
            "scenes/das.toml",
            "--width",
            "64",
            "--height",
            "36",
            "--repeat",
            "1",
            "--parts",
            "trace",
            "--isa",
            isa,
            "--json",
        ]);
        if ok {
            let report: serde_json::Value =
                serde_json::from_str(out.lines().last().unwrap()).unwrap();
            assert_eq!(report["isa"], isa, "{report}");
            ran.push(isa);
        } else {
            let lines: Vec<&str> = err.lines().collect();
            assert_eq!(lines.len(), 1, "{err}");
            assert!(
                lines[0].starts_with(&format!("error: --isa {isa}: this CPU lacks {isa}")),
                "{err}"
            );
        }
    }
    assert!(ran.contains(&"portable"), "{ran:?}");
}

#[test]
fn bench_measures_its_repeats_and_how_busy_the_frame_kept_its_workers() {
    let (ok, out, err) = seethru(&[
        "bench",
        "scenes/das.toml",
        "--width",
        "160",
        "--height",
        "90",
        "--repeat",
        "3",
        "--threads",
        "2",
        "--json",
    ]);
    assert!(ok, "{err}");
    let v: serde_json::Value = serde_json::from_str(out.lines().last().unwrap()).unwrap();
    // Three repeats each: measured times that are positive, ordered, and not all the same (a
    // clock that is not read, or one figure for all repeats, gives min = max).
    let spreads = [
        &v["rays"]["primary"]["mrays_per_s"],
        &v["rays"]["shadow"]["mrays_per_s"],
        &v["rays"]["primary_shadow_per_ray"]["mrays_per_s"],
        &v["frame"]["truth"]["ms"],
        &v["frame"]["frontal"]["ms"],
    ];
    for spread in spreads {
        let [min, median, max] =
            ["min", "median", "max"].map(|k| spread[k].as_f64().unwrap_or(-1.0));
        assert!(
            0.0 < min && min <= median && median <= max && min < max && max.is_finite(),
            "{spread}"
        );
    }
    for view in ["truth", "frontal"] {
        // CPU time over wall time × threads: about 1 where the workers never wait, lower on a
        // busy machine; never twice as much (the threads left out) nor a thousandth (a unit
        // slip). Linux says; other systems give null.
        let busy = &v["frame"][view]["workers_busy"];
        if cfg!(target_os = "linux") {
            let busy = busy.as_f64().unwrap_or_else(|| panic!("{view}: {busy}"));
            assert!((0.05..=1.1).contains(&busy), "{view}: {busy}");
        } else {
            assert!(busy.is_null(), "{view}: {busy}");
        }
    }
}
