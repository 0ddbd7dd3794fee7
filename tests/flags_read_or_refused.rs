//! Every flag is read or refused: spaces around every choice value are ignored, and every flag of `run`, `sequence` and `compare` either changes the output or is refused
//! where the other flags make the command ignore it. Both walk the commands' own `--help`,
//! so a flag added later is checked too.

mod common;

use std::collections::BTreeMap;
use std::path::Path;

use common::refusal::run_in;

/// An option of a command's `--help`: its flag, value name (None for a switch), possible
/// values (choices), default and description.
#[derive(Debug, Clone)]
struct HelpOption {
    flag: String,
    value: Option<String>,
    choices: Vec<String>,
    default: Option<String>,
    help: String,
}

fn help_options(words: &[&str]) -> Vec<HelpOption> {
    let mut args = words.to_vec();
    args.push("--help");
    let (ok, help, err) = common::seethru(&args);
    assert!(ok, "{args:?}: {err}");
    let lines: Vec<&str> = help.lines().map(str::trim).collect();
    let mut found = Vec::new();
    for (i, line) in lines.iter().enumerate() {
        let Some(rest) = line.strip_prefix("--") else {
            continue;
        };
        let (flag, value) = match rest.split_once(" <") {
            Some((f, v)) => (f, Some(v.trim_end_matches('>').to_string())),
            None => (rest, None),
        };
        let below: Vec<&str> = lines[i + 1..]
            .iter()
            .copied()
            .take_while(|l| !l.starts_with("--") && !l.starts_with("-h,"))
            .collect();
        let choices = below
            .iter()
            .filter_map(|l| l.strip_prefix("- "))
            .map(|c| c.split(':').next().unwrap().trim().to_string())
            .collect();
        let default = below
            .iter()
            .find_map(|l| l.strip_prefix("[default: "))
            .map(|d| d.trim_end_matches(']').to_string());
        found.push(HelpOption {
            flag: format!("--{flag}"),
            value,
            choices,
            default,
            help: below.join(" "),
        });
    }
    found
}

const COMMANDS: [&[&str]; 19] = [
    &["render"],
    &["capture"],
    &["score"],
    &["diff"],
    &["check"],
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
    &["head-poses"],
];

#[test]
fn every_choice_flag_ignores_spaces_around_its_values() {
    // `--eyes ' both'` is `both`, as `--width ' 5'` is 5; in a list each item is trimmed.
    // `--flag=v --help` parses the value, then prints the help: nothing runs.
    let mut walked = 0;
    let mut wrong = Vec::new();
    for words in COMMANDS {
        for option in help_options(words) {
            if option.choices.is_empty() {
                continue;
            }
            walked += 1;
            for choice in &option.choices {
                for given in [
                    format!(" {choice}"),
                    format!("{choice} "),
                    format!(" {choice} "),
                ] {
                    let arg = format!("{}={given}", option.flag);
                    let mut args: Vec<&str> = words.to_vec();
                    args.extend([arg.as_str(), "--help"]);
                    let (ok, _, err) = common::seethru(&args);
                    if !ok {
                        wrong.push(format!("{words:?} {arg:?}: {err}"));
                    }
                }
            }
            // A value that is no choice, spaced or not, is still refused, naming the flag.
            let arg = format!("{}= nothing-of-the-kind ", option.flag);
            let mut args: Vec<&str> = words.to_vec();
            args.extend([arg.as_str(), "--help"]);
            let (ok, _, err) = common::seethru(&args);
            if ok || !err.starts_with("error: invalid value") || !err.contains(&option.flag) {
                wrong.push(format!("{words:?} {arg:?} accepted or unclear: {err}"));
            }
        }
    }
    // A list: `compare --methods 'planar-inf, ground'`.
    let (ok, _, err) = common::seethru(&["compare", "--methods= planar-inf , ground", "--help"]);
    if !ok {
        wrong.push(format!("compare --methods with spaces: {err}"));
    }
    // Every choice flag that takes a list (`a,b` accepted) takes it spaced, `' a , b '`.
    for words in COMMANDS {
        for option in help_options(words) {
            let [a, b, ..] = option.choices.as_slice() else {
                continue;
            };
            let parses = |value: String| {
                let arg = format!("{}={value}", option.flag);
                let mut args: Vec<&str> = words.to_vec();
                args.extend([arg.as_str(), "--help"]);
                common::seethru(&args)
            };
            if parses(format!("{a},{b}")).0 {
                let (ok, _, err) = parses(format!(" {a} , {b} "));
                if !ok {
                    wrong.push(format!("{words:?} {} ' {a} , {b} ': {err}", option.flag));
                }
            }
        }
    }
    assert!(wrong.is_empty(), "{}", wrong.join("\n"));
    assert!(walked >= 20, "{walked} choice flags");
}

