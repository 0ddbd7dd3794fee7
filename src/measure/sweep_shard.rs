//! Sweeps beyond one machine: `--shard K/N` computes the configurations whose hash falls in
//! part K of N, and [`merge`] joins the parts' CSVs into the CSV one unsharded run writes.

use std::collections::BTreeMap;
use std::path::Path;

use anyhow::{Context, Result, bail};

use crate::io::atomic::write_text;
use crate::measure::sweep_csv::{
    GRID_COLUMN, MAX_SWEEP_CSV_BYTES, METRIC_COLUMNS, SeenRows, check_row, columns_text, encode,
    first_difference, header as sweep_header, header_difference, params_of, records,
};
use crate::measure::sweep_grid::Param;
use crate::util::hash::Fnv64;
use crate::util::input_file::read_input_text;

/// Part `index` (0-based, as `SLURM_ARRAY_TASK_ID` with `--array=0-(N-1)` and a Kubernetes
/// Indexed Job's `JOB_COMPLETION_INDEX` count) of `count` disjoint parts.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Shard {
    pub index: u32,
    pub count: u32,
}

/// Most parts a sweep can be cut into.
pub const MAX_SHARDS: u32 = 100_000;

impl std::str::FromStr for Shard {
    type Err = String;
    fn from_str(text: &str) -> Result<Self, String> {
        let parsed = text.split_once('/').and_then(|(k, n)| {
            Some((k.trim().parse::<u32>().ok()?, n.trim().parse::<u32>().ok()?))
        });
        match parsed {
            Some((index, count)) if (1..=MAX_SHARDS).contains(&count) && index < count => {
                Ok(Shard { index, count })
            }
            _ => Err(format!(
                "must be K/N with N in [1, {MAX_SHARDS}] and K in [0, N-1] (e.g. 0/3, 1/3, 2/3)"
            )),
        }
    }
}

impl Shard {
    /// Whether this part computes `config`. The assignment depends on the configuration's
    /// parameter names and values only (FNV-1a of `name=value;…`), not on its position in the
    /// grid or on the machine, so every part agrees on it.
    pub fn owns(&self, config: &[(String, String)]) -> bool {
        let mut hash = Fnv64::default();
        for (name, value) in config {
            hash.bytes(name.as_bytes())
                .bytes(b"=")
                .bytes(value.as_bytes())
                .bytes(b";");
        }
        let hash = hash.finish();
        hash % u64::from(self.count) == u64::from(self.index)
    }
}

/// What [`merge`] wrote ([`join`] would write).
pub struct Merged {
    pub rows: usize,
    pub params: Vec<Param>,
    pub body: Vec<(usize, String)>,
    /// The merged CSV, header first.
    pub text: String,
}

/// Joins the CSVs of a sharded sweep into `out`: one header (every part must have the same),
/// the rows in configuration order. Every row is checked as a resumed one is
/// ([`check_row`]) and must have the same `configurations` and settings as every other; a
/// configuration missing from every part, or given twice with different values, is an error
/// naming it. The grid's size is the `configurations` the rows record, so a part that never
/// ran is noticed.
pub fn merge(parts: &[&Path], out: &Path) -> Result<Merged> {
    let joined = join(parts)?;
    write_text(out, &joined.text)?;
    Ok(joined)
}

