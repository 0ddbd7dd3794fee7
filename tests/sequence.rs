//! `seethru sequence`: the dynamic misregistration against its formula, the moving part's
//! own hierarchy against a full rebuild, determinism across thread counts, bad input.

mod common;

use std::path::Path;

use seethru::analysis::dynamic::{Motion, dynamic_misregistration};
use seethru::analysis::physical::ARCMIN_PER_RAD;
use seethru::measure::image_metrics::Flip;
use seethru::measure::sequence::{SequenceStepper, run_sequence};
use seethru::render::integrator::RenderContext;
use seethru::render::render_job::RenderJob;
use seethru::render::settings::RenderSettings;
use seethru::scene::world::view_bit;
use seethru::system::options::{Method, RunOptions, WorkingDistance};
use seethru::system::sequence::head_motion::HeadMotion;
use seethru::system::sequence::predict::Prediction;
use seethru::system::sequence::system_loop::{SequenceOptions, SystemLoop};
use seethru::system::sequence::timeline::Timeline;

fn options(latency: f64, fps: f64, display_hz: f64, yaw_rate: f64) -> SequenceOptions {
    SequenceOptions {
        run: RunOptions {
            d2: WorkingDistance::Metres(6.0),
            spp: 1,
            yaw_rate_deg_s: yaw_rate.to_degrees(),
            ..RunOptions::default()
        },
        timeline: Timeline {
            duration: 9.0 / fps,
            fps,
            display_hz,
            latency_camera: latency,
            latency_tracking: 0.0,
        },
        head: HeadMotion::Still,
        predict: Prediction::None,
        reproject: false,
        byo: Default::default(),
    }
}

/// A textured wall 6 m ahead, the model plane on it (so the static error is the resampling
/// quantum), a still head and a constant yaw rate: every frame's measured mean
/// misregistration is the formula's `ω L`, L being the age of the image shown — the camera
/// latency plus, with a slower display, the time since its refresh — within 2 % (the issue
/// asks 5 %; the resampling quantum and the wall's tilt leave about 0.5 %).
#[test]
fn the_measured_dynamic_misregistration_follows_the_formula() {
    let wall = common::WallScene::default();
    let scene = wall.scene();
    let eye = scene.obstacle.in_obstacle_frame(scene.eye());
    let yaw_rate = 20f64.to_radians();
    for (latency, display_hz) in [(0.05, 60.0), (0.1, 60.0), (0.033, 30.0)] {
        let how = common::measuring(Flip::Skipped);
        let run = run_sequence(
            &scene,
            options(latency, 60.0, display_hz, yaw_rate),
            how,
            &mut |_| Ok(()),
        )
        .unwrap();
        let mut ages = std::collections::BTreeSet::new();
        for r in &run.records {
            let m = r.metrics.unwrap();
            assert_eq!(m.coverage, 1.0);
            let age = r.times.display - r.times.capture;
            ages.insert((age * 1e6).round() as i64);
            let motion = Motion {
                speed: 0.0,
                yaw_rate,
                eye_speed: 0.0,
                latency: age,
                tracking_latency: 0.0,
            };
            // A pure yaw turns every direction alike: any distance and bearing.
            let predicted = dynamic_misregistration(6.0 - eye.z, 0.3, eye.z, 6.0, &motion).abs()
                * ARCMIN_PER_RAD;
            let error = (m.mean_arcmin - predicted).abs() / predicted;
            assert!(
                error < 0.02,
                "latency {latency} s, {display_hz} Hz, frame {}: measured {:.2}′, formula {predicted:.2}′",
                r.frame,
                m.mean_arcmin
            );
        }
        // The held display shows images of two ages.
        assert_eq!(
            ages.len(),
            if display_hz < 60.0 { 2 } else { 1 },
            "{ages:?}"
        );
        // The planar crop is rendered alone: a part of the frontal image, more than none.
        let frontal = scene.frontal;
        let whole = f64::from(frontal.width) * f64::from(frontal.height);
        let rendered = run.frontal_pixels_per_refresh;
        assert!(
            rendered > 0.0 && rendered < 0.8 * whole,
            "{rendered} of {whole} pixels"
        );
    }
}

/// What a stepped run reports beside its metrics: the frames made so far; each frame's
/// vehicle heading, against the turn of the driver's view the rig renders at that time; the
/// stages' seconds, each within the frames' time; and the frontal pixels rendered per
/// camera refresh, the whole frontal image when the method has no crop to render alone.
#[test]
fn a_run_reports_its_frames_headings_stage_times_and_frontal_pixels() {
    let wall = common::WallScene::default();
    let scene = wall.scene();
    let mut o = options(0.05, 60.0, 20.0, 20f64.to_radians());
    o.run.method = Method::None;
    let how = common::measuring(Flip::Skipped);
    let mut stepper = SequenceStepper::new(&scene, o, how, 10.0).unwrap();
    // Headings in the ground plane (the driver looks a little down).
    let level = |v: glam::DVec3| glam::DVec3::new(v.x, 0.0, v.z);
    let base = level(stepper.system.rig.scene_at(0.0).driver.forward());
    let mut made = 0;
    while stepper.step().unwrap().is_some() {
        made += 1;
        let records = stepper.records();
        assert_eq!(records.len(), made);
        let r = records.last().unwrap();
        assert_eq!(r.frame, made - 1);
        let forward = stepper
            .system
            .rig
            .scene_at(r.times.display)
            .driver
            .forward();
        let turned = base.cross(forward).y.atan2(base.dot(forward)).to_degrees();
        assert!(
            (r.vehicle_yaw_deg - turned).abs() < 1e-9,
            "frame {}: heading {}°, the view turned {turned}°",
            r.frame,
            r.vehicle_yaw_deg
        );
    }
    assert_eq!(made, 9);
    let refreshes: std::collections::BTreeSet<i64> =
        stepper.records().iter().map(|r| r.times.refresh).collect();
    assert!(refreshes.len() >= 3, "{refreshes:?}");
    let frontal = stepper.system.rig.base.frontal;
    let run = stepper.finish();
    assert!(run.records[8].vehicle_yaw_deg > 2.0);
    assert_eq!(
        run.frontal_pixels_per_refresh,
        f64::from(frontal.width) * f64::from(frontal.height)
    );
    assert!(run.truth_seconds > 0.0 && run.metrics_seconds > 0.0);
    assert!(run.truth_seconds + run.metrics_seconds <= run.stepping_seconds);
    // The system's stages are parts of the stepping too, none counted twice.
    let parts = run.system.total() + run.truth_seconds + run.metrics_seconds;
    assert!(
        run.system.compensation > 0.0 && parts <= run.stepping_seconds,
        "{:?}, truth {} s, metrics {} s, stepping {} s",
        run.system,
        run.truth_seconds,
        run.metrics_seconds,
        run.stepping_seconds
    );
    assert!(run.stepping_seconds <= run.total_seconds);
}

