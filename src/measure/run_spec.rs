//! One validated run specification, built once from the option table's values
//! ([`crate::measure::option_table`]): the command line and the Python package hand over the
//! values the user gave, by option name, and get the run, or an error that names the option
//! for the front end to spell (`--eyes`, `eyes=`).

use crate::measure::measured_run::MeasureSettings;
use crate::measure::option_table::{Command, OptionSpec, Value, options_of};
use crate::system::depth_sensor::SensorKind;
use crate::system::display::{DisplayModel, Filter};
use crate::system::eyes::{Eye, Viewing};
use crate::system::options::{HeadSource, Method, Outside, RunOptions};
use crate::system::reads::{ReadWhen, capture_reads, first_ignored, run_reads};
use crate::system::scene_model_options::Fill;

/// A run as its command will make it, every option checked.
#[derive(Clone, Debug)]
pub struct RunSpec {
    pub command: Command,
    /// The system's options (`progress` off: the front end sets it).
    pub options: RunOptions,
    /// Each eye in turn (`eyes both`, `seethru run` only).
    pub both_eyes: bool,
    /// A capture writes the depth sensor's image.
    pub depth: bool,
    /// The measurement's settings (run and compare).
    pub measure: MeasureSettings,
    /// The memory the run may take, GiB.
    pub max_memory_gib: f64,
    /// Each option of the command with its value (`None`: derived, as the table says), in the
    /// table's order.
    pub values: Vec<(&'static OptionSpec, Option<Value>)>,
    /// The options the user gave (not defaulted), by name.
    pub given: Vec<&'static str>,
}

/// Why the options given make no run; the front end spells the option its own way.
#[derive(Clone, Debug, PartialEq)]
pub enum SpecError {
    /// `option`'s value `value` is refused: `why`.
    Value {
        option: &'static str,
        value: String,
        why: String,
    },
    /// The option is not one of the command's.
    Unknown { option: String, command: Command },
    /// An option the other settings make the command ignore.
    Ignored(ReadWhen),
}

impl RunSpec {
    /// The run of `command` with the values `given` (each option at most once, each of
    /// `command`'s), the rest at the table's defaults; refuses an option that the others
    /// make the command ignore (`system::reads`). `compare`'s rules depend on its methods
    /// and are its own to apply.
    pub fn build(
        command: Command,
        given: &[(&'static OptionSpec, Value)],
    ) -> Result<RunSpec, SpecError> {
        for (i, (option, value)) in given.iter().enumerate() {
            if !option.taken_by(command) {
                return Err(SpecError::Unknown {
                    option: option.name.to_string(),
                    command,
                });
            }
            if given[..i].iter().any(|(o, _)| o.name == option.name) {
                return Err(SpecError::Value {
                    option: option.name,
                    value: format!("{value:?}"),
                    why: "given twice".to_string(),
                });
            }
        }
        let values: Vec<(&'static OptionSpec, Option<Value>)> = options_of(command)
            .map(|option| {
                let value = given
                    .iter()
                    .find(|(o, _)| o.name == option.name)
                    .map(|(_, v)| v.clone())
                    .or_else(|| option.default_value_for(command));
                (option, value)
            })
            .collect();
        let mut spec = RunSpec {
            command,
            options: RunOptions {
                progress: false,
                ..RunOptions::default()
            },
            both_eyes: false,
            depth: false,
            measure: MeasureSettings::default(),
            max_memory_gib: 0.0,
            values: Vec::new(),
            given: given.iter().map(|(o, _)| o.name).collect(),
        };
        for (option, value) in &values {
            if let Some(value) = value {
                spec.set(option.name, value);
            }
        }
        spec.values = values;
        if command == Command::Compare {
            // A crop past the frontal view is shown black and counted, not an error: every
            // method gets its row.
            spec.options.outside = Outside::Black;
        }
        if command == Command::Sequence && spec.options.frontal_width.is_none() {
            // A sequence's frontal camera is as wide as its driver views unless given.
            spec.options.frontal_width = spec.options.width;
        }
        if command == Command::Capture && spec.both_eyes {
            return Err(SpecError::Value {
                option: "eyes",
                value: "both".into(),
                why: "a capture is for one eye (mono, left or right)".into(),
            });
        }
        let rules = match command {
            Command::Run => run_reads(&spec.options, spec.both_eyes),
            Command::Capture => capture_reads(&spec.options, spec.depth),
            // A sequence's rules need its own options too (the head's motion, the maps): its
            // front ends apply `sequence_reads` to the run this builds.
            Command::Compare | Command::Sequence | Command::Render => Vec::new(),
        };
        spec.refuse_ignored(&rules)?;
        Ok(spec)
    }

    /// Refuses the first option of `rules` given but not read.
    pub fn refuse_ignored(&self, rules: &[ReadWhen]) -> Result<(), SpecError> {
        match first_ignored(rules, |option| self.given.contains(&option)) {
            Some(rule) => Err(SpecError::Ignored(rule.clone())),
            None => Ok(()),
        }
    }

    /// Stores `value` of the option `name` (of the table, whose kind it has).
    fn set(&mut self, name: &str, value: &Value) {
        let o = &mut self.options;
        let sensor = &mut o.scene_model.sensor;
        match name {
            "method" => o.method = value.choice::<Method>(),
            "d2" => o.d2 = value.working_distance(),
            "head" => o.head = value.choice::<HeadSource>(),
            "head_bias_cm" => o.head_bias_cm = value.triple(),
            "head_jitter_cm" => o.head_jitter_cm = value.real(),
            "speed" => o.speed_kmh = value.real(),
            "yaw_rate" => o.yaw_rate_deg_s = value.real(),
            "latency_camera" => o.latency_camera_ms = value.real(),
            "seed" => o.seed = value.integer() as u32,
            "feature_width" => o.feature_width = value.real(),
            "require_confident_head" => o.require_confident_head = value.switch(),
            "min_head_confidence" => o.min_head_confidence = value.real(),
            "outside" => o.outside = value.choice::<Outside>(),
            "filter" => o.filter = value.choice::<Filter>(),
            "display" => o.display = value.choice::<DisplayModel>(),
            "frontal_width" => o.frontal_width = Some(value.integer() as u32),
            "back_width" => o.back_width = Some(value.integer() as u32),
            "eyes" => {
                let viewing = value.choice::<Viewing>();
                self.both_eyes = viewing == Viewing::Both;
                o.eyes.view = viewing.view();
            }
            "ipd" => o.eyes.ipd = value.real(),
            "target_eye" => o.eyes.target = value.choice::<Eye>(),
            "depth" => self.depth = value.switch(),
            "band" => self.measure.band = value.integer() as u32,
            "hazard_bound_arcmin" => self.measure.hazard_bound_arcmin = value.real(),
            "depth_sensor" => sensor.kind = value.choice::<SensorKind>(),
            "depth_resolution" => sensor.width = Some(value.integer() as u32),
            "depth_range" => sensor.range_m = Some(value.real()),
            "depth_noise" => sensor.noise_1m = Some(value.real()),
            "depth_quantum" => sensor.quantum_1m = Some(value.real()),
            "fill" => o.scene_model.fill = value.choice::<Fill>(),
            "width" => o.width = Some(value.integer() as u32),
            "height" => o.height = Some(value.integer() as u32),
            "spp" => o.spp = value.integer() as u32,
            "max_memory" => self.max_memory_gib = value.real(),
            _ => unreachable!("the table's option {name} has no place in a run"),
        }
    }

    /// The specification as `seethru spec` prints it and `seethru.spec` returns it: the
    /// command and each of its options' values (null where derived).
    pub fn to_json(&self) -> serde_json::Value {
        let options: serde_json::Map<String, serde_json::Value> = self
            .values
            .iter()
            .map(|(o, v)| {
                let json = v.as_ref().map_or(serde_json::Value::Null, Value::to_json);
                (o.name.to_string(), json)
            })
            .collect();
        serde_json::json!({"command": self.command.name(), "options": options})
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::measure::option_table::{Kind, OPTIONS, option};

    /// The option's value at the low or high end of its range (or its last choice).
    fn end(option: &OptionSpec, high: bool) -> Value {
        let text = match option.kind {
            Kind::Integer { min, max } => (if high { max } else { min }).to_string(),
            Kind::Real { min, max } | Kind::Distance { min, max } => {
                (if high { max } else { min }).to_string()
            }
            Kind::Triple { max } => format!("{0},{0},{0}", if high { max } else { -max }),
            Kind::Choice(_) => {
                let names = option.kind.choices();
                if high {
                    names[names.len() - 1].clone()
                } else {
                    names[0].clone()
                }
            }
            Kind::Switch => high.to_string(),
        };
        option.parse(&text).unwrap()
    }

    #[test]
    fn every_option_reaches_the_run() {
        // Each option moved alone from its default to either end, under the settings that
        // make it read, changes the run: an option the table declares but `set` drops would
        // not.
        for command in Command::ALL {
            for option in options_of(command) {
                let context = context_of(command, option);
                let base = RunSpec::build(command, &context).unwrap();
                for high in [false, true] {
                    let value = end(option, high);
                    if Some(&value) == option.default_value_for(command).as_ref() {
                        continue;
                    }
                    let mut given = context.clone();
                    given.push((option, value.clone()));
                    let spec = match RunSpec::build(command, &given) {
                        Ok(spec) => spec,
                        // A capture of both eyes: a rule, tested apart.
                        Err(SpecError::Value { option: "eyes", .. }) => continue,
                        Err(e) => panic!("{} {}: {e:?}", command.name(), option.name),
                    };
                    let changed = format!("{:?}", spec.options) != format!("{:?}", base.options)
                        || spec.both_eyes != base.both_eyes
                        || spec.depth != base.depth
                        || spec.measure != base.measure
                        || spec.max_memory_gib != base.max_memory_gib;
                    assert!(changed, "{} {} = {value:?}", command.name(), option.name);
                }
            }
        }
    }

    /// The settings under which `command` reads `option`, as the table names them.
    fn context_of(command: Command, option: &OptionSpec) -> Vec<(&'static OptionSpec, Value)> {
        option
            .read_with
            .iter()
            .filter_map(|(name, text)| option_of(command, name, text))
            .collect()
    }

    #[test]
    fn the_defaults_are_the_libraries_own() {
        let run = RunSpec::build(Command::Run, &[]).unwrap();
        let defaults = RunOptions {
            progress: false,
            ..RunOptions::default()
        };
        assert_eq!(format!("{:?}", run.options), format!("{defaults:?}"));
        assert_eq!(run.measure, MeasureSettings::default());
    }

    #[test]
    fn each_option_is_read_under_the_settings_the_table_names() {
        for command in [Command::Run, Command::Capture] {
            for option in options_of(command) {
                let mut given = context_of(command, option);
                given.push((option, end(option, true)));
                let built = RunSpec::build(command, &given);
                assert!(
                    !matches!(built, Err(SpecError::Ignored(_))),
                    "{} {}: {built:?}",
                    command.name(),
                    option.name
                );
            }
        }
        // And the settings are needed: without them a rule refuses these.
        for name in ["fill", "depth_noise", "feature_width", "ipd"] {
            let option = option(name).unwrap();
            let built = RunSpec::build(Command::Run, &[(option, end(option, true))]);
            assert!(matches!(built, Err(SpecError::Ignored(_))), "{name}");
        }
    }

    fn option_of(command: Command, name: &str, text: &str) -> Option<(&'static OptionSpec, Value)> {
        let o = OPTIONS.iter().find(|o| o.name == name)?;
        o.taken_by(command).then(|| (o, o.parse(text).unwrap()))
    }

    #[test]
    fn a_capture_is_for_one_eye_and_an_option_of_another_command_is_refused() {
        let eyes = option("eyes").unwrap();
        let both = eyes.parse("both").unwrap();
        assert!(RunSpec::build(Command::Run, &[(eyes, both.clone())]).is_ok());
        assert!(matches!(
            RunSpec::build(Command::Capture, &[(eyes, both)]),
            Err(SpecError::Value { option: "eyes", .. })
        ));
        let fill = option("fill").unwrap();
        assert!(matches!(
            RunSpec::build(Command::Capture, &[(fill, fill.parse("inpaint").unwrap())]),
            Err(SpecError::Unknown { .. })
        ));
        let compare = RunSpec::build(Command::Compare, &[]).unwrap();
        assert_eq!(compare.options.outside, Outside::Black);
    }
}