/// A value for `option` that differs from its default and is quick to compute with.
fn probe(option: &HelpOption) -> Option<String> {
    let quick: BTreeMap<&str, &str> = [
        ("--width", "24"),
        ("--height", "12"),
        ("--frontal-width", "40"),
        ("--back-width", "40"),
        ("--spp", "2"),
        ("--band", "2"),
        ("--duration", "0.1"),
        ("--fps", "30"),
        ("--display-hz", "20"),
        ("--depth-resolution", "20"),
        ("--lean-at", "0.02"),
        ("--lean-s", "0.05"),
        ("--latency-camera", "30"),
        ("--head-bias-cm", "2,0,0"),
        ("--d2", "3"),
        ("--head-jitter-cm", "2"),
        ("--speed", "40"),
    ]
    .into_iter()
    .collect();
    if let Some(v) = quick.get(option.flag.as_str()) {
        return Some(v.to_string());
    }
    if !option.choices.is_empty() {
        return option
            .choices
            .iter()
            .find(|c| Some(*c) != option.default.as_ref())
            .cloned();
    }
    option.value.as_ref()?;
    // The middle of the documented range, or its low end when that is the default.
    let text = option.help.as_str();
    let open = text.find('[')?;
    let (low, high) = text[open + 1..].split(']').next()?.split_once(", ")?;
    let (low, high): (f64, f64) = (low.trim().parse().ok()?, high.trim().parse().ok()?);
    let mid = (low + high.min(1e3)) / 2.0;
    let default: Option<f64> = option.default.as_ref().and_then(|d| d.parse().ok());
    Some(if default == Some(mid) { low } else { mid }.to_string())
}

/// Every file under `dir` (relative path → bytes), but `skip`'s names, which record the
/// parameters themselves.
fn files(dir: &Path, skip: &[&str]) -> BTreeMap<String, Vec<u8>> {
    let mut out = BTreeMap::new();
    let mut stack = vec![dir.to_path_buf()];
    while let Some(d) = stack.pop() {
        for e in std::fs::read_dir(&d).unwrap().flatten() {
            let p = e.path();
            if p.is_dir() {
                stack.push(p);
            } else if !skip.contains(&e.file_name().to_str().unwrap()) {
                out.insert(
                    p.strip_prefix(dir).unwrap().display().to_string(),
                    std::fs::read(&p).unwrap(),
                );
            }
        }
    }
    out
}

/// Flags no output file can show: where the output goes, how it is computed (identical
/// for any thread count, by design), its memory limit, the log, and inputs that need a file.
const NOT_OUTPUTS: [&str; 8] = [
    "--out",
    "--threads",
    "--max-memory",
    "--quiet",
    "--calibration",
    "--head-path",
    "--help",
    "--version",
];

/// Runs `base` with each flag of `words`' help set to a probe value: each must be refused
/// as ignored (one line naming it) or change an output file. `unchanged_ok` lists flags the
/// scene cannot show under `base`, each with the reason.
fn each_flag_is_read_or_refused(
    words: &[&str],
    base: &[&str],
    skip: &[&str],
    unchanged_ok: &[(&str, &str)],
) -> Vec<String> {
    let dir = common::refusal::scratch("", &[]);
    let mut args: Vec<&str> = words.to_vec();
    args.extend(["scene.toml", "--out", "base"]);
    args.extend(base);
    let (code, err) = run_in(dir.path(), &args);
    assert_eq!(code, 0, "{args:?}: {err}");
    let reference = files(&dir.path().join("base"), skip);
    let mut wrong = Vec::new();
    for option in help_options(words) {
        if NOT_OUTPUTS.contains(&option.flag.as_str())
            || base.contains(&option.flag.as_str())
            || unchanged_ok.iter().any(|(f, _)| *f == option.flag)
        {
            continue;
        }
        let value = probe(&option);
        let mut args: Vec<&str> = words.to_vec();
        args.extend(["scene.toml", "--out", "probe"]);
        args.extend(base);
        args.push(&option.flag);
        if option.value.is_some() {
            let Some(v) = value.as_deref() else {
                wrong.push(format!("{}: no probe value", option.flag));
                continue;
            };
            args.push(v);
        }
        let _ = std::fs::remove_dir_all(dir.path().join("probe"));
        let (code, err) = run_in(dir.path(), &args);
        if code != 0 {
            // Refused as ignored (naming the flag), or for another reason the user is told
            // (no face in the minimal scene's back camera): not silently dropped.
            if !(err.starts_with("error: ") && err.lines().count() == 1) {
                wrong.push(format!("{args:?}: refused without one error line: {err}"));
            }
            continue;
        }
        if files(&dir.path().join("probe"), skip) == reference {
            wrong.push(format!(
                "{args:?}: accepted, and every output is identical without it: ignored"
            ));
        }
    }
    wrong
}

#[test]
fn every_flag_of_run_changes_the_output_or_is_refused() {
    let mut wrong = Vec::new();
    // run.json records every parameter: the views and metrics must show the flag.
    let skip = ["run.json"];
    for (base, unchanged_ok) in [
        (
            &["--spp", "1", "--head-jitter-cm", "0"][..],
            &[(
                "--outside",
                "only a crop past the frontal view differs, and the minimal scene's fits",
            )][..],
        ),
        (
            &["--spp", "1", "--method", "depth"],
            &[
                ("--outside", "as above"),
                (
                    "--fill",
                    "the minimal scene's sphere leaves no disocclusion hole",
                ),
                (
                    "--depth-sensor",
                    "tested by tests/bad_input.rs (its settings follow it)",
                ),
            ],
        ),
        (
            &["--spp", "1", "--method", "none"],
            &[
                ("--outside", "as above"),
                (
                    "--filter",
                    "none scales the whole frontal image; its filter is read",
                ),
            ],
        ),
    ] {
        wrong.extend(each_flag_is_read_or_refused(
            &["run"],
            base,
            &skip,
            unchanged_ok,
        ));
    }
    assert!(wrong.is_empty(), "{}", wrong.join("\n"));
}

