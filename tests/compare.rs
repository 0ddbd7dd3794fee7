//! `seethru compare` and the scene-model methods on the command line: the table, strips and
//! rows as `run` and `measure` give them, and one line per bad input.

mod common;

#[test]
fn bad_method_inputs_give_one_line_each() {
    let dir = tempfile::tempdir().unwrap();
    let wall = dir.path().join("wall.toml");
    std::fs::write(
        &wall,
        common::WallScene::default().text().replace(
            "../assets",
            &common::repo_path("assets").display().to_string(),
        ),
    )
    .unwrap();
    let out = dir.path().join("out");
    let (out, wall) = (out.to_str().unwrap(), wall.to_str().unwrap());
    let small = [
        "--width",
        "32",
        "--frontal-width",
        "64",
        "--back-width",
        "16",
        "--spp",
        "1",
    ];
    let cases: Vec<(Vec<&str>, String)> = vec![
        (
            vec!["run", "scenes/das.toml", "--out", out, "--method", "depth-map"],
            "error: invalid value 'depth-map' for '--method <METHOD>'".into(),
        ),
        (
            vec!["compare", "scenes/das.toml", "--out", out, "--methods", "planar-inf,planar-9"],
            "error: invalid value 'planar-9' for '--methods <METHOD>'".into(),
        ),
        (
            vec!["run", "scenes/das.toml", "--out", out, "--method", "depth", "--depth-sensor", "tof", "--depth-resolution", "0"],
            "error: invalid value '0' for '--depth-resolution <PIXELS>': must be an integer in [1, 16384]".into(),
        ),
        (
            [vec!["run", "scenes/das.toml", "--out", out, "--method", "depth", "--depth-sensor", "tof", "--depth-resolution", "65"], small.to_vec()].concat(),
            "error: --depth-resolution 65 is out of range [1, 64] (the frontal camera's width)".into(),
        ),
        (
            vec!["run", "scenes/das.toml", "--out", out, "--method", "depth", "--depth-sensor", "stereo", "--depth-noise", "-0.01"],
            "error: invalid value '-0.01' for '--depth-noise <METRES>': must be a number in [0, 10]".into(),
        ),
        (
            [vec!["run", "scenes/das.toml", "--out", out, "--method", "depth", "--depth-noise", "0.01"], small.to_vec()].concat(),
            "error: --depth-noise does not apply to --depth-sensor ideal".into(),
        ),
        (
            vec![
                "run",
                "scenes/das.toml",
                "--out",
                out,
                "--method",
                "plane-fit",
                "--display",
                "ideal",
            ],
            "error: --display ideal works with --method none or planar".into(),
        ),
        (
            [vec!["run", wall, "--out", out, "--method", "ground"], small.to_vec()].concat(),
            format!("error: --method ground: the scene {wall} has no ground plane"),
        ),
        (
            [vec!["run", "scenes/das.toml", "--out", out, "--method", "plane-fit", "--calibration", "scenes/calibration/focal_1pct.toml"], small.to_vec()].concat(),
            "error: --method plane-fit: the [calibration.frontal] is not exact".into(),
        ),
        (
            // A bad sensor flag still fails compare whole (only the scene's own limits become
            // a row). The oracle head renders no back view: no --back-width.
            [vec!["compare", wall, "--out", out, "--methods", "planar-inf,depth-tof", "--depth-resolution", "65"], small[..4].to_vec(), small[6..].to_vec()].concat(),
            "error: depth-tof: --depth-resolution 65 is out of range [1, 64]".into(),
        ),
    ];
    for (args, expected) in cases {
        let (ok, _, err) = common::seethru(&args);
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
        assert!(!std::path::Path::new(out).exists(), "{args:?} wrote {out}");
    }
}

#[test]
fn compare_writes_one_row_and_one_strip_per_method_as_run_measures_them() {
    let dir = tempfile::tempdir().unwrap();
    let scene = dir.path().join("scene.toml");
    std::fs::write(&scene, common::MINIMAL).unwrap();
    let out = dir.path().join("cmp");
    let small = [
        "--width",
        "48",
        "--frontal-width",
        "64",
        "--back-width",
        "16",
        "--spp",
        "1",
        "--threads",
        "2",
    ];
    let scene_arg = scene.to_str().unwrap();
    let (ok, table, err) = common::seethru(
        &[
            vec![
                "compare",
                scene_arg,
                "--out",
                out.to_str().unwrap(),
                "--methods",
                "planar-inf,ground,depth-ideal,depth-tof",
            ],
            // The oracle head: compare renders no back view, so no --back-width.
            small[..4].to_vec(),
            small[6..].to_vec(),
        ]
        .concat(),
    );
    assert!(ok, "{err}");
    let json: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("compare.json")).unwrap()).unwrap();
    let rows = json["rows"].as_array().unwrap();
    let names: Vec<&str> = rows.iter().map(|r| r["method"].as_str().unwrap()).collect();
    assert_eq!(names, ["planar-inf", "ground", "depth-ideal", "depth-tof"]);
    let md = std::fs::read_to_string(out.join("compare.md")).unwrap();
    let html = std::fs::read_to_string(out.join("compare.html")).unwrap();
    for name in &names {
        assert!(
            md.contains(&format!("| {name} |")) && table.contains(&format!("| {name} |")),
            "{name}"
        );
        assert!(
            html.contains(&format!("<img src=\"strip_{name}.png\"")),
            "{name}"
        );
        // Four panels of the display's bounding box, three gaps of 4 pixels, the colour bar.
        let strip = image::open(out.join(format!("strip_{name}.png"))).unwrap();
        let bar = seethru::io::colour_bar::BAR_COLUMN;
        assert_eq!((strip.width() - 12 - bar) % 4, 0);
    }
    // The rows are the metrics `run` gives for the same method.
    let run_out = dir.path().join("run");
    let (ok, _, err) = common::seethru(
        &[
            vec![
                "run",
                scene_arg,
                "--out",
                run_out.to_str().unwrap(),
                "--method",
                "depth",
                "--exr",
                "all",
            ],
            small.to_vec(),
        ]
        .concat(),
    );
    assert!(ok, "{err}");
    let metrics: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(run_out.join("metrics.json")).unwrap())
            .unwrap();
    assert_eq!(
        rows[2]["misregistration_mean_arcmin"],
        metrics["display"]["misregistration_arcmin"]["mean"]
    );
    assert_eq!(rows[2]["holes_fraction"], metrics["holes"]["fraction"]);
    // `measure` recomputes the same holes from the run directory's holes.png.
    let (ok, _, err) = common::seethru(&["measure", run_out.to_str().unwrap()]);
    assert!(ok, "{err}");
    let again: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(run_out.join("metrics.json")).unwrap())
            .unwrap();
    assert_eq!(again["holes"], metrics["holes"]);
    // Per-pixel depth beats the d2 → ∞ plane on a scene of a road and a ball 10 m away.
    let mean = |k: usize| rows[k]["misregistration_mean_arcmin"].as_f64().unwrap();
    assert!(mean(2) < mean(0), "{} vs {}", mean(2), mean(0));
}

