//! Sweeps: one row per configuration, deterministic, resumed without recomputing.

mod common;

use common::refusal::{refused, run_in, scratch};
use seethru::measure::{
    sweep::{SweepOptions, merge_parts, sweep},
    sweep_grid::parse_param,
    sweep_shard::Shard,
};
use seethru::render::settings::resized;
use seethru::scene::Scene;
use seethru::system::options::HeadSource;

/// A sweep of the minimal scene in `dir`, as the command line runs it; panics on failure.
fn sweep_in(dir: &std::path::Path, args: &[&str]) -> String {
    let mut all = vec!["sweep", "scene.toml", "--width", "16"];
    all.extend_from_slice(args);
    let (code, err) = run_in(dir, &all);
    assert_eq!(code, 0, "{all:?}: {err}");
    err
}

#[test]
fn resume_refuses_rows_computed_with_other_settings_or_another_scene() {
    // The audit's case: a CSV made at one width (or spp, band, head, scene) and resumed with
    // another printed `computed 0 configurations` and kept the old rows as the new sweep's.
    let dir = scratch("", &[]);
    let grid = [
        "--param",
        "theta_f=30,40",
        "--param",
        "d2=2,5",
        "--out",
        "s.csv",
    ];
    sweep_in(dir.path(), &grid);
    let csv = dir.path().join("s.csv");
    let before = std::fs::read_to_string(&csv).unwrap();
    for (flag, value, was) in [
        ("--width", "24", "16"),
        ("--spp", "2", "1"),
        ("--band", "9", "5"),
        ("--head", "estimated", "oracle"),
    ] {
        let mut args = vec!["sweep", "scene.toml"];
        if flag != "--width" {
            args.extend_from_slice(&["--width", "16"]);
        }
        args.extend_from_slice(&[flag, value]);
        args.extend_from_slice(&grid);
        let words = format!("s.csv:2: computed with {flag} {was}, this sweep has {flag} {value}");
        refused(dir.path(), &args, 1, &[&words]);
        assert_eq!(std::fs::read_to_string(&csv).unwrap(), before, "{flag}");
    }
    // Another scene: the same file with the ball moved; the same scene from another folder
    // (a copy of the file elsewhere) resumes.
    let scene = std::fs::read_to_string(dir.path().join("scene.toml")).unwrap();
    std::fs::create_dir(dir.path().join("copy")).unwrap();
    std::fs::write(dir.path().join("copy/scene.toml"), &scene).unwrap();
    let mut args = vec!["sweep", "copy/scene.toml", "--width", "16"];
    args.extend_from_slice(&grid);
    let (code, err) = run_in(dir.path(), &args);
    assert_eq!(code, 0, "{err}");
    assert_eq!(std::fs::read_to_string(&csv).unwrap(), before);
    let moved = scene.replace(
        "translate = [0.0, 1.0, -10.0]",
        "translate = [0.5, 1.0, -10.0]",
    );
    assert_ne!(moved, scene);
    std::fs::write(dir.path().join("copy/scene.toml"), moved).unwrap();
    refused(
        dir.path(),
        &args,
        1,
        &["s.csv:2: computed with scene_hash ", "another scene"],
    );
    assert_eq!(std::fs::read_to_string(&csv).unwrap(), before);
}

#[test]
fn resume_refuses_impossible_cells_and_keeps_undefined_metrics() {
    let dir = scratch("", &[]);
    // A display of 1e-6 m covers no driver pixel: its metrics are undefined, written NaN.
    let grid = ["--param", "display_width=1e-6,0.3", "--out", "s.csv"];
    sweep_in(dir.path(), &grid);
    let csv = dir.path().join("s.csv");
    let good = std::fs::read_to_string(&csv).unwrap();
    let lines: Vec<&str> = good.lines().collect();
    assert!(lines[1].contains(",NaN,"), "{}", lines[1]);
    let err = sweep_in(dir.path(), &grid);
    assert!(err.is_empty(), "{err}");
    assert_eq!(std::fs::read_to_string(&csv).unwrap(), good);
    let header: Vec<&str> = lines[0].split(',').collect();
    for (column, cell, range) in [
        ("misregistration_mean_arcmin", "-1", "[0, 10800]"),
        ("misregistration_mean_arcmin", "inf", "[0, 10800]"),
        ("psnr_db", "1e300", "[0, 200]"),
        ("coverage", "-1", "[0, 1]"),
        ("coverage", "1e300", "[0, 1]"),
        ("missing_fraction", "x", "[0, 1]"),
        ("R1", "inf", "a finite number"),
    ] {
        let at = header.iter().position(|c| *c == column).unwrap();
        let mut row: Vec<&str> = lines[2].split(',').collect();
        row[at] = cell;
        let text = format!("{}\n{}\n{}\n", lines[0], lines[1], row.join(","));
        std::fs::write(&csv, &text).unwrap();
        let mut args = vec!["sweep", "scene.toml", "--width", "16"];
        args.extend_from_slice(&grid);
        refused(
            dir.path(),
            &args,
            1,
            &["s.csv:3: ", column, range, "delete the row"],
        );
        assert_eq!(std::fs::read_to_string(&csv).unwrap(), text);
    }
}

