//! Reading a file that a person or another program wrote, within a limit: a regular file only
//! (a folder is named as one; `/dev/zero` would be read until memory runs out and a FIFO would
//! block for good), and never more than the limit, checked against the size the file reports
//! and again while reading (a file can grow, and `/proc` files report 0).

use std::io::Read;
use std::path::{Path, PathBuf};
use std::sync::{Mutex, PoisonError};

/// Every input file this process has opened, so that a command can refuse to write over one
/// of its inputs.
static INPUTS: Mutex<Vec<PathBuf>> = Mutex::new(Vec::new());

/// Records `path` as an input of this process (readers outside [`read_input`] call it).
pub fn note_input(path: &Path) {
    let mut inputs = INPUTS.lock().unwrap_or_else(PoisonError::into_inner);
    if !inputs.iter().any(|p| p == path) {
        inputs.push(path.to_path_buf());
    }
}

/// The input `path` is, if it is one this process has read (the same file, under whatever
/// name: links and `..` included).
pub fn input_at(path: &Path) -> Option<PathBuf> {
    let inputs = INPUTS.lock().unwrap_or_else(PoisonError::into_inner);
    inputs.iter().find(|input| same_file(input, path)).cloned()
}

/// Whether `a` and `b` are one existing file.
pub fn same_file(a: &Path, b: &Path) -> bool {
    let (Ok(ma), Ok(mb)) = (std::fs::metadata(a), std::fs::metadata(b)) else {
        return false;
    };
    #[cfg(unix)]
    {
        use std::os::unix::fs::MetadataExt;
        ma.dev() == mb.dev() && ma.ino() == mb.ino()
    }
    #[cfg(not(unix))]
    {
        let _ = (ma, mb);
        matches!((a.canonicalize(), b.canonicalize()), (Ok(x), Ok(y)) if x == y)
    }
}

/// A size in bytes for a message: `64 MiB`, `1 GiB`, `812 bytes`.
pub fn bytes_text(bytes: u64) -> String {
    const UNITS: [(&str, u64); 3] = [("GiB", 1 << 30), ("MiB", 1 << 20), ("KiB", 1 << 10)];
    for (unit, size) in UNITS {
        if bytes >= size {
            let value = bytes as f64 / size as f64;
            return if bytes.is_multiple_of(size) {
                format!("{} {unit}", bytes / size)
            } else {
                format!("{value:.1} {unit}")
            };
        }
    }
    format!("{bytes} bytes")
}

/// Why `path` cannot be read as an input file, or `None` where it is a regular file.
pub fn not_a_file(path: &Path) -> Option<String> {
    match std::fs::metadata(path) {
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => Some("no such file".into()),
        Err(e) => Some(e.to_string()),
        Ok(m) if m.is_dir() => Some("it is a folder, not a file".into()),
        Ok(m) if !m.is_file() => {
            Some("it is not a regular file (a device, a pipe or a socket)".into())
        }
        Ok(_) => None,
    }
}

/// The bytes of the regular file `path`, at most `limit` of them; the error says why in words
/// (without the path, which the caller names as the user wrote it).
pub fn read_input(path: &Path, limit: u64) -> std::io::Result<Vec<u8>> {
    note_input(path);
    if let Some(why) = not_a_file(path) {
        return Err(std::io::Error::other(why));
    }
    let too_large = |size: &str| {
        std::io::Error::other(format!(
            "{size} is larger than the limit of {}",
            bytes_text(limit)
        ))
    };
    let reported = std::fs::metadata(path)?.len();
    if reported > limit {
        return Err(too_large(&bytes_text(reported)));
    }
    let mut bytes = Vec::with_capacity(reported as usize);
    std::fs::File::open(path)?
        .take(limit + 1)
        .read_to_end(&mut bytes)?;
    if bytes.len() as u64 > limit {
        return Err(too_large("the file (it grew while read)"));
    }
    Ok(bytes)
}

/// [`read_input_text`] parsed as JSON; the error names the file.
pub fn read_input_json(path: &Path, limit: u64) -> anyhow::Result<serde_json::Value> {
    use anyhow::Context;
    let text = read_input_text(path, limit)?;
    serde_json::from_str(&text)
        .with_context(|| format!("cannot read {}: invalid JSON", path.display()))
}

/// [`read_input`] as UTF-8 text; the error names the first byte that is not.
pub fn read_input_text(path: &Path, limit: u64) -> std::io::Result<String> {
    String::from_utf8(read_input(path, limit)?).map_err(|e| {
        let at = e.utf8_error().valid_up_to();
        std::io::Error::other(format!("not UTF-8 text (byte {at} is not)"))
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn folders_devices_and_files_past_the_limit_are_refused_without_reading_them() {
        let dir = tempfile::tempdir().unwrap();
        let folder = read_input(dir.path(), 10).unwrap_err().to_string();
        assert!(folder.contains("folder"), "{folder}");
        // /dev/zero reports size 0 and never ends: refused before a byte is read.
        let device = read_input(Path::new("/dev/zero"), 10)
            .unwrap_err()
            .to_string();
        assert!(device.contains("not a regular file"), "{device}");
        let file = dir.path().join("f");
        std::fs::write(&file, [b'x'; 11]).unwrap();
        let large = read_input(&file, 10).unwrap_err().to_string();
        assert!(
            large.contains("11 bytes is larger than the limit of 10 bytes"),
            "{large}"
        );
        assert_eq!(read_input(&file, 11).unwrap().len(), 11);
        let missing = read_input(&dir.path().join("none"), 10).unwrap_err();
        assert_eq!(missing.to_string(), "no such file");
        std::fs::write(&file, b"ok\xff").unwrap();
        let text = read_input_text(&file, 10).unwrap_err().to_string();
        assert!(text.contains("byte 2"), "{text}");
    }

    #[test]
    fn sizes_read_in_binary_units() {
        assert_eq!(bytes_text(64 << 20), "64 MiB");
        assert_eq!(bytes_text(1 << 30), "1 GiB");
        assert_eq!(bytes_text(3 << 29), "1.5 GiB");
        assert_eq!(bytes_text(812), "812 bytes");
    }
}
