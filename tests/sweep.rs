//! Sweeps: one row per configuration, deterministic, resumed without recomputing.

mod common;

use seethru::measure::{
    sweep::{SweepOptions, merge_parts, sweep},
    sweep_grid::parse_param,
    sweep_shard::Shard,
};
use seethru::render::settings::resized;
use seethru::system::options::HeadSource;

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
    };
    let scene = common::repo_path("scenes/das.toml");
    assert_eq!(sweep(&scene, &params, &csv, &options).unwrap(), 4);
    let first = std::fs::read_to_string(&csv).unwrap();
    let lines: Vec<&str> = first.lines().collect();
    assert_eq!(lines.len(), 5);
    assert!(lines[0].starts_with("index,theta_f,d2,misregistration_mean_arcmin"));
    assert!(lines[0].ends_with(",R1,R2,coverage"), "{}", lines[0]);
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
    assert_eq!(sweep(&scene, &params, &csv, &options).unwrap(), 0);
    assert_eq!(std::fs::read_to_string(&csv).unwrap(), first);
    // An interrupted sweep (a row missing) redoes only that row, bit-identically.
    let without: String = first
        .lines()
        .filter(|l| !l.starts_with("2,"))
        .map(|l| format!("{l}\n"))
        .collect();
    std::fs::write(&csv, without).unwrap();
    assert_eq!(sweep(&scene, &params, &csv, &options).unwrap(), 1);
    assert_eq!(std::fs::read_to_string(&csv).unwrap(), first);
    // Bad parameters are rejected before anything renders.
    let err = sweep(
        &scene,
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
    };
    let scene = common::repo_path("scenes/das.toml");
    assert_eq!(sweep(&scene, &params, &csv, &options).unwrap(), 8);
    let all = std::fs::read_to_string(&csv).unwrap();
    for row in [1, 2, 5] {
        let without: String = all
            .lines()
            .filter(|l| !l.starts_with(&format!("{row},")))
            .map(|l| format!("{l}\n"))
            .collect();
        std::fs::write(&csv, without).unwrap();
        assert_eq!(sweep(&scene, &params, &csv, &options).unwrap(), 1);
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
            sweep(&scene, &params, &part, &options).unwrap();
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
