//! The sweep's CSV files, read and written with the `csv` crate: one record per
//! configuration, and reading back an interrupted sweep to see which rows can be kept.
//!
//! Columns: `index`, one per swept parameter, the metrics ([`METRIC_COLUMNS`]), then
//! `configurations` (the size of the grid the row belongs to) and the settings every row was
//! computed with ([`SETTING_COLUMNS`]: the options that change results, the scene's
//! fingerprint and seethru's version), the same on every row. Every cell has its admissible
//! values; a file to resume or merge with a cell outside them is refused, naming the line.

use std::collections::HashMap;
use std::path::Path;

use anyhow::{Result, bail};

use crate::measure::sweep_grid::MAX_CONFIGURATIONS;
use crate::util::number::short;

/// Largest sweep CSV read back (to resume or merge): a million rows fit.
pub const MAX_SWEEP_CSV_BYTES: u64 = 1 << 30;

/// `fields` as one CSV line without its line end, quoted only where CSV needs it (a field
/// with a comma, a quote or a line break), so that plain numbers read as they are written.
pub fn encode(fields: &[String]) -> String {
    let mut writer = csv::WriterBuilder::new()
        .terminator(csv::Terminator::Any(b'\n'))
        .from_writer(Vec::new());
    // Writing into memory cannot fail, and `into_inner` only flushes into the vector.
    let bytes = writer
        .write_record(fields)
        .ok()
        .and_then(|()| writer.into_inner().ok())
        .unwrap_or_default();
    let line = String::from_utf8(bytes).unwrap_or_default();
    line.trim_end_matches('\n').to_string()
}

/// The fields of one line that [`encode`] wrote.
pub fn decode(line: &str) -> Vec<String> {
    csv::ReaderBuilder::new()
        .has_headers(false)
        .from_reader(line.as_bytes())
        .records()
        .next()
        .and_then(|r| r.ok())
        .map(|r| r.iter().map(str::to_string).collect())
        .unwrap_or_default()
}

/// The records of CSV text `text` (the file `path`), each with its line number (1-based);
/// empty lines are skipped. A record the reader cannot take is an error naming the line.
pub fn records(text: &str, path: &Path) -> Result<Vec<(usize, Vec<String>)>> {
    let mut reader = csv::ReaderBuilder::new()
        .has_headers(false)
        .flexible(true)
        .from_reader(text.as_bytes());
    // The reader's own line count leaves out the empty lines it skips: count from byte
    // offsets instead, onwards from the previous record (records come in order).
    let (mut counted_to, mut line) = (0usize, 1usize);
    let mut line_at = |byte: u64| {
        // A record's position can be that of the empty lines before it: step over them.
        let mut byte = (byte as usize).clamp(counted_to, text.len());
        while matches!(text.as_bytes().get(byte), Some(b'\n' | b'\r')) {
            byte += 1;
        }
        line += text.as_bytes()[counted_to..byte]
            .iter()
            .filter(|&&b| b == b'\n')
            .count();
        counted_to = byte;
        line
    };
    let mut out = Vec::new();
    for record in reader.records() {
        match record {
            Ok(record) => {
                let line = record.position().map_or(0, |p| line_at(p.byte()));
                out.push((line, record.iter().map(str::to_string).collect()));
            }
            Err(e) => {
                let line = e.position().map_or(0, |p| line_at(p.byte()));
                bail!("{}:{line}: not CSV: {e}", path.display());
            }
        }
    }
    Ok(out)
}

/// Largest angle between two directions, arc-minutes (180°).
const MAX_ARCMIN: f64 = 10_800.0;

/// The metric columns of a row and their admissible values: NaN (the metric is undefined:
/// no pixel to take it over) or a number in `[low, high]` (to rounding, 1e-9 relative).
/// `coverage` (the fraction of display pixels that show the scene, over which the
/// misregistration means are taken) comes last, so that the columns before it keep their
/// places. PSNR is of 8-bit colours: at most 135 dB even for the largest image, or +∞ where
/// the two images are identical over the display ([`UNBOUNDED_ABOVE`]).
pub const METRIC_COLUMNS: [(&str, f64, f64); 12] = [
    ("misregistration_mean_arcmin", 0.0, MAX_ARCMIN),
    ("misregistration_p95_arcmin", 0.0, MAX_ARCMIN),
    ("misregistration_max_arcmin", 0.0, MAX_ARCMIN),
    ("border_mean_arcmin", 0.0, MAX_ARCMIN),
    ("border_p95_arcmin", 0.0, MAX_ARCMIN),
    ("psnr_db", 0.0, 200.0),
    ("ssim", -1.0, 1.0),
    ("missing_fraction", 0.0, 1.0),
    ("display_outside_frontal_fraction", 0.0, 1.0),
    ("R1", -f64::MAX, f64::MAX),
    ("R2", -f64::MAX, f64::MAX),
    ("coverage", 0.0, 1.0),
];

