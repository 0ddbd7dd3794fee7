//! Inputs the fuzzers of `fuzz/` found a failure with, replayed through the same reader and
//! held to the same rule: an error of one line, or rows that are rows of the sweep.

use std::path::Path;

use seethru::measure::sweep_csv::finished_rows;

const HEADER: &str = "index,theta_f,d2,misregistration_mean_arcmin";

/// The fuzz target's configurations: θ_F ∈ {20, 40} × d2 ∈ {inf, 5}.
fn configs() -> Vec<Vec<(String, String)>> {
    ["20", "40"]
        .iter()
        .flat_map(|t| {
            ["inf", "5"].iter().map(move |d| {
                vec![
                    ("theta_f".to_string(), t.to_string()),
                    ("d2".to_string(), d.to_string()),
                ]
            })
        })
        .collect()
}

#[test]
fn sweep_csv_inputs_found_by_fuzzing_give_one_line_errors() {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/fuzz/sweep_csv");
    let mut replayed = 0;
    for entry in std::fs::read_dir(&dir).unwrap().flatten() {
        let bytes = std::fs::read(entry.path()).unwrap();
        let Ok(text) = std::str::from_utf8(&bytes) else {
            continue;
        };
        replayed += 1;
        match finished_rows(text, Path::new("sweep.csv"), HEADER, &configs()) {
            Ok(rows) => assert!(rows.iter().all(|(i, _)| *i < 4), "{rows:?}"),
            // A quoted field may hold line breaks: the message must not.
            Err(e) => {
                let shown = format!("{e:#}");
                assert!(!shown.contains('\n'), "{}: {shown}", entry.path().display());
            }
        }
    }
    assert!(replayed > 0, "no inputs in {}", dir.display());
}
