//! Compensation methods side by side on one scene: the same eye, the same truth and the same
//! metrics for each, as one table (Markdown, JSON, HTML) and one image strip per method.

use anyhow::Result;
use serde_json::json;

use crate::measure::maps::{heat_color, p99_top};
use crate::measure::measured_run::{MeasureSettings, MeasuredRun, measure_run};
use crate::measure::metrics::MetricMaps;
use crate::render::frame::Frame;
use crate::render::integrator::RenderContext;
use crate::render::render_job::RenderJob;
use crate::render::settings::RenderSettings;
use crate::render::views::View;
use crate::system::depth_sensor::SensorKind;
use crate::system::options::{HeadSource, Method, RunOptions, WorkingDistance};
use crate::system::pipeline::{check_display_seen, driver_camera, run_with_truth};
use crate::system::reads::{ReadWhen, scene_model_reads};
use crate::system::scene_model::{check_scene_model_options, scene_model_unavailable};
use crate::util::color::encode_srgb8;
use crate::util::progress::Progress;

/// A method as `compare` names it: the method with its working distance or depth sensor.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum Candidate {
    /// The whole frontal image scaled into the display.
    None,
    /// The paper's planar model, d2 → ∞.
    PlanarInf,
    /// The planar model at the median frontal depth where the display is.
    PlanarAuto,
    /// A plane fitted to the ideal depth sensor's points.
    PlaneFit,
    /// The road plane, d2 → ∞ above the horizon.
    Ground,
    /// Per-pixel reprojection with the frontal render's exact depth.
    DepthIdeal,
    /// Per-pixel reprojection with the time-of-flight sensor's depth.
    DepthTof,
    /// Per-pixel reprojection with the stereo sensor's depth.
    DepthStereo,
}

/// `compare`'s rules (`seethru compare`, `seethru.compare`): the settings no listed method
/// reads. `candidates` are the built-in methods listed, `maps` whether an outside method's
/// map is listed too, `options` the run options given.
pub fn compare_reads(candidates: &[Candidate], maps: bool, options: &RunOptions) -> Vec<ReadWhen> {
    use Candidate::{DepthIdeal, DepthStereo, DepthTof, PlaneFit};
    let any = |these: &[Candidate]| candidates.iter().any(|c| these.contains(c));
    let mut rules = scene_model_reads(
        any(&[PlaneFit, DepthIdeal, DepthTof, DepthStereo]),
        any(&[PlaneFit, DepthIdeal]),
        any(&[DepthIdeal, DepthTof, DepthStereo]),
        "when option `methods` lists plane-fit or a depth method (the sensor's kind: plane-fit or depth-ideal)",
        "when option `methods` lists a depth method (their disocclusion holes)",
    );
    let noisy_kind = options.scene_model.sensor.kind != SensorKind::Ideal;
    rules.push(ReadWhen {
        option: "seed",
        read: any(&[PlaneFit, DepthTof, DepthStereo])
            || (noisy_kind && any(&[DepthIdeal]))
            || options.head == HeadSource::Model,
        when: "with option `head` model (the tracker model's noise and dropouts) or when option `methods` lists plane-fit or a noisy depth sensor",
    });
    rules.push(ReadWhen {
        option: "back_width",
        read: options.head == HeadSource::Estimated || maps,
        when: "with option `head` estimated or a map: method (the back camera is rendered for the face detector and for the capture a map is checked against)",
    });
    rules
}

impl Candidate {
    pub fn name(self) -> &'static str {
        match self {
            Candidate::None => "none",
            Candidate::PlanarInf => "planar-inf",
            Candidate::PlanarAuto => "planar-auto",
            Candidate::PlaneFit => "plane-fit",
            Candidate::Ground => "ground",
            Candidate::DepthIdeal => "depth-ideal",
            Candidate::DepthTof => "depth-tof",
            Candidate::DepthStereo => "depth-stereo",
        }
    }

    /// `base` with this method (and its working distance or sensor kind).
    pub fn options(self, base: &RunOptions) -> RunOptions {
        let mut o = base.clone();
        let (method, d2, sensor) = match self {
            Candidate::None => (Method::None, WorkingDistance::Infinity, None),
            Candidate::PlanarInf => (Method::Planar, WorkingDistance::Infinity, None),
            Candidate::PlanarAuto => (Method::Planar, WorkingDistance::Auto, None),
            Candidate::PlaneFit => (Method::PlaneFit, WorkingDistance::Infinity, None),
            Candidate::Ground => (Method::Ground, WorkingDistance::Infinity, None),
            Candidate::DepthIdeal => (Method::Depth, WorkingDistance::Infinity, None),
            Candidate::DepthTof => (
                Method::Depth,
                WorkingDistance::Infinity,
                Some(SensorKind::Tof),
            ),
            Candidate::DepthStereo => (
                Method::Depth,
                WorkingDistance::Infinity,
                Some(SensorKind::Stereo),
            ),
        };
        o.method = method;
        o.d2 = d2;
        if let Some(kind) = sensor {
            o.scene_model.sensor.kind = kind;
        }
        o
    }
}