/// The metric columns that may also be +∞: a PSNR of identical images (`sweep` writes
/// `inf`; its own rows must resume and merge).
pub const UNBOUNDED_ABOVE: [&str; 1] = ["psnr_db"];

/// The column after the metrics: how many configurations the row's grid has (so that
/// `sweep-merge` knows when a part is missing).
pub const GRID_COLUMN: &str = "configurations";

/// The columns after it: what a row's results depend on besides its parameter values, with
/// how a message names each. Resuming or merging refuses rows that differ in any.
pub const SETTING_COLUMNS: [(&str, &str); 6] = [
    ("width", "option `width`"),
    ("spp", "option `spp`"),
    ("head", "option `head`"),
    ("band", "option `band`"),
    ("scene_hash", "scene_hash"),
    ("seethru_version", "seethru"),
];

/// The header of a sweep of `params`.
pub fn header(params: &[String]) -> Vec<String> {
    std::iter::once("index")
        .chain(params.iter().map(String::as_str))
        .chain(METRIC_COLUMNS.iter().map(|c| c.0))
        .chain(std::iter::once(GRID_COLUMN))
        .chain(SETTING_COLUMNS.iter().map(|c| c.0))
        .map(str::to_string)
        .collect()
}

/// The parameter names of a sweep CSV's header, or `None` if it is not one.
pub fn params_of(header: &[String]) -> Option<Vec<String>> {
    let tail = METRIC_COLUMNS.len() + 1 + SETTING_COLUMNS.len();
    if header.len() < 2 + tail || header[0] != "index" {
        return None;
    }
    let params = header[1..header.len() - tail].to_vec();
    (self::header(&params) == header).then_some(params)
}

/// A cell for a message: a number short, text escaped (one line) and cut to 40 characters.
fn cell_text(cell: &str) -> String {
    match cell.trim().parse::<f64>() {
        Ok(x) => short(x),
        Err(_) => format!("`{}`", text_shown(cell)),
    }
}

/// Text from the file for a message, as written but escaped (a quoted cell may hold line
/// breaks and control characters) and cut to 40 characters.
fn text_shown(cell: &str) -> String {
    let start: String = cell.chars().take(40).collect();
    let more = if cell.chars().count() > 40 { "…" } else { "" };
    format!("{}{more}", start.escape_debug())
}

/// `columns` up to and including the `upto`-th, joined, `…` for the rest, and their count.
pub fn columns_text(columns: &[String], upto: usize) -> String {
    let shown: Vec<String> = columns
        .iter()
        .take(upto + 1)
        .map(|c| {
            let c: String = c.chars().take(40).collect();
            c.escape_debug().to_string()
        })
        .collect();
    let more = if columns.len() > upto + 1 { ",…" } else { "" };
    format!("`{}{more}` ({})", shown.join(","), columns.len())
}

/// Says how the header `found` differs from the header `expected`, short: both up to the
/// first column that differs.
pub fn header_difference(found: &[String], expected: &[String]) -> String {
    let at = (0..found.len().max(expected.len()))
        .find(|&i| found.get(i) != expected.get(i))
        .unwrap_or(0);
    // Names as written in the file may hold quotes and line breaks: escaped, cut.
    let name = |c: &String| -> String {
        let start: String = c.chars().take(40).collect();
        start.escape_debug().to_string()
    };
    let which = match (found.get(at).map(name), expected.get(at).map(name)) {
        (Some(f), Some(e)) => format!("column {} is `{f}` where `{e}` belongs", at + 1),
        (None, Some(e)) => format!("column {} (`{e}`) is missing", at + 1),
        (Some(f), None) => format!("column {} (`{f}`) is extra", at + 1),
        (None, None) => String::new(),
    };
    format!(
        "it has the columns {}, expected {}: {which}",
        columns_text(found, at),
        columns_text(expected, at)
    )
}