/// The moving part traced beside the static hierarchy gives the images of a world rebuilt
/// whole with every object where the sequence puts it.
#[test]
fn the_moving_part_renders_as_a_whole_rebuilt_world() {
    let scene = common::das();
    let mut o = options(0.0, 10.0, 10.0, 0.1);
    o.run.speed_kmh = 50.0;
    o.head = HeadMotion::Lean {
        distance: 0.1,
        duration: 0.3,
        start: 0.0,
    };
    let mut system = SystemLoop::new(&scene, o).unwrap();
    let t = 1.5;
    let layered = system.context_at(t).unwrap();
    let mut whole = system.rig.scene_at(t);
    for (i, object) in whole.objects.iter_mut().enumerate() {
        if let Some(m) = system.rig.object_motion(t, i as u32 + 1) {
            object.world_from_object = m * object.world_from_object;
        }
    }
    // The ball rolled 2.25 m, the head leaned, the rig drove 20.8 m and turned 8.6°.
    assert!((whole.objects[6].world_from_object.translation.x - 1.35).abs() < 1e-9);
    let whole = RenderContext::new(whole).unwrap();
    let settings = RenderSettings::default();
    let s = &layered.scene;
    for (camera, view) in [
        (s.frontal.with_resolution(128, 72), view_bit::FRONTAL),
        (s.driver.with_resolution(128, 72), view_bit::OCCLUDED),
        (s.back.with_resolution(96, 72), view_bit::BACK),
    ] {
        let (a, _) = layered.render(
            RenderJob::new(&camera, view)
                .settings(settings)
                .label("layered"),
        );
        let (b, _) = whole.render(
            RenderJob::new(&camera, view)
                .settings(settings)
                .label("whole"),
        );
        let differ = a
            .object_id
            .iter()
            .zip(&b.object_id)
            .filter(|(x, y)| x != y)
            .count();
        assert!(
            differ * 500 < a.object_id.len(),
            "view {view}: {differ} ids differ"
        );
        let colour: f32 = a
            .color
            .iter()
            .zip(&b.color)
            .map(|(x, y)| (*x - *y).abs().max_element())
            .sum::<f32>()
            / a.color.len() as f32;
        assert!(
            colour < 2e-3,
            "view {view}: mean colour difference {colour}"
        );
        // What moves is seen: the obstacle in the driver's view, the head from the back.
        let expected = if view == view_bit::OCCLUDED {
            layered.world.obstacle_id
        } else {
            9
        };
        if view != view_bit::FRONTAL {
            assert!(a.object_id.contains(&expected), "view {view}");
        }
    }
}

fn files(dir: &Path) -> Vec<(String, Vec<u8>)> {
    let mut out = Vec::new();
    for entry in walk(dir) {
        let name = entry
            .strip_prefix(dir)
            .unwrap()
            .to_string_lossy()
            .to_string();
        if name.ends_with("summary.json") {
            continue; // holds wall-clock timings
        }
        out.push((name, std::fs::read(&entry).unwrap()));
    }
    out.sort();
    out
}

fn walk(dir: &Path) -> Vec<std::path::PathBuf> {
    let mut out = Vec::new();
    for e in std::fs::read_dir(dir).unwrap() {
        let p = e.unwrap().path();
        if p.is_dir() {
            out.extend(walk(&p));
        } else {
            out.push(p);
        }
    }
    out
}

#[test]
fn frames_and_csv_are_bit_identical_for_any_thread_count() {
    let dir = tempfile::tempdir().unwrap();
    let mut outputs = Vec::new();
    for threads in ["1", "3"] {
        let out = dir.path().join(threads);
        let (ok, _, err) = common::seethru(&[
            "sequence",
            "scenes/das.toml",
            "--out",
            out.to_str().unwrap(),
            "--duration",
            "0.3",
            "--fps",
            "10",
            "--speed",
            "50",
            "--yaw-rate",
            "10",
            "--head",
            "sway",
            "--latency-camera",
            "0,100",
            "--predict",
            "kalman",
            "--width",
            "96",
            "--frames",
            "png",
            "--threads",
            threads,
        ]);
        assert!(ok, "{err}");
        outputs.push(files(&out));
    }
    let names: Vec<&str> = outputs[0].iter().map(|f| f.0.as_str()).collect();
    assert!(names.contains(&"latency_100ms/frames.csv"), "{names:?}");
    assert!(
        names.contains(&"latency_0ms/frames/seethru_00002.png"),
        "{names:?}"
    );
    assert!(names.contains(&"latency.svg") && names.contains(&"latency_0ms/preview.png"));
    assert_eq!(outputs[0].len(), outputs[1].len());
    for (a, b) in outputs[0].iter().zip(&outputs[1]) {
        assert!(a == b, "{} differs between 1 and 3 threads", a.0);
    }
    let text = |name: &str| {
        let file = outputs[0].iter().find(|f| f.0 == name).unwrap();
        String::from_utf8(file.1.clone()).unwrap()
    };
    // Three frames per latency, and more misregistration with 100 ms of latency.
    let csv = text("latency.csv");
    let rows: Vec<Vec<f64>> = csv
        .lines()
        .skip(1)
        .map(|l| l.split(',').map(|v| v.parse().unwrap()).collect())
        .collect();
    assert_eq!(rows.len(), 2);
    // Without --flip, frames.csv's FLIP column is NaN in every row.
    let frames = text("latency_0ms/frames.csv");
    let header: Vec<&str> = frames.lines().next().unwrap().split(',').collect();
    let flip = header.iter().position(|c| *c == "flip").unwrap();
    for row in frames.lines().skip(1) {
        assert_eq!(row.split(',').nth(flip), Some("NaN"), "{row}");
    }
    assert!(rows[1][1] > rows[0][1] + 10.0, "{rows:?}");
}

