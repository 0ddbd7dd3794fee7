//! The viewer: one self-contained HTML page, `view.html`, beside a run's, a sequence's or a
//! compare's outputs, to look at them instead of reading them. The page shows the PNGs beside
//! it (relative paths, so the folder can move); the per-pixel values its readout needs
//! (misregistration, the truth's depth, the ids shown and to be shown) are embedded in it,
//! only over the display's bounding box, as little-endian base64. No server, no network.
//!
//! `run` writes the page from the frames in memory, `seethru view DIR` from the files; both
//! give the same bytes for the same run (tests/viewer.rs).

use std::path::{Path, PathBuf};

use anyhow::{Context, Result, bail};
use base64::Engine;
use serde_json::{Value, json};

use crate::io::atomic::write_text;
use crate::io::frame_files::{FirstLayer, exr_size, read_first_layer};
use crate::measure::maps::{heat_color, p99_top};
use crate::measure::metrics::MetricMaps;
use crate::render::frame::Frame;
use crate::render::frame_over::{Field, FrameView};
use crate::util::input_file::{read_input_json, read_input_text};

/// The page's file name in the folder it shows.
pub const VIEW_FILE: &str = "view.html";

const TEMPLATE: &str = include_str!("viewer/viewer.html");
const DATA_SLOT: &str = "/*SEETHRU_DATA*/";

/// Per-pixel state bits of the readout (`state` in the page).
const ON_DISPLAY: u8 = 1;
const HAS_VALUE: u8 = 2;
const MISSING: u8 = 4;

/// The per-pixel values of a run's driver view that the readout shows, whole-view arrays
/// (row-major, `width × height`).
pub struct RunPixels {
    pub width: u32,
    pub height: u32,
    /// Misregistration, arc-minutes; NaN outside the display and where it has no value.
    pub misregistration: Vec<f32>,
    /// Display pixels whose truth point the frontal camera cannot see.
    pub missing: Vec<bool>,
    /// Pixels where the driver sees the display (`None`: not recorded, as in the
    /// misregistration.exr of runs before the viewer; then the pixels with a value or missing).
    pub display: Option<Vec<bool>>,
    /// The truth's distance along each pixel's ray, metres (+∞ for sky).
    pub truth_depth: Option<Vec<f32>>,
    /// The object the truth shows (`id.object`, 0 sky): what the display should show.
    pub truth_ids: Option<Vec<u32>>,
    /// The object the `seethru` view shows: on the display, what the display shows.
    pub shown_ids: Option<Vec<u32>>,
}

impl RunPixels {
    /// From a run's maps and frames in memory.
    pub fn of_run(maps: &MetricMaps, truth: &Frame, seethru: FrameView) -> RunPixels {
        let ids: Field<u32> = |f| &f.object_id;
        RunPixels {
            width: maps.width,
            height: maps.height,
            misregistration: maps.misregistration.clone(),
            missing: maps.missing.clone(),
            display: Some(maps.display.clone()),
            truth_depth: Some(truth.depth.clone()),
            truth_ids: Some(truth.object_id.clone()),
            shown_ids: Some(
                (0..maps.misregistration.len())
                    .map(|i| seethru.get(ids, i))
                    .collect(),
            ),
        }
    }

