//! The share of drivers for whom misregistration stays under a bound: from the rows of a
//! `--param eye=eyellipse` sweep (one sampled driver's eye each), with its binomial
//! uncertainty as a Wilson score interval.

use serde_json::{Value, json};

use crate::measure::sweep_csv::decode;
use crate::measure::sweep_grid::Param;

/// The standard normal's 97.5th percentile: a two-sided 95 % interval.
pub const Z_975: f64 = 1.959_963_984_540_054;

/// The Wilson score interval of `k` successes in `n` trials at normal quantile `z`: the
/// binomial proportions that a test at that level would not reject. (0, 1) when `n` is 0.
pub fn wilson_interval(k: usize, n: usize, z: f64) -> (f64, f64) {
    if n == 0 {
        return (0.0, 1.0);
    }
    let (k, n) = (k as f64, n as f64);
    let p = k / n;
    let z2 = z * z;
    let denominator = 1.0 + z2 / n;
    let centre = (p + z2 / (2.0 * n)) / denominator;
    let half = z / denominator * (p * (1.0 - p) / n + z2 / (4.0 * n * n)).sqrt();
    ((centre - half).max(0.0), (centre + half).min(1.0))
}

/// One metric's share of drivers under the bound.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Share {
    /// Drivers whose metric is at most the bound.
    pub under: usize,
    /// Drivers with a metric (the denominator).
    pub counted: usize,
    /// Drivers without one (no display pixel measured: NaN in the CSV), left out of the share.
    pub excluded: usize,
}

impl Share {
    /// Counts the finite values at most `bound`; NaN values are excluded, and counted.
    pub fn of(values: &[f64], bound: f64) -> Share {
        let counted = values.iter().filter(|v| !v.is_nan()).count();
        Share {
            under: values.iter().filter(|v| **v <= bound).count(),
            counted,
            excluded: values.len() - counted,
        }
    }

    pub fn fraction(&self) -> f64 {
        if self.counted == 0 {
            f64::NAN
        } else {
            self.under as f64 / self.counted as f64
        }
    }

    fn json(&self) -> Value {
        let (lo, hi) = wilson_interval(self.under, self.counted, Z_975);
        json!({
            "under_bound": self.under,
            "drivers_counted": self.counted,
            "drivers_excluded_no_metric": self.excluded,
            "share": if self.counted == 0 { Value::Null } else { json!(self.fraction()) },
            "wilson_95": [lo, hi],
        })
    }
}

/// One combination of the other parameters' values and its drivers' mean and p95.
type Group = (Vec<(String, String)>, Vec<f64>, Vec<f64>);

/// For each combination of the parameters other than `eye` (one group when there are none):
/// the shares of drivers whose display mean and p95 misregistration are at most
/// `bound_arcmin`. `rows` are the sweep CSV's data lines; `seed` and `samples` are stated in
/// the result.
pub fn driver_shares(
    params: &[Param],
    rows: &[(usize, String)],
    bound_arcmin: f64,
) -> Option<Value> {
    let eye = params.iter().position(|p| p.name == "eye")?;
    let mean_column = 1 + params.len();
    // (the other parameters' values, each driver's mean, each driver's p95)
    let mut groups: Vec<Group> = Vec::new();
    for (_, line) in rows {
        let fields = decode(line);
        let config: Vec<(String, String)> = params
            .iter()
            .enumerate()
            .filter(|(i, _)| *i != eye)
            .map(|(i, p)| (p.name.clone(), fields[1 + i].clone()))
            .collect();
        let metric = |c: usize| fields[c].parse::<f64>().unwrap_or(f64::NAN);
        let (mean, p95) = (metric(mean_column), metric(mean_column + 1));
        match groups.iter_mut().find(|(c, _, _)| *c == config) {
            Some((_, m, p)) => {
                m.push(mean);
                p.push(p95);
            }
            None => groups.push((config, vec![mean], vec![p95])),
        }
    }
    let samples = params[eye].values.len();
    let seed = params[eye].values[0]
        .split(':')
        .nth(1)
        .unwrap_or("")
        .to_string();
    Some(json!({
        "bound_arcmin": bound_arcmin,
        "samples": samples,
        "seed": seed,
        "eyes": "SAE J941 95th-percentile eyellipse, tangent-cutoff normal (σ = semi-axis / 1.645)",
        "interval": "Wilson score, 95 %",
        "groups": groups.iter().map(|(config, mean, p95)| json!({
            "configuration": config.iter().map(|(n, v)| json!({n: v})).collect::<Vec<_>>(),
            "mean_misregistration": Share::of(mean, bound_arcmin).json(),
            "p95_misregistration": Share::of(p95, bound_arcmin).json(),
        })).collect::<Vec<_>>(),
    }))
}

