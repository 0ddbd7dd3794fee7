//! Reading back the CSV of an interrupted sweep: which rows are finished and can be kept.

use std::collections::HashMap;
use std::path::Path;

use anyhow::{Result, bail};

/// The rows of an earlier run of the same sweep (`text`, the file `csv`) that can be kept: the
/// header must be `header` exactly; a row is kept when its index names a configuration of
/// `configs` with the same parameter values and it has every column, each metric a number
/// (`NaN` included). Other rows are dropped, to be computed again. A row that is not even
/// an index, or an index given twice, is an error naming the line: the file is not what this
/// sweep wrote.
pub fn finished_rows(
    text: &str,
    csv: &Path,
    header: &str,
    configs: &[Vec<(String, String)>],
) -> Result<Vec<(usize, String)>> {
    let mut lines = text.lines().enumerate();
    let first = lines.next().map(|(_, l)| l);
    if first != Some(header) {
        bail!(
            "{} exists with other columns; remove it or choose another --out",
            csv.display()
        );
    }
    let columns = header.split(',').count();
    let mut rows = Vec::new();
    let mut line_of_index: HashMap<usize, usize> = HashMap::new();
    for (number, line) in lines {
        let number = number + 1;
        if line.is_empty() {
            continue;
        }
        let fields: Vec<&str> = line.split(',').collect();
        let Ok(index) = fields[0].parse::<usize>() else {
            let start: String = fields[0].chars().take(40).collect();
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
            rows.push((index, line.to_string()));
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
}