#[test]
fn resume_refuses_to_drop_rows_and_keeps_them_in_a_grown_grid() {
    let dir = scratch("", &[]);
    sweep_in(
        dir.path(),
        &[
            "--param",
            "theta_f=30,40",
            "--param",
            "d2=2,5",
            "--out",
            "s.csv",
        ],
    );
    let csv = dir.path().join("s.csv");
    let before = std::fs::read_to_string(&csv).unwrap();
    // Fewer values: the rows of θ_F = 40 would be lost.
    let args = [
        "sweep",
        "scene.toml",
        "--width",
        "16",
        "--param",
        "theta_f=30",
        "--param",
        "d2=2,5",
        "--out",
        "s.csv",
    ];
    refused(
        dir.path(),
        &args,
        1,
        &[
            "s.csv: 2 of its 4 rows are outside this sweep's grid",
            "theta_f=40, d2=2",
            "another --out",
        ],
    );
    assert_eq!(std::fs::read_to_string(&csv).unwrap(), before);
    // More values: the four rows move to their places; only θ_F = 35 is computed, and the
    // CSV is what a fresh run of the grown grid writes.
    let grown = ["--param", "theta_f=30,35,40", "--param", "d2=2,5"];
    let err = sweep_in(dir.path(), &[&grown[..], &["--out", "s.csv"]].concat());
    assert!(err.is_empty(), "{err}");
    sweep_in(dir.path(), &[&grown[..], &["--out", "fresh.csv"]].concat());
    let resumed = std::fs::read_to_string(&csv).unwrap();
    assert_eq!(
        resumed,
        std::fs::read_to_string(dir.path().join("fresh.csv")).unwrap()
    );
    assert_eq!(resumed.lines().count(), 7);
    // The kept rows are the old ones, with their new index and grid size.
    let old_row_40_5 = before.lines().nth(4).unwrap();
    assert!(old_row_40_5.starts_with("3,40,5,"), "{old_row_40_5}");
    let new_row = old_row_40_5
        .replacen("3,", "5,", 1)
        .replacen(",4,16,", ",6,16,", 1);
    assert_eq!(resumed.lines().nth(6).unwrap(), new_row);
}