/// [`merge`] without writing: the merged CSV's text in [`Merged::text`].
pub fn join(parts: &[&Path]) -> Result<Merged> {
    if parts.is_empty() {
        bail!("give the CSVs of the parts to merge");
    }
    let hint = "not a row of `seethru sweep` (remove it, or run that part again)";
    let mut header: Option<(Vec<String>, Vec<String>, &Path)> = None;
    let mut first_tail: Option<(Vec<String>, &Path, usize)> = None;
    let mut rows: BTreeMap<usize, (Vec<String>, &Path, usize)> = BTreeMap::new();
    for &part in parts {
        let text = read_input_text(part, MAX_SWEEP_CSV_BYTES)
            .with_context(|| format!("cannot read {}", part.display()))?;
        let mut records = records(&text, part)?.into_iter();
        let first = records.next().map(|(_, r)| r).unwrap_or_default();
        let Some(names) = params_of(&first) else {
            bail!(
                "{}: not a seethru sweep CSV: its header is {}, where a sweep's is `index`, its parameters, then {}",
                part.display(),
                columns_text(&first, 2),
                columns_text(&sweep_header(&[])[1..], 0)
            );
        };
        match &header {
            None => header = Some((first.clone(), names.clone(), part)),
            Some((h, _, from)) if *h != first => bail!(
                "{}: its header differs from {}'s ({}): not parts of one sweep",
                part.display(),
                from.display(),
                header_difference(&first, h)
            ),
            Some(_) => {}
        }
        let tail_at = 1 + names.len() + METRIC_COLUMNS.len();
        // Within one part, as in a resumed CSV: no configuration twice.
        let mut seen = SeenRows::default();
        for (number, fields) in records {
            let index = check_row(&fields, names.len(), part, number, hint)?;
            seen.note(&fields, &names, index, part, number)?;
            let tail = &fields[tail_at..];
            match &first_tail {
                None => first_tail = Some((tail.to_vec(), part, number)),
                Some((earlier, from, at)) if earlier.as_slice() != tail => {
                    let (shown, a, b) = if earlier[0] != tail[0] {
                        // check_row admitted both: integers, shown as written.
                        (GRID_COLUMN, tail[0].clone(), earlier[0].clone())
                    } else {
                        first_difference(&tail[1..], &earlier[1..]).unwrap_or_default()
                    };
                    bail!(
                        "{}:{number}: computed with {shown} {a}, {}:{at} with {shown} {b}: not parts of one sweep",
                        part.display(),
                        from.display()
                    );
                }
                Some(_) => {}
            }
            if let Some((earlier, from, at)) = rows.get(&index) {
                if *earlier != fields {
                    bail!(
                        "{}:{number}: configuration {index} differs from {}:{at}",
                        part.display(),
                        from.display()
                    );
                }
                continue;
            }
            rows.insert(index, (fields, part, number));
        }
    }
    let (header, param_names, _) = header.expect("at least one part");
    let Some((tail, _, _)) = first_tail else {
        bail!(
            "the parts hold no configurations (header only): nothing to merge — run their shards (or resume them) and merge again"
        );
    };
    // check_row admitted it: an integer in [1, MAX_CONFIGURATIONS].
    let expected: usize = tail[0].parse().unwrap_or(0);
    // Each parameter's values in grid order: the grid runs the first parameter slowest, so
    // the order of first appearance by index is the order given on the command line.
    let mut params: Vec<Param> = param_names
        .iter()
        .map(|n| Param {
            name: n.to_string(),
            values: Vec::new(),
        })
        .collect();
    for (fields, _, _) in rows.values() {
        for (p, value) in params.iter_mut().zip(fields.iter().skip(1)) {
            if !p.values.iter().any(|v| v == value) {
                p.values.push(value.to_string());
            }
        }
    }
    let missing: Vec<String> = (0..expected)
        .filter(|i| !rows.contains_key(i))
        .map(|i| i.to_string())
        .collect();
    if !missing.is_empty() {
        bail!(
            "the parts hold {} of the grid's {expected} configurations; missing: {}{} — run their shards (or resume them) and merge again",
            rows.len(),
            missing
                .iter()
                .take(20)
                .cloned()
                .collect::<Vec<_>>()
                .join(", "),
            if missing.len() > 20 { ", …" } else { "" }
        );
    }
    let body: Vec<(usize, String)> = rows
        .into_iter()
        .map(|(i, (fields, _, _))| (i, encode(&fields)))
        .collect();
    let text: String = std::iter::once(encode(&header))
        .chain(body.iter().map(|(_, l)| l.clone()))
        .map(|l| l + "\n")
        .collect();
    Ok(Merged {
        rows: body.len(),
        params,
        body,
        text,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_shard_is_k_of_n_with_k_below_n() {
        for (text, shard) in [("0/1", (0, 1)), ("2/3", (2, 3)), (" 1 / 3 ", (1, 3))] {
            let got: Shard = text.parse().unwrap();
            assert_eq!((got.index, got.count), shard, "{text}");
        }
        let top = format!("{}/{}", MAX_SHARDS - 1, MAX_SHARDS);
        assert!(top.parse::<Shard>().is_ok());
        for text in [
            "3/3",
            "4/3",
            "0/0",
            "1/0",
            &format!("0/{}", MAX_SHARDS + 1),
            "1",
            "a/2",
        ] {
            let e = text.parse::<Shard>().unwrap_err();
            assert!(e.contains("K/N with N in [1, "), "{text}: {e}");
        }
    }

    /// Parts of two sweeps are refused by their headers, before any row is read.
    #[test]
    fn parts_with_different_headers_are_refused() {
        let dir = tempfile::tempdir().unwrap();
        let part = |name: &str, param: &str| {
            let path = dir.path().join(name);
            std::fs::write(&path, encode(&sweep_header(&[param.to_string()])) + "\n").unwrap();
            path
        };
        let (a, b) = (part("a.csv", "d2"), part("b.csv", "ipd"));
        let e = merge(&[&a, &b], &dir.path().join("out.csv"))
            .err()
            .map(|e| format!("{e:#}"))
            .unwrap_or_default();
        assert!(
            e.contains("b.csv: its header differs from") && e.contains("a.csv"),
            "{e}"
        );
        assert!(!dir.path().join("out.csv").exists());
    }
}
