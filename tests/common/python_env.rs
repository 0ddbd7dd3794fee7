//! A Python with the packages a test needs: `SEETHRU_PYTHON` if set, else a virtual
//! environment made once in `target/python-venv` (under a file lock, so that parallel tests
//! and test binaries make it once) with `python3 -m venv` and pip. A test that needs Python
//! fails with a clear message when none can be made: it is never skipped silently.

use std::path::PathBuf;
use std::process::Command;

/// The interpreter to run, with every package of `packages` importable (pip names that are
/// also module names, e.g. `numpy`; more can be added by other tests, they are installed
/// on first use).
pub fn python_with(packages: &[&str]) -> PathBuf {
    if let Some(python) = std::env::var_os("SEETHRU_PYTHON") {
        let python = PathBuf::from(python);
        check_imports(&python, packages)
            .unwrap_or_else(|e| panic!("SEETHRU_PYTHON={}: {e}", python.display()));
        return python;
    }
    let target = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("target");
    std::fs::create_dir_all(&target).expect("target/ can be made");
    let lock = std::fs::File::create(target.join("python-venv.lock")).expect("a lock file");
    lock.lock().expect("the python-venv lock");
    let venv = target.join("python-venv");
    let python = venv.join("bin").join("python");
    if !python.exists() {
        let made = Command::new("python3")
            .args(["-m", "venv"])
            .arg(&venv)
            .output()
            .unwrap_or_else(|e| panic!("cannot run python3 to make {}: {e}; install Python 3 with venv, or set SEETHRU_PYTHON to an interpreter with {packages:?}", venv.display()));
        assert!(
            made.status.success(),
            "python3 -m venv {} failed: {}; install python3-venv, or set SEETHRU_PYTHON",
            venv.display(),
            String::from_utf8_lossy(&made.stderr)
        );
    }
    if check_imports(&python, packages).is_err() {
        let pip = Command::new(&python)
            .args(["-m", "pip", "install", "--quiet"])
            .args(packages)
            .output()
            .expect("pip runs");
        assert!(
            pip.status.success(),
            "pip install {packages:?} into {} failed (is PyPI reachable?): {}; or set SEETHRU_PYTHON to an interpreter that has them",
            venv.display(),
            String::from_utf8_lossy(&pip.stderr)
        );
        check_imports(&python, packages).unwrap_or_else(|e| panic!("{e}"));
    }
    drop(lock);
    python
}

fn check_imports(python: &PathBuf, packages: &[&str]) -> Result<(), String> {
    let script = packages
        .iter()
        .map(|p| format!("import {p}"))
        .collect::<Vec<_>>()
        .join("; ");
    let out = Command::new(python)
        .args(["-c", &script])
        .output()
        .map_err(|e| format!("cannot run {}: {e}", python.display()))?;
    match out.status.success() {
        true => Ok(()),
        false => Err(format!(
            "{} cannot import {packages:?}: {}",
            python.display(),
            String::from_utf8_lossy(&out.stderr).trim()
        )),
    }
}