/// Checks the cells of one row that do not depend on the sweep (`fields`, on line `number`
/// of `path`, in a file whose header has `params` parameter columns): as many cells as the
/// header, an index below the row's `configurations` (a positive integer up to
/// [`MAX_CONFIGURATIONS`]) and every metric admissible. Returns the index. `hint` ends each
/// message (what to do about it).
pub fn check_row(
    fields: &[String],
    params: usize,
    path: &Path,
    number: usize,
    hint: &str,
) -> Result<usize> {
    let at = format!("{}:{number}", path.display());
    let first = fields.first().map_or("", String::as_str);
    let Ok(index) = first.parse::<usize>() else {
        bail!(
            "{at}: a row starts with {}, not a configuration index; {hint}",
            cell_text(first)
        );
    };
    let columns = 1 + params + METRIC_COLUMNS.len() + 1 + SETTING_COLUMNS.len();
    if fields.len() != columns {
        bail!(
            "{at}: the row has {} cells, the header {columns}; {hint}",
            fields.len()
        );
    }
    for (cell, (name, low, high)) in fields[1 + params..].iter().zip(METRIC_COLUMNS) {
        let tolerance = 1e-9 * high.abs().max(1.0);
        let unbounded = UNBOUNDED_ABOVE.contains(&name);
        let admissible = match cell.parse::<f64>() {
            Ok(x) => {
                x.is_nan()
                    || (unbounded && x == f64::INFINITY)
                    || (x.is_finite() && x >= low - tolerance && x <= high + tolerance)
            }
            Err(_) => false,
        };
        if !admissible {
            let range = if high == f64::MAX {
                "a finite number".to_string()
            } else if unbounded {
                format!(
                    "a number in [{}, {}], or inf where the images are identical",
                    short(low),
                    short(high)
                )
            } else {
                format!("a number in [{}, {}]", short(low), short(high))
            };
            bail!(
                "{at}: {name} = {} is not admissible (NaN, for undefined, or {range}); {hint}",
                cell_text(cell)
            );
        }
    }
    let grid_cell = &fields[1 + params + METRIC_COLUMNS.len()];
    match grid_cell.parse::<usize>() {
        Ok(n) if (1..=MAX_CONFIGURATIONS).contains(&n) => {
            if index >= n {
                bail!(
                    "{at}: index {index} is outside its grid's [0, {}] ({GRID_COLUMN} = {n}); {hint}",
                    n - 1
                );
            }
        }
        _ => bail!(
            "{at}: {GRID_COLUMN} = {} is not admissible (an integer in [1, {MAX_CONFIGURATIONS}]); {hint}",
            cell_text(grid_cell)
        ),
    }
    Ok(index)
}

/// The settings cells of a checked row.
pub fn settings_of(fields: &[String]) -> &[String] {
    &fields[fields.len() - SETTING_COLUMNS.len()..]
}

/// The first setting in which `a` and `b` differ: its name for messages and both values as a
/// message shows them (escaped and cut: a file's cell may hold line breaks).
pub fn first_difference(a: &[String], b: &[String]) -> Option<(&'static str, String, String)> {
    a.iter()
        .zip(b)
        .zip(SETTING_COLUMNS)
        .find(|((x, y), _)| x != y)
        .map(|((x, y), (_, shown))| (shown, text_shown(x), text_shown(y)))
}

