//! seethru in its users' CI: `diff` of images and run folders with thresholds and exit codes
//! (0 pass, 1 worse, 2 bad input), `check` of expectation files with JUnit reports and
//! `--bless`, and the example expectations of examples/ci/.

mod common;

use std::path::Path;
use std::process::Command;

use exr::prelude::{AnyChannel, FlatSamples};
use seethru::io::frame_files::write_exr_channels;

/// Runs seethru in `dir` without `CI` in its environment unless `ci` is given: (exit code,
/// stdout, stderr).
fn seethru_ci(dir: &Path, args: &[&str], ci: Option<&str>) -> (i32, String, String) {
    let mut command = Command::new(env!("CARGO_BIN_EXE_seethru"));
    command.args(args).current_dir(dir).env_remove("CI");
    if let Some(v) = ci {
        command.env("CI", v);
    }
    let out = command.output().unwrap();
    (
        out.status.code().unwrap_or(-1),
        String::from_utf8_lossy(&out.stdout).into(),
        String::from_utf8_lossy(&out.stderr).into(),
    )
}

fn run(dir: &Path, args: &[&str]) -> (i32, String, String) {
    seethru_ci(dir, args, None)
}

/// A 32×24 image with texture (so that FLIP and SSIM see structure).
fn pattern() -> image::RgbImage {
    image::RgbImage::from_fn(32, 24, |x, y| {
        image::Rgb([
            (x * 8) as u8,
            (y * 10) as u8,
            ((x * 37 + y * 91) % 256) as u8,
        ])
    })
}

fn json(stdout: &str) -> serde_json::Value {
    serde_json::from_str(stdout).unwrap_or_else(|e| panic!("{e}: {stdout}"))
}

fn assert_one_error_line(err: &str, words: &[&str]) {
    let err = err.trim_end();
    assert_eq!(err.lines().count(), 1, "{err}");
    assert!(err.starts_with("error: "), "{err}");
    for w in words {
        assert!(err.contains(w), "`{w}` not in: {err}");
    }
}

#[test]
fn identical_images_differ_by_nothing_and_pass() {
    let dir = tempfile::tempdir().unwrap();
    pattern().save(dir.path().join("a.png")).unwrap();
    pattern().save(dir.path().join("b.png")).unwrap();
    let (code, out, err) = run(
        dir.path(),
        &[
            "diff",
            "a.png",
            "b.png",
            "--json",
            "--max",
            "flip_max=0",
            "--min",
            "ssim=1",
        ],
    );
    assert_eq!(code, 0, "{err}");
    let report = json(&out);
    let colour = &report["layers"]["colour"];
    assert_eq!(colour["flip_mean"], 0.0);
    assert_eq!(colour["flip_max"], 0.0);
    assert_eq!(colour["psnr_db"], "inf");
    assert_eq!(colour["differing_pixels"], 0.0);
    assert_eq!(colour["flip_pixels_per_degree"], 67.0);
    assert_eq!(report["pass"], true);
}