#[test]
fn merging_counts_the_grid_the_parts_were_cut_from_and_refuses_mixed_settings() {
    // theta_f = 40, 60, 80 × d2 = inf, 6 in two parts: part 0 holds every d2 = 6 row, part 1
    // every d2 = inf row. Merged alone, part 0 was said to hold "3 of the grid's 3".
    let dir = scratch("", &[]);
    let grid = ["--param", "theta_f=40:80:20", "--param", "d2=inf,6"];
    for k in 0..2 {
        let shard = format!("{k}/2");
        let out = format!("p{k}.csv");
        sweep_in(
            dir.path(),
            &[&grid[..], &["--shard", &shard, "--out", &out]].concat(),
        );
    }
    let p0 = std::fs::read_to_string(dir.path().join("p0.csv")).unwrap();
    assert!(
        p0.lines().skip(1).all(|l| l.split(',').nth(2) == Some("6")),
        "{p0}"
    );
    refused(
        dir.path(),
        &["sweep-merge", "p0.csv", "--out", "m.csv"],
        1,
        &["the parts hold 3 of the grid's 6 configurations; missing: 0, 2, 4"],
    );
    let (code, err) = run_in(
        dir.path(),
        &["sweep-merge", "p0.csv", "p1.csv", "--out", "m.csv"],
    );
    assert_eq!(code, 0, "{err}");
    // The merge is the unsharded sweep: its CSV and its plot (drawn from the parameters'
    // values the merge collects), byte for byte.
    sweep_in(dir.path(), &[&grid[..], &["--out", "whole.csv"]].concat());
    for (merged, whole) in [
        ("m.csv", "whole.csv"),
        ("m_plot.svg", "whole_plot.svg"),
        ("m_plot.csv", "whole_plot.csv"),
    ] {
        let read = |name: &str| std::fs::read(dir.path().join(name)).unwrap();
        assert!(read(merged) == read(whole), "{merged} differs from {whole}");
    }
    // A part given twice merges as once; a row of it changed is refused.
    let (code, err) = run_in(
        dir.path(),
        &[
            "sweep-merge",
            "p0.csv",
            "p1.csv",
            "p1.csv",
            "--out",
            "m3.csv",
        ],
    );
    assert_eq!(code, 0, "{err}");
    let p1 = std::fs::read_to_string(dir.path().join("p1.csv")).unwrap();
    let mut lines = p1.lines();
    let header = lines.next().unwrap();
    let mut fields: Vec<&str> = lines.next().unwrap().split(',').collect();
    let index = fields[0].to_string();
    fields[3] = "999";
    let changed = format!("{header}\n{}\n", fields.join(","));
    std::fs::write(dir.path().join("d.csv"), changed).unwrap();
    refused(
        dir.path(),
        &[
            "sweep-merge",
            "p0.csv",
            "p1.csv",
            "d.csv",
            "--out",
            "m4.csv",
        ],
        1,
        &[&format!(
            "d.csv:2: configuration {index} differs from p1.csv:2"
        )],
    );
    // A part computed at another width is not a part of this sweep.
    sweep_in(
        dir.path(),
        &[&grid[..], &["--shard", "1/2", "--out", "w.csv"]].concat(),
    );
    let w = std::fs::read_to_string(dir.path().join("w.csv")).unwrap();
    std::fs::write(dir.path().join("w.csv"), w.replace(",6,16,1,", ",6,24,1,")).unwrap();
    refused(
        dir.path(),
        &["sweep-merge", "p0.csv", "w.csv", "--out", "m2.csv"],
        1,
        &["w.csv:2: computed with --width 24, p0.csv:2 with --width 16: not parts of one sweep"],
    );
    assert!(!dir.path().join("m2.csv").exists());
}

