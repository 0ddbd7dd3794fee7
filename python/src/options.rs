//! Keyword arguments: those of `seethru.run`, `capture` and `compare` read through the
//! library's option table (the command line's flags of the same names), and the others
//! (`sequence`, `ratio`, …) one by one with their ranges; unknown keywords are refused.

use clap::ValueEnum;
use pyo3::prelude::*;
use pyo3::types::{PyBool, PyDict};
use seethru::measure::option_table::{Command, Kind, OptionSpec, Value, option, options_of};
use seethru::measure::run_spec::{RunSpec, SpecError};
use seethru::system::options::MAX_HEAD_BIAS_CM;

use crate::errors::bad_value;

pub fn int_in(key: &str, v: i64, min: i64, max: i64) -> PyResult<i64> {
    match (min..=max).contains(&v) {
        true => Ok(v),
        false => Err(bad_value(format!(
            "{key}={v} is out of range: must be an integer in [{min}, {max}]"
        ))),
    }
}

pub fn real_in(key: &str, v: f64, min: f64, max: f64) -> PyResult<f64> {
    match v.is_finite() && (min..=max).contains(&v) {
        true => Ok(v),
        false => Err(bad_value(format!(
            "{key}={v} is out of range: must be a number in [{min}, {max}]"
        ))),
    }
}

fn choice<T: ValueEnum>(key: &str, value: &str) -> PyResult<T> {
    let names = || {
        T::value_variants()
            .iter()
            .filter_map(|v| v.to_possible_value())
            .map(|p| p.get_name().to_string())
            .collect::<Vec<_>>()
    };
    T::value_variants()
        .iter()
        .find(|v| v.to_possible_value().is_some_and(|p| p.get_name() == value))
        .cloned()
        .ok_or_else(|| {
            bad_value(format!(
                "{key}={value:?} is not one of {}",
                names().join(", ")
            ))
        })
}

