//! The flags the user typed (as opposed to defaults), recorded when a command line is parsed,
//! so that a command can refuse a flag it would ignore ([`super::args::refuse_ignored`]).
//! `check` parses each case's command line in turn: the flags are those of the command line
//! parsed last, so a case is held to the rules its own command line would be on its own.

use std::sync::{PoisonError, RwLock};

use clap::parser::ValueSource;

static GIVEN: RwLock<Vec<String>> = RwLock::new(Vec::new());

/// Records the long flags given on the command line in `matches` (of `command`), down the
/// subcommands, in place of those of the command line parsed before. Called by the parser.
pub fn record(command: &clap::Command, matches: &clap::ArgMatches) {
    let mut flags = Vec::new();
    walk(command, matches, &mut flags);
    *GIVEN.write().unwrap_or_else(PoisonError::into_inner) = flags;
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
        .read()
        .unwrap_or_else(PoisonError::into_inner)
        .iter()
        .any(|f| f == flag)
}