#[test]
fn every_flag_of_sequence_changes_the_output_or_is_refused() {
    let mut wrong = Vec::new();
    // The summaries record every parameter: frames.csv, the plots and previews must show it.
    let skip = ["summary.json"];
    let quick = [
        "--duration",
        "0.1",
        "--width",
        "24",
        "--fps",
        "30",
        "--speed",
        "40",
        "--yaw-rate",
        "10",
    ];
    // Lean starts within the 0.1 s; the yaw makes --reproject visible (at d2 → ∞ a pure
    // translation needs none); --method none reads no eye estimate.
    for extra in [
        &["--head", "sway"][..],
        &["--head", "lean", "--lean-at", "0.02"],
        &["--head", "sway", "--method", "none"],
    ] {
        let mut base: Vec<&str> = quick.to_vec();
        base.extend(["--latency-camera", "30"]);
        base.extend(extra);
        wrong.extend(each_flag_is_read_or_refused(
            &["sequence"],
            &base,
            &skip,
            &[
                ("--outside", "only a crop past the frontal view differs"),
                (
                    "--capture",
                    "writes a folder of its own, outside --out (tests/sequence_capture.rs reads it)",
                ),
                (
                    "--maps",
                    "needs a folder of maps made from a --capture (tests/sequence_capture.rs scores them)",
                ),
            ],
        ));
    }
    assert!(wrong.is_empty(), "{}", wrong.join("\n"));
}

#[test]
fn every_flag_of_compare_changes_the_output_or_is_refused() {
    // Methods that read no depth: every depth flag is refused, as `run` refuses them.
    // The table's files record the settings: the strips must show the flag.
    let wrong = each_flag_is_read_or_refused(
        &["compare"],
        &["--spp", "1", "--methods", "planar-inf,ground"],
        &["compare.md", "compare.html", "compare.json"],
        &[(
            "--band",
            "changes the table's border-band metrics only (tests/measurements.rs checks them)",
        )],
    );
    assert!(wrong.is_empty(), "{}", wrong.join("\n"));
}

#[test]
fn compare_reads_the_hazard_bound_only_for_a_scene_with_hazards() {
    // The minimal scene's ball stands behind the pillar; a hazard sphere nearer, at 4 m,
    // is hidden too. planar-inf misplaces it by a few arc-minutes (its plane is at ∞), so
    // a bound of 0.5′ shows fewer of its hidden pixels than the default 30′.
    let hazard = "\n[[object]]\nname = \"walker\"\nkind = \"sphere\"\nmaterial = \"grey\"\nradius = 0.4\ntranslate = [0.0, 1.2, -4.0]\nhazard = true\n";
    let dir = common::refusal::scratch(hazard, &[]);
    let compare = |out: &str, extra: &[&str]| -> serde_json::Value {
        let mut args = vec![
            "compare",
            "scene.toml",
            "--out",
            out,
            "--spp",
            "1",
            "--width",
            "64",
            "--methods",
            "planar-inf,planar-auto",
        ];
        args.extend(extra);
        let (code, err) = run_in(dir.path(), &args);
        assert_eq!(code, 0, "{args:?}: {err}");
        let md = std::fs::read_to_string(dir.path().join(out).join("compare.md")).unwrap();
        assert!(
            md.contains("| walker visibility | walker centroid ′ |"),
            "{md}"
        );
        serde_json::from_str(
            &std::fs::read_to_string(dir.path().join(out).join("compare.json")).unwrap(),
        )
        .unwrap()
    };
    let (wide, tight) = (
        compare("wide", &[]),
        compare("tight", &["--hazard-bound-arcmin", "0.5"]),
    );
    let walker = |json: &serde_json::Value, row: usize, key: &str| {
        json["rows"][row]["hazards"]["objects"][0][key].clone()
    };
    assert_eq!(wide["rows"][0]["hazards"]["bound_arcmin"], 30.0);
    assert_eq!(tight["rows"][0]["hazards"]["bound_arcmin"], 0.5);
    let hidden = walker(&wide, 0, "hidden_pixels").as_u64().unwrap();
    assert!(hidden > 20, "{wide}");
    assert_eq!(
        walker(&tight, 0, "hidden_pixels"),
        walker(&wide, 0, "hidden_pixels")
    );
    let shown = |json: &serde_json::Value| walker(json, 0, "shown_pixels").as_u64().unwrap();
    assert!(shown(&wide) > hidden / 2, "{wide}");
    assert!(
        shown(&tight) < shown(&wide) / 2,
        "{} vs {}",
        shown(&tight),
        shown(&wide)
    );
    // The centroid error does not depend on the bound; each row has its own.
    assert_eq!(
        walker(&tight, 0, "centroid_error_arcmin"),
        walker(&wide, 0, "centroid_error_arcmin")
    );
    assert!(walker(&wide, 1, "visibility").as_f64().is_some());
    // Without a hazard object the flag would be ignored: refused, in one line.
    let plain = common::refusal::scratch("", &[]);
    common::refusal::refused(
        plain.path(),
        &[
            "compare",
            "scene.toml",
            "--out",
            "out",
            "--width",
            "16",
            "--hazard-bound-arcmin",
            "5",
        ],
        1,
        &["--hazard-bound-arcmin is read only for a scene with an object marked `hazard = true`"],
    );
    assert!(!plain.path().join("out").exists());
}

