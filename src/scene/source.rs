//! A scene file's text and the errors that point into it (file, line, key).

use std::fmt;
use std::path::{Path, PathBuf};

use toml_edit::ImDocument;

/// A scene file's text, kept to turn byte offsets into line numbers.
pub struct SourceFile {
    pub path: PathBuf,
    text: String,
}

/// An error in a scene file: where it is and what is wrong.
#[derive(Debug, Clone, PartialEq)]
pub struct SceneError {
    pub path: PathBuf,
    /// 1-based line number of the offending value (or table), if known.
    pub line: Option<usize>,
    /// Dotted key path, e.g. `object[3].radius`.
    pub key: String,
    pub message: String,
}

impl fmt::Display for SceneError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self.line {
            Some(line) => write!(f, "{}:{}: ", self.path.display(), line)?,
            None => write!(f, "{}: ", self.path.display())?,
        }
        if self.key.is_empty() {
            write!(f, "{}", self.message)
        } else {
            write!(f, "key `{}`: {}", self.key, self.message)
        }
    }
}

impl std::error::Error for SceneError {}

impl SourceFile {
    pub fn read(path: &Path) -> Result<Self, SceneError> {
        let text = std::fs::read_to_string(path).map_err(|e| SceneError {
            path: path.to_path_buf(),
            line: None,
            key: String::new(),
            message: format!("cannot read scene file: {e}"),
        })?;
        Ok(Self::from_text(path, text))
    }

    pub fn from_text(path: &Path, text: String) -> Self {
        Self {
            path: path.to_path_buf(),
            text,
        }
    }

    pub fn line_of(&self, offset: usize) -> usize {
        let end = offset.min(self.text.len());
        self.text.as_bytes()[..end]
            .iter()
            .filter(|&&b| b == b'\n')
            .count()
            + 1
    }

    /// Parses the TOML and returns the reader of its root table.
    pub fn parse(&self) -> Result<ImDocument<&str>, SceneError> {
        ImDocument::parse(self.text.as_str()).map_err(|e| SceneError {
            path: self.path.clone(),
            line: e.span().map(|s| self.line_of(s.start)),
            key: String::new(),
            message: format!("invalid TOML: {}", e.message()),
        })
    }

    /// Directory that relative asset paths in this file are resolved against.
    pub fn dir(&self) -> PathBuf {
        self.path
            .parent()
            .map(Path::to_path_buf)
            .unwrap_or_default()
    }
}

/// Largest image side accepted anywhere, in pixels.
pub const MAX_RESOLUTION: u32 = 16384;
/// Largest image accepted anywhere, in pixels (16k × 8k): beyond it the AOVs of one frame
/// would not fit in memory.
pub const MAX_PIXELS: u64 = 16384 * 8192;
