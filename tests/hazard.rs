//! Issue 27: the head tracker's confidence, the tracker model, the left-turn scene and the
//! hazard-visibility metric.

mod common;

use seethru::render::integrator::RenderContext;
use seethru::scene::Scene;
use seethru::system::options::{HeadSource, Outside, RunOptions};
use seethru::system::pipeline::run;

/// das with the pillar turned 31° towards the driver and leaning back (its up vector tilted
/// 56° towards the driver): the back camera on its top edge sees the head from below and
/// rolled. The eye is placed in a virtual camera square to the face (issue 51), so the
/// estimate is right, but the image cues, measured in the rolled image, still doubt it.
/// The textures and meshes are given as absolute paths so the text can live anywhere.
fn slanted_text() -> String {
    common::slanted_scene_text("das.toml")
}

fn slanted() -> Scene {
    common::parse_in(
        &common::repo_path("scenes"),
        "slanted.toml",
        &slanted_text(),
    )
    .unwrap()
}

/// das with its back camera 1.25 m to the display's left, yawed 58° to keep the face in view:
/// it sees the face 65° off its front, where the far pupil is half hidden and the estimate
/// is badly wrong.
fn far_side() -> Scene {
    let text = std::fs::read_to_string(common::repo_path("scenes/das.toml"))
        .unwrap()
        .replace(
            "[camera.back]",
            "[camera.back]\nyaw_deg = 58\noffset = [-1.25, 0.3, 0.0]",
        );
    common::parse_in(&common::repo_path("scenes"), "far_side.toml", &text).unwrap()
}

fn estimated() -> RunOptions {
    RunOptions {
        head: HeadSource::Estimated,
        spp: 1,
        width: Some(64),
        outside: Outside::Black,
        ..RunOptions::default()
    }
}

#[test]
fn the_confidence_is_low_where_the_estimate_is_badly_wrong_and_high_on_das() {
    let bad = run(&RenderContext::new(far_side()).unwrap(), &estimated()).unwrap();
    let slanted = run(&RenderContext::new(slanted()).unwrap(), &estimated()).unwrap();
    let good = run(&RenderContext::new(common::das()).unwrap(), &estimated()).unwrap();
    let error = |r: &seethru::system::pipeline::RunResult| {
        r.report["eye_used"]["error_m"].as_f64().unwrap()
    };
    let confidence = |r: &seethru::system::pipeline::RunResult| {
        r.report["head_detection"]["confidence"]["value"]
            .as_f64()
            .unwrap()
    };
    assert!(
        error(&bad) > 0.1,
        "the far-side case is badly wrong: {}",
        error(&bad)
    );
    assert!(confidence(&bad) < 0.5, "{}", bad.report["head_detection"]);
    // The slanted pillar's camera pose is corrected for (17.9 cm off before issue 51); the
    // cues, read in its rolled image, stay doubtful: a false alarm, not a missed failure.
    assert!(error(&slanted) < 0.03, "{}", error(&slanted));
    assert!(
        confidence(&slanted) < 0.5,
        "{}",
        slanted.report["head_detection"]
    );
    assert!(error(&good) < 0.01, "{}", error(&good));
    assert!(confidence(&good) > 0.9, "{}", good.report["head_detection"]);
    // The detection struct carries it (head.json serialises the struct).
    assert_eq!(
        bad.detection.unwrap().confidence.value,
        confidence(&bad),
        "run.json and the detection agree"
    );
}

#[test]
fn an_unreliable_estimate_warns_in_one_line_and_can_be_made_an_error() {
    let dir = tempfile::tempdir().unwrap();
    let scene = dir.path().join("slanted.toml");
    std::fs::write(&scene, slanted_text()).unwrap();
    let args = |out: &str, extra: &[&str]| {
        common::estimated_run_args(&scene, &dir.path().join(out), extra)
    };
    let (ok, _, err) = common::seethru(&args("warned", &[]));
    assert!(ok, "{err}");
    let warnings: Vec<&str> = err.lines().filter(|l| l.starts_with("warning:")).collect();
    assert_eq!(warnings.len(), 1, "{err}");
    assert!(
        warnings[0].contains("head estimate unreliable") && warnings[0].contains("confidence"),
        "{err}"
    );
    let (ok, _, err) = common::seethru(&args("refused", &["--require-confident-head"]));
    assert!(!ok);
    assert!(
        err.starts_with("error:") && err.contains("--require-confident-head"),
        "{err}"
    );
    assert!(!dir.path().join("refused").exists(), "nothing written");
    // das: confident, no warning, and the flag lets it through.
    let (ok, _, err) = common::seethru(&[
        "run",
        "scenes/das.toml",
        "--out",
        dir.path().join("das").to_str().unwrap(),
        "--head",
        "estimated",
        "--width",
        "48",
        "--spp",
        "1",
        "--require-confident-head",
    ]);
    assert!(ok && !err.contains("warning:"), "{err}");
    // The flag means nothing for the oracle: refused.
    let (ok, _, err) = common::seethru(&[
        "run",
        "scenes/das.toml",
        "--out",
        dir.path().join("oracle").to_str().unwrap(),
        "--width",
        "48",
        "--require-confident-head",
    ]);
    assert!(!ok && err.contains("needs --head estimated"), "{err}");
}

