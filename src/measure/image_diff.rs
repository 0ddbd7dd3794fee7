//! The difference between two images of one size, layer by layer: FLIP, PSNR and SSIM on the
//! colour layers (8-bit sRGB), and the largest and mean absolute error of every channel, in
//! the layer's own units. `seethru diff` and `seethru check` report these.
//!
//! Nothing is dropped silently: a pixel where one image holds a finite value and the other a
//! non-finite one (sky depth is +inf in one and a distance in the other) cannot give an
//! absolute error; it is counted in `nonfinite_mismatch_pixels` and left out of the errors'
//! mean and maximum, and it counts as a differing pixel.
//!
//! The images are read into layers by measure/picture_layers.rs; the bounds `--max` and
//! `--min` put on these metrics are measure/diff_thresholds.rs's.

use std::path::Path;

use anyhow::{Result, bail};
use serde_json::{Value, json};

use crate::io::run_dir::MAX_RUN_JSON_BYTES;
use crate::measure::image_metrics::{masked_ssim_map, psnr};
use crate::measure::picture_layers::{Layer, LayerKind, Picture};
use crate::util::color::{encode_srgb8, luma};
use crate::util::input_file::read_input_text;
use crate::util::quantile::nearest_rank;

/// Pixels per degree of FLIP's standard observer (0.7 m from a 0.7 m wide 4K monitor), used
/// where the run does not give the driver camera's.
pub const STANDARD_PPD: f32 = 67.0;

/// The 8-bit sRGB pixels of a colour layer.
fn srgb8(layer: &Layer) -> Vec<[u8; 3]> {
    let n = layer.values[0].len();
    (0..n)
        .map(|i| {
            let [r, g, b] = [0, 1, 2].map(|c| layer.values[c][i]);
            match layer.kind {
                LayerKind::Srgb8 => [r as u8, g as u8, b as u8],
                _ => encode_srgb8(glam::Vec3::new(r as f32, g as f32, b as f32)),
            }
        })
        .collect()
}

/// FLIP per pixel of two 8-bit sRGB images of `width`×`height`, at `ppd` pixels per degree.
pub fn flip_map(a: &[[u8; 3]], b: &[[u8; 3]], width: u32, height: u32, ppd: f32) -> Vec<f32> {
    let bytes = |image: &[[u8; 3]]| image.iter().flatten().copied().collect::<Vec<u8>>();
    nv_flip::flip(
        nv_flip::FlipImageRgb8::with_data(width, height, &bytes(a)),
        nv_flip::FlipImageRgb8::with_data(width, height, &bytes(b)),
        ppd,
    )
    .to_vec()
}

/// The difference of one layer present in both images.
pub struct LayerDiff {
    pub name: String,
    /// The size of the layer compared, pixels.
    pub width: u32,
    pub height: u32,
    /// Metric name → value (names as in [`KNOWN_METRICS`]).
    pub metrics: Vec<(&'static str, f64)>,
    /// FLIP per pixel (colour layers only), for the heatmap.
    pub flip: Option<Vec<f32>>,
    /// Pixels per degree FLIP was computed at, and where that came from.
    pub ppd: Option<(f32, String)>,
}

impl LayerDiff {
    pub fn metric(&self, name: &str) -> Option<f64> {
        self.metrics.iter().find(|(n, _)| *n == name).map(|m| m.1)
    }