#[test]
fn a_one_pixel_change_fails_a_tight_bound_and_passes_a_loose_one() {
    let dir = tempfile::tempdir().unwrap();
    let a = pattern();
    let mut b = a.clone();
    let before = b.get_pixel(10, 7).0;
    b.put_pixel(
        10,
        7,
        image::Rgb([before[0], before[1].wrapping_add(100), before[2]]),
    );
    a.save(dir.path().join("a.png")).unwrap();
    b.save(dir.path().join("b.png")).unwrap();
    let change = (before[1].wrapping_add(100) as f64 - before[1] as f64).abs();
    let (code, out, err) = run(
        dir.path(),
        &["diff", "a.png", "b.png", "--json", "--max", "flip_max=0.01"],
    );
    assert_eq!(code, 1, "{err}");
    assert!(
        err.starts_with("FAIL: ") && err.contains("flip_max <= 0.01"),
        "{err}"
    );
    let colour = &json(&out)["layers"]["colour"];
    assert_eq!(colour["differing_pixels"], 1.0);
    assert_eq!(colour["max_abs_error"], change);
    // One channel of one pixel of 32×24×3 values.
    let mean = colour["mean_abs_error"].as_f64().unwrap();
    assert!(
        (mean - change / (32.0 * 24.0 * 3.0)).abs() < 1e-12,
        "{mean}"
    );
    let flip_max = colour["flip_max"].as_f64().unwrap();
    assert!(flip_max > 0.01, "{flip_max}");
    // A bound the change meets passes, and the heatmap is written with its colour bar.
    let (code, out, err) = run(
        dir.path(),
        &[
            "diff",
            "a.png",
            "b.png",
            "--max",
            "flip_mean=0.5",
            "--min",
            "psnr_db=20",
            "--out",
            "heat",
        ],
    );
    assert_eq!(code, 0, "{err}");
    assert!(out.contains("PASS flip_mean <= 0.5"), "{out}");
    // A lower bound above the measured PSNR fails.
    let (code, _, err) = run(
        dir.path(),
        &["diff", "a.png", "b.png", "--min", "psnr_db=200"],
    );
    assert_eq!(code, 1, "{err}");
    assert!(err.contains("psnr_db >= 200"), "{err}");
    let heat = image::open(dir.path().join("heat/flip_colour.png")).unwrap();
    assert!(heat.width() > 32 + 100, "{}", heat.width());
}

fn exr(path: &Path, z: Vec<f32>, with_z: bool) {
    let n = z.len();
    let mut channels = vec![
        AnyChannel::new("R", FlatSamples::F32(vec![0.25; n])),
        AnyChannel::new("G", FlatSamples::F32(vec![0.5; n])),
        AnyChannel::new("B", FlatSamples::F32(vec![0.75; n])),
    ];
    if with_z {
        channels.push(AnyChannel::new("Z", FlatSamples::F32(z)));
    }
    write_exr_channels(path, 4, 2, channels).unwrap();
}

#[test]
fn exr_layers_are_compared_one_by_one_and_a_missing_layer_is_refused() {
    let dir = tempfile::tempdir().unwrap();
    let inf = f32::INFINITY;
    exr(
        &dir.path().join("a.exr"),
        vec![1.0, 2.0, inf, inf, 5.0, 6.0, 7.0, 8.0],
        true,
    );
    exr(
        &dir.path().join("b.exr"),
        vec![1.0, 2.5, inf, 4.0, 5.0, 6.0, 7.0, 9.0],
        true,
    );
    exr(&dir.path().join("c.exr"), vec![0.0; 8], false);
    let (code, out, err) = run(dir.path(), &["diff", "a.exr", "b.exr", "--json"]);
    assert_eq!(code, 0, "{err}");
    let report = json(&out);
    let z = &report["layers"]["Z"];
    assert_eq!(z["max_abs_error"], 1.0);
    // |0.5| + |1| over the 7 pixels finite in both (the sky pixel equal, one mismatched).
    assert_eq!(z["mean_abs_error"], 1.5 / 6.0);
    assert_eq!(z["nonfinite_mismatch_pixels"], 1.0);
    assert_eq!(z["differing_pixels"], 3.0);
    assert!(z.get("flip_mean").is_none());
    assert_eq!(report["layers"]["colour"]["flip_max"], 0.0);
    // A threshold on one layer.
    let (code, _, err) = run(
        dir.path(),
        &["diff", "a.exr", "b.exr", "--max", "Z.max_abs_error=0.9"],
    );
    assert_eq!(code, 1, "{err}");
    let (code, _, err) = run(dir.path(), &["diff", "a.exr", "c.exr"]);
    assert_eq!(code, 2);
    assert_one_error_line(&err, &["c.exr has no layer `Z`", "a.exr has it"]);
    // The same the other way round: the second file's extra layer is missing in the first.
    let (code, _, err) = run(dir.path(), &["diff", "c.exr", "a.exr"]);
    assert_eq!(code, 2);
    assert_one_error_line(&err, &["c.exr has no layer `Z`", "a.exr has it"]);
    let (code, _, err) = run(dir.path(), &["diff", "a.exr", "b.exr", "--layer", "P"]);
    assert_eq!(code, 2);
    assert_one_error_line(&err, &["no layer `P`", "colour, Z"]);
}

