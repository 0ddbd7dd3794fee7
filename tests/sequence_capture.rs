//! `sequence --capture DIR` writes one `seethru capture` folder per refresh with its times;
//! the example numpy planar method, run on each folder, scored by `sequence --maps DIR`,
//! gives the built-in planar sequence's per-frame misregistration within the resampling
//! quantum; a frame's shifted map raises that frame's misregistration only; bad maps get one
//! `error:` line naming the file and the frame.

mod common;

use std::path::{Path, PathBuf};
use std::process::Command;

use common::python_env::python_with;
use common::seethru;
use serde_json::Value;

/// Three frames at 10 Hz, the vehicle driving at 40 km/h, the head swaying, the image 50 ms
/// late (the frontal image fine enough that the resampling quantum is about 10′): the rig's world pose and the head estimate differ per frame.
const FPS: f64 = 10.0;
const SPEED_KMH: f64 = 40.0;
const LATENCY_S: f64 = 0.05;
const SEQUENCE: [&str; 14] = [
    "--frontal-width",
    "960",
    "--duration",
    "0.3",
    "--fps",
    "10",
    "--width",
    "96",
    "--speed",
    "40",
    "--head",
    "sway",
    "--latency-camera",
    "50",
];
const FRAMES: usize = 3;

fn sequence(out: &Path, extra: &[&str]) -> (bool, String) {
    let mut args = vec![
        "sequence",
        "scenes/das.toml",
        "--out",
        out.to_str().unwrap(),
    ];
    args.extend(SEQUENCE);
    args.extend(extra);
    let (ok, out, err) = seethru(&args);
    (ok, out + &err)
}

fn sequence_ok(out: &Path, extra: &[&str]) {
    let (ok, text) = sequence(out, extra);
    assert!(ok, "{text}");
}

fn json(path: &Path) -> Value {
    serde_json::from_str(&std::fs::read_to_string(path).unwrap()).unwrap()
}

fn folder(k: usize) -> String {
    format!("frame_{k:05}")
}

/// Captures the sequence into `dir/cap`, its metrics into `dir/builtin`.
fn capture(dir: &Path) -> PathBuf {
    let cap = dir.join("cap");
    sequence_ok(&dir.join("builtin"), &["--capture", cap.to_str().unwrap()]);
    cap
}

/// The example planar method on every frame's folder, maps into `dir/maps`; `--shift` on
/// frame `shifted`.
fn planar_maps(cap: &Path, maps: &Path, shifted: Option<(usize, u32)>) {
    std::fs::create_dir_all(maps).unwrap();
    let script = common::repo_path("examples/python/planar_method.py");
    for k in 0..FRAMES {
        let mut cmd = Command::new(python_with(&["numpy"]));
        cmd.arg(&script)
            .arg(cap.join(folder(k)))
            .arg(maps.join(format!("{}.npy", folder(k))));
        if let Some((frame, px)) = shifted
            && frame == k
        {
            cmd.args(["--shift", &px.to_string()]);
        }
        let out = cmd.output().unwrap();
        assert!(
            out.status.success(),
            "{}",
            String::from_utf8_lossy(&out.stderr)
        );
    }
}

/// Per frame, a column of `frames.csv`.
fn column(out: &Path, name: &str) -> Vec<f64> {
    let text = std::fs::read_to_string(out.join("latency_50ms/frames.csv")).unwrap();
    let mut lines = text.lines();
    let header: Vec<&str> = lines.next().unwrap().split(',').collect();
    let at = header.iter().position(|h| *h == name).unwrap();
    lines
        .map(|l| l.split(',').nth(at).unwrap().parse().unwrap())
        .collect()
}

/// One diagonal frontal pixel's angle, arcmin: the resampling quantum (as tests/byo_method.rs).
fn quantum_arcmin(cap: &Path) -> f64 {
    let fx = json(&cap.join("frame_00000/calibration.json"))["frontal"]["K"][0][0]
        .as_f64()
        .unwrap();
    (2f64.sqrt() / fx).atan().to_degrees() * 60.0
}

