//! The sweep's CSV files, read and written with the `csv` crate: one record per
//! configuration, and reading back an interrupted sweep to see which rows can be kept.

use std::collections::HashMap;
use std::path::Path;

use anyhow::{Result, bail};

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

/// The rows of an earlier run of the same sweep (`text`, the file `csv`) that can be kept: the
/// header must be `header` exactly; a row is kept when its index names a configuration of
/// `configs` with the same parameter values and it has every column, each metric a number
/// (`NaN` included). Other rows are dropped, to be computed again. A row that is not even
/// an index, or an index given twice, is an error naming the line: the file is not what this
/// sweep wrote. Rows come back as [`encode`] writes them.
pub fn finished_rows(
    text: &str,
    csv: &Path,
    header: &str,
    configs: &[Vec<(String, String)>],
) -> Result<Vec<(usize, String)>> {
    let other_columns = || {
        anyhow::anyhow!(
            "{} exists with other columns; remove it or choose another --out",
            csv.display()
        )
    };
    let all = records(text, csv).map_err(|_| other_columns())?;
    let mut all = all.into_iter();
    match all.next() {
        Some((_, first)) if encode(&first) == header => {}
        _ => return Err(other_columns()),
    }
    let columns = records(header, csv)?.first().map_or(0, |(_, h)| h.len());
    let mut rows = Vec::new();
    let mut line_of_index: HashMap<usize, usize> = HashMap::new();
    for (number, fields) in all {
        let first = fields.first().map_or("", String::as_str);
        let Ok(index) = first.parse::<usize>() else {
            // Escaped: a quoted field can hold line breaks, and an error is one line.
            let start: String = first
                .chars()
                .take(40)
                .collect::<String>()
                .escape_debug()
                .to_string();
            bail!(
                "{}:{number}: a row starts with `{start}`, not a configuration index; remove the file or choose another --out",
                csv.display()
            );
        };
        if let Some(earlier) = line_of_index.insert(index, number) {
            bail!(
                "{}:{number}: configuration {index} appears twice (also on line {earlier}); remove the file or choose another --out",
                csv.display()
            );
        }
        let Some(config) = configs.get(index) else {
            continue;
        };
        let same_values = fields.len() == columns
            && config
                .iter()
                .zip(&fields[1..])
                .all(|((_, value), field)| value == field);
        let metrics_are_numbers = fields
            .iter()
            .skip(1 + config.len())
            .all(|f| f.parse::<f64>().is_ok());
        if same_values && metrics_are_numbers {
            rows.push((index, encode(&fields)));
        }
    }
    Ok(rows)
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

    #[test]
    fn keeps_matching_rows_and_drops_the_rest() {
        let header = "index,theta_f,mean";
        let text = "index,theta_f,mean\n0,20,1.5\n1,45,2\n7,20,1\n\n";
        let rows = finished_rows(text, Path::new("s.csv"), header, &configs()).unwrap();
        assert_eq!(rows, vec![(0, "0,20,1.5".to_string())]);
        let text = "index,theta_f,mean\n0,20,NaN\n1,40,abc\n";
        let rows = finished_rows(text, Path::new("s.csv"), header, &configs()).unwrap();
        assert_eq!(rows.len(), 1, "a metric that is not a number is recomputed");
    }

    #[test]
    fn foreign_files_are_errors_naming_the_line() {
        let header = "index,theta_f,mean";
        for (text, words) in [
            ("index,x\n", "other columns"),
            ("", "other columns"),
            (
                "index,theta_f,mean\n0,20,1\nx,20,1\n",
                "s.csv:3: a row starts with `x`",
            ),
            (
                "index,theta_f,mean\n0,20,1\n0,20,1\n",
                "s.csv:3: configuration 0 appears twice (also on line 2)",
            ),
        ] {
            let err = finished_rows(text, Path::new("s.csv"), header, &configs())
                .unwrap_err()
                .to_string();
            assert!(err.contains(words), "{err}");
        }
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
