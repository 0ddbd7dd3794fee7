//! What failing and interrupted commands leave behind (their output location as they found
//! it, no temporaries), and `measure` on run directories whose files are wrong.

mod common;

use std::path::{Path, PathBuf};
use std::process::Command;

use common::refusal::{RENDER, listing, refused, run_in};

/// A finished run of the minimal scene in `dir/run` (truth, seethru and occluded EXRs with
/// every AOV, as `measure` reads them).
fn finished_run(dir: &Path) -> PathBuf {
    std::fs::write(dir.join("scene.toml"), common::MINIMAL).unwrap();
    let (code, err) = run_in(dir, &["run", "scene.toml", "--out", "run", "--exr", "all"]);
    assert_eq!(code, 0, "{err}");
    dir.join("run")
}

#[test]
fn measure_names_the_exr_and_what_is_wrong_with_it() {
    use exr::prelude::*;
    let dir = tempfile::tempdir().unwrap();
    let run = finished_run(dir.path());
    let good = std::fs::read(run.join("seethru.exr")).unwrap();
    let measure = ["measure", "run"];
    let restore = || std::fs::write(run.join("seethru.exr"), &good).unwrap();

    // Another size than truth.exr (this panicked).
    let (code, err) = run_in(
        dir.path(),
        &[
            "render",
            "scene.toml",
            "--out",
            "small",
            "--view",
            "truth",
            "--width",
            "32",
        ],
    );
    assert_eq!(code, 0, "{err}");
    std::fs::copy(dir.path().join("small/truth.exr"), run.join("seethru.exr")).unwrap();
    refused(
        dir.path(),
        &measure,
        1,
        &["run/seethru.exr is 32×18", "run/truth.exr is 64×36"],
    );

    // Truncated, and not an EXR at all.
    for (bytes, words) in [
        (
            &good[..good.len() / 2],
            &["run/seethru.exr", "truncated"][..],
        ),
        (&good[..40], &["run/seethru.exr", "not a readable EXR"]),
        (
            b"\x89PNG\r\n\x1a\n",
            &["run/seethru.exr", "not a readable EXR"],
        ),
    ] {
        std::fs::write(run.join("seethru.exr"), bytes).unwrap();
        refused(dir.path(), &measure, 1, words);
    }

    // A channel missing, and one of the wrong type.
    let plain = |channels: SmallVec<[AnyChannel<FlatSamples>; 4]>| {
        let layer = Layer::new(
            (64, 36),
            LayerAttributes::default(),
            Encoding::UNCOMPRESSED,
            AnyChannels::sort(channels),
        );
        Image::from_layer(layer)
            .write()
            .to_file(run.join("seethru.exr"))
            .unwrap();
    };
    let f32s = |name: &str| AnyChannel::new(name, FlatSamples::F32(vec![0.5; 64 * 36]));
    plain(SmallVec::from_vec(vec![f32s("R"), f32s("G"), f32s("B")]));
    refused(
        dir.path(),
        &measure,
        1,
        &["run/seethru.exr", "no channel `Z`"],
    );
    let mut channels: Vec<AnyChannel<FlatSamples>> = ["R", "G", "B", "Z", "camera_z.Z"]
        .into_iter()
        .chain(["P.X", "P.Y", "P.Z", "N.X", "N.Y", "N.Z", "id.part"])
        .map(f32s)
        .collect();
    channels.push(AnyChannel::new(
        "id.object",
        FlatSamples::F32(vec![0.0; 64 * 36]),
    ));
    plain(SmallVec::from_vec(channels));
    refused(
        dir.path(),
        &measure,
        1,
        &[
            "run/seethru.exr",
            "channel `id.object` is f32, expected u32",
        ],
    );
    restore();

    // An invalid run.json names that file.
    let json = std::fs::read_to_string(run.join("run.json")).unwrap();
    for (text, words) in [
        (
            &json[..json.len() / 2],
            &["run/run.json", "invalid JSON"][..],
        ),
        ("{}", &["run/run.json", "no `scene`"]),
        (
            "{\"scene\": 3}",
            &["run/run.json", "`scene` must be the path"],
        ),
    ] {
        std::fs::write(run.join("run.json"), text).unwrap();
        refused(dir.path(), &measure, 1, words);
    }
    std::fs::write(run.join("run.json"), &json).unwrap();
    let (code, err) = run_in(dir.path(), &measure);
    assert_eq!(code, 0, "restored, the run measures again: {err}");
}

