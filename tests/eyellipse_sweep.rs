//! `sweep --param eye=eyellipse`: one row per sampled driver's eye, the eye each row names,
//! the share of drivers under a bound recounted from the CSV, and shards that merge into the
//! unsharded sweep.

mod common;

use seethru::measure::sweep::{SweepOptions, merge_parts_with_bound, sweep};
use seethru::measure::sweep_grid::{configure, eyellipse_param, parse_param};
use seethru::scene::Scene;
use seethru::system::options::{HeadSource, RunOptions};

#[test]
fn an_eye_value_places_that_sample_of_the_scenes_eyellipse() {
    let scene = Scene::load(&common::repo_path("scenes/cabin.toml")).unwrap();
    let ellipse = scene.eyellipse.unwrap();
    let param = eyellipse_param(4, 9);
    assert_eq!(param.values[3], "eyellipse:9:3");
    let (moved, _) = configure(
        &scene,
        &RunOptions::default(),
        &[("eye".into(), param.values[3].clone())],
    )
    .unwrap();
    assert_eq!(moved.eye(), ellipse.sample(9, 3));
    assert_ne!(moved.eye(), scene.eye());
    // The driver's view keeps its orientation.
    assert_eq!(
        moved.driver.world_from_camera.matrix3,
        scene.driver.world_from_camera.matrix3
    );
    // A scene without [eyellipse] cannot be sampled; `eye` takes no other value.
    let das = common::das();
    let err = configure(
        &das,
        &RunOptions::default(),
        &[("eye".into(), "eyellipse:1:0".into())],
    )
    .unwrap_err()
    .to_string();
    assert!(err.contains("has no [eyellipse] table"), "{err}");
    let err = parse_param("eye=1.2").unwrap_err().to_string();
    assert!(err.contains("the only value is eyellipse"), "{err}");
}

#[test]
fn each_driver_is_a_row_and_the_share_is_recounted_from_them() {
    let dir = tempfile::tempdir().unwrap();
    let csv = dir.path().join("drivers.csv");
    let scene = common::repo_path("scenes/cabin.toml");
    let params = [eyellipse_param(6, 5)];
    let bound = 21.0;
    let options = SweepOptions {
        width: 40,
        spp: 1,
        head: HeadSource::Oracle,
        band: 2,
        shard: None,
        bound_arcmin: bound,
    };
    assert_eq!(
        sweep(
            &seethru::scene::Scene::load(&scene).unwrap(),
            &params,
            &csv,
            &options
        )
        .unwrap(),
        6
    );
    let text = std::fs::read_to_string(&csv).unwrap();
    let rows: Vec<Vec<&str>> = text
        .lines()
        .skip(1)
        .map(|l| l.split(',').collect())
        .collect();
    assert_eq!(rows.len(), 6);
    for (i, row) in rows.iter().enumerate() {
        assert_eq!(row[1], format!("eyellipse:5:{i}"));
    }
    // Different eyes give different misregistration.
    assert!(rows.iter().any(|r| r[2] != rows[0][2]), "{text}");
    let count = |column: usize| {
        rows.iter()
            .filter(|r| r[column].parse::<f64>().unwrap() <= bound)
            .count()
    };
    let shares: serde_json::Value = serde_json::from_str(
        &std::fs::read_to_string(dir.path().join("drivers_drivers.json")).unwrap(),
    )
    .unwrap();
    assert_eq!(shares["samples"], 6);
    assert_eq!(shares["seed"], "5");
    let group = &shares["groups"][0];
    for (key, column) in [("mean_misregistration", 2), ("p95_misregistration", 3)] {
        let s = &group[key];
        assert_eq!(s["under_bound"], count(column), "{key}");
        assert_eq!(s["drivers_counted"], 6);
        assert_eq!(s["drivers_excluded_no_metric"], 0);
        let lo = s["wilson_95"][0].as_f64().unwrap();
        let hi = s["wilson_95"][1].as_f64().unwrap();
        let share = s["share"].as_f64().unwrap();
        assert!(lo <= share && share <= hi && hi - lo > 0.2, "{s}");
    }
    // Two shards merge into the same CSV and the same shares.
    let parts: Vec<std::path::PathBuf> = (0..2)
        .map(|k| {
            let part = dir.path().join(format!("part{k}.csv"));
            let options = SweepOptions {
                shard: Some(format!("{k}/2").parse().unwrap()),
                ..options
            };
            sweep(
                &seethru::scene::Scene::load(&scene).unwrap(),
                &params,
                &part,
                &options,
            )
            .unwrap();
            part
        })
        .collect();
    let merged = dir.path().join("merged.csv");
    let paths: Vec<&std::path::Path> = parts.iter().map(|p| p.as_path()).collect();
    assert_eq!(
        merge_parts_with_bound(&paths, &merged, Some(bound)).unwrap(),
        6
    );
    assert_eq!(std::fs::read_to_string(&merged).unwrap(), text);
    let merged_shares: serde_json::Value = serde_json::from_str(
        &std::fs::read_to_string(dir.path().join("merged_drivers.json")).unwrap(),
    )
    .unwrap();
    assert_eq!(merged_shares, shares);
}
