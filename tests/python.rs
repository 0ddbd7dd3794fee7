//! The Python package (python/): builds it into a virtual environment under target/, then
//! runs its pytest tests, which compare renders and runs from Python with the command line's
//! EXRs and metrics.json bit for bit, check that the GIL is released, that Ctrl-C stops a
//! render and that bad input raises with the command line's message.
//!
//! Needs `python3` (≥ 3.10, with `venv`) and PyPI or a pip wheel cache: the environment
//! (numpy, pytest, maturin, OpenEXR, OpenCV, Ray, distributed, PyArrow;
//! tests/common/python_env.rs) is made once and reused.

use std::path::{Path, PathBuf};
use std::process::Command;
use std::time::Instant;

mod common;

/// What the tests import (common::python_env's entries); OpenCV for the docs' EXR-reading
/// blocks (python/tests/test_docs.py), pinned below 5, whose wheels have no EXR codec; Ray and
/// Dask's distributed for the dataset recipes (python/tests/test_dataset_engines.py), PyArrow
/// for its Parquet manifest.
const PACKAGES: [&str; 8] = [
    "numpy",
    "pytest",
    "maturin",
    "OpenEXR",
    "cv2=opencv-python-headless<5",
    "ray",
    "distributed",
    "pyarrow",
];

fn repo() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

fn run(command: &mut Command) -> std::process::Output {
    let out = command
        .output()
        .unwrap_or_else(|e| panic!("{command:?}: {e}"));
    assert!(
        out.status.success(),
        "{command:?} failed ({}):\n{}\n{}",
        out.status,
        String::from_utf8_lossy(&out.stdout),
        String::from_utf8_lossy(&out.stderr)
    );
    out
}

/// Builds the package and installs it into the environment (`maturin develop --release`).
fn install(python: &Path) {
    let venv = python.parent().unwrap().parent().unwrap();
    run(
        Command::new(venv.join("bin/maturin"))
            .args(["develop", "--release", "--quiet", "--manifest-path"])
            .arg(repo().join("python/Cargo.toml"))
            .env("VIRTUAL_ENV", venv), // The same target/ as the outer `cargo test` (which releases its lock before it runs
                                       // the tests: measured with cargo 1.95), so every dependency built for the package
                                       // by `pip install ./python` or a previous run is reused.
    );
}

#[test]
fn pytest_passes() {
    let start = Instant::now();
    let python = common::python_env::python_with(&PACKAGES);
    let made = start.elapsed();
    install(&python);
    let built = start.elapsed();
    let out = Command::new(&python)
        .args(["-m", "pytest", "-q", "-p", "no:cacheprovider"])
        .arg(repo().join("python/tests"))
        .env("SEETHRU_BIN", env!("CARGO_BIN_EXE_seethru"))
        .env("SEETHRU_REPO", repo())
        .current_dir(repo())
        .output()
        .unwrap();
    let text = format!(
        "{}\n{}",
        String::from_utf8_lossy(&out.stdout),
        String::from_utf8_lossy(&out.stderr)
    );
    eprintln!(
        "python: environment {:.1} s, build {:.1} s, pytest {:.1} s",
        made.as_secs_f64(),
        (built - made).as_secs_f64(),
        (start.elapsed() - built).as_secs_f64()
    );
    // Exit 5 is pytest's "no tests collected": a failure too.
    assert!(
        out.status.success(),
        "pytest failed ({}):\n{text}",
        out.status
    );
    assert!(text.contains(" passed"), "pytest ran no test:\n{text}");
}
