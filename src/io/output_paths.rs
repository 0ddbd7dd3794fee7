//! The paths a command reads and writes, checked before any work starts: an output that would
//! overwrite one of the command's inputs (a report written over the expectations it was
//! made from, a run folder swapped in over the scene's folder), an output that cannot be
//! written (under `/proc`, below a file, a folder where a file goes), and an input that is not
//! a plain file or folder (a FIFO would hang the reader) are refused, with the option named,
//! before a case runs or a pixel is traced.

use std::path::{Path, PathBuf};

use anyhow::{Result, bail};

use crate::util::input_file::not_a_file;

/// How a command writes an output path.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Written {
    /// One file, replaced whole (with, perhaps, files beside it of the same stem).
    File,
    /// A folder replaced whole: nothing the command reads may lie inside it.
    Folder,
}

/// How a command reads an input path.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Read {
    File,
    Folder,
    /// A file or a folder (`diff` compares two images or two run folders).
    Either,
}

/// One path a command writes: the option that names it (as the front end spells it), the path.
#[derive(Clone, Copy, Debug)]
pub struct Output<'a> {
    pub option: &'a str,
    pub path: &'a Path,
    pub written: Written,
}

/// One path a command reads.
#[derive(Clone, Copy, Debug)]
pub struct Input<'a> {
    pub option: &'a str,
    pub path: &'a Path,
    pub read: Read,
}

impl<'a> Input<'a> {
    pub fn file(option: &'a str, path: &'a Path) -> Self {
        Input {
            option,
            path,
            read: Read::File,
        }
    }

    pub fn folder(option: &'a str, path: &'a Path) -> Self {
        Input {
            option,
            path,
            read: Read::Folder,
        }
    }
}

impl<'a> Output<'a> {
    pub fn file(option: &'a str, path: &'a Path) -> Self {
        Output {
            option,
            path,
            written: Written::File,
        }
    }

    pub fn folder(option: &'a str, path: &'a Path) -> Self {
        Output {
            option,
            path,
            written: Written::Folder,
        }
    }
}

/// Refuses, in one line, the first input that is not a readable plain file or folder of its
/// kind, and the first output that cannot be written or would overwrite an input.
pub fn check_paths(inputs: &[Input], outputs: &[Output]) -> Result<()> {
    for input in inputs {
        check_input(input)?;
    }
    for output in outputs {
        check_output(output)?;
        let written = resolved(output.path);
        for input in inputs {
            let read = resolved(input.path);
            let clash = match output.written {
                Written::File => written == read,
                Written::Folder => read.starts_with(&written),
            };
            if clash {
                let how = if written == read {
                    "is"
                } else {
                    "is a folder holding"
                };
                bail!(
                    "{} {}: {how} the input {} ({}) this command reads; writing it would destroy that input: choose another path",
                    output.option,
                    output.path.display(),
                    input.path.display(),
                    input.option,
                );
            }
        }
    }
    for (i, a) in outputs.iter().enumerate() {
        for b in &outputs[i + 1..] {
            if resolved(a.path) == resolved(b.path) {
                bail!(
                    "{} and {} name the same path {}: each output needs its own",
                    a.option,
                    b.option,
                    a.path.display()
                );
            }
        }
    }
    Ok(())
}

/// An input is what the command reads there: a FIFO, a device or a folder given for a file
/// would hang or fail mid-way. A missing input is left to its reader, which names what it
/// needed it for.
pub fn check_input(input: &Input) -> Result<()> {
    let shown = input.path.display();
    let Ok(meta) = std::fs::metadata(input.path) else {
        return Ok(());
    };
    match input.read {
        Read::File => match not_a_file(input.path) {
            Some(why) => bail!("{} {shown}: {why}", input.option),
            None => Ok(()),
        },
        Read::Folder if !meta.is_dir() => {
            bail!("{} {shown}: it is not a folder", input.option)
        }
        Read::Either if !meta.is_dir() && !meta.is_file() => bail!(
            "{} {shown}: it is not a regular file or a folder (a device, a pipe or a socket)",
            input.option
        ),
        _ => Ok(()),
    }
}

