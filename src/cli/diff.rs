//! `seethru diff A B`: two images (PNG, or EXR layer by layer) or two run folders (their
//! views and their metrics.json), with thresholds: exit 0 when every one holds, 1 when one
//! does not, 2 on bad input.

use std::path::{Path, PathBuf};

use anyhow::{Result, bail};
use seethru::io::atomic::write_text;
use seethru::io::frame_files::write_png;
use seethru::io::output_paths::{Input, Output, Read, check_paths};
use seethru::io::staged::StagedDir;
use seethru::measure::diff_thresholds::{BoundKind, Threshold, Verdict, check_thresholds};
use seethru::measure::headline::{RUN_HEADLINES, SEQUENCE_HEADLINES, read_results, value_of};
use seethru::measure::image_diff::{
    LayerDiff, diff_layer, flip_heatmap, number, paired_layers, pixels_per_degree,
};
use seethru::measure::picture_layers::{Picture, read_picture};
use seethru::util::number::short;
use serde_json::{Value, json};

use crate::cli::args::{ReadWhen, real, refuse_ignored};
use crate::cli::verdict::ChecksFailed;

/// The views of a run folder that `diff` compares, as their colour PNGs.
const VIEWS: [&str; 6] = ["truth", "occluded", "seethru", "display", "frontal", "back"];

fn at_most(text: &str) -> Result<Threshold, String> {
    Threshold::parse(text, BoundKind::AtMost)
}

fn at_least(text: &str) -> Result<Threshold, String> {
    Threshold::parse(text, BoundKind::AtLeast)
}

/// `NAME=VALUE` with NAME a headline metric of metrics.json and VALUE in [0, 1e9].
fn tolerance(text: &str) -> Result<(String, f64), String> {
    let (name, value) = text
        .split_once('=')
        .ok_or_else(|| format!("`{text}` is not NAME=VALUE (e.g. misregistration.mean=0.5)"))?;
    let name = name.trim();
    if !RUN_HEADLINES
        .iter()
        .chain(&SEQUENCE_HEADLINES)
        .any(|h| h.name == name)
    {
        let mut names: Vec<&str> = RUN_HEADLINES.iter().map(|h| h.name).collect();
        names.extend(SEQUENCE_HEADLINES.iter().map(|h| h.name));
        names.dedup();
        names.sort_unstable();
        names.dedup();
        return Err(format!(
            "unknown metric `{name}` (known: {})",
            names.join(", ")
        ));
    }
    let value = real(0.0, 1e9)(value).map_err(|e| format!("the tolerance {e}"))?;
    Ok((name.to_string(), value))
}

#[derive(clap::Args)]
pub struct Diff {
    /// The reference: an image (PNG or EXR) or a run folder.
    a: PathBuf,
    /// The image or run folder compared with it (same size, same layers).
    b: PathBuf,
    /// Compare only this layer of EXRs (colour, Z, camera_z, P, N, id, ...) or this view of
    /// run folders (truth, seethru, ...); repeatable (default: all).
    #[arg(long, value_name = "LAYER")]
    layer: Vec<String>,
    /// Fail (exit 1) when a metric exceeds VALUE: `flip_mean=0.05`, or one layer's
    /// `seethru.flip_mean=0.05`; repeatable. Metrics: flip_mean, flip_p95, flip_max,
    /// psnr_db, ssim, max_abs_error, mean_abs_error, differing_pixels, differing_fraction,
    /// nonfinite_mismatch_pixels.
    #[arg(long, value_name = "NAME=VALUE", value_parser = at_most)]
    max: Vec<Threshold>,
    /// Fail (exit 1) when a metric is below VALUE: `psnr_db=40`, `ssim=0.99`; repeatable.
    #[arg(long, value_name = "NAME=VALUE", value_parser = at_least)]
    min: Vec<Threshold>,
    /// Run folders: how far a metric of metrics.json (summary.json of a sequence) may move,
    /// `misregistration.mean=0.5`, in the metric's unit, in [0, 1e9]; repeatable (defaults:
    /// docs/guide/ci-checks.md).
    #[arg(long, value_name = "NAME=VALUE", value_parser = tolerance)]
    tolerance: Vec<(String, f64)>,
    /// FLIP's pixels per degree, in [1, 1000] (default: the run's driver camera for the
    /// driver's views, else 67).
    #[arg(long, value_parser = real(1.0, 1000.0))]
    ppd: Option<f64>,
    /// Print the report as JSON on stdout instead of the table.
    #[arg(long)]
    json: bool,
    /// Write diff.json and a FLIP heatmap per colour layer (flip_<layer>.png) into DIR.
    #[arg(long, value_name = "DIR")]
    out: Option<PathBuf>,
}