    pub fn to_json(&self) -> Value {
        let mut map = serde_json::Map::new();
        for (name, value) in &self.metrics {
            map.insert(name.to_string(), number(*value));
        }
        if let Some((ppd, source)) = &self.ppd {
            map.insert("flip_pixels_per_degree".into(), json!(ppd));
            map.insert("flip_pixels_per_degree_from".into(), json!(source));
        }
        Value::Object(map)
    }
}

/// A JSON number, or the strings `inf`/`-inf`/`nan` (PSNR of identical images is +∞).
pub fn number(v: f64) -> Value {
    if v.is_finite() {
        json!(v)
    } else if v.is_nan() {
        json!("nan")
    } else if v > 0.0 {
        json!("inf")
    } else {
        json!("-inf")
    }
}

/// Every metric a layer diff may give, with what it is: thresholds may name only these.
pub const KNOWN_METRICS: [(&str, &str); 10] = [
    ("flip_mean", "mean FLIP, [0, 1] (colour layers)"),
    (
        "flip_p95",
        "95th percentile of FLIP, [0, 1] (colour layers)",
    ),
    ("flip_max", "largest FLIP, [0, 1] (colour layers)"),
    (
        "psnr_db",
        "PSNR of the 8-bit sRGB colours, dB (+inf when equal)",
    ),
    ("ssim", "mean SSIM of the luminance, 7×7 windows, [-1, 1]"),
    (
        "max_abs_error",
        "largest |A − B| of any channel, the layer's units",
    ),
    ("mean_abs_error", "mean |A − B| over channels and pixels"),
    ("differing_pixels", "pixels where any channel differs"),
    (
        "differing_fraction",
        "differing pixels over all pixels, [0, 1]",
    ),
    (
        "nonfinite_mismatch_pixels",
        "pixels finite in one image and not in the other (left out of the errors)",
    ),
];

/// The names of [`KNOWN_METRICS`], comma-separated, for messages.
pub fn known_metric_names() -> String {
    KNOWN_METRICS.map(|m| m.0).join(", ")
}

/// The difference of layer `a` and `b` (same name, size and channels), FLIP at `ppd`.
pub fn diff_layer(
    a: &Layer,
    b: &Layer,
    width: u32,
    height: u32,
    ppd: (f32, String),
) -> Result<LayerDiff> {
    if a.channels != b.channels {
        bail!(
            "layer `{}` has channels {} in one image and {} in the other",
            a.name,
            a.channels.join(", "),
            b.channels.join(", ")
        );
    }
    let pixels = width as usize * height as usize;
    let (mut max_abs, mut sum_abs, mut counted) = (0.0f64, 0.0f64, 0usize);
    let (mut differing, mut nonfinite) = (0usize, 0usize);
    for i in 0..pixels {
        let (mut differs, mut mismatch) = (false, false);
        for c in 0..a.channels.len() {
            let (x, y) = (a.values[c][i], b.values[c][i]);
            let same = x == y || (x.is_nan() && y.is_nan());
            if x.is_finite() && y.is_finite() {
                let d = (x - y).abs();
                max_abs = max_abs.max(d);
                sum_abs += d;
                counted += 1;
            } else if !same {
                mismatch = true;
            }
            differs |= !same;
        }
        differing += differs as usize;
        nonfinite += mismatch as usize;
    }
    let mut metrics = vec![
        ("max_abs_error", max_abs),
        (
            "mean_abs_error",
            if counted == 0 {
                0.0
            } else {
                sum_abs / counted as f64
            },
        ),
        ("differing_pixels", differing as f64),
        ("differing_fraction", differing as f64 / pixels as f64),
        ("nonfinite_mismatch_pixels", nonfinite as f64),
    ];
    let (mut flip, mut flip_ppd) = (None, None);
    if a.kind != LayerKind::Data {
        let (sa, sb) = (srgb8(a), srgb8(b));
        let map = flip_map(&sa, &sb, width, height, ppd.0);
        let mut sorted = map.clone();
        sorted.sort_by(f32::total_cmp);
        let everywhere = vec![true; pixels];
        let lum = |s: &[[u8; 3]]| -> Vec<f64> { s.iter().map(|&c| luma(c)).collect() };
        let ssim = masked_ssim_map(
            &lum(&sa),
            &lum(&sb),
            &everywhere,
            width as usize,
            height as usize,
        );
        metrics.splice(
            0..0,
            [
                (
                    "flip_mean",
                    map.iter().map(|&v| v as f64).sum::<f64>() / pixels as f64,
                ),
                ("flip_p95", nearest_rank(&sorted, 0.95) as f64),
                ("flip_max", sorted[pixels - 1] as f64),
                ("psnr_db", psnr(&sa, &sb, &everywhere)),
                ("ssim", ssim.iter().sum::<f64>() / pixels as f64),
            ],
        );
        flip = Some(map);
        flip_ppd = Some(ppd);
    }
    Ok(LayerDiff {
        name: a.name.clone(),
        width,
        height,
        metrics,
        flip,
        ppd: flip_ppd,
    })
}

/// The layers of two pictures, paired by name: both must have the same size and the same
/// layers (`only`: just the layers named, each present in both).
pub fn paired_layers<'a>(
    a: &'a Picture,
    b: &'a Picture,
    only: &[String],
) -> Result<Vec<(&'a Layer, &'a Layer)>> {
    if (a.width, a.height) != (b.width, b.height) {
        bail!(
            "{} is {}×{} but {} is {}×{}: images of different sizes cannot be compared",
            a.path.display(),
            a.width,
            a.height,
            b.path.display(),
            b.width,
            b.height
        );
    }
    let missing_in = |p: &Picture, name: &str, other: &Picture| {
        anyhow::anyhow!(
            "{} has no layer `{name}` (its layers: {}){}",
            p.path.display(),
            p.layer_names().join(", "),
            if other.layer(name).is_some() {
                format!("; {} has it", other.path.display())
            } else {
                String::new()
            }
        )
    };
    let names: Vec<String> = if only.is_empty() {
        let mut names: Vec<String> = a.layers.iter().map(|l| l.name.clone()).collect();
        for l in &b.layers {
            if !names.contains(&l.name) {
                names.push(l.name.clone());
            }
        }
        names
    } else {
        only.to_vec()
    };
    names
        .iter()
        .map(|name| {
            let la = a.layer(name).ok_or_else(|| missing_in(a, name, b))?;
            let lb = b.layer(name).ok_or_else(|| missing_in(b, name, a))?;
            Ok((la, lb))
        })
        .collect()
}

