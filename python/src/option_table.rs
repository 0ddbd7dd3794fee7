//! `seethru.options()` and `seethru.spec()`: the library's option table, and the run
//! specification a call would make of its keywords (`seethru spec` on the command line).

use pyo3::prelude::*;
use pyo3::types::PyDict;
use seethru::measure::option_table::{Command, Default, Kind, OPTIONS};

use crate::errors::bad_value;
use crate::options::run_spec;
use crate::run::json_to_py;

fn command_named(name: &str) -> PyResult<Command> {
    Command::ALL
        .into_iter()
        .find(|c| c.name() == name)
        .ok_or_else(|| {
            bad_value(format!(
                "command={name:?} is not one of run, capture, compare, sequence, render"
            ))
        })
}

/// Every option of `seethru.run`, `capture` and `compare`, and those `sequence` shares with
/// them (the flags of the commands of the same names): a list of dicts with name, flag, kind,
/// min, max, choices, unit, default (and command_defaults where a command's differs), help,
/// read_with and commands, in the table's order.
#[pyfunction]
pub fn options(py: Python<'_>) -> PyResult<Py<PyAny>> {
    let rows: Vec<serde_json::Value> = OPTIONS
        .iter()
        .map(|o| {
            let (kind, min, max, choices) = match o.kind {
                Kind::Integer { min, max } => ("integer", Some(min as f64), Some(max as f64), None),
                Kind::Real { min, max } => ("number", Some(min), Some(max), None),
                Kind::Triple { max } => ("triple", Some(-max), Some(max), None),
                Kind::Distance { min, max } => ("distance", Some(min), Some(max), None),
                Kind::Choice(_) => ("choice", None, None, Some(o.kind.choices())),
                Kind::Switch => ("switch", None, None, None),
            };
            let default = match o.default {
                Default::Value(_) => o.default_value().map_or(serde_json::Value::Null, |v| v.to_json()),
                Default::Derived(_) => serde_json::Value::Null,
            };
            let derived = match o.default {
                Default::Derived(what) => Some(what),
                Default::Value(_) => None,
            };
            // A command's own default where it differs (a sequence's `spp` 1).
            let own_defaults: serde_json::Map<String, serde_json::Value> = Command::ALL
                .into_iter()
                .filter(|&c| o.taken_by(c) && o.default_for(c) != o.default)
                .map(|c| {
                    let value = o
                        .default_value_for(c)
                        .map_or(serde_json::Value::Null, |v| v.to_json());
                    (c.name().to_string(), value)
                })
                .collect();
            serde_json::json!({
                "name": o.name,
                "command_defaults": own_defaults,
                "flag": o.flag(),
                "kind": kind,
                "min": min,
                "max": max,
                "choices": choices,
                "unit": o.unit,
                "default": default,
                "default_derived": derived,
                "help": o.help,
                "read_with": o.read_with.iter().map(|(k, v)| (k.to_string(), serde_json::Value::from(*v))).collect::<serde_json::Map<_, _>>(),
                "commands": o.commands.iter().map(|c| c.name()).collect::<Vec<_>>(),
            })
        })
        .collect();
    json_to_py(py, &serde_json::Value::Array(rows))
}

/// The run specification `command` ("run", "capture" or "compare") would make of `options`,
/// every option checked and nothing rendered: {"command", "options": {name: value}}, the
/// same as `seethru spec COMMAND` prints.
#[pyfunction]
#[pyo3(signature = (command, **options))]
pub fn spec(
    py: Python<'_>,
    command: &str,
    options: Option<&Bound<'_, PyDict>>,
) -> PyResult<Py<PyAny>> {
    let command = command_named(command)?;
    let spec = run_spec(options, command, Vec::new())?;
    json_to_py(py, &spec.to_json())
}