#[test]
fn the_capture_holds_one_capture_folder_per_refresh_with_its_times_and_pose() {
    let dir = tempfile::tempdir().unwrap();
    let cap = capture(dir.path());
    let index = json(&cap.join("frames.json"));
    let rows = index["frames"].as_array().unwrap();
    assert_eq!(rows.len(), FRAMES);
    let speed = SPEED_KMH / 3.6;
    for (k, row) in rows.iter().enumerate() {
        let t = k as f64 / FPS;
        let f = |key: &str| row[key].as_f64().unwrap();
        assert_eq!(row["folder"], folder(k));
        assert!((f("display_time_s") - t).abs() < 1e-12);
        assert!((f("capture_time_s") - (t - LATENCY_S)).abs() < 1e-12);
        assert!((f("head_sample_time_s") - (t - LATENCY_S)).abs() < 1e-12);
        // The rig rides with the vehicle: its world pose is the capture time's, the vehicle
        // having driven speed × t along −z (das's obstacle starts at z = −0.75 m).
        let pose = &row["world_from_obstacle_at_capture"];
        let z = pose[2][3].as_f64().unwrap();
        assert!(
            (z - (-0.75 - speed * (t - LATENCY_S))).abs() < 1e-9,
            "frame {k}: z {z}"
        );
        // The folder's calibration is that pose, its head estimate in the same world.
        let frame = cap.join(folder(k));
        let calibration = json(&frame.join("calibration.json"));
        assert_eq!(&calibration["obstacle_frame"]["world_from_obstacle"], pose);
        let head = &json(&frame.join("head.json"))["head"];
        let (world, obstacle) = (&head["eye_world_m"], &head["eye_obstacle_m"]);
        let dz = world[2].as_f64().unwrap() - obstacle[2].as_f64().unwrap();
        assert!((dz - z).abs() < 1e-9, "frame {k}: eye z offset {dz} vs {z}");
        // Whole images, not only the pixels the built-in method reads (an outside method may
        // read any): a pixel left unrendered would be black.
        for file in ["frontal.png", "back.png"] {
            let image = image::open(frame.join(file)).unwrap().to_rgb8();
            let black = image.pixels().filter(|p| p.0 == [0; 3]).count();
            assert!(
                black * 1000 < image.len() / 3,
                "{k}: {file} has {black} black pixels"
            );
        }
        let truth = json(&frame.join("truth/truth.json"));
        assert!(truth["eye_world_m"].is_array());
    }
    // Each refresh has a fingerprint of its own (the images differ as the vehicle moves).
    let prints: std::collections::BTreeSet<String> = (0..FRAMES)
        .map(|k| json(&cap.join(folder(k)).join("capture.json"))["fingerprint"].to_string())
        .collect();
    assert_eq!(prints.len(), FRAMES);
}

#[test]
fn per_frame_numpy_planar_maps_score_as_the_builtin_planar_sequence() {
    let dir = tempfile::tempdir().unwrap();
    let cap = capture(dir.path());
    let maps = dir.path().join("maps");
    planar_maps(&cap, &maps, None);
    let scored = dir.path().join("scored");
    sequence_ok(&scored, &["--maps", maps.to_str().unwrap()]);
    let builtin = dir.path().join("builtin");
    let quantum = quantum_arcmin(&cap);
    for key in ["display_pixels", "coverage", "blank_fraction"] {
        assert_eq!(column(&scored, key), column(&builtin, key), "{key}");
    }
    let (mine, theirs) = (
        column(&scored, "misregistration_mean_arcmin"),
        column(&builtin, "misregistration_mean_arcmin"),
    );
    assert_eq!(mine.len(), FRAMES);
    for (k, (a, b)) in mine.iter().zip(&theirs).enumerate() {
        assert!(
            (a - b).abs() <= quantum,
            "frame {k}: {a} vs {b} arcmin, more than the quantum {quantum}"
        );
    }
    // The frames differ from each other (the head sways, the image is late): a map scored
    // against the wrong frame would show.
    assert!((theirs[0] - theirs[2]).abs() > 2.0 * quantum, "{theirs:?}");
    // The summary has the same figures.
    let s = |d: &Path| {
        json(&d.join("latency_50ms/summary.json"))["misregistration_arcmin"]["mean_of_frame_means"]
            .as_f64()
            .unwrap()
    };
    assert!((s(&scored) - s(&builtin)).abs() <= quantum);
}

