//! Wave 2's inputs held to wave 1's standard: spaces around every choice value are ignored,
//! and every flag of `run`, `sequence` and `compare` either changes the output or is refused
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

const COMMANDS: [&[&str]; 14] = [
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
            &[("--outside", "only a crop past the frontal view differs")],
        ));
    }
    assert!(wrong.is_empty(), "{}", wrong.join("\n"));
}

#[test]
fn every_flag_of_compare_changes_the_output_or_is_refused() {
    // Methods that read no depth: every depth flag is refused, as `run` refuses them.
    let wrong = each_flag_is_read_or_refused(
        &["compare"],
        &["--spp", "1", "--methods", "planar-inf,ground"],
        &[],
        &[("--methods", "the base lists them")],
    );
    assert!(wrong.is_empty(), "{}", wrong.join("\n"));
}
