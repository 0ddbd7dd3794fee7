//! Expectation files for `seethru check`: cases (a scene, a command, its options) with
//! bounds on their metrics. They are typed data like scene files: unknown keys, unknown
//! metrics and malformed bounds are errors naming the file, the line and the key.
//!
//! ```toml
//! [[case]]
//! name = "das-planar"
//! scene = "../scenes/das.toml"     # relative to this file
//! command = "run"                  # run (default) or sequence
//! options = ["--width", "160"]     # flags of the command (not --out)
//! golden = "golden/das-planar.png" # seethru.png of the run, for the *_vs_golden metrics
//! expect = [
//!   "misregistration.mean <= 35",
//!   "coverage >= 0.99",
//!   "flip_mean_vs_golden <= 0.02",
//!   "misregistration.p95 == 61.3 +- 0.5",  # a recorded value: --bless rewrites it
//! ]
//! ```

use std::ops::Range;
use std::path::{Path, PathBuf};

use crate::measure::headline::RunKind;
use crate::scene::source::{SceneError, SourceFile};
use crate::scene::table_reader::TableReader;
use crate::util::number::short;

/// Metrics of a run's `seethru.png` against the case's golden image.
pub const GOLDEN_METRICS: [(&str, &str); 3] = [
    ("flip_mean_vs_golden", "flip_mean"),
    ("psnr_db_vs_golden", "psnr_db"),
    ("max_abs_error_vs_golden", "max_abs_error"),
];

/// How a bound holds a metric.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Relation {
    AtMost,
    AtLeast,
    /// `== value +- tolerance`: a recorded value, which `--bless` rewrites.
    Recorded {
        tolerance: f64,
    },
}

/// One bound of a case, as written (`coverage >= 0.99`).
#[derive(Clone, Debug, PartialEq)]
pub struct Bound {
    pub metric: String,
    pub relation: Relation,
    pub value: f64,
    /// The bound as written (its words joined by single spaces).
    pub written: String,
    /// Byte span of the bound's string (quotes included) in the file, for `--bless`.
    pub span: Option<Range<usize>>,
    /// 1-based line of the bound in the file.
    pub line: Option<usize>,
}

impl Bound {
    /// Whether `measured` satisfies the bound (NaN never does).
    pub fn holds(&self, measured: f64) -> bool {
        match self.relation {
            Relation::AtMost => measured <= self.value,
            Relation::AtLeast => measured >= self.value,
            Relation::Recorded { tolerance } => (measured - self.value).abs() <= tolerance,
        }
    }

    /// The bound as written in a file, with `value` in place of its own.
    pub fn text_with(&self, value: f64) -> String {
        match self.relation {
            Relation::AtMost => format!("{} <= {}", self.metric, short(value)),
            Relation::AtLeast => format!("{} >= {}", self.metric, short(value)),
            Relation::Recorded { tolerance } => {
                format!(
                    "{} == {} +- {}",
                    self.metric,
                    recorded(value),
                    short(tolerance)
                )
            }
        }
    }

    /// The bound as written in the file.
    pub fn text(&self) -> String {
        self.written.clone()
    }

    /// Whether the bound compares against the golden image.
    pub fn needs_golden(&self) -> bool {
        GOLDEN_METRICS.iter().any(|g| g.0 == self.metric)
    }
}

/// A recorded value with enough digits to be read back as itself within 1e-6 relative.
fn recorded(value: f64) -> String {
    let text = format!("{value:.6}");
    let trimmed = text.trim_end_matches('0').trim_end_matches('.');
    trimmed.to_string()
}

/// What a case runs.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum CaseCommand {
    Run,
    Sequence,
}

impl CaseCommand {
    pub fn name(self) -> &'static str {
        match self {
            CaseCommand::Run => "run",
            CaseCommand::Sequence => "sequence",
        }
    }

    pub fn kind(self) -> RunKind {
        match self {
            CaseCommand::Run => RunKind::Run,
            CaseCommand::Sequence => RunKind::Sequence,
        }
    }
}