#[test]
fn a_failed_command_leaves_the_output_location_as_it_found_it() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("scene.toml"), common::MINIMAL).unwrap();
    // An output folder with a previous file and a folder where a view's file goes: the run
    // renders everything, cannot place display.png, and moves nothing.
    let out = dir.path().join("out");
    std::fs::create_dir_all(out.join("display.png")).unwrap();
    std::fs::write(out.join("truth.png"), "an older truth").unwrap();
    let before = listing(dir.path());
    refused(
        dir.path(),
        &["run", "scene.toml", "--out", "out"],
        1,
        &["out/display.png", "in the way"],
    );
    assert_eq!(listing(dir.path()), before);
    assert_eq!(
        std::fs::read_to_string(out.join("truth.png")).unwrap(),
        "an older truth"
    );

    // A command that fails after it started its output creates no folder, nested or not.
    refused(
        dir.path(),
        &[
            "reproduce",
            "--quick",
            "--scene",
            "none.toml",
            "--out",
            "new/nested/report",
        ],
        1,
        &["none.toml"],
    );
    assert_eq!(listing(dir.path()), before);
}

#[test]
#[cfg(target_os = "linux")]
fn staging_folders_of_killed_processes_are_removed_by_the_next_run() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("scene.toml"), common::MINIMAL).unwrap();
    // A process id above the kernel's maximum (2²²) never runs.
    let stale = dir.path().join(".out.tmp-4194305");
    std::fs::create_dir(&stale).unwrap();
    std::fs::write(stale.join("truth.png"), "half a run").unwrap();
    let (code, err) = run_in(dir.path(), RENDER);
    assert_eq!(code, 0, "{err}");
    assert_eq!(
        listing(&dir.path().join("out")).len(),
        3,
        "truth PNG, ids, EXR"
    );
    assert!(!stale.exists());
    assert_eq!(
        listing(dir.path())
            .iter()
            .filter(|n| n.contains(".tmp-"))
            .count(),
        0
    );
}

#[test]
#[cfg(unix)]
fn sigterm_removes_the_commands_temporaries() {
    // SIGTERM at several moments of a run: exit 130 with one line, and afterwards either a
    // whole output (the signal came too late) or none, and no temporary anywhere.
    let scratch = tempfile::tempdir().unwrap();
    let mut interrupted = 0;
    for (k, delay_ms) in [100u64, 300, 500, 800].into_iter().enumerate() {
        let out = scratch.path().join(format!("out{k}"));
        let child = Command::new(env!("CARGO_BIN_EXE_seethru"))
            .args([
                "run",
                "scenes/das.toml",
                "--quiet",
                "--out",
                out.to_str().unwrap(),
            ])
            .current_dir(env!("CARGO_MANIFEST_DIR"))
            .stderr(std::process::Stdio::piped())
            .spawn()
            .unwrap();
        std::thread::sleep(std::time::Duration::from_millis(delay_ms));
        let _ = Command::new("kill")
            .args(["-TERM", &child.id().to_string()])
            .status();
        let output = child.wait_with_output().unwrap();
        let err = String::from_utf8_lossy(&output.stderr);
        match output.status.code() {
            Some(130) => {
                interrupted += 1;
                assert_eq!(err.lines().count(), 1, "{err}");
                assert!(err.starts_with("error: interrupted;"), "{err}");
                assert!(!out.exists(), "an interrupted run left {}", out.display());
            }
            Some(0) => assert!(out.join("run.json").exists()),
            // Killed before the handler was installed (a loaded machine): nothing to check.
            None => {}
            Some(other) => panic!("exit {other}: {err}"),
        }
        let left: Vec<String> = listing(scratch.path())
            .into_iter()
            .filter(|n| n.contains(".tmp-"))
            .collect();
        assert!(left.is_empty(), "after {delay_ms} ms: {left:?}");
    }
    assert!(interrupted > 0, "no run was interrupted");
}