/// One line per group for the terminal: `82 of 100 drivers (82.0 %, 95 % CI 73.3–88.3 %) ...`.
pub fn summary_lines(shares: &Value) -> Vec<String> {
    let bound = shares["bound_arcmin"].as_f64().unwrap_or(f64::NAN);
    let one = |s: &Value, what: &str| {
        let lo = s["wilson_95"][0].as_f64().unwrap_or(0.0) * 100.0;
        let hi = s["wilson_95"][1].as_f64().unwrap_or(1.0) * 100.0;
        format!(
            "{what} ≤ {bound}′ for {} of {} drivers ({:.1} %, 95 % Wilson interval {lo:.1}–{hi:.1} %; {} without a metric left out)",
            s["under_bound"],
            s["drivers_counted"],
            s["share"].as_f64().unwrap_or(f64::NAN) * 100.0,
            s["drivers_excluded_no_metric"],
        )
    };
    let mut lines = Vec::new();
    for g in shares["groups"].as_array().into_iter().flatten() {
        let config = g["configuration"].to_string();
        let prefix = if config == "[]" {
            String::new()
        } else {
            format!("{config}: ")
        };
        lines.push(format!(
            "{prefix}{}",
            one(&g["mean_misregistration"], "mean misregistration")
        ));
        lines.push(format!(
            "{prefix}{}",
            one(&g["p95_misregistration"], "p95 misregistration")
        ));
    }
    lines
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn wilson_matches_published_values() {
        // Wilson (1927) 95 % intervals as tabulated by Newcombe (1998), Table I.
        let (lo, hi) = wilson_interval(81, 263, Z_975);
        assert!(
            (lo - 0.2553).abs() < 5e-5 && (hi - 0.3662).abs() < 5e-5,
            "{lo} {hi}"
        );
        let (lo, hi) = wilson_interval(15, 148, Z_975);
        assert!(
            (lo - 0.0624).abs() < 5e-5 && (hi - 0.1605).abs() < 5e-5,
            "{lo} {hi}"
        );
        let (lo, hi) = wilson_interval(0, 20, Z_975);
        assert!(lo == 0.0 && (hi - 0.1611).abs() < 5e-5, "{lo} {hi}");
        let (lo, hi) = wilson_interval(1, 29, Z_975);
        assert!(
            (lo - 0.0061).abs() < 5e-5 && (hi - 0.1718).abs() < 5e-5,
            "{lo} {hi}"
        );
    }

    #[test]
    fn drivers_are_grouped_by_the_other_parameters_and_summed_up_per_group() {
        // `eye` first, d2 second: each row's group is its d2, read from its own column.
        let params = [
            crate::measure::sweep_grid::eyellipse_param(3, 7),
            crate::measure::sweep_grid::parse_param("d2=inf,6").unwrap(),
        ];
        let eyes = &params[0].values;
        let means = [
            ("inf", [(0.5, 1.0), (2.0, 3.0), (f64::NAN, f64::NAN)]),
            ("6", [(0.2, 0.9), (0.3, 1.5), (0.4, 2.5)]),
        ];
        let mut rows = Vec::new();
        for (d2, drivers) in means {
            for (eye, (mean, p95)) in eyes.iter().zip(drivers) {
                let index = rows.len();
                let fields = [index.to_string(), eye.to_string(), d2.into()]
                    .into_iter()
                    .chain([mean, p95].map(|v| v.to_string()))
                    .collect::<Vec<_>>();
                rows.push((index, crate::measure::sweep_csv::encode(&fields)));
            }
        }
        let shares = driver_shares(&params, &rows, 1.0).unwrap();
        assert_eq!(
            (shares["samples"].as_u64(), shares["seed"].as_str()),
            (Some(3), Some("7"))
        );
        let groups = shares["groups"].as_array().unwrap();
        let counts = |g: &Value, which: &str| {
            let s = &g[which];
            (
                s["under_bound"].as_u64().unwrap(),
                s["drivers_counted"].as_u64().unwrap(),
            )
        };
        assert_eq!(groups.len(), 2);
        assert_eq!(groups[0]["configuration"], json!([{"d2": "inf"}]));
        assert_eq!(counts(&groups[0], "mean_misregistration"), (1, 2));
        assert_eq!(counts(&groups[0], "p95_misregistration"), (1, 2));
        assert_eq!(groups[1]["configuration"], json!([{"d2": "6"}]));
        assert_eq!(counts(&groups[1], "mean_misregistration"), (3, 3));
        assert_eq!(counts(&groups[1], "p95_misregistration"), (1, 3));
        // The terminal's lines: per group, the mean's then the p95's, in percent.
        let lines = summary_lines(&shares);
        let (lo, hi) = wilson_interval(1, 2, Z_975);
        assert_eq!(lines.len(), 4);
        assert_eq!(
            lines[0],
            format!(
                "[{{\"d2\":\"inf\"}}]: mean misregistration ≤ 1′ for 1 of 2 drivers (50.0 %, 95 % Wilson interval {:.1}–{:.1} %; 1 without a metric left out)",
                100.0 * lo,
                100.0 * hi
            )
        );
        assert!(
            lines[3].starts_with(
                "[{\"d2\":\"6\"}]: p95 misregistration ≤ 1′ for 1 of 3 drivers (33.3 %"
            ),
            "{}",
            lines[3]
        );
    }

    #[test]
    fn nan_rows_are_excluded_and_counted() {
        let s = Share::of(&[0.5, 2.0, f64::NAN, 1.0], 1.0);
        assert_eq!(
            s,
            Share {
                under: 2,
                counted: 3,
                excluded: 1
            }
        );
        assert!((s.fraction() - 2.0 / 3.0).abs() < 1e-15);
    }
}
