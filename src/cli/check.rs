//! `seethru check expectations.toml`: runs each case of the file (a `run` or a `sequence`
//! into OUT/<case>), checks the bounds of its metrics, prints a PASS/FAIL table, writes the
//! JUnit report and the diff images of failures; `--bless` rewrites the goldens and the
//! recorded values. Exit 0 when every bound holds, 1 when one does not, 2 on bad input or a
//! case that could not run.

use std::path::{Path, PathBuf};
use std::time::Instant;

use anyhow::{Context, Result, bail};
use seethru::io::atomic::{write_atomically, write_text};
use seethru::io::frame_files::write_png;
use seethru::io::junit::{Outcome, TestCase, junit_xml};
use seethru::io::output_paths::{Input, Output, check_paths};
use seethru::measure::expectations::{
    Case, CaseCommand, GOLDEN_METRICS, Relation, read_expectations, rewritten,
};
use seethru::measure::headline::{read_results, value_of};
use seethru::measure::image_diff::{
    LayerDiff, diff_layer, flip_heatmap, paired_layers, pixels_per_degree,
};
use seethru::measure::picture_layers::read_picture;
use seethru::util::number::short;

use crate::cli::verdict::ChecksFailed;

#[derive(clap::Args)]
pub struct Check {
    /// Expectations file (TOML): cases and the bounds of their metrics.
    expectations: PathBuf,
    /// Folder the cases run into (OUT/<case>), with the diff images of failures in
    /// OUT/failures/<case>.
    #[arg(long, value_name = "DIR", default_value = "seethru-check")]
    out: PathBuf,
    /// Also write the results as JUnit XML to FILE (for GitHub Actions, GitLab, Jenkins).
    #[arg(long, value_name = "FILE")]
    junit: Option<PathBuf>,
    /// Rewrite the golden images and the recorded values (`METRIC == V +- T`) of the cases
    /// run from their results, and list what was written. Refused when CI is set.
    #[arg(long)]
    bless: bool,
    /// Run only the case of this name; repeatable (default: every case).
    #[arg(long = "case", value_name = "CASE")]
    cases: Vec<String>,
}

/// Whether the environment says this is a CI job (`CI` set to anything but empty, `0` or
/// `false`, as insta reads it): goldens are blessed on a developer's machine, never by CI.
fn in_ci() -> Option<String> {
    std::env::var("CI")
        .ok()
        .filter(|v| !v.is_empty() && v != "0" && !v.eq_ignore_ascii_case("false"))
}

/// The command line a case runs (`out` is where it writes).
fn case_args(command: CaseCommand, scene: &Path, out: &Path, options: &[String]) -> Vec<String> {
    let mut args = vec![
        "seethru".to_string(),
        command.name().to_string(),
        scene.display().to_string(),
        "--out".to_string(),
        out.display().to_string(),
    ];
    args.extend(options.iter().cloned());
    args
}

fn parse_case(args: Vec<String>) -> Result<crate::cli::Cli, String> {
    let args = crate::cli::with_negative_values_joined(args.into_iter().map(Into::into));
    // Parsed as the command line itself is, recording the case's flags: a flag its command
    // would ignore is refused as `run` alone refuses it.
    crate::cli::parse(args).map_err(|e| {
        let line = crate::cli::one_line(&e);
        line.strip_prefix("error: ").unwrap_or(&line).to_string()
    })
}

/// One bound checked.
struct Row {
    bound: String,
    measured: f64,
    pass: bool,
}

/// What one case gave.
struct CaseResult {
    name: String,
    seconds: f64,
    rows: Vec<Row>,
    /// Why the case could not run.
    error: Option<String>,
    /// Files that show a failure.
    evidence: Vec<PathBuf>,
}

