//! Typed, span-aware reading of one TOML table.
//!
//! Scene files are data: every object kind reads its keys through a [`TableReader`], which
//! checks types and ranges, supplies documented defaults and rejects unknown keys. Every error
//! names the file, the line and the key, so that a user can fix the file without guessing.

use std::cell::RefCell;
use std::collections::HashSet;

use glam::DVec3;
use toml_edit::{ImDocument, Item, TableLike};

use crate::scene::limits::{MAX_COORDINATE, MAX_PIXELS, MAX_RESOLUTION};
use crate::scene::source::{SceneError, SourceFile};
use crate::util::message::controls_escaped;
use crate::util::number::{short, short_list};

/// A string of a TOML array and its byte span in the file.
pub type SpannedStr<'a> = (&'a str, Option<std::ops::Range<usize>>);

/// Reads the keys of one TOML table, remembering which were read so that
/// [`TableReader::finish`] can reject the rest as unknown.
pub struct TableReader<'a> {
    file: &'a SourceFile,
    table: &'a dyn TableLike,
    /// Key path of this table, e.g. `object[2]`; empty for the root.
    prefix: String,
    /// Line and column of the table header, for errors about missing keys.
    at: Option<(usize, usize)>,
    read: RefCell<HashSet<String>>,
}

impl<'a> TableReader<'a> {
    pub fn root(file: &'a SourceFile, doc: &'a ImDocument<&'a str>) -> Self {
        Self {
            file,
            table: doc.as_table(),
            prefix: String::new(),
            at: None,
            read: RefCell::new(HashSet::new()),
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
        let at = self
            .table
            .get_key_value(key)
            .and_then(|(k, item)| item.span().or_else(|| k.span()))
            .map(|s| self.file.position_of(s.start))
            .or(self.at);
        self.error_at(at, self.full_key(key), message)
    }

    /// An error about this table as a whole (e.g. an object placed outside the world).
    pub fn table_error(&self, message: impl Into<String>) -> SceneError {
        self.error_at(self.at, self.prefix.clone(), message)
    }

    fn error_at(
        &self,
        at: Option<(usize, usize)>,
        key: String,
        message: impl Into<String>,
    ) -> SceneError {
        // Keys and messages echo the file's text (a choice, a key name), which may hold a
        // TOML `\n` or an escape: shown, not obeyed, so that the error stays one line.
        SceneError {
            path: self.file.path.clone(),
            line: at.map(|a| a.0),
            column: at.map(|a| a.1),
            key: controls_escaped(&key),
            message: controls_escaped(&message.into()),
        }
    }

    fn item(&self, key: &str) -> Option<&'a Item> {
        self.read.borrow_mut().insert(key.to_string());
        self.table.get(key)
    }

    fn position(&self, span: Option<std::ops::Range<usize>>) -> Option<(usize, usize)> {
        span.map(|s| self.file.position_of(s.start)).or(self.at)
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
            at: self.position(item.span()),
            read: RefCell::new(HashSet::new()),
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
                at: self.position(span),
                read: RefCell::new(HashSet::new()),
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

    /// The keys of this table in the file's order (none is marked read: each is read by name
    /// afterwards, as the keys of a table keyed by names of their own, such as options).
    pub fn keys(&self) -> Vec<&'a str> {
        self.table.iter().map(|(k, _)| k).collect()
    }

    /// A string, number or boolean as text (numbers as TOML wrote them): for values that a
    /// typed parser of their own reads, such as the option table's.
    pub fn scalar_text(&self, key: &str) -> Result<String, SceneError> {
        let item = self.item(key).ok_or_else(|| self.missing(key))?;
        let value = item.as_value().ok_or_else(|| {
            self.error(key, format!("expected a value, found {}", item.type_name()))
        })?;
        scalar_text(value).ok_or_else(|| {
            self.error(
                key,
                format!(
                    "expected a string, number or boolean, found {}",
                    value.type_name()
                ),
            )
        })
    }

    /// A non-empty array of strings, numbers or booleans, each as text.
    pub fn scalar_texts(&self, key: &str) -> Result<Vec<String>, SceneError> {
        let texts: Option<Vec<String>> = self.values(key)?.iter().map(scalar_text).collect();
        texts.ok_or_else(|| {
            self.error(
                key,
                "expected strings, numbers or booleans, found an array or table inside",
            )
        })
    }

    /// Rejects every key that was not read: scene files have no ignored keys.
    pub fn finish(self) -> Result<(), SceneError> {
        let read = self.read.borrow();
        for (key, _) in self.table.iter() {
            if !read.contains(key) {
                let mut known: Vec<&str> = read.iter().map(String::as_str).collect();
                known.sort_unstable();
                return Err(self.error(
                    key,
                    format!("unknown key (known keys here: {})", known.join(", ")),
                ));
            }
        }
        Ok(())
    }

