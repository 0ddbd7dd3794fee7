//! The difference between two images of one size, layer by layer: FLIP, PSNR and SSIM on the
//! colour layers (8-bit sRGB), and the largest and mean absolute error of every channel, in
//! the layer's own units. `seethru diff` and `seethru check` report these.
//!
//! Nothing is dropped silently: a pixel where one image holds a finite value and the other a
//! non-finite one (sky depth is +inf in one and a distance in the other) cannot give an
//! absolute error; it is counted in `nonfinite_mismatch_pixels` and left out of the errors'
//! mean and maximum, and it counts as a differing pixel.

use std::path::{Path, PathBuf};

use anyhow::{Context, Result, bail};
use exr::prelude::FlatSamples;
use serde_json::{Value, json};

use crate::io::run_dir::MAX_RUN_JSON_BYTES;
use crate::measure::image_metrics::{masked_ssim_map, psnr};
use crate::scene::limits::{MAX_PIXELS, MAX_RESOLUTION};
use crate::util::color::{encode_srgb8, luma};
use crate::util::input_file::{not_a_file, read_input_text};
use crate::util::quantile::nearest_rank;

/// Pixels per degree of FLIP's standard observer (0.7 m from a 0.7 m wide 4K monitor), used
/// where the run does not give the driver camera's.
pub const STANDARD_PPD: f32 = 67.0;

/// What the values of a layer are.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum LayerKind {
    /// 8-bit sRGB colour, [0, 255] per channel (a PNG).
    Srgb8,
    /// Linear RGB colour, [0, ∞) per channel (an EXR's `R`, `G`, `B`).
    LinearColour,
    /// Any other channels (depth in m, positions, normals, ids, masks).
    Data,
}

/// One layer of an image: channels that belong together (`P.X`, `P.Y`, `P.Z` → `P`).
pub struct Layer {
    pub name: String,
    pub kind: LayerKind,
    /// Channel names as in the file.
    pub channels: Vec<String>,
    /// Values per channel, row-major, `width × height` each.
    pub values: Vec<Vec<f64>>,
}

/// An image read for comparison.
pub struct Picture {
    pub path: PathBuf,
    pub width: u32,
    pub height: u32,
    pub layers: Vec<Layer>,
}

impl Picture {
    pub fn layer(&self, name: &str) -> Option<&Layer> {
        self.layers.iter().find(|l| l.name == name)
    }

    pub fn layer_names(&self) -> Vec<&str> {
        self.layers.iter().map(|l| l.name.as_str()).collect()
    }
}

/// The layer a channel of an EXR belongs to: `R`, `G`, `B` form `colour`; `P.X` belongs to `P`.
fn layer_of(channel: &str) -> &str {
    match channel {
        "R" | "G" | "B" => "colour",
        _ => channel.rsplit_once('.').map_or(channel, |(layer, _)| layer),
    }
}

fn check_size(width: usize, height: usize) -> Result<()> {
    if width == 0
        || height == 0
        || width > MAX_RESOLUTION as usize
        || height > MAX_RESOLUTION as usize
        || (width as u64) * (height as u64) > MAX_PIXELS
    {
        bail!(
            "the image is {width}×{height}: each side must be in [1, {MAX_RESOLUTION}], at most {MAX_PIXELS} pixels"
        );
    }
    Ok(())
}

/// Reads a PNG (one `colour` layer, 8-bit sRGB) or an EXR (its channels grouped into layers).
/// Errors name the file.
pub fn read_picture(path: &Path) -> Result<Picture> {
    crate::util::input_file::note_input(path);
    if let Some(why) = not_a_file(path) {
        bail!("cannot read {}: {why}", path.display());
    }
    let is_exr = path
        .extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("exr"));
    let picture = if is_exr {
        read_exr_layers(path)
    } else {
        read_png(path)
    };
    picture.with_context(|| format!("cannot read {}", path.display()))
}

fn read_png(path: &Path) -> Result<Picture> {
    let reader = image::ImageReader::open(path)?
        .with_guessed_format()
        .context("not a readable image")?;
    let (w, h) = reader
        .into_dimensions()
        .map_err(|e| anyhow::anyhow!("not a readable PNG: {e}"))?;
    check_size(w as usize, h as usize)?;
    let image = image::ImageReader::open(path)?
        .with_guessed_format()?
        .decode()
        .map_err(|e| anyhow::anyhow!("not a readable PNG: {e}"))?
        .to_rgb8();
    let values = (0..3)
        .map(|c| image.pixels().map(|p| p[c] as f64).collect())
        .collect();
    Ok(Picture {
        path: path.to_path_buf(),
        width: w,
        height: h,
        layers: vec![Layer {
            name: "colour".into(),
            kind: LayerKind::Srgb8,
            channels: ["R", "G", "B"].map(String::from).to_vec(),
            values,
        }],
    })
}