#[test]
fn the_worlds_limits_follow_what_moves() {
    // A keyframed mesh: its origin stays inside the world, its triangles leave it at t = 1 s
    // (a sphere on the same path was refused; the mesh was not).
    let mesh = "v -3 0 0\nv 3 0 0\nv 0 3 0\nf 1 2 3\n";
    let keyed = |x: &str| {
        format!(
            "\n[[object]]\nname = \"m\"\nkind = \"mesh\"\npath = \"m.obj\"\ntranslate = [0.0, 0.0, -10.0]\n[[object.keyframe]]\nt = 0.0\n[[object.keyframe]]\nt = 1.0\ntranslate = [{x}, 0.0, -10.0]\n"
        )
    };
    let dir = common::refusal::scratch(&keyed("999998.0"), &[("m.obj", mesh.as_bytes())]);
    let text = std::fs::read_to_string(dir.path().join("scene.toml")).unwrap();
    let line = text
        .lines()
        .position(|l| l.starts_with("translate = [999998.0"))
        .unwrap()
        + 1;
    common::refusal::refused(
        dir.path(),
        &["render", "scene.toml", "--out", "out", "--width", "8"],
        1,
        &[
            &format!("scene.toml:{line}:"),
            "keyframe[1].translate",
            "takes its mesh m.obj outside the world at t = 1 s",
            "1000001",
        ],
    );
    assert!(!dir.path().join("out").exists());
    // Three metres nearer, every vertex is inside: accepted.
    let dir = common::refusal::scratch(&keyed("999996.0"), &[("m.obj", mesh.as_bytes())]);
    let (code, err) = run_in(
        dir.path(),
        &["render", "scene.toml", "--out", "out", "--width", "8"],
    );
    assert_eq!(code, 0, "{err}");

    // A head path: within the CSV's ±1e6 in the obstacle frame, but the obstacle stands at
    // z = −0.8 m, so z = −999999.5 puts the eye at −1000000.3 in the world.
    let dir = common::refusal::scratch(
        "",
        &[("p.csv", b"t,x,y,z\n0,0,0,0.8\n0.05,0,0,-999999.5\n")],
    );
    common::refusal::refused(
        dir.path(),
        &[
            "sequence",
            "scene.toml",
            "--out",
            "out",
            "--head-path",
            "p.csv",
            "--duration",
            "0.1",
            "--width",
            "16",
        ],
        1,
        &["p.csv:3: the eye at t = 0.05 s lies outside the world"],
    );
    assert!(!dir.path().join("out").exists());
}

#[test]
fn sweep_merge_checks_each_parts_rows_as_a_resume_does() {
    let dir = common::refusal::scratch("", &[]);
    let sweep = |out: &str| {
        let (code, err) = run_in(
            dir.path(),
            &[
                "sweep",
                "scene.toml",
                "--width",
                "8",
                "--param",
                "theta_f=20,40",
                "--out",
                out,
            ],
        );
        assert_eq!(code, 0, "{err}");
        std::fs::read_to_string(dir.path().join(out)).unwrap()
    };
    let whole = sweep("s.csv");
    let (code, err) = run_in(dir.path(), &["sweep-merge", "s.csv", "--out", "m.csv"]);
    assert_eq!(code, 0, "{err}");
    // One row twice in a part: refused by the merge, as by a resume of the same file.
    let lines: Vec<&str> = whole.lines().collect();
    let twice = format!("{}\n{}\n{}\n{}\n", lines[0], lines[1], lines[1], lines[2]);
    std::fs::write(dir.path().join("twice.csv"), &twice).unwrap();
    let merged = common::refusal::refused(
        dir.path(),
        &["sweep-merge", "twice.csv", "--out", "m2.csv"],
        1,
        &["twice.csv:3: configuration 0 appears twice (also on line 2)"],
    );
    std::fs::write(dir.path().join("s.csv"), &twice).unwrap();
    let resumed = common::refusal::refused(
        dir.path(),
        &[
            "sweep",
            "scene.toml",
            "--width",
            "8",
            "--param",
            "theta_f=20,40",
            "--out",
            "s.csv",
        ],
        1,
        &["s.csv:3: configuration 0 appears twice (also on line 2)"],
    );
    assert_eq!(
        merged.split(": configuration").nth(1),
        resumed.split(": configuration").nth(1)
    );
    assert!(!dir.path().join("m2.csv").exists());
}

#[test]
fn sequence_estimates_its_memory_first_and_messages_name_the_form_and_the_file() {
    let dir = common::refusal::scratch("", &[]);
    common::refusal::refused(
        dir.path(),
        &[
            "sequence",
            "scene.toml",
            "--out",
            "out",
            "--width",
            "64",
            "--max-memory",
            "0.0001",
        ],
        1,
        &[
            "this needs about",
            "more than --max-memory 0.0001 GiB",
            "preview frames",
        ],
    );
    assert!(common::refusal::listing(dir.path()) == ["scene.toml"]);
    // The estimate counts the frames kept: a long sequence needs more than a short one.
    let needs = |duration: &str| -> String {
        let (_, err) = run_in(
            dir.path(),
            &[
                "sequence",
                "scene.toml",
                "--out",
                "out",
                "--duration",
                duration,
                "--max-memory",
                "0.000001",
            ],
        );
        assert!(err.contains("this needs about"), "{err}");
        err
    };
    assert!(needs("1").contains(" 30 preview frames and the records of 1×60 frames"));
    assert!(needs("1000").contains(" 30000 preview frames and the records of 1×60000 frames"));
    common::refusal::refused(
        dir.path(),
        &[
            "run",
            "scene.toml",
            "--out",
            "out",
            "--head-bias-cm",
            "nan",
            "0",
            "0",
        ],
        2,
        &["--head-bias-cm takes x,y,z in one word", "got `nan 0 …`"],
    );
    common::refusal::refused(
        dir.path(),
        &["export", "scene.toml", "--out", "/proc/x.obj"],
        1,
        &["--out /proc/x.obj", "cannot write into /proc"],
    );
}

