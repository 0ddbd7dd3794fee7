//! Files written whole or not at all: to a temporary sibling, then renamed into place. The
//! temporaries in flight are known, so that an interrupted command (Ctrl-C, SIGTERM) removes
//! them, and one left by a process that was killed outright is removed by the next write of
//! the same file.
//!
//! The rule that makes the interrupt clean-up complete: a temporary (a file, or a staging
//! folder of `io::staged`) and the folders it needs are created and registered under one
//! lock, and the interrupt handler takes that lock, removes what is registered and keeps the
//! lock until the process exits. A thread that would create a temporary, or move a finished
//! one into place, after the clean-up began waits for the exit instead; a writer only writes
//! into the file it was handed open.

use std::collections::BTreeSet;
use std::fs::File;
use std::io::{BufWriter, Write};
use std::path::{Path, PathBuf};
use std::sync::{Mutex, MutexGuard, PoisonError};

use anyhow::{Context, Result, bail};

/// What this process is writing now, by any of its threads.
pub(crate) struct InFlight {
    /// Temporaries being written: files, and the staging folders of `io::staged`.
    paths: BTreeSet<PathBuf>,
    /// Set by the interrupt handler: no temporary is created any more.
    interrupted: bool,
    /// Staging folders and the output each stands for (kept for messages, which name the
    /// output the user asked for, not the staging folder).
    staged_as: Vec<(PathBuf, PathBuf)>,
}

static IN_FLIGHT: Mutex<InFlight> = Mutex::new(InFlight {
    paths: BTreeSet::new(),
    interrupted: false,
    staged_as: Vec::new(),
});

/// The registry, locked (a panic elsewhere does not make it unusable).
pub(crate) fn in_flight() -> MutexGuard<'static, InFlight> {
    IN_FLIGHT.lock().unwrap_or_else(PoisonError::into_inner)
}

impl InFlight {
    /// Registers `tmp` as being written (`writing`) or as done with.
    pub(crate) fn track(&mut self, tmp: &Path, writing: bool) {
        if writing {
            self.paths.insert(tmp.to_path_buf());
        } else {
            self.paths.remove(tmp);
        }
    }

    /// An error where an interrupt has begun: then nothing new may be created.
    pub(crate) fn check_running(&self) -> Result<()> {
        if self.interrupted {
            bail!("interrupted");
        }
        Ok(())
    }

    /// Names `staging` (and what is in it) in messages as `target`.
    pub(crate) fn stage_as(&mut self, staging: &Path, target: &Path) {
        self.staged_as
            .push((staging.to_path_buf(), target.to_path_buf()));
    }

    fn shown(&self, path: &Path) -> PathBuf {
        for (staging, target) in self.staged_as.iter().rev() {
            if let Ok(rest) = path.strip_prefix(staging) {
                return self.shown(&target.join(rest));
            }
        }
        path.to_path_buf()
    }
}

pub(crate) fn track(tmp: &Path, writing: bool) {
    in_flight().track(tmp, writing);
}

/// `path` as messages name it: a path inside a staging folder of `io::staged` is named where
/// it goes when the output is committed (`OUT/truth.exr`, not `.OUT.tmp-PID/truth.exr`).
pub fn shown(path: &Path) -> PathBuf {
    in_flight().shown(path)
}