#[test]
fn bad_inputs_exit_2_with_one_line_each() {
    let dir = tempfile::tempdir().unwrap();
    pattern().save(dir.path().join("a.png")).unwrap();
    image::RgbImage::new(31, 24)
        .save(dir.path().join("small.png"))
        .unwrap();
    std::fs::write(dir.path().join("text.png"), "not a png").unwrap();
    let cases: [(&[&str], &[&str]); 6] = [
        (
            &["diff", "a.png", "small.png"],
            &["32×24", "31×24", "different sizes"],
        ),
        (
            &["diff", "a.png", "none.png"],
            &["none.png", "no such file"],
        ),
        (&["diff", "a.png", "text.png"], &["text.png"]),
        (
            &["diff", "a.png", "."],
            &["a folder", "two images or two run folders"],
        ),
        (
            &["diff", "a.png", "a.png", "--max", "flop_mean=1"],
            &["--max", "unknown metric `flop_mean`", "flip_mean"],
        ),
        (
            &["diff", "a.png", "a.png", "--max", "Z.flip_mean=1"],
            &["no layer `Z` was compared"],
        ),
    ];
    for (args, words) in cases {
        let (code, out, err) = run(dir.path(), args);
        assert_eq!(code, 2, "{args:?}: {err}");
        assert!(out.is_empty(), "{args:?}: {out}");
        assert_one_error_line(&err, words);
    }
    // Other commands keep exit 1 for their errors.
    let (code, _, _) = run(dir.path(), &["render", "none.toml", "--out", "x"]);
    assert_eq!(code, 1);
}

/// Each flag of `diff` and `check`, given a value outside its range or form, is refused
/// before any work, in one line naming the flag (or the file) and what it accepts.
#[test]
fn each_flag_of_diff_and_check_refuses_a_bad_value_in_one_line() {
    let dir = tempfile::tempdir().unwrap();
    pattern().save(dir.path().join("a.png")).unwrap();
    let scene = common::repo_path("scenes/das.toml");
    std::fs::write(
        dir.path().join("e.toml"),
        format!(
            "[[case]]\nname = \"a\"\nscene = {:?}\ncommand = \"run\"\noptions = [\"--width\", \"8\"]\nexpect = [\"coverage >= 0\"]\n",
            scene.to_str().unwrap()
        ),
    )
    .unwrap();
    let diff = ["diff", "a.png", "a.png"];
    let cases: Vec<(Vec<&str>, &[&str])> = vec![
        (vec!["--ppd", "0"], &["--ppd", "[1, 1000]"]),
        (vec!["--ppd", "1001"], &["--ppd", "[1, 1000]"]),
        (vec!["--ppd", "nan"], &["--ppd", "[1, 1000]"]),
        (vec!["--max", "flip_mean"], &["--max", "NAME=VALUE"]),
        (
            vec!["--max", "flip_mean=x"],
            &["--max", "not a finite number"],
        ),
        (
            vec!["--min", "psnr_db=inf"],
            &["--min", "not a finite number"],
        ),
        (vec!["--min", "=1"], &["--min", "unknown metric", "psnr_db"]),
        (vec!["--layer", "nope"], &["no layer `nope`", "colour"]),
        (
            vec!["--tolerance", "coverage=-1"],
            &["--tolerance", "[0, 1000000000]"],
        ),
        (
            vec!["--tolerance", "x=1"],
            &["--tolerance", "unknown metric `x`"],
        ),
        (vec!["--out", "a.png"], &["--out a.png"]),
    ];
    for (flags, words) in cases {
        let args: Vec<&str> = diff.iter().copied().chain(flags).collect();
        let (code, out, err) = run(dir.path(), &args);
        assert_eq!(code, 2, "{args:?}: {err}");
        assert!(out.is_empty(), "{args:?}: {out}");
        assert_one_error_line(&err, words);
    }
    let check: [(&[&str], &[&str]); 4] = [
        (
            &["check", "e.toml", "--case", "nope"],
            &["--case nope", "cases: a"],
        ),
        (
            &["check", "e.toml", "--junit", "e.toml"],
            &["--junit e.toml", "input"],
        ),
        (&["check", "e.toml", "--out", "e.toml"], &["--out e.toml"]),
        (&["check", "none.toml"], &["none.toml"]),
    ];
    for (args, words) in check {
        let (code, _, err) = run(dir.path(), args);
        assert_eq!(code, 2, "{args:?}: {err}");
        assert_one_error_line(&err, words);
    }
    // Nothing ran: no case folder, no report.
    assert!(!dir.path().join("seethru-check").exists());
}

