//! The values of the option table (`measure/option_table.rs`): each option's kind with its
//! range or choices, a value read and checked, and a default; with the typed reads of a value
//! whose kind the table fixes.

use crate::system::options::WorkingDistance;
use crate::util::number::short;

/// The type of an option's value, with its range or choices.
#[derive(Clone, Copy, Debug)]
pub enum Kind {
    /// An integer in `[min, max]`.
    Integer { min: u64, max: u64 },
    /// A finite number in `[min, max]`.
    Real { min: f64, max: f64 },
    /// Three numbers x, y, z, each in `[-max, max]`.
    Triple { max: f64 },
    /// `inf`, `auto` or metres in `[min, max]`: a working distance.
    Distance { min: f64, max: f64 },
    /// One of a fixed list of names, each with its help (a `clap::ValueEnum`'s variants).
    Choice(fn() -> Vec<clap::builder::PossibleValue>),
    /// On or off: a flag without a value on the command line, a bool in Python.
    Switch,
}

/// A value enum's variants as typed (`plane-fit`), with their doc comments as help.
pub fn choice_values<T: clap::ValueEnum>() -> Vec<clap::builder::PossibleValue> {
    T::value_variants()
        .iter()
        .filter_map(|v| v.to_possible_value())
        .collect()
}

/// The variant of `T` named `name` (one of [`choice_names`]).
pub fn choice_of<T: clap::ValueEnum + Clone>(name: &str) -> Option<T> {
    T::value_variants()
        .iter()
        .find(|v| v.to_possible_value().is_some_and(|p| p.get_name() == name))
        .cloned()
}

/// An option's value, read and checked.
#[derive(Clone, Debug, PartialEq)]
pub enum Value {
    Integer(u64),
    Real(f64),
    Triple([f64; 3]),
    /// `inf` is `f64::INFINITY`; `auto` is `None`.
    Distance(Option<f64>),
    Choice(String),
    Switch(bool),
}

impl Value {
    /// The value in JSON, as `seethru spec` prints it and `seethru.spec` returns it.
    pub fn to_json(&self) -> serde_json::Value {
        use serde_json::json;
        match self {
            Value::Integer(v) => json!(v),
            Value::Real(v) => json!(v),
            Value::Triple(v) => json!(v),
            Value::Distance(None) => json!("auto"),
            Value::Distance(Some(v)) if v.is_infinite() => json!("inf"),
            Value::Distance(Some(v)) => json!(v),
            Value::Choice(v) => json!(v),
            Value::Switch(v) => json!(v),
        }
    }
}

/// What an option is when not given.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Default {
    /// This value, written as on the command line.
    Value(&'static str),
    /// No value: the run takes it from elsewhere, as the text says (`the scene's`).
    Derived(&'static str),
}

impl Kind {
    /// The names of a choice (`plane-fit`), none for another kind.
    pub fn choices(&self) -> Vec<String> {
        match self {
            Kind::Choice(values) => values().iter().map(|p| p.get_name().to_string()).collect(),
            _ => Vec::new(),
        }
    }

    /// What a value must be, for errors and help: `an integer in [1, 16384]`.
    pub fn need(&self) -> String {
        match self {
            Kind::Integer { min, max } => format!("an integer in [{min}, {max}]"),
            Kind::Real { min, max } => format!("a number in [{}, {}]", short(*min), short(*max)),
            Kind::Triple { max } => {
                format!("x,y,z: three numbers in [{}, {}]", short(-max), short(*max))
            }
            Kind::Distance { min, max } => format!(
                "inf, auto or a distance in metres in [{}, {}]",
                short(*min),
                short(*max)
            ),
            Kind::Choice(_) => format!("one of {}", self.choices().join(", ")),
            Kind::Switch => "true or false".to_string(),
        }
    }

    /// Reads a value written as on the command line (spaces around it ignored), `None` when
    /// it is not one of this kind.
    pub fn parse(&self, text: &str) -> Option<Value> {
        let t = text.trim();
        match *self {
            Kind::Integer { min, max } => t
                .parse::<u64>()
                .ok()
                .filter(|v| (min..=max).contains(v))
                .map(Value::Integer),
            Kind::Real { min, max } => real_in(t, min, max).map(Value::Real),
            Kind::Triple { max } => {
                let parts: Vec<Option<f64>> = t.split(',').map(|p| real_in(p, -max, max)).collect();
                match parts.as_slice() {
                    [Some(x), Some(y), Some(z)] => Some(Value::Triple([*x, *y, *z])),
                    _ => None,
                }
            }
            Kind::Distance { min, max } => match t {
                "inf" | "infinity" => Some(Value::Distance(Some(f64::INFINITY))),
                "auto" => Some(Value::Distance(None)),
                _ => real_in(t, min, max).map(|v| Value::Distance(Some(v))),
            },
            Kind::Choice(_) => self
                .choices()
                .into_iter()
                .find(|n| n == t)
                .map(Value::Choice),
            Kind::Switch => match t {
                "true" => Some(Value::Switch(true)),
                "false" => Some(Value::Switch(false)),
                _ => None,
            },
        }
    }
}

/// A finite number in `[min, max]` read from `text` (spaces around it ignored).
fn real_in(text: &str, min: f64, max: f64) -> Option<f64> {
    text.trim()
        .parse::<f64>()
        .ok()
        .filter(|v| v.is_finite() && (min..=max).contains(v))
}

/// The typed reads of a value whose kind the table fixes (a mismatch is a bug of the table,
/// which `every_option_reaches_the_run` walks).
impl Value {
    pub fn integer(&self) -> u64 {
        match self {
            Value::Integer(v) => *v,
            other => unreachable!("an integer option holds {other:?}"),
        }
    }

    /// A working distance: `auto`, `inf` or metres.
    pub fn working_distance(&self) -> WorkingDistance {
        match self {
            Value::Distance(None) => WorkingDistance::Auto,
            Value::Distance(Some(v)) if v.is_infinite() => WorkingDistance::Infinity,
            _ => WorkingDistance::Metres(self.real()),
        }
    }

    pub fn real(&self) -> f64 {
        match self {
            Value::Real(v) | Value::Distance(Some(v)) => *v,
            other => unreachable!("a number option holds {other:?}"),
        }
    }

    pub fn triple(&self) -> [f64; 3] {
        match self {
            Value::Triple(v) => *v,
            other => unreachable!("a triple option holds {other:?}"),
        }
    }

    pub fn switch(&self) -> bool {
        match self {
            Value::Switch(v) => *v,
            other => unreachable!("a switch holds {other:?}"),
        }
    }

    pub fn choice<T: clap::ValueEnum + Clone>(&self) -> T {
        match self {
            Value::Choice(name) => choice_of(name).expect("a choice of the option's list"),
            other => unreachable!("a choice option holds {other:?}"),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use serde_json::json;

    #[test]
    fn a_distance_is_written_as_given() {
        assert_eq!(Value::Distance(Some(6.0)).to_json(), json!(6.0));
        assert_eq!(Value::Distance(Some(f64::INFINITY)).to_json(), json!("inf"));
        assert_eq!(Value::Distance(None).to_json(), json!("auto"));
        assert_eq!(
            Value::Distance(Some(6.0)).working_distance(),
            WorkingDistance::Metres(6.0)
        );
        assert_eq!(
            Value::Distance(Some(f64::INFINITY)).working_distance(),
            WorkingDistance::Infinity
        );
        assert_eq!(
            Value::Distance(None).working_distance(),
            WorkingDistance::Auto
        );
    }
}