/// One case: a command on a scene and the bounds its metrics must meet.
#[derive(Clone, Debug)]
pub struct Case {
    pub name: String,
    /// The scene file, resolved against the expectation file's folder.
    pub scene: PathBuf,
    pub command: CaseCommand,
    /// Flags passed to the command, as written.
    pub options: Vec<String>,
    /// The golden image (PNG), resolved against the expectation file's folder.
    pub golden: Option<PathBuf>,
    pub bounds: Vec<Bound>,
    /// 1-based line of the case's `[[case]]` header.
    pub line: Option<usize>,
}

/// An expectation file: its path, its text (for `--bless`) and its cases.
pub struct Expectations {
    pub path: PathBuf,
    pub text: String,
    pub cases: Vec<Case>,
}

/// The keys of a case, with their defaults, for messages and the documentation.
pub const CASE_KEYS: [&str; 6] = ["name", "scene", "command", "options", "golden", "expect"];

/// Every metric a bound of a `command` case may name, comma-separated.
pub fn known_metrics(command: CaseCommand) -> String {
    let mut names = command.kind().names();
    if command == CaseCommand::Run {
        for g in GOLDEN_METRICS {
            names.push_str(", ");
            names.push_str(g.0);
        }
    }
    names
}

/// Reads one bound `METRIC OP VALUE` (OP `<=` or `>=`) or `METRIC == VALUE +- TOLERANCE`;
/// the message says what is wrong.
pub fn parse_bound(text: &str, command: CaseCommand) -> Result<Bound, String> {
    // The messages echo what was written: a line break or an escape in the TOML string must
    // not split them or reach the terminal.
    bound_of(text, command).map_err(|m| crate::util::message::printable(&m))
}

fn bound_of(text: &str, command: CaseCommand) -> Result<Bound, String> {
    let words: Vec<&str> = text.split_whitespace().collect();
    let form = "a bound is `METRIC <= VALUE`, `METRIC >= VALUE` or `METRIC == VALUE +- TOLERANCE`";
    let metric = *words
        .first()
        .ok_or_else(|| format!("empty bound; {form}"))?;
    let known = command.kind().headline(metric).is_some()
        || (command == CaseCommand::Run && GOLDEN_METRICS.iter().any(|g| g.0 == metric));
    if !known {
        return Err(format!(
            "unknown metric `{metric}` for a {} case (known: {})",
            command.name(),
            known_metrics(command)
        ));
    }
    let number = |word: Option<&&str>, what: &str| -> Result<f64, String> {
        let word = word.ok_or_else(|| format!("`{text}` has no {what}; {form}"))?;
        word.parse::<f64>()
            .ok()
            .filter(|v| v.is_finite())
            .ok_or_else(|| format!("the {what} `{word}` is not a finite number"))
    };
    let (relation, count) = match words.get(1).copied() {
        Some("<=") => (Relation::AtMost, 3),
        Some(">=") => (Relation::AtLeast, 3),
        Some("==") => {
            if !matches!(words.get(3).copied(), Some("+-" | "±")) {
                return Err(format!(
                    "`{text}`: a recorded value needs its tolerance, `{metric} == VALUE +- TOLERANCE`"
                ));
            }
            let tolerance = number(words.get(4), "tolerance")?;
            if tolerance < 0.0 {
                return Err(format!(
                    "the tolerance {} must be in [0, inf)",
                    short(tolerance)
                ));
            }
            (Relation::Recorded { tolerance }, 5)
        }
        Some(op) => return Err(format!("`{op}` is not a comparison; {form}")),
        None => return Err(format!("`{text}` has no comparison; {form}")),
    };
    let value = number(words.get(2), "value")?;
    if words.len() > count {
        return Err(format!(
            "`{text}` goes on after the bound (`{}`); {form}",
            words[count..].join(" ")
        ));
    }
    Ok(Bound {
        metric: metric.to_string(),
        relation,
        value,
        written: words.join(" "),
        span: None,
        line: None,
    })
}