/// The mean misregistration of das at the test's size, from a `seethru run`.
fn measured_das(dir: &Path) -> serde_json::Value {
    let scene = common::repo_path("scenes/das.toml");
    let (code, _, err) = run(
        dir,
        &[
            "run",
            scene.to_str().unwrap(),
            "--out",
            "measured",
            "--width",
            "96",
        ],
    );
    assert_eq!(code, 0, "{err}");
    // The summary line gives the headline metrics.
    assert!(
        err.contains("misregistration mean ") && err.contains("coverage "),
        "{err}"
    );
    json(&std::fs::read_to_string(dir.join("measured/metrics.json")).unwrap())
}

fn case(name: &str, expect: &[String], golden: Option<&str>) -> String {
    let scene = common::repo_path("scenes/das.toml");
    let expect: Vec<String> = expect.iter().map(|e| format!("  \"{e}\",")).collect();
    format!(
        "[[case]]\nname = \"{name}\"\nscene = \"{}\"\noptions = [\"--width\", \"96\"]\n{}expect = [\n{}\n]\n\n",
        scene.display(),
        golden.map_or(String::new(), |g| format!("golden = \"{g}\"\n")),
        expect.join("\n")
    )
}

#[test]
fn a_bound_below_the_measured_mean_fails_one_above_passes_and_junit_says_so() {
    let dir = tempfile::tempdir().unwrap();
    let metrics = measured_das(dir.path());
    let mean = metrics["display"]["misregistration_arcmin"]["mean"]
        .as_f64()
        .unwrap();
    let above = format!("misregistration.mean <= {}", mean + 1.0);
    let below = format!("misregistration.mean <= {}", mean - 1.0);
    let text = case("above", std::slice::from_ref(&above), None)
        + &case("below", &[below.clone(), "coverage >= 0".into()], None);
    std::fs::write(dir.path().join("both.toml"), text).unwrap();
    let (code, out, err) = run(
        dir.path(),
        &["check", "both.toml", "--junit", "report.xml", "--out", "c"],
    );
    assert_eq!(code, 1, "{out}{err}");
    let row = |name: &str, bound: &str| {
        out.lines()
            .find(|l| l.starts_with(name) && l.contains(bound))
            .unwrap_or_else(|| panic!("no row {name} {bound} in {out}"))
            .to_string()
    };
    assert!(row("above", &above).ends_with("PASS"), "{out}");
    assert!(row("below", &below).ends_with("FAIL"), "{out}");
    assert!(row("below", "coverage >= 0").ends_with("PASS"), "{out}");
    assert!(
        err.contains("1 of 2 cases failed") && err.contains("below"),
        "{err}"
    );
    // The JUnit report: one suite of two cases, one failure naming the bound.
    let xml = std::fs::read_to_string(dir.path().join("report.xml")).unwrap();
    let doc = roxmltree::Document::parse(&xml).unwrap();
    let root = doc.root_element();
    assert_eq!(root.tag_name().name(), "testsuites");
    let suites: Vec<_> = root
        .children()
        .filter(|n| n.has_tag_name("testsuite"))
        .collect();
    assert_eq!(suites.len(), 1);
    let suite = suites[0];
    assert_eq!(suite.attribute("tests"), Some("2"));
    assert_eq!(suite.attribute("failures"), Some("1"));
    assert_eq!(suite.attribute("errors"), Some("0"));
    let cases: Vec<_> = suite
        .children()
        .filter(|n| n.has_tag_name("testcase"))
        .collect();
    assert_eq!(cases.len(), 2);
    let failures = |c: &roxmltree::Node| c.children().filter(|n| n.has_tag_name("failure")).count();
    assert_eq!(cases[0].attribute("name"), Some("above"));
    assert_eq!(failures(&cases[0]), 0);
    assert_eq!(cases[1].attribute("name"), Some("below"));
    assert_eq!(failures(&cases[1]), 1);
    let failure = cases[1]
        .children()
        .find(|n| n.has_tag_name("failure"))
        .unwrap();
    assert!(
        failure.attribute("message").unwrap().contains(&below),
        "{xml}"
    );
    // The passing case alone passes.
    std::fs::write(dir.path().join("pass.toml"), case("above", &[above], None)).unwrap();
    let (code, out, err) = run(dir.path(), &["check", "pass.toml", "--out", "c"]);
    assert_eq!(code, 0, "{out}{err}");
}