#[test]
fn a_sequence_records_the_confidence_of_every_estimate() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("seq");
    let (ok, _, err) = common::seethru(&[
        "sequence",
        "scenes/das.toml",
        "--out",
        out.to_str().unwrap(),
        "--duration",
        "0.2",
        "--fps",
        "10",
        "--head-source",
        "estimated",
        "--width",
        "64",
        "--spp",
        "1",
    ]);
    assert!(ok && !err.contains("warning:"), "{err}");
    let csv = std::fs::read_to_string(out.join("latency_0ms/frames.csv")).unwrap();
    let mut lines = csv.lines();
    let header: Vec<&str> = lines.next().unwrap().split(',').collect();
    let column = header.iter().position(|h| *h == "head_confidence").unwrap();
    let values: Vec<f64> = lines
        .map(|l| l.split(',').nth(column).unwrap().parse().unwrap())
        .collect();
    assert_eq!(values.len(), 2);
    assert!(values.iter().all(|c| (0.9..=1.0).contains(c)), "{values:?}");
}

#[test]
fn the_tracker_model_moves_the_eye_by_its_noise_seeded_and_states_its_figures() {
    let ctx = RenderContext::new(common::das()).unwrap();
    let model = |seed| {
        run(
            &ctx,
            &RunOptions {
                head: HeadSource::Model,
                seed,
                spp: 1,
                width: Some(48),
                ..RunOptions::default()
            },
        )
        .unwrap()
    };
    let (a, b, c) = (model(1), model(1), model(2));
    let error = |r: &seethru::system::pipeline::RunResult| {
        r.report["eye_used"]["error_m"].as_f64().unwrap()
    };
    // Depth σ 5% of 0.75 m = 3.8 cm, lateral 2 mm: one draw is off, and within 5 σ.
    assert!(error(&a) > 1e-4 && error(&a) < 0.2, "{}", error(&a));
    assert_eq!(error(&a), error(&b), "seeded");
    assert_ne!(error(&a), error(&c));
    assert_eq!(a.report["head_model"]["sigma_depth_fraction"], 0.05);
    assert!(a.report["head_detection"].is_null());
}

/// `run` on the left turn at `--display ideal` with `extra` flags: the pedestrian's and the
/// cyclist's hazard records.
fn left_turn(dir: &std::path::Path, name: &str, extra: &[&str]) -> Vec<serde_json::Value> {
    let out = dir.join(name);
    let mut args = vec![
        "run",
        "scenes/left_turn.toml",
        "--out",
        out.to_str().unwrap(),
        "--width",
        "320",
        "--spp",
        "1",
        "--display",
        "ideal",
        "--outside",
        "black",
    ];
    args.extend(extra);
    let (ok, _, err) = common::seethru(&args);
    assert!(ok, "{err}");
    let m: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("hazards.json")).unwrap()).unwrap();
    m["objects"].as_array().unwrap().clone()
}

