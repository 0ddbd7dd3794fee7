//! What failing and interrupted commands leave behind (their output location as they found
//! it, no temporaries), and `measure` on run directories whose files are wrong.

mod common;

use std::path::{Path, PathBuf};
use std::process::Command;

use common::refusal::{RENDER, listing, refused, run_in};

/// A finished run of the minimal scene in `dir/run` (truth, seethru and occluded EXRs).
fn finished_run(dir: &Path) -> PathBuf {
    std::fs::write(dir.join("scene.toml"), common::MINIMAL).unwrap();
    let (code, err) = run_in(dir, &["run", "scene.toml", "--out", "run"]);
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
