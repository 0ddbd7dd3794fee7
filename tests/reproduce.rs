//! `reproduce --quick` end to end: the report's numbers, not only its files.

mod common;

use seethru::render::settings::resized;

#[test]
fn quick_reproduction_reports_the_papers_experiments() {
    let dir = tempfile::tempdir().unwrap();
    let report = seethru::paper::reproduce::reproduce(
        &common::repo_path("scenes/das.toml"),
        dir.path(),
        true,
    )
    .unwrap();
    let md = std::fs::read_to_string(dir.path().join("report.md")).unwrap();
    let html = std::fs::read_to_string(dir.path().join("report.html")).unwrap();
    // Four das cases: car close and far, each at θ_F = 30° and 63.5°. Each case's coverage is
    // what ray casting predicts for its display (driver 256 px and frontal 480 px wide, the
    // quick sizes): 30° cannot cover a 1 m display at d1 = 0.75 m, 63.5° can.
    let cases = report["cases"].as_array().unwrap();
    assert_eq!(cases.len(), 4);
    let base = common::das();
    for (case, (distance, theta)) in
        cases
            .iter()
            .zip([(4.0, 30.0), (4.0, 63.5), (15.0, 30.0), (15.0, 63.5)])
    {
        let scene = seethru::paper::reproduce::das_case(&base, distance, 1.0, theta).unwrap();
        let driver = resized(scene.driver, Some(256), None, "--width").unwrap();
        let frontal = resized(scene.frontal, Some(480), None, "--frontal-width").unwrap();
        let (display, covered, ambiguous) =
            common::expected_coverage(&scene, &driver, &frontal, None);
        let expected = covered as f64 / display as f64;
        let coverage = case["metrics"]["coverage"].as_f64().unwrap();
        assert!(
            (coverage - expected).abs() <= (ambiguous + 2) as f64 / display as f64,
            "{}: coverage {coverage} vs {expected} (±{ambiguous} of {display} pixels)",
            case["name"]
        );
        if theta == 30.0 {
            assert!(expected < 0.8, "{expected}");
        } else {
            assert_eq!(coverage, 1.0);
        }
        // The table row carries this case's coverage and mean, marked when not covered.
        let mean = case["metrics"]["display"]["misregistration_arcmin"]["mean"]
            .as_f64()
            .unwrap();
        let row = md
            .lines()
            .find(|l| l.starts_with(&format!("| {} |", case["name"].as_str().unwrap())))
            .unwrap();
        assert!(row.contains(&format!("| {mean:.2} |")), "{row}");
        assert!(row.contains(&format!("{:.1}%", 100.0 * coverage)), "{row}");
        assert_eq!(row.contains('†'), coverage < 1.0, "{row}");
    }
    // Equal coverage: each car's two cases over the pixels both cover (those 30° covers).
    let equal = report["equal_coverage"].as_array().unwrap();
    assert_eq!(equal.len(), 2);
    for (e, pair) in equal.iter().zip([[0, 1], [2, 3]]) {
        let display = cases[pair[0]]["metrics"]["display_pixels"]
            .as_u64()
            .unwrap() as f64;
        let narrow = cases[pair[0]]["metrics"]["coverage"].as_f64().unwrap();
        assert!(
            (e["coverage"].as_f64().unwrap() - narrow).abs() < 1.5 / display,
            "{e}"
        );
        // Over the covered pixels of the 30° case, its mean is its own table mean.
        let own = cases[pair[0]]["metrics"]["display"]["misregistration_arcmin"]["mean"]
            .as_f64()
            .unwrap();
        let at_equal = e["means"][0][1].as_f64().unwrap();
        assert!((at_equal - own).abs() < 1e-6 * own, "{at_equal} vs {own}");
    }
    // The ratios: observed within uncertainty of the closed form, and in the report.
    let ratios = report["ratios"].as_array().unwrap();
    assert_eq!(ratios.len(), 2);
    for r in ratios {
        let r = &r["result"]["ratio"];
        let (pred, obs, unc) = (
            r["predicted"].as_f64().unwrap(),
            r["observed"].as_f64().unwrap(),
            r["uncertainty"].as_f64().unwrap(),
        );
        assert!((pred - obs).abs() <= unc, "{r}");
        assert!(md.contains(&format!("{obs:.4}")) && md.contains(&format!("±{unc:.4}")));
    }
    assert!(md.contains("| -0.73 | -0.71 |") && md.contains("| 2.47 | 2.64 |"));
    // Self-contained HTML: every picture embedded, none referenced.
    // The renders and heatmaps as PNG, the paper's figures as SVG.
    let png = html.matches("data:image/png;base64,").count();
    let svg = html.matches("data:image/svg+xml;base64,").count();
    assert_eq!((png, svg), (4 * 3 + 2 * 2, 4), "embedded images");
    assert!(!html.contains("src=\"car_") && !html.contains("src=\"figures/"));
}

/// `reproduce` outside the repository: without `--scene` it runs the das scene built into the
/// binary and reports the same numbers as the repository's scenes/das.toml; a `--scene` that is
/// missing is named as the flag.
#[test]
fn reproduce_outside_the_repository_uses_the_built_in_das_scene() {
    let empty = tempfile::tempdir().unwrap();
    let seethru = |args: &[&str]| {
        std::process::Command::new(env!("CARGO_BIN_EXE_seethru"))
            .args(args)
            .arg("--quiet")
            .current_dir(empty.path())
            .output()
            .unwrap()
    };
    let built_in = seethru(&["reproduce", "--quick", "--out", "built_in"]);
    assert!(
        built_in.status.success(),
        "{}",
        String::from_utf8_lossy(&built_in.stderr)
    );
    let repo_scene = common::repo_path("scenes/das.toml");
    let from_repo = seethru(&[
        "reproduce",
        "--quick",
        "--out",
        "from_repo",
        "--scene",
        repo_scene.to_str().unwrap(),
    ]);
    assert!(from_repo.status.success());
    let report = |dir: &str| -> serde_json::Value {
        serde_json::from_str(
            &std::fs::read_to_string(empty.path().join(dir).join("report.json")).unwrap(),
        )
        .unwrap()
    };
    let (a, b) = (report("built_in"), report("from_repo"));
    assert!(
        a["scene"].as_str().unwrap().contains("built into seethru"),
        "{}",
        a["scene"]
    );
    let metrics = |r: &serde_json::Value| -> Vec<serde_json::Value> {
        r["cases"]
            .as_array()
            .unwrap()
            .iter()
            .map(|c| c["metrics"].clone())
            .collect()
    };
    assert!(
        metrics(&a) == metrics(&b),
        "the built-in das gives other metrics than the repository's scenes/das.toml"
    );
    // The built-in copy leaves nothing behind in the temporary folder.
    let pid_dirs = std::fs::read_dir(std::env::temp_dir())
        .unwrap()
        .flatten()
        .filter(|e| {
            e.file_name()
                .to_string_lossy()
                .starts_with("seethru-builtin-das-")
        })
        .count();
    assert_eq!(
        pid_dirs, 0,
        "a built-in scene folder was left in the temporary folder"
    );

    let missing = seethru(&["reproduce", "--quick", "--out", "x", "--scene", "nope.toml"]);
    let stderr = String::from_utf8_lossy(&missing.stderr);
    assert!(!missing.status.success());
    assert!(
        stderr.starts_with("error: --scene nope.toml: no such file") && stderr.lines().count() == 1,
        "{stderr}"
    );
    assert!(!empty.path().join("x").exists());
}