/// Reads an expectation file. `check_options(command, options)` says why a case's options
/// would not run (the command line's own parser), or `None`.
pub fn read_expectations(
    path: &Path,
    check_options: &dyn Fn(CaseCommand, &[String]) -> Option<String>,
) -> Result<Expectations, SceneError> {
    expectations_from_source(&SourceFile::read(path)?, check_options)
}

/// [`read_expectations`] of a file already read (the fuzz target's entry).
pub fn expectations_from_source(
    file: &SourceFile,
    check_options: &dyn Fn(CaseCommand, &[String]) -> Option<String>,
) -> Result<Expectations, SceneError> {
    let path = file.path.as_path();
    let doc = file.parse()?;
    let root = TableReader::root(file, &doc);
    let tables = root.array_of_tables("case")?;
    if tables.is_empty() {
        return Err(root.error(
            "case",
            "no [[case]]: an expectation file lists at least one",
        ));
    }
    let dir = file.dir();
    let mut cases: Vec<Case> = Vec::new();
    for table in tables {
        let name = table.required_str("name")?;
        if name.trim().is_empty() || name.chars().any(|c| c.is_control() || c == '/') {
            return Err(table.error(
                "name",
                format!(
                    "`{}` is not a case name (not empty, no `/`, no control characters)",
                    crate::util::message::printable(name)
                ),
            ));
        }
        if cases.iter().any(|c| c.name == name) {
            return Err(table.error("name", format!("a second case named `{name}`")));
        }
        let scene = dir.join(table.required_str("scene")?);
        let command = match table.choice("command", "run", &["run", "sequence"])? {
            "sequence" => CaseCommand::Sequence,
            _ => CaseCommand::Run,
        };
        let options: Vec<String> = table
            .strings_with_spans("options")?
            .into_iter()
            .map(|(s, _)| s.to_string())
            .collect();
        if options
            .iter()
            .any(|o| o == "--out" || o.starts_with("--out="))
        {
            return Err(table.error(
                "options",
                "option `out` is set by seethru check (each case runs into OUT/<name>)",
            ));
        }
        if let Some(why) = check_options(command, &options) {
            return Err(table.error("options", why));
        }
        let golden = table.opt_str("golden")?.map(|g| dir.join(g));
        if golden.is_some() && command == CaseCommand::Sequence {
            return Err(table.error(
                "golden",
                "a golden image is compared with a run's seethru.png: only run cases have one",
            ));
        }
        let mut bounds = Vec::new();
        for (text, span) in table.strings_with_spans("expect")? {
            let at = span.as_ref().map(|s| s.start);
            let mut bound =
                parse_bound(text, command).map_err(|m| table.error_at_offset("expect", at, m))?;
            if bound.needs_golden() && golden.is_none() {
                return Err(table.error_at_offset(
                    "expect",
                    at,
                    format!(
                        "`{}` compares with the golden image: the case needs `golden = \"FILE.png\"`",
                        bound.metric
                    ),
                ));
            }
            bound.line = at.map(|o| file.line_of(o));
            bound.span = span;
            bounds.push(bound);
        }
        if bounds.is_empty() {
            return Err(table.error(
                "expect",
                "a case needs at least one bound, e.g. expect = [\"misregistration.mean <= 35\"]",
            ));
        }
        let line = table.table_error("").line;
        table.finish()?;
        cases.push(Case {
            name: name.to_string(),
            scene,
            command,
            options,
            golden,
            bounds,
            line,
        });
    }
    root.finish()?;
    Ok(Expectations {
        path: path.to_path_buf(),
        text: file.text().to_string(),
        cases,
    })
}