#[test]
fn bad_input_is_one_line_and_writes_nothing() {
    let dir = tempfile::tempdir().unwrap();
    let path = |name: &str, text: &str| {
        let p = dir.path().join(name);
        std::fs::write(&p, text).unwrap();
        p.to_string_lossy().to_string()
    };
    let decreasing = path(
        "decreasing.csv",
        "t,x,y,z\n0,0.3,0,0.7\n0.5,0.3,0,0.7\n0.4,0.3,0,0.7\n",
    );
    let nan = path("nan.csv", "0,0.3,0,0.7\n0.5,nan,0,0.7\n");
    let behind = path("behind.csv", "0,0.3,0,0.7\n1,0.3,0,-0.3\n");
    let das = std::fs::read_to_string(common::repo_path("scenes/das.toml")).unwrap();
    let far = das.replace(
        "translate = [5.1, 0.35, -5.5]",
        "translate = [999999.9, 0.35, -5.5]",
    );
    let far_line = far.lines().position(|l| l.contains("999999.9")).unwrap() + 1;
    let far = path(
        "far.toml",
        &far.replace("../assets", &common::repo_path("assets").to_string_lossy()),
    );
    let unknown = path(
        "unknown.toml",
        &das.replace("t = 4.0\n", "t = 4.0\nspeed = 3\n")
            .replace("../assets", &common::repo_path("assets").to_string_lossy()),
    );
    let cases: Vec<(Vec<&str>, &str)> = vec![
        (vec!["--duration", "0"], "--duration"),
        (vec!["--duration", "-1"], "--duration"),
        (vec!["--fps", "0"], "--fps"),
        (vec!["--display-hz", "0"], "--display-hz"),
        (
            vec!["--duration", "0.1", "--latency-camera", "0,200"],
            "--latency-camera 200 ms must be ≥ 0 and shorter than the sequence (100 ms)",
        ),
        (
            vec!["--duration", "0.1", "--latency-tracking", "150"],
            "--latency-tracking 150 ms",
        ),
        (vec!["--latency-camera", "0,nan"], "--latency-camera"),
        (
            vec!["--head-path", &decreasing],
            "decreasing.csv:4: times must increase: t = 0.4 s follows t = 0.5 s",
        ),
        (
            vec!["--head-path", &nan],
            "nan.csv:2: `x` must be a finite number",
        ),
        (
            vec!["--head-path", &behind],
            "behind the display at t = 0.8 s",
        ),
        (
            vec!["--method", "depth"],
            "sequence: --method ground, plane-fit and depth are not modelled over time",
        ),
    ];
    let out = dir.path().join("out");
    for (extra, expected) in cases {
        let mut args = vec![
            "sequence",
            "scenes/das.toml",
            "--out",
            out.to_str().unwrap(),
            "--width",
            "32",
        ];
        for (flag, default) in [("--duration", "1"), ("--fps", "5")] {
            if !extra.contains(&flag) {
                args.extend([flag, default]);
            }
        }
        args.extend(extra);
        let (ok, _, err) = common::seethru(&args);
        assert!(!ok, "{args:?}");
        assert_eq!(err.trim_end().lines().count(), 1, "{args:?}: {err}");
        assert!(
            err.starts_with("error:") && err.contains(expected),
            "{args:?}: {err}"
        );
        assert!(!out.exists(), "{args:?} wrote {}", out.display());
    }
    for (scene, expected) in [
        (
            far.as_str(),
            format!(
                "far.toml:{far_line}:13: key `object[6].keyframe[1].translate`: the path leaves the world at t = 4 s"
            ),
        ),
        (
            unknown.as_str(),
            "key `object[6].keyframe[1].speed`: unknown key".to_string(),
        ),
    ] {
        let (ok, _, err) = common::seethru(&["sequence", scene, "--out", out.to_str().unwrap()]);
        assert!(!ok);
        assert_eq!(err.trim_end().lines().count(), 1, "{err}");
        assert!(err.contains(&expected), "{err}");
        assert!(!out.exists());
    }
}

/// The error budget's das geometry is das's: the eye's distance and bearing from the display
/// centre, the display's half width, and the depth `--d2 auto` finds behind it.
#[test]
fn the_budget_geometry_is_the_das_scene() {
    let scene = common::das();
    let g = seethru::analysis::examples::das_geometry();
    let eye = scene.obstacle.in_obstacle_frame(scene.eye());
    assert!((eye.z - g.d1).abs() < 1e-9, "{eye}");
    // The road runs along −z; the display centre is ahead-left of the eye.
    let to_display = scene.obstacle.world_from_obstacle.translation - scene.eye();
    let bearing = (-to_display.x).atan2(-to_display.z);
    assert!((bearing - g.bearing).abs() < 1e-9, "{bearing}");
    assert!((scene.obstacle.width / 2.0 - g.half_width).abs() < 1e-12);
    let ctx = RenderContext::new(scene).unwrap();
    let options = RunOptions {
        d2: WorkingDistance::Auto,
        width: Some(64),
        frontal_width: Some(640),
        back_width: Some(64),
        spp: 1,
        ..RunOptions::default()
    };
    let run = seethru::system::pipeline::run(&ctx, &options).unwrap();
    let d2 = run.report["d2_m"].as_f64().unwrap();
    assert!((d2 - g.scene_depth).abs() < 0.1, "d2 auto = {d2} m");
}

/// FLIP is a sequence's costliest image metric and is computed only when asked: without it
/// every frame's `flip` is NaN and every other metric is the same, bit for bit; with it each
/// frame has a FLIP in (0, 1] (the yawing wall is shown late, so the images differ).
#[test]
fn a_sequence_computes_flip_only_when_asked() {
    let wall = common::WallScene::default();
    let scene = wall.scene();
    let records = |flip: Flip| {
        let how = common::measuring(flip);
        let o = options(0.1, 30.0, 30.0, 20f64.to_radians());
        let run = run_sequence(&scene, o, how, &mut |_| Ok(())).unwrap();
        run.records
            .iter()
            .map(|r| r.metrics.unwrap())
            .collect::<Vec<_>>()
    };
    let (with, without) = (records(Flip::Computed), records(Flip::Skipped));
    assert_eq!(with.len(), without.len());
    assert!(with.len() >= 3);
    for (a, b) in with.iter().zip(&without) {
        assert!(a.flip > 0.0 && a.flip <= 1.0, "{}", a.flip);
        assert!(b.flip.is_nan(), "{}", b.flip);
        let others = |m: &seethru::measure::sequence_records::FrameMetrics| {
            [
                m.coverage,
                m.mean_arcmin,
                m.p95_arcmin,
                m.max_arcmin,
                m.border_mean_arcmin,
                m.psnr_db,
                m.ssim,
                m.missing_fraction,
            ]
            .map(f64::to_bits)
        };
        assert_eq!(others(a), others(b));
        assert_eq!(a.display_pixels, b.display_pixels);
    }
}