/// The rows of an earlier run of the same sweep (`text`, the file `csv`) to keep. The header
/// must be this sweep's (`params`); every row must pass [`check_row`], have been computed
/// with this sweep's `settings` (the values of [`SETTING_COLUMNS`]), and name by its
/// parameter values a configuration of `configs`, each once. A row whose values are in the
/// grid at another place (the grid grew) is kept with its index and `configurations`
/// rewritten. Anything else is an error naming the file (and line): nothing is dropped
/// silently, nothing computed otherwise is mixed in. Rows come back as [`encode`] writes
/// them.
pub fn finished_rows(
    text: &str,
    csv: &Path,
    params: &[String],
    configs: &[Vec<(String, String)>],
    settings: &[String],
) -> Result<Vec<(usize, String)>> {
    let expected = header(params);
    let all = records(text, csv)?;
    let mut all = all.into_iter();
    match all.next() {
        Some((_, first)) if first == expected => {}
        Some((_, first)) => bail!(
            "{} exists with other columns: {}; remove it or choose another option `out`",
            csv.display(),
            header_difference(&first, &expected)
        ),
        None => bail!(
            "{} exists but is empty (no header; expected {}); remove it or choose another option `out`",
            csv.display(),
            columns_text(&expected, params.len())
        ),
    }
    let hint = "delete the row to compute it again, or choose another option `out`";
    let place: HashMap<&[(String, String)], usize> = configs
        .iter()
        .enumerate()
        .map(|(i, c)| (c.as_slice(), i))
        .collect();
    let mut rows = Vec::new();
    let mut seen = SeenRows::default();
    let (mut outside, mut first_outside, mut count) = (0usize, None, 0usize);
    for (number, mut fields) in all {
        let index = check_row(&fields, params.len(), csv, number, hint)?;
        count += 1;
        seen.note(&fields, params, index, csv, number)?;
        if let Some((shown, theirs, ours)) = first_difference(settings_of(&fields), settings) {
            bail!(
                "{}:{number}: computed with {shown} {theirs}, this sweep has {shown} {ours}{}: resuming would mix the two; resume with the same settings, or choose another option `out`",
                csv.display(),
                if shown == "scene_hash" {
                    " (another scene, or the scene file, a mesh or a texture it reads changed)"
                } else {
                    ""
                }
            );
        }
        let values: Vec<(String, String)> = params
            .iter()
            .cloned()
            .zip(fields[1..=params.len()].iter().cloned())
            .collect();
        let Some(&at) = place.get(values.as_slice()) else {
            outside += 1;
            first_outside.get_or_insert((number, values));
            continue;
        };
        fields[0] = at.to_string();
        fields[1 + params.len() + METRIC_COLUMNS.len()] = configs.len().to_string();
        rows.push((at, encode(&fields)));
    }
    if let Some((line, values)) = first_outside {
        bail!(
            "{}: {outside} of its {count} rows are outside this sweep's grid (the first, line {line}: {}); resuming would drop them: give option `param` values that include theirs, or choose another option `out`",
            csv.display(),
            config_text(&values)
        );
    }
    Ok(rows)
}

/// The rows of one sweep CSV read so far: a configuration given twice in one file, by its
/// index or by its parameter values, is an error naming both lines. The one check of a
/// resumed CSV and of each part `sweep-merge` joins.
#[derive(Default)]
pub struct SeenRows {
    line_of_index: HashMap<usize, usize>,
    line_of_values: HashMap<Vec<String>, usize>,
}

impl SeenRows {
    /// Notes the checked row `fields` (of the parameters `names`, index `index`) on line
    /// `number` of `csv`.
    pub fn note(
        &mut self,
        fields: &[String],
        names: &[String],
        index: usize,
        csv: &Path,
        number: usize,
    ) -> Result<()> {
        if let Some(earlier) = self.line_of_index.insert(index, number) {
            bail!(
                "{}:{number}: configuration {index} appears twice (also on line {earlier}); remove the file or choose another option `out`",
                csv.display()
            );
        }
        let values = fields[1..=names.len()].to_vec();
        if let Some(earlier) = self.line_of_values.insert(values, number) {
            bail!(
                "{}:{number}: the configuration {} appears twice (also on line {earlier}); remove the file or choose another option `out`",
                csv.display(),
                config_text(
                    &names
                        .iter()
                        .cloned()
                        .zip(fields[1..].iter().cloned())
                        .collect::<Vec<_>>()
                )
            );
        }
        Ok(())
    }
}

/// A configuration for a message: `theta_f=30, d2=inf`.
pub fn config_text(config: &[(String, String)]) -> String {
    config
        .iter()
        .map(|(n, v)| format!("{n}={}", cell_text(v).trim_matches('`')))
        .collect::<Vec<_>>()
        .join(", ")
}

#[cfg(test)]
mod tests {
    use super::*;

    fn configs() -> Vec<Vec<(String, String)>> {
        ["20", "40"]
            .iter()
            .map(|v| vec![("theta_f".to_string(), v.to_string())])
            .collect()
    }

    fn params() -> Vec<String> {
        vec!["theta_f".to_string()]
    }

    fn settings() -> Vec<String> {
        ["32", "1", "oracle", "5", "0123456789abcdef", "0.1.0"]
            .iter()
            .map(|s| s.to_string())
            .collect()
    }

    /// A row as a sweep writes it: index, θ_F, the metrics (`cells` first, then 0.5), the
    /// grid's size and the settings.
    fn row(index: usize, theta: &str, cells: &[&str], configurations: usize) -> String {
        let metrics = (0..METRIC_COLUMNS.len()).map(|i| cells.get(i).copied().unwrap_or("0.5"));
        let fields: Vec<String> = [index.to_string(), theta.to_string()]
            .into_iter()
            .chain(metrics.map(str::to_string))
            .chain([configurations.to_string()])
            .chain(settings())
            .collect();
        encode(&fields)
    }

