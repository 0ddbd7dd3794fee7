//! Bring your own method: an independent numpy implementation of the planar crop, reading
//! only a capture's calibration.json and head.json, scored by `seethru score`, agrees with the
//! built-in planar method; shifting its map by k display pixels raises the misregistration by
//! the angle k display pixels subtend at the eye; a depth forward warp from the captured depth
//! image lands between planar and the built-in depth method.

mod common;

use std::path::{Path, PathBuf};
use std::process::Command;

use common::python_env::python_with;
use common::seethru;
use serde_json::Value;

const SIZES: [&str; 6] = [
    "--width",
    "160",
    "--frontal-width",
    "320",
    "--back-width",
    "160",
];

fn example(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("examples/python")
        .join(name)
}

fn run_ok(args: &[&str]) -> String {
    let (ok, out, err) = seethru(args);
    assert!(ok, "seethru {args:?} failed: {err}");
    out + &err
}

fn python(script: &str, args: &[&Path], extra: &[&str]) {
    let out = Command::new(python_with(&["numpy"]))
        .arg(example(script))
        .args(args)
        .args(extra)
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{script}: {}",
        String::from_utf8_lossy(&out.stderr)
    );
}

fn json(path: &Path) -> Value {
    serde_json::from_str(&std::fs::read_to_string(path).unwrap()).unwrap()
}

/// The `Y` channel of a misregistration.exr (arcmin per driver pixel, NaN off the display).
fn misregistration_map(dir: &Path) -> Vec<f32> {
    let channels = common::exr_channels(&dir.join("misregistration.exr"));
    match channels
        .into_iter()
        .find(|(name, _)| name == "Y")
        .map(|(_, v)| v)
    {
        Some(exr::prelude::FlatSamples::F32(v)) => v,
        _ => panic!("misregistration.exr has no f32 channel Y"),
    }
}

fn capture(dir: &Path, extra: &[&str]) -> PathBuf {
    let inputs = dir.join("inputs");
    let mut args = vec![
        "capture",
        "scenes/das.toml",
        "--out",
        inputs.to_str().unwrap(),
    ];
    args.extend(SIZES);
    args.extend(extra);
    run_ok(&args);
    inputs
}

fn score(inputs: &Path, map: &Path, out: &Path) -> Value {
    run_ok(&[
        "score",
        inputs.to_str().unwrap(),
        "--map",
        map.to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
    ]);
    json(&out.join("metrics.json"))
}

fn mean(m: &Value) -> f64 {
    m["display"]["misregistration_arcmin"]["mean"]
        .as_f64()
        .unwrap()
}

#[test]
fn the_numpy_planar_crop_scores_as_the_builtin_planar_method() {
    let dir = tempfile::tempdir().unwrap();
    let inputs = capture(dir.path(), &[]);
    let map = dir.path().join("planar.npy");
    python("planar_method.py", &[&inputs, &map], &[]);
    let scored = dir.path().join("scored");
    let mine = score(&inputs, &map, &scored);
    let builtin = dir.path().join("builtin");
    let mut args = vec!["run", "scenes/das.toml", "--out", builtin.to_str().unwrap()];
    args.extend(SIZES);
    run_ok(&args);
    let theirs = json(&builtin.join("metrics.json"));
    for key in ["display_pixels", "blank_pixels", "undefined_pixels"] {
        assert_eq!(mine[key], theirs[key], "{key}");
    }
    // The colours are sampled at the same points up to float32 rounding of the map.
    let psnr = |m: &Value| m["display"]["psnr_db"].as_f64().unwrap();
    assert!((psnr(&mine) - psnr(&theirs)).abs() < 0.05);
    // Per pixel: the same misregistration, except where the map's float32 rounding takes a
    // point across a frontal pixel's edge: the shown point is then a neighbour's, at most
    // one diagonal frontal pixel away — the resampling quantum.
    let calibration = json(&inputs.join("calibration.json"));
    let fx = calibration["frontal"]["K"][0][0].as_f64().unwrap();
    let quantum_arcmin = (2f64.sqrt() / fx).atan().to_degrees() * 60.0;
    let (a, b) = (misregistration_map(&scored), misregistration_map(&builtin));
    let both: Vec<(f32, f32)> = a
        .iter()
        .zip(&b)
        .filter(|(x, y)| x.is_finite() || y.is_finite())
        .map(|(&x, &y)| (x, y))
        .collect();
    let differing = both.iter().filter(|(x, y)| x != y).count();
    assert!(
        differing * 20 <= both.len(),
        "{differing} of {} pixels differ: more than rounding at pixel edges",
        both.len()
    );
    for (x, y) in &both {
        assert!(
            ((x - y).abs() as f64) <= quantum_arcmin,
            "{x} vs {y} arcmin: more than the quantum {quantum_arcmin}"
        );
    }
    assert!(
        (mean(&mine) - mean(&theirs)).abs()
            <= quantum_arcmin * differing as f64 / both.len() as f64 + 1e-9
    );
}

