//! The bounds a diff is checked against (`--max`, `--min`: `flip_mean=0.05`,
//! `seethru.psnr_db=40`) and each bound's verdict on the compared layers. Apart from the diff
//! (measure/image_diff.rs), which computes the metrics these bounds name: reading a bound and
//! judging the layers by it is the commands' check, not the measurement.

use anyhow::{Context, Result, bail};

use crate::measure::image_diff::{KNOWN_METRICS, LayerDiff, known_metric_names};

/// Which way a threshold bounds a metric.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum BoundKind {
    /// The value must be at most the bound (`--max`).
    AtMost,
    /// The value must be at least the bound (`--min`).
    AtLeast,
}

/// A threshold on one metric of one layer (`layer.metric`), or of every layer that has the
/// metric (`metric`).
#[derive(Clone, Debug, PartialEq)]
pub struct Threshold {
    pub layer: Option<String>,
    pub metric: String,
    pub kind: BoundKind,
    pub value: f64,
}

impl Threshold {
    /// Reads `NAME=VALUE` (NAME: `metric` or `layer.metric`, metric one of
    /// [`KNOWN_METRICS`]; VALUE a finite number).
    pub fn parse(text: &str, kind: BoundKind) -> Result<Self, String> {
        let (name, value) = text
            .split_once('=')
            .ok_or_else(|| format!("`{text}` is not NAME=VALUE (e.g. flip_mean=0.05)"))?;
        let (layer, metric) = match name.trim().rsplit_once('.') {
            Some((layer, metric)) => (Some(layer.to_string()), metric),
            None => (None, name.trim()),
        };
        if !KNOWN_METRICS.iter().any(|m| m.0 == metric) {
            return Err(format!(
                "unknown metric `{metric}` (known: {})",
                known_metric_names()
            ));
        }
        let value = value
            .trim()
            .parse::<f64>()
            .ok()
            .filter(|v| v.is_finite())
            .ok_or_else(|| format!("the bound `{}` is not a finite number", value.trim()))?;
        Ok(Self {
            layer,
            metric: metric.to_string(),
            kind,
            value,
        })
    }

    pub fn holds(&self, value: f64) -> bool {
        match self.kind {
            BoundKind::AtMost => value <= self.value,
            BoundKind::AtLeast => value >= self.value,
        }
    }

    pub fn describe(&self) -> String {
        let op = match self.kind {
            BoundKind::AtMost => "<=",
            BoundKind::AtLeast => ">=",
        };
        let name = match &self.layer {
            Some(l) => format!("{l}.{}", self.metric),
            None => self.metric.clone(),
        };
        format!("{name} {op} {}", crate::util::number::short(self.value))
    }
}

/// One threshold checked against one layer.
pub struct Verdict {
    pub threshold: String,
    pub layer: String,
    pub value: f64,
    pub pass: bool,
}

/// Checks every threshold against the layers it names. A threshold that names a layer no
/// diff has, or a metric no named layer has (FLIP of a depth layer), is an error.
pub fn check_thresholds(diffs: &[LayerDiff], thresholds: &[Threshold]) -> Result<Vec<Verdict>> {
    let mut verdicts = Vec::new();
    for t in thresholds {
        let layers: Vec<&LayerDiff> = match &t.layer {
            Some(name) => {
                let d = diffs.iter().find(|d| &d.name == name).with_context(|| {
                    format!(
                        "threshold `{}`: no layer `{name}` was compared (layers: {})",
                        t.describe(),
                        diffs
                            .iter()
                            .map(|d| d.name.as_str())
                            .collect::<Vec<_>>()
                            .join(", ")
                    )
                })?;
                vec![d]
            }
            None => diffs
                .iter()
                .filter(|d| d.metric(&t.metric).is_some())
                .collect(),
        };
        let mut any = false;
        for d in layers {
            let Some(value) = d.metric(&t.metric) else {
                bail!(
                    "threshold `{}`: layer `{}` has no {} (FLIP, PSNR and SSIM are of colour layers)",
                    t.describe(),
                    d.name,
                    t.metric
                );
            };
            any = true;
            verdicts.push(Verdict {
                threshold: t.describe(),
                layer: d.name.clone(),
                value,
                // NaN never passes a bound.
                pass: t.holds(value),
            });
        }
        if !any {
            bail!(
                "threshold `{}`: no compared layer has {} (FLIP, PSNR and SSIM are of colour layers)",
                t.describe(),
                t.metric
            );
        }
    }
    Ok(verdicts)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn thresholds_read_and_refuse() {
        let t = Threshold::parse("seethru.flip_mean=0.05", BoundKind::AtMost).unwrap();
        assert_eq!(t.layer.as_deref(), Some("seethru"));
        assert!(t.holds(0.05) && !t.holds(0.0500001));
        let e = Threshold::parse("flop=1", BoundKind::AtMost).unwrap_err();
        assert!(
            e.contains("unknown metric `flop`") && e.contains("flip_mean"),
            "{e}"
        );
        assert!(Threshold::parse("psnr_db=nan", BoundKind::AtLeast).is_err());
        assert!(
            !Threshold::parse("psnr_db=40", BoundKind::AtLeast)
                .unwrap()
                .holds(f64::NAN)
        );
    }
}