    fn file(rows: &[String]) -> String {
        let mut text = encode(&header(&params())) + "\n";
        for r in rows {
            text += &format!("{r}\n");
        }
        text
    }

    fn resume(text: &str) -> Result<Vec<(usize, String)>> {
        finished_rows(text, Path::new("s.csv"), &params(), &configs(), &settings())
    }

    #[test]
    fn rows_of_this_sweep_are_kept_and_moved_to_their_place_in_a_grown_grid() {
        let text = file(&[row(0, "20", &["1.5"], 2), row(1, "40", &["NaN"], 2)]);
        let rows = resume(&text).unwrap();
        assert_eq!(
            rows,
            vec![
                (0, row(0, "20", &["1.5"], 2)),
                (1, row(1, "40", &["NaN"], 2))
            ]
        );
        // The same row from a grid of 3 where θ_F = 40 was index 2: now index 1 of 2.
        let rows = resume(&file(&[row(2, "40", &[], 3)])).unwrap();
        assert_eq!(rows, vec![(1, row(1, "40", &[], 2))]);
    }

    #[test]
    fn a_psnr_of_identical_images_is_a_row_of_the_sweep() {
        // `sweep` writes a PSNR of +∞ where the display shows exactly the truth; its own
        // row must resume (and merge), as NaN and finite values do; −∞ must not.
        let fields = |psnr: &str| -> Vec<String> {
            let mut f = vec!["0".to_string(), "20".to_string()];
            for (column, _, _) in METRIC_COLUMNS {
                f.push(if column == "psnr_db" {
                    psnr.into()
                } else {
                    "0.5".into()
                });
            }
            f.push("2".into());
            f.extend(settings());
            f
        };
        let text = |psnr: &str| {
            format!(
                "{}\n{}\n",
                encode(&header(&params())),
                encode(&fields(psnr))
            )
        };
        assert_eq!(resume(&text("inf")).unwrap().len(), 1);
        assert!(resume(&text("-inf")).is_err());
    }

    #[test]
    fn every_cell_outside_its_column_is_refused_naming_the_line_column_and_range() {
        for (cells, words) in [
            (
                vec!["-1"],
                "misregistration_mean_arcmin = -1 is not admissible (NaN, for undefined, or a number in [0, 10800])",
            ),
            (vec!["inf"], "misregistration_mean_arcmin = inf"),
            (
                vec!["0.5"; 5].into_iter().chain(["1e300"]).collect(),
                "psnr_db = 1e300",
            ),
            (
                vec!["0.5"; 6].into_iter().chain(["1.5"]).collect(),
                "ssim = 1.5",
            ),
            (
                vec!["0.5"; 7].into_iter().chain(["abc"]).collect(),
                "missing_fraction = `abc`",
            ),
            (
                vec!["0.5"; 9].into_iter().chain(["inf"]).collect(),
                "R1 = inf is not admissible (NaN, for undefined, or a finite number)",
            ),
            (
                vec!["0.5"; 11].into_iter().chain(["-1"]).collect(),
                "coverage = -1",
            ),
            (
                vec!["0.5"; 11].into_iter().chain(["1e300"]).collect(),
                "coverage = 1e300",
            ),
            (
                vec!["0.5"; 11].into_iter().chain([""]).collect(),
                "coverage = ``",
            ),
        ] {
            let text = file(&[row(0, "20", &[], 2), row(1, "40", &cells, 2)]);
            let err = resume(&text).unwrap_err().to_string();
            assert!(err.starts_with("s.csv:3: ") && err.contains(words), "{err}");
            assert!(err.contains("delete the row"), "{err}");
        }
        // Rounding past a bound, either way, is not a bad cell; NaN is the undefined metric a
        // sweep writes.
        let rows = resume(&file(&[row(
            0,
            "20",
            &["NaN", "10800.000000000002", "-1e-9"],
            2,
        )]))
        .unwrap();
        assert_eq!(rows.len(), 1);
        let err = resume(&file(&[row(0, "20", &[], 0)]))
            .unwrap_err()
            .to_string();
        assert!(
            err.contains("configurations = 0 is not admissible"),
            "{err}"
        );
        let short_row = file(&["0,20,1".to_string()]);
        let err = resume(&short_row).unwrap_err().to_string();
        assert!(
            err.contains("s.csv:2: the row has 3 cells, the header 21"),
            "{err}"
        );
    }