/// One method's row and its strip.
pub struct Compared {
    pub name: String,
    /// The row: metrics and cost (see [`compare`]), or (the method cannot run on the scene)
    /// `reason` and no metrics.
    pub row: serde_json::Value,
    /// The strip before its heatmap is coloured: [`coloured_strips`] puts every method's
    /// strip on one scale. `None` for a method that did not run.
    pub strip: Option<StripDraft>,
}

impl Compared {
    /// The row of a method that cannot run on the scene: its name and why, every metric null.
    pub fn not_run(name: &str, reason: String) -> Self {
        Compared {
            name: name.to_string(),
            row: json!({ "method": name, "reason": reason }),
            strip: None,
        }
    }
}

/// Runs every candidate at `base` on one scene (the truth rendered once, the same for all)
/// and measures each with a border band of `band` display pixels; a hidden hazard pixel
/// counts as shown within `hazard_bound_arcmin` ([`crate::measure::hazard::hazard_frame`]).
pub fn compare(
    ctx: &RenderContext,
    candidates: &[Candidate],
    base: &RunOptions,
    band: u32,
    hazard_bound_arcmin: f64,
) -> Result<Vec<Compared>> {
    let scene = &ctx.scene;
    let settings = RenderSettings {
        spp: base.spp,
        progress: false,
    };
    // Every method's flags are checked before anything is rendered (a bad flag fails the
    // command); a method the scene does not admit (no road for `ground`) gets a row saying so.
    let mut unavailable = Vec::new();
    for &candidate in candidates {
        let options = candidate.options(base);
        let mut reason = None;
        if options.method.models_the_scene() {
            let mut scene = scene.clone();
            scene.frontal = options.sized_frontal(scene.frontal)?;
            check_scene_model_options(&scene, &options)
                .map_err(|e| anyhow::anyhow!("{}: {e:#}", candidate.name()))?;
            reason = scene_model_unavailable(&scene, options.method);
        }
        unavailable.push(reason);
    }
    let progress = Progress::new("compare", candidates.len() + 1, base.progress);
    let driver = driver_camera(scene, base)?;
    let (truth, _) = ctx.render(
        RenderJob::new(&driver, View::Truth.bit())
            .settings(settings)
            .label("truth"),
    );
    progress.advance(1);
    let mut out = Vec::new();
    for (&candidate, reason) in candidates.iter().zip(unavailable) {
        if let Some(reason) = reason {
            out.push(Compared::not_run(candidate.name(), reason));
            progress.advance(1);
            continue;
        }
        let mut options = candidate.options(base);
        options.progress = false;
        // A method that fails on this scene's content (a plane fit with no returns where the
        // display is) gets a row saying why; a display the eye cannot see fails them all.
        let result = match run_with_truth(ctx, &options, Some(&truth)) {
            Ok(result) => result,
            Err(e) if options.method.models_the_scene() => {
                out.push(Compared::not_run(candidate.name(), format!("{e:#}")));
                progress.advance(1);
                continue;
            }
            Err(e) => anyhow::bail!("{}: {e:#}", candidate.name()),
        };
        check_display_seen(ctx, &result.occluded)
            .map_err(|e| anyhow::anyhow!("{}: {e:#}", candidate.name()))?;
        let settings = MeasureSettings {
            band,
            hazard_bound_arcmin,
        };
        let MeasuredRun {
            maps,
            metrics,
            holes,
            hazards,
        } = measure_run(ctx, &options, &result, settings)?;
        let display = &metrics.display;
        let misregistration = &display.misregistration_arcmin;
        let row = json!({
            // Per `hazard = true` object, as `run`'s hazards.json.
            "hazards": hazards,
            "method": candidate.name(),
            "reason": null,
            "misregistration_mean_arcmin": misregistration.mean,
            "misregistration_p95_arcmin": misregistration.p95,
            "border_mean_arcmin": metrics.border.misregistration_arcmin.mean,
            "coverage": metrics.coverage,
            "holes_fraction": metrics.holes.as_ref().map_or(json!(0.0), |h| h["fraction"].clone()),
            "psnr_db": display.psnr_db,
            "ssim": display.ssim,
            "flip_mean": display.flip_mean,
            "ms_per_frame": result.report["timings_s"]["display"].as_f64().map(|s| s * 1e3),
            "d2_m": result.report["d2_m"],
            "scene_model": result.report.get("scene_model"),
            "metrics": metrics.to_json(),
        });
        out.push(Compared {
            name: candidate.name().to_string(),
            row,
            strip: Some(strip(
                &maps,
                &result.truth,
                &result.seethru,
                holes.as_deref(),
            )),
        });
        progress.advance(1);
    }
    progress.finish();
    Ok(out)
}

