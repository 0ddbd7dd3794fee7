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
