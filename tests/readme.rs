//! Every seethru command the docs show, run verbatim, so that the docs cannot drift from the
//! program: for README.md and each page of docs/guide/ and docs/reference/, the lines of its
//! ```sh blocks, in order, then the complete commands quoted inline, in a scratch folder of
//! the page's own (with copies of the repository's scenes/ and assets/). And every relative
//! link of the docs leads to a file (and heading) that exists.

use std::path::{Path, PathBuf};
use std::process::Command;

/// Lines of ```sh blocks that are not seethru commands, by how they start: the test command
/// itself, the bless variable, the asset generator and the other tools' setups and scripts
/// (which need Node, Blender or Mitsuba from the network).
const NOT_SEETHRU: [&str; 9] = [
    "cargo test --release",
    "SEETHRU_BLESS=",
    "cargo run --example",
    "npm install",
    "node tools/",
    "python -m venv",
    "mi/bin/python",
    "bl/bin/python",
    "python3",
];

/// The seethru arguments of a documented command line, or `None` when it is not one.
fn seethru_args(line: &str) -> Option<Vec<String>> {
    let rest = line
        .strip_prefix("cargo run --release -- ")
        .or_else(|| line.strip_prefix("seethru "))?;
    Some(rest.split_whitespace().map(str::to_string).collect())
}

/// The documentation pages whose commands are run: README.md, then every page of
/// docs/guide/ and docs/reference/, by name.
fn doc_pages() -> Vec<PathBuf> {
    let repo = PathBuf::from(env!("CARGO_MANIFEST_DIR"));
    let mut pages = vec![repo.join("README.md")];
    for folder in ["docs/guide", "docs/reference"] {
        let mut found: Vec<PathBuf> = std::fs::read_dir(repo.join(folder))
            .unwrap()
            .flatten()
            .map(|e| e.path())
            .filter(|p| p.extension().is_some_and(|x| x == "md"))
            .collect();
        found.sort();
        pages.extend(found);
    }
    pages
}

/// A page's name relative to the repository, for messages: `docs/guide/sweeps.md`.
fn shown(page: &Path) -> String {
    page.strip_prefix(env!("CARGO_MANIFEST_DIR"))
        .unwrap_or(page)
        .display()
        .to_string()
}

/// Commands of a page: (line number, arguments).
type Commands = Vec<(usize, Vec<String>)>;

