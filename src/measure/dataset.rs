//! A dataset's samples: each sample's draws (from the dataset's seed and the sample's index
//! alone, so that any shard or resumed run draws the same), its folder, and the manifest read
//! back from the sample folders (so that however the samples were made, in one process,
//! sharded or resumed, the manifest is the same bytes).

use std::path::{Path, PathBuf};

use anyhow::{Context, Result, bail};
use serde_json::{Value, json};

use crate::measure::dataset_spec::{DatasetSpec, Law};
use crate::measure::option_table::Kind;
use crate::util::hash::Fnv64;
use crate::util::input_file::read_input_json;

/// The dataset's record in its folder: which spec its samples follow.
pub const RECORD: &str = "dataset.json";
/// One row per sample.
pub const MANIFEST: &str = "manifest.csv";
/// A sample's draws, in its folder.
pub const SAMPLE_RECORD: &str = "sample.json";

/// The folder of sample `index`: `samples/000042`.
pub fn sample_dir(dataset: &Path, index: usize) -> PathBuf {
    dataset.join("samples").join(format!("{index:06}"))
}

/// A finished sample's folder holds its run.json (written last of its files, and the folder
/// moved into place whole).
pub fn is_done(dataset: &Path, index: usize) -> bool {
    sample_dir(dataset, index).join("run.json").is_file()
}

fn splitmix64(mut z: u64) -> u64 {
    z = z.wrapping_add(0x9E37_79B9_7F4A_7C15);
    z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    z ^ (z >> 31)
}

/// The `k`-th uniform number in (0, 1] of draw `name` of sample `index`: independent of the
/// other draws, so adding a draw to a spec changes no other column.
fn unit(seed: u64, index: usize, name: &str, k: u64) -> f64 {
    let name_hash = Fnv64::default().bytes(name.as_bytes()).finish();
    let state = splitmix64(seed ^ splitmix64(index as u64 ^ splitmix64(name_hash ^ splitmix64(k))));
    ((state >> 11) as f64 + 1.0) / (1u64 << 53) as f64
}

/// Box–Muller with two uniforms in (0, 1]: finite for every draw.
fn standard_normal(u0: f64, u1: f64) -> f64 {
    (-2.0 * u0.ln()).sqrt() * (std::f64::consts::TAU * u1).cos()
}

/// A drawn vector as text, as TOML writes an array: `[1.5, 0, -12]`.
fn vector(components: impl Iterator<Item = f64>) -> String {
    let parts: Vec<String> = components.map(|c| format!("{c}")).collect();
    format!("[{}]", parts.join(", "))
}

/// Sample `index`'s drawn values: (name, value as text), in the spec's order. Numbers are
/// written as Rust writes the `f64` (shortest round trip); an integer option's uniform draw
/// is uniform over the integers of its range, its normal draw rounded.
pub fn sample_draws(spec: &DatasetSpec, index: usize) -> Vec<(String, String)> {
    spec.draws
        .iter()
        .map(|draw| {
            let u = |k| unit(spec.seed, index, &draw.name, k);
            let number = |v: f64| match draw.option.map(|o| o.kind) {
                Some(Kind::Integer { .. }) => format!("{}", v.round() as i64),
                _ => format!("{v}"),
            };
            let text = match &draw.law {
                Law::Eyellipse => format!("eyellipse:{}:{index}", spec.seed),
                Law::OneOf(values) => {
                    let pick =
                        ((u(0) * values.len() as f64).ceil() as usize).clamp(1, values.len());
                    values[pick - 1].clone()
                }
                Law::Uniform(low, high) => match draw.option.map(|o| o.kind) {
                    // An integer option: each integer of [low, high] as likely (rounding a
                    // real draw would halve the ends' chances).
                    Some(Kind::Integer { .. }) => {
                        let (first, last) = (low.ceil(), high.floor().max(low.ceil()));
                        let pick =
                            (first + ((last - first + 1.0) * (1.0 - u(0))).floor()).min(last);
                        format!("{}", pick as i64)
                    }
                    _ => number(low + (high - low) * (1.0 - u(0))),
                },
                Law::Normal(mean, sd) => number(mean + sd * standard_normal(u(0), u(1))),
                // Component i from the draw's uniforms 2i and 2i + 1: the first component is
                // the scalar law's draw.
                Law::UniformVector(low, high) => vector(
                    low.iter()
                        .zip(high)
                        .enumerate()
                        .map(|(i, (low, high))| low + (high - low) * (1.0 - u(2 * i as u64))),
                ),
                Law::NormalVector(mean, sd) => {
                    vector(mean.iter().zip(sd).enumerate().map(|(i, (mean, sd))| {
                        let k = 2 * i as u64;
                        mean + sd * standard_normal(u(k), u(k + 1))
                    }))
                }
            };
            (draw.name.clone(), text)
        })
        .collect()
}