/// One metric of metrics.json in both runs.
struct MetricChange {
    name: &'static str,
    a: f64,
    b: f64,
    tolerance: f64,
}

impl MetricChange {
    fn pass(&self) -> bool {
        (self.a.is_nan() && self.b.is_nan()) || (self.a - self.b).abs() <= self.tolerance
    }
}

impl Diff {
    pub fn run(self) -> Result<()> {
        let outputs: Vec<Output> = self
            .out
            .as_deref()
            .map(|o| Output::folder("--out", o))
            .into_iter()
            .collect();
        check_paths(
            &[
                Input {
                    option: "A",
                    path: &self.a,
                    read: Read::Either,
                },
                Input {
                    option: "B",
                    path: &self.b,
                    read: Read::Either,
                },
            ],
            &outputs,
        )?;
        let (a_dir, b_dir) = (self.a.is_dir(), self.b.is_dir());
        refuse_ignored(&[ReadWhen {
            option: "tolerance",
            read: a_dir && b_dir,
            when: "when two run folders are compared (their metrics.json)",
        }])?;
        let (diffs, changes) = match (a_dir, b_dir) {
            (true, true) => self.folders()?,
            (false, false) => {
                let (a, b) = (read_picture(&self.a)?, read_picture(&self.b)?);
                let ppd = self.ppd(&self.a);
                (self.layers(&a, &b, &|_| ppd.clone())?, Vec::new())
            }
            _ => bail!(
                "{} is a {} but {} is a {}: compare two images or two run folders",
                self.a.display(),
                kind(a_dir),
                self.b.display(),
                kind(b_dir)
            ),
        };
        let thresholds: Vec<Threshold> = self.max.iter().chain(&self.min).cloned().collect();
        let verdicts = check_thresholds(&diffs, &thresholds)?;
        let failed = verdicts.iter().filter(|v| !v.pass).count()
            + changes.iter().filter(|c| !c.pass()).count();
        let report = self.report(&diffs, &verdicts, &changes, failed == 0);
        if let Some(out) = &self.out {
            let staged = StagedDir::new(out)?;
            write_text(
                &staged.path().join("diff.json"),
                &serde_json::to_string_pretty(&report)?,
            )?;
            for d in &diffs {
                if let Some(flip) = &d.flip {
                    let (w, h, rgb) = flip_heatmap(flip, d.width, d.height)?;
                    write_png(
                        &staged.path().join(format!("flip_{}.png", d.name)),
                        w,
                        h,
                        rgb,
                    )?;
                }
            }
            staged.commit()?;
        }
        if self.json {
            println!("{}", serde_json::to_string_pretty(&report)?);
        } else {
            print!("{}", table(&diffs, &verdicts, &changes));
        }
        let checked = verdicts.len() + changes.len();
        if failed > 0 {
            let first: Vec<String> = verdicts
                .iter()
                .filter(|v| !v.pass)
                .map(|v| format!("{} ({}: {})", v.threshold, v.layer, short(v.value)))
                .chain(changes.iter().filter(|c| !c.pass()).map(|c| {
                    format!(
                        "{} moved {} → {} (tolerance {})",
                        c.name,
                        short(c.a),
                        short(c.b),
                        short(c.tolerance)
                    )
                }))
                .collect();
            return Err(ChecksFailed(format!(
                "{failed} of {checked} checks of {} against {}: {}",
                self.b.display(),
                self.a.display(),
                first.join("; ")
            ))
            .into());
        }
        seethru::util::progress::summary(format!(
            "{} layer(s) compared, {checked} checks passed{}",
            diffs.len(),
            self.out.as_ref().map_or(String::new(), |o| format!(
                "; wrote diff.json and heatmaps to {}",
                o.display()
            ))
        ));
        Ok(())
    }

    fn ppd(&self, image: &Path) -> (f32, String) {
        if let Some(ppd) = self.ppd {
            return (ppd as f32, "--ppd".into());
        }
        let dir = image.parent().unwrap_or(Path::new(""));
        let view = image
            .file_stem()
            .map(|s| s.to_string_lossy().to_string())
            .unwrap_or_default();
        pixels_per_degree(dir, &view)
    }

    fn layers(
        &self,
        a: &Picture,
        b: &Picture,
        ppd: &dyn Fn(&str) -> (f32, String),
    ) -> Result<Vec<LayerDiff>> {
        paired_layers(a, b, &self.layer)?
            .into_iter()
            .map(|(la, lb)| diff_layer(la, lb, a.width, a.height, ppd(&la.name)))
            .collect()
    }