#[test]
fn the_readmes_dozen_line_method_scores_as_the_builtin_planar_method_at_infinity() {
    let dir = tempfile::tempdir().unwrap();
    let inputs = capture(dir.path(), &[]);
    let map = dir.path().join("mine.npy");
    python("dozen_lines.py", &[&inputs, &map], &[]);
    let mine = score(&inputs, &map, &dir.path().join("scored"));
    let builtin = dir.path().join("builtin");
    let mut args = vec!["run", "scenes/das.toml", "--out", builtin.to_str().unwrap()];
    args.extend(["--d2", "inf"]);
    args.extend(SIZES);
    run_ok(&args);
    let theirs = json(&builtin.join("metrics.json"));
    for key in ["display_pixels", "blank_pixels", "undefined_pixels"] {
        assert_eq!(mine[key], theirs[key], "{key}");
    }
    // Every pixel within one diagonal frontal pixel's angle: the mean is too.
    let fx = json(&inputs.join("calibration.json"))["frontal"]["K"][0][0]
        .as_f64()
        .unwrap();
    let quantum_arcmin = (2f64.sqrt() / fx).atan().to_degrees() * 60.0;
    assert!(
        (mean(&mine) - mean(&theirs)).abs() <= quantum_arcmin,
        "{} vs {} arcmin",
        mean(&mine),
        mean(&theirs)
    );
}

#[test]
fn a_map_shifted_by_k_display_pixels_adds_the_angle_they_subtend() {
    let dir = tempfile::tempdir().unwrap();
    let inputs = capture(dir.path(), &[]);
    let (map0, mapk) = (dir.path().join("m0.npy"), dir.path().join("mk.npy"));
    let k = 60;
    python("planar_method.py", &[&inputs, &map0], &[]);
    python(
        "planar_method.py",
        &[&inputs, &mapk],
        &["--shift", &k.to_string()],
    );
    let m0 = score(&inputs, &map0, &dir.path().join("s0"));
    let mk = score(&inputs, &mapk, &dir.path().join("sk"));
    // The prediction from the geometry: display pixel i now shows what i − k showed, k pixel
    // pitches to the left on the display; seen from the eye that is the angle between the
    // rays to the two points, averaged over the display pixels (each seen about equally).
    let calibration = json(&inputs.join("calibration.json"));
    let d = &calibration["display"];
    let [w, h] = [0, 1].map(|i| d["resolution_px"][i].as_u64().unwrap() as usize);
    let (dw, dh) = (
        d["width_m"].as_f64().unwrap(),
        d["height_m"].as_f64().unwrap(),
    );
    let eye: Vec<f64> =
        serde_json::from_value(json(&inputs.join("truth/truth.json"))["eye_world_m"].clone())
            .unwrap();
    let m: Vec<Vec<f64>> = serde_json::from_value(d["world_from_display"].clone()).unwrap();
    let world = |x: f64, y: f64| -> [f64; 3] {
        [0, 1, 2].map(|r| m[r][0] * x + m[r][1] * y + m[r][3] - eye[r])
    };
    let angle = |a: [f64; 3], b: [f64; 3]| {
        let dot: f64 = (0..3).map(|i| a[i] * b[i]).sum();
        let cross = [
            a[1] * b[2] - a[2] * b[1],
            a[2] * b[0] - a[0] * b[2],
            a[0] * b[1] - a[1] * b[0],
        ];
        cross.iter().map(|c| c * c).sum::<f64>().sqrt().atan2(dot)
    };
    let (mut sum, mut n) = (0.0, 0);
    for j in 0..h {
        for i in k..w {
            let y = (0.5 - (j as f64 + 0.5) / h as f64) * dh;
            let x = ((i as f64 + 0.5) / w as f64 - 0.5) * dw;
            sum += angle(world(x, y), world(x - k as f64 * dw / w as f64, y));
            n += 1;
        }
    }
    let predicted = sum / n as f64 * 60f64.to_degrees();
    // |e + s| lies within |s| ± |e| for the planar error e: the shift's angle within the
    // unshifted mean (and a tenth of a driver pixel for the coarse view's sampling).
    let slack = mean(&m0) + 0.1 * m0["driver_pixel_arcmin"].as_f64().unwrap();
    assert!(
        (mean(&mk) - predicted).abs() <= slack,
        "shifted by {k}: {} arcmin, predicted {predicted} ± {slack}",
        mean(&mk)
    );
    assert!(
        predicted > 3.0 * slack,
        "the shift must dominate: {predicted} vs {slack}"
    );
    // The k uncovered columns show nothing: blank, counted, not dropped.
    assert!(mk["blank_pixels"].as_u64().unwrap() > 0);
    assert!(mk["coverage"].as_f64().unwrap() < 1.0);
}

