//! An expectation file (`seethru check`) → its cases: no panic; every kept bound reads back
//! from its own text and from its span in the file; an error is one line.
#![no_main]

use std::path::Path;

use libfuzzer_sys::fuzz_target;
use seethru::measure::expectations::{expectations_from_source, parse_bound, rewritten};
use seethru::scene::source::SourceFile;

fuzz_target!(|data: &[u8]| {
    let Ok(text) = std::str::from_utf8(data) else {
        return;
    };
    let file = SourceFile::from_text(Path::new("ci/expectations.toml"), text.to_string());
    // The command line's own check of a case's options lives in the binary: here any option
    // list is taken, except one that names a flag `--refused`.
    let options = |_: _, o: &[String]| o.iter().any(|o| o == "--refused").then(|| "no".into());
    match expectations_from_source(&file, &options) {
        Ok(e) => {
            assert!(!e.cases.is_empty());
            let mut updates = Vec::new();
            for case in &e.cases {
                assert!(!case.bounds.is_empty());
                for bound in &case.bounds {
                    let again = parse_bound(&bound.written, case.command).expect(&bound.written);
                    assert_eq!(again.relation, bound.relation);
                    assert!(again.value == bound.value, "{}", bound.written);
                    if let Some(span) = &bound.span {
                        updates.push((span.clone(), bound.written.clone()));
                    }
                }
            }
            // Rewriting every bound with its own canonical text keeps the file readable.
            let text = rewritten(&e.text, updates);
            let again = SourceFile::from_text(Path::new("ci/expectations.toml"), text);
            let reread = expectations_from_source(&again, &options).expect("rewritten file");
            assert_eq!(reread.cases.len(), e.cases.len());
        }
        Err(e) => {
            let shown = e.to_string();
            assert!(
                shown.starts_with("ci/expectations.toml") && !shown.contains('\n'),
                "{shown}"
            );
        }
    }
});
