//! The option table (`src/measure/option_table.rs`) against everything said of it elsewhere:
//! `docs/reference/options.md` and the Python stubs' signatures are made from the table here
//! and must match it (`SEETHRU_BLESS=1` rewrites them), and every flag of `run`, `capture` and
//! `compare` is either the table's or one of the few that only the command line has. (The
//! walk through both front ends, value by value, is `python/tests/test_option_table.py`.)

mod common;

use seethru::measure::option_table::{Command, Default, Kind, OPTIONS, OptionSpec, options_of};

/// The flags of each command that are not options of a run: files, output formats, threads.
fn command_line_only(command: Command) -> &'static [&'static str] {
    match command {
        Command::Run => &[
            "out",
            "calibration",
            "exr",
            "heatmap-max",
            "threads",
            "quiet",
            "help",
        ],
        Command::Capture => &["out", "calibration", "exr", "threads", "quiet", "help"],
        Command::Compare => &["methods", "out", "threads", "quiet", "help"],
        // A sequence's own options (Python's keywords too, `SEQUENCE_KEYS`): its timeline, the
        // vehicle's and the head's motion, the head's source, what it writes; and `budget`, the
        // command line's alone (it runs the sequence again per effect of time and writes the
        // split: from Python, the steps are sequences of scenes without the effects).
        Command::Sequence => &[
            "out",
            "quiet",
            "duration",
            "fps",
            "display-hz",
            "speed",
            "yaw-rate",
            "head",
            "head-path",
            "sway-cm",
            "sway-hz",
            "lean-cm",
            "lean-s",
            "lean-at",
            "latency-camera",
            "latency-tracking",
            "predict",
            "reproject",
            "frames",
            "flip",
            "exr",
            "head-source",
            "threads",
            "heatmap-max",
            "capture",
            "maps",
            "budget",
            "help",
        ],
        Command::Render => &["view", "out", "exr", "threads", "quiet", "help"],
    }
}

/// Python's type and default of an option of `command`, as the stubs write them:
/// `int | None = None`.
fn python_annotation(option: &OptionSpec, command: Command) -> String {
    let ty = match option.kind {
        Kind::Integer { .. } => "int".to_string(),
        Kind::Real { .. } => "float".to_string(),
        Kind::Triple { .. } => "tuple[float, float, float]".to_string(),
        Kind::Distance { .. } => "float | str".to_string(),
        Kind::Switch => "bool".to_string(),
        Kind::Choice(_) => {
            // A call is one run: `both` is the command line's alone.
            let names: Vec<String> = option
                .kind
                .choices()
                .into_iter()
                .filter(|n| !(option.name == "eyes" && n == "both"))
                .map(|n| format!("\"{n}\""))
                .collect();
            format!("Literal[{}]", names.join(", "))
        }
    };
    let Default::Value(text) = option.default_for(command) else {
        return format!("{ty} | None = None");
    };
    let number = |v: f64| match v.fract() == 0.0 {
        true => format!("{v:.1}"),
        false => v.to_string(),
    };
    let default = match option.kind {
        Kind::Choice(_) | Kind::Distance { .. } => format!("\"{text}\""),
        Kind::Switch => if text == "true" { "True" } else { "False" }.to_string(),
        Kind::Real { .. } => number(text.parse().unwrap()),
        Kind::Triple { .. } => {
            let xyz: Vec<String> = text
                .split(',')
                .map(|v| number(v.parse().unwrap()))
                .collect();
            format!("({})", xyz.join(", "))
        }
        Kind::Integer { .. } => text.to_string(),
    };
    format!("{ty} = {default}")
}

/// The indentation of a command's keywords in the stubs: `Scene.render` is a method.
fn stub_indent(command: Command) -> &'static str {
    match command {
        Command::Render => "        ",
        _ => "    ",
    }
}

fn stub_block(command: Command) -> String {
    let indent = stub_indent(command);
    let mut block = format!(
        "{indent}# The option table's ({}): tests/option_table.rs checks it (SEETHRU_BLESS=1 rewrites it).\n",
        command.name()
    );
    // A capture's `depth` is a parameter of its own, before the keywords.
    for option in
        options_of(command).filter(|o| !(command == Command::Capture && o.name == "depth"))
    {
        block.push_str(&format!(
            "{indent}{}: {},\n",
            option.name,
            python_annotation(option, command)
        ));
    }
    block.push_str(&format!("{indent}# End of the option table's.\n"));
    block
}

