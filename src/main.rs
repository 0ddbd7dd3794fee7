//! The `seethru` command line: parses the arguments and dispatches to the command.
#![forbid(unsafe_code)]

mod cli;

use std::process::ExitCode;

use clap::error::ErrorKind;
use seethru::util::message::{error_text, printable};
use seethru::util::option_words::as_flags;

fn main() -> ExitCode {
    // `seethru analyze | head`: a reader that closes the pipe early ends the command quietly,
    // as the shell's own tools do (exit 141 = killed by SIGPIPE), instead of a panic that
    // `println!` raises on the broken pipe.
    let default_hook = std::panic::take_hook();
    std::panic::set_hook(Box::new(move |info| {
        let message = info
            .payload()
            .downcast_ref::<String>()
            .map(String::as_str)
            .or_else(|| info.payload().downcast_ref::<&str>().copied())
            .unwrap_or_default();
        if message.contains("failed printing to stdout") && message.contains("Broken pipe") {
            std::process::exit(141);
        }
        default_hook(info);
    }));
    let cli = match cli::parse(cli::with_negative_values_joined(std::env::args_os())) {
        Ok(cli) => cli,
        Err(e) if matches!(e.kind(), ErrorKind::DisplayHelp | ErrorKind::DisplayVersion) => {
            e.exit()
        }
        Err(e) => {
            eprintln!("{}", printable(&cli::one_line(&e)));
            return ExitCode::from(2);
        }
    };
    seethru::util::progress::set_quiet(cli.quiet);
    // Ctrl-C or SIGTERM: no half-written file stays behind (finished files are whole).
    // The handler keeps the registry of temporaries locked until the exit, so that no thread
    // creates one after the clean-up.
    let _ = ctrlc::set_handler(|| {
        seethru::io::atomic::remove_in_flight_then(|removed| {
            eprintln!("error: interrupted; {removed} partly written files removed");
            std::process::exit(130)
        })
    });
    let error_status = cli.command.error_status();
    match cli.command.run() {
        Ok(()) => ExitCode::SUCCESS,
        // Thresholds exceeded: the command has said which; exit 1 ("worse"), not an error.
        Err(e) if e.downcast_ref::<cli::verdict::ChecksFailed>().is_some() => {
            eprintln!("{}", printable(&as_flags(&e.to_string())));
            ExitCode::from(1)
        }
        Err(e) => {
            // Messages repeat the input: an 800-digit number stays 12 digits, a line break
            // in a name is shown as `\n`; each cause is said once; the options the library's
            // words name ("option `width`") are the command line's flags (`--width`).
            eprintln!("error: {}", printable(&as_flags(&error_text(&e))));
            ExitCode::from(error_status)
        }
    }
}