/// Re-projecting the late frontal image by the known vehicle motion takes the yaw's error
/// away: on the wall with the model plane on it only the static error (the resampling
/// quantum) of a sequence without latency is left.
#[test]
fn reprojection_by_the_known_yaw_removes_the_dynamic_error() {
    let wall = common::WallScene::default();
    let scene = wall.scene();
    let how = common::measuring(Flip::Skipped);
    let mut means = Vec::new();
    for (latency, reproject) in [(0.1, false), (0.1, true), (0.0, false)] {
        let mut o = options(latency, 30.0, 30.0, 20f64.to_radians());
        o.reproject = reproject;
        let run = run_sequence(&scene, o, how, &mut |_| Ok(())).unwrap();
        let m: Vec<f64> = run
            .records
            .iter()
            .map(|r| r.metrics.unwrap().mean_arcmin)
            .collect();
        means.push(m.iter().sum::<f64>() / m.len() as f64);
    }
    assert!((means[0] - 120.0).abs() < 2.4, "{means:?}");
    assert!(
        means[2] < 10.0 && means[1] < 1.5 * means[2] + 0.5,
        "{means:?}"
    );
}

/// The formula's head term: a swaying head and a late head estimate, the wall on the model
/// plane and no vehicle motion: each frame's mean misregistration is the eye's speed across
/// the display (at display time) times the latency, through the planar model's
/// `d2 / (d1 (d1 + d2))`, within 8 % where the sway is fast: the formula is first order in the
/// latency and paraxial (off the display's axis a lateral eye error turns the view by cos² of
/// the viewing angle less — up to 18° here, so the measured mean is a few percent lower).
#[test]
fn a_late_head_estimate_costs_what_the_formula_says() {
    let wall = common::WallScene::default();
    let scene = wall.scene();
    let eye = scene.obstacle.in_obstacle_frame(scene.eye());
    let (amplitude, frequency, latency) = (0.03, 0.5, 0.02);
    let mut o = options(latency, 10.0, 10.0, 0.0);
    o.timeline.duration = 2.0;
    // The ideal display: no resampling quantum, only the planar model's (here zero) error.
    o.run.display = seethru::system::display::DisplayModel::Ideal;
    o.head = HeadMotion::Sway {
        amplitude,
        frequency,
    };
    let how = common::measuring(Flip::Skipped);
    let run = run_sequence(&scene, o, how, &mut |_| Ok(())).unwrap();
    let mut checked = 0;
    for r in &run.records {
        let phase = std::f64::consts::TAU * frequency * r.times.display;
        if phase.cos().abs() < 0.8 {
            continue; // near the turning points the first-order formula is not the point
        }
        let motion = Motion {
            speed: 0.0,
            yaw_rate: 0.0,
            eye_speed: amplitude * std::f64::consts::TAU * frequency * phase.cos(),
            latency,
            tracking_latency: 0.0,
        };
        let predicted = dynamic_misregistration(6.0 - eye.z, 0.0, r.eye_true.z, 6.0, &motion).abs()
            * ARCMIN_PER_RAD;
        let measured = r.metrics.unwrap().mean_arcmin;
        assert!(
            measured < predicted * 1.02 && measured > predicted * 0.92,
            "frame {}: measured {measured:.2}′, formula {predicted:.2}′",
            r.frame
        );
        checked += 1;
    }
    assert!(checked >= 6, "{checked}");
}

/// A turning vehicle and a swaying head at once: each frame's measured error is the formula's
/// *signed* sum of the two terms. The sway reverses, so the head term in turn adds to the yaw
/// term and takes from it; a sign error between them would swap those frames' errors (up to
/// 58′ against 2′ here). Tolerances as in the two tests above: 2 % of the yaw term, 8 % of
/// the head term (paraxial: off the display's axis a lateral eye error costs cos² less).
#[test]
fn the_yaw_and_head_terms_add_with_their_signs() {
    let wall = common::WallScene::default();
    let scene = wall.scene();
    let eye = scene.obstacle.in_obstacle_frame(scene.eye());
    let (amplitude, frequency, latency, tracking) = (0.008, 1.0, 0.1, 0.03);
    let yaw_rate = 5f64.to_radians();
    let mut o = options(latency, 20.0, 20.0, yaw_rate);
    o.timeline.duration = 1.0;
    o.timeline.latency_tracking = tracking;
    o.run.display = seethru::system::display::DisplayModel::Ideal;
    o.head = HeadMotion::Sway {
        amplitude,
        frequency,
    };
    let sway = o.head.clone();
    let how = common::measuring(Flip::Skipped);
    let run = run_sequence(&scene, o, how, &mut |_| Ok(())).unwrap();
    let (mut adding, mut opposing) = (0, 0);
    for r in &run.records {
        let t = r.times;
        // The eye's mean speed over the estimate's age: speed × age is its displacement.
        let moved = sway.eye(eye, t.display).x - sway.eye(eye, t.head).x;
        let motion = Motion {
            speed: 0.0,
            yaw_rate,
            eye_speed: moved / (t.display - t.head),
            latency: t.display - t.capture,
            tracking_latency: t.capture - t.head,
        };
        let term = |m: Motion| {
            dynamic_misregistration(6.0 - eye.z, 0.0, r.eye_true.z, 6.0, &m) * ARCMIN_PER_RAD
        };
        let yaw_term = term(Motion {
            eye_speed: 0.0,
            ..motion
        });
        let head_term = term(Motion {
            yaw_rate: 0.0,
            ..motion
        });
        let predicted = term(motion).abs();
        let measured = r.metrics.unwrap().mean_arcmin;
        let tolerance = 0.02 * yaw_term.abs() + 0.08 * head_term.abs();
        assert!(
            (measured - predicted).abs() <= tolerance,
            "frame {}: measured {measured:.2}′, formula {predicted:.2}′ (yaw {yaw_term:.2}′, head {head_term:.2}′)",
            r.frame
        );
        if head_term.abs() > 0.5 * yaw_term.abs() {
            match head_term.signum() == yaw_term.signum() {
                true => adding += 1,
                false => opposing += 1,
            }
        }
    }
    assert!(
        adding >= 4 && opposing >= 4,
        "{adding} adding, {opposing} opposing"
    );
}

