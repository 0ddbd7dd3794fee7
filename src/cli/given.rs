//! The flags the user typed (as opposed to defaults), recorded once when the command line is
//! parsed, so that a command can refuse a flag it would ignore ([`super::args::refuse_ignored`]).

use std::sync::OnceLock;

use clap::parser::ValueSource;

static GIVEN: OnceLock<Vec<String>> = OnceLock::new();

/// Records the long flags given on the command line in `matches` (of `command`), down the
/// subcommands. Called once, by the parser.
pub fn record(command: &clap::Command, matches: &clap::ArgMatches) {
    let mut flags = Vec::new();
    walk(command, matches, &mut flags);
    let _ = GIVEN.set(flags);
}

fn walk(command: &clap::Command, matches: &clap::ArgMatches, flags: &mut Vec<String>) {
    for arg in command.get_arguments() {
        if matches.value_source(arg.get_id().as_str()) == Some(ValueSource::CommandLine)
            && let Some(long) = arg.get_long()
        {
            flags.push(format!("--{long}"));
        }
    }
    if let Some((name, sub)) = matches.subcommand()
        && let Some(sub_command) = command.find_subcommand(name)
    {
        walk(sub_command, sub, flags);
    }
}

/// Whether `flag` (`--ipd`) was on the command line.
pub fn given(flag: &str) -> bool {
    GIVEN
        .get()
        .is_some_and(|flags| flags.iter().any(|f| f == flag))
}