/// The colour images of a run folder, by name.
fn images(dir: &Path) -> BTreeMap<String, Vec<u8>> {
    files(dir, &[])
        .into_iter()
        .filter(|(name, _)| name.ends_with(".png"))
        .collect()
}

#[test]
fn a_kill_at_any_moment_leaves_the_old_set_or_the_new_one() {
    // Two generations of one output (spp 1 and 2 differ in every view's colours) written in
    // turn into the same existing --out, each killed (SIGKILL) at a seeded random moment of
    // its run: afterwards the folder holds exactly one generation's images, never a mix.
    let dir = common::refusal::scratch("", &[]);
    let args = |spp: &'static str| {
        vec![
            "run",
            "scene.toml",
            "--out",
            "out",
            "--spp",
            spp,
            "--frontal-width",
            "96",
            "--width",
            "96",
        ]
    };
    let mut generations = Vec::new();
    let start = std::time::Instant::now();
    for spp in ["1", "2"] {
        let (code, err) = run_in(dir.path(), &args(spp));
        assert_eq!(code, 0, "{err}");
        generations.push(images(&dir.path().join("out")));
    }
    assert_ne!(generations[0], generations[1]);
    let one_run = start.elapsed().as_secs_f64() / 2.0;
    let mut state: u64 = 0x5eed;
    let mut kills = 0;
    let deadline = std::time::Instant::now() + std::time::Duration::from_secs(40);
    let mut round = 0usize;
    while std::time::Instant::now() < deadline && round < 200 {
        state = state
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        let at = one_run * 1.2 * ((state >> 11) as f64 / (1u64 << 53) as f64);
        let mut child = std::process::Command::new(env!("CARGO_BIN_EXE_seethru"))
            .arg("--quiet")
            .args(args(["1", "2"][round % 2]))
            .current_dir(dir.path())
            .spawn()
            .unwrap();
        std::thread::sleep(std::time::Duration::from_secs_f64(at));
        if child.try_wait().unwrap().is_none() {
            child.kill().unwrap();
            kills += 1;
        }
        let _ = child.wait();
        let now = images(&dir.path().join("out"));
        assert!(
            generations.contains(&now),
            "round {round}, killed at {at:.3} s: a mixed set of {} images",
            now.len()
        );
        round += 1;
    }
    assert!(kills > 0 && round > 10, "{kills} kills in {round} rounds");
}

/// Runs `words positional --out o base --flag v` and the same with `' v '` for every value
/// of every choice flag of `words`' help (in `dir`): both give the same exit code, stderr
/// and files (but `skip`'s, which record the command line as typed). Refusals count too:
/// a spaced value must be refused with the unspaced one's message.
fn spaced_choices_give_the_same_output(
    dir: &Path,
    words: &[&str],
    positional: &str,
    base: &[&str],
    skip: &[&str],
) -> (usize, Vec<String>) {
    let out = dir.join("o");
    let mut compared = 0;
    let mut wrong = Vec::new();
    let outcome = |flag: &str, value: &str| {
        let _ = std::fs::remove_dir_all(&out);
        let mut args: Vec<&str> = words.to_vec();
        args.extend([positional, "--out", "o"]);
        args.extend(base);
        args.extend([flag, value]);
        let (code, err) = run_in(dir, &args);
        let mut written = if out.is_dir() {
            files(&out, skip)
        } else {
            BTreeMap::new()
        };
        // run.json records every parameter as parsed (compared), and the time and memory
        // the run took (which vary from run to run: left out).
        for (name, bytes) in written.iter_mut() {
            if name.ends_with("run.json") {
                let mut report: serde_json::Value = serde_json::from_slice(bytes).unwrap();
                for key in ["timings_s", "peak_rss_bytes"] {
                    report.as_object_mut().unwrap().remove(key);
                }
                *bytes = report.to_string().into_bytes();
            }
        }
        (code, err, written)
    };
    for option in help_options(words) {
        if base.contains(&option.flag.as_str()) {
            continue;
        }
        for choice in &option.choices {
            let plain = outcome(&option.flag, choice);
            let spaced = outcome(&option.flag, &format!(" {choice} "));
            compared += 1;
            if plain != spaced {
                wrong.push(format!(
                    "{words:?} {} ' {choice} ' differs from '{choice}': exit {} vs {}, `{}` vs `{}`",
                    option.flag,
                    spaced.0,
                    plain.0,
                    spaced.1.trim(),
                    plain.1.trim()
                ));
            }
        }
    }
    (compared, wrong)
}

#[test]
fn every_spaced_choice_value_gives_the_unspaced_output() {
    let dir = common::refusal::scratch("", &[]);
    let mut wrong = Vec::new();
    let mut compared = 0;
    for (words, base, skip) in [
        (
            &["render"][..],
            &["--width", "8", "--spp", "1"][..],
            &[][..],
        ),
        (&["run"], &["--width", "16", "--spp", "1"], &[]),
        // capture_spec.json holds the parsed options: spaced values give the same file.
        (&["capture"], &["--width", "16", "--spp", "1"], &[]),
        (&["export"], &[], &[]),
    ] {
        let positional = "scene.toml";
        let (n, w) = spaced_choices_give_the_same_output(dir.path(), words, positional, base, skip);
        compared += n;
        wrong.extend(w);
    }
    // score: a capture and a map for it.
    let inputs = score_inputs(dir.path());
    let (n, w) = spaced_choices_give_the_same_output(
        dir.path(),
        &["score"],
        &inputs,
        &["--map", "map.npy"],
        &[],
    );
    compared += n;
    wrong.extend(w);
    assert!(wrong.is_empty(), "{}", wrong.join("\n"));
    // render 7 values, run 30, capture 16, export 3, score 2.
    assert!(compared >= 55, "{compared} values compared");
}

