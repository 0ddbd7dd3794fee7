//! Typed, span-aware reading of one TOML table.
//!
//! Scene files are data: every object kind reads its keys through a [`TableReader`], which
//! checks types and ranges, supplies documented defaults and rejects unknown keys. Every error
//! names the file, the line and the key, so that a user can fix the file without guessing.

use std::cell::RefCell;

use toml_edit::{ImDocument, Item, TableLike};

use crate::scene::source::{MAX_PIXELS, MAX_RESOLUTION, SceneError, SourceFile};

/// Reads the keys of one TOML table, remembering which were read so that
/// [`TableReader::finish`] can reject the rest as unknown.
pub struct TableReader<'a> {
    file: &'a SourceFile,
    table: &'a dyn TableLike,
    /// Key path of this table, e.g. `object[2]`; empty for the root.
    prefix: String,
    /// Line of the table header, for errors about missing keys.
    line: Option<usize>,
    read: RefCell<Vec<String>>,
}

impl<'a> TableReader<'a> {
    pub fn root(file: &'a SourceFile, doc: &'a ImDocument<&'a str>) -> Self {
        Self {
            file,
            table: doc.as_table(),
            prefix: String::new(),
            line: None,
            read: RefCell::new(Vec::new()),
        }
    }

    fn full_key(&self, key: &str) -> String {
        if self.prefix.is_empty() {
            key.to_string()
        } else {
            format!("{}.{}", self.prefix, key)
        }
    }

    /// An error located at `key` of this table (its value's line, else the table's).
    pub fn error(&self, key: &str, message: impl Into<String>) -> SceneError {
        let line = self
            .table
            .get_key_value(key)
            .and_then(|(k, item)| item.span().or_else(|| k.span()))
            .map(|s| self.file.line_of(s.start))
            .or(self.line);
        SceneError {
            path: self.file.path.clone(),
            line,
            key: self.full_key(key),
            message: message.into(),
        }
    }