fn read_exr_layers(path: &Path) -> Result<Picture> {
    let file = std::fs::File::open(path)?;
    let meta = exr::meta::MetaData::read_from_unbuffered(file, false)
        .map_err(|e| anyhow::anyhow!("not a readable EXR: {e}"))?;
    let header = meta.headers.first().context("the file has no layer")?;
    check_size(header.layer_size.width(), header.layer_size.height())?;
    let image = crate::io::frame_files::read_first_layer(|r| r.from_file(path))?;
    let layer = &image.layer_data;
    let (width, height) = (layer.size.width() as u32, layer.size.height() as u32);
    let mut layers: Vec<Layer> = Vec::new();
    for channel in &layer.channel_data.list {
        let name = channel.name.to_string();
        let values: Vec<f64> = match &channel.sample_data {
            FlatSamples::F16(v) => v.iter().map(|x| x.to_f64()).collect(),
            FlatSamples::F32(v) => v.iter().map(|&x| x as f64).collect(),
            FlatSamples::U32(v) => v.iter().map(|&x| x as f64).collect(),
        };
        let layer_name = layer_of(&name).to_string();
        match layers.iter_mut().find(|l| l.name == layer_name) {
            Some(l) => {
                l.channels.push(name);
                l.values.push(values);
            }
            None => layers.push(Layer {
                kind: if layer_name == "colour" {
                    LayerKind::LinearColour
                } else {
                    LayerKind::Data
                },
                name: layer_name,
                channels: vec![name],
                values: vec![values],
            }),
        }
    }
    // The colour channels in R, G, B order (EXR sorts channels by name: B, G, R).
    for l in layers
        .iter_mut()
        .filter(|l| l.kind == LayerKind::LinearColour)
    {
        let mut pairs: Vec<(String, Vec<f64>)> =
            l.channels.drain(..).zip(l.values.drain(..)).collect();
        pairs.sort_by_key(|(n, _)| ["R", "G", "B"].iter().position(|c| c == n));
        (l.channels, l.values) = pairs.into_iter().unzip();
        if l.channels.len() != 3 {
            bail!(
                "the colour layer has channels {} (expected R, G and B)",
                l.channels.join(", ")
            );
        }
    }
    Ok(Picture {
        path: path.to_path_buf(),
        width,
        height,
        layers,
    })
}

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

    /// Each side in [1, MAX_RESOLUTION] and the area at most MAX_PIXELS, every bound
    /// inclusive, each rule refusing alone.
    #[test]
    fn picture_sizes_are_checked_at_their_bounds() {
        let max = MAX_RESOLUTION as usize;
        let tall = (MAX_PIXELS / u64::from(MAX_RESOLUTION)) as usize;
        for (w, h) in [(1, 1), (max, 1), (1, max), (max, tall), (tall, max)] {
            assert!(check_size(w, h).is_ok(), "{w}×{h}");
        }
        for (w, h) in [(0, 1), (1, 0), (max + 1, 1), (1, max + 1), (max, tall + 1)] {
            let e = check_size(w, h).unwrap_err().to_string();
            assert!(e.contains(&format!("{w}×{h}")), "{e}");
        }
    }

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

    /// EXR stores channels sorted by name (B, G, R); the colour layer reads back as R, G, B.
    #[test]
    fn an_exr_colour_layer_reads_as_r_g_b() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("c.exr");
        let channel =
            |name: &str, v: f32| exr::prelude::AnyChannel::new(name, FlatSamples::F32(vec![v; 2]));
        let channels = vec![channel("R", 1.0), channel("G", 2.0), channel("B", 3.0)];
        crate::io::frame_files::write_exr_channels(&path, 2, 1, channels).unwrap();
        let picture = read_picture(&path).unwrap();
        let colour = picture.layers.iter().find(|l| l.name == "colour").unwrap();
        assert_eq!(colour.channels, ["R", "G", "B"]);
        assert_eq!(colour.values, [vec![1.0; 2], vec![2.0; 2], vec![3.0; 2]]);
    }

    #[test]
    fn channels_group_into_layers() {
        assert_eq!(layer_of("R"), "colour");
        assert_eq!(layer_of("P.X"), "P");
        assert_eq!(layer_of("camera_z.Z"), "camera_z");
        assert_eq!(layer_of("Z"), "Z");
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