/// The views of a run rendered from the driver's eye: FLIP sees them with the driver
/// camera's pixels per degree.
pub const DRIVER_VIEWS: [&str; 3] = ["truth", "occluded", "seethru"];

/// FLIP's pixels per degree for an image of view `view` in the run folder `dir`: the
/// driver camera's (metrics.json's `flip_pixels_per_degree`) for the driver's views,
/// else the standard observer's; with where it came from.
pub fn pixels_per_degree(dir: &Path, view: &str) -> (f32, String) {
    let from_run = DRIVER_VIEWS.contains(&view).then(|| {
        let text = read_input_text(&dir.join("metrics.json"), MAX_RUN_JSON_BYTES).ok()?;
        let json: Value = serde_json::from_str(&text).ok()?;
        json["flip_pixels_per_degree"].as_f64()
    });
    match from_run.flatten() {
        Some(ppd) if ppd.is_finite() && ppd > 0.0 => (
            ppd as f32,
            format!("the driver camera ({})", dir.join("metrics.json").display()),
        ),
        _ => (STANDARD_PPD, "the standard observer".into()),
    }
}

/// FLIP's colours (magma, as NVIDIA's FLIP tool shows its error maps).
fn flip_colour(t: f32) -> [u8; 3] {
    colorous::MAGMA
        .eval_continuous(f64::from(t.clamp(0.0, 1.0)))
        .as_array()
}