impl Check {
    pub fn run(self) -> Result<()> {
        let mut outputs = vec![Output::folder("--out", &self.out)];
        outputs.extend(self.junit.as_deref().map(|j| Output::file("--junit", j)));
        check_paths(&[Input::file("EXPECTATIONS", &self.expectations)], &outputs)?;
        if self.bless
            && let Some(value) = in_ci()
        {
            bail!(
                "--bless is refused when CI is set (CI={value}): bless on a developer machine, look at what it wrote, and commit it"
            );
        }
        let check_options = |command: CaseCommand, options: &[String]| {
            let args = case_args(command, Path::new("scene.toml"), Path::new("out"), options);
            parse_case(args).err()
        };
        let expectations = read_expectations(&self.expectations, &check_options)?;
        for name in &self.cases {
            if !expectations.cases.iter().any(|c| &c.name == name) {
                bail!(
                    "--case {name}: {} has no such case (cases: {})",
                    self.expectations.display(),
                    expectations
                        .cases
                        .iter()
                        .map(|c| c.name.as_str())
                        .collect::<Vec<_>>()
                        .join(", ")
                );
            }
        }
        let cases: Vec<&Case> = expectations
            .cases
            .iter()
            .filter(|c| self.cases.is_empty() || self.cases.contains(&c.name))
            .collect();
        let mut results = Vec::new();
        let mut blessed: Vec<String> = Vec::new();
        let mut updates = Vec::new();
        for case in &cases {
            let started = Instant::now();
            let mut result = CaseResult {
                name: case.name.clone(),
                seconds: 0.0,
                rows: Vec::new(),
                error: None,
                evidence: Vec::new(),
            };
            match self.run_case(case, &mut blessed, &mut updates, &mut result) {
                Ok(()) => {}
                Err(e) => {
                    result.error = Some(seethru::util::option_words::as_flags(
                        &seethru::util::message::error_text(&e),
                    ))
                }
            }
            result.seconds = started.elapsed().as_secs_f64();
            results.push(result);
        }
        if !updates.is_empty() {
            let text = rewritten(&expectations.text, updates);
            write_text(&self.expectations, &text)?;
            blessed.push(format!("{} (recorded values)", self.expectations.display()));
        }
        print!("{}", table(&results));
        if let Some(path) = &self.junit {
            let suite = self.expectations.display().to_string();
            write_text(path, &junit_xml(&suite, &junit_cases(&results, &suite)))?;
        }
        for line in &blessed {
            seethru::util::progress::summary(format!("blessed {line}"));
        }
        let errors: Vec<String> = results
            .iter()
            .filter_map(|r| r.error.as_ref().map(|e| format!("case {}: {e}", r.name)))
            .collect();
        if !errors.is_empty() {
            bail!(
                "{} of {} cases could not run; {}",
                errors.len(),
                results.len(),
                errors.join("; ")
            );
        }
        let failed: Vec<&CaseResult> = results
            .iter()
            .filter(|r| r.rows.iter().any(|b| !b.pass))
            .collect();
        if !failed.is_empty() {
            let names: Vec<String> = failed
                .iter()
                .map(|r| {
                    let bounds: Vec<String> = r
                        .rows
                        .iter()
                        .filter(|b| !b.pass)
                        .map(|b| format!("{} (measured {})", b.bound, short(b.measured)))
                        .collect();
                    format!("{}: {}", r.name, bounds.join(", "))
                })
                .collect();
            return Err(ChecksFailed(format!(
                "{} of {} cases failed: {}; diff images in {}",
                failed.len(),
                results.len(),
                names.join("; "),
                self.out.join("failures").display()
            ))
            .into());
        }
        seethru::util::progress::summary(format!(
            "{} cases passed, {} bounds; outputs in {}",
            results.len(),
            results.iter().map(|r| r.rows.len()).sum::<usize>(),
            self.out.display()
        ));
        Ok(())
    }

    fn run_case(
        &self,
        case: &Case,
        blessed: &mut Vec<String>,
        updates: &mut Vec<(std::ops::Range<usize>, String)>,
        result: &mut CaseResult,
    ) -> Result<()> {
        let dir = self.out.join(&case.name);
        let cli = parse_case(case_args(case.command, &case.scene, &dir, &case.options))
            .map_err(|e| anyhow::anyhow!(e))?;
        let quiet = seethru::util::progress::is_quiet();
        seethru::util::progress::set_quiet(true);
        let ran = cli.command.run();
        seethru::util::progress::set_quiet(quiet);
        ran?;
        let (kind, metrics) = read_results(&dir)?;
        let golden = match &case.golden {
            Some(golden) => {
                let actual = dir.join("seethru.png");
                if self.bless {
                    bless_golden(&actual, golden, blessed)?;
                }
                Some(self.against_golden(case, &dir, &actual, golden)?)
            }
            None => None,
        };
        for bound in &case.bounds {
            let measured = match GOLDEN_METRICS.iter().find(|g| g.0 == bound.metric) {
                Some((_, metric)) => golden
                    .as_ref()
                    .and_then(|g| g.metric(metric))
                    .unwrap_or(f64::NAN),
                None => kind
                    .headline(&bound.metric)
                    .map_or(f64::NAN, |h| value_of(&metrics, h)),
            };
            let mut bound = bound.clone();
            if self.bless
                && matches!(bound.relation, Relation::Recorded { .. })
                && measured.is_finite()
            {
                let text = bound.text_with(measured);
                if text != bound.text()
                    && let Some(span) = bound.span.clone()
                {
                    blessed.push(format!(
                        "{}:{}: {text}",
                        self.expectations.display(),
                        bound.line.unwrap_or(0)
                    ));
                    updates.push((span, text));
                }
                bound.value = measured;
                bound.written = bound.text_with(measured);
            }
            result.rows.push(Row {
                bound: bound.text(),
                measured,
                pass: bound.holds(measured),
            });
        }
        if result.rows.iter().any(|r| !r.pass) {
            result.evidence.push(dir.join("misregistration.png"));
            if let (Some(golden), Some(diff)) = (&case.golden, &golden) {
                let failures = self.out.join("failures").join(&case.name);
                let copy = |from: &Path, name: &str| -> Result<PathBuf> {
                    let bytes = std::fs::read(from)
                        .with_context(|| format!("cannot read {}", from.display()))?;
                    let to = failures.join(name);
                    write_atomically(&to, |file| Ok(std::io::Write::write_all(file, &bytes)?))?;
                    Ok(to)
                };
                result.evidence.push(copy(golden, "expected.png")?);
                result
                    .evidence
                    .push(copy(&dir.join("seethru.png"), "actual.png")?);
                if let Some(flip) = &diff.flip {
                    let (w, h) = image::image_dimensions(golden)?;
                    let (cw, ch, rgb) = flip_heatmap(flip, w, h)?;
                    let to = failures.join("flip.png");
                    write_png(&to, cw, ch, rgb)?;
                    result.evidence.push(to);
                }
            }
        }
        Ok(())
    }