fn range_of(option: &OptionSpec) -> String {
    match option.kind {
        Kind::Choice(_) => option.kind.choices().join(", "),
        Kind::Switch => "on or off".to_string(),
        kind => kind.need(),
    }
}

fn options_page() -> String {
    let mut page = String::from(
        "# Options of run, capture, compare, sequence and render\n\n\
         Generated from the option table, `src/measure/option_table.rs`, by\n\
         `SEETHRU_BLESS=1 cargo test --release --test option_table` (the test fails when this page\n\
         and the table differ). Each option is a flag of the commands listed\n\
         (`--head-jitter-cm`) and a keyword of the Python functions of the same names\n\
         (`head_jitter_cm=`), with the same type, range and default; `seethru spec COMMAND\n\
         [FLAGS]` and `seethru.spec(command, **options)` print the run they make, checked.\n\
         \"Read with\" names settings under which the option is read: given where the others make\n\
         the command ignore it, an option is refused ([flags read or refused](flags-read-or-refused.md)).\n\n\
         ```sh\n\
         seethru spec run --method depth --depth-sensor tof --depth-noise 0.01\n\
         ```\n\n\
         | Option | Flag | Value | Unit | Default | Commands | Read with | What it does |\n\
         |---|---|---|---|---|---|---|---|\n",
    );
    for o in OPTIONS {
        let shown = |default: Default| match default {
            Default::Value(text) => format!("`{text}`"),
            Default::Derived(what) => what.to_string(),
        };
        let mut default = shown(o.default);
        for command in Command::ALL.into_iter().filter(|&c| o.taken_by(c)) {
            if o.default_for(command) != o.default {
                default.push_str(&format!(
                    " ({}: {})",
                    command.name(),
                    shown(o.default_for(command))
                ));
            }
        }
        let commands: Vec<&str> = o.commands.iter().map(|c| c.name()).collect();
        let read_with: Vec<String> = o
            .read_with
            .iter()
            .map(|(k, v)| format!("`{k}={v}`"))
            .collect();
        page.push_str(&format!(
            "| `{}` | `{}` | {} | {} | {} | {} | {} | {} |\n",
            o.name,
            o.flag(),
            range_of(o),
            o.unit,
            default,
            commands.join(", "),
            if read_with.is_empty() {
                "the defaults".to_string()
            } else {
                read_with.join(" or ")
            },
            o.help.replace('|', "\\|"),
        ));
    }
    page.push_str(
        "\nThe command line's own flags (files, output formats, threads) are in \
         [the command line](command-line.md). A sequence takes the options it shares with a \
         run from this table, with its own defaults where they differ; its timeline, the \
         vehicle's and the head's motion and the head's source (`head_source`: a sequence's \
         `head` is the head's motion) are its own (`seethru sequence --help`). `render` (and \
         `Scene.render`) takes the size, samples and memory bound of the views it renders.\n",
    );
    page
}

fn blessing() -> bool {
    std::env::var_os("SEETHRU_BLESS").is_some_and(|v| v == "1")
}

#[test]
fn the_options_page_is_the_tables() {
    let path = common::repo_path("docs/reference/options.md");
    let page = options_page();
    if blessing() {
        std::fs::write(&path, &page).unwrap();
    }
    let written = std::fs::read_to_string(&path).unwrap_or_default();
    assert!(
        written == page,
        "docs/reference/options.md differs from the option table: SEETHRU_BLESS=1 cargo test --release --test option_table rewrites it"
    );
}

#[test]
fn the_python_stubs_declare_the_tables_keywords() {
    let path = common::repo_path("python/seethru/__init__.pyi");
    let mut stubs = std::fs::read_to_string(&path).unwrap();
    let start = |c: Command| format!("{}# The option table's ({}):", stub_indent(c), c.name());
    let end = |c: Command| format!("{}# End of the option table's.\n", stub_indent(c));
    for command in Command::ALL {
        let at = stubs
            .find(&start(command))
            .unwrap_or_else(|| panic!("the stubs have no table block for {}", command.name()));
        let stop =
            at + stubs[at..].find(&end(command)).expect("the block's end") + end(command).len();
        let expected = stub_block(command);
        if blessing() {
            stubs.replace_range(at..stop, &expected);
            continue;
        }
        assert!(
            stubs[at..stop] == expected,
            "__init__.pyi's keywords of {} differ from the option table:\n{}\nexpected:\n{expected}",
            command.name(),
            &stubs[at..stop]
        );
    }
    if blessing() {
        std::fs::write(&path, stubs).unwrap();
    }
}