    /// From a run folder's `misregistration.exr`, `truth.exr` and `seethru.exr` (the EXRs
    /// without a depth or ids, as `--exr colour` or `none` writes them, leave those out).
    pub fn read(dir: &Path) -> Result<RunPixels> {
        let maps_path = dir.join("misregistration.exr");
        let maps = read_exr_layer(&maps_path)?;
        let (width, height) = layer_size(&maps);
        let mis = f32_channel(&maps, "Y").with_context(|| no_channel(&maps_path, "Y"))?;
        let missing = f32_channel(&maps, "missing.mask")
            .with_context(|| no_channel(&maps_path, "missing.mask"))?;
        let display =
            f32_channel(&maps, "display.mask").map(|d| d.iter().map(|&v| v > 0.5).collect());
        let of_view = |name: &str| -> Result<Option<FirstLayer>> {
            let path = dir.join(format!("{name}.exr"));
            if !path.exists() {
                return Ok(None);
            }
            if exr_size(&path)? != (width, height) {
                bail!(
                    "cannot read {}: its size differs from misregistration.exr's {width}×{height}",
                    path.display()
                );
            }
            read_exr_layer(&path).map(Some)
        };
        let (truth, seethru) = (of_view("truth")?, of_view("seethru")?);
        Ok(RunPixels {
            width,
            height,
            misregistration: mis,
            missing: missing.iter().map(|&m| m > 0.5).collect(),
            display,
            truth_depth: truth.as_ref().and_then(|t| f32_channel(t, "Z")),
            truth_ids: truth.as_ref().and_then(|t| u32_channel(t, "id.object")),
            shown_ids: seethru.as_ref().and_then(|s| u32_channel(s, "id.object")),
        })
    }

    fn state(&self, i: usize) -> u8 {
        let value = self.misregistration[i].is_finite();
        let on_display = match &self.display {
            Some(d) => d[i],
            None => value || self.missing[i],
        };
        let mut s = 0;
        if on_display {
            s |= ON_DISPLAY;
        }
        if value {
            s |= HAS_VALUE;
        }
        if self.missing[i] {
            s |= MISSING;
        }
        s
    }
}

fn no_channel(path: &Path, name: &str) -> String {
    format!(
        "cannot read {}: no channel `{name}` (not a seethru misregistration map?)",
        path.display()
    )
}

fn read_exr_layer(path: &Path) -> Result<FirstLayer> {
    exr_size(path)?;
    let file =
        std::fs::File::open(path).with_context(|| format!("cannot read {}", path.display()))?;
    read_first_layer(|r| r.from_buffered(std::io::BufReader::new(file)))
        .with_context(|| format!("cannot read {}", path.display()))
}

fn layer_size(layer: &FirstLayer) -> (u32, u32) {
    let size = layer.layer_data.size;
    (size.width() as u32, size.height() as u32)
}

fn channel<'a>(layer: &'a FirstLayer, name: &str) -> Option<&'a exr::prelude::FlatSamples> {
    layer
        .layer_data
        .channel_data
        .list
        .iter()
        .find(|c| c.name.to_string() == name)
        .map(|c| &c.sample_data)
}

fn f32_channel(layer: &FirstLayer, name: &str) -> Option<Vec<f32>> {
    match channel(layer, name)? {
        exr::prelude::FlatSamples::F32(v) => Some(v.clone()),
        _ => None,
    }
}

fn u32_channel(layer: &FirstLayer, name: &str) -> Option<Vec<u32>> {
    match channel(layer, name)? {
        exr::prelude::FlatSamples::U32(v) => Some(v.clone()),
        _ => None,
    }
}

/// The bounding box `[x0, y0, w, h]` of the pixels on the display or with a value.
fn display_box(pixels: &RunPixels) -> Option<[u32; 4]> {
    let w = pixels.width as usize;
    let (mut x0, mut y0, mut x1, mut y1) = (u32::MAX, u32::MAX, 0, 0);
    for i in 0..pixels.misregistration.len() {
        if pixels.state(i) != 0 {
            let (x, y) = ((i % w) as u32, (i / w) as u32);
            (x0, y0, x1, y1) = (x0.min(x), y0.min(y), x1.max(x), y1.max(y));
        }
    }
    (x0 <= x1).then(|| [x0, y0, x1 - x0 + 1, y1 - y0 + 1])
}

/// `values` inside `bbox`, row by row, as little-endian base64.
fn boxed<T: Copy>(
    values: &[T],
    width: u32,
    bbox: [u32; 4],
    bytes: impl Fn(T) -> Vec<u8>,
) -> String {
    let [x0, y0, w, h] = bbox;
    let mut out = Vec::new();
    for y in y0..y0 + h {
        let row = (y * width + x0) as usize;
        for &v in &values[row..row + w as usize] {
            out.extend(bytes(v));
        }
    }
    base64::engine::general_purpose::STANDARD.encode(out)
}

