//! An output directory written whole or not at all. A command writes its files into a staging
//! folder beside the output (`.<name>.tmp-<pid>`), and only when every file is written are
//! they moved into place: a command that fails, or is interrupted, leaves the output location
//! as it found it — no partial set of files, no empty folder it created. A staging folder left
//! by a killed process is removed by the next command writing the same output.

use std::path::{Path, PathBuf};

use anyhow::{Context, Result, bail};

use crate::io::atomic::{create_folders, in_flight, remove_stale, temporary, track};

/// A staging folder for the output directory `target`; dropped without [`commit`], it is
/// removed with everything in it, and so are the folders it created.
///
/// [`commit`]: StagedDir::commit
pub struct StagedDir {
    target: PathBuf,
    /// The target as the caller named it (`` for the current folder), for paths in messages.
    shown: PathBuf,
    staging: PathBuf,
    /// The topmost folder that this created (removed on failure, if empty), and the innermost
    /// one the removal starts from.
    created: Option<(PathBuf, PathBuf)>,
    committed: bool,
    /// Whether an existing target is swapped whole (a folder output), not merged file by
    /// file (files staged into a shared folder, [`StagedDir::inside`]).
    swaps: bool,
}

impl StagedDir {
    /// Stages the output directory `target`, which must be a directory or not exist yet. The
    /// staging folder lies beside it.
    pub fn new(target: &Path) -> Result<Self> {
        // `.` and `..` name no folder of their own: stage beside the folder they are.
        let resolved;
        let target = if target.file_name().is_none() {
            resolved = target
                .canonicalize()
                .with_context(|| format!("cannot find the output {}", target.display()))?;
            resolved.as_path()
        } else {
            target
        };
        if target.exists() && !target.is_dir() {
            bail!(
                "the output {} exists and is not a directory",
                target.display()
            );
        }
        let name = target
            .file_name()
            .with_context(|| format!("not a directory path: {}", target.display()))?
            .to_string_lossy()
            .to_string();
        let parent = target.parent().unwrap_or(Path::new(""));
        Self::create(target, parent, &name, target)
    }

    /// Stages files that go into the folder `folder` (created if missing), for an output
    /// named `name` there: the staging folder `.<name>.tmp-<pid>` lies inside `folder`, so
    /// the files move into place by renames on one file system, and a file beside the
    /// output (a `.mtl`, an assets folder) is staged with it.
    pub fn inside(folder: &Path, name: &str) -> Result<Self> {
        let target = if folder.as_os_str().is_empty() {
            Path::new(".")
        } else {
            folder
        };
        if target.exists() && !target.is_dir() {
            bail!("{} is a file, not a folder", target.display());
        }
        // `commit` moves the files into the folder itself.
        let mut staged = Self::create(target, target, name, &folder.join(name))?;
        staged.shown = folder.to_path_buf();
        staged.swaps = false;
        in_flight().stage_as(&staged.staging, folder);
        Ok(staged)
    }

    /// Creates `parent` (where missing) and the staging folder `.<name>.tmp-<pid>` in it,
    /// under the registry's lock: no staging folder is created once an interrupt began.
    /// `output` is the path messages name: the folder, or the file staged inside one.
    fn create(target: &Path, parent: &Path, name: &str, output: &Path) -> Result<Self> {
        let created = parent
            .ancestors()
            .take_while(|a| !a.as_os_str().is_empty() && !a.exists())
            .last()
            .map(|top| (top.to_path_buf(), parent.to_path_buf()));
        // Declared before the lock: on an error, dropped (and cleaned up) after its release.
        let mut staged = Self {
            target: target.to_path_buf(),
            shown: target.to_path_buf(),
            staging: temporary(&parent.join(name), name, std::process::id()),
            created: None,
            committed: false,
            swaps: true,
        };
        let mut state = in_flight();
        state.check_running()?;
        remove_stale(&parent.join(name), name);
        let _ = std::fs::remove_dir_all(&staged.staging);
        create_folders(&state, parent)
            .with_context(|| format!("cannot write the output {}", output.display()))?;
        staged.created = created;
        std::fs::create_dir(&staged.staging).map_err(|e| {
            anyhow::anyhow!(
                "cannot write the output {}: cannot create a folder in {}: {e}",
                output.display(),
                if parent.as_os_str().is_empty() {
                    Path::new(".")
                } else {
                    parent
                }
                .display()
            )
        })?;
        state.track(&staged.staging, true);
        state.stage_as(&staged.staging, target);
        Ok(staged)
    }