/// A scratch folder with the minimal scene plus a mesh `m.obj` and its `m.mtl`.
fn scene_with_mesh() -> tempfile::TempDir {
    let dir = tempfile::tempdir().unwrap();
    let scene = format!(
        "{}\n[[object]]\nname = \"m\"\nkind = \"mesh\"\npath = \"m.obj\"\ntranslate = [0.0, 0.0, -5.0]\n",
        common::MINIMAL
    );
    std::fs::write(dir.path().join("scene.toml"), scene).unwrap();
    std::fs::write(
        dir.path().join("m.obj"),
        "mtllib m.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nusemtl a\nf 1 2 3\n",
    )
    .unwrap();
    std::fs::write(dir.path().join("m.mtl"), "newmtl a\nKd 0.5 0.5 0.5\n").unwrap();
    dir
}

/// Every file under `dir` with its bytes.
fn contents(dir: &Path) -> Vec<(String, Vec<u8>)> {
    listing(dir)
        .into_iter()
        .filter(|name| dir.join(name).is_file())
        .map(|name| {
            let bytes = std::fs::read(dir.join(&name)).unwrap();
            (name, bytes)
        })
        .collect()
}

#[test]
fn a_failed_export_leaves_no_file_of_any_format() {
    let dir = scene_with_mesh();
    // The last file each format writes, blocked by a folder of its name, in a folder of its
    // own and beside the scene.
    for (out, blocked) in [
        ("e/x.glb", "e/x.cameras.json"),
        ("e/x.obj", "e/x.cameras.json"),
        ("e/x.obj", "e/x.mtl"),
        ("e/x.xml", "e/x.cameras.json"),
        ("e/x.xml", "e/x.truth.xml"),
        ("x.xml", "x.cameras.json"),
    ] {
        std::fs::create_dir_all(dir.path().join(blocked)).unwrap();
        let before = listing(dir.path());
        refused(
            dir.path(),
            &["export", "scene.toml", "--out", out],
            1,
            &[blocked, "in the way"],
        );
        assert_eq!(listing(dir.path()), before, "{out} with {blocked} blocked");
        std::fs::remove_dir(dir.path().join(blocked)).unwrap();
    }
    // Into a new folder: created, and holding the files only (no staging).
    let (code, err) = run_in(dir.path(), &["export", "scene.toml", "--out", "new/y.glb"]);
    assert_eq!(code, 0, "{err}");
    assert_eq!(
        listing(&dir.path().join("new")),
        ["y.cameras.json", "y.glb"]
    );
}

#[test]
fn export_refuses_to_overwrite_its_inputs() {
    let dir = scene_with_mesh();
    for out in ["m.obj", "./sub/../m.obj"] {
        std::fs::create_dir_all(dir.path().join("sub")).unwrap();
        let before = contents(dir.path());
        refused(
            dir.path(),
            &["export", "scene.toml", "--out", out],
            1,
            &["--out", "m.obj", "an input of the scene scene.toml"],
        );
        assert_eq!(contents(dir.path()), before, "--out {out}");
    }
    // The MTL alone: `--out m.glb` writes no m.mtl, but an OBJ export named like the mesh
    // would write the scene's m.mtl beside it.
    std::fs::rename(dir.path().join("m.obj"), dir.path().join("mesh.obj")).unwrap();
    let scene = std::fs::read_to_string(dir.path().join("scene.toml")).unwrap();
    std::fs::write(
        dir.path().join("scene.toml"),
        scene.replace("\"m.obj\"", "\"mesh.obj\""),
    )
    .unwrap();
    let before = contents(dir.path());
    refused(
        dir.path(),
        &["export", "scene.toml", "--out", "m.obj"],
        1,
        &["--out m.obj", "would overwrite m.mtl"],
    );
    assert_eq!(contents(dir.path()), before);
}

#[test]
fn a_failed_measure_replaces_none_of_its_outputs() {
    let dir = tempfile::tempdir().unwrap();
    let run = finished_run(dir.path());
    std::fs::remove_file(run.join("misregistration.png")).unwrap();
    std::fs::create_dir(run.join("misregistration.png")).unwrap();
    let before = contents(dir.path());
    refused(
        dir.path(),
        &["measure", "run", "--band", "9"],
        1,
        &["run/misregistration.png", "in the way"],
    );
    assert_eq!(
        contents(dir.path()),
        before,
        "metrics.json or the EXR replaced"
    );
    assert_eq!(
        listing(dir.path()).len(),
        before.len() + 2,
        "no staging left"
    );
}

