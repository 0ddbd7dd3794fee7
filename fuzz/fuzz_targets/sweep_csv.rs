//! A sweep CSV to resume → the rows kept: no panic; kept rows are rows of this sweep.
#![no_main]

use std::path::Path;

use libfuzzer_sys::fuzz_target;
use seethru::measure::sweep_csv::{METRIC_COLUMNS, SETTING_COLUMNS, finished_rows};

/// The settings the kept rows must have been computed with (sweep_csv::SETTING_COLUMNS).
fn settings() -> Vec<String> {
    ["32", "1", "oracle", "5", "0123456789abcdef", "0.1.0"]
        .iter()
        .map(|s| s.to_string())
        .collect()
}

fuzz_target!(|data: &[u8]| {
    let Ok(text) = std::str::from_utf8(data) else {
        return;
    };
    let configs: Vec<Vec<(String, String)>> = ["20", "40"]
        .iter()
        .flat_map(|t| {
            ["inf", "5"].iter().map(move |d| {
                vec![
                    ("theta_f".to_string(), t.to_string()),
                    ("d2".to_string(), d.to_string()),
                ]
            })
        })
        .collect();
    match finished_rows(
        text,
        Path::new("sweep.csv"),
        &["theta_f".into(), "d2".into()],
        &configs,
        &settings(),
    ) {
        Ok(rows) => {
            let mut seen = std::collections::HashSet::new();
            for (index, line) in rows {
                assert!(index < configs.len() && seen.insert(index), "{line}");
                let columns = 3 + METRIC_COLUMNS.len() + 1 + SETTING_COLUMNS.len();
                assert_eq!(line.split(',').count(), columns, "{line}");
            }
        }
        Err(e) => assert!(!format!("{e:#}").contains('\n'), "{e:#}"),
    }
});
