//! The `seethru` command line: parses the arguments and dispatches to the command.
#![forbid(unsafe_code)]

mod cli;

use std::process::ExitCode;

use clap::Parser;
use clap::error::ErrorKind;

fn main() -> ExitCode {
    let cli = match cli::Cli::try_parse() {
        Ok(cli) => cli,
        Err(e) if matches!(e.kind(), ErrorKind::DisplayHelp | ErrorKind::DisplayVersion) => {
            e.exit()
        }
        Err(e) => {
            eprintln!("{}", cli::one_line(&e));
            return ExitCode::from(2);
        }
    };
    seethru::util::progress::set_quiet(cli.quiet);
    // Ctrl-C or SIGTERM: no half-written file stays behind (finished files are whole).
    let _ = ctrlc::set_handler(|| {
        let removed = seethru::io::atomic::remove_in_flight();
        eprintln!("error: interrupted; {removed} partly written files removed");
        std::process::exit(130);
    });
    match cli.command.run() {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("error: {e:#}");
            ExitCode::FAILURE
        }
    }
}