    /// Where the command writes its files (and folders).
    pub fn path(&self) -> &Path {
        &self.staging
    }

    /// Where the staged file `staged` (a path under [`path`]) goes on [`commit`].
    ///
    /// [`path`]: StagedDir::path
    /// [`commit`]: StagedDir::commit
    pub fn final_path(&self, staged: &Path) -> PathBuf {
        staged
            .strip_prefix(&self.staging)
            .map_or_else(|_| staged.to_path_buf(), |rest| self.shown.join(rest))
    }

    /// Moves every staged file into the output directory (replacing files of the same name)
    /// and removes the staging folder. Nothing is moved unless every file can be. The moves
    /// hold the registry's lock: an interrupt comes before them (nothing moved) or after.
    pub fn commit(mut self) -> Result<()> {
        let mut state = in_flight();
        state.check_running()?;
        if !self.target.exists() {
            std::fs::rename(&self.staging, &self.target).with_context(|| {
                format!("cannot move the output into {}", self.target.display())
            })?;
        } else {
            let mut moves = Vec::new();
            plan_moves(&self.staging, &self.target, &mut moves)?;
            // Into an existing folder: the old files the new set does not replace join the
            // staging folder, and the two folders swap in one step, so a kill at any moment
            // leaves the old set or the new one, never a mix. Where the file system cannot
            // swap (or the folder holds the current directory, which a swap would unlink),
            // the files move one by one.
            if self.swaps && swaps_whole(&self.target) {
                // Temporaries that killed processes left for these files go, as with moves.
                for (_, to) in &moves {
                    if let Some(name) = to.file_name() {
                        remove_stale(to, &name.to_string_lossy());
                    }
                }
                keep_old_files(&self.target, &self.staging).with_context(|| {
                    format!("cannot keep the files of {}", self.target.display())
                })?;
                // `out/.` names `out`, but renameat2 refuses a path ending in `.`.
                let target: PathBuf = self.target.components().collect();
                match exchange(&self.staging, &target) {
                    Ok(()) => {
                        // The staging path now holds the old set.
                        let _ = std::fs::remove_dir_all(&self.staging);
                        self.committed = true;
                        state.track(&self.staging, false);
                        return Ok(());
                    }
                    Err(e) if e.kind() == std::io::ErrorKind::Unsupported => {}
                    Err(e) => {
                        return Err(e).with_context(|| {
                            format!("cannot move the output into {}", self.target.display())
                        });
                    }
                }
            }
            for (from, to) in moves {
                if let (Some(dir), Some(name)) = (to.parent(), to.file_name()) {
                    create_folders(&state, dir)?;
                    remove_stale(&to, &name.to_string_lossy());
                }
                std::fs::rename(&from, &to)
                    .with_context(|| format!("cannot move {} into place", to.display()))?;
            }
            let _ = std::fs::remove_dir_all(&self.staging);
        }
        self.committed = true;
        state.track(&self.staging, false);
        Ok(())
    }
}

/// Whether the output `target` (an existing folder) is replaced by swapping folders: not
/// when it holds the current directory.
fn swaps_whole(target: &Path) -> bool {
    match (std::env::current_dir(), target.canonicalize()) {
        (Ok(here), Ok(target)) => !here.starts_with(target),
        _ => false,
    }
}

/// Hard-links (or copies, where links fail) every file of `old` that `new` lacks into `new`,
/// folders made as needed, so that `new` holds the set the file-by-file moves would leave.
fn keep_old_files(old: &Path, new: &Path) -> Result<()> {
    for entry in std::fs::read_dir(old)? {
        let entry = entry?;
        let (from, to) = (entry.path(), new.join(entry.file_name()));
        let kind = entry.file_type()?;
        if kind.is_dir() {
            if !to.exists() {
                std::fs::create_dir(&to)?;
            }
            keep_old_files(&from, &to)?;
        } else if std::fs::symlink_metadata(&to).is_err() && std::fs::hard_link(&from, &to).is_err()
        {
            std::fs::copy(&from, &to)?;
        }
    }
    Ok(())
}