/// The run specification of `command` from its keywords, read through the library's option
/// table (the same names, kinds, ranges and defaults as the command's flags) with `extra`
/// given besides (`capture`'s `depth`); a keyword None is absent, as a flag left off.
pub fn run_spec(
    kwargs: Option<&Bound<'_, PyDict>>,
    command: Command,
    extra: Vec<(&'static OptionSpec, Value)>,
) -> PyResult<RunSpec> {
    let mut given = extra;
    if let Some(kwargs) = kwargs {
        for (key, value) in kwargs.iter() {
            let key: String = key.extract()?;
            let Some(option) = option(&key).filter(|o| o.taken_by(command)) else {
                let names: Vec<&str> = options_of(command).map(|o| o.name).collect();
                return Err(bad_value(format!(
                    "unknown option {key:?}: the options are {}",
                    names.join(", ")
                )));
            };
            if value.is_none() {
                continue;
            }
            if let Some(value) = value_of(option, &value)? {
                given.push((option, value));
            }
        }
    }
    RunSpec::build(command, &given).map_err(spelled)
}

/// The run specification of `command` from named Python values (each read by its table
/// option's parser); a value None is not given.
pub fn spec_of(
    command: Command,
    values: &[(&'static str, Option<&Bound<'_, PyAny>>)],
) -> PyResult<RunSpec> {
    let mut given = Vec::new();
    for (name, value) in values {
        let spec = option(name).unwrap_or_else(|| panic!("{name} is not in the option table"));
        if let Some(value) = value.filter(|v| !v.is_none())
            && let Some(value) = value_of(spec, value)?
        {
            given.push((spec, value));
        }
    }
    RunSpec::build(command, &given).map_err(spelled)
}

/// A [`SpecError`] in Python's words: keyword names.
pub fn spelled(error: SpecError) -> PyErr {
    match error {
        SpecError::Value { option, value, why } => bad_value(format!("{option}={value}: {why}")),
        SpecError::Unknown { option, command } => bad_value(format!(
            "unknown option {option:?}: not one of seethru.{}'s",
            command.name()
        )),
        SpecError::Ignored(rule) => bad_value(rule.keyword_refusal()),
    }
}

/// The value of `option` given as the Python object `value`, of the option's type, read by the
/// option's own parser (so with the command line's ranges); `None` for a switch given False
/// (as a flag left off).
fn value_of(option: &'static OptionSpec, value: &Bound<'_, PyAny>) -> PyResult<Option<Value>> {
    let name = option.name;
    let shown = value
        .repr()
        .map_or_else(|_| "?".to_string(), |r| r.to_string());
    let wrong_type = || bad_value(format!("{name}={shown}: must be {}", option.kind.need()));
    let is_bool = value.is_instance_of::<PyBool>();
    let number = || -> PyResult<f64> {
        match is_bool {
            true => Err(wrong_type()),
            false => value.extract::<f64>().map_err(|_| wrong_type()),
        }
    };
    let text = match option.kind {
        Kind::Switch => {
            return match is_bool {
                true => Ok(value.extract::<bool>()?.then_some(Value::Switch(true))),
                false => Err(wrong_type()),
            };
        }
        Kind::Choice(_) => {
            let text: String = value.extract().map_err(|_| wrong_type())?;
            return option.parse(&text).map(Some).map_err(|_| {
                bad_value(format!(
                    "{name}={text:?} is not one of {}",
                    names_of(option)
                ))
            });
        }
        Kind::Integer { .. } => match is_bool {
            true => return Err(wrong_type()),
            false => value
                .extract::<i64>()
                .map_err(|_| wrong_type())?
                .to_string(),
        },
        Kind::Real { .. } => number()?.to_string(),
        Kind::Triple { .. } => {
            let xyz: [f64; 3] = value.extract().map_err(|_| wrong_type())?;
            xyz.map(|v| v.to_string()).join(",")
        }
        Kind::Distance { .. } => match value.extract::<String>() {
            Ok(text) => text,
            Err(_) => number()?.to_string(),
        },
    };
    option
        .parse(&text)
        .map(Some)
        .map_err(|why| bad_value(format!("{name}={shown} is out of range: {why}")))
}

/// The choices of a choice option, comma-separated.
fn names_of(option: &OptionSpec) -> String {
    match option.kind {
        Kind::Choice(_) => option.kind.choices().join(", "),
        _ => String::new(),
    }
}

/// Keyword arguments read one by one with their ranges; [`Keywords::finish`] refuses the rest.
pub struct Keywords<'py> {
    given: Vec<(String, Bound<'py, PyAny>)>,
    read: Vec<&'static str>,
}

impl<'py> Keywords<'py> {
    pub fn new(kwargs: Option<&Bound<'py, PyDict>>) -> PyResult<Self> {
        let mut given = Vec::new();
        if let Some(kwargs) = kwargs {
            for (k, v) in kwargs.iter() {
                given.push((k.extract::<String>()?, v));
            }
        }
        Ok(Keywords {
            given,
            read: Vec::new(),
        })
    }

    /// The value of `key` unless absent or None.
    fn value(&mut self, key: &'static str) -> Option<Bound<'py, PyAny>> {
        self.read.push(key);
        self.given
            .iter()
            .find(|(k, v)| k == key && !v.is_none())
            .map(|(_, v)| v.clone())
    }

    /// The run specification of `command` from the keywords of its table options (each read
    /// by the table's parser); the others are left for the caller to read.
    pub fn spec(&mut self, command: Command) -> PyResult<RunSpec> {
        let mut given = Vec::new();
        for option in options_of(command) {
            if let Some(value) = self.table(option.name)? {
                given.push((option, value));
            }
        }
        RunSpec::build(command, &given).map_err(spelled)
    }

    /// The value of the option table's `name`, if given: read by the table's parser, so with
    /// its range and `seethru.run`'s words when refused.
    pub fn table(&mut self, name: &'static str) -> PyResult<Option<Value>> {
        let spec = option(name).unwrap_or_else(|| panic!("{name} is not in the option table"));
        match self.value(name) {
            None => Ok(None),
            Some(v) => Ok(Some(value_of(spec, &v)?.unwrap_or(Value::Switch(false)))),
        }
    }

    pub fn real(&mut self, key: &'static str, default: f64, min: f64, max: f64) -> PyResult<f64> {
        match self.value(key) {
            None => Ok(default),
            Some(v) => {
                let v: f64 = v
                    .extract()
                    .map_err(|_| bad_value(format!("{key}: a number is needed")))?;
                real_in(key, v, min, max)
            }
        }
    }

    /// A number in [min, max] or infinity (a distance `inf`).
    pub fn real_or_inf(
        &mut self,
        key: &'static str,
        default: f64,
        min: f64,
        max: f64,
    ) -> PyResult<f64> {
        match self.value(key) {
            None => Ok(default),
            Some(v) => match v.extract::<f64>() {
                Ok(f) if f == f64::INFINITY => Ok(f),
                Ok(f) => real_in(key, f, min, max),
                Err(_) => match v.extract::<String>().as_deref() {
                    Ok("inf") => Ok(f64::INFINITY),
                    _ => Err(bad_value(format!(
                        "{key}: a number in [{min}, {max}] or inf is needed"
                    ))),
                },
            },
        }
    }

    pub fn required(&mut self, key: &'static str, min: f64, max: f64) -> PyResult<f64> {
        match self.value(key) {
            None => Err(bad_value(format!(
                "{key} is required: a number in [{min}, {max}]"
            ))),
            Some(_) => self.real(key, 0.0, min, max),
        }
    }

    pub fn int(&mut self, key: &'static str, default: i64, min: i64, max: i64) -> PyResult<i64> {
        match self.value(key) {
            None => Ok(default),
            Some(v) => {
                let v: i64 = v
                    .extract()
                    .map_err(|_| bad_value(format!("{key}: an integer is needed")))?;
                int_in(key, v, min, max)
            }
        }
    }

    /// Whether `key` was given (and not None).
    pub fn given(&self, key: &str) -> bool {
        self.given.iter().any(|(k, v)| k == key && !v.is_none())
    }

    /// The value of `key`, any type, unless absent or None.
    pub fn any(&mut self, key: &'static str) -> Option<Bound<'py, PyAny>> {
        self.value(key)
    }

    /// A choice among a clap value enum's names, `default` when absent.
    pub fn choice<T: ValueEnum>(&mut self, key: &'static str, default: T) -> PyResult<T> {
        match self.string(key)? {
            None => Ok(default),
            Some(v) => choice(key, &v),
        }
    }

    /// A switch (a command line flag without value): a bool, False when absent.
    pub fn flag(&mut self, key: &'static str) -> PyResult<bool> {
        match self.value(key) {
            None => Ok(false),
            Some(v) => v
                .extract::<bool>()
                .map_err(|_| bad_value(format!("{key}: True or False is needed"))),
        }
    }

    /// A string, or `None` when absent.
    pub fn string(&mut self, key: &'static str) -> PyResult<Option<String>> {
        self.value(key)
            .map(|v| {
                v.extract::<String>()
                    .map_err(|_| bad_value(format!("{key}: a string is needed")))
            })
            .transpose()
    }

    pub fn head_bias_cm(&mut self) -> PyResult<[f64; 3]> {
        match self.value("head_bias_cm") {
            None => Ok([0.0; 3]),
            Some(v) => {
                let v: [f64; 3] = v
                    .extract()
                    .map_err(|_| bad_value("head_bias_cm: three numbers (x, y, z) are needed"))?;
                for (axis, c) in ["x", "y", "z"].iter().zip(v) {
                    real_in(
                        &format!("head_bias_cm {axis}"),
                        c,
                        -MAX_HEAD_BIAS_CM,
                        MAX_HEAD_BIAS_CM,
                    )?;
                }
                Ok(v)
            }
        }
    }

    /// Refuses keywords that were not read.
    pub fn finish(self) -> PyResult<()> {
        match self
            .given
            .iter()
            .find(|(k, _)| !self.read.contains(&k.as_str()))
        {
            Some((k, _)) => Err(bad_value(format!(
                "unknown option {k:?}: the options are {}",
                self.read.join(", ")
            ))),
            None => Ok(()),
        }
    }
}

/// A choice among a clap value enum's names (as on the command line).
pub fn choice_of<T: ValueEnum>(key: &str, value: &str) -> PyResult<T> {
    choice(key, value)
}