/// A capture of the minimal scene in `dir`/cap and a display map for it, `dir`/map.npy: the
/// display's pixels spread over the frontal image (so that the filters differ).
fn score_inputs(dir: &Path) -> String {
    let (code, err) = run_in(
        dir,
        &[
            "capture",
            "scene.toml",
            "--out",
            "cap",
            "--width",
            "16",
            "--spp",
            "1",
        ],
    );
    assert_eq!(code, 0, "{err}");
    let manifest: serde_json::Value =
        serde_json::from_slice(&std::fs::read(dir.join("cap/capture.json")).unwrap()).unwrap();
    let size = |key: &str, i: usize| manifest[key][i].as_u64().unwrap() as usize;
    let (dw, dh) = (
        size("display_resolution_px", 0),
        size("display_resolution_px", 1),
    );
    let (fw, fh) = (size("frontal_size_px", 0), size("frontal_size_px", 1));
    let mut xy = Vec::new();
    for v in 0..dh {
        for u in 0..dw {
            // A non-integer scale: samples between pixels, where the filters differ.
            xy.push(u as f32 * (fw as f32 - 1.0) / (dw as f32 + 0.37));
            xy.push(v as f32 * (fh as f32 - 1.0) / (dh as f32 + 0.37));
        }
    }
    seethru::io::display_map::write_npy_f32(&dir.join("map.npy"), &[dh, dw, 2], &xy).unwrap();
    "cap".to_string()
}

#[test]
fn every_flag_of_capture_changes_the_output_or_is_refused() {
    // truth/capture_spec.json records the options: the other files must show them.
    let mut wrong = Vec::new();
    for base in [
        &["--spp", "1", "--width", "16"][..],
        // The depth sensor's flags are read with --depth and a sensor that has settings.
        &[
            "--spp",
            "1",
            "--width",
            "16",
            "--depth",
            "--depth-sensor",
            "tof",
        ],
        // The tracker model draws its noise from --seed.
        &["--spp", "1", "--width", "16", "--head", "model"],
        // --ipd places the eyes.
        &["--spp", "1", "--width", "16", "--eyes", "left"],
    ] {
        wrong.extend(each_flag_is_read_or_refused(
            &["capture"],
            base,
            &["capture_spec.json"],
            &[],
        ));
    }
    assert!(wrong.is_empty(), "{}", wrong.join("\n"));
}

#[test]
fn score_refuses_a_filter_it_would_not_read() {
    let dir = common::refusal::scratch("", &[]);
    let inputs = score_inputs(dir.path());
    let score = |out: &str, extra: &[&str]| {
        let mut args = vec!["score", inputs.as_str(), "--out", out];
        args.extend(extra);
        let (code, err) = run_in(dir.path(), &args);
        (code, err, dir.path().join(out))
    };
    // With a map, the filter is read: bicubic shows other colours than bilinear.
    let (code, err, bilinear) = score("bilinear", &["--map", "map.npy"]);
    assert_eq!(code, 0, "{err}");
    let (code, err, bicubic) = score("bicubic", &["--map", "map.npy", "--filter", "bicubic"]);
    assert_eq!(code, 0, "{err}");
    assert_ne!(
        std::fs::read(bilinear.join("display.png")).unwrap(),
        std::fs::read(bicubic.join("display.png")).unwrap()
    );
    // A display image replaces the map's colours, and alone has no points to resample at:
    // --filter, even at its default, is refused with one line, and nothing is written.
    std::fs::copy(bilinear.join("display.png"), dir.path().join("shown.png")).unwrap();
    for extra in [
        &["--display-image", "shown.png", "--filter", "bilinear"][..],
        &[
            "--display-image",
            "shown.png",
            "--map",
            "map.npy",
            "--filter",
            "bicubic",
        ],
    ] {
        let mut args = vec!["score", inputs.as_str(), "--out", "refused"];
        args.extend(extra);
        common::refusal::refused(
            dir.path(),
            &args,
            1,
            &["--filter is read only with --map and no --display-image"],
        );
        assert!(!dir.path().join("refused").exists());
    }
    // --display-codes says what a display image holds: without one it is refused.
    common::refusal::refused(
        dir.path(),
        &[
            "score",
            inputs.as_str(),
            "--out",
            "refused",
            "--map",
            "map.npy",
            "--display-codes",
        ],
        1,
        &["--display-codes is read only with --display-image"],
    );
    assert!(!dir.path().join("refused").exists());
}

#[test]
fn the_tracker_models_seed_is_read_not_refused() {
    // `--head model` draws the tracker's noise and dropouts from --seed: another seed, another
    // estimate, in run, compare and capture (run and compare refused --seed as ignored).
    let dir = common::refusal::scratch("", &[]);
    for (words, base, shown) in [
        (
            &["run"][..],
            &["--spp", "1", "--width", "16", "--head", "model"][..],
            "seethru.png",
        ),
        (
            &["compare"],
            &[
                "--spp",
                "1",
                "--width",
                "16",
                "--head",
                "model",
                "--methods",
                "planar-inf",
            ],
            "strip_planar-inf.png",
        ),
        (
            &["capture"],
            &["--spp", "1", "--width", "16", "--head", "model"],
            "head.json",
        ),
    ] {
        let mut shown_by = Vec::new();
        for (out, seed) in [("a", "1"), ("b", "7")] {
            let mut args: Vec<&str> = words.to_vec();
            args.extend(["scene.toml", "--out", out]);
            args.extend(base);
            args.extend(["--seed", seed]);
            let (code, err) = run_in(dir.path(), &args);
            assert_eq!(code, 0, "{args:?}: {err}");
            let all = files(&dir.path().join(out), &[]);
            let image = all
                .iter()
                .find(|(name, _)| name.ends_with(shown))
                .unwrap_or_else(|| panic!("{words:?}: no {shown} in {:?}", all.keys()));
            shown_by.push(image.1.clone());
        }
        assert_ne!(
            shown_by[0], shown_by[1],
            "{words:?}: --seed changes nothing"
        );
    }
}

