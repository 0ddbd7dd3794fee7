//! The headline metrics of a `run` (`metrics.json`) or a `sequence` (`summary.json`) under
//! short names (`misregistration.mean`, `coverage`, ...), with the tolerance two runs may
//! differ by: what `run` and `sequence` print in their summary line, what `seethru diff`
//! compares between two run folders and what `seethru check` bounds.

use std::path::Path;

use anyhow::{Context, Result, bail};
use serde_json::Value;

use crate::util::input_file::read_input_text;

/// Largest metrics or summary file read, bytes.
const MAX_METRICS_BYTES: u64 = 64 << 20;

/// What made a folder of results.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum RunKind {
    /// `seethru run`: `metrics.json`.
    Run,
    /// `seethru sequence` with one camera latency: `summary.json`.
    Sequence,
}

/// One headline metric: its short name, where it is in the JSON, the default tolerance of a
/// diff of two runs (absolute, in the metric's unit) and what it is.
pub struct Headline {
    pub name: &'static str,
    pub pointer: &'static str,
    pub tolerance: f64,
    pub about: &'static str,
}

/// The headline metrics of a `run`'s `metrics.json`. Tolerances: renders are bit-identical
/// on one platform; across platforms (libm variants) a few silhouette pixels may change,
/// which moves a mean by hundredths of an arc-minute.
pub const RUN_HEADLINES: [Headline; 13] = [
    Headline {
        name: "misregistration.mean",
        pointer: "/display/misregistration_arcmin/mean",
        tolerance: 0.05,
        about: "mean misregistration over the covered display pixels, arcmin",
    },
    Headline {
        name: "misregistration.p95",
        pointer: "/display/misregistration_arcmin/p95",
        tolerance: 0.1,
        about: "95th percentile of the misregistration, arcmin",
    },
    Headline {
        name: "misregistration.max",
        pointer: "/display/misregistration_arcmin/max",
        tolerance: 0.5,
        about: "largest misregistration, arcmin",
    },
    Headline {
        name: "coverage",
        pointer: "/coverage",
        tolerance: 1e-4,
        about: "fraction of display pixels that show the scene, [0, 1]",
    },
    Headline {
        name: "missing.fraction",
        pointer: "/missing/fraction",
        tolerance: 1e-4,
        about: "fraction of display pixels the frontal camera cannot see, [0, 1]",
    },
    Headline {
        name: "border.misregistration.mean",
        pointer: "/border/misregistration_arcmin/mean",
        tolerance: 0.05,
        about: "mean misregistration in the border band, arcmin",
    },
    Headline {
        name: "border.misregistration.p95",
        pointer: "/border/misregistration_arcmin/p95",
        tolerance: 0.1,
        about: "95th percentile in the border band, arcmin",
    },
    Headline {
        name: "psnr_db",
        pointer: "/display/psnr_db",
        tolerance: 0.1,
        about: "PSNR of seethru against the truth over the display, dB",
    },
    Headline {
        name: "ssim",
        pointer: "/display/ssim",
        tolerance: 1e-3,
        about: "mean SSIM over the display, [-1, 1]",
    },
    Headline {
        name: "flip_mean",
        pointer: "/display/flip_mean",
        tolerance: 1e-3,
        about: "mean FLIP of seethru against the truth over the display, [0, 1]",
    },
    Headline {
        name: "luminance.ratio_log2.median",
        pointer: "/luminance/display/ratio_log2/median",
        tolerance: 0.01,
        about: "median of log2(display luminance / the truth's) over the display, stops (a scene lit in physical units)",
    },
    Headline {
        name: "luminance.border.ratio_log2.mean",
        pointer: "/luminance/border/ratio_log2/mean",
        tolerance: 0.01,
        about: "mean of that ratio in the border band, stops: the photometric seam",
    },
    Headline {
        name: "luminance.visible_share",
        pointer: "/luminance/display/visible_share",
        tolerance: 1e-3,
        about: "fraction of display pixels whose luminance differs from the truth's by a visible step (Weber contrast > 0.02), [0, 1]",
    },
];

/// The headline metrics of one sequence's `summary.json`.
pub const SEQUENCE_HEADLINES: [Headline; 6] = [
    Headline {
        name: "misregistration.mean",
        pointer: "/misregistration_arcmin/mean_of_frame_means",
        tolerance: 0.05,
        about: "mean over the frames of each frame's mean misregistration, arcmin",
    },
    Headline {
        name: "misregistration.p95",
        pointer: "/misregistration_arcmin/mean_of_frame_p95",
        tolerance: 0.1,
        about: "mean over the frames of each frame's p95, arcmin",
    },
    Headline {
        name: "misregistration.max",
        pointer: "/misregistration_arcmin/max",
        tolerance: 0.5,
        about: "largest misregistration of any frame, arcmin",
    },
    Headline {
        name: "coverage",
        pointer: "/coverage/mean",
        tolerance: 1e-4,
        about: "mean coverage over the frames, [0, 1]",
    },
    Headline {
        name: "coverage.min",
        pointer: "/coverage/min",
        tolerance: 1e-4,
        about: "smallest coverage of any frame, [0, 1]",
    },
    Headline {
        name: "missing.fraction",
        pointer: "/missing_fraction_mean",
        tolerance: 1e-4,
        about: "mean missing fraction over the frames, [0, 1]",
    },
];