#[test]
fn bless_is_refused_in_ci_and_writes_only_goldens_and_recorded_values_elsewhere() {
    let dir = tempfile::tempdir().unwrap();
    let text = format!(
        "# recorded values are rewritten in place; this comment stays\n{}",
        case(
            "golden",
            &[
                "flip_mean_vs_golden <= 0".into(),
                "misregistration.p95 == 0 +- 0.001".into(),
                "coverage >= 0.5".into(),
            ],
            Some("golden/das.png"),
        )
    );
    std::fs::write(dir.path().join("e.toml"), &text).unwrap();
    // No golden yet: the case cannot run, and says how to make it.
    let (code, out, err) = run(dir.path(), &["check", "e.toml", "--out", "c"]);
    assert_eq!(code, 2, "{out}{err}");
    assert!(
        err.contains("does not exist") && err.contains("--bless"),
        "{err}"
    );
    // CI=true: refused before anything runs; nothing written.
    let (code, _, err) = seethru_ci(dir.path(), &["check", "e.toml", "--bless"], Some("true"));
    assert_eq!(code, 2);
    assert_one_error_line(&err, &["--bless is refused", "CI"]);
    assert!(!dir.path().join("golden").exists());
    assert_eq!(
        std::fs::read_to_string(dir.path().join("e.toml")).unwrap(),
        text
    );
    // Elsewhere: the golden and the recorded p95 are written, and listed.
    let (code, out, err) = run(dir.path(), &["check", "e.toml", "--bless", "--out", "c"]);
    assert_eq!(code, 0, "{out}{err}");
    assert!(err.contains("blessed golden/das.png"), "{err}");
    assert!(
        err.contains("e.toml:") && err.contains("misregistration.p95 =="),
        "{err}"
    );
    let metrics: serde_json::Value =
        json(&std::fs::read_to_string(dir.path().join("c/golden/metrics.json")).unwrap());
    let p95 = metrics["display"]["misregistration_arcmin"]["p95"]
        .as_f64()
        .unwrap();
    let blessed = std::fs::read_to_string(dir.path().join("e.toml")).unwrap();
    assert!(blessed.starts_with("# recorded values are rewritten in place"));
    assert!(blessed.contains("\"coverage >= 0.5\""), "{blessed}");
    let recorded: f64 = blessed
        .lines()
        .find_map(|l| l.trim().strip_prefix("\"misregistration.p95 == "))
        .and_then(|rest| rest.split_whitespace().next())
        .unwrap()
        .parse()
        .unwrap();
    assert!((recorded - p95).abs() < 1e-5, "{recorded} vs {p95}");
    // Blessed: the check passes (the run is deterministic: FLIP 0 against its golden).
    let (code, out, err) = run(dir.path(), &["check", "e.toml", "--out", "c"]);
    assert_eq!(code, 0, "{out}{err}");
}

