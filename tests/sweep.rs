//! Sweeps: one row per configuration, deterministic, resumed without recomputing.

mod common;

use seethru::measure::{
    sweep::{SweepOptions, sweep},
    sweep_grid::parse_param,
};
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
    };
    let scene = common::repo_path("scenes/das.toml");
    assert_eq!(sweep(&scene, &params, &csv, &options).unwrap(), 4);
    let first = std::fs::read_to_string(&csv).unwrap();
    let lines: Vec<&str> = first.lines().collect();
    assert_eq!(lines.len(), 5);
    assert!(lines[0].starts_with("index,theta_f,d2,misregistration_mean_arcmin"));
    assert!(lines[1].starts_with("0,30,inf,") && lines[4].starts_with("3,60,6,"));
    // A finite model distance nearer the scene's content changes the misregistration.
    let mean = |l: &str| l.split(',').nth(3).unwrap().parse::<f64>().unwrap();
    assert_ne!(mean(lines[3]), mean(lines[4]));
    assert!(dir.path().join("s_plot.png").exists());
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
}