/// A page's commands: (line number, arguments), ```sh blocks first, in order.
fn page_commands(page: &Path) -> Commands {
    let text = std::fs::read_to_string(page).unwrap();
    let name = shown(page);
    let mut commands = Vec::new();
    let mut inline = Vec::new();
    let mut prose: Vec<(usize, &str)> = Vec::new();
    let mut fence: Option<String> = None;
    for (number, line) in text.lines().enumerate() {
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
                        "{name}:{number}: `{trimmed}` is neither a seethru command nor a known other one"
                    ),
                }
            }
            Some(_) => {}
            None => prose.push((number, line)),
        }
    }
    // Inline code spans that are whole commands (no <placeholders>, PLACEHOLDERS or [options],
    // and more than the command's name: `seethru capture` names the command); a span may wrap
    // onto the next line of the paragraph.
    let placeholder = |a: &String| {
        a.chars().filter(char::is_ascii_uppercase).count() >= 2
            && !a.chars().any(|c| c.is_ascii_lowercase())
    };
    let mut in_span: Option<(usize, String)> = None;
    for (number, line) in prose {
        for (k, piece) in line.split('`').enumerate() {
            if k > 0 {
                in_span = match in_span.take() {
                    Some((start, span)) => {
                        if let Some(args) = seethru_args(&span)
                            && !span.contains(['<', '['])
                            && args.len() > 1
                            && !args.iter().any(placeholder)
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

/// Copies `from` into `to`, folders and files (a page's commands may write beside the scenes).
fn copy_tree(from: &Path, to: &Path) {
    std::fs::create_dir_all(to).unwrap();
    for entry in std::fs::read_dir(from).unwrap().flatten() {
        let target = to.join(entry.file_name());
        if entry.file_type().unwrap().is_dir() {
            copy_tree(&entry.path(), &target);
        } else {
            std::fs::copy(entry.path(), target).unwrap();
        }
    }
}

#[test]
fn every_command_in_the_docs_runs_as_written() {
    let repo = PathBuf::from(env!("CARGO_MANIFEST_DIR"));
    let pages = doc_pages();
    let all: Vec<(PathBuf, Commands)> = pages
        .iter()
        .map(|p| (p.clone(), page_commands(p)))
        .collect();
    let of = |name: &str| &all.iter().find(|(p, _)| shown(p) == name).unwrap().1;
    assert!(of("README.md").len() >= 5, "{:?}", of("README.md"));
    // The main command, and an inline one that wraps across two lines of its paragraph.
    for (page, expected) in [
        ("README.md", "run scenes/das.toml --out out/"),
        (
            "docs/guide/paper.md",
            "ratio occlusion --L 5 --b1 -0.35 --d2 6.3 --d1 2.5 --bh 1.75",
        ),
    ] {
        assert!(
            of(page).iter().any(|(_, a)| a.join(" ") == expected),
            "`{expected}` not found in {page}: {:?}",
            of(page)
        );
    }
    for (page, commands) in all {
        let name = shown(&page);
        // Each page in a folder of its own: what one page writes cannot make another pass.
        let scratch = tempfile::tempdir().unwrap();
        for folder in ["scenes", "assets", "examples"] {
            copy_tree(&repo.join(folder), &scratch.path().join(folder));
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
                "{name}:{number}: seethru {} failed: {}",
                args.join(" "),
                String::from_utf8_lossy(&output.stderr)
            );
        }
    }
}

/// Every Markdown file of the repository's documentation: README.md and docs/, recursively.
fn markdown_files() -> Vec<PathBuf> {
    fn walk(dir: &Path, out: &mut Vec<PathBuf>) {
        for entry in std::fs::read_dir(dir).unwrap().flatten() {
            let path = entry.path();
            if path.is_dir() {
                walk(&path, out);
            } else if path.extension().is_some_and(|x| x == "md") {
                out.push(path);
            }
        }
    }
    let repo = PathBuf::from(env!("CARGO_MANIFEST_DIR"));
    let mut files = vec![repo.join("README.md")];
    walk(&repo.join("docs"), &mut files);
    files.sort();
    files
}

/// GitHub's anchor of a heading: lower case, spaces to hyphens, punctuation dropped.
fn slug(heading: &str) -> String {
    heading
        .to_lowercase()
        .chars()
        .filter_map(|c| match c {
            ' ' => Some('-'),
            c if c.is_alphanumeric() || c == '-' || c == '_' => Some(c),
            _ => None,
        })
        .collect()
}

/// The anchors of a Markdown file's headings (outside code blocks), with GitHub's `-1`, `-2`
/// for repeated headings.
fn anchors(text: &str) -> Vec<String> {
    let mut seen: Vec<String> = Vec::new();
    let mut fenced = false;
    for line in text.lines() {
        if line.trim_start().starts_with("```") {
            fenced = !fenced;
            continue;
        }
        if fenced || !line.starts_with('#') {
            continue;
        }
        let base = slug(line.trim_start_matches('#').trim());
        let repeats = seen
            .iter()
            .filter(|s| {
                **s == base
                    || s.strip_prefix(&format!("{base}-"))
                        .is_some_and(|n| n.parse::<u32>().is_ok())
            })
            .count();
        seen.push(if repeats == 0 {
            base
        } else {
            format!("{base}-{repeats}")
        });
    }
    seen
}

/// The relative link targets of a Markdown text outside code blocks and code spans:
/// (line number, target), for `[text](target)` and `![alt](target)`.
fn relative_links(text: &str) -> Vec<(usize, String)> {
    let mut links = Vec::new();
    let mut fenced = false;
    for (number, line) in text.lines().enumerate() {
        if line.trim_start().starts_with("```") {
            fenced = !fenced;
            continue;
        }
        if fenced {
            continue;
        }
        // Code spans are not links: keep the pieces between backticks at even positions.
        let prose: String = line
            .split('`')
            .enumerate()
            .filter(|(k, _)| k % 2 == 0)
            .map(|(_, p)| p)
            .collect::<Vec<_>>()
            .join(" ");
        let mut rest = prose.as_str();
        while let Some(at) = rest.find("](") {
            let after = &rest[at + 2..];
            let Some(close) = after.find(')') else { break };
            let target = after[..close].trim();
            if !target.contains("://") && !target.starts_with("mailto:") {
                links.push((number + 1, target.to_string()));
            }
            rest = &after[close..];
        }
    }
    links
}

#[test]
fn every_relative_link_in_the_docs_resolves() {
    let mut checked = 0;
    let mut broken = Vec::new();
    for file in markdown_files() {
        let text = std::fs::read_to_string(&file).unwrap();
        for (number, target) in relative_links(&text) {
            let (path, anchor) = target.split_once('#').unwrap_or((&target, ""));
            let resolved = if path.is_empty() {
                file.clone()
            } else {
                file.parent().unwrap().join(path)
            };
            // Normalise `a/../b` to name the file as the repository does.
            let mut normal = PathBuf::new();
            for part in resolved.components() {
                match part {
                    std::path::Component::ParentDir => {
                        normal.pop();
                    }
                    std::path::Component::CurDir => {}
                    other => normal.push(other),
                }
            }
            let name = shown(&normal);
            checked += 1;
            if !normal.exists() {
                broken.push(format!(
                    "{}:{number}: {target}: no file {name}",
                    shown(&file)
                ));
                continue;
            }
            if !anchor.is_empty() && normal.extension().is_some_and(|x| x == "md") {
                let headings = anchors(&std::fs::read_to_string(&normal).unwrap());
                if !headings.iter().any(|h| h == anchor) {
                    broken.push(format!(
                        "{}:{number}: {target}: no heading #{anchor} in {name} (it has {headings:?})",
                        shown(&file)
                    ));
                }
            }
        }
    }
    assert!(
        checked >= 50,
        "only {checked} links found: is the parser blind?"
    );
    assert!(broken.is_empty(), "broken links:\n{}", broken.join("\n"));
}

#[test]
fn anchors_and_links_are_read_as_github_does() {
    assert_eq!(
        slug("Time: sequences and latency (`sequence`)"),
        "time-sequences-and-latency-sequence"
    );
    assert_eq!(slug("`[[object]]`"), "object");
    assert_eq!(
        anchors("# A\n## `run`\n```\n# not a heading\n```\n## run\n"),
        ["a", "run", "run-1"]
    );
    assert_eq!(
        relative_links("see [x](a.md#b), `[y](not.md)` and ![i](../img.png) or [w](https://e.org)"),
        [(1, "a.md#b".to_string()), (1, "../img.png".to_string())]
    );
}

#[test]
fn every_guide_and_reference_page_opens_with_a_sentence_and_a_runnable_example() {
    for page in doc_pages().iter().skip(1) {
        let text = std::fs::read_to_string(page).unwrap();
        // The first paragraph under the title, its lines joined.
        let sentence = text
            .lines()
            .skip(1)
            .skip_while(|l| l.trim().is_empty())
            .take_while(|l| !l.trim().is_empty())
            .collect::<Vec<_>>()
            .join(" ");
        assert!(
            !sentence.starts_with('#') && !sentence.starts_with("```") && sentence.contains('.'),
            "{}: no opening sentence under the title (found `{sentence}`)",
            shown(page)
        );
        let first_fence = text.lines().find(|l| l.trim_start().starts_with("```"));
        assert_eq!(
            first_fence.map(str::trim),
            Some("```sh"),
            "{}: the first example is not a ```sh block",
            shown(page)
        );
    }
}