#[test]
fn every_flag_of_head_poses_changes_its_table_or_is_refused_with_its_range() {
    // head-poses prints its table on stdout: each flag walked from its help must change it,
    // but --threads (bit-identical by design); out-of-range values are one error line naming
    // the flag and its range; a scene without a head to turn is refused.
    let dir = tempfile::tempdir().unwrap();
    let scene = dir.path().join("mesh.toml");
    std::fs::write(&scene, common::das_with_mesh_head_text()).unwrap();
    let scene = scene.to_str().unwrap();
    let base = ["--yaw", "0", "--pitch", "0", "--distance-scale", "1"];
    let table = |extra: &[&str]| {
        let mut args = vec!["head-poses", scene];
        args.extend(base);
        args.extend(extra);
        let (ok, out, err) = common::seethru(&args);
        assert!(ok, "{args:?}: {err}");
        out
    };
    let reference = table(&[]);
    assert!(
        reference.contains("1 poses") && reference.contains("| yaw fit |"),
        "{reference}"
    );
    let mut walked = Vec::new();
    for option in help_options(&["head-poses"]) {
        let probe = match option.flag.as_str() {
            "--help" | "--version" => continue,
            "--threads" => {
                assert_eq!(
                    table(&["--threads", "1"]),
                    reference,
                    "--threads changed the table"
                );
                walked.push("--threads".to_string());
                continue;
            }
            "--quiet" => {
                // Quiets the log on stderr; the table is the output.
                assert_eq!(table(&["--quiet"]), reference, "--quiet changed the table");
                walked.push("--quiet".to_string());
                continue;
            }
            "--yaw" => "20",
            "--pitch" => "8",
            "--distance-scale" => "1.2",
            "--back-width" => "480",
            other => panic!("{other}: a new flag of head-poses: give it a probe here"),
        };
        assert_ne!(
            table(&[&option.flag, probe]),
            reference,
            "{} {probe}: accepted, and the table is identical without it: ignored",
            option.flag
        );
        walked.push(option.flag.clone());
    }
    assert_eq!(walked.len(), 6, "{walked:?}");
    for (flag, bad, range) in [
        ("--yaw", "90", "[-89, 89]"),
        ("--pitch", "-46", "[-45, 45]"),
        ("--distance-scale", "0.4", "[0.5, 2]"),
        ("--back-width", "0", "[1, 16384]"),
    ] {
        let (ok, out, err) = common::seethru(&["head-poses", scene, flag, bad]);
        assert!(!ok && out.is_empty(), "{flag} {bad} accepted");
        assert!(
            err.starts_with("error:") && err.lines().count() == 1 && err.contains(flag),
            "{flag} {bad}: {err}"
        );
        assert!(
            err.contains(range) || err.contains(&range.replace(", ", "..")),
            "{flag} {bad}: {err}"
        );
    }
    let plain = dir.path().join("plain.toml");
    std::fs::write(&plain, common::MINIMAL).unwrap();
    let (ok, _, err) = common::seethru(&["head-poses", plain.to_str().unwrap()]);
    assert!(
        !ok && err.starts_with("error:") && err.contains("moves_with"),
        "{err}"
    );
}