/// Every method on a scene whose frontal camera has a lens (Brown–Conrady) and no road: each
/// row is there, in order; `ground` says why it cannot run (and has no strip), every other
/// method is measured.
#[test]
fn compare_on_a_lens_scene_lists_every_method_and_says_why_ground_cannot_run() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("cmp");
    let all = "none,planar-inf,planar-auto,plane-fit,ground,depth-ideal,depth-tof,depth-stereo";
    let (ok, table, err) = common::seethru(&[
        "compare",
        "scenes/wall_brown.toml",
        "--out",
        out.to_str().unwrap(),
        "--methods",
        all,
        "--width",
        "48",
        "--frontal-width",
        "160",
        "--spp",
        "1",
    ]);
    assert!(ok, "{err}");
    let json: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("compare.json")).unwrap()).unwrap();
    let rows = json["rows"].as_array().unwrap();
    let names: Vec<&str> = rows.iter().map(|r| r["method"].as_str().unwrap()).collect();
    assert_eq!(names, all.split(',').collect::<Vec<_>>());
    for row in rows {
        let name = row["method"].as_str().unwrap();
        if name == "ground" {
            let reason = row["reason"].as_str().unwrap();
            assert!(reason.contains("has no ground plane"), "{reason}");
            assert!(row["misregistration_mean_arcmin"].is_null());
            assert!(!out.join("strip_ground.png").exists());
            assert!(table.contains("| ground | — |") && table.contains("has no ground plane"));
        } else {
            assert!(row["reason"].is_null(), "{name}: {}", row["reason"]);
            let mean = row["misregistration_mean_arcmin"].as_f64().unwrap();
            assert!(mean.is_finite(), "{name}: {mean}");
            assert!(out.join(format!("strip_{name}.png")).exists(), "{name}");
        }
    }
    // The wall is one plane 6 m away, the lens followed through: the scene-model methods
    // register it to a few arc-minutes (pixels of the 160-wide frontal image are 17′).
    let mean = |k: usize| rows[k]["misregistration_mean_arcmin"].as_f64().unwrap();
    for k in [3, 5] {
        assert!(
            mean(k) < 0.5 * mean(1),
            "{}: {} vs {}",
            names[k],
            mean(k),
            mean(1)
        );
    }
}

/// The lens changes the frontal camera's pixels, not the geometry: `das_fisheye.toml` (the
/// same street through a Kannala–Brandt fisheye) is registered by each scene-model method
/// within 1′ of `das.toml` (a 45° pinhole), the true eye and the ideal depth sensor in both.
/// What is left is the frontal pixels' size (the fisheye's fx is 500 px, the pinhole's 640).
#[test]
fn a_fisheye_frontal_camera_registers_as_the_pinhole_does_with_every_scene_model_method() {
    let dir = tempfile::tempdir().unwrap();
    let mean = |scene: &str, method: &str| {
        let out = dir.path().join(format!("{scene}-{method}"));
        let (ok, _, err) = common::seethru(&[
            "run",
            &format!("scenes/{scene}.toml"),
            "--method",
            method,
            "--head",
            "oracle",
            "--width",
            "160",
            "--spp",
            "1",
            "--quiet",
            "--out",
            out.to_str().unwrap(),
        ]);
        assert!(ok, "{scene} {method}: {err}");
        let metrics: serde_json::Value =
            serde_json::from_str(&std::fs::read_to_string(out.join("metrics.json")).unwrap())
                .unwrap();
        metrics["display"]["misregistration_arcmin"]["mean"]
            .as_f64()
            .unwrap()
    };
    for method in ["depth", "ground", "plane-fit"] {
        let (pinhole, fisheye) = (mean("das", method), mean("das_fisheye", method));
        assert!(
            (fisheye - pinhole).abs() < 1.0,
            "{method}: das_fisheye {fisheye}′ vs das {pinhole}′"
        );
    }
}