#[test]
fn bad_expectation_files_name_the_file_and_line() {
    let dir = tempfile::tempdir().unwrap();
    let good = case("c", &["coverage >= 0.5".into()], None);
    let line_of =
        |text: &str, needle: &str| text.lines().position(|l| l.contains(needle)).unwrap() + 1;
    let cases = [
        (
            good.replace(
                "coverage >= 0.5",
                "coverage >= 0.5\",\n  \"misregistration.avg <= 3",
            ),
            "misregistration.avg",
            vec![
                "unknown metric `misregistration.avg`",
                "misregistration.mean",
            ],
        ),
        (
            good.replace("options =", "colour = 1\noptions ="),
            "colour = 1",
            vec!["unknown key", "colour"],
        ),
        (
            good.replace("coverage >= 0.5", "coverage > 0.5"),
            "coverage > 0.5",
            vec!["`>` is not a comparison"],
        ),
        (
            good.replace("\"96\"", "\"0\""),
            "options",
            vec!["--width", "[1, 16384]"],
        ),
        (
            good.replace("coverage >= 0.5", "flip_mean_vs_golden <= 0.1"),
            "flip_mean_vs_golden",
            vec!["needs `golden"],
        ),
    ];
    for (text, needle, words) in cases {
        std::fs::write(dir.path().join("bad.toml"), &text).unwrap();
        let (code, out, err) = run(dir.path(), &["check", "bad.toml", "--out", "c"]);
        assert_eq!(code, 2, "{text}: {err}");
        assert!(out.is_empty(), "{out}");
        let at = format!("bad.toml:{}:", line_of(&text, needle));
        let mut words: Vec<&str> = words;
        words.push(&at);
        assert_one_error_line(&err, &words);
        assert!(!dir.path().join("c").exists(), "nothing ran");
    }
}

#[test]
fn the_example_expectations_pass_on_das() {
    let dir = tempfile::tempdir().unwrap();
    let file = common::repo_path("examples/ci/expectations.toml");
    let (code, out, err) = run(
        dir.path(),
        &[
            "check",
            file.to_str().unwrap(),
            "--out",
            "c",
            "--junit",
            "j.xml",
        ],
    );
    assert_eq!(code, 0, "{out}{err}");
    assert!(!out.contains("FAIL"), "{out}");
    let xml = std::fs::read_to_string(dir.path().join("j.xml")).unwrap();
    let doc = roxmltree::Document::parse(&xml).unwrap();
    assert_eq!(doc.root_element().attribute("failures"), Some("0"));
}

#[test]
fn two_run_folders_diff_their_views_and_their_metrics_with_tolerances() {
    let dir = tempfile::tempdir().unwrap();
    let scene = common::repo_path("scenes/das.toml");
    let scene = scene.to_str().unwrap();
    for (out, extra) in [("a", None), ("b", Some("--head-bias-cm=2,0,0"))] {
        let mut args = vec!["run", scene, "--out", out, "--width", "96"];
        args.extend(extra);
        let (code, _, err) = run(dir.path(), &args);
        assert_eq!(code, 0, "{err}");
    }
    let mean = |run: &str| {
        let m = json(&std::fs::read_to_string(dir.path().join(run).join("metrics.json")).unwrap());
        m["display"]["misregistration_arcmin"]["mean"]
            .as_f64()
            .unwrap()
    };
    // The same run: every view and metric equal; heatmaps of views of different sizes.
    let (code, _, err) = run(dir.path(), &["diff", "a", "a", "--out", "same"]);
    assert_eq!(code, 0, "{err}");
    for view in ["truth", "seethru", "frontal", "back"] {
        assert!(
            dir.path().join(format!("same/flip_{view}.png")).is_file(),
            "{view}"
        );
    }
    // A biased head tracker: the truth is the same, seethru and its metrics are not.
    let (code, out, err) = run(dir.path(), &["diff", "a", "b", "--json"]);
    assert_eq!(code, 1, "{err}");
    let report = json(&out);
    assert_eq!(report["layers"]["truth"]["differing_pixels"], 0.0);
    assert!(
        report["layers"]["seethru"]["differing_pixels"]
            .as_f64()
            .unwrap()
            > 0.0
    );
    let change = report["metrics"]
        .as_array()
        .unwrap()
        .iter()
        .find(|m| m["metric"] == "misregistration.mean")
        .unwrap()
        .clone();
    assert_eq!(change["a"].as_f64().unwrap(), mean("a"));
    assert_eq!(change["b"].as_f64().unwrap(), mean("b"));
    assert_eq!(change["pass"], false);
    assert!(err.contains("misregistration.mean moved"), "{err}");
    // The other way round, the metric moves the other way: it fails as well (a comparison
    // without its `abs` would pass one direction).
    let (code, _, err) = run(dir.path(), &["diff", "b", "a"]);
    assert_eq!(code, 1, "{err}");
    assert!(err.contains("misregistration.mean moved"), "{err}");
    // Tolerances wide enough for the change pass (the images are not bounded here).
    let moved = (mean("a") - mean("b")).abs();
    let mut args: Vec<String> = ["diff", "a", "b"].map(String::from).to_vec();
    for name in [
        "misregistration.mean",
        "misregistration.p95",
        "misregistration.max",
        "coverage",
        "missing.fraction",
        "border.misregistration.mean",
        "border.misregistration.p95",
        "psnr_db",
        "ssim",
        "flip_mean",
    ] {
        let tolerance = if name == "misregistration.mean" {
            moved * 1.001
        } else {
            1e6
        };
        args.extend(["--tolerance".into(), format!("{name}={tolerance}")]);
    }
    let args: Vec<&str> = args.iter().map(String::as_str).collect();
    let (code, _, err) = run(dir.path(), &args);
    assert_eq!(code, 0, "{err}");
    let (code, _, err) = run(
        dir.path(),
        &["diff", "a", "b", "--tolerance", "coverage.min=1"],
    );
    assert_eq!(code, 2);
    assert_one_error_line(&err, &["--tolerance coverage.min", "misregistration.mean"]);
}