/// The heatmap PNG's 256 colours, RGB, base64.
fn heat_lut() -> String {
    let lut: Vec<u8> = (0..256)
        .flat_map(|i| heat_color(i as f32 / 255.0))
        .collect();
    base64::engine::general_purpose::STANDARD.encode(lut)
}

/// The page around `data` (one JSON object): `</` escaped so that no string ends the script.
fn page(data: &Value) -> String {
    let json = serde_json::to_string(data)
        .expect("a JSON value serialises")
        .replace("</", "<\\/");
    TEMPLATE.replacen(DATA_SLOT, &json, 1)
}

/// One image the page shows: its name, file (relative to the page) and size.
fn image_entry(dir: &Path, name: &str, file: &str, driver: bool) -> Result<Option<Value>> {
    let path = dir.join(file);
    if !path.is_file() {
        return Ok(None);
    }
    let (w, h) = image::image_dimensions(&path)
        .with_context(|| format!("cannot read {} (not a PNG?)", path.display()))?;
    Ok(Some(
        json!({"name": name, "file": file, "width": w, "height": h, "driver": driver}),
    ))
}

/// The views of a run folder the page flicks between, in this order: the driver views first.
const RUN_VIEWS: [(&str, bool); 6] = [
    ("truth", true),
    ("seethru", true),
    ("occluded", true),
    ("frontal", false),
    ("back", false),
    ("display", false),
];

/// Writes `out/view.html` for a run (or `score`, `measure`) folder: its views, the
/// misregistration heatmap and the readout from `pixels`; the headline from `out`'s
/// metrics.json; the images, the title, the object names (index i is `id.object` i + 1) and
/// the heatmap's fixed top (`--heatmap-max`, else the p99 like the PNG) from `inputs`' PNGs
/// and run.json (`measure` stages new metrics beside a run's files: `inputs` is the run).
pub fn write_run_view(out: &Path, inputs: &Path, pixels: &RunPixels) -> Result<PathBuf> {
    let metrics_path = out.join("metrics.json");
    let metrics = metrics_path
        .is_file()
        .then(|| read_json(&metrics_path))
        .transpose()?;
    let run_path = inputs.join("run.json");
    let run = run_path
        .is_file()
        .then(|| read_json(&run_path))
        .transpose()?;
    let metrics = metrics.as_ref();
    let title = title_of(run.as_ref(), "run");
    let object_names = run.as_ref().and_then(|r| r.get("object_names"));
    let heat_max = run
        .as_ref()
        .and_then(|r| r["options"]["heatmap_max_arcmin"].as_f64())
        .map(|v| v as f32);
    let mut views = Vec::new();
    for (name, driver) in RUN_VIEWS {
        if let Some(entry) = image_entry(inputs, name, &format!("{name}.png"), driver)? {
            if driver && (entry["width"] != pixels.width || entry["height"] != pixels.height) {
                bail!(
                    "cannot show {}: {name}.png is {}×{}, the misregistration map {}×{}",
                    inputs.display(),
                    entry["width"],
                    entry["height"],
                    pixels.width,
                    pixels.height
                );
            }
            views.push(entry);
        }
    }
    if !views.iter().any(|v| v["driver"] == true) {
        bail!(
            "cannot show {}: no driver view (truth.png, seethru.png or occluded.png)",
            inputs.display()
        );
    }
    let bbox = display_box(pixels);
    let (top, heat_title) = match heat_max {
        Some(t) => (
            t,
            "arc-minutes; top fixed when the run was made".to_string(),
        ),
        None => (
            p99_top(pixels.misregistration.iter().copied()),
            "arc-minutes; top at the display's 99th percentile, like misregistration.png".into(),
        ),
    };
    let w = pixels.width;
    let le_f32 = |v: f32| v.to_le_bytes().to_vec();
    let le_u32 = |v: u32| v.to_le_bytes().to_vec();
    let state: Vec<u8> = (0..pixels.misregistration.len())
        .map(|i| pixels.state(i))
        .collect();
    let per_pixel = |values: Option<String>| values.map_or(Value::Null, Value::String);
    let mut notes = Vec::new();
    if pixels.truth_depth.is_none() || pixels.truth_ids.is_none() {
        notes.push("The readout has no depth or ids: the run's EXRs do not hold them (written with colour only, or none).");
    }
    if pixels.display.is_none() {
        notes.push("This misregistration.exr records no display mask (written before the viewer): the display is taken as its pixels with a value or missing.");
    }
    let data = json!({
        "kind": "run",
        "title": title,
        "subtitle": headline(metrics),
        "width": pixels.width,
        "height": pixels.height,
        "views": views,
        "box": bbox,
        "misregistration": bbox.map(|b| boxed(&pixels.misregistration, w, b, le_f32)),
        "state": bbox.map(|b| boxed(&state, w, b, |s| vec![s])),
        "truth_depth": per_pixel(bbox.zip(pixels.truth_depth.as_ref()).map(|(b, d)| boxed(d, w, b, le_f32))),
        "truth_ids": per_pixel(bbox.zip(pixels.truth_ids.as_ref()).map(|(b, d)| boxed(d, w, b, le_u32))),
        "shown_ids": per_pixel(bbox.zip(pixels.shown_ids.as_ref()).map(|(b, d)| boxed(d, w, b, le_u32))),
        "object_names": object_names,
        "heat_lut": heat_lut(),
        "heat_top": top,
        "heat_title": heat_title,
        "metrics": metrics,
        "notes": notes,
    });
    let path = out.join(VIEW_FILE);
    write_text(&path, &page(&data))?;
    Ok(path)
}

