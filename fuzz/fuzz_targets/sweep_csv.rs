//! A sweep CSV to resume → the rows kept: no panic; kept rows are rows of this sweep.
#![no_main]

use std::path::Path;

use libfuzzer_sys::fuzz_target;
use seethru::measure::sweep_csv::finished_rows;

const HEADER: &str = "index,theta_f,d2,misregistration_mean_arcmin";

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
    match finished_rows(text, Path::new("sweep.csv"), HEADER, &configs) {
        Ok(rows) => {
            let mut seen = std::collections::HashSet::new();
            for (index, line) in rows {
                assert!(index < configs.len() && seen.insert(index), "{line}");
                assert_eq!(line.split(',').count(), 4, "{line}");
            }
        }
        Err(e) => assert!(!format!("{e:#}").contains('\n'), "{e:#}"),
    }
});
