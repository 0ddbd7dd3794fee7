//! A command's flags made from the option table (`seethru::measure::option_table`): each
//! option becomes `--name-with-dashes` with the table's help, default, value name and parser,
//! so that the command line cannot drift from the Python keywords or the docs. A command
//! flattens `OptionArgs<Run>` (or `Capture`, `Compare`) and asks it for its [`RunSpec`].

use std::marker::PhantomData;

use anyhow::{Result, anyhow};
use clap::builder::{PossibleValue, PossibleValuesParser, TypedValueParser};
use clap::parser::ValueSource;
use clap::{Arg, ArgAction, ArgMatches};
use seethru::measure::option_table::{Command, Default, Kind, OptionSpec, Value, options_of};
use seethru::measure::run_spec::{RunSpec, SpecError};
use seethru::system::reads::flag_of;

/// A command whose options the table declares.
pub trait TableCommand {
    const COMMAND: Command;
}

/// `seethru run`'s options.
pub struct Run;
/// `seethru capture`'s options.
pub struct Capture;
/// `seethru compare`'s options.
pub struct Compare;
/// The options `seethru sequence` shares with a run.
pub struct Sequence;
/// `seethru render`'s size, samples and memory bound.
pub struct Render;

impl TableCommand for Run {
    const COMMAND: Command = Command::Run;
}
impl TableCommand for Capture {
    const COMMAND: Command = Command::Capture;
}
impl TableCommand for Compare {
    const COMMAND: Command = Command::Compare;
}
impl TableCommand for Sequence {
    const COMMAND: Command = Command::Sequence;
}
impl TableCommand for Render {
    const COMMAND: Command = Command::Render;
}

/// The table's options of command `C` given on the command line.
pub struct OptionArgs<C> {
    /// Each option typed, with its value, in the table's order.
    pub given: Vec<(&'static OptionSpec, Value)>,
    command: PhantomData<C>,
}

impl<C: TableCommand> OptionArgs<C> {
    /// The run these flags make, every option checked; errors name the flags.
    pub fn spec(&self) -> Result<RunSpec> {
        RunSpec::build(C::COMMAND, &self.given).map_err(spelled)
    }
}

/// A [`SpecError`] in the command line's words.
pub fn spelled(error: SpecError) -> anyhow::Error {
    match error {
        SpecError::Value { option, value, why } => anyhow!("{} {value}: {why}", flag_of(option)),
        SpecError::Unknown { option, command } => anyhow!(
            "{} is not a flag of seethru {}",
            flag_of(&option),
            command.name()
        ),
        SpecError::Ignored(rule) => anyhow!("{}", rule.flag_refusal()),
    }
}

/// `--help`'s text of an option of `command`: the table's help, the unit and range, a derived
/// default.
fn help_of(option: &OptionSpec, command: Command) -> String {
    let mut help = option.help.to_string();
    let need = option.kind.need();
    match (option.kind, option.unit) {
        (Kind::Choice(_) | Kind::Switch, _) => {}
        // The need names the unit: `inf, auto or a distance in metres in […]`.
        (Kind::Distance { .. }, _) | (_, "") => {
            help.push_str(&format!(" {}{}.", need[..1].to_uppercase(), &need[1..]))
        }
        (_, unit) => help.push_str(&format!(" In {unit}: {need}.")),
    }
    if let Default::Derived(what) = option.default_for(command) {
        help.push_str(&format!(" Default: {what}."));
    }
    help
}

/// The placeholder of an option's value in `--help`: `PIXELS`, `X,Y,Z`.
fn value_name(option: &OptionSpec) -> String {
    match option.kind {
        Kind::Triple { .. } => "X,Y,Z".to_string(),
        Kind::Distance { .. } => "METRES|inf|auto".to_string(),
        _ if !option.unit.is_empty() => option.unit.to_uppercase(),
        _ => option.name.to_uppercase(),
    }
}

/// A choice among names, spaces around the value ignored (as around numbers: `--eyes ' both'`),
/// with clap's list of the possible values and their help in `--help` and errors.
#[derive(Clone)]
struct ChoiceValue(Vec<PossibleValue>);

impl TypedValueParser for ChoiceValue {
    type Value = Value;

    fn parse_ref(
        &self,
        cmd: &clap::Command,
        arg: Option<&Arg>,
        value: &std::ffi::OsStr,
    ) -> Result<Value, clap::Error> {
        let trimmed = value
            .to_str()
            .map_or(value, |v| std::ffi::OsStr::new(v.trim()));
        PossibleValuesParser::new(self.0.clone())
            .parse_ref(cmd, arg, trimmed)
            .map(Value::Choice)
    }

    fn possible_values(&self) -> Option<Box<dyn Iterator<Item = PossibleValue> + '_>> {
        Some(Box::new(self.0.iter().cloned()))
    }
}

/// The flag of `option` in `command`.
fn arg_of(option: &'static OptionSpec, command: Command) -> Arg {
    let arg = Arg::new(option.name)
        .long(option.name.replace('_', "-"))
        .help(help_of(option, command));
    let arg = match option.kind {
        Kind::Switch => return arg.action(ArgAction::SetTrue),
        Kind::Choice(values) => arg.value_parser(ChoiceValue(values())),
        Kind::Triple { .. } => arg
            .allow_hyphen_values(true)
            .value_parser(move |text: &str| option.parse(text)),
        _ => arg.value_parser(move |text: &str| option.parse(text)),
    };
    let arg = arg.value_name(value_name(option));
    match option.default_for(command) {
        Default::Value(text) => arg.default_value(text),
        Default::Derived(_) => arg,
    }
}

impl<C: TableCommand> clap::Args for OptionArgs<C> {
    fn augment_args(cmd: clap::Command) -> clap::Command {
        options_of(C::COMMAND).fold(cmd, |cmd, option| cmd.arg(arg_of(option, C::COMMAND)))
    }

    fn augment_args_for_update(cmd: clap::Command) -> clap::Command {
        Self::augment_args(cmd)
    }
}

impl<C: TableCommand> clap::FromArgMatches for OptionArgs<C> {
    fn from_arg_matches(matches: &ArgMatches) -> Result<Self, clap::Error> {
        let given = options_of(C::COMMAND)
            .filter(|o| matches.value_source(o.name) == Some(ValueSource::CommandLine))
            .map(|o| {
                let value = match o.kind {
                    Kind::Switch => Value::Switch(matches.get_flag(o.name)),
                    _ => matches
                        .get_one::<Value>(o.name)
                        .cloned()
                        .expect("a value given is parsed"),
                };
                (o, value)
            })
            .collect();
        Ok(OptionArgs {
            given,
            command: PhantomData,
        })
    }

    fn update_from_arg_matches(&mut self, matches: &ArgMatches) -> Result<(), clap::Error> {
        *self = Self::from_arg_matches(matches)?;
        Ok(())
    }
}