#[test]
fn hazard_visibility_is_one_at_the_pedestrians_depth_and_falls_as_the_plane_moves_away() {
    let scene = Scene::load(&common::repo_path("scenes/left_turn.toml")).unwrap();
    let hazards: Vec<&str> = scene
        .objects
        .iter()
        .filter(|o| o.hazard)
        .map(|o| o.name.as_str())
        .collect();
    assert_eq!(hazards, ["pedestrian", "cyclist"]);
    // The prediction from the scene's geometry: the frontal camera at C sees the pedestrian's
    // centre P along C→P; the planar model puts that ray's point on the model plane (d2
    // behind the display plane, parallel to it) at Q, and the display shows it where the eye
    // E sees Q. The error is the angle at E between P and Q.
    let pedestrian = scene
        .objects
        .iter()
        .find(|o| o.name == "pedestrian")
        .unwrap();
    let p = pedestrian.world_from_object.translation;
    let (e, c) = (scene.eye(), scene.frontal.position());
    let n = scene
        .obstacle
        .world_from_obstacle
        .transform_vector3(glam::DVec3::Z)
        .normalize();
    let centre = scene.obstacle.world_from_obstacle.translation;
    let depth = (centre - p).dot(n);
    let predicted = |d2: f64| {
        let q = if d2.is_infinite() {
            // A plane at infinity: the direction C→P seen from E.
            e + (p - c)
        } else {
            let plane = centre - n * d2;
            let s = (plane - c).dot(n) / (p - c).dot(n);
            c + (p - c) * s
        };
        (p - e).angle_between(q - e).to_degrees() * 60.0
    };
    let bound = 8.0;
    let dir = tempfile::tempdir().unwrap();
    let measured = |d2: f64| {
        let text = if d2.is_infinite() {
            "inf".to_string()
        } else {
            d2.to_string()
        };
        let h = left_turn(
            dir.path(),
            &text,
            &["--d2", &text, "--hazard-bound-arcmin", &bound.to_string()],
        );
        assert!(h[0]["hidden_pixels"].as_u64().unwrap() > 20, "{h:?}");
        (
            h[0]["visibility"].as_f64().unwrap(),
            h[0]["centroid_error_arcmin"].as_f64().unwrap(),
        )
    };
    // From the pedestrian's depth outwards: the predicted error grows, the visibility falls.
    let planes = [depth, 1.3 * depth, 2.0 * depth, f64::INFINITY];
    let mut last = (f64::INFINITY, -1.0);
    for d2 in planes {
        let (visibility, centroid) = measured(d2);
        let error = predicted(d2);
        assert!(error > last.1, "{d2}: predicted {error}′ after {}′", last.1);
        assert!(
            visibility <= last.0 + 0.02,
            "{d2}: {visibility} after {}",
            last.0
        );
        if error < 0.5 * bound {
            assert!(
                visibility > 0.9,
                "{d2} m: {visibility} at a predicted {error}′"
            );
        }
        if error > 1.5 * bound {
            assert!(
                visibility < 0.05,
                "{d2} m: {visibility} at a predicted {error}′"
            );
        }
        // The shown centroid moves by the predicted error (the body's ±0.25 m of depth and
        // the pixel pitch: within 2′ + 30%).
        assert!(
            (centroid - error).abs() < 2.0 + 0.3 * error,
            "{d2} m: centroid {centroid}′ against a predicted {error}′"
        );
        last = (visibility, error);
    }
    assert!(predicted(depth) < 0.01, "{}", predicted(depth));
    assert!(
        predicted(f64::INFINITY) > 1.5 * bound,
        "the test needs a plane that hides it"
    );
}

#[test]
fn a_road_user_outside_the_pillars_shadow_is_not_counted_as_hidden() {
    let dir = tempfile::tempdir().unwrap();
    let h = left_turn(dir.path(), "static", &[]);
    let cyclist = &h[1];
    assert_eq!(cyclist["name"], "cyclist");
    assert!(
        cyclist["truth_pixels"].as_u64().unwrap() > 0,
        "in view: {cyclist}"
    );
    assert_eq!(cyclist["hidden_pixels"], 0, "{cyclist}");
    assert!(cyclist["visibility"].is_null(), "{cyclist}");
}

/// The left turn as a sequence (10 km/h on a 10 m radius, 3 s at 10 frames/s): frames.csv's
/// header and rows, and summary.json's hazard block.
fn left_turn_sequence(dir: &std::path::Path) -> (Vec<String>, Vec<Vec<f64>>, serde_json::Value) {
    let out = dir.join("seq");
    let args = [
        "sequence",
        "scenes/left_turn.toml",
        "--out",
        out.to_str().unwrap(),
        "--speed",
        "10",
        "--yaw-rate",
        "15.9",
        "--duration",
        "3",
        "--fps",
        "10",
        "--width",
        "96",
    ];
    let (ok, _, err) = common::seethru(&args);
    assert!(ok, "{err}");
    let dir = out.join("latency_0ms");
    let text = std::fs::read_to_string(dir.join("frames.csv")).unwrap();
    let mut lines = text.lines();
    let header: Vec<String> = lines
        .next()
        .unwrap()
        .split(',')
        .map(str::to_string)
        .collect();
    let rows = lines
        .map(|l| l.split(',').map(|v| v.parse().unwrap()).collect())
        .collect();
    let s: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("summary.json")).unwrap()).unwrap();
    (header, rows, s["hazards"].clone())
}

