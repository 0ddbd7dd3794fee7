//! A scene file's text and the errors that point into it (file, line, column, key).

use std::fmt;
use std::path::{Path, PathBuf};

use toml_edit::ImDocument;

use crate::scene::limits::MAX_SCENE_BYTES;
pub use crate::scene::limits::{MAX_PIXELS, MAX_RESOLUTION};

/// A scene file's text, with the offsets of its lines to turn byte offsets into line and
/// column numbers in O(log lines).
pub struct SourceFile {
    pub path: PathBuf,
    text: String,
    /// Byte offset of the start of every line.
    line_starts: Vec<usize>,
}

/// An error in a scene file: where it is and what is wrong.
#[derive(Debug, Clone, PartialEq)]
pub struct SceneError {
    pub path: PathBuf,
    /// 1-based line number of the offending value (or table), if known.
    pub line: Option<usize>,
    /// 1-based column (in characters) of the offending value, if known.
    pub column: Option<usize>,
    /// Dotted key path, e.g. `object[3].radius`.
    pub key: String,
    /// What is wrong: one line.
    pub message: String,
}

impl fmt::Display for SceneError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}:", self.path.display())?;
        if let Some(line) = self.line {
            write!(f, "{line}:")?;
            if let Some(column) = self.column {
                write!(f, "{column}:")?;
            }
        }
        if self.key.is_empty() {
            write!(f, " {}", self.message)
        } else {
            write!(f, " key `{}`: {}", self.key, self.message)
        }
    }
}

impl std::error::Error for SceneError {}

/// Text on one line: line breaks and runs of white space become single spaces.
pub fn one_line(text: &str) -> String {
    text.split_whitespace().collect::<Vec<_>>().join(" ")
}

impl SourceFile {
    pub fn read(path: &Path) -> Result<Self, SceneError> {
        let error = |message: String| SceneError {
            path: path.to_path_buf(),
            line: None,
            column: None,
            key: String::new(),
            message,
        };
        let text = crate::util::input_file::read_input_text(path, MAX_SCENE_BYTES)
            .map_err(|e| error(format!("cannot read the file: {e}")))?;
        Ok(Self::from_text(path, text))
    }

    /// The content hash of the text (`util::hash::content_hash`).
    pub fn content_hash(&self) -> String {
        crate::util::hash::content_hash(self.text.as_bytes())
    }

    pub fn from_text(path: &Path, text: String) -> Self {
        let line_starts = std::iter::once(0)
            .chain(text.match_indices('\n').map(|(i, _)| i + 1))
            .collect();
        Self {
            path: path.to_path_buf(),
            text,
            line_starts,
        }
    }

    /// The file's text, as parsed (the spans of its document index into it).
    pub fn text(&self) -> &str {
        &self.text
    }

    /// 1-based line of a byte offset.
    pub fn line_of(&self, offset: usize) -> usize {
        self.line_starts.partition_point(|&start| start <= offset)
    }

    /// 1-based (line, column) of a byte offset; the column counts characters.
    pub fn position_of(&self, offset: usize) -> (usize, usize) {
        let offset = offset.min(self.text.len());
        let line = self.line_of(offset);
        let start = self.line_starts[line - 1];
        let column = self
            .text
            .get(start..offset)
            .map_or(offset - start, |s| s.chars().count());
        (line, column + 1)
    }

    /// Parses the TOML and returns the reader of its root table.
    pub fn parse(&self) -> Result<ImDocument<&str>, SceneError> {
        ImDocument::parse(self.text.as_str()).map_err(|e| {
            let (line, column) = e
                .span()
                .map(|s| self.position_of(s.start))
                .map_or((None, None), |(l, c)| (Some(l), Some(c)));
            SceneError {
                path: self.path.clone(),
                line,
                column,
                key: String::new(),
                message: format!("invalid TOML: {}", one_line(e.message())),
            }
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

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn lines_and_columns_of_offsets() {
        let file = SourceFile::from_text(Path::new("x.toml"), "ab\nçd = 1\n\nx".into());
        assert_eq!(file.line_of(0), 1);
        assert_eq!(file.line_of(2), 1);
        assert_eq!(file.line_of(3), 2);
        assert_eq!(file.position_of(3 + "çd".len()), (2, 3));
        assert_eq!(file.position_of(file.text.len()), (4, 2));
        assert_eq!(file.line_of(usize::MAX), 4);
    }
}