/// A fisheye frontal camera: the display goes through the believed lens in every frame, as
/// `run` does, so a still sequence misregisters as the single run of the same instant.
#[test]
fn a_lens_goes_through_the_sequence_as_through_run() {
    let dir = tempfile::tempdir().unwrap();
    let small = [
        "--width",
        "96",
        "--frontal-width",
        "192",
        "--back-width",
        "32",
        "--spp",
        "1",
    ];
    let seq = dir.path().join("seq");
    let run = dir.path().join("run");
    let (ok, _, err) = common::seethru(
        &[
            &[
                "sequence",
                "scenes/das_fisheye.toml",
                "--out",
                seq.to_str().unwrap(),
            ][..],
            &[
                "--duration",
                "0.05",
                "--fps",
                "20",
                "--head",
                "still",
                "--flip",
            ],
            // The oracle sequence renders no back view: --back-width would be refused.
            &small[..4],
            &small[6..],
        ]
        .concat(),
    );
    assert!(ok, "{err}");
    let (ok, _, err) = common::seethru(
        &[
            &[
                "run",
                "scenes/das_fisheye.toml",
                "--out",
                run.to_str().unwrap(),
            ][..],
            &small,
        ]
        .concat(),
    );
    assert!(ok, "{err}");
    let metrics: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(run.join("metrics.json")).unwrap()).unwrap();
    let single = metrics["display"]["misregistration_arcmin"]["mean"]
        .as_f64()
        .unwrap();
    let csv = std::fs::read_to_string(seq.join("latency_0ms/frames.csv")).unwrap();
    let mut lines = csv.lines();
    let header: Vec<&str> = lines.next().unwrap().split(',').collect();
    let column = header
        .iter()
        .position(|c| *c == "misregistration_mean_arcmin")
        .unwrap_or_else(|| panic!("{header:?}"));
    let first: Vec<&str> = lines.next().unwrap().split(',').collect();
    let sequence: f64 = first[column].parse().unwrap();
    // A crop that ignored the lens would be off by degrees at the display's edges.
    assert!(
        (sequence - single).abs() <= 0.05 * single,
        "sequence {sequence}′ against run {single}′"
    );
    // --flip: the frame's FLIP, as the run's of the same instant.
    let flip_column = header.iter().position(|c| *c == "flip").unwrap();
    let flip: f64 = first[flip_column].parse().unwrap();
    let run_flip = metrics["display"]["flip_mean"].as_f64().unwrap();
    assert!(
        (flip - run_flip).abs() <= 0.1 * run_flip,
        "sequence FLIP {flip} against run {run_flip}"
    );
}

/// The first frame of `dir`'s preview.png (8-bit RGB) and the scale summary.json records.
fn preview_of(dir: &Path, extra: &[&str]) -> (image::RgbImage, f64, String) {
    let mut args = vec![
        "sequence",
        "scenes/das.toml",
        "--out",
        dir.to_str().unwrap(),
        "--duration",
        "0.2",
        "--fps",
        "20",
        "--speed",
        "50",
        "--latency-camera",
        "100",
        "--width",
        "96",
    ];
    args.extend(extra);
    let (ok, _, err) = common::seethru(&args);
    assert!(ok, "{err}");
    let run = dir.join("latency_100ms");
    let png = std::fs::read(run.join("preview.png")).unwrap();
    let first = image::load_from_memory(&png).unwrap().to_rgb8();
    let summary: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(run.join("summary.json")).unwrap()).unwrap();
    (
        first,
        summary["preview_heat_scale_arcmin"].as_f64().unwrap(),
        summary["preview_heat_scale"].as_str().unwrap().to_string(),
    )
}

/// The pixels of column `x` (top to bottom) and of the heat panel that are not grey: grey is
/// the caption, the white margins, blank pixels and the dimmed truth outside the display.
fn coloured(img: &image::RgbImage, xs: std::ops::Range<u32>) -> Vec<[u8; 3]> {
    let mut out = Vec::new();
    for y in 0..img.height() {
        for x in xs.clone() {
            let p = img.get_pixel(x, y).0;
            if !(p[0] == p[1] && p[1] == p[2]) {
                out.push(p);
            }
        }
    }
    out
}

#[test]
fn the_preview_has_a_colour_bar_whose_scale_heatmap_max_fixes() {
    use seethru::measure::maps::heat_color;
    let dir = tempfile::tempdir().unwrap();
    let (auto, auto_top, auto_how) = preview_of(&dir.path().join("auto"), &[]);
    let (tiny, tiny_top, tiny_how) =
        preview_of(&dir.path().join("tiny"), &["--heatmap-max", "0.000001"]);
    // The bar's column (170 px, its bar 25 px in) right of three panels with 4 px gaps.
    let bar_column = 170;
    for img in [&auto, &tiny] {
        assert!(img.width() > bar_column, "{}", img.width());
        let w = (img.width() - bar_column - 8) / 3;
        assert_eq!(3 * w + 8 + bar_column, img.width(), "no bar column");
        let bar = coloured(
            img,
            img.width() - bar_column + 25..img.width() - bar_column + 26,
        );
        // Top to bottom: the colour map from its top down to its bottom, tall enough to
        // read. Each colour is read back as the t in [0, 1] whose colour is nearest.
        assert!(bar.len() >= 70, "bar of {} pixels", bar.len());
        let t_of = |c: [u8; 3]| {
            (0..=1000)
                .map(|k| k as f32 / 1000.0)
                .min_by_key(|&t| {
                    let m = heat_color(t);
                    (0..3)
                        .map(|i| (c[i] as i32 - m[i] as i32).pow(2))
                        .sum::<i32>()
                })
                .unwrap()
        };
        let ts: Vec<f32> = bar.iter().map(|&c| t_of(c)).collect();
        assert!(ts[0] > 0.97 && *ts.last().unwrap() < 0.05, "{ts:?}");
        assert!(ts.windows(2).all(|p| p[1] <= p[0] + 0.02), "{ts:?}");
    }
    // A scale topping out at a millionth of an arc-minute clips every misregistration to
    // the top colour; the p99 scale does not.
    let heat = |img: &image::RgbImage| {
        let w = (img.width() - bar_column - 8) / 3;
        coloured(img, 2 * (w + 4)..3 * w + 8)
    };
    let (tiny_heat, auto_heat) = (heat(&tiny), heat(&auto));
    assert!(tiny_heat.len() > 50 && auto_heat.len() > 50);
    assert!(tiny_heat.iter().all(|&p| p == heat_color(1.0)));
    assert!(
        auto_heat.iter().filter(|&&p| p != heat_color(1.0)).count() > auto_heat.len() / 2,
        "the p99 scale clips most pixels"
    );
    // summary.json says which scale and how it was chosen.
    assert!((tiny_top - 1e-6).abs() < 1e-9, "{tiny_top}");
    assert_eq!(tiny_how, "fixed (--heatmap-max)");
    assert!(
        auto_top >= 1.0 && auto_how == "p99 of all frames",
        "{auto_top} {auto_how}"
    );
}