    #[test]
    fn other_settings_and_rows_outside_the_grid_are_refused() {
        let mut other = row(1, "40", &[], 2);
        other = other.replace(",32,1,oracle,", ",64,1,oracle,");
        let err = resume(&file(&[row(0, "20", &[], 2), other]))
            .unwrap_err()
            .to_string();
        assert!(
            err.starts_with(
                "s.csv:3: computed with option `width` 64, this sweep has option `width` 32"
            ),
            "{err}"
        );
        let other = row(0, "20", &[], 2).replace("0123456789abcdef", "fedcba9876543210");
        let err = resume(&file(&[other])).unwrap_err().to_string();
        assert!(
            err.contains("computed with scene_hash fedcba9876543210, this sweep has scene_hash 0123456789abcdef (another scene"),
            "{err}"
        );
        let text = file(&[
            row(0, "20", &[], 3),
            row(1, "30", &[], 3),
            row(2, "40", &[], 3),
        ]);
        let err = resume(&text).unwrap_err().to_string();
        assert!(
            err.contains("s.csv: 1 of its 3 rows are outside this sweep's grid (the first, line 3: theta_f=30)"),
            "{err}"
        );
    }

    #[test]
    fn foreign_files_are_errors_naming_the_line() {
        for (text, words) in [
            ("index,x\n".to_string(), "exists with other columns: it has the columns `index,x` (2), expected `index,theta_f,…` (21): column 2 is `x` where `theta_f` belongs".to_string()),
            (String::new(), "exists but is empty (no header; expected `index,theta_f,…` (21))".to_string()),
            (file(&[row(0, "20", &[], 2), "x,20,1".to_string()]), "s.csv:3: a row starts with `x`".to_string()),
            (file(&[row(0, "20", &[], 2), row(0, "40", &[], 2)]), "s.csv:3: configuration 0 appears twice (also on line 2)".to_string()),
            (file(&[row(0, "20", &[], 2), row(1, "20", &[], 2)]), "s.csv:3: the configuration theta_f=20 appears twice (also on line 2)".to_string()),
        ] {
            let err = resume(&text).unwrap_err().to_string();
            assert!(err.contains(&words), "{err}\nlacks {words}");
            assert!(!err.contains('\n'));
        }
    }

    /// A sweep's header gives back its parameters, however many; a header with a column
    /// missing, added, renamed or moved, or without `index` first, is not a sweep's.
    #[test]
    fn a_sweep_header_gives_back_its_parameters_and_nothing_else_does() {
        let names = |n: &[&str]| n.iter().map(|s| s.to_string()).collect::<Vec<_>>();
        for params in [
            names(&["theta_f"]),
            names(&["d2", "eye_x", "head_bias_x_cm"]),
        ] {
            let full = header(&params);
            assert_eq!(params_of(&full), Some(params.clone()));
            let mut extra = full.clone();
            extra.push("note".into());
            let mut swapped = full.clone();
            swapped.swap(params.len() + 1, params.len() + 2);
            let mut renamed = full.clone();
            renamed[0] = "row".into();
            for other in [
                full[1..].to_vec(),
                full[..full.len() - 1].to_vec(),
                extra,
                swapped,
                renamed,
            ] {
                assert_eq!(params_of(&other), None, "{other:?}");
            }
        }
        // No parameter column: the metrics and settings alone are not a sweep.
        assert_eq!(params_of(&header(&[])), None);
        assert_eq!(params_of(&[]), None);
    }

    /// A cell in a message: 40 characters as written, then `…` when there are more.
    #[test]
    fn a_long_cell_is_cut_at_40_characters_with_an_ellipsis() {
        let forty = "é".repeat(40);
        assert_eq!(text_shown(&forty), forty);
        assert_eq!(text_shown(&format!("{forty}x")), format!("{forty}…"));
        assert_eq!(text_shown("a\nb"), "a\\nb");
        assert_eq!(cell_text(" 2.50 "), "2.5");
    }

    #[test]
    fn fields_with_commas_and_quotes_survive_a_round_trip() {
        let fields: Vec<String> = ["3", "a,b", "say \"hi\"", "1.5"]
            .iter()
            .map(|s| s.to_string())
            .collect();
        let line = encode(&fields);
        assert_eq!(decode(&line), fields);
        assert_eq!(line, "3,\"a,b\",\"say \"\"hi\"\"\",1.5");
        let back = records(&format!("{line}\n\n{line}\n"), Path::new("s.csv")).unwrap();
        assert_eq!(back, vec![(1, fields.clone()), (3, fields)]);
    }
}