#[test]
fn measure_refuses_samples_seethru_never_writes() {
    use seethru::io::frame_files::{read_exr, write_exr};
    let dir = tempfile::tempdir().unwrap();
    let run = finished_run(dir.path());
    let good_truth = std::fs::read(run.join("truth.exr")).unwrap();
    let frame = read_exr(&run.join("truth.exr")).unwrap();
    // The sky's P is NaN, with Z inf: accepted.
    let sky = frame.depth.iter().position(|d| d.is_infinite()).unwrap();
    assert!(frame.position[sky].x.is_nan(), "seethru's sky P is NaN");
    type Edit = fn(&mut seethru::render::frame::Frame, usize);
    let cases: [(&str, &str, Edit, &[&str]); 5] = [
        (
            "truth",
            "P.X",
            |f, i| f.position[i].x = f32::NAN,
            &["NaN", "[-1e6, 1e6] m"],
        ),
        (
            "seethru",
            "P.Y",
            |f, i| f.position[i].y = 1e38,
            &["1e38", "[-1e6, 1e6] m"],
        ),
        (
            "truth",
            "R",
            |f, i| f.color[i].x = f32::NAN,
            &["NaN", "finite"],
        ),
        (
            "occluded",
            "Z",
            |f, i| f.depth[i] = -1.0,
            &["-1", "[0, inf] m"],
        ),
        (
            "truth",
            "N.Z",
            |f, i| f.normal[i].z = f32::INFINITY,
            &["inf", "[-1, 1]"],
        ),
    ];
    for (view, channel, edit, words) in cases {
        let path = run.join(format!("{view}.exr"));
        let good = std::fs::read(&path).unwrap();
        let mut bad = read_exr(&path).unwrap();
        // The last pixel that shows an object (finite Z).
        let hit = bad.depth.iter().rposition(|d| d.is_finite()).unwrap();
        let (x, y) = (hit % bad.width as usize, hit / bad.width as usize);
        let pixel = format!("pixel ({x}, {y})");
        edit(&mut bad, hit);
        write_exr(&bad, &path).unwrap();
        let file = format!("run/{view}.exr");
        let channel = format!("channel `{channel}`");
        let mut all = vec![file.as_str(), channel.as_str(), pixel.as_str()];
        all.extend_from_slice(words);
        refused(dir.path(), &["measure", "run"], 1, &all);
        std::fs::write(&path, good).unwrap();
    }
    assert_eq!(std::fs::read(run.join("truth.exr")).unwrap(), good_truth);
    let (code, err) = run_in(dir.path(), &["measure", "run"]);
    assert_eq!(code, 0, "restored, the run measures again: {err}");
}

#[test]
fn measure_reads_the_scene_the_run_rendered_or_says_why_not() {
    let dir = tempfile::tempdir().unwrap();
    let run = finished_run(dir.path());
    // From inside the run folder: run.json records the scene's absolute path too.
    let (code, err) = run_in(&run, &["measure", "."]);
    assert_eq!(code, 0, "{err}");
    let json = std::fs::read_to_string(run.join("run.json")).unwrap();
    let value: serde_json::Value = serde_json::from_str(&json).unwrap();
    assert_eq!(value["scene"], "scene.toml");

    // The scene edited since the run: refused, naming both files.
    let scene = dir.path().join("scene.toml");
    let text = std::fs::read_to_string(&scene).unwrap();
    std::fs::write(&scene, text.replace("radius = 1.0", "radius = 2.0")).unwrap();
    let before = contents(dir.path());
    refused(
        dir.path(),
        &["measure", "run"],
        1,
        &["scene.toml has changed since the run", "run/run.json"],
    );
    assert_eq!(contents(dir.path()), before);
    std::fs::write(&scene, &text).unwrap();

    // A run.json naming another scene: refused the same way.
    std::fs::write(
        dir.path().join("other.toml"),
        text.replace("1.0, -10.0", "1.0, -9.0"),
    )
    .unwrap();
    let other = std::fs::canonicalize(dir.path().join("other.toml")).unwrap();
    let mut edited = value.clone();
    edited["scene"] = "other.toml".into();
    edited["scene_absolute"] = other.display().to_string().into();
    std::fs::write(run.join("run.json"), edited.to_string()).unwrap();
    refused(
        dir.path(),
        &["measure", "run"],
        1,
        &["other.toml has changed since the run", "run/run.json"],
    );

    // A scene that is gone: the error names the path as resolved.
    std::fs::remove_file(dir.path().join("other.toml")).unwrap();
    refused(
        dir.path(),
        &["measure", "run"],
        1,
        &[
            &other.display().to_string(),
            "run/run.json",
            "`scene` = other.toml",
        ],
    );

    // A run.json older than the hash: its `scene`, relative to the current folder.
    let mut old = value.clone();
    let object = old.as_object_mut().unwrap();
    object.remove("scene_absolute");
    object.remove("scene_hash");
    std::fs::write(run.join("run.json"), old.to_string()).unwrap();
    let (code, err) = run_in(dir.path(), &["measure", "run"]);
    assert_eq!(code, 0, "{err}");
}

