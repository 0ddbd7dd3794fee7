//! Every seethru command the README shows, run verbatim, so that the README cannot drift from
//! the program: the lines of its ```sh blocks, in order, in one scratch folder (with the
//! repository's scenes/ and assets/ beside them), and the complete commands quoted inline.

use std::path::{Path, PathBuf};
use std::process::Command;

/// Lines of ```sh blocks that are not seethru commands, by how they start: the test command
/// itself, the bless variable, the asset generator and the other tools' setups and scripts
/// (which need Node, Blender or Mitsuba from the network).
const NOT_SEETHRU: [&str; 9] = [
    "cargo test --release",
    "SEETHRU_BLESS=1 cargo test",
    "cargo run --example",
    "npm install",
    "node tools/",
    "python -m venv",
    "mi/bin/python",
    "bl/bin/python",
    "python3",
];

/// The seethru arguments of a README command line, or `None` when it is not one.
fn seethru_args(line: &str) -> Option<Vec<String>> {
    let rest = line
        .strip_prefix("cargo run --release -- ")
        .or_else(|| line.strip_prefix("seethru "))?;
    Some(rest.split_whitespace().map(str::to_string).collect())
}

/// The README's commands: (line number, arguments), ```sh blocks first, in order.
fn readme_commands() -> Vec<(usize, Vec<String>)> {
    let readme =
        std::fs::read_to_string(Path::new(env!("CARGO_MANIFEST_DIR")).join("README.md")).unwrap();
    let mut commands = Vec::new();
    let mut inline = Vec::new();
    let mut prose: Vec<(usize, &str)> = Vec::new();
    let mut fence: Option<String> = None;
    for (number, line) in readme.lines().enumerate() {
        let number = number + 1;
        let trimmed = line.trim();
        if let Some(lang) = trimmed.strip_prefix("```") {
            fence = match fence {
                Some(_) => None,
                None => Some(lang.to_string()),
            };
            continue;
        }
        match fence.as_deref() {
            Some("sh") => {
                if trimmed.is_empty() || trimmed.starts_with('#') {
                    continue;
                }
                match seethru_args(trimmed) {
                    Some(args) => commands.push((number, args)),
                    None => assert!(
                        NOT_SEETHRU.iter().any(|p| trimmed.starts_with(p)),
                        "README.md:{number}: `{trimmed}` is neither a seethru command nor a known other one"
                    ),
                }
            }
            Some(_) => {}
            None => prose.push((number, line)),
        }
    }
    // Inline code spans that are whole commands (no <placeholders> or [options]); a span may
    // wrap onto the next line of the paragraph.
    let mut in_span: Option<(usize, String)> = None;
    for (number, line) in prose {
        for (k, piece) in line.split('`').enumerate() {
            if k > 0 {
                in_span = match in_span.take() {
                    Some((start, span)) => {
                        if let Some(args) = seethru_args(&span)
                            && !span.contains(['<', '['])
                        {
                            inline.push((start, args));
                        }
                        None
                    }
                    None => Some((number, String::new())),
                };
            }
            if let Some((_, span)) = in_span.as_mut() {
                span.push_str(piece);
            }
        }
        if let Some((_, span)) = in_span.as_mut() {
            span.push(' ');
        }
        if line.trim().is_empty() {
            in_span = None; // A paragraph ends any span.
        }
    }
    commands.extend(inline);
    commands
}

/// `parts/*.csv` → the matching files of `dir`, sorted, as a shell would expand it.
fn expand(dir: &Path, arg: &str) -> Vec<String> {
    let Some((folder, pattern)) = arg.rsplit_once('/').filter(|_| arg.contains('*')) else {
        return vec![arg.to_string()];
    };
    let (prefix, suffix) = pattern.split_once('*').unwrap();
    let mut found: Vec<String> = std::fs::read_dir(dir.join(folder))
        .unwrap()
        .flatten()
        .map(|e| e.file_name().to_string_lossy().to_string())
        .filter(|n| n.starts_with(prefix) && n.ends_with(suffix))
        .map(|n| format!("{folder}/{n}"))
        .collect();
    found.sort();
    assert!(!found.is_empty(), "{arg} matches nothing");
    found
}

#[test]
#[cfg(unix)]
fn every_command_in_the_readme_runs_as_written() {
    let repo = PathBuf::from(env!("CARGO_MANIFEST_DIR"));
    let scratch = tempfile::tempdir().unwrap();
    for folder in ["scenes", "assets"] {
        std::os::unix::fs::symlink(repo.join(folder), scratch.path().join(folder)).unwrap();
    }
    let commands = readme_commands();
    assert!(commands.len() >= 10, "{commands:?}");
    // The main command, and an inline one that wraps across two lines of its paragraph.
    for expected in [
        "run scenes/das.toml --out out/",
        "ratio occlusion --L 5 --b1 -0.35 --d2 6.3 --d1 2.5 --bh 1.75",
    ] {
        assert!(
            commands.iter().any(|(_, a)| a.join(" ") == expected),
            "`{expected}` not found in {commands:?}"
        );
    }
    for (number, args) in commands {
        let args: Vec<String> = args
            .iter()
            .flat_map(|a| expand(scratch.path(), a))
            .collect();
        let output = Command::new(env!("CARGO_BIN_EXE_seethru"))
            .args(&args)
            .arg("--quiet")
            .current_dir(scratch.path())
            .output()
            .unwrap();
        assert!(
            output.status.success(),
            "README.md:{number}: seethru {} failed: {}",
            args.join(" "),
            String::from_utf8_lossy(&output.stderr)
        );
    }
}