/// The page's title: the command and the scene its record (`record["scene"]`) names.
fn title_of(record: Option<&Value>, command: &str) -> String {
    match record.and_then(|r| r["scene"].as_str()) {
        Some(scene) => format!("seethru {command}: {scene}"),
        None => format!("seethru {command}"),
    }
}

/// The headline a run's metrics.json gives, for the page's subtitle.
fn headline(metrics: Option<&Value>) -> String {
    let Some(m) = metrics else {
        return "no metrics.json".into();
    };
    let d = &m["display"]["misregistration_arcmin"];
    let num = |v: &Value| v.as_f64().map_or("—".to_string(), |v| format!("{v:.2}"));
    format!(
        "misregistration on the display: mean {}′, p95 {}′; coverage {}; {} display pixels",
        num(&d["mean"]),
        num(&d["p95"]),
        m["display"]["coverage"]
            .as_f64()
            .map_or("—".into(), |v| format!("{v:.4}")),
        m["display_pixels"]
    )
}

/// Largest JSON or CSV file the viewer reads (seethru writes far less).
const MAX_TEXT_BYTES: u64 = 64 << 20;

fn read_json(path: &Path) -> Result<Value> {
    read_input_json(path, MAX_TEXT_BYTES)
}

/// Writes `dir/view.html` for a sequence folder: per latency folder (`latency_*` with a
/// `frames.csv`, or the folder itself), its frames' metrics, the plot and the frame images of
/// `--frames png`.
pub fn write_sequence_view(dir: &Path) -> Result<PathBuf> {
    let mut runs: Vec<(String, PathBuf)> = Vec::new();
    if dir.join("frames.csv").is_file() {
        runs.push((".".into(), dir.to_path_buf()));
    }
    let mut entries: Vec<PathBuf> = std::fs::read_dir(dir)
        .with_context(|| format!("cannot read {}", dir.display()))?
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| p.join("frames.csv").is_file())
        .collect();
    entries.sort();
    for path in entries {
        let name = path
            .file_name()
            .expect("a folder entry")
            .to_string_lossy()
            .into_owned();
        runs.push((name, path));
    }
    if runs.is_empty() {
        bail!(
            "cannot show {}: no frames.csv in it or in its folders",
            dir.display()
        );
    }
    let mut latencies = Vec::new();
    for (name, path) in runs {
        let csv = read_input_text(&path.join("frames.csv"), MAX_TEXT_BYTES)?;
        let rows = csv
            .lines()
            .filter(|l| !l.is_empty())
            .count()
            .saturating_sub(1);
        if rows == 0 {
            bail!("cannot show {}: frames.csv has no frame", path.display());
        }
        let first = path.join("frames").join("truth_00000.png");
        let size = first
            .is_file()
            .then(|| image::image_dimensions(&first))
            .transpose()
            .with_context(|| format!("cannot read {}", first.display()))?;
        let preview = path
            .join("preview.png")
            .is_file()
            .then(|| format!("{name}/preview.png"));
        latencies.push(json!({
            "name": name,
            "frames_csv": csv,
            "frame_pngs": size.is_some(),
            "size": size.map(|(w, h)| [w, h]),
            "preview": preview,
        }));
    }
    // Linked, not embedded: its timings would make the page differ from run to run.
    let summary_path = dir.join("summary.json");
    let summary = summary_path
        .is_file()
        .then(|| read_json(&summary_path))
        .transpose()?;
    let data = json!({
        "kind": "sequence",
        "title": title_of(summary.as_ref(), "sequence"),
        "subtitle": format!("{} run(s) of frames; the slider and the plot pick a frame", latencies.len()),
        "latencies": latencies,
        "summary_file": summary.is_some().then_some("summary.json"),
        "heat_lut": heat_lut(),
    });
    let path = dir.join(VIEW_FILE);
    write_text(&path, &page(&data))?;
    Ok(path)
}

