//! The Python package as a user installs it: `maturin build --release` makes one abi3
//! manylinux wheel, stripped, which installs into a fresh virtual environment (numpy from PyPI
//! or the pip cache) and runs the Python guide's quick start and the datasets guide's Python
//! there with no cargo or rustc on PATH.

use std::path::{Path, PathBuf};
use std::process::Command;

mod common;

fn repo() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

fn ok(command: &mut Command) -> String {
    let out = command
        .output()
        .unwrap_or_else(|e| panic!("{command:?}: {e}"));
    let text = format!(
        "{}\n{}",
        String::from_utf8_lossy(&out.stdout),
        String::from_utf8_lossy(&out.stderr)
    );
    assert!(
        out.status.success(),
        "{command:?} failed ({}):\n{text}",
        out.status
    );
    text
}

/// The first ```python block after `heading` in a Markdown page.
fn python_block_after(page: &Path, heading: &str) -> String {
    let text = std::fs::read_to_string(page).unwrap();
    let after = &text[text.find(heading).unwrap_or_else(|| panic!("no {heading}"))..];
    let start = after.find("```python\n").expect("a python block") + "```python\n".len();
    let end = start + after[start..].find("\n```").expect("its end");
    after[start..end].to_string()
}

#[test]
fn the_abi3_wheel_installs_without_a_toolchain_and_runs_the_quick_start() {
    let python = common::python_env::python_with(&["maturin"]);
    let venv = python.parent().unwrap().parent().unwrap();
    let dir = tempfile::tempdir().unwrap();
    let wheels = dir.path().join("wheels");
    ok(Command::new(venv.join("bin/maturin"))
        .args(["build", "--release", "--quiet", "--manifest-path"])
        .arg(repo().join("python/Cargo.toml"))
        .arg("--out")
        .arg(&wheels));
    let built: Vec<PathBuf> = std::fs::read_dir(&wheels)
        .unwrap()
        .map(|e| e.unwrap().path())
        .collect();
    assert_eq!(built.len(), 1, "{built:?}");
    let name = built[0].file_name().unwrap().to_str().unwrap();
    // One wheel for every CPython ≥ 3.10 (the stable ABI) on any glibc Linux of its era.
    assert!(
        name.starts_with("seethru-") && name.contains("-cp310-abi3-manylinux_"),
        "{name}"
    );
    // Stripped: line tables would more than double it (19.5 MB).
    let bytes = std::fs::metadata(&built[0]).unwrap().len();
    assert!(
        bytes < 12 << 20,
        "the wheel is {bytes} bytes: is it stripped?"
    );

    // A fresh environment, and a PATH with the system's Python but no Rust toolchain.
    let fresh = dir.path().join("venv");
    ok(Command::new("python3").args(["-m", "venv"]).arg(&fresh));
    let pip = fresh.join("bin/pip");
    ok(Command::new(&pip)
        .args(["install", "--quiet"])
        .arg(&built[0]));
    let path = format!("{}:/usr/bin:/bin", fresh.join("bin").display());
    let scratch = dir.path().join("user");
    std::fs::create_dir_all(&scratch).unwrap();
    for folder in ["scenes", "assets", "examples"] {
        ok(Command::new("cp")
            .arg("-r")
            .arg(repo().join(folder))
            .arg(&scratch));
    }
    // The quick start reads the EXR its page's command writes first.
    let (written, _, err) = common::seethru_in(
        &scratch,
        &[
            "render",
            "scenes/das.toml",
            "--view",
            "truth",
            "--width",
            "160",
            "--spp",
            "2",
            "--quiet",
            "--out",
            "py_check",
        ],
    );
    assert!(written, "{err}");
    let quick = python_block_after(&repo().join("docs/guide/python.md"), "## Quick start");
    // And a dataset, as a cluster's worker with the wheel alone makes one.
    let dataset = python_block_after(&repo().join("docs/guide/datasets.md"), "## From Python");
    let script = format!(
        "import shutil, sys\nassert shutil.which('cargo') is None and shutil.which('rustc') is None, 'a toolchain on PATH'\n{quick}\nimport seethru._native as native\nassert 'site-packages' in native.__file__, native.__file__\nprint('quick start ran', np.nanmean(result.misregistration))\n{dataset}\nassert made['done'] == made['samples'] and made['manifest'].is_file(), made\nprint('dataset made')\n"
    );
    let said = ok(Command::new(fresh.join("bin/python"))
        .args(["-c", &script])
        .current_dir(&scratch)
        .env_clear()
        .env("PATH", &path)
        .env("HOME", dir.path()));
    assert!(
        said.contains("quick start ran") && said.contains("dataset made"),
        "{said}"
    );
}