#[test]
fn a_depth_forward_warp_lands_between_planar_and_depth_ideal_in_compares_table() {
    let dir = tempfile::tempdir().unwrap();
    let inputs = capture(dir.path(), &["--depth"]);
    let map = dir.path().join("warp.npy");
    python("depth_warp_method.py", &[&inputs, &map], &[]);
    let table = dir.path().join("table");
    let methods = format!("planar-inf,depth-ideal,map:warp={}", map.display());
    let mut args = vec![
        "compare",
        "scenes/das.toml",
        "--methods",
        &methods,
        "--out",
        table.to_str().unwrap(),
    ];
    args.extend(SIZES);
    run_ok(&args);
    let rows = json(&table.join("compare.json"))["rows"].clone();
    let row = |name: &str| {
        rows.as_array()
            .unwrap()
            .iter()
            .find(|r| r["method"] == name)
            .unwrap_or_else(|| panic!("no row {name} in {rows}"))["misregistration_mean_arcmin"]
            .as_f64()
            .unwrap()
    };
    let (planar, ideal, warp) = (row("planar-inf"), row("depth-ideal"), row("map:warp"));
    assert!(
        ideal < warp && warp < planar,
        "depth-ideal {ideal} < warp {warp} < planar-inf {planar} arcmin expected"
    );
    assert_eq!(
        rows[2]["method"], "map:warp",
        "the table keeps --methods' order"
    );
}

#[test]
fn a_map_for_another_capture_is_refused_by_its_fingerprint() {
    let dir = tempfile::tempdir().unwrap();
    let inputs = capture(dir.path(), &[]);
    let map = dir.path().join("m.npy");
    python("planar_method.py", &[&inputs, &map], &[]);
    // Another head estimate; and the same images for a driver's view one pixel wider (the
    // fingerprint did not cover --width, so the map was scored in another capture's view).
    let wider: Vec<&str> = SIZES
        .iter()
        .map(|&w| if w == "160" { "161" } else { w })
        .collect();
    for (name, args) in [("bias", vec!["--head-bias-cm", "1,0,0"]), ("wider", wider)] {
        let other = dir.path().join(name);
        let mut capture_args = vec![
            "capture",
            "scenes/das.toml",
            "--out",
            other.to_str().unwrap(),
        ];
        capture_args.extend(&args);
        if name == "bias" {
            capture_args.extend(SIZES);
        }
        run_ok(&capture_args);
        let (ok, _, err) = seethru(&[
            "score",
            other.to_str().unwrap(),
            "--map",
            map.to_str().unwrap(),
            "--out",
            dir.path().join("s").to_str().unwrap(),
        ]);
        assert!(!ok, "{name}");
        assert!(
            err.starts_with("error:") && err.contains("made for capture") && err.contains("m.npy"),
            "{name}: {err}"
        );
        assert_eq!(err.lines().count(), 1, "{err}");
    }
}