/// The record of `spec` a dataset folder keeps (`dataset.json`).
pub fn record(spec: &DatasetSpec) -> Value {
    json!({
        "spec": spec.path.display().to_string(),
        "spec_hash": spec.source_hash,
        "scene": spec.scene.display().to_string(),
        "samples": spec.samples,
        "seed": spec.seed,
        "draws": spec.draws.iter().map(|d| &d.name).collect::<Vec<_>>(),
    })
}

/// Refuses a folder whose samples follow another spec (or another version of this one): a
/// dataset is resumed or sharded only with the spec that began it.
pub fn check_record(dataset: &Path, spec: &DatasetSpec) -> Result<bool> {
    let path = dataset.join(RECORD);
    if !path.is_file() {
        return Ok(false);
    }
    let old = read_input_json(&path, 1 << 20)?;
    if old["spec_hash"] != json!(spec.source_hash) {
        bail!(
            "{} holds the samples of another spec ({}, hash {}; this one {}): write it into another folder, or give the spec that began it",
            dataset.display(),
            old["spec"].as_str().unwrap_or("?"),
            old["spec_hash"].as_str().unwrap_or("?"),
            spec.source_hash
        );
    }
    Ok(true)
}

/// The manifest's metric columns: (column, where in metrics.json or run.json).
pub const METRIC_COLUMNS: [(&str, &str, &[&str]); 8] = [
    (
        "misregistration_mean_arcmin",
        "metrics",
        &["display", "misregistration_arcmin", "mean"],
    ),
    (
        "misregistration_p95_arcmin",
        "metrics",
        &["display", "misregistration_arcmin", "p95"],
    ),
    ("coverage", "metrics", &["display", "coverage"]),
    (
        "border_mean_arcmin",
        "metrics",
        &["border", "misregistration_arcmin", "mean"],
    ),
    ("psnr_db", "metrics", &["display", "psnr_db"]),
    ("ssim", "metrics", &["display", "ssim"]),
    ("display_pixels", "metrics", &["display_pixels"]),
    ("eye_error_m", "run", &["eye_used", "error_m"]),
];

/// The files of a sample, relative to the dataset folder, as the manifest's last columns.
pub const FILE_COLUMNS: [(&str, &str); 7] = [
    ("truth_png", "truth.png"),
    ("seethru_png", "seethru.png"),
    ("frontal_png", "frontal.png"),
    ("back_png", "back.png"),
    ("misregistration_exr", "misregistration.exr"),
    ("metrics_json", "metrics.json"),
    ("run_json", "run.json"),
];

/// A CSV field: quoted when it holds a comma, a quote or a line break.
fn field(text: &str) -> String {
    if text.contains([',', '"', '\n', '\r']) {
        format!("\"{}\"", text.replace('"', "\"\""))
    } else {
        text.to_string()
    }
}

/// A finished dataset's manifest: one row per sample with its draws, its headline metrics
/// (`None` where a metric has no value) and its files' paths relative to the dataset folder
/// (`None` where the sample has no such file), read from the sample folders.
pub struct Manifest {
    /// The draws' names, in the spec's order.
    pub draws: Vec<String>,
    pub rows: Vec<ManifestRow>,
}