/// An RGB8 image: width, height, bytes.
pub type Rgb8Image = (u32, u32, Vec<u8>);

/// Every row's strip (truth | seethru | misregistration | holes over the display's bounding
/// box, and the heatmap's colour bar), RGB8 as (width, height, bytes), all on one scale
/// that none saturates; `None` for a row that did not run.
pub fn coloured_strips(rows: &[Compared]) -> Result<Vec<Option<Rgb8Image>>> {
    let drafts: Vec<&StripDraft> = rows.iter().filter_map(|r| r.strip.as_ref()).collect();
    let top = shared_heat_top(&drafts);
    rows.iter()
        .map(|r| r.strip.as_ref().map(|d| finish_strip(d, top)).transpose())
        .collect()
}

/// A strip before its heatmap panel is coloured: the misregistration of each of that
/// panel's pixels (by byte offset in `rgb`), so that every method's strip can share one
/// scale that none saturates.
pub struct StripDraft {
    width: u32,
    height: u32,
    rgb: Vec<u8>,
    heat: Vec<(usize, f32)>,
}

/// Colours of the heatmap panel that are not on its scale.
const BLANK: [u8; 3] = [0, 0, 0];
const NO_DIRECTION: [u8; 3] = [40, 40, 40];
const HOLE: [u8; 3] = [255, 0, 255];

/// The shared scale of the strips' heatmaps: the largest 99th percentile of any method's
/// misregistration, rounded up to a multiple of 10 arc-minutes (at least 10).
fn shared_heat_top(drafts: &[&StripDraft]) -> f32 {
    let top = drafts
        .iter()
        .map(|d| p99_top(d.heat.iter().map(|h| h.1)))
        .fold(0.0f32, f32::max);
    ((top / 10.0).ceil() * 10.0).max(10.0)
}

/// The strip with its heatmap coloured on the scale 0 to `top` arc-minutes, beside the
/// labelled colour bar and the legend of the special colours.
fn finish_strip(draft: &StripDraft, top: f32) -> Result<(u32, u32, Vec<u8>)> {
    let mut rgb = draft.rgb.clone();
    for &(o, v) in &draft.heat {
        rgb[o..o + 3].copy_from_slice(&heat_color(v / top));
    }
    let bar = crate::io::colour_bar::ColourBar {
        colours: heat_color,
        bottom: 0.0,
        top: top as f64,
        unit: "′",
        title: "arcmin, one scale for all".into(),
        legend: vec![
            (BLANK, "blank".into()),
            (NO_DIRECTION, "no direction".into()),
            (HOLE, "hole (4th panel)".into()),
        ],
        clipped: true,
    };
    crate::io::colour_bar::with_colour_bar(draft.width, draft.height, &rgb, &bar)
}