/// Every column of frames.csv and every figure of summary.json against what the sequence
/// was asked for: a swaying head (its path known in closed form), a display refreshing at
/// 4 Hz under 10 Hz frames (so images are held), 50 ms camera and 30 ms tracking latency,
/// a head-tracking bias of (2, −1, 0.5) cm.
/// The clock, the eye columns, the ages, the eye error and the eye's velocity come from the
/// sway and the refresh grid computed here; the summary's figures from the CSV's columns.
#[test]
fn frames_csv_and_summary_hold_what_the_sequence_was_asked_for() {
    use seethru::measure::sequence_files::{frames_csv, summary};
    let wall = common::WallScene::default();
    let scene = wall.scene();
    let eye0 = scene.obstacle.in_obstacle_frame(scene.eye());
    let (amplitude, frequency) = (0.03, 0.7);
    let mut o = options(0.05, 10.0, 4.0, 0.0);
    o.timeline.duration = 0.6;
    o.timeline.latency_tracking = 0.03;
    // A head-tracking bias, cm, obstacle frame: the estimate is off by it.
    o.run.head_bias_cm = [2.0, -1.0, 0.5];
    o.head = HeadMotion::Sway {
        amplitude,
        frequency,
    };
    let how = common::measuring(Flip::Skipped);
    let run = run_sequence(&scene, o.clone(), how, &mut |_| Ok(())).unwrap();
    let csv = frames_csv(&run.records, &o.timeline).unwrap();
    let mut lines = csv.lines();
    let header: Vec<&str> = lines.next().unwrap().split(',').collect();
    let rows: Vec<Vec<f64>> = lines
        .map(|l| l.split(',').map(|v| v.parse().unwrap()).collect())
        .collect();
    assert_eq!(rows.len(), 6);
    let columns: std::collections::HashMap<&str, Vec<f64>> = header
        .iter()
        .enumerate()
        .map(|(i, name)| (*name, rows.iter().map(|r| r[i]).collect()))
        .collect();
    let col = |name: &str| -> &[f64] { &columns[name] };
    let sway_x = |t: f64| eye0.x + amplitude * (std::f64::consts::TAU * frequency * t).sin();
    let close = |a: f64, b: f64, what: &str| assert!((a - b).abs() < 1e-9, "{what}: {a} vs {b}");
    let mut errors = Vec::new();
    for (k, row_t) in col("t_s").iter().copied().enumerate() {
        let t = k as f64 / 10.0;
        let refresh = (t * 4.0 + 1e-9).floor() / 4.0;
        let (capture, head) = (refresh - 0.05, refresh - 0.08);
        close(row_t, t, "t_s");
        close(col("frame")[k], k as f64, "frame");
        close(col("refresh_s")[k], refresh, "refresh_s");
        close(col("capture_s")[k], capture, "capture_s");
        close(col("head_sample_s")[k], head, "head_sample_s");
        close(col("latency_camera_ms")[k], 50.0, "latency_camera_ms");
        close(col("latency_tracking_ms")[k], 30.0, "latency_tracking_ms");
        close(col("hold_ms")[k], (t - refresh) * 1e3, "hold_ms");
        close(col("image_age_ms")[k], (t - capture) * 1e3, "image_age_ms");
        close(col("head_age_ms")[k], (t - head) * 1e3, "head_age_ms");
        for (axis, true_m) in [("x", sway_x(t)), ("y", eye0.y), ("z", eye0.z)] {
            close(col(&format!("eye_true_{axis}_m"))[k], true_m, "eye_true");
        }
        // The oracle head source: the true eye at the head sample's time plus the bias,
        // used unpredicted.
        let estimated = col("eye_estimated_x_m")[k];
        close(estimated, sway_x(head) + 0.02, "eye_estimated_x_m");
        close(
            col("eye_estimated_y_m")[k],
            eye0.y - 0.01,
            "eye_estimated_y_m",
        );
        close(
            col("eye_estimated_z_m")[k],
            eye0.z + 0.005,
            "eye_estimated_z_m",
        );
        for axis in ["x", "y", "z"] {
            let (used, estimated) = (
                format!("eye_used_{axis}_m"),
                format!("eye_estimated_{axis}_m"),
            );
            close(col(&used)[k], col(&estimated)[k], &used);
        }
        let used = glam::DVec3::new(
            col("eye_used_x_m")[k],
            col("eye_used_y_m")[k],
            col("eye_used_z_m")[k],
        );
        let error = (used - glam::DVec3::new(sway_x(t), eye0.y, eye0.z)).length() * 1e3;
        close(col("eye_error_mm")[k], error, "eye_error_mm");
        errors.push(error);
        let velocity = if k == 0 {
            0.0
        } else {
            (sway_x(t) - sway_x(t - 0.1)) / 0.1
        };
        close(col("eye_x_velocity_m_s")[k], velocity, "eye_x_velocity_m_s");
        close(col("eye_z_velocity_m_s")[k], 0.0, "eye_z_velocity_m_s");
        close(col("d2_m")[k], 6.0, "d2_m");
        let coverage = col("coverage")[k];
        assert!(coverage > 0.5 && coverage <= 1.0, "frame {k}: {coverage}");
        close(col("blank_fraction")[k], 1.0 - coverage, "blank_fraction");
    }
    // The eye moves and the images are held: some frames' errors differ, none is zero.
    assert!(errors.iter().all(|e| *e > 1.0), "{errors:?}");
    let s = summary(&run, &o.timeline);
    let mean = |v: &[f64]| v.iter().sum::<f64>() / v.len() as f64;
    let max = |v: &[f64]| v.iter().copied().fold(f64::NEG_INFINITY, f64::max);
    let min = |v: &[f64]| v.iter().copied().fold(f64::INFINITY, f64::min);
    let figure = |path: &str| s.pointer(path).and_then(|v| v.as_f64()).unwrap();
    assert_eq!(s["frames"], 6);
    close(
        figure("/latency_camera_ms"),
        50.0,
        "summary latency_camera_ms",
    );
    close(
        figure("/latency_tracking_ms"),
        30.0,
        "summary latency_tracking_ms",
    );
    for (path, expected) in [
        (
            "/misregistration_arcmin/mean_of_frame_means",
            mean(col("misregistration_mean_arcmin")),
        ),
        (
            "/misregistration_arcmin/mean_of_frame_p95",
            mean(col("misregistration_p95_arcmin")),
        ),
        (
            "/misregistration_arcmin/max_of_frame_p95",
            max(col("misregistration_p95_arcmin")),
        ),
        (
            "/misregistration_arcmin/max",
            max(col("misregistration_max_arcmin")),
        ),
        ("/coverage/mean", mean(col("coverage"))),
        ("/coverage/min", min(col("coverage"))),
        ("/missing_fraction_mean", mean(col("missing_fraction"))),
        ("/eye_error_mm/mean", mean(&errors)),
        ("/eye_error_mm/max", max(&errors)),
        (
            "/frames_per_second/system_loop",
            6.0 / figure("/seconds/system_total"),
        ),
        (
            "/frames_per_second/with_truth_and_metrics",
            6.0 / figure("/seconds/total"),
        ),
    ] {
        close(figure(path), expected, path);
    }
    // The means and maxima differ here, so a summary that swapped them would fail.
    assert!(max(&errors) > mean(&errors) * 1.05, "{errors:?}");
    // The system loop's total is its five stages' sum (the head's is zero here: the oracle
    // head source reads no image).
    let stages = ["moving", "frontal", "head", "compensation", "seethru"]
        .map(|stage| figure(&format!("/seconds/system/{stage}")));
    assert!(stages.iter().all(|&s| s >= 0.0), "{stages:?}");
    assert!([0, 1, 3, 4].iter().all(|&i| stages[i] > 0.0), "{stages:?}");
    close(
        figure("/seconds/system_total"),
        stages.iter().sum(),
        "system_total",
    );
}