/// An output can be written: what exists there is of its kind, and the nearest existing folder
/// above it takes a new file (probed by creating and removing one).
pub fn check_output(output: &Output) -> Result<()> {
    let shown = output.path.display();
    if let Ok(meta) = std::fs::metadata(output.path) {
        match output.written {
            Written::File => {
                if let Some(why) = not_a_file(output.path) {
                    bail!("{} {shown}: {why}", output.option);
                }
            }
            Written::Folder if !meta.is_dir() => {
                bail!("{} {shown}: it exists and is not a folder", output.option)
            }
            Written::Folder => {}
        }
    }
    // The folder the output's staging goes into: its nearest existing ancestor.
    let mut folder = output.path.parent().map(Path::to_path_buf);
    while let Some(f) = &folder {
        let f = if f.as_os_str().is_empty() {
            Path::new(".")
        } else {
            f.as_path()
        };
        if f.exists() {
            break;
        }
        folder = f.parent().map(Path::to_path_buf);
    }
    let folder = match folder {
        Some(f) if !f.as_os_str().is_empty() => f,
        _ => PathBuf::from("."),
    };
    if !folder.is_dir() {
        bail!(
            "{} {shown}: {} is a file, not a folder",
            output.option,
            folder.display()
        );
    }
    let probe = folder.join(format!(".seethru-probe-{}", std::process::id()));
    match std::fs::OpenOptions::new()
        .write(true)
        .create_new(true)
        .open(&probe)
    {
        Ok(_) => {
            std::fs::remove_file(&probe).ok();
            Ok(())
        }
        Err(e) if e.kind() == std::io::ErrorKind::AlreadyExists => Ok(()),
        Err(e) => bail!(
            "{} {shown}: cannot write into {}: {e}",
            output.option,
            folder.display()
        ),
    }
}