#[test]
fn every_flag_of_the_commands_is_the_tables_or_the_command_lines_own() {
    for command in Command::ALL {
        let (ok, text, _) = common::seethru(&[command.name(), "--help"]);
        assert!(ok);
        let flags: Vec<&str> = text
            .lines()
            .filter_map(|l| l.trim_start().strip_prefix("--"))
            .map(|l| l.split([' ', '<']).next().unwrap())
            .collect();
        let table: Vec<String> = options_of(command)
            .map(|o| o.name.replace('_', "-"))
            .collect();
        for flag in &flags {
            assert!(
                table.iter().any(|t| t == flag) || command_line_only(command).contains(flag),
                "seethru {} --{flag}: neither the option table's nor the command line's own",
                command.name()
            );
        }
        for option in &table {
            assert!(
                flags.contains(&option.as_str()),
                "seethru {} has no --{option}",
                command.name()
            );
        }
    }
}

/// The library's errors name an option in neither front end's words but as "option `name`"
/// (a Rust caller reads that as it is); the command line spells it `--name`, Python `name`.
#[test]
fn the_librarys_errors_name_options_in_no_front_ends_words() {
    use seethru::measure::run_spec::{RunSpec, SpecError};
    use seethru::util::option_words::{as_flags, as_keywords};

    let spp = seethru::render::settings::check_spp(0).unwrap_err();
    let text = format!("{spp:#}");
    assert!(text.starts_with("option `spp` 0 is out of range"), "{text}");
    assert!(!text.contains("--"), "{text}");
    assert!(as_flags(&text).starts_with("--spp 0 is out of range"));
    assert!(as_keywords(&text).starts_with("spp 0 is out of range"));

    // A setting the others make the run ignore: the seed with no noise to draw.
    let option = |name: &str| OPTIONS.iter().find(|o| o.name == name).unwrap();
    let given = [
        (option("method"), option("method").parse("none").unwrap()),
        (
            option("head_bias_cm"),
            option("head_bias_cm").parse("1,0,0").unwrap(),
        ),
    ];
    let Err(SpecError::Ignored(rule)) = RunSpec::build(Command::Run, &given) else {
        panic!("a head bias with method none is ignored, so refused");
    };
    let text = rule.refusal("options");
    assert_eq!(
        text,
        "option `head_bias_cm` is read only by the methods that compensate for the eye (not option `method` none); with the other options given it would be ignored: remove it"
    );
    assert!(rule.flag_refusal().starts_with("--head-bias-cm is read only by the methods that compensate for the eye (not --method none); with the other flags given"));
    assert!(rule.keyword_refusal().starts_with("head_bias_cm is read only by the methods that compensate for the eye (not method none); with the other options given"));
}

/// The string literals of `text` (Rust source) outside comments, with their line numbers;
/// the file's unit tests (after `#[cfg(test)]`) are left out: they assert texts, they are none.
fn string_literals(text: &str) -> Vec<(usize, String)> {
    let end = text
        .match_indices("#[cfg(test)]")
        .map(|(at, mark)| at + mark.len())
        .find(|&after| text[after..].trim_start().starts_with("mod "))
        .unwrap_or(text.len());
    let bytes = &text.as_bytes()[..end];
    let line = |at: usize| text[..at].matches('\n').count() + 1;
    let mut found = Vec::new();
    let mut i = 0;
    while i < bytes.len() {
        let rest = &text[i..end];
        if rest.starts_with("//") {
            i += rest.find('\n').unwrap_or(rest.len());
        } else if rest.starts_with("/*") {
            i += rest.find("*/").map_or(rest.len(), |e| e + 2);
        } else if (rest.starts_with("r\"") || rest.starts_with("r#"))
            && (i == 0 || !(bytes[i - 1].is_ascii_alphanumeric() || bytes[i - 1] == b'_'))
        {
            let hashes = rest[1..].chars().take_while(|&c| c == '#').count();
            if rest[1 + hashes..].starts_with('"') {
                let close = format!("\"{}", "#".repeat(hashes));
                let start = i + 2 + hashes;
                let stop = start + text[start..end].find(&close).unwrap();
                found.push((line(start), text[start..stop].to_string()));
                i = stop + close.len();
            } else {
                i += 1;
            }
        } else if bytes[i] == b'"' {
            let mut j = i + 1;
            while bytes[j] != b'"' {
                j += if bytes[j] == b'\\' { 2 } else { 1 };
            }
            found.push((line(i + 1), text[i + 1..j].to_string()));
            i = j + 1;
        } else if bytes[i] == b'\'' {
            // A char literal ('"', '\'') is skipped whole; a lifetime is not one.
            if rest[1..].starts_with('\\') {
                i += 2 + rest[2..].find('\'').unwrap() + 1;
            } else if rest[1..].chars().nth(1) == Some('\'') {
                i += 1 + rest[1..].chars().next().unwrap().len_utf8() + 1;
            } else {
                i += 1;
            }
        } else {
            i += 1;
        }
    }
    found
}