pub struct ManifestRow {
    pub sample: usize,
    /// Each draw as drawn (text), in [`Manifest::draws`]' order.
    pub draws: Vec<String>,
    /// [`METRIC_COLUMNS`]' values.
    pub metrics: Vec<Option<f64>>,
    /// [`FILE_COLUMNS`]' paths.
    pub files: Vec<Option<String>>,
}

impl Manifest {
    /// Reads every sample folder of a finished dataset.
    pub fn read(dataset: &Path, spec: &DatasetSpec) -> Result<Manifest> {
        let mut rows = Vec::new();
        for index in 0..spec.samples {
            let dir = sample_dir(dataset, index);
            let read_json = |name: &str| read_input_json(&dir.join(name), 64 << 20);
            let sample = read_json(SAMPLE_RECORD)?;
            let metrics = read_json("metrics.json")?;
            let run = read_json("run.json")?;
            let mut draws = Vec::new();
            for d in &spec.draws {
                let v = sample["draws"][&d.name].as_str().with_context(|| {
                    format!(
                        "{}: no draw `{}`",
                        dir.join(SAMPLE_RECORD).display(),
                        d.name
                    )
                })?;
                draws.push(v.to_string());
            }
            let metrics = METRIC_COLUMNS
                .iter()
                .map(|(_, from, path)| {
                    let mut v = if *from == "metrics" { &metrics } else { &run };
                    for key in *path {
                        v = &v[*key];
                    }
                    v.as_f64()
                })
                .collect();
            let files = FILE_COLUMNS
                .iter()
                .map(|(_, file)| {
                    let rel = format!("samples/{index:06}/{file}");
                    dataset.join(&rel).is_file().then_some(rel)
                })
                .collect();
            rows.push(ManifestRow {
                sample: index,
                draws,
                metrics,
                files,
            });
        }
        Ok(Manifest {
            draws: spec.draws.iter().map(|d| d.name.clone()).collect(),
            rows,
        })
    }

    /// The column names: `sample`, the draws, the metrics, the files.
    pub fn header(&self) -> Vec<String> {
        let mut header = vec!["sample".to_string()];
        header.extend(self.draws.iter().cloned());
        header.extend(METRIC_COLUMNS.iter().map(|c| c.0.to_string()));
        header.extend(FILE_COLUMNS.iter().map(|c| c.0.to_string()));
        header
    }

    /// `manifest.csv`: numbers as Rust writes the f64, an absent value as an empty field.
    pub fn csv(&self) -> String {
        let mut csv = self.header().join(",") + "\n";
        for r in &self.rows {
            let mut row = vec![r.sample.to_string()];
            row.extend(r.draws.iter().map(|d| field(d)));
            row.extend(
                r.metrics
                    .iter()
                    .map(|m| m.map_or(String::new(), |x| format!("{x}"))),
            );
            row.extend(r.files.iter().map(|f| f.clone().unwrap_or_default()));
            csv += &(row.join(",") + "\n");
        }
        csv
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn draws_are_independent_per_name_and_index_and_fill_their_range() {
        let a: Vec<f64> = (0..4000).map(|i| unit(7, i, "theta_f", 0)).collect();
        assert!(a.iter().all(|&u| u > 0.0 && u <= 1.0));
        let mean = a.iter().sum::<f64>() / a.len() as f64;
        // The mean of 4000 uniforms: 0.5 ± 0.0046 (one σ); 4σ.
        assert!((mean - 0.5).abs() < 0.019, "{mean}");
        // Another name, another seed or another k: another stream.
        assert_ne!(unit(7, 3, "theta_f", 0), unit(7, 3, "d2", 0));
        assert_ne!(unit(7, 3, "theta_f", 0), unit(8, 3, "theta_f", 0));
        assert_ne!(unit(7, 3, "theta_f", 0), unit(7, 3, "theta_f", 1));
        assert_eq!(unit(7, 3, "theta_f", 0), unit(7, 3, "theta_f", 0));
    }

    #[test]
    fn csv_fields_with_commas_or_quotes_are_quoted() {
        assert_eq!(field("planar-inf"), "planar-inf");
        assert_eq!(field("a,b"), "\"a,b\"");
        assert_eq!(field("say \"x\""), "\"say \"\"x\"\"\"");
    }
}
