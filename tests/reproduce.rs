//! `reproduce --quick` end to end: the report's numbers, not only its files.

mod common;

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
    // Four das cases; θ_F = 30° with D = 1 m cannot cover the display, 63.5° nearly can.
    let cases = report["cases"].as_array().unwrap();
    assert_eq!(cases.len(), 4);
    let missing = |i: usize| cases[i]["run"]["missing_fraction"].as_f64().unwrap();
    assert!(
        missing(0) > 0.2 && missing(1) < 0.01,
        "{} {}",
        missing(0),
        missing(1)
    );
    for case in cases {
        let mean = case["metrics"]["display"]["misregistration_arcmin"]["mean"]
            .as_f64()
            .unwrap();
        assert!(mean > 1.0 && mean < 600.0, "{mean}");
        // The table row carries this case's number.
        assert!(
            md.contains(&format!("{mean:.2}")),
            "report.md lacks {mean:.2}"
        );
    }
    // The ratios: observed within uncertainty of the closed form, and in the report.
    let ratios = report["ratios"].as_array().unwrap();
    assert_eq!(ratios.len(), 2);
    for r in ratios {
        let r = &r["result"];
        let (pred, obs, unc) = (
            r["ratio_predicted"].as_f64().unwrap(),
            r["ratio_observed"].as_f64().unwrap(),
            r["ratio_uncertainty"].as_f64().unwrap(),
        );
        assert!((pred - obs).abs() <= unc, "{r}");
        assert!(md.contains(&format!("{obs:.4}")) && md.contains(&format!("±{unc:.4}")));
    }
    assert!(md.contains("| -0.73 | -0.71 |") && md.contains("| 2.47 | 2.64 |"));
    // Self-contained HTML: every picture embedded, none referenced.
    let embedded = html.matches("data:image/png;base64,").count();
    assert_eq!(embedded, 4 * 3 + 2 * 2 + 4, "{embedded} embedded images");
    assert!(!html.contains("src=\"car_") && !html.contains("src=\"figures/"));
}