#[test]
fn output_errors_name_the_users_path() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("scene.toml"), common::MINIMAL).unwrap();
    std::fs::write(dir.path().join("f"), "a file").unwrap();
    let before = listing(dir.path());
    let mut args: Vec<&str> = RENDER.to_vec();
    for (out, words) in [
        ("f/sub", &["f/sub", "f is a file, not a folder"][..]),
        ("f/a/b", &["f/a/b", "f is a file, not a folder"]),
        (
            "/proc/self/nope",
            &["--out /proc/self/nope", "cannot write into /proc/self"],
        ),
    ] {
        args[3] = out;
        let err = refused(dir.path(), &args, 1, words);
        assert!(!err.contains(".tmp-"), "{err}");
    }
    assert_eq!(listing(dir.path()), before);
}

#[test]
fn an_output_over_an_input_or_where_nothing_can_be_written_is_refused_before_any_work() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("scene.toml"), common::MINIMAL).unwrap();
    std::fs::write(
        dir.path().join("mine.toml"),
        "[[case]]\nname = \"a\"\nscene = \"scene.toml\"\ncommand = \"run\"\nexpect = [\"misregistration.mean <= 1000\"]\n",
    )
    .unwrap();
    let before = contents(dir.path());
    // Each refusal names the option and the path, and leaves the folder as it was: no case
    // ran (no `seethru-check` folder), the expectations are intact.
    for (args, words) in [
        (
            &["check", "mine.toml", "--junit", "mine.toml"][..],
            &["--junit mine.toml", "EXPECTATIONS", "would destroy"][..],
        ),
        (
            &["check", "mine.toml", "--junit", "./sub/../mine.toml"],
            &["--junit", "would destroy"],
        ),
        (
            &["check", "mine.toml", "--junit", "/proc/x.xml"],
            &["--junit /proc/x.xml", "cannot write into /proc"],
        ),
        (
            &["check", "mine.toml", "--junit", "."],
            &["--junit .", "is a folder, not a file"],
        ),
        (
            &["check", "mine.toml", "--out", "."],
            &["--out .", "holding the input", "would destroy"],
        ),
        (
            &["run", "scene.toml", "--out", "."],
            &["--out .", "holding the input", "scene.toml"],
        ),
        (
            &[
                "sweep",
                "scene.toml",
                "--param",
                "d2=2",
                "--out",
                "scene.toml",
            ],
            &["--out scene.toml", "is the input"],
        ),
        (
            &["render", "scene.toml", "--out", "scene.toml/x"],
            &["--out scene.toml/x", "scene.toml is a file, not a folder"],
        ),
        (
            &["score", ".", "--display-image", "scene.toml", "--out", "."],
            &["--out .", "is the input . (INPUTS)"],
        ),
    ] {
        // `check` exits 2 on bad input (1 is its failed-bounds verdict).
        let code = if args[0] == "check" { 2 } else { 1 };
        refused(dir.path(), args, code, words);
        assert_eq!(contents(dir.path()), before, "{args:?}");
    }
    // A FIFO where a file is read is refused at once, not read until the writer comes.
    let fifo = dir.path().join("fifo.toml");
    if Command::new("mkfifo")
        .arg(&fifo)
        .status()
        .is_ok_and(|s| s.success())
    {
        refused(
            dir.path(),
            &["run", "fifo.toml", "--out", "o"],
            1,
            &["fifo.toml", "not a regular file"],
        );
        std::fs::create_dir(dir.path().join("cap")).unwrap();
        std::fs::rename(&fifo, dir.path().join("cap/capture.json")).unwrap();
        image::RgbImage::new(1, 1)
            .save(dir.path().join("d.png"))
            .unwrap();
        refused(
            dir.path(),
            &["score", "cap", "--display-image", "d.png", "--out", "o"],
            1,
            &["capture.json", "not a regular file"],
        );
    }
}