impl RunKind {
    pub fn headlines(self) -> &'static [Headline] {
        match self {
            RunKind::Run => &RUN_HEADLINES,
            RunKind::Sequence => &SEQUENCE_HEADLINES,
        }
    }

    /// The names of its headlines, comma-separated, for messages.
    pub fn names(self) -> String {
        self.headlines()
            .iter()
            .map(|h| h.name)
            .collect::<Vec<_>>()
            .join(", ")
    }

    pub fn headline(self, name: &str) -> Option<&'static Headline> {
        self.headlines().iter().find(|h| h.name == name)
    }
}

/// A metric's value in `json`: NaN where it is absent or not a number (a display that
/// covers no pixel has no mean).
pub fn value_of(json: &Value, headline: &Headline) -> f64 {
    json.pointer(headline.pointer)
        .and_then(Value::as_f64)
        .unwrap_or(f64::NAN)
}

/// Every headline metric of `json` as (name, value).
pub fn headlines_of(kind: RunKind, json: &Value) -> Vec<(&'static str, f64)> {
    kind.headlines()
        .iter()
        .map(|h| (h.name, value_of(json, h)))
        .collect()
}

/// The summary line's metrics: `misregistration mean 12.3′, p95 20.1′, coverage 0.998`, and
/// in a scene lit in physical units the display's luminance against the world's.
pub fn summary_text(kind: RunKind, json: &Value) -> String {
    let get = |name: &str| kind.headline(name).map_or(f64::NAN, |h| value_of(json, h));
    let mut text = format!(
        "misregistration mean {:.2}′, p95 {:.2}′, coverage {:.4}",
        get("misregistration.mean"),
        get("misregistration.p95"),
        get("coverage")
    );
    if json.get("luminance").is_some() {
        text += &format!(
            ", display luminance {:+.2} stops from the world's (median), a visible step on {:.1} % of it",
            get("luminance.ratio_log2.median"),
            100.0 * get("luminance.visible_share")
        );
    }
    text
}

/// The kind of results folder `dir` is and its metrics JSON: `metrics.json` of a `run`, or
/// the `summary.json` of a `sequence` with one latency (its one sequence's summary).
pub fn read_results(dir: &Path) -> Result<(RunKind, Value)> {
    let read = |name: &str| -> Result<Value> {
        let path = dir.join(name);
        let text = read_input_text(&path, MAX_METRICS_BYTES)
            .with_context(|| format!("cannot read {}", path.display()))?;
        serde_json::from_str(&text).with_context(|| format!("{} is not JSON", path.display()))
    };
    if dir.join("metrics.json").is_file() {
        return Ok((RunKind::Run, read("metrics.json")?));
    }
    if dir.join("summary.json").is_file() {
        let overview = read("summary.json")?;
        // A latency's own folder holds that sequence's summary itself.
        if overview.get("misregistration_arcmin").is_some() {
            return Ok((RunKind::Sequence, overview));
        }
        let sequences = overview["sequences"].as_array().with_context(|| {
            format!(
                "{} has no `sequences` (not written by seethru sequence?)",
                dir.join("summary.json").display()
            )
        })?;
        if sequences.len() != 1 {
            bail!(
                "{} holds {} sequences (one per option `latency_camera` value); compare a folder of one, e.g. {}",
                dir.join("summary.json").display(),
                sequences.len(),
                dir.join(sequences[0]["dir"].as_str().unwrap_or("latency_<ms>ms"))
                    .display()
            );
        }
        return Ok((RunKind::Sequence, sequences[0]["summary"].clone()));
    }
    bail!(
        "{} holds neither metrics.json (a run) nor summary.json (a sequence)",
        dir.display()
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn headlines_are_read_where_the_metrics_put_them() {
        let json = serde_json::json!({
            "coverage": 0.9,
            "display": {"misregistration_arcmin": {"mean": 12.5, "p95": 30.0}},
        });
        let values = headlines_of(RunKind::Run, &json);
        assert!(values.contains(&("misregistration.mean", 12.5)));
        assert!(values.contains(&("coverage", 0.9)));
        let border = values.iter().find(|v| v.0 == "border.misregistration.mean");
        assert!(border.unwrap().1.is_nan());
        assert_eq!(
            summary_text(RunKind::Run, &json),
            "misregistration mean 12.50′, p95 30.00′, coverage 0.9000"
        );
    }
}
