//! Files written whole or not at all: to a temporary sibling, then renamed into place. The
//! temporaries in flight are known, so that an interrupted command (Ctrl-C, SIGTERM) removes
//! them, and one left by a process that was killed outright is removed by the next write of
//! the same file.

use std::collections::HashSet;
use std::path::{Path, PathBuf};
use std::sync::Mutex;

use anyhow::{Context, Result};

/// Temporaries being written now, by any thread of this process: files, and the staging
/// folders of `io::staged`.
static IN_FLIGHT: Mutex<Option<HashSet<PathBuf>>> = Mutex::new(None);

pub(crate) fn track(tmp: &Path, writing: bool) {
    if let Ok(mut set) = IN_FLIGHT.lock() {
        let set = set.get_or_insert_with(HashSet::new);
        if writing {
            set.insert(tmp.to_path_buf());
        } else {
            set.remove(tmp);
        }
    }
}

/// Removes every temporary this process is writing; for the interrupt handler, after which
/// the process exits. Returns how many were removed.
pub fn remove_in_flight() -> usize {
    let Ok(mut set) = IN_FLIGHT.lock() else {
        return 0;
    };
    let paths: Vec<PathBuf> = set.take().unwrap_or_default().into_iter().collect();
    paths
        .iter()
        .filter(|p| std::fs::remove_file(p).is_ok() || std::fs::remove_dir_all(p).is_ok())
        .count()
}

/// The temporary name of `path` for process `pid`.
pub(crate) fn temporary(path: &Path, name: &str, pid: u32) -> PathBuf {
    path.with_file_name(format!(".{name}.tmp-{pid}"))
}

/// Removes temporaries of `path` left by processes that no longer run (killed before they
/// could clean up). Only Linux says which processes run; elsewhere nothing is removed.
pub(crate) fn remove_stale(path: &Path, name: &str) {
    let (Some(dir), true) = (path.parent(), Path::new("/proc/self").exists()) else {
        return;
    };
    let dir = if dir.as_os_str().is_empty() {
        Path::new(".")
    } else {
        dir
    };
    let prefix = format!(".{name}.tmp-");
    let Ok(entries) = std::fs::read_dir(dir) else {
        return;
    };
    for entry in entries.flatten() {
        let file = entry.file_name().to_string_lossy().to_string();
        let Some(pid) = file
            .strip_prefix(&prefix)
            .and_then(|p| p.parse::<u32>().ok())
        else {
            continue;
        };
        if !Path::new(&format!("/proc/{pid}")).exists() {
            // A file of an atomic write, or a staging folder (`io::staged`).
            let _ = std::fs::remove_file(entry.path())
                .or_else(|_| std::fs::remove_dir_all(entry.path()));
        }
    }
}

/// Writes a file through `write` to a temporary sibling, then renames it into place, so that
/// readers never see a partial file and a failure leaves nothing behind.
pub fn write_atomically(path: &Path, write: impl FnOnce(&Path) -> Result<()>) -> Result<()> {
    let name = path
        .file_name()
        .with_context(|| format!("not a file path: {}", path.display()))?
        .to_string_lossy()
        .to_string();
    if let Some(parent) = path.parent().filter(|p| !p.as_os_str().is_empty()) {
        std::fs::create_dir_all(parent)
            .with_context(|| format!("cannot create the folder {}", parent.display()))?;
    }
    remove_stale(path, &name);
    let tmp = temporary(path, &name, std::process::id());
    track(&tmp, true);
    let result = write(&tmp).and_then(|()| {
        std::fs::rename(&tmp, path)
            .with_context(|| format!("cannot move {} into place", path.display()))
    });
    if result.is_err() {
        let _ = std::fs::remove_file(&tmp);
    }
    track(&tmp, false);
    result.with_context(|| format!("cannot write {}", path.display()))
}

pub fn write_text(path: &Path, text: &str) -> Result<()> {
    write_atomically(path, |tmp| Ok(std::fs::write(tmp, text)?))
}