/// Truth, seethru, the misregistration heatmap and the holes, side by side, each cut to the
/// display's bounding box; the heatmap is coloured later, on the scale shared by every
/// method ([`finish_strip`]).
pub(crate) fn strip(
    maps: &MetricMaps,
    truth: &Frame,
    seethru: &Frame,
    holes: Option<&[bool]>,
) -> StripDraft {
    const GAP: usize = 4;
    let w = maps.width as usize;
    let (mut x0, mut y0, mut x1, mut y1) = (usize::MAX, usize::MAX, 0, 0);
    for i in (0..maps.display.len()).filter(|&i| maps.display[i]) {
        let (x, y) = (i % w, i / w);
        (x0, y0, x1, y1) = (x0.min(x), y0.min(y), x1.max(x + 1), y1.max(y + 1));
    }
    if x0 >= x1 {
        (x0, y0, x1, y1) = (0, 0, w, maps.height as usize);
    }
    let (bw, bh) = (x1 - x0, y1 - y0);
    let panels = 4;
    let sw = panels * bw + (panels - 1) * GAP;
    let mut rgb = vec![255u8; sw * bh * 3];
    let mut heat_values = Vec::new();
    for y in 0..bh {
        for x in 0..bw {
            let i = (y0 + y) * w + x0 + x;
            let heat = if maps.blank[i] {
                BLANK
            } else if maps.misregistration[i].is_finite() {
                heat_values.push(((y * sw + 2 * (bw + GAP) + x) * 3, maps.misregistration[i]));
                BLANK
            } else {
                NO_DIRECTION
            };
            let hole = match holes {
                Some(h) if h[i] => HOLE,
                _ if maps.display[i] => [60, 60, 60],
                _ => [0, 0, 0],
            };
            let colours = [
                encode_srgb8(truth.color[i]),
                encode_srgb8(seethru.color[i]),
                heat,
                hole,
            ];
            for (k, c) in colours.iter().enumerate() {
                let o = (y * sw + k * (bw + GAP) + x) * 3;
                rgb[o..o + 3].copy_from_slice(c);
            }
        }
    }
    StripDraft {
        width: sw as u32,
        height: bh as u32,
        rgb,
        heat: heat_values,
    }
}

/// The table as Markdown: one row per method.
pub fn markdown_table(rows: &[Compared]) -> String {
    // One visibility column per hazard object (the same objects in every row).
    let hazards = |r: &Compared| {
        r.row["hazards"]["objects"]
            .as_array()
            .cloned()
            .unwrap_or_default()
    };
    // The hazard objects are the same in every row that ran.
    let names: Vec<String> = rows
        .iter()
        .find(|r| r.strip.is_some())
        .map_or(Vec::new(), |r| {
            hazards(r)
                .iter()
                .map(|h| h["name"].as_str().unwrap_or("?").to_string())
                .collect()
        });
    let mut s = String::from(
        "| method | mean ′ | p95 ′ | border ′ | coverage | holes | PSNR dB | SSIM | FLIP | ms/frame |",
    );
    for n in &names {
        s += &format!(" {n} visibility | {n} centroid ′ |");
    }
    s += " not run because |";
    s += "\n|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|";
    s += &"---:|---:|".repeat(names.len());
    s += "---|";
    s += "\n";
    for r in rows {
        let v = &r.row;
        let mut extra = String::new();
        for h in hazards(r) {
            let g = |key: &str, digits: usize| {
                h[key]
                    .as_f64()
                    .map_or("—".to_string(), |x| format!("{x:.digits$}"))
            };
            extra += &format!(
                " {} | {} |",
                g("visibility", 3),
                g("centroid_error_arcmin", 1)
            );
        }
        if r.strip.is_none() {
            extra += &" — | — |".repeat(names.len());
        }
        // A `|` in a reason would split its cell.
        let reason = v["reason"].as_str().unwrap_or("").replace('|', "/");
        extra += &format!(" {reason} |");
        let f = |key: &str, digits: usize| {
            v[key]
                .as_f64()
                .map_or("—".to_string(), |x| format!("{x:.digits$}"))
        };
        s += &format!(
            "| {} | {} | {} | {} | {} | {} | {} | {} | {} | {} |{extra}\n",
            r.name,
            f("misregistration_mean_arcmin", 1),
            f("misregistration_p95_arcmin", 1),
            f("border_mean_arcmin", 1),
            f("coverage", 3),
            f("holes_fraction", 3),
            f("psnr_db", 1),
            f("ssim", 3),
            f("flip_mean", 3),
            f("ms_per_frame", 1),
        );
    }
    s
}