#[test]
fn sweeps_write_every_row_and_resume() {
    let dir = tempfile::tempdir().unwrap();
    let csv = dir.path().join("s.csv");
    let params = [
        parse_param("theta_f=30,60").unwrap(),
        parse_param("d2=inf,6").unwrap(),
    ];
    let options = SweepOptions {
        width: 64,
        spp: 1,
        head: HeadSource::Oracle,
        band: 3,
        shard: None,
        bound_arcmin: 1.0,
    };
    let scene = common::repo_path("scenes/das.toml");
    assert_eq!(
        sweep(&Scene::load(&scene).unwrap(), &params, &csv, &options).unwrap(),
        4
    );
    let first = std::fs::read_to_string(&csv).unwrap();
    let lines: Vec<&str> = first.lines().collect();
    assert_eq!(lines.len(), 5);
    assert_eq!(
        lines[0],
        "index,theta_f,d2,misregistration_mean_arcmin,misregistration_p95_arcmin,\
         misregistration_max_arcmin,border_mean_arcmin,border_p95_arcmin,psnr_db,ssim,\
         missing_fraction,display_outside_frontal_fraction,R1,R2,coverage,configurations,\
         width,spp,head,band,scene_hash,seethru_version"
    );
    // The grid's size and the settings close every row, the same on each.
    let tail = |l: &str| l.split(',').skip(15).collect::<Vec<_>>().join(",");
    for line in &lines[1..] {
        let t = tail(line);
        assert!(t.starts_with("4,64,1,oracle,3,"), "{line}");
        assert!(
            t.ends_with(&format!(",{}", env!("CARGO_PKG_VERSION"))),
            "{line}"
        );
        assert_eq!(t, tail(lines[1]));
    }
    assert!(lines[1].starts_with("0,30,inf,") && lines[4].starts_with("3,60,6,"));
    // Each row's coverage is what ray casting predicts for its configuration (driver 64 px
    // wide, the frontal camera at the scene's resolution and the row's θ_F): at 30° the das
    // display leaves the frontal view, at 60° it does not.
    let base = common::das();
    let field = |l: &str, k: usize| l.split(',').nth(k).unwrap().parse::<f64>().unwrap();
    let columns: Vec<&str> = lines[0].split(',').collect();
    let coverage_at = columns.iter().position(|c| *c == "coverage").unwrap();
    for (line, (theta, d2)) in lines[1..].iter().zip([
        (30.0, None),
        (30.0, Some(6.0)),
        (60.0, None),
        (60.0, Some(6.0)),
    ]) {
        let mut scene = base.clone();
        scene.frontal.half_angle_x = f64::to_radians(theta);
        let driver = resized(scene.driver, Some(64), None, "--width").unwrap();
        let (display, covered, ambiguous) =
            common::expected_coverage(&scene, &driver, &scene.frontal, d2);
        let expected = covered as f64 / display as f64;
        let coverage = field(line, coverage_at);
        assert!(
            (coverage - expected).abs() <= (ambiguous + 1) as f64 / display as f64,
            "{line}: coverage {coverage} vs {expected} (±{ambiguous} of {display})"
        );
        assert_eq!(coverage < 1.0, theta == 30.0, "{line}");
    }
    // The plot draws the mean misregistration column against θ_F, one curve per d2.
    let plot = std::fs::read_to_string(dir.path().join("s_plot.csv")).unwrap();
    let plot_rows: Vec<Vec<f64>> = plot
        .lines()
        .skip(1)
        .map(|l| l.split(',').map(|v| v.parse().unwrap()).collect())
        .collect();
    assert_eq!(
        plot_rows,
        vec![
            vec![30.0, field(lines[1], 3), field(lines[2], 3)],
            vec![60.0, field(lines[3], 3), field(lines[4], 3)],
        ]
    );
    // Nothing left to do: nothing recomputed, file unchanged.
    assert_eq!(
        sweep(&Scene::load(&scene).unwrap(), &params, &csv, &options).unwrap(),
        0
    );
    assert_eq!(std::fs::read_to_string(&csv).unwrap(), first);
    // An interrupted sweep (a row missing) redoes only that row, bit-identically.
    let without: String = first
        .lines()
        .filter(|l| !l.starts_with("2,"))
        .map(|l| format!("{l}\n"))
        .collect();
    std::fs::write(&csv, without).unwrap();
    assert_eq!(
        sweep(&Scene::load(&scene).unwrap(), &params, &csv, &options).unwrap(),
        1
    );
    assert_eq!(std::fs::read_to_string(&csv).unwrap(), first);
    // Bad parameters are rejected before anything renders.
    let err = sweep(
        &Scene::load(&scene).unwrap(),
        &[parse_param("eye_z=-2").unwrap()],
        &dir.path().join("t.csv"),
        &options,
    )
    .unwrap_err();
    assert!(err.to_string().contains("behind the display"), "{err}");
}