/// The path with every existing part resolved (links, `..`), the rest appended: two names of
/// one file resolve alike, whether or not it exists yet.
fn resolved(path: &Path) -> PathBuf {
    let absolute = std::path::absolute(path).unwrap_or_else(|_| path.to_path_buf());
    let mut existing = absolute.clone();
    let mut rest: Vec<std::ffi::OsString> = Vec::new();
    loop {
        if let Ok(real) = existing.canonicalize() {
            // The parts that do not exist yet are taken as written, `..` and `.` resolved by
            // name: the folders a command creates on the way hold no links.
            let mut path = real;
            for part in rest.iter().rev() {
                match part.to_str() {
                    Some("..") => {
                        path.pop();
                    }
                    Some(".") => {}
                    _ => path.push(part),
                }
            }
            return path;
        }
        let Some(last) = existing.components().next_back() else {
            return absolute;
        };
        rest.push(last.as_os_str().to_os_string());
        if !existing.pop() {
            return absolute;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn input(path: &Path, read: Read) -> Input<'_> {
        Input {
            option: "IN",
            path,
            read,
        }
    }

    fn output(path: &Path, written: Written) -> Output<'_> {
        Output {
            option: "--out",
            path,
            written,
        }
    }

    #[test]
    fn an_output_over_an_input_or_around_it_is_refused_and_a_path_beside_it_is_not() {
        let dir = tempfile::tempdir().unwrap();
        let scene = dir.path().join("scenes/a.toml");
        std::fs::create_dir_all(scene.parent().unwrap()).unwrap();
        std::fs::write(&scene, "x").unwrap();
        let inputs = [input(&scene, Read::File)];
        let refused = |path: PathBuf, written| {
            let err = check_paths(&inputs, &[output(&path, written)]).unwrap_err();
            assert!(err.to_string().contains("would destroy"), "{err}");
        };
        // The same file under other names.
        refused(scene.clone(), Written::File);
        refused(dir.path().join("scenes/../scenes/./a.toml"), Written::File);
        refused(dir.path().join("new/../scenes/a.toml"), Written::File);
        // A folder replaced whole that holds the input.
        refused(dir.path().join("scenes"), Written::Folder);
        refused(dir.path().to_path_buf(), Written::Folder);
        // Beside it, or a file named like its folder's child that is not it: fine.
        for (path, written) in [
            (dir.path().join("scenes/b.toml"), Written::File),
            (dir.path().join("out"), Written::Folder),
            (dir.path().join("scenes/a.toml.d"), Written::Folder),
            (dir.path().join("new/deeper/x.csv"), Written::File),
        ] {
            check_paths(&inputs, &[output(&path, written)]).unwrap();
        }
        // A file output that is a folder holding the input is no clash (it fails as a folder).
        let err = check_paths(
            &inputs,
            &[output(&dir.path().join("scenes"), Written::File)],
        )
        .unwrap_err();
        assert!(err.to_string().contains("is a folder"), "{err}");
        // Two outputs on one path.
        let p = dir.path().join("r.xml");
        let err =
            check_paths(&[], &[output(&p, Written::File), output(&p, Written::File)]).unwrap_err();
        assert!(err.to_string().contains("same path"), "{err}");
    }

    #[test]
    fn an_output_that_cannot_be_written_and_an_input_that_is_no_plain_file_are_refused() {
        let dir = tempfile::tempdir().unwrap();
        let file = dir.path().join("f.txt");
        std::fs::write(&file, "x").unwrap();
        for (path, written, says) in [
            (
                file.join("below.xml"),
                Written::File,
                "is a file, not a folder",
            ),
            (file.clone(), Written::Folder, "is not a folder"),
            (
                dir.path().to_path_buf(),
                Written::File,
                "is a folder, not a file",
            ),
            (
                PathBuf::from("/proc/x.xml"),
                Written::File,
                "cannot write into /proc",
            ),
        ] {
            let err = check_output(&output(&path, written)).unwrap_err();
            assert!(err.to_string().contains(says), "{path:?}: {err}");
            assert!(err.to_string().starts_with("--out "), "{err}");
        }
        check_output(&output(&file, Written::File)).unwrap();
        check_output(&output(&dir.path().join("a/b/c"), Written::Folder)).unwrap();
        // Nothing is left behind by the probe.
        assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 1);

        let fifo = dir.path().join("fifo.json");
        let made = std::process::Command::new("mkfifo").arg(&fifo).status();
        if made.is_ok_and(|s| s.success()) {
            let err = check_input(&input(&fifo, Read::File)).unwrap_err();
            assert!(err.to_string().contains("not a regular file"), "{err}");
            // An input that may be a file or a folder (`diff`'s) is neither as a pipe.
            let err = check_input(&input(&fifo, Read::Either)).unwrap_err();
            assert!(
                err.to_string().contains("not a regular file or a folder"),
                "{err}"
            );
        }
        for (path, read, says) in [
            (
                dir.path().to_path_buf(),
                Read::File,
                "is a folder, not a file",
            ),
            (file.clone(), Read::Folder, "is not a folder"),
        ] {
            let err = check_input(&input(&path, read)).unwrap_err();
            assert!(err.to_string().contains(says), "{path:?}: {err}");
        }
        check_input(&input(&file, Read::File)).unwrap();
        check_input(&input(&dir.path().join("none"), Read::File)).unwrap();
        check_input(&input(dir.path(), Read::Folder)).unwrap();
        check_input(&input(&file, Read::Either)).unwrap();
        check_input(&input(dir.path(), Read::Either)).unwrap();
    }

    #[test]
    fn a_probe_left_by_this_process_does_not_make_a_folder_unwritable() {
        // A probe of the same name (a process of this id killed between creating and removing
        // it) proves the folder takes files; it is someone's file: left alone.
        let dir = tempfile::tempdir().unwrap();
        let left = dir
            .path()
            .join(format!(".seethru-probe-{}", std::process::id()));
        std::fs::write(&left, "x").unwrap();
        check_output(&output(&dir.path().join("r.xml"), Written::File)).unwrap();
        assert_eq!(std::fs::read_to_string(&left).unwrap(), "x");
    }
}