/// Writes `dir/view.html` for a compare folder: each method's strip (one scale for all, as
/// compare draws them) with its misregistration and coverage.
pub fn write_compare_view(dir: &Path) -> Result<PathBuf> {
    let table = read_json(&dir.join("compare.json"))?;
    let rows = table["rows"].as_array().with_context(|| {
        format!(
            "cannot read {}: no `rows` (not written by seethru compare?)",
            dir.join("compare.json").display()
        )
    })?;
    let mut methods = Vec::new();
    for row in rows {
        let name = row["method"].as_str().unwrap_or("?");
        let strip = format!("strip_{name}.png");
        let num = |k: &str| {
            row[k]
                .as_f64()
                .map_or("—".to_string(), |v| format!("{v:.2}"))
        };
        let summary = match row["reason"].as_str() {
            Some(reason) if !reason.is_empty() => format!("not run: {reason}"),
            _ => format!(
                "mean {}′ · p95 {}′ · coverage {}",
                num("misregistration_mean_arcmin"),
                num("misregistration_p95_arcmin"),
                num("coverage")
            ),
        };
        methods.push(json!({"name": name, "strip": strip, "summary": summary}));
    }
    let data = json!({
        "kind": "compare",
        "title": title_of(Some(&table), "compare"),
        "subtitle": format!("{} methods", methods.len()),
        "methods": methods,
        "scale_note": "Each strip: truth, seethru, the misregistration heatmap on one scale for all methods, and the holes.",
        "table_html": dir.join("compare.html").is_file().then_some("compare.html"),
        "heat_lut": heat_lut(),
    });
    let path = dir.join(VIEW_FILE);
    write_text(&path, &page(&data))?;
    Ok(path)
}

/// Writes `dir/view.html` for a dataset folder: a grid of its samples (each sample's seethru
/// view, linking to the sample's own viewer), sortable by any column of `manifest.csv`.
pub fn write_dataset_view(dir: &Path) -> Result<PathBuf> {
    let manifest = read_input_text(&dir.join("manifest.csv"), MAX_TEXT_BYTES)?;
    let record_path = dir.join("dataset.json");
    let record = record_path
        .is_file()
        .then(|| read_json(&record_path))
        .transpose()?;
    let samples = manifest
        .lines()
        .filter(|l| !l.is_empty())
        .count()
        .saturating_sub(1);
    let data = json!({
        "kind": "dataset",
        "title": match record.as_ref().and_then(|r| r["spec"].as_str()) {
            Some(spec) => format!("seethru dataset: {spec}"),
            None => "seethru dataset".to_string(),
        },
        "subtitle": format!("{samples} samples; sort by any column; a sample opens its own viewer"),
        "manifest_csv": manifest,
        "heat_lut": heat_lut(),
    });
    let path = dir.join(VIEW_FILE);
    write_text(&path, &page(&data))?;
    Ok(path)
}

