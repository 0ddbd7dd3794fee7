//! Running the binary on bad input and checking its refusal: one `error:` line holding given
//! words, the exit code, and nothing left behind.

use std::path::Path;
use std::process::Command;

/// Runs seethru in `dir`; (exit code, stderr).
pub fn run_in(dir: &Path, args: &[&str]) -> (i32, String) {
    let out = Command::new(env!("CARGO_BIN_EXE_seethru"))
        .arg("--quiet")
        .args(args)
        .current_dir(dir)
        .output()
        .unwrap();
    (
        out.status.code().unwrap_or(-1),
        String::from_utf8_lossy(&out.stderr).into(),
    )
}

/// The command fails with `code` and one `error:` line holding every one of `words`.
pub fn refused(dir: &Path, args: &[&str], code: i32, words: &[&str]) -> String {
    let (got, err) = run_in(dir, args);
    assert_eq!(got, code, "{args:?}: exit code {got}: {err}");
    assert!(!err.contains("panicked"), "{args:?}: {err}");
    assert_eq!(err.lines().count(), 1, "{args:?}: one line: {err}");
    assert!(err.starts_with("error: "), "{args:?}: {err}");
    for w in words {
        assert!(
            err.contains(w),
            "{args:?}: `{}` lacks `{w}`",
            err.trim_end()
        );
    }
    err.trim_end().to_string()
}

/// Every entry under `dir`, recursively, as sorted relative paths.
pub fn listing(dir: &Path) -> Vec<String> {
    let mut out = Vec::new();
    let mut stack = vec![dir.to_path_buf()];
    while let Some(d) = stack.pop() {
        for e in std::fs::read_dir(&d).unwrap().flatten() {
            let p = e.path();
            out.push(p.strip_prefix(dir).unwrap().display().to_string());
            if p.is_dir() {
                stack.push(p);
            }
        }
    }
    out.sort();
    out
}

/// A scratch folder with the minimal scene plus `extra` TOML as `scene.toml`, and `files`.
pub fn scratch(extra: &str, files: &[(&str, &[u8])]) -> tempfile::TempDir {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(
        dir.path().join("scene.toml"),
        format!("{}{extra}", super::MINIMAL),
    )
    .unwrap();
    for (name, bytes) in files {
        let path = dir.path().join(name);
        std::fs::create_dir_all(path.parent().unwrap()).unwrap();
        std::fs::write(path, bytes).unwrap();
    }
    dir
}

pub const RENDER: &[&str] = &[
    "render",
    "scene.toml",
    "--out",
    "out",
    "--view",
    "truth",
    "--width",
    "8",
];

/// Renders the scene of `dir` and expects a refusal holding `words`; nothing new in `dir`.
pub fn render_refused(dir: &Path, words: &[&str]) -> String {
    let before = listing(dir);
    let err = refused(dir, RENDER, 1, words);
    assert_eq!(listing(dir), before, "the failed render left files behind");
    err
}