#[test]
fn rows_that_share_an_eye_or_a_world_equal_rows_computed_alone() {
    // display_width changes the obstacle (a world of its own, the truth shared with the other
    // width); eye_x changes the truth; theta_f shares both. Rows that shared, recomputed
    // alone (deleted and resumed), must come out bit for bit the same: row 1 shared its
    // world and truth with row 0, row 5 its truth with rows 0 and 1, row 2 nothing.
    let dir = tempfile::tempdir().unwrap();
    let csv = dir.path().join("s.csv");
    let params = [
        parse_param("display_width=0.2,0.25").unwrap(),
        parse_param("eye_x=0,0.02").unwrap(),
        parse_param("theta_f=40,50").unwrap(),
    ];
    let options = SweepOptions {
        width: 48,
        spp: 1,
        head: HeadSource::Oracle,
        band: 2,
        shard: None,
        bound_arcmin: 1.0,
    };
    let scene = common::repo_path("scenes/das.toml");
    assert_eq!(
        sweep(&Scene::load(&scene).unwrap(), &params, &csv, &options).unwrap(),
        8
    );
    let all = std::fs::read_to_string(&csv).unwrap();
    for row in [1, 2, 5] {
        let without: String = all
            .lines()
            .filter(|l| !l.starts_with(&format!("{row},")))
            .map(|l| format!("{l}\n"))
            .collect();
        std::fs::write(&csv, without).unwrap();
        assert_eq!(
            sweep(&Scene::load(&scene).unwrap(), &params, &csv, &options).unwrap(),
            1
        );
        assert_eq!(std::fs::read_to_string(&csv).unwrap(), all, "row {row}");
    }
    // The same sweep in three parts, as three machines would run it: the parts are disjoint,
    // cover the grid, and merge into the unsharded CSV byte for byte.
    let parts: Vec<std::path::PathBuf> = (0..3)
        .map(|k| {
            let part = dir.path().join(format!("part{k}.csv"));
            let options = SweepOptions {
                shard: Some(format!("{k}/3").parse::<Shard>().unwrap()),
                ..options
            };
            sweep(&Scene::load(&scene).unwrap(), &params, &part, &options).unwrap();
            part
        })
        .collect();
    let rows_of = |p: &std::path::Path| std::fs::read_to_string(p).unwrap().lines().count() - 1;
    assert_eq!(parts.iter().map(|p| rows_of(p)).sum::<usize>(), 8);
    assert!(
        parts.iter().all(|p| rows_of(p) < 8),
        "one part took everything"
    );
    let merged = dir.path().join("merged.csv");
    let paths: Vec<&std::path::Path> = parts.iter().map(|p| p.as_path()).collect();
    assert_eq!(merge_parts(&paths, &merged).unwrap(), 8);
    assert_eq!(std::fs::read_to_string(&merged).unwrap(), all);
    // A part missing is an error that says how many configurations are there.
    let err = merge_parts(&paths[1..], &dir.path().join("partial.csv"))
        .unwrap_err()
        .to_string();
    assert!(err.contains("of the grid's 8 configurations"), "{err}");
}

#[test]
fn a_row_holds_the_metrics_of_run_with_the_same_settings() {
    // The sweep's own settings (--width, --spp, --head, --band; --outside black) reach every
    // row: a row equals what `seethru run` reports for its configuration, bit for bit.
    // The estimated head makes the back camera's size matter too.
    let dir = tempfile::tempdir().unwrap();
    let csv = dir.path().join("s.csv");
    let options = SweepOptions {
        width: 96,
        spp: 2,
        head: HeadSource::Estimated,
        band: 2,
        shard: None,
        bound_arcmin: 1.0,
    };
    let scene = common::repo_path("scenes/das.toml");
    let params = [parse_param("d2=6").unwrap()];
    assert_eq!(
        sweep(&Scene::load(&scene).unwrap(), &params, &csv, &options).unwrap(),
        1
    );
    let text = std::fs::read_to_string(&csv).unwrap();
    let lines: Vec<&str> = text.lines().collect();
    let row: std::collections::HashMap<&str, &str> =
        lines[0].split(',').zip(lines[1].split(',')).collect();
    let out = dir.path().join("run");
    let (ok, _, err) = common::seethru(&[
        "run",
        scene.to_str().unwrap(),
        "--width",
        "96",
        "--spp",
        "2",
        "--head",
        "estimated",
        "--band",
        "2",
        "--outside",
        "black",
        "--d2",
        "6",
        "--exr",
        "none",
        "--out",
        out.to_str().unwrap(),
    ]);
    assert!(ok, "{err}");
    let json = |name: &str| -> serde_json::Value {
        serde_json::from_str(&std::fs::read_to_string(out.join(name)).unwrap()).unwrap()
    };
    let (metrics, report) = (json("metrics.json"), json("run.json"));
    let display = &metrics["display"];
    let border = &metrics["border"];
    for (column, value) in [
        (
            "misregistration_mean_arcmin",
            &display["misregistration_arcmin"]["mean"],
        ),
        (
            "misregistration_p95_arcmin",
            &display["misregistration_arcmin"]["p95"],
        ),
        (
            "misregistration_max_arcmin",
            &display["misregistration_arcmin"]["max"],
        ),
        (
            "border_mean_arcmin",
            &border["misregistration_arcmin"]["mean"],
        ),
        (
            "border_p95_arcmin",
            &border["misregistration_arcmin"]["p95"],
        ),
        ("psnr_db", &display["psnr_db"]),
        ("ssim", &display["ssim"]),
        ("missing_fraction", &metrics["missing"]["fraction"]),
        (
            "display_outside_frontal_fraction",
            &report["missing_fraction"],
        ),
        ("R1", &report["crop"]["R1_left"]),
        ("R2", &report["crop"]["R2_right"]),
        ("coverage", &metrics["coverage"]),
    ] {
        // serde_json's reader may miss the last bit of a number: a few ulp of room.
        let want = value
            .as_f64()
            .unwrap_or_else(|| panic!("{column}: {value}"));
        let got: f64 = row[column].parse().unwrap();
        assert!(
            (got - want).abs() <= 4.0 * f64::EPSILON * want.abs(),
            "{column}: sweep {got}, run {want}"
        );
    }
    // The head was estimated, as asked: the eye used is not the scene's, so the rows of an
    // oracle head would differ.
    assert!(
        report["eye_used"]["error_m"].as_f64().unwrap() > 1e-4,
        "{}",
        report["eye_used"]
    );
}