#[test]
fn bad_maps_and_display_images_get_one_line_each_and_outside_points_count_as_blank() {
    use seethru::io::display_map::write_npy_f32;
    let dir = tempfile::tempdir().unwrap();
    let inputs = capture(dir.path(), &[]);
    let calibration = json(&inputs.join("calibration.json"));
    let size = &calibration["display"]["resolution_px"];
    let (w, h) = (
        size[0].as_u64().unwrap() as usize,
        size[1].as_u64().unwrap() as usize,
    );
    let file = |name: &str| dir.path().join(name);
    let score_with = |flag: &str, path: &Path| {
        seethru(&[
            "score",
            inputs.to_str().unwrap(),
            flag,
            path.to_str().unwrap(),
            "--out",
            file("scored").to_str().unwrap(),
        ])
    };
    // Each bad input: its file, and what the one line must say.
    write_npy_f32(
        &file("tall.npy"),
        &[h + 1, w, 2],
        &vec![1.0; (h + 1) * w * 2],
    )
    .unwrap();
    write_npy_f32(&file("rgb.npy"), &[h, w, 3], &vec![1.0; h * w * 3]).unwrap();
    write_npy_f32(&file("nan.npy"), &[h, w, 2], &vec![f32::NAN; h * w * 2]).unwrap();
    seethru::io::frame_files::write_png(&file("small.png"), 2, 2, vec![0; 12]).unwrap();
    // Every point inside a 1280-wide frontal image, none inside the capture's 320×180 one (a
    // map made for another frontal size showed a blank display, scored as coverage 0).
    write_npy_f32(
        &file("wide.npy"),
        &[h, w, 2],
        &[[900.0, 100.0]; 1].repeat(h * w).concat(),
    )
    .unwrap();
    // One point inside is enough (the rest counts as blank, below).
    let mut one = [[900.0_f32, 100.0]; 1].repeat(h * w);
    one[0] = [319.4, 179.4];
    write_npy_f32(&file("one_inside.npy"), &[h, w, 2], &one.concat()).unwrap();
    assert!(score_with("--map", &file("one_inside.npy")).0);
    std::fs::remove_dir_all(file("scored")).unwrap();
    let cases = [
        (
            "--map",
            "wide.npy",
            "inside the 320×180 frontal image".to_string(),
        ),
        ("--map", "tall.npy", format!("({h}, {w}, 2)")),
        ("--map", "rgb.npy", "3 channels".to_string()),
        ("--map", "nan.npy", "NaN".to_string()),
        ("--display-image", "small.png", format!("{w}×{h}")),
    ];
    for (flag, name, says) in &cases {
        let (ok, _, err) = score_with(flag, &file(name));
        assert!(!ok, "{name} must be refused");
        assert!(
            err.starts_with("error:") && err.contains(name) && err.contains(says.as_str()),
            "{name}: `{err}` should name the file and say {says}"
        );
        assert_eq!(err.trim_end().lines().count(), 1, "{err}");
        assert!(!file("scored").exists(), "{name}: nothing is written");
    }
    // A map whose left half points outside the frontal image: scored, that half blank.
    let planar = file("planar.npy");
    python("planar_method.py", &[&inputs, &planar], &[]);
    let full = score(&inputs, &planar, &file("full"));
    let mut half = seethru::io::display_map::read_map(&planar).unwrap();
    for (k, p) in half.xy.iter_mut().enumerate() {
        if k % w < w / 2 {
            p[0] = -1e4;
        }
    }
    let flat: Vec<f32> = half.xy.iter().flatten().copied().collect();
    let halved = file("half.npy");
    write_npy_f32(&halved, &[h, w, 2], &flat).unwrap();
    let m = score(&inputs, &halved, &file("half"));
    let blank = |m: &Value| m["blank_pixels"].as_u64().unwrap();
    assert!(
        blank(&m) > blank(&full) && m["coverage"].as_f64() < full["coverage"].as_f64(),
        "outside points must count as blank: {} vs {}",
        blank(&m),
        blank(&full)
    );
}