/// The misregistration figures hold every point, with 5 to 10 % headroom above the highest
/// (and 2 to 5 % right of the longest latency); a curve below 1′ gets the axis to 1.1′.
#[test]
fn the_misregistration_figures_hold_their_points_with_a_little_headroom() {
    use seethru::measure::sequence_files::{latency_figure, over_time_figure};
    use seethru::measure::sequence_records::FrameMetrics;
    let wall = common::WallScene::default();
    let scene = wall.scene();
    let how = common::measuring(Flip::Skipped);
    let run = run_sequence(&scene, options(0.1, 10.0, 10.0, 0.3), how, &mut |_| Ok(())).unwrap();
    let mut low = run.records.clone();
    for r in &mut low {
        r.metrics = Some(FrameMetrics {
            mean_arcmin: 0.5,
            ..r.metrics.unwrap()
        });
    }
    let highest = |points: &[(f64, f64)]| points.iter().map(|p| p.1).fold(0.0, f64::max);
    let figure = over_time_figure(
        &[
            ("turning".into(), &run.records[..]),
            ("low".into(), &low[..]),
        ],
        0.9,
    );
    let top = highest(&figure.series[0].points);
    assert!(top > 5.0, "{top}");
    assert_eq!(figure.y_range.0, 0.0);
    assert!(
        figure.y_range.1 >= 1.05 * top && figure.y_range.1 <= 1.1 * top + 1e-9,
        "{:?} for {top}",
        figure.y_range
    );
    assert_eq!(figure.x_range, (0.0, 0.9));
    let figure = over_time_figure(&[("low".into(), &low[..])], 0.9);
    assert!(
        (figure.y_range.1 - 1.1).abs() < 1e-12,
        "{:?}",
        figure.y_range
    );
    // Latency (ms), mean, p95.
    let points = [(0.0, 1.0, 3.0), (50.0, 8.0, 20.0), (120.0, 15.0, 30.0)];
    let figure = latency_figure(&points);
    assert!(
        figure.y_range.1 >= 31.5 && figure.y_range.1 <= 33.0 + 1e-9,
        "{:?}",
        figure.y_range
    );
    assert!(
        figure.x_range.1 >= 122.4 && figure.x_range.1 <= 126.0 + 1e-9,
        "{:?}",
        figure.x_range
    );
    let p95: Vec<(f64, f64)> = points.iter().map(|p| (p.0, p.2)).collect();
    assert_eq!(figure.series[1].points, p95);
    let figure = latency_figure(&[(0.0, 0.2, 0.5), (0.5, 0.3, 0.6)]);
    assert!((figure.y_range.1 - 1.1).abs() < 1e-12 && (figure.x_range.1 - 1.05).abs() < 1e-12);
}

