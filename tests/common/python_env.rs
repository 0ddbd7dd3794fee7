//! A Python with the packages a test needs: `SEETHRU_PYTHON` if set, else a virtual
//! environment made once in `target/python-venv` (under a file lock, so that parallel tests
//! and test binaries make it once) with `python3 -m venv` and pip. A test that needs Python
//! fails with a clear message when none can be made: it is never skipped silently.

use std::path::PathBuf;
use std::process::Command;

/// The interpreter to run, with every package of `packages` importable: pip names that are
/// also module names (`numpy`), or `module=requirement` where they differ
/// (`cv2=opencv-python-headless<5`); more can be added by other tests, they are installed on
/// first use.
pub fn python_with(packages: &[&str]) -> PathBuf {
    if let Some(python) = std::env::var_os("SEETHRU_PYTHON") {
        let python = PathBuf::from(python);
        check_imports(&python, packages)
            .unwrap_or_else(|e| panic!("SEETHRU_PYTHON={}: {e}", python.display()));
        return python;
    }
    let target = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("target");
    std::fs::create_dir_all(&target).expect("target/ can be made");
    let lock = DirLock::take(target.join("python-venv.lock"));
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
            .args(packages.iter().map(|p| requirement(p)))
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

/// A lock held by a folder's existence (`create_dir` is atomic; `File::lock` is newer than
/// the crate's MSRV). A lock older than 15 minutes is a killed test's and is taken over.
struct DirLock(PathBuf);

impl DirLock {
    fn take(path: PathBuf) -> Self {
        let start = std::time::Instant::now();
        loop {
            match std::fs::create_dir(&path) {
                Ok(()) => return DirLock(path),
                Err(e) if e.kind() == std::io::ErrorKind::AlreadyExists => {
                    let stale = std::fs::metadata(&path)
                        .and_then(|m| m.modified())
                        .ok()
                        .and_then(|t| t.elapsed().ok())
                        .is_some_and(|age| age.as_secs() > 900);
                    if stale {
                        let _ = std::fs::remove_dir(&path);
                    }
                    assert!(
                        start.elapsed().as_secs() < 1200,
                        "waited 20 minutes for {} (another test making the venv?)",
                        path.display()
                    );
                    std::thread::sleep(std::time::Duration::from_millis(200));
                }
                Err(e) => panic!("cannot make the lock {}: {e}", path.display()),
            }
        }
    }
}

impl Drop for DirLock {
    fn drop(&mut self) {
        let _ = std::fs::remove_dir(&self.0);
    }
}

/// The module a package entry imports (`cv2` of `cv2=opencv-python-headless<5`).
fn module(package: &str) -> &str {
    package.split_once('=').map_or(package, |(m, _)| m)
}

/// What pip installs for a package entry (`opencv-python-headless<5`).
fn requirement(package: &str) -> &str {
    package.split_once('=').map_or(package, |(_, r)| r)
}

fn check_imports(python: &PathBuf, packages: &[&str]) -> Result<(), String> {
    let script = packages
        .iter()
        .map(|p| format!("import {}", module(p)))
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