/// For the interrupt handler: marks the process as interrupted (no temporary is created from
/// now on), removes every temporary it is writing, and calls `then` with how many were
/// removed, still holding the lock that every creation of a temporary takes; `then` exits
/// the process.
pub fn remove_in_flight_then(then: impl FnOnce(usize) -> std::convert::Infallible) -> ! {
    let mut state = in_flight();
    state.interrupted = true;
    let paths = std::mem::take(&mut state.paths);
    let removed = paths
        .iter()
        .filter(|p| std::fs::remove_file(p).is_ok() || std::fs::remove_dir_all(p).is_ok())
        .count();
    match then(removed) {}
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

/// Creates `folder` and its parents; where that fails because a part of the path is a file,
/// the error says so. Messages name [`shown`] paths. For a caller holding the registry.
pub(crate) fn create_folders(state: &InFlight, folder: &Path) -> Result<()> {
    if folder.as_os_str().is_empty() || folder.is_dir() {
        return Ok(());
    }
    std::fs::create_dir_all(folder).map_err(|e| {
        let file = folder
            .ancestors()
            .find(|a| !a.as_os_str().is_empty() && a.exists() && !a.is_dir());
        match file {
            Some(file) => anyhow::anyhow!(
                "cannot create the folder {}: {} is a file, not a folder",
                state.shown(folder).display(),
                state.shown(file).display()
            ),
            None => anyhow::anyhow!(
                "cannot create the folder {}: {e}",
                state.shown(folder).display()
            ),
        }
    })
}

/// Writes a file through `write` to a temporary sibling, then renames it into place, so that
/// readers never see a partial file and a failure leaves nothing behind. `write` writes into
/// the temporary it is handed open (it must not open the file by name: see the module's rule).
pub fn write_atomically(
    path: &Path,
    write: impl FnOnce(&mut BufWriter<File>) -> Result<()>,
) -> Result<()> {
    let name = path
        .file_name()
        .with_context(|| format!("not a file path: {}", shown(path).display()))?
        .to_string_lossy()
        .to_string();
    remove_stale(path, &name);
    let tmp = temporary(path, &name, std::process::id());
    let file = {
        let mut state = in_flight();
        state.check_running()?;
        if let Some(parent) = path.parent() {
            create_folders(&state, parent)?;
        }
        let file = File::create(&tmp)
            .map_err(|e| anyhow::anyhow!("cannot write {}: {e}", state.shown(path).display()))?;
        state.track(&tmp, true);
        file
    };
    let mut writer = BufWriter::new(file);
    let result = write(&mut writer)
        .and_then(|()| Ok(writer.flush()?))
        .with_context(|| format!("cannot write {}", shown(path).display()))
        .and_then(|()| {
            drop(writer);
            // Under the lock, like the creation: an interrupt's clean-up (which keeps the
            // lock until the exit) never runs while a finished file moves into a staging
            // folder it is removing, which would leave the folder with that file in it.
            let state = in_flight();
            std::fs::rename(&tmp, path).map_err(|e| {
                anyhow::anyhow!(
                    "cannot move {} into place: {e}",
                    state.shown(path).display()
                )
            })
        });
    if result.is_err() {
        let _ = std::fs::remove_file(&tmp);
    }
    track(&tmp, false);
    result
}

pub fn write_text(path: &Path, text: &str) -> Result<()> {
    write_atomically(path, |file| Ok(file.write_all(text.as_bytes())?))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The rule the interrupt handler relies on: while it holds the registry (it keeps it
    /// until the process exits), no thread creates a temporary or a folder for one.
    #[test]
    fn no_temporary_or_folder_is_created_while_the_handler_holds_the_registry() {
        let dir = tempfile::tempdir().unwrap();
        let out = dir.path().join("late/sub/file.txt");
        let (writer, seen) = {
            let _handler = in_flight();
            let out = out.clone();
            let writer = std::thread::spawn(move || write_text(&out, "late"));
            std::thread::sleep(std::time::Duration::from_millis(200));
            (writer, std::fs::read_dir(dir.path()).unwrap().count())
        };
        writer.join().unwrap().unwrap();
        assert_eq!(seen, 0, "the writer created a folder or a temporary");
        assert_eq!(std::fs::read_to_string(&out).unwrap(), "late");
    }

    #[test]
    fn messages_name_the_output_not_the_staging_folder_and_a_file_in_the_way() {
        let dir = tempfile::tempdir().unwrap();
        std::fs::write(dir.path().join("f"), "a file").unwrap();
        let err = format!(
            "{:#}",
            write_text(&dir.path().join("f/sub/x.txt"), "x").unwrap_err()
        );
        assert!(err.contains("f is a file, not a folder"), "{err}");
        let staging = dir.path().join(".OUT.tmp-1");
        in_flight().stage_as(&staging, &dir.path().join("OUT"));
        assert_eq!(
            shown(&staging.join("a/truth.exr")),
            dir.path().join("OUT/a/truth.exr")
        );
    }
}