/// The file's text with each bound of `updates` (its span in the file, its new text) put in
/// place of the old one; everything else (comments, order, spacing) as it was.
pub fn rewritten(text: &str, mut updates: Vec<(Range<usize>, String)>) -> String {
    updates.sort_by_key(|u| std::cmp::Reverse(u.0.start));
    let mut out = text.to_string();
    for (span, bound) in updates {
        out.replace_range(span, &format!("\"{bound}\""));
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn bounds_are_read_and_checked() {
        let b = parse_bound("misregistration.mean <= 35", CaseCommand::Run).unwrap();
        assert!(b.holds(35.0) && !b.holds(35.01) && !b.holds(f64::NAN));
        let b = parse_bound("coverage >= 0.99", CaseCommand::Run).unwrap();
        assert!(b.holds(0.99) && !b.holds(0.98));
        let b = parse_bound("misregistration.p95 == 60 +- 0.5", CaseCommand::Run).unwrap();
        assert!(b.holds(60.5) && b.holds(59.5) && !b.holds(60.6));
        assert_eq!(
            b.text_with(61.234_567_89),
            "misregistration.p95 == 61.234568 +- 0.5"
        );
        for (text, says) in [
            ("misregistration.mean < 35", "not a comparison"),
            (
                "misregistration.avg <= 35",
                "unknown metric `misregistration.avg`",
            ),
            ("coverage >= high", "not a finite number"),
            ("coverage == 0.9", "needs its tolerance"),
            ("coverage <= 1 and more", "goes on after"),
            ("coverage == 1 +- -1", "[0, inf)"),
            ("coverage == 1 +- -0.0001", "[0, inf)"),
            ("flip_mean_vs_golden <= 1", "unknown metric"),
        ] {
            let command = if text.starts_with("flip") {
                CaseCommand::Sequence
            } else {
                CaseCommand::Run
            };
            let e = parse_bound(text, command).unwrap_err();
            assert!(e.contains(says), "{text}: {e}");
        }
        // A recorded value may be held exactly.
        let b = parse_bound("coverage == 1 +- 0", CaseCommand::Run).unwrap();
        assert!(b.holds(1.0) && !b.holds(1.0 + 1e-12));
        // The golden metrics are a run case's alone, in its list and not a sequence's.
        let run = parse_bound("misregistration.avg <= 1", CaseCommand::Run).unwrap_err();
        let sequence = parse_bound("misregistration.avg <= 1", CaseCommand::Sequence).unwrap_err();
        for (metric, _) in GOLDEN_METRICS {
            assert!(run.contains(metric), "{run}");
            assert!(!sequence.contains(metric), "{sequence}");
        }
        assert!(run.contains("misregistration.mean") && sequence.contains("coverage.min"));
    }

    /// A case's name must be a folder name and its options must leave `--out` to `check`;
    /// each rule alone refuses its case, and a case that keeps them all is read.
    #[test]
    fn case_names_and_options_are_checked() {
        let read = |name: &str, options: &str| {
            let text = format!(
                "[[case]]\nname = \"{name}\"\nscene = \"das.toml\"\noptions = {options}\nexpect = [\"coverage >= 0.9\"]\n"
            );
            let file = SourceFile::from_text(Path::new("cases.toml"), text);
            expectations_from_source(&file, &|_, _| None).map_err(|e| e.to_string())
        };
        let read = |name: &str, options: &str| {
            let got = read(name, options);
            (
                got.as_ref().map(|e| e.cases.len()).ok(),
                got.err().unwrap_or_default(),
            )
        };
        assert_eq!(read("lean", r#"["--width", "64"]"#).0, Some(1));
        for name in ["", "  ", "a/b", "/", "a\\tb"] {
            let (cases, e) = read(name, "[]");
            assert!(
                cases.is_none() && e.contains("is not a case name"),
                "{name:?}: {e}"
            );
        }
        for options in [
            r#"["--out", "x"]"#,
            r#"["--out=x"]"#,
            r#"["--width", "64", "--out", "x"]"#,
        ] {
            let (cases, e) = read("lean", options);
            assert!(
                cases.is_none() && e.contains("option `out` is set by seethru check"),
                "{options}: {e}"
            );
        }
    }

    #[test]
    fn rewriting_replaces_only_the_spans() {
        let text = "expect = [\"a <= 1\", # keep\n \"b == 2 +- 1\"]";
        let start = text.find("\"b").unwrap();
        let end = text[start + 1..].find('"').unwrap() + start + 2;
        let out = rewritten(text, vec![(start..end, "b == 3 +- 1".into())]);
        assert_eq!(out, "expect = [\"a <= 1\", # keep\n \"b == 3 +- 1\"]");
    }
}