/// A command-line flag in `literal` (`--width`, starting a word): the library's messages
/// write "option `width`" instead, which each front end spells.
fn flag_in(literal: &str) -> Option<String> {
    let mut rest = literal;
    let mut before: Option<char> = None;
    while let Some(at) = rest.find("--") {
        let prior = rest[..at].chars().last().or(before);
        let name: String = rest[at + 2..]
            .chars()
            .take_while(|c| c.is_ascii_alphanumeric() || *c == '-')
            .collect();
        let starts_word = prior.is_none_or(|c| !(c.is_alphanumeric() || c == '-' || c == '_'));
        if starts_word && name.starts_with(|c: char| c.is_ascii_alphabetic()) {
            return Some(format!("--{name}"));
        }
        before = rest[..at + 2].chars().last();
        rest = &rest[at + 2..];
    }
    None
}

/// Every string of the library (src/ outside the command line: src/cli, src/main.rs) names an
/// option as "option `name`", never as the command line's flag: a Python user would read
/// about `--width`. The few strings that hold a flag for another reason are listed, with why.
#[test]
fn no_string_of_the_library_names_a_command_line_flag() {
    // (file, the string's flag, why it is the command line's own word)
    let allowed: [(&str, &str, &str); 3] = [
        (
            "src/measure/expectations.rs",
            "--out",
            "an expectation file lists the command line's arguments; `--out` is looked for in them",
        ),
        (
            "src/measure/maps.rs",
            "--heatmap-max",
            "the heatmap's scale label, drawn into the image `run` writes: heatmap_max is the command line's alone",
        ),
        (
            "src/measure/sequence_files.rs",
            "--heatmap-max",
            "the preview's scale label in summary.json and on the APNG `sequence` writes: the command line's alone",
        ),
    ];
    let src = common::repo_path("src");
    let mut files = Vec::new();
    fn walk(dir: &std::path::Path, out: &mut Vec<std::path::PathBuf>) {
        for entry in std::fs::read_dir(dir).unwrap() {
            let path = entry.unwrap().path();
            if path.is_dir() {
                walk(&path, out);
            } else if path.extension().is_some_and(|e| e == "rs") {
                out.push(path);
            }
        }
    }
    walk(&src, &mut files);
    files.sort();
    let mut found = Vec::new();
    for file in &files {
        let rel = format!("src/{}", file.strip_prefix(&src).unwrap().display());
        if rel.starts_with("src/cli/") || rel == "src/main.rs" {
            continue;
        }
        let text = std::fs::read_to_string(file).unwrap();
        for (line, literal) in string_literals(&text) {
            if let Some(flag) = flag_in(&literal)
                && !allowed.iter().any(|(f, a, _)| *f == rel && *a == flag)
            {
                found.push(format!("{rel}:{line}: {flag} in {literal:?}"));
            }
        }
    }
    assert!(
        found.is_empty(),
        "write \"option `name`\" instead of the flag (util/option_words.rs):\n{}",
        found.join("\n")
    );
    // The scan sees a flag where there is one.
    assert_eq!(flag_in("use --outside black"), Some("--outside".into()));
    assert_eq!(flag_in("--L must be > 0"), Some("--L".into()));
    assert_eq!(flag_in("runs--old/a.toml, -- x, option `outside`"), None);
    let sample = "let a = '\"'; // \"--x\"\n let b = \"see --width\"; let c = r#\"--raw\"#;";
    let literals: Vec<String> = string_literals(sample).into_iter().map(|l| l.1).collect();
    assert_eq!(literals, ["see --width", "--raw"]);
}