    /// A number as written, NaN and infinities included (`nan`, `inf` are TOML floats).
    fn raw_f64(&self, key: &str) -> Result<Option<f64>, SceneError> {
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
        Ok(Some(value))
    }

    /// A finite number, if given.
    pub fn opt_f64(&self, key: &str) -> Result<Option<f64>, SceneError> {
        let value = self.raw_f64(key)?;
        if let Some(v) = value.filter(|v| !v.is_finite()) {
            return Err(self.error(key, format!("must be a finite number, got {}", short(v))));
        }
        Ok(value)
    }

    /// Whether the key holds a single number (NaN and infinities included).
    pub fn is_number(&self, key: &str) -> bool {
        self.item(key)
            .is_some_and(|i| i.as_float().is_some() || i.as_integer().is_some())
    }

    /// A number with a default, checked against an inclusive range (NaN and infinities are
    /// outside every range, and the message gives it).
    pub fn f64_in(&self, key: &str, default: f64, min: f64, max: f64) -> Result<f64, SceneError> {
        let value = self.raw_f64(key)?.unwrap_or(default);
        if !(min..=max).contains(&value) {
            return Err(self.error(key, range_message(value, min, max)));
        }
        Ok(value)
    }

    fn missing(&self, key: &str) -> SceneError {
        self.error_at(self.at, self.full_key(key), "required key is missing")
    }

    pub fn opt_usize(
        &self,
        key: &str,
        min: usize,
        max: usize,
    ) -> Result<Option<usize>, SceneError> {
        Ok(self
            .opt_i64(key, min as i64, max as i64)?
            .map(|v| v as usize))
    }

    /// An integer in [`min`, `max`], if given.
    pub fn opt_i64(&self, key: &str, min: i64, max: i64) -> Result<Option<i64>, SceneError> {
        let Some(item) = self.item(key) else {
            return Ok(None);
        };
        let value = item.as_integer().ok_or_else(|| {
            self.error(
                key,
                format!("expected an integer, found {}", item.type_name()),
            )
        })?;
        if value < min || value > max {
            return Err(self.error(
                key,
                format!("must be an integer in [{min}, {max}], got {value}"),
            ));
        }
        Ok(Some(value))
    }

    /// The file a path key names, resolved against the scene's folder; an error if it is not
    /// a readable file.
    pub fn existing_asset(&self, key: &str, rel: &str) -> Result<std::path::PathBuf, SceneError> {
        let path = self.file.dir().join(rel);
        if let Some(why) = crate::util::input_file::not_a_file(&path) {
            return Err(self.error(
                key,
                format!(
                    "cannot read `{rel}` (resolved against the scene's folder: {}): {why}",
                    path.display()
                ),
            ));
        }
        Ok(path)
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

    /// An array of free strings with the byte span of each in the file (for errors at the
    /// element's own line, and for rewriting one element in place); empty if absent.
    pub fn strings_with_spans(&self, key: &str) -> Result<Vec<SpannedStr<'a>>, SceneError> {
        let Some(item) = self.item(key) else {
            return Ok(Vec::new());
        };
        let array = item.as_array().ok_or_else(|| {
            self.error(
                key,
                format!("expected an array of strings, found {}", item.type_name()),
            )
        })?;
        array
            .iter()
            .map(|value| {
                let s = value.as_str().ok_or_else(|| {
                    self.error(
                        key,
                        format!("expected strings, found {}", value.type_name()),
                    )
                })?;
                Ok((s, value.span()))
            })
            .collect()
    }

    /// An error about `key` located at byte `offset` of the file (an element of its array).
    pub fn error_at_offset(
        &self,
        key: &str,
        offset: Option<usize>,
        message: impl Into<String>,
    ) -> SceneError {
        match offset {
            Some(o) => self.error_at(Some(self.file.position_of(o)), self.full_key(key), message),
            None => self.error(key, message),
        }
    }