    /// The run's seethru.png against the golden image: the colour layer's diff.
    fn against_golden(
        &self,
        case: &Case,
        dir: &Path,
        actual: &Path,
        golden: &Path,
    ) -> Result<LayerDiff> {
        if !golden.is_file() {
            bail!(
                "the golden {} does not exist; make it with `seethru check {} --bless --case {}` and commit it",
                golden.display(),
                self.expectations.display(),
                case.name
            );
        }
        let (expected, actual) = (read_picture(golden)?, read_picture(actual)?);
        let pairs = paired_layers(&expected, &actual, &[])?;
        let (a, b) = pairs[0];
        diff_layer(
            a,
            b,
            expected.width,
            expected.height,
            pixels_per_degree(dir, "seethru"),
        )
    }
}

/// Writes the run's image as the golden, when it differs from it (or there is none).
fn bless_golden(actual: &Path, golden: &Path, blessed: &mut Vec<String>) -> Result<()> {
    let bytes =
        std::fs::read(actual).with_context(|| format!("cannot read {}", actual.display()))?;
    if std::fs::read(golden).ok().as_deref() != Some(bytes.as_slice()) {
        write_atomically(golden, |file| Ok(std::io::Write::write_all(file, &bytes)?))?;
        blessed.push(golden.display().to_string());
    }
    Ok(())
}

/// The PASS/FAIL table: a row per bound of every case.
fn table(results: &[CaseResult]) -> String {
    let width = results
        .iter()
        .map(|r| r.name.len())
        .max()
        .unwrap_or(4)
        .max(4);
    let bound_width = results
        .iter()
        .flat_map(|r| r.rows.iter().map(|b| b.bound.len()))
        .max()
        .unwrap_or(5)
        .max(5);
    let mut out = format!(
        "{:<width$}  {:<bound_width$}  {:>12}  result\n",
        "case", "bound", "measured"
    );
    for r in results {
        if let Some(e) = &r.error {
            out.push_str(&format!("{:<width$}  ERROR: {e}\n", r.name));
            continue;
        }
        for b in &r.rows {
            out.push_str(&format!(
                "{:<width$}  {:<bound_width$}  {:>12}  {}\n",
                r.name,
                b.bound,
                short(b.measured),
                if b.pass { "PASS" } else { "FAIL" }
            ));
        }
    }
    out
}

fn junit_cases(results: &[CaseResult], suite: &str) -> Vec<TestCase> {
    results
        .iter()
        .map(|r| {
            let output = table(std::slice::from_ref(r));
            let failed: Vec<String> = r
                .rows
                .iter()
                .filter(|b| !b.pass)
                .map(|b| format!("{}: measured {}", b.bound, short(b.measured)))
                .collect();
            let outcome = match (&r.error, failed.is_empty()) {
                (Some(e), _) => Outcome::Error { message: e.clone() },
                (None, true) => Outcome::Passed,
                (None, false) => Outcome::Failed {
                    message: failed.join("; "),
                    details: format!(
                        "{}\nsee: {}",
                        failed.join("\n"),
                        r.evidence
                            .iter()
                            .map(|p| p.display().to_string())
                            .collect::<Vec<_>>()
                            .join(", ")
                    ),
                },
            };
            TestCase {
                name: r.name.clone(),
                classname: format!("seethru.check.{}", suite_class(suite)),
                seconds: r.seconds,
                outcome,
                output,
            }
        })
        .collect()
}

/// The suite's file stem as a class name (`ci/expectations.toml` → `expectations`).
fn suite_class(suite: &str) -> String {
    Path::new(suite)
        .file_stem()
        .map_or("expectations".into(), |s| s.to_string_lossy().to_string())
}