#[test]
fn over_the_left_turn_the_hazard_times_agree_with_a_frame_by_frame_check() {
    let dir = tempfile::tempdir().unwrap();
    let (header, rows, hazards) = left_turn_sequence(dir.path());
    let col = |name: &str| {
        header
            .iter()
            .position(|h| h == name)
            .unwrap_or_else(|| panic!("no column {name} in {header:?}"))
    };
    let (t, off, on, vis, truth, hidden) = (
        col("t_s"),
        col("hazard_pedestrian_seen_display_off"),
        col("hazard_pedestrian_seen_display_on"),
        col("hazard_pedestrian_visibility"),
        col("hazard_pedestrian_truth_pixels"),
        col("hazard_pedestrian_hidden_pixels"),
    );
    let period = 0.1;
    // The guide's definition, applied to the rows: hidden when in view and less than half
    // of it is seen.
    let below = 0.5;
    let first = |c: usize| rows.iter().find(|r| r[c] >= below).map(|r| r[t]);
    let first_hidden = rows
        .iter()
        .find(|r| r[truth] > 0.0 && r[off] < below)
        .map(|r| r[t]);
    let longest = |c: usize| {
        let (mut best, mut run) = (0, 0);
        for r in &rows {
            run = if r[truth] > 0.0 && r[c] < below {
                run + 1
            } else {
                0
            };
            best = best.max(run);
        }
        best as f64 * period
    };
    for r in &rows {
        // What the display adds can only add to what the pillar leaves in view; what it
        // leaves is no more than the pixels off the display.
        assert!(r[on] >= r[off], "{r:?}");
        if r[truth] > 0.0 {
            assert!(r[off] <= 1.0 - r[hidden] / r[truth] + 1e-12, "{r:?}");
        }
    }
    let p = &hazards["objects"][0];
    assert_eq!(p["name"], "pedestrian");
    let close = |a: &serde_json::Value, b: Option<f64>| {
        let b = b.expect("the pedestrian is hidden and shown during the turn");
        assert!((a.as_f64().unwrap() - b).abs() < 1e-9, "{a} against {b}");
    };
    close(&p["first_hidden_s"], first_hidden);
    close(&p["first_visible_on_display_s"], first(vis));
    close(&p["longest_hidden_display_off_s"], Some(longest(off)));
    close(&p["longest_hidden_display_on_s"], Some(longest(on)));
    // The scene's geometry puts the pedestrian in the pillar's shadow from about 0.5 s to
    // 2.6 s; the display shortens the time hidden.
    let hidden_off = p["longest_hidden_display_off_s"].as_f64().unwrap();
    assert!((1.5..=2.5).contains(&hidden_off), "{hidden_off}");
    assert!(p["longest_hidden_display_on_s"].as_f64().unwrap() < hidden_off);
    assert!(
        (0.3..=0.8).contains(&p["first_hidden_s"].as_f64().unwrap()),
        "{p}"
    );
}

#[test]
fn compare_rows_carry_each_hazards_visibility_as_run_measures_it() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("cmp");
    let (ok, _, err) = common::seethru(&[
        "compare",
        "scenes/left_turn.toml",
        "--out",
        out.to_str().unwrap(),
        "--width",
        "160",
        "--spp",
        "1",
    ]);
    assert!(ok, "{err}");
    let j: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("compare.json")).unwrap()).unwrap();
    let rows = j
        .as_array()
        .or(j["rows"].as_array())
        .or(j["methods"].as_array());
    let rows = rows.unwrap_or_else(|| panic!("rows in {j}"));
    let planar_inf = rows.iter().find(|r| r["method"] == "planar-inf").unwrap();
    // The same method as a `run` (planar, d2 = ∞, 30′): the same hazard figures.
    let ran = dir.path().join("run");
    let (ok, _, err) = common::seethru(&[
        "run",
        "scenes/left_turn.toml",
        "--out",
        ran.to_str().unwrap(),
        "--width",
        "160",
        "--spp",
        "1",
        "--d2",
        "inf",
        "--outside",
        "black",
    ]);
    assert!(ok, "{err}");
    let h: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(ran.join("hazards.json")).unwrap()).unwrap();
    let (a, b) = (&planar_inf["hazards"]["objects"], &h["objects"]);
    assert_eq!(a[0]["name"], "pedestrian");
    assert!(a[0]["hidden_pixels"].as_u64().unwrap() > 0, "{a}");
    assert_eq!(
        a[0]["hidden_pixels"], b[0]["hidden_pixels"],
        "{a} against {b}"
    );
    assert_eq!(
        a[0]["shown_pixels"], b[0]["shown_pixels"],
        "{a} against {b}"
    );
    let md = std::fs::read_to_string(out.join("compare.md")).unwrap();
    assert!(md.contains("| pedestrian visibility |"), "{md}");
}