#[test]
fn a_shifted_map_raises_only_its_frames_misregistration() {
    let dir = tempfile::tempdir().unwrap();
    let cap = capture(dir.path());
    let maps = dir.path().join("maps");
    planar_maps(&cap, &maps, Some((1, 20)));
    let scored = dir.path().join("scored");
    sequence_ok(&scored, &["--maps", maps.to_str().unwrap()]);
    let quantum = quantum_arcmin(&cap);
    let mine = column(&scored, "misregistration_mean_arcmin");
    let theirs = column(&dir.path().join("builtin"), "misregistration_mean_arcmin");
    for k in [0, 2] {
        assert!((mine[k] - theirs[k]).abs() <= quantum, "frame {k}");
    }
    assert!(
        mine[1] > theirs[1] + 3.0 * quantum,
        "frame 1 shifted: {} vs {}",
        mine[1],
        theirs[1]
    );
    let blank = column(&scored, "blank_fraction");
    assert!(
        blank[1] > 0.0 && blank[0] == 0.0 && blank[2] == 0.0,
        "{blank:?}"
    );
}

fn one_error_line(text: &str, names: &[&str]) {
    assert!(
        text.starts_with("error: ") && text.trim_end().lines().count() == 1,
        "{text}"
    );
    for n in names {
        assert!(text.contains(n), "{text} should name {n}");
    }
}

#[test]
fn bad_maps_get_one_error_line_naming_the_file_and_the_frame() {
    let dir = tempfile::tempdir().unwrap();
    let cap = capture(dir.path());
    let maps = dir.path().join("maps");
    planar_maps(&cap, &maps, None);
    let out = dir.path().join("out");
    let maps_arg = maps.to_str().unwrap();
    // A map places a flat display's pixels: neither the ideal display nor a curved one (the
    // cabin's, 100 × 600 pixels: maps of its size) has them.
    let cabin_maps = dir.path().join("cabin_maps");
    std::fs::create_dir_all(&cabin_maps).unwrap();
    for k in 0..FRAMES {
        let status = Command::new(python_with(&["numpy"]))
            .args([
                "-c",
                "import numpy, sys; numpy.save(sys.argv[1], numpy.zeros((600, 100, 2), numpy.float32))",
            ])
            .arg(cabin_maps.join(format!("{}.npy", folder(k))))
            .status()
            .unwrap();
        assert!(status.success());
    }
    for (scene, maps, extra, words) in [
        (
            "scenes/das.toml",
            &maps,
            &["--display", "ideal"][..],
            "--display",
        ),
        (
            "scenes/cabin.toml",
            &cabin_maps,
            &[][..],
            "flat display's pixels",
        ),
    ] {
        let mut args = vec!["sequence", scene, "--out", out.to_str().unwrap()];
        args.extend(SEQUENCE);
        args.extend(["--maps", maps.to_str().unwrap()]);
        args.extend(extra);
        let (ok, o, e) = seethru(&args);
        assert!(!ok, "{scene} {extra:?}");
        one_error_line(&(o + &e), &["--maps", words]);
    }
    // Made for another capture: the same sequence without the latency.
    let (ok, text) = {
        let mut args = vec![
            "sequence",
            "scenes/das.toml",
            "--out",
            out.to_str().unwrap(),
        ];
        args.extend(&SEQUENCE[..12]);
        args.extend(["--maps", maps_arg]);
        let (ok, o, e) = seethru(&args);
        (ok, o + &e)
    };
    assert!(!ok);
    one_error_line(&text, &["frame_00000.npy", "frame 0", "made for capture"]);
    // The wrong size: a (2, 3, 2) map for frame 1.
    let frame1 = maps.join("frame_00001.npy");
    let good = std::fs::read(&frame1).unwrap();
    let status = Command::new(python_with(&["numpy"]))
        .args([
            "-c",
            "import numpy, sys; numpy.save(sys.argv[1], numpy.zeros((2, 3, 2), numpy.float32))",
        ])
        .arg(&frame1)
        .status()
        .unwrap();
    assert!(status.success());
    let (ok, text) = sequence(&out, &["--maps", maps_arg]);
    assert!(!ok);
    one_error_line(&text, &["frame_00001.npy", "frame 1", "3×2"]);
    // Missing.
    std::fs::write(&frame1, good).unwrap();
    std::fs::remove_file(maps.join("frame_00002.npy")).unwrap();
    let (ok, text) = sequence(&out, &["--maps", maps_arg]);
    assert!(!ok);
    one_error_line(&text, &["frame_00002.npy", "frame 2"]);
    // Nothing written by a refused run.
    assert!(!out.exists());
    // The maps replace the method: a method flag would be ignored.
    let (ok, text) = sequence(&out, &["--maps", maps_arg, "--method", "none"]);
    assert!(!ok);
    one_error_line(&text, &["--method", "--maps"]);
}