/// What an output folder holds, as the viewer sees it.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Outputs {
    Dataset,
    Run,
    Sequence,
    Compare,
}

/// Which viewer `dir` takes; an error names the files looked for.
pub fn outputs_in(dir: &Path) -> Result<Outputs> {
    if !dir.is_dir() {
        bail!("cannot show {}: not a folder", dir.display());
    }
    if dir.join("manifest.csv").is_file() && dir.join("dataset.json").is_file() {
        Ok(Outputs::Dataset)
    } else if dir.join("misregistration.exr").is_file() {
        Ok(Outputs::Run)
    } else if dir.join("compare.json").is_file() {
        Ok(Outputs::Compare)
    } else if dir.join("summary.json").is_file() || dir.join("frames.csv").is_file() {
        Ok(Outputs::Sequence)
    } else {
        bail!(
            "cannot show {}: it holds no seethru outputs (misregistration.exr of run/score/measure, summary.json or frames.csv of sequence, compare.json of compare, manifest.csv of a finished dataset)",
            dir.display()
        )
    }
}

/// Writes the viewer of whatever `dir` holds (`seethru view DIR`).
pub fn write_view(dir: &Path) -> Result<PathBuf> {
    match outputs_in(dir)? {
        Outputs::Run => write_run_view(dir, dir, &RunPixels::read(dir)?),
        Outputs::Sequence => write_sequence_view(dir),
        Outputs::Compare => write_compare_view(dir),
        Outputs::Dataset => write_dataset_view(dir),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn pixels(mis: Vec<f32>, display: Vec<bool>) -> RunPixels {
        let n = mis.len();
        RunPixels {
            width: 4,
            height: (n / 4) as u32,
            misregistration: mis,
            missing: vec![false; n],
            display: Some(display),
            truth_depth: None,
            truth_ids: None,
            shown_ids: None,
        }
    }

    #[test]
    fn the_box_holds_every_display_pixel_and_no_more() {
        let nan = f32::NAN;
        // 4 × 3: display pixels at (1, 0), (2, 1) (blank) and (1, 2).
        let mis = vec![nan, 1.0, nan, nan, nan, nan, nan, nan, nan, 3.0, nan, nan];
        let mut display = vec![false; 12];
        for i in [1, 6, 9] {
            display[i] = true;
        }
        let p = pixels(mis, display);
        assert_eq!(display_box(&p), Some([1, 0, 2, 3]));
        assert_eq!(p.state(6), ON_DISPLAY);
        assert_eq!(p.state(9), ON_DISPLAY | HAS_VALUE);
        let boxed_values = boxed(&p.misregistration, 4, [1, 0, 2, 3], |v: f32| {
            v.to_le_bytes().to_vec()
        });
        let raw = base64::engine::general_purpose::STANDARD
            .decode(boxed_values)
            .unwrap();
        let back: Vec<f32> = raw
            .chunks(4)
            .map(|c| f32::from_le_bytes(c.try_into().unwrap()))
            .collect();
        assert_eq!(back.len(), 6);
        assert_eq!((back[0], back[4]), (1.0, 3.0));
        assert!(back[1].is_nan() && back[2].is_nan() && back[3].is_nan() && back[5].is_nan());
    }

    #[test]
    fn no_display_pixel_gives_no_box() {
        let p = pixels(vec![f32::NAN; 8], vec![false; 8]);
        assert_eq!(display_box(&p), None);
    }

    #[test]
    fn a_string_cannot_close_the_data_script() {
        let html = page(&json!({"kind": "run", "title": "</script><script>alert(1)</script>"}));
        let data = &html[html.find("application/json\">").unwrap()..];
        let end = data.find("</script>").unwrap();
        assert!(!data[..end].contains("alert(1)</"), "{}", &data[..end]);
        let parsed: Value = serde_json::from_str(&data["application/json\">".len()..end]).unwrap();
        assert_eq!(parsed["title"], "</script><script>alert(1)</script>");
    }
}