/// The FLIP map of a colour layer as a heatmap beside its colour bar (0 to 1, not clipped).
pub fn flip_heatmap(flip: &[f32], width: u32, height: u32) -> Result<(u32, u32, Vec<u8>)> {
    let rgb: Vec<u8> = flip.iter().flat_map(|&v| flip_colour(v)).collect();
    let bar = crate::io::colour_bar::ColourBar {
        colours: flip_colour,
        bottom: 0.0,
        top: 1.0,
        unit: "",
        title: "FLIP error, 0 to 1".into(),
        legend: Vec::new(),
        clipped: false,
    };
    crate::io::colour_bar::with_colour_bar(width, height, &rgb, &bar)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A driver view is seen at the driver camera's pixels per degree, read from the run's
    /// metrics.json when it is a positive number; any other view, no file, or a value that
    /// is not a positive number falls back to the standard observer.
    #[test]
    fn flip_sees_a_runs_driver_views_at_its_cameras_pixels_per_degree() {
        let dir = tempfile::tempdir().unwrap();
        let ppd = |view| pixels_per_degree(dir.path(), view);
        let standard = (STANDARD_PPD, "the standard observer".to_string());
        assert_eq!(ppd("truth"), standard);
        let write = |value: &str| {
            let json = format!("{{\"flip_pixels_per_degree\": {value}}}");
            std::fs::write(dir.path().join("metrics.json"), json).unwrap();
        };
        write("41.5");
        for view in DRIVER_VIEWS {
            let (value, from) = ppd(view);
            assert_eq!(value, 41.5, "{view}");
            assert!(from.starts_with("the driver camera") && from.contains("metrics.json"));
        }
        for view in ["frontal", "back", "display", "misregistration"] {
            assert_eq!(ppd(view), standard, "{view}");
        }
        for bad in ["0", "-0.0", "-3", "null", "\"41\""] {
            write(bad);
            assert_eq!(ppd("seethru"), standard, "{bad}");
        }
    }

    /// The FLIP heatmap is magma, as NVIDIA's tool shows it: near black at 0, pale yellow
    /// at 1 and beyond (clamped), brighter as the error grows; the colour bar to its right.
    #[test]
    fn the_flip_heatmap_runs_from_black_at_0_to_pale_yellow_at_1() {
        let values = [0.0, 0.25, 0.5, 0.75, 1.0, 3.0];
        let (w, _, rgb) = flip_heatmap(&values, 6, 1).unwrap();
        assert_eq!(w, 6 + crate::io::colour_bar::BAR_COLUMN);
        let px = |i: usize| [rgb[3 * i], rgb[3 * i + 1], rgb[3 * i + 2]];
        let sum = |c: [u8; 3]| c.iter().map(|&v| u32::from(v)).sum::<u32>();
        assert!(sum(px(0)) < 15, "{:?}", px(0));
        let pale = px(4);
        assert!(
            pale[0] > 240 && pale[1] > 240 && pale[2] > 170 && pale[2] < 210,
            "{pale:?}"
        );
        assert_eq!(px(5), pale);
        for i in 1..5 {
            assert!(
                sum(px(i)) > sum(px(i - 1)),
                "{i}: {:?} {:?}",
                px(i - 1),
                px(i)
            );
        }
        // Magma's middle is red-purple: red well above green.
        let mid = px(2);
        assert!(mid[0] > 150 && mid[1] < 80, "{mid:?}");
    }

    fn data_layer(values: Vec<f64>) -> Layer {
        Layer {
            name: "Z".into(),
            kind: LayerKind::Data,
            channels: vec!["Z".into()],
            values: vec![values],
        }
    }

    /// Equal non-finite values (∞ and ∞, NaN and NaN) are the same; a non-finite value
    /// against anything else differs and is a mismatch, left out of the errors.
    #[test]
    fn absolute_errors_count_nonfinite_mismatches_apart() {
        let (inf, nan) = (f64::INFINITY, f64::NAN);
        let a = data_layer(vec![1.0, inf, 3.0, inf, nan, nan, inf, -inf]);
        let b = data_layer(vec![1.5, inf, 5.0, 7.0, 2.0, nan, nan, inf]);
        let d = diff_layer(&a, &b, 4, 2, (STANDARD_PPD, "x".into())).unwrap();
        assert_eq!(d.metric("max_abs_error"), Some(2.0));
        // (0.5 + 2) over the two pixels both finite.
        assert_eq!(d.metric("mean_abs_error"), Some(1.25));
        assert_eq!(d.metric("differing_pixels"), Some(6.0));
        assert_eq!(d.metric("differing_fraction"), Some(0.75));
        assert_eq!(d.metric("nonfinite_mismatch_pixels"), Some(4.0));
        assert_eq!(d.metric("flip_mean"), None);
    }
}