    /// A fixed-length array of numbers as written, NaN and infinities included.
    fn raw_array<const N: usize>(&self, key: &str) -> Result<Option<[f64; N]>, SceneError> {
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
        }
        Ok(Some(out))
    }

    /// A fixed-length array of finite numbers.
    pub fn opt_array<const N: usize>(&self, key: &str) -> Result<Option<[f64; N]>, SceneError> {
        let value = self.raw_array::<N>(key)?;
        if let Some(values) = value.filter(|v| v.iter().any(|x| !x.is_finite())) {
            return Err(self.error(
                key,
                format!("must be finite numbers, got {}", short_list(&values)),
            ));
        }
        Ok(value)
    }

    /// An array whose every element is in [min, max].
    pub fn array_in<const N: usize>(
        &self,
        key: &str,
        default: [f64; N],
        min: f64,
        max: f64,
    ) -> Result<[f64; N], SceneError> {
        let value = self.raw_array(key)?.unwrap_or(default);
        if let Some(&bad) = value.iter().find(|v| !(min..=max).contains(*v)) {
            return Err(self.error(
                key,
                format!("every element {}", range_message(bad, min, max)),
            ));
        }
        Ok(value)
    }

    /// A point in the world: three coordinates within ±[`MAX_COORDINATE`] metres.
    pub fn point(&self, key: &str, default: Option<[f64; 3]>) -> Result<DVec3, SceneError> {
        let Some(default) = default.or(self.opt_array(key)?) else {
            return Err(self.missing(key));
        };
        let value = self.array_in(key, default, -MAX_COORDINATE, MAX_COORDINATE)?;
        Ok(DVec3::from_array(value))
    }

    /// A direction: three finite numbers, not all zero; returned normalised.
    pub fn direction(&self, key: &str, default: [f64; 3]) -> Result<DVec3, SceneError> {
        let value = DVec3::from_array(self.array_or(key, default)?);
        // Scaled first, so that huge components do not overflow the length.
        let largest = value.abs().max_element();
        if largest == 0.0 {
            return Err(self.error(key, "must not be the zero vector"));
        }
        Ok((value / largest).normalize())
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

    /// A law's two parameters: two finite numbers, or two arrays of finite numbers of one
    /// length (component by component); `None` for numbers, the arrays' length for arrays.
    pub fn number_pair_or_vectors(
        &self,
        key: &str,
    ) -> Result<([Vec<f64>; 2], Option<usize>), SceneError> {
        let item = self.item(key).ok_or_else(|| self.missing(key))?;
        let wrong = || {
            self.error(
                key,
                "expected two finite numbers, or two arrays of finite numbers of one length",
            )
        };
        let pair = item.as_array().filter(|a| a.len() == 2).ok_or_else(wrong)?;
        let finite = |v: &toml_edit::Value| {
            v.as_float()
                .or_else(|| v.as_integer().map(|i| i as f64))
                .filter(|x| x.is_finite())
        };
        let mut out = [Vec::new(), Vec::new()];
        let mut length = None;
        for (slot, value) in out.iter_mut().zip(pair.iter()) {
            match value.as_array() {
                Some(inner) => {
                    *slot = inner
                        .iter()
                        .map(finite)
                        .collect::<Option<_>>()
                        .ok_or_else(wrong)?;
                    length = Some(inner.len());
                }
                None => *slot = vec![finite(value).ok_or_else(wrong)?],
            }
        }
        let [a, b] = &out;
        let scalars = pair.iter().all(|v| v.as_array().is_none());
        let vectors = pair.iter().all(|v| v.as_array().is_some()) && a.len() == b.len();
        match (scalars, vectors && !a.is_empty()) {
            (true, _) => Ok((out, None)),
            (false, true) => Ok((out, length)),
            _ => Err(wrong()),
        }
    }

    /// A non-empty array of TOML values as written (strings, numbers, booleans, arrays): what
    /// a scene key drawn with `one_of` may be set to.
    pub fn values(&self, key: &str) -> Result<Vec<toml_edit::Value>, SceneError> {
        let item = self.item(key).ok_or_else(|| self.missing(key))?;
        let array = item.as_array().ok_or_else(|| {
            self.error(
                key,
                format!("expected an array, found {}", item.type_name()),
            )
        })?;
        if array.is_empty() {
            return Err(self.error(key, "expected at least one value, found none"));
        }
        Ok(array.iter().cloned().collect())
    }

    /// A colour: three components in [0, 1].
    pub fn color(&self, key: &str, default: [f64; 3]) -> Result<[f64; 3], SceneError> {
        let value = self.raw_array(key)?.unwrap_or(default);
        if value.iter().any(|&v| !(0.0..=1.0).contains(&v)) {
            return Err(self.error(
                key,
                format!(
                    "colour components must be in [0, 1], got {}",
                    short_list(&value)
                ),
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
            array.and_then(|a| a.iter().map(|v| v.as_integer()).collect());
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
                format!(
                    "expected [width, height], integers in [1, {MAX_RESOLUTION}], at most {MAX_RESOLUTION}×{} pixels in all",
                    MAX_PIXELS / MAX_RESOLUTION as u64
                ),
            )),
        }
    }
}

/// `must be in [min, max], got value`, with short numbers.
pub fn range_message(value: f64, min: f64, max: f64) -> String {
    format!(
        "must be in [{}, {}], got {}",
        short(min),
        short(max),
        short(value)
    )
}

/// A TOML string, integer, float or boolean as text (a float as Rust writes the f64).
fn scalar_text(value: &toml_edit::Value) -> Option<String> {
    match value {
        toml_edit::Value::String(s) => Some(s.value().clone()),
        toml_edit::Value::Integer(i) => Some(i.value().to_string()),
        toml_edit::Value::Float(f) => Some(f.value().to_string()),
        toml_edit::Value::Boolean(b) => Some(b.value().to_string()),
        _ => None,
    }
}