/// `sweep --param eye=eyellipse`'s own flags, walked as `run`'s are: each changes an output
/// (the rows, their eyes and metrics, the share of drivers under the bound); each is refused
/// in one line without `eye=eyellipse`, and outside its range naming the range; and each
/// reads a spaced value as the unspaced one, output for output. Nothing is written when
/// refused.
#[test]
fn the_sweeps_eyellipse_flags_are_read_refused_and_take_spaced_values() {
    let dir = tempfile::tempdir().unwrap();
    let cabin = common::repo_path("scenes/cabin.toml");
    let cabin = cabin.to_str().unwrap();
    let sweep = |out: &str, flags: &[&str]| -> (String, String) {
        let mut args = vec!["sweep", cabin, "--out", out, "--width", "16"];
        args.extend(flags);
        let (code, err) = run_in(dir.path(), &args);
        assert_eq!(code, 0, "{args:?}: {err}");
        let stem = out.trim_end_matches(".csv");
        (
            std::fs::read_to_string(dir.path().join(out)).unwrap(),
            std::fs::read_to_string(dir.path().join(format!("{stem}_drivers.json"))).unwrap(),
        )
    };
    let base = [
        "--param",
        "eye=eyellipse",
        "--samples",
        "2",
        "--seed",
        "3",
        "--bound-arcmin",
        "20",
    ];
    let (csv, shares) = sweep("base.csv", &base);
    let rows = |csv: &str| csv.lines().skip(1).count();
    let means = |csv: &str| -> Vec<String> {
        csv.lines()
            .skip(1)
            .map(|l| l.split(',').nth(2).unwrap().to_string())
            .collect()
    };
    let under = |json: &str| {
        let v: serde_json::Value = serde_json::from_str(json).unwrap();
        v["groups"][0]["mean_misregistration"]["under_bound"]
            .as_u64()
            .unwrap()
    };
    assert_eq!(rows(&csv), 2, "{csv}");
    fn with<'a>(base: &[&'a str], flag: &str, value: &'a str) -> Vec<&'a str> {
        let mut flags = base.to_vec();
        let at = flags.iter().position(|f| *f == flag).unwrap();
        flags[at + 1] = value;
        flags
    }
    // --samples: one row per driver.
    let (more, _) = sweep("samples.csv", &with(&base, "--samples", "3"));
    assert_eq!(rows(&more), 3, "{more}");
    // --seed: other drivers, other metrics.
    let (other, _) = sweep("seed.csv", &with(&base, "--seed", "4"));
    assert!(
        means(&other).iter().all(|m| !means(&csv).contains(m)),
        "{other}\n{csv}"
    );
    // --bound-arcmin: the same rows, another share (the two drivers' means straddle 20′).
    let m: Vec<f64> = means(&csv).iter().map(|m| m.parse().unwrap()).collect();
    let expected = |bound: f64| m.iter().filter(|&&v| v <= bound).count() as u64;
    assert_eq!(under(&shares), expected(20.0), "{csv}");
    let (same, wide) = sweep("bound.csv", &with(&base, "--bound-arcmin", "1000"));
    assert_eq!(same, csv.replace("base.csv", "bound.csv"));
    assert_eq!(under(&wide), 2);
    assert_ne!(
        expected(20.0),
        2,
        "the base bound must leave a driver out: {m:?}"
    );
    // Spaced values are the values.
    let spaced = [
        "--param",
        " eye = eyellipse ",
        "--samples",
        " 2 ",
        "--seed",
        " 3",
        "--bound-arcmin",
        "20 ",
    ];
    assert_eq!(sweep("base.csv", &spaced), (csv.clone(), shares.clone()));

    // Refused without eye=eyellipse, and out of range, in one line, writing nothing.
    for (flag, value) in [("--samples", "3"), ("--seed", "2"), ("--bound-arcmin", "5")] {
        common::refusal::refused(
            dir.path(),
            &[
                "sweep", cabin, "--out", "no.csv", "--width", "16", "--param", "d2=3,4", flag,
                value,
            ],
            1,
            &[flag, "eye=eyellipse"],
        );
    }
    for (flag, value, range) in [
        ("--samples", "0", "[1, 10000]"),
        ("--samples", "10001", "[1, 10000]"),
        ("--samples", "1.5", "[1, 10000]"),
        ("--samples", "", "[1, 10000]"),
        ("--seed", "-1", "[0, 4294967295]"),
        ("--seed", "4294967296", "[0, 4294967295]"),
        ("--seed", "x", "[0, 4294967295]"),
        ("--bound-arcmin", "0", "[1e-6, 10800]"),
        ("--bound-arcmin", "10801", "[1e-6, 10800]"),
        ("--bound-arcmin", "nan", "[1e-6, 10800]"),
        ("--bound-arcmin", "-inf", "[1e-6, 10800]"),
    ] {
        let flags = with(&base, flag, value);
        let mut args = vec!["sweep", cabin, "--out", "no.csv", "--width", "16"];
        args.extend(flags);
        common::refusal::refused(dir.path(), &args, 2, &[flag, range, &format!("'{value}'")]);
    }
    assert!(!dir.path().join("no.csv").exists());
    assert!(!dir.path().join("no_drivers.json").exists());
}

/// A capture folder whose specification was edited (a file that is no path, an option out of
/// its range or unknown) is refused by `score` in one line naming the file and the key; the
/// untouched folder scores.
#[test]
fn score_refuses_an_edited_capture_spec_by_file_and_key() {
    let dir = common::refusal::scratch("", &[]);
    let inputs = score_inputs(dir.path());
    let spec_file = dir.path().join(&inputs).join("truth/capture_spec.json");
    let spec: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&spec_file).unwrap()).unwrap();
    let score = |out: &str| {
        run_in(
            dir.path(),
            &["score", &inputs, "--map", "map.npy", "--out", out],
        )
    };
    let (code, err) = score("s");
    assert_eq!(code, 0, "{err}");
    let edited = |edit: &dyn Fn(&mut serde_json::Value)| {
        let mut s = spec.clone();
        edit(&mut s);
        s
    };
    for (spec, words) in [
        (
            edited(&|s| s["scene"] = "scene.toml".into()),
            &[
                "capture_spec.json",
                "scene must be the scene file (an absolute path)",
            ][..],
        ),
        (
            edited(&|s| s["run_options"]["spp"] = 0.into()),
            &["capture_spec.json: capturing again", "spp 0", "[1, 4096]"],
        ),
        (
            edited(&|s| s["run_options"]["colour"] = 1.into()),
            &["capture_spec.json: run_options", "unknown field `colour`"],
        ),
        (
            edited(&|s| {
                s["run_options"].as_object_mut().unwrap().remove("seed");
            }),
            &["capture_spec.json: run_options", "missing field `seed`"],
        ),
    ] {
        std::fs::write(&spec_file, spec.to_string()).unwrap();
        let (code, err) = score("s2");
        assert_ne!(code, 0);
        let err = err.trim_end();
        assert!(
            err.lines().count() == 1 && err.starts_with("error: "),
            "{err}"
        );
        for w in words {
            assert!(err.contains(w), "`{w}` not in {err}");
        }
        assert!(!dir.path().join("s2").exists());
    }
}