    fn item(&self, key: &str) -> Option<&'a Item> {
        self.read.borrow_mut().push(key.to_string());
        self.table.get(key)
    }

    pub fn has(&self, key: &str) -> bool {
        self.table.get(key).is_some()
    }

    /// A sub-table (`[a.b]` or an inline table), if present.
    pub fn table(&self, key: &str) -> Result<Option<TableReader<'a>>, SceneError> {
        let Some(item) = self.item(key) else {
            return Ok(None);
        };
        let table = item.as_table_like().ok_or_else(|| {
            self.error(key, format!("expected a table, found {}", item.type_name()))
        })?;
        Ok(Some(TableReader {
            file: self.file,
            table,
            prefix: self.full_key(key),
            line: item
                .span()
                .map(|s| self.file.line_of(s.start))
                .or(self.line),
            read: RefCell::new(Vec::new()),
        }))
    }

    /// The tables of an array of tables (`[[key]]`); empty if absent.
    pub fn array_of_tables(&self, key: &str) -> Result<Vec<TableReader<'a>>, SceneError> {
        let Some(item) = self.item(key) else {
            return Ok(Vec::new());
        };
        let make = |i: usize, table: &'a dyn TableLike, span: Option<std::ops::Range<usize>>| {
            TableReader {
                file: self.file,
                table,
                prefix: format!("{}[{}]", self.full_key(key), i),
                line: span.map(|s| self.file.line_of(s.start)).or(self.line),
                read: RefCell::new(Vec::new()),
            }
        };
        if let Some(tables) = item.as_array_of_tables() {
            return Ok(tables
                .iter()
                .enumerate()
                .map(|(i, t)| make(i, t as &dyn TableLike, t.span()))
                .collect());
        }
        if let Some(array) = item.as_array() {
            let mut out = Vec::new();
            for (i, value) in array.iter().enumerate() {
                let table = value.as_inline_table().ok_or_else(|| {
                    self.error(
                        key,
                        format!("element {i} is a {}, expected a table", value.type_name()),
                    )
                })?;
                out.push(make(i, table as &dyn TableLike, value.span()));
            }
            return Ok(out);
        }
        Err(self.error(
            key,
            format!("expected an array of tables, found {}", item.type_name()),
        ))
    }

    /// Rejects every key that was not read: scene files have no ignored keys.
    pub fn finish(self) -> Result<(), SceneError> {
        let read = self.read.borrow();
        for (key, _) in self.table.iter() {
            if !read.iter().any(|k| k == key) {
                let mut known: Vec<&str> = read.iter().map(String::as_str).collect();
                known.sort_unstable();
                known.dedup();
                return Err(self.error(
                    key,
                    format!("unknown key (known keys here: {})", known.join(", ")),
                ));
            }
        }
        Ok(())
    }

    pub fn opt_f64(&self, key: &str) -> Result<Option<f64>, SceneError> {
        let Some(item) = self.item(key) else {
            return Ok(None);
        };
        let value = item
            .as_float()
            .or_else(|| item.as_integer().map(|i| i as f64))
            .ok_or_else(|| {
                self.error(
                    key,
                    format!("expected a number, found {}", item.type_name()),
                )
            })?;
        if !value.is_finite() {
            return Err(self.error(key, format!("must be finite, got {value}")));
        }
        Ok(Some(value))
    }

    /// A number with a default, checked against an inclusive range.
    pub fn f64_in(&self, key: &str, default: f64, min: f64, max: f64) -> Result<f64, SceneError> {
        let value = self.opt_f64(key)?.unwrap_or(default);
        if !(min..=max).contains(&value) {
            return Err(self.error(key, format!("must be in [{min}, {max}], got {value}")));
        }
        Ok(value)
    }

    /// A strictly positive number with a default, at most `max`.
    pub fn positive(&self, key: &str, default: f64, max: f64) -> Result<f64, SceneError> {
        let value = self.opt_f64(key)?.unwrap_or(default);
        if !(value > 0.0 && value <= max) {
            return Err(self.error(key, format!("must be in (0, {max}], got {value}")));
        }
        Ok(value)
    }

    pub fn required_positive(&self, key: &str, max: f64) -> Result<f64, SceneError> {
        if !self.has(key) {
            return Err(self.missing(key));
        }
        self.positive(key, 1.0, max)
    }

    fn missing(&self, key: &str) -> SceneError {
        SceneError {
            path: self.file.path.clone(),
            line: self.line,
            key: self.full_key(key),
            message: "required key is missing".into(),
        }
    }

    pub fn opt_usize(
        &self,
        key: &str,
        min: usize,
        max: usize,
    ) -> Result<Option<usize>, SceneError> {
        let Some(item) = self.item(key) else {
            return Ok(None);
        };
        let value = item.as_integer().ok_or_else(|| {
            self.error(
                key,
                format!("expected an integer, found {}", item.type_name()),
            )
        })?;
        if value < min as i64 || value > max as i64 {
            return Err(self.error(key, format!("must be in [{min}, {max}], got {value}")));
        }
        Ok(Some(value as usize))
    }

    pub fn usize_in(
        &self,
        key: &str,
        default: usize,
        min: usize,
        max: usize,
    ) -> Result<usize, SceneError> {
        Ok(self.opt_usize(key, min, max)?.unwrap_or(default))
    }

    pub fn bool_or(&self, key: &str, default: bool) -> Result<bool, SceneError> {
        let Some(item) = self.item(key) else {
            return Ok(default);
        };
        item.as_bool().ok_or_else(|| {
            self.error(
                key,
                format!("expected true or false, found {}", item.type_name()),
            )
        })
    }

    pub fn opt_str(&self, key: &str) -> Result<Option<&'a str>, SceneError> {
        let Some(item) = self.item(key) else {
            return Ok(None);
        };
        item.as_str().map(Some).ok_or_else(|| {
            self.error(
                key,
                format!("expected a string, found {}", item.type_name()),
            )
        })
    }

    pub fn required_str(&self, key: &str) -> Result<&'a str, SceneError> {
        self.opt_str(key)?.ok_or_else(|| self.missing(key))
    }

    /// A string that must be one of `choices`.
    pub fn choice(
        &self,
        key: &str,
        default: &'a str,
        choices: &[&str],
    ) -> Result<&'a str, SceneError> {
        let value = self.opt_str(key)?.unwrap_or(default);
        if !choices.contains(&value) {
            return Err(self.error(
                key,
                format!("`{value}` is not one of: {}", choices.join(", ")),
            ));
        }
        Ok(value)
    }

    pub fn str_list(&self, key: &str, choices: &[&str]) -> Result<Vec<&'a str>, SceneError> {
        let Some(item) = self.item(key) else {
            return Ok(Vec::new());
        };
        let array = item.as_array().ok_or_else(|| {
            self.error(
                key,
                format!("expected an array of strings, found {}", item.type_name()),
            )
        })?;
        let mut out = Vec::new();
        for value in array.iter() {
            let s = value.as_str().ok_or_else(|| {
                self.error(
                    key,
                    format!("expected strings, found {}", value.type_name()),
                )
            })?;
            if !choices.contains(&s) {
                return Err(self.error(key, format!("`{s}` is not one of: {}", choices.join(", "))));
            }
            out.push(s);
        }
        Ok(out)
    }

    /// A fixed-length array of finite numbers.
    pub fn opt_array<const N: usize>(&self, key: &str) -> Result<Option<[f64; N]>, SceneError> {
        let Some(item) = self.item(key) else {
            return Ok(None);
        };
        let wrong = || self.error(key, format!("expected an array of {N} numbers"));
        let array = item.as_array().ok_or_else(wrong)?;
        if array.len() != N {
            return Err(self.error(key, format!("expected {N} numbers, found {}", array.len())));
        }
        let mut out = [0.0; N];
        for (slot, value) in out.iter_mut().zip(array.iter()) {
            *slot = value
                .as_float()
                .or_else(|| value.as_integer().map(|i| i as f64))
                .ok_or_else(wrong)?;
            if !slot.is_finite() {
                return Err(self.error(key, format!("must be finite, got {slot}")));
            }
        }
        Ok(Some(out))
    }

    pub fn array_or<const N: usize>(
        &self,
        key: &str,
        default: [f64; N],
    ) -> Result<[f64; N], SceneError> {
        Ok(self.opt_array(key)?.unwrap_or(default))
    }

    pub fn required_array<const N: usize>(&self, key: &str) -> Result<[f64; N], SceneError> {
        self.opt_array(key)?.ok_or_else(|| self.missing(key))
    }

    /// An array whose every element is strictly positive (sizes, scales).
    pub fn positive_array<const N: usize>(
        &self,
        key: &str,
        default: [f64; N],
    ) -> Result<[f64; N], SceneError> {
        let value = self.array_or(key, default)?;
        if value.iter().any(|&v| v <= 0.0) {
            return Err(self.error(key, format!("every element must be > 0, got {value:?}")));
        }
        Ok(value)
    }

    /// A colour: three components in [0, 1].
    pub fn color(&self, key: &str, default: [f64; 3]) -> Result<[f64; 3], SceneError> {
        let value = self.array_or(key, default)?;
        if value.iter().any(|&v| !(0.0..=1.0).contains(&v)) {
            return Err(self.error(
                key,
                format!("colour components must be in [0, 1], got {value:?}"),
            ));
        }
        Ok(value)
    }

    /// A resolution `[width, height]` in pixels.
    pub fn resolution(&self, key: &str, default: [u32; 2]) -> Result<[u32; 2], SceneError> {
        let Some(item) = self.item(key) else {
            return Ok(default);
        };
        let array = item.as_array().filter(|a| a.len() == 2);
        let values: Option<Vec<i64>> =
            array.map(|a| a.iter().filter_map(|v| v.as_integer()).collect());
        match values.as_deref() {
            Some(&[w, h])
                if (1..=MAX_RESOLUTION as i64).contains(&w)
                    && (1..=MAX_RESOLUTION as i64).contains(&h)
                    && w * h <= MAX_PIXELS as i64 =>
            {
                Ok([w as u32, h as u32])
            }
            _ => Err(self.error(
                key,
                format!("expected [width, height], integers in [1, {MAX_RESOLUTION}], at most {MAX_PIXELS} pixels"),
            )),
        }
    }
}
