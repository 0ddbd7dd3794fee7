//! Files written whole or not at all: to a temporary sibling, then renamed into place.

use std::path::{Path, PathBuf};

use anyhow::{Context, Result};

/// Writes a file through `write` to a temporary sibling, then renames it into place, so that
/// readers never see a partial file and a failure leaves nothing behind.
pub fn write_atomically(path: &Path, write: impl FnOnce(&Path) -> Result<()>) -> Result<()> {
    let name = path
        .file_name()
        .with_context(|| format!("not a file path: {}", path.display()))?;
    let tmp: PathBuf = path.with_file_name(format!(
        ".{}.tmp-{}",
        name.to_string_lossy(),
        std::process::id()
    ));
    let result = write(&tmp).and_then(|()| {
        std::fs::rename(&tmp, path)
            .with_context(|| format!("cannot move {} into place", path.display()))
    });
    if result.is_err() {
        let _ = std::fs::remove_file(&tmp);
    }
    result.with_context(|| format!("cannot write {}", path.display()))
}

pub fn write_text(path: &Path, text: &str) -> Result<()> {
    write_atomically(path, |tmp| Ok(std::fs::write(tmp, text)?))
}