    /// Two run folders: the views both have as PNGs (each a layer named after its view),
    /// and the headline metrics.
    fn folders(&self) -> Result<(Vec<LayerDiff>, Vec<MetricChange>)> {
        let views: Vec<&str> = if self.layer.is_empty() {
            VIEWS
                .iter()
                .copied()
                .filter(|v| self.a.join(format!("{v}.png")).is_file())
                .collect()
        } else {
            for name in &self.layer {
                if !VIEWS.contains(&name.as_str()) {
                    bail!(
                        "--layer {name}: run folders have the views {}",
                        VIEWS.join(", ")
                    );
                }
            }
            self.layer.iter().map(String::as_str).collect()
        };
        let mut diffs = Vec::new();
        for view in views {
            let read = |dir: &Path| -> Result<Picture> {
                let mut p = read_picture(&dir.join(format!("{view}.png")))?;
                p.layers[0].name = view.to_string();
                Ok(p)
            };
            let (a, b) = (read(&self.a)?, read(&self.b)?);
            let ppd = self.ppd(&self.a.join(format!("{view}.png")));
            diffs.extend(self.layers(&a, &b, &|_| ppd.clone())?);
        }
        let (kind_a, json_a) = read_results(&self.a)?;
        let (kind_b, json_b) = read_results(&self.b)?;
        if kind_a != kind_b {
            bail!(
                "{} holds a {kind_a:?} but {} a {kind_b:?}: compare like with like",
                self.a.display(),
                self.b.display()
            );
        }
        for (name, _) in &self.tolerance {
            if kind_a.headline(name).is_none() {
                bail!(
                    "--tolerance {name}: not a metric of a {kind_a:?} folder (known: {})",
                    kind_a.names()
                );
            }
        }
        let changes = kind_a
            .headlines()
            .iter()
            .map(|h| MetricChange {
                name: h.name,
                a: value_of(&json_a, h),
                b: value_of(&json_b, h),
                tolerance: self
                    .tolerance
                    .iter()
                    .rev()
                    .find(|t| t.0 == h.name)
                    .map_or(h.tolerance, |t| t.1),
            })
            .collect();
        Ok((diffs, changes))
    }

    fn report(
        &self,
        diffs: &[LayerDiff],
        verdicts: &[Verdict],
        changes: &[MetricChange],
        pass: bool,
    ) -> Value {
        let layers: serde_json::Map<String, Value> = diffs
            .iter()
            .map(|d| (d.name.clone(), d.to_json()))
            .collect();
        json!({
            "a": self.a.display().to_string(),
            "b": self.b.display().to_string(),
            "layers": layers,
            "thresholds": verdicts.iter().map(|v| json!({
                "threshold": v.threshold,
                "layer": v.layer,
                "value": number(v.value),
                "pass": v.pass,
            })).collect::<Vec<_>>(),
            "metrics": changes.iter().map(|c| json!({
                "metric": c.name,
                "a": number(c.a),
                "b": number(c.b),
                "tolerance": c.tolerance,
                "pass": c.pass(),
            })).collect::<Vec<_>>(),
            "pass": pass,
            "notes": "FLIP, PSNR and SSIM on 8-bit sRGB colour (linear EXR colour encoded to sRGB first); absolute errors in each layer's units, over the values finite in both images (nonfinite_mismatch_pixels counts the rest)",
        })
    }
}

fn kind(dir: bool) -> &'static str {
    if dir { "folder" } else { "file" }
}

fn cell(v: Option<f64>) -> String {
    match v {
        None => "-".into(),
        Some(v) if v.is_infinite() => "inf".into(),
        Some(v) => format!("{v:.4}"),
    }
}

/// The table on stdout: a row per layer, then a row per threshold and metric checked.
fn table(diffs: &[LayerDiff], verdicts: &[Verdict], changes: &[MetricChange]) -> String {
    let columns = [
        "flip_mean",
        "flip_max",
        "psnr_db",
        "ssim",
        "max_abs_error",
        "mean_abs_error",
        "differing_pixels",
    ];
    let mut out = format!("{:<12}", "layer");
    for c in columns {
        out.push_str(&format!(" {c:>16}"));
    }
    out.push('\n');
    for d in diffs {
        out.push_str(&format!("{:<12}", d.name));
        for c in columns {
            out.push_str(&format!(" {:>16}", cell(d.metric(c))));
        }
        out.push('\n');
    }
    for v in verdicts {
        out.push_str(&format!(
            "{} {} ({}: {})\n",
            if v.pass { "PASS" } else { "FAIL" },
            v.threshold,
            v.layer,
            cell(Some(v.value))
        ));
    }
    for c in changes {
        out.push_str(&format!(
            "{} {}: {} → {} (tolerance {})\n",
            if c.pass() { "PASS" } else { "FAIL" },
            c.name,
            cell(Some(c.a)),
            cell(Some(c.b)),
            short(c.tolerance)
        ));
    }
    out
}