#[test]
fn each_bound_passes_on_its_side_and_fails_on_the_other_and_a_case_is_held_to_its_commands_rules() {
    let dir = tempfile::tempdir().unwrap();
    let metrics = measured_das(dir.path());
    let mean = metrics["display"]["misregistration_arcmin"]["mean"]
        .as_f64()
        .unwrap();
    // (bound, passes): each relation on both sides of the measured mean, the recorded one
    // far above and far below its tolerance (a comparison without its `abs` passed the
    // value below).
    let bounds = [
        (format!("misregistration.mean <= {}", mean + 1.0), true),
        (format!("misregistration.mean <= {}", mean - 1.0), false),
        (format!("misregistration.mean >= {}", mean - 1.0), true),
        (format!("misregistration.mean >= {}", mean + 1.0), false),
        (
            format!("misregistration.mean == {} +- 0.5", mean + 0.25),
            true,
        ),
        (
            format!("misregistration.mean == {} +- 0.5", mean - 0.25),
            true,
        ),
        (
            format!("misregistration.mean == {} +- 0.5", mean + 10.0),
            false,
        ),
        (
            format!("misregistration.mean == {} +- 0.5", mean - 10.0),
            false,
        ),
    ];
    for (k, (bound, passes)) in bounds.iter().enumerate() {
        let file = format!("b{k}.toml");
        std::fs::write(
            dir.path().join(&file),
            case("das", std::slice::from_ref(bound), None),
        )
        .unwrap();
        let (code, out, err) = run(dir.path(), &["check", &file, "--out", "c"]);
        let verdict = if *passes { "PASS" } else { "FAIL" };
        assert_eq!(code, if *passes { 0 } else { 1 }, "{bound}: {out}{err}");
        assert!(
            out.lines()
                .any(|l| l.contains(bound.as_str()) && l.ends_with(verdict)),
            "{bound} should {verdict}: {out}"
        );
    }
    // A case whose options its command refuses on its own (`--fill` without a depth method)
    // could not run: it does not pass.
    let text = case("fill", &["coverage >= 0".into()], None).replace(
        "options = [\"--width\", \"96\"]",
        "options = [\"--width\", \"96\", \"--fill\", \"inpaint\"]",
    );
    std::fs::write(dir.path().join("fill.toml"), text).unwrap();
    let (code, out, err) = run(dir.path(), &["check", "fill.toml", "--out", "c"]);
    assert_eq!(code, 2, "{out}{err}");
    assert_one_error_line(&err, &["case fill", "--fill", "--method depth"]);
}
