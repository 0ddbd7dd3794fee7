//! CSV files of numbers (a recorded head path, an object's placements): rows of a fixed
//! number of finite values, read with the `csv` crate; a first line of names is a header, `#`
//! starts a comment; errors name the file and the line.

use anyhow::{Result, bail};

/// Largest magnitude of a value.
const LIMIT: f64 = 1e6;

/// The rows of `text` (named `name` in errors), each with its line: `columns.len()` values a
/// row, `meaning` saying what they are (in the message of a row of another length), at most
/// `max_rows` rows.
pub fn number_rows<const N: usize>(
    text: &[u8],
    name: &str,
    columns: [&str; N],
    meaning: &str,
    max_rows: usize,
) -> Result<Vec<(u64, [f64; N])>> {
    let mut reader = csv::ReaderBuilder::new()
        .has_headers(false)
        .flexible(true)
        .trim(csv::Trim::All)
        .comment(Some(b'#'))
        .from_reader(text);
    let mut rows = Vec::new();
    for (i, record) in reader.records().enumerate() {
        let record = record.map_err(|e| {
            let line = e.position().map_or(i as u64 + 1, |p| p.line());
            anyhow::anyhow!("{name}:{line}: not CSV: {e}")
        })?;
        let line = record.position().map_or(i as u64 + 1, |p| p.line());
        if i == 0 && record.iter().all(|f| f.parse::<f64>().is_err()) {
            continue; // a header
        }
        if record.len() != N {
            bail!(
                "{name}:{line}: expected {N} values {} ({meaning}), got {}",
                columns.join(","),
                record.len()
            );
        }
        let mut values = [0.0; N];
        for (k, column) in columns.iter().enumerate() {
            let field = &record[k];
            values[k] = match field.parse::<f64>() {
                Ok(v) if v.is_finite() && v.abs() <= LIMIT => v,
                // A quoted field may hold line breaks and escapes: shown, not obeyed.
                _ => bail!(
                    "{name}:{line}: `{column}` must be a finite number in [-1000000, 1000000], got `{}`",
                    crate::util::message::printable(field)
                ),
            };
        }
        if rows.len() == max_rows {
            bail!("{name}:{line}: more than {max_rows} rows");
        }
        rows.push((line, values));
    }
    Ok(rows)
}