/// A display that fills only part of the driver's view (the wall scene's 30 × 20 cm display
/// under a 40° view): the window starts below the view's top row, and the preview holds the
/// whole window (under 320 pixels, so at full size) — three panels as wide as it, and at
/// least as tall — beside the colour bar; its heat panel dims the truth outside the display and
/// shows blank display pixels black; a caption is above them.
#[test]
fn the_preview_holds_a_window_below_the_views_top() {
    let dir = tempfile::tempdir().unwrap();
    // A frontal camera of ±10° sees less than the display asks for (±13.5°): blank pixels.
    let wall = common::WallScene {
        frontal_half_angle: 10.0,
        ..Default::default()
    };
    let scene = wall.file_in(dir.path());
    let out = dir.path().join("out");
    let (ok, _, err) = common::seethru(&[
        "sequence",
        scene.to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
        "--duration",
        "0.2",
        "--fps",
        "10",
        "--yaw-rate",
        "10",
        "--width",
        "96",
    ]);
    assert!(ok, "{err}");
    let run = out.join("latency_0ms");
    let summary: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(run.join("summary.json")).unwrap()).unwrap();
    let window: Vec<u32> = summary["window_px"]
        .as_array()
        .unwrap()
        .iter()
        .map(|v| v.as_u64().unwrap() as u32)
        .collect();
    let (ww, wh) = (window[2] - window[0], window[3] - window[1]);
    assert!(window[1] > 0 && ww.max(wh) <= 320, "{window:?}");
    let png = std::fs::read(run.join("preview.png")).unwrap();
    let preview = image::load_from_memory(&png).unwrap().to_rgb8();
    let bar_column = seethru::io::colour_bar::BAR_COLUMN;
    assert_eq!(preview.width(), 3 * ww + 8 + bar_column, "{window:?}");
    assert!(
        preview.height() >= wh,
        "{} for {window:?}",
        preview.height()
    );
    // The heat panel: outside the display (the window's margin and the obstacle's body), the
    // truth dimmed to grey, a sixth of its channels' sum; on it, the heat colours (never
    // grey). The panels' rows end at the last row whose truth is not the white padding.
    let pixel = |x: u32, y: u32| preview.get_pixel(x, y).0;
    let last = (0..preview.height())
        .rev()
        .find(|&y| pixel(0, y) != [255; 3])
        .unwrap();
    let (mut dimmed, mut blank, mut heat) = (0, 0, 0);
    for y in last + 1 - wh..=last {
        for x in 0..ww {
            let truth = pixel(x, y);
            let shown = pixel(2 * (ww + 4) + x, y);
            let grey = (truth.iter().map(|&c| c as u32).sum::<u32>() / 6) as u8;
            if shown == [grey; 3] {
                dimmed += 1;
            } else if shown == [0; 3] {
                blank += 1;
            } else {
                assert!(
                    shown[0] != shown[1] || shown[1] != shown[2],
                    "({x}, {y}): {shown:?}"
                );
                heat += 1;
            }
        }
    }
    assert!(
        dimmed > 200 && blank > 50 && heat > 200,
        "{dimmed} dimmed, {blank} blank, {heat} heat"
    );
    // Above the panels, the caption: at least a line's strip, with dark text on it.
    let top = last + 1 - wh;
    assert!(top >= seethru::io::caption::strip_height(1), "{top}");
    let text = (0..top)
        .flat_map(|y| (0..preview.width()).map(move |x| (x, y)))
        .filter(|&(x, y)| pixel(x, y).iter().all(|&c| c < 100))
        .count();
    assert!(text > 20, "{text} dark pixels in the caption");
}

/// `--head-source model`: the estimate delivered at a head sample's time is of the eye one
/// tracker latency (1/30 s) earlier, with the tracker's 2 mm lateral noise. A 10 cm, 1 Hz
/// sway moves the eye up to 21 mm in a latency: the median lateral residual against the
/// sway's closed form one latency back stays within the noise, while the eye of the sample
/// time itself is off by about 15 mm.
#[test]
fn the_model_head_source_estimates_the_eye_one_latency_back() {
    let wall = common::WallScene::default();
    let scene = wall.scene();
    let eye0 = scene.obstacle.in_obstacle_frame(scene.eye());
    let mut o = options(0.0, 30.0, 30.0, 0.0);
    o.timeline.duration = 1.0;
    o.run.head = seethru::system::options::HeadSource::Model;
    o.run.width = Some(32);
    o.run.frontal_width = Some(64);
    let (amplitude, frequency) = (0.1, 1.0);
    o.head = HeadMotion::Sway {
        amplitude,
        frequency,
    };
    let sway = |t: f64| eye0.x + amplitude * (std::f64::consts::TAU * frequency * t).sin();
    let latency = 1.0 / 30.0;
    let mut system = SystemLoop::new(&scene, o).unwrap();
    let frames = system.options.timeline.frames();
    assert_eq!(frames, 30);
    let (mut back, mut now) = (Vec::new(), Vec::new());
    for k in 0..frames {
        let t = system.options.timeline.times(k).head;
        let x = system.show(k).unwrap().eye_estimated.x;
        back.push((x - sway(t - latency)).abs());
        now.push((x - sway(t)).abs());
    }
    let median = |mut v: Vec<f64>| {
        v.sort_by(f64::total_cmp);
        v[v.len() / 2]
    };
    let (back, now) = (median(back), median(now));
    assert!(back < 0.003, "median residual one latency back {back} m");
    assert!(now > 0.008, "median residual at the sample time {now} m");
}

/// `d2 auto` in a sequence: every refresh renders the whole frontal image (the median depth
/// is read from it) and finds the wall 6 m ahead of the display.
#[test]
fn a_sequence_with_d2_auto_finds_the_wall_each_refresh() {
    let wall = common::WallScene::default();
    let scene = wall.scene();
    let mut o = options(0.05, 20.0, 20.0, 0.0);
    o.run.d2 = WorkingDistance::Auto;
    o.run.frontal_width = Some(128);
    let mut system = SystemLoop::new(&scene, o).unwrap();
    let frames = system.options.timeline.frames();
    for k in 0..frames {
        let d2 = system.show(k).unwrap().d2_used.unwrap();
        assert!((d2 - 6.0).abs() < 0.06, "frame {k}: d2 auto = {d2} m");
    }
    let frontal = system.rig.base.frontal;
    assert_eq!(
        system.frontal_pixels,
        frames as u64 * u64::from(frontal.width) * u64::from(frontal.height)
    );
}

/// A crop that leaves the frontal camera's view stops a sequence as it stops `run`, with the
/// same message (the side, how far, where the eye may be) and the refresh's time; with
/// `--outside black` the frame shows black there and counts it.
#[test]
fn a_crop_outside_the_frontal_view_is_refused_as_run_refuses_it() {
    let wall = common::WallScene {
        frontal_half_angle: 14.0,
        ..Default::default()
    };
    let scene = wall.scene();
    let o = options(0.05, 20.0, 20.0, 0.0);
    let err = SystemLoop::new(&scene, o.clone())
        .unwrap()
        .show(0)
        .map(|_| ())
        .unwrap_err();
    let err = format!("{err:#}");
    let ctx = RenderContext::new(scene.clone()).unwrap();
    let single = seethru::system::pipeline::run(&ctx, &o.run)
        .map(|_| ())
        .unwrap_err()
        .to_string();
    assert!(
        single.starts_with("the crop leaves the frontal camera's view on the ")
            && single.contains("the eye must stay within x ∈ ["),
        "{single}"
    );
    assert_eq!(err, format!("at t = 0 s: {single}"));
    let mut black = o;
    black.run.outside = seethru::system::options::Outside::Black;
    let how = common::measuring(Flip::Skipped);
    let run = run_sequence(&scene, black, how, &mut |_| Ok(())).unwrap();
    let coverage = run.records[0].metrics.unwrap().coverage;
    assert!(coverage > 0.0 && coverage < 1.0, "coverage {coverage}");
}