/// Each sweep parameter sets its scene key or run option, and nothing else: θ_F in radians,
/// the model distance, the display's width with its pixel columns in proportion, the eye
/// (with the head) along the display's x or normal, the head bias, the frontal width. A
/// configuration that puts the eye behind the display is refused.
#[test]
fn every_parameter_sets_its_key_or_option() {
    use seethru::measure::sweep_grid::configure;
    use seethru::system::options::{RunOptions, WorkingDistance};
    let das = common::das();
    let base = RunOptions::default();
    let one = |name: &str, value: &str| {
        configure(&das, &base, &[(name.to_string(), value.to_string())]).unwrap()
    };
    let (s, _) = one("theta_f", "30");
    assert_eq!(s.frontal.half_angle_x, 30f64.to_radians());
    let (_, o) = one("d2", "7.5");
    assert_eq!(o.d2, WorkingDistance::Metres(7.5));
    // das: 0.25 m wide at 250 × 450 pixels.
    let (s, _) = one("display_width", "0.375");
    assert_eq!(s.obstacle.width, 0.375);
    assert_eq!(s.obstacle.display_resolution, [375, 450]);
    let (s, _) = one("display_width", "0.1");
    assert_eq!(s.obstacle.display_resolution, [100, 450]);
    let world_from_obstacle = das.obstacle.world_from_obstacle;
    for (name, axis) in [("eye_x", glam::DVec3::X), ("eye_z", glam::DVec3::Z)] {
        let (s, _) = one(name, "0.05");
        let moved = s.eye() - das.eye();
        let expected = world_from_obstacle.transform_vector3(axis * 0.05);
        assert!((moved - expected).length() < 1e-12, "{name}: {moved}");
        let head = |scene: &seethru::scene::Scene| {
            scene
                .objects
                .iter()
                .find(|o| o.name == "head")
                .unwrap()
                .world_from_object
                .translation
        };
        assert!(
            (head(&s) - head(&das) - expected).length() < 1e-12,
            "{name}: the head"
        );
    }
    let (_, o) = one("head_bias_x_cm", "-3");
    assert_eq!(o.head_bias_cm, [-3.0, 0.0, 0.0]);
    let (s, o) = one("frontal_width", "640");
    assert_eq!(o.frontal_width, Some(640));
    assert_eq!(
        s.frontal, das.frontal,
        "frontal_width is a run option, not a scene key"
    );
    let d1 = world_from_obstacle.inverse().transform_point3(das.eye()).z;
    let behind = format!("{}", -d1);
    let err = configure(&das, &base, &[("eye_z".into(), behind)])
        .unwrap_err()
        .to_string();
    assert!(err.contains("puts the eye behind the display"), "{err}");
    let (s, _) = one("eye_z", &format!("{}", 0.5 - d1));
    assert!((world_from_obstacle.inverse().transform_point3(s.eye()).z - 0.5).abs() < 1e-12);
}