/// Swaps the folders `a` and `b` in one step (Linux `renameat2` with `RENAME_EXCHANGE`);
/// `Unsupported` where the system or the file system cannot.
#[cfg(target_os = "linux")]
fn exchange(a: &Path, b: &Path) -> std::io::Result<()> {
    use rustix::fs::{CWD, RenameFlags, renameat_with};
    match renameat_with(CWD, a, CWD, b, RenameFlags::EXCHANGE) {
        Ok(()) => Ok(()),
        Err(e) if e == rustix::io::Errno::INVAL || e == rustix::io::Errno::NOSYS => Err(
            std::io::Error::new(std::io::ErrorKind::Unsupported, "no RENAME_EXCHANGE"),
        ),
        Err(e) => Err(e.into()),
    }
}

#[cfg(not(target_os = "linux"))]
fn exchange(_: &Path, _: &Path) -> std::io::Result<()> {
    Err(std::io::Error::new(
        std::io::ErrorKind::Unsupported,
        "no atomic folder swap here",
    ))
}

/// Every file under `from` with its place under `to`; an error, before anything moves, where
/// a file would replace a folder or a folder a file.
fn plan_moves(from: &Path, to: &Path, moves: &mut Vec<(PathBuf, PathBuf)>) -> Result<()> {
    let entries =
        std::fs::read_dir(from).with_context(|| format!("cannot read {}", from.display()))?;
    for entry in entries {
        let entry = entry?;
        let (source, dest) = (entry.path(), to.join(entry.file_name()));
        if entry.file_type()?.is_dir() {
            if dest.exists() && !dest.is_dir() {
                bail!(
                    "cannot write {}: a file of that name is in the way",
                    dest.display()
                );
            }
            plan_moves(&source, &dest, moves)?;
        } else {
            if dest.is_dir() {
                bail!(
                    "cannot write {}: a folder of that name is in the way",
                    dest.display()
                );
            }
            moves.push((source, dest));
        }
    }
    Ok(())
}

impl Drop for StagedDir {
    fn drop(&mut self) {
        if self.committed {
            return;
        }
        let _ = std::fs::remove_dir_all(&self.staging);
        track(&self.staging, false);
        // The folders this created, innermost first, each only if it is empty.
        if let Some((top, innermost)) = &self.created {
            for folder in innermost.ancestors() {
                if std::fs::remove_dir(folder).is_err() || folder == top {
                    break;
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn names(dir: &Path) -> Vec<String> {
        let mut names: Vec<String> = std::fs::read_dir(dir)
            .unwrap()
            .flatten()
            .map(|e| e.file_name().to_string_lossy().to_string())
            .collect();
        names.sort();
        names
    }

    #[test]
    fn a_dropped_stage_leaves_nothing_and_a_commit_moves_everything() {
        let scratch = tempfile::tempdir().unwrap();
        let target = scratch.path().join("new/nested/out");
        let staged = StagedDir::new(&target).unwrap();
        std::fs::write(staged.path().join("a.txt"), "a").unwrap();
        drop(staged);
        assert_eq!(names(scratch.path()), Vec::<String>::new());

        let staged = StagedDir::new(&target).unwrap();
        std::fs::create_dir(staged.path().join("sub")).unwrap();
        std::fs::write(staged.path().join("sub/b.txt"), "b").unwrap();
        staged.commit().unwrap();
        assert_eq!(names(&target), ["sub"]);

        // Into an existing folder: files replaced, others kept, nothing moved when one
        // cannot be.
        std::fs::write(target.join("keep.txt"), "k").unwrap();
        let staged = StagedDir::new(&target).unwrap();
        std::fs::write(staged.path().join("keep.txt"), "new").unwrap();
        std::fs::write(staged.path().join("sub"), "a file where a folder is").unwrap();
        assert!(staged.commit().is_err());
        assert_eq!(
            std::fs::read_to_string(target.join("keep.txt")).unwrap(),
            "k"
        );
        assert_eq!(names(&target), ["keep.txt", "sub"]);
        assert_eq!(names(target.parent().unwrap()), ["out"]);

        // `.` is the folder it names.
        let here = target.join("sub/.");
        let staged = StagedDir::new(&here).unwrap();
        std::fs::write(staged.path().join("c.txt"), "c").unwrap();
        staged.commit().unwrap();
        assert_eq!(names(&target.join("sub")), ["b.txt", "c.txt"]);
    }
}