/// A self-contained HTML page: the table (from the Markdown) and each strip (by file name).
pub fn html_page(title: &str, table_md: &str, strips: &[(&str, String)]) -> String {
    let mut html = String::new();
    let parser = pulldown_cmark::Parser::new_ext(table_md, pulldown_cmark::Options::ENABLE_TABLES);
    pulldown_cmark::html::push_html(&mut html, parser);
    let mut page = format!(
        "<!DOCTYPE html>\n<html><head><meta charset=\"utf-8\"><title>{title}</title>\n<style>body{{font-family:sans-serif;margin:2em}}table{{border-collapse:collapse}}td,th{{border:1px solid #ccc;padding:4px 8px}}img{{max-width:100%}}</style></head><body>\n<h1>{title}</h1>\n{html}<p>Strips: truth | seethru | misregistration (0–60′, Turbo; black: blank) | holes (magenta).</p>\n"
    );
    for (name, file) in strips {
        page += &format!("<h2>{name}</h2>\n<img src=\"{file}\" alt=\"{name}\">\n");
    }
    page += "</body></html>\n";
    page
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Whether `compare --methods <candidates>` reads `--seed` under `options`.
    fn seed_read(candidates: &[Candidate], options: &RunOptions) -> bool {
        compare_reads(candidates, false, options)
            .into_iter()
            .find(|r| r.option == "seed")
            .unwrap()
            .read
    }

    #[test]
    fn the_seed_is_read_by_what_draws_noise_and_by_nothing_else() {
        use Candidate::{DepthIdeal, Ground, PlanarInf, PlaneFit};
        let oracle = RunOptions::default();
        let mut tof = RunOptions::default();
        tof.scene_model.sensor.kind = SensorKind::Tof;
        let model = RunOptions {
            head: HeadSource::Model,
            ..RunOptions::default()
        };
        // depth-ideal draws noise only from a noisy sensor kind.
        assert!(!seed_read(&[DepthIdeal], &oracle));
        assert!(seed_read(&[DepthIdeal], &tof));
        // A noisy kind alone, for methods that read no sensor, draws nothing.
        assert!(!seed_read(&[Ground, PlanarInf], &tof));
        // The tracker model draws its noise and dropouts for any method.
        assert!(seed_read(&[Ground], &model));
        assert!(seed_read(&[PlaneFit], &oracle));
    }
    use glam::Vec3;

    const WHITE: [u8; 3] = [255, 255, 255];

    /// A 5 × 4 view whose display is (1,1), (2,1), (3,1), (1,2) and (3,2) (bounding box
    /// x 1..=3, y 1..=2): misregistration 5′ at (1,1), 20′ at (2,1) and 1′ at (3,2), (3,1)
    /// blank, (1,2) without a direction; holes at (3,2) and at (0,0), outside the display.
    fn view() -> (MetricMaps, Frame, Frame, Vec<bool>) {
        let (w, n) = (5, 20);
        let at = |x: usize, y: usize| y * w + x;
        let mut display = vec![false; n];
        for (x, y) in [(1, 1), (2, 1), (3, 1), (1, 2), (3, 2)] {
            display[at(x, y)] = true;
        }
        let mut misregistration = vec![f32::NAN; n];
        misregistration[at(1, 1)] = 5.0;
        misregistration[at(2, 1)] = 20.0;
        misregistration[at(3, 2)] = 1.0;
        let mut blank = vec![false; n];
        blank[at(3, 1)] = true;
        let maps = MetricMaps::of_masks([5, 4], misregistration, display, blank);
        let (mut truth, mut seethru) = (Frame::new(5, 4), Frame::new(5, 4));
        for i in 0..n {
            let v = i as f32 / n as f32;
            truth.color[i] = Vec3::splat(v);
            seethru.color[i] = Vec3::new(0.0, v, 1.0);
        }
        let mut holes = vec![false; n];
        holes[at(3, 2)] = true;
        holes[at(0, 0)] = true;
        (maps, truth, seethru, holes)
    }

    /// Four panels of the 3 × 2 bounding box, 4 white pixels apart (24 × 2): truth,
    /// seethru, the heatmap (its values kept for later, at their pixels' bytes) and holes.
    #[test]
    fn the_strip_cuts_each_panel_to_the_displays_box() {
        let (maps, truth, seethru, holes) = view();
        let d = strip(&maps, &truth, &seethru, Some(&holes));
        assert_eq!((d.width, d.height), (24, 2));
        let pixel = |x: usize, y: usize| {
            let o = (y * 24 + x) * 3;
            [d.rgb[o], d.rgb[o + 1], d.rgb[o + 2]]
        };
        let srgb = |f: &Frame, x: usize, y: usize| encode_srgb8(f.color[y * 5 + x]);
        assert_eq!(pixel(0, 0), srgb(&truth, 1, 1));
        assert_eq!(pixel(2, 1), srgb(&truth, 3, 2));
        assert_eq!(pixel(7, 0), srgb(&seethru, 1, 1));
        assert_eq!(pixel(9, 1), srgb(&seethru, 3, 2));
        // The heatmap: black until coloured, blank black, no direction dark grey.
        assert_eq!([pixel(14, 0), pixel(16, 0)], [BLANK, BLANK]);
        assert_eq!([pixel(14, 1), pixel(15, 1)], [NO_DIRECTION; 2]);
        let heat = [((14, 0), 5.0), ((15, 0), 20.0), ((16, 1), 1.0)];
        let want: Vec<(usize, f32)> = heat
            .iter()
            .map(|&((x, y), v)| ((y * 24 + x) * 3, v))
            .collect();
        assert_eq!(d.heat, want);
        // Holes magenta, the display's other pixels grey, the rest black.
        assert_eq!(
            [pixel(21, 0), pixel(23, 1), pixel(22, 1)],
            [[60; 3], HOLE, [0; 3]]
        );
        for (x, y) in [(3, 0), (6, 1), (13, 0), (17, 1), (20, 0)] {
            assert_eq!(pixel(x, y), WHITE, "({x}, {y})");
        }
        // Without holes, the fourth panel is only the display.
        let d = strip(&maps, &truth, &seethru, None);
        assert_eq!(d.rgb[(24 + 23) * 3], 60);
        // No display pixel: the whole view.
        let mut none = maps;
        none.display = vec![false; 20];
        let d = strip(&none, &truth, &seethru, None);
        assert_eq!((d.width, d.height), (4 * 5 + 3 * 4, 4));
    }

    /// The shared top is the largest p99 of any strip, rounded up to ten arc-minutes, ten at
    /// least; each heatmap pixel is coloured by its value over it.
    #[test]
    fn strips_share_a_top_rounded_up_to_ten_arcmin() {
        let draft = |heat: Vec<f32>| StripDraft {
            width: 1,
            height: 1,
            rgb: vec![0; 3],
            heat: heat.into_iter().map(|v| (0, v)).collect(),
        };
        // p99 of 100 values is the largest (rank ⌊0.99 · 100⌋ of 0…99).
        let steep = draft((1..=100).map(|k| 0.23 * k as f32).collect());
        let flat = draft(vec![3.0; 100]);
        let (thirty, just_over) = (draft(vec![30.0]), draft(vec![30.5]));
        assert_eq!(shared_heat_top(&[&steep, &flat]), 30.0);
        assert_eq!(shared_heat_top(&[&flat]), 10.0);
        assert_eq!(shared_heat_top(&[&draft(Vec::new())]), 10.0);
        assert_eq!(shared_heat_top(&[&flat, &thirty]), 30.0);
        assert_eq!(shared_heat_top(&[&just_over, &flat]), 40.0);

        let (maps, truth, seethru, holes) = view();
        let d = strip(&maps, &truth, &seethru, Some(&holes));
        let (w, _, rgb) = finish_strip(&d, 40.0).unwrap();
        assert!(w > 24);
        let pixel = |x: usize, y: usize| {
            let o = (y * w as usize + x) * 3;
            [rgb[o], rgb[o + 1], rgb[o + 2]]
        };
        assert_eq!(pixel(14, 0), heat_color(5.0 / 40.0));
        assert_eq!(pixel(15, 0), heat_color(20.0 / 40.0));
        assert_eq!(pixel(16, 1), heat_color(1.0 / 40.0));
        assert_eq!(pixel(0, 0), encode_srgb8(truth.color[6]));
    }
}
