//! The command line as a user meets it: exit codes, one-line errors, no partial outputs.

mod common;

use std::process::Command;

fn seethru(args: &[&str]) -> (bool, String, String) {
    let out = Command::new(env!("CARGO_BIN_EXE_seethru"))
        .args(args)
        .output()
        .unwrap();
    (
        out.status.success(),
        String::from_utf8_lossy(&out.stdout).into(),
        String::from_utf8_lossy(&out.stderr).into(),
    )
}

#[test]
fn render_writes_png_ids_and_exr_per_view() {
    let dir = tempfile::tempdir().unwrap();
    let scene = dir.path().join("scene.toml");
    std::fs::write(&scene, common::MINIMAL).unwrap();
    let out = dir.path().join("out");
    let (ok, _, err) = seethru(&[
        "render",
        scene.to_str().unwrap(),
        "--view",
        "truth",
        "--view",
        "back",
        "--out",
        out.to_str().unwrap(),
        "--width",
        "40",
        "--threads",
        "1",
    ]);
    assert!(ok, "{err}");
    let mut files: Vec<String> = std::fs::read_dir(&out)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into())
        .collect();
    files.sort();
    assert_eq!(
        files,
        [
            "back.exr",
            "back.png",
            "back_ids.png",
            "truth.exr",
            "truth.png",
            "truth_ids.png"
        ]
    );
    // --width alone keeps the aspect ratio (64×36 → 40×23).
    let png = image::open(out.join("truth.png")).unwrap();
    assert_eq!((png.width(), png.height()), (40, 23));
}

#[test]
fn bad_input_gives_one_line_and_no_output() {
    let dir = tempfile::tempdir().unwrap();
    let scene = dir.path().join("bad.toml");
    let text = common::MINIMAL.replace("radius = 1.0", "radius = 0");
    let line = text.lines().position(|l| l == "radius = 0").unwrap() + 1;
    std::fs::write(&scene, text).unwrap();
    let out = dir.path().join("out");
    let scene_arg = scene.to_str().unwrap();
    let out_arg = out.to_str().unwrap();
    let cases: Vec<(Vec<&str>, String)> = vec![
        (
            vec!["render", scene_arg, "--out", out_arg],
            format!(
                "error: {scene_arg}:{line}: key `object[1].radius`: must be in (0, 100000], got 0"
            ),
        ),
        (
            vec!["render", "nowhere.toml", "--out", out_arg],
            "error: nowhere.toml: cannot read scene file".into(),
        ),
        (
            vec![
                "render",
                "scenes/das.toml",
                "--out",
                out_arg,
                "--width",
                "0",
            ],
            "error: resolution 0×".into(),
        ),
        (
            vec!["render", "scenes/das.toml", "--out", out_arg, "--spp", "0"],
            "error: --spp 0 is out of range".into(),
        ),
        (
            vec![
                "render",
                "scenes/das.toml",
                "--out",
                out_arg,
                "--threads",
                "0",
            ],
            "error: --threads 0 is out of range".into(),
        ),
        (
            vec!["bench", "scenes/das.toml", "--width", "99999"],
            "error: resolution 99999×720".into(),
        ),
        (
            vec!["export", "scenes/das.toml", "--out", "x.stl"],
            "error: export writes .obj or .glb".into(),
        ),
    ];
    for (args, expected) in cases {
        let (ok, _, err) = seethru(&args);
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
        assert!(!err.contains("panicked"), "{err}");
        assert!(!out.exists(), "{args:?} left output behind");
    }
}
