//! A measured sequence on disk: `frames.csv` (one row per frame), the summary, the plots and
//! the animated preview truth | seethru | misregistration.

use std::path::Path;

use anyhow::Result;
use plotters::prelude::SeriesLabelPosition;
use serde_json::json;

use crate::io::animation::write_apng;
use crate::io::caption::{caption_lines, caption_strip, strip_height};
use crate::io::colour_bar::{BAR_COLUMN, ColourBar, with_colour_bar};
use crate::io::plot::{Figure, Series};
use crate::measure::hazard::{HIDDEN_BELOW, HazardSeen, hazard_times};
use crate::measure::maps::{heat_color, p99_top};
use crate::measure::sequence::{FrameImages, SequenceRun};
use crate::measure::sequence_records::{FrameMetrics, FrameRecord};
use crate::system::sequence::timeline::Timeline;
use crate::util::color::encode_srgb8;

/// The columns of `frames.csv`.
pub const FRAME_COLUMNS: [&str; 45] = [
    "frame",
    "t_s",
    "refresh_s",
    "capture_s",
    "head_sample_s",
    "latency_camera_ms",
    "latency_tracking_ms",
    "hold_ms",
    "image_age_ms",
    "head_age_ms",
    "eye_true_x_m",
    "eye_true_y_m",
    "eye_true_z_m",
    "eye_estimated_x_m",
    "eye_estimated_y_m",
    "eye_estimated_z_m",
    "eye_used_x_m",
    "eye_used_y_m",
    "eye_used_z_m",
    "eye_error_mm",
    "vehicle_x_m",
    "vehicle_y_m",
    "vehicle_z_m",
    "vehicle_yaw_deg",
    "d2_m",
    "display_pixels",
    "coverage",
    "misregistration_mean_arcmin",
    "misregistration_p95_arcmin",
    "misregistration_max_arcmin",
    "border_mean_arcmin",
    "psnr_db",
    "ssim",
    "flip",
    "missing_fraction",
    "blank_fraction",
    "eye_x_velocity_m_s",
    "eye_z_velocity_m_s",
    "head_confidence",
    "head_yaw_deg",
    "head_fit_margin",
    "head_yaw_true_deg",
    "frontal_exposure_ms",
    "frontal_gain",
    "frontal_metered",
];

/// The columns of `frames.csv` for each hazard object, after [`FRAME_COLUMNS`], each named
/// `hazard_<object name>_<column>`: its truth pixels, those behind the display, the display's
/// visibility of them, the centroid error (arc-minutes), and the fraction of it the driver
/// sees with the display off and on (docs/guide/hazards.md).
pub const HAZARD_COLUMNS: [&str; 6] = [
    "truth_pixels",
    "hidden_pixels",
    "visibility",
    "centroid_error_arcmin",
    "seen_display_off",
    "seen_display_on",
];

/// `frames.csv`: every number in Rust's shortest round-trip form (the same bytes for any
/// thread count).
pub fn frames_csv(records: &[FrameRecord], timeline: &Timeline) -> Result<String> {
    let mut w = csv::Writer::from_writer(Vec::new());
    // Then, per hazard object (in scene order), HAZARD_COLUMNS prefixed `hazard_<name>_`.
    let names: Vec<String> = records
        .first()
        .map(|r| r.hazards.iter().map(|h| h.frame.name.clone()).collect())
        .unwrap_or_default();
    let mut header: Vec<String> = FRAME_COLUMNS.iter().map(|c| c.to_string()).collect();
    for name in &names {
        header.extend(HAZARD_COLUMNS.iter().map(|c| format!("hazard_{name}_{c}")));
    }
    w.write_record(&header)?;
    for (i, r) in records.iter().enumerate() {
        let t = &r.times;
        let m = r.metrics.unwrap_or(FrameMetrics {
            coverage: f64::NAN,
            mean_arcmin: f64::NAN,
            p95_arcmin: f64::NAN,
            max_arcmin: f64::NAN,
            border_mean_arcmin: f64::NAN,
            psnr_db: f64::NAN,
            ssim: f64::NAN,
            flip: f64::NAN,
            missing_fraction: f64::NAN,
            display_pixels: 0,
        });
        // The eye's velocity over the previous frame (zero for the first).
        let velocity = match i.checked_sub(1).map(|j| &records[j]) {
            Some(p) => (r.eye_true - p.eye_true) / (t.display - p.times.display),
            None => glam::DVec3::ZERO,
        };
        let ms = |s: f64| s * 1e3;
        let values: Vec<String> = [
            t.display,
            t.refresh_time,
            t.capture,
            t.head,
            ms(timeline.latency_camera),
            ms(timeline.latency_tracking),
            ms(t.display - t.refresh_time),
            ms(t.display - t.capture),
            ms(t.display - t.head),
            r.eye_true.x,
            r.eye_true.y,
            r.eye_true.z,
            r.eye_estimated.x,
            r.eye_estimated.y,
            r.eye_estimated.z,
            r.eye_used.x,
            r.eye_used.y,
            r.eye_used.z,
            (r.eye_used - r.eye_true).length() * 1e3,
            r.vehicle_position.x,
            r.vehicle_position.y,
            r.vehicle_position.z,
            r.vehicle_yaw_deg,
            r.d2_used.unwrap_or(f64::INFINITY),
            m.display_pixels as f64,
            m.coverage,
            m.mean_arcmin,
            m.p95_arcmin,
            m.max_arcmin,
            m.border_mean_arcmin,
            m.psnr_db,
            m.ssim,
            m.flip,
            m.missing_fraction,
            1.0 - m.coverage,
            velocity.x,
            velocity.z,
            r.head_confidence.unwrap_or(f64::NAN),
            r.head_pose.map_or(f64::NAN, |p| p.yaw_deg),
            r.head_pose.map_or(f64::NAN, |p| p.margin),
            r.head_yaw_true_deg.unwrap_or(f64::NAN),
            r.frontal_exposure.map_or(f64::NAN, |e| e.exposure_s * 1e3),
            r.frontal_exposure.map_or(f64::NAN, |e| e.gain),
            (r.frontal_exposure.and_then(|e| e.metered)).unwrap_or(f64::NAN),
        ]
        .iter()
        .map(|v| format!("{v}"))
        .collect();
        let mut row = vec![r.frame.to_string()];
        row.extend(values);
        for h in &r.hazards {
            row.extend(
                [
                    h.frame.truth_pixels as f64,
                    h.frame.hidden_pixels as f64,
                    h.frame.visibility,
                    h.frame.centroid_error_arcmin,
                    h.seen_off(),
                    h.seen_on(),
                ]
                .iter()
                .map(|v| format!("{v}")),
            );
        }
        w.write_record(&row)?;
    }
    Ok(String::from_utf8(w.into_inner()?)?)
}

fn mean(values: impl Iterator<Item = f64>) -> f64 {
    let (s, n) = values.fold((0.0, 0usize), |(s, n), v| (s + v, n + 1));
    if n == 0 { f64::NAN } else { s / n as f64 }
}

/// The frames' metrics where some display pixel shows the scene: a frame whose display is
/// dark (between a short persistence's flashes), covered
/// or off screen has no misregistration to average ([`unmeasured_frames`] counts them).
fn measured(run: &SequenceRun) -> impl Iterator<Item = FrameMetrics> + '_ {
    run.records
        .iter()
        .filter_map(|r| r.metrics)
        .filter(|m| m.mean_arcmin.is_finite())
}

/// The frames without a display pixel that shows the scene, left out of the means.
pub fn unmeasured_frames(run: &SequenceRun) -> usize {
    run.records.len() - measured(run).count()
}

/// The means over `run`'s measured frames of their mean and of their p95 misregistration,
/// arc-minutes (NaN without a measured frame): the summary's `mean_of_frame_means` and
/// `mean_of_frame_p95`.
pub fn mean_of_frame_stats(run: &SequenceRun) -> [f64; 2] {
    let m = || measured(run);
    [
        mean(m().map(|x| x.mean_arcmin)),
        mean(m().map(|x| x.p95_arcmin)),
    ]
}

/// The sequence's figures over its frames: means of the per-frame statistics, the extremes,
/// and the coverage they were taken at.
pub fn summary(run: &SequenceRun, timeline: &Timeline) -> serde_json::Value {
    let m: Vec<FrameMetrics> = run.records.iter().filter_map(|r| r.metrics).collect();
    let frames = run.records.len() as f64;
    let [frame_means, frame_p95] = mean_of_frame_stats(run);
    let errors: Vec<f64> = run
        .records
        .iter()
        .map(|r| (r.eye_used - r.eye_true).length() * 1e3)
        .collect();
    json!({
        "frames": run.records.len(),
        "latency_camera_ms": timeline.latency_camera * 1e3,
        "latency_tracking_ms": timeline.latency_tracking * 1e3,
        "misregistration_arcmin": {
            "mean_of_frame_means": frame_means,
            "mean_of_frame_p95": frame_p95,
            "max_of_frame_p95": m.iter().map(|x| x.p95_arcmin).fold(f64::NAN, f64::max),
            "max": m.iter().map(|x| x.max_arcmin).fold(f64::NAN, f64::max),
            "frames_left_out": unmeasured_frames(run),
        },
        "coverage": {
            "mean": mean(m.iter().map(|x| x.coverage)),
            "min": m.iter().map(|x| x.coverage).fold(f64::NAN, f64::min),
        },
        "missing_fraction_mean": mean(m.iter().map(|x| x.missing_fraction)),
        "eye_error_mm": {
            "mean": mean(errors.iter().copied()),
            "max": errors.iter().copied().fold(f64::NAN, f64::max),
        },
        "seconds": {
            "system": run.system,
            "system_total": run.system.total(),
            "truth_and_occluded": run.truth_seconds,
            "metrics": run.metrics_seconds,
            "total": run.total_seconds,
        },
        "frames_per_second": {
            "system_loop": frames / run.system.total(),
            "with_truth_and_metrics": frames / run.total_seconds,
        },
        "frontal_pixels_per_refresh": run.frontal_pixels_per_refresh,
        "window_px": [run.window.x0, run.window.y0, run.window.x1, run.window.y1],
        "hazards": hazards_summary(run, timeline),
        "notes": "per-frame statistics over the display pixels that show the scene (coverage beside them); frames where none does (a display dark between a short persistence's flashes) are left out of the misregistration's means and counted in frames_left_out, and count in the coverage; mean_of_frame_means averages the frames' means; eye_error: the compensation's eye against the true eye at display time",
    })
}

/// The `hazards` block of summary.json: per hazard object, the times of [`hazard_times`].
fn hazards_summary(run: &SequenceRun, timeline: &Timeline) -> serde_json::Value {
    let t: Vec<f64> = run.records.iter().map(|r| r.times.display).collect();
    let seen: Vec<Vec<HazardSeen>> = run.records.iter().map(|r| r.hazards.clone()).collect();
    json!({
        "hidden_below": HIDDEN_BELOW,
        "definition": "per frame, a hazard is hidden from the driver when it is in the rendered view and the driver sees less than hidden_below of its truth pixels (display off: the occluded view shows the same object; display on: the seethru view shows it, within the bound where the display is); first_hidden_s: the first frame hidden with the display off; first_visible_on_display_s: the first frame whose visibility (display pixels shown within the bound / its pixels behind the display) is at least hidden_below; longest_hidden_*_s: the longest run of consecutive hidden frames times the frame period; null: never",
        "frame_period_s": 1.0 / timeline.fps,
        "objects": hazard_times(&t, &seen, 1.0 / timeline.fps),
    })
}

/// Hazard visibility over time: per hazard, the fraction the driver sees with the display
/// on and off, and the display's visibility of what the pillar hides.
pub fn hazard_figure(records: &[FrameRecord], duration: f64) -> Figure {
    let count = records.first().map_or(0, |r| r.hazards.len());
    let mut series = Vec::new();
    for h in 0..count {
        let name = &records[0].hazards[h].frame.name;
        let curve = |label: &str, f: &dyn Fn(&HazardSeen) -> f64| {
            Series::new(
                format!("{name}: {label}"),
                records
                    .iter()
                    // NaN (not in view, nothing hidden) stays: the CSV keeps every row, the
                    // plot skips what is outside its range.
                    .map(|r| (r.times.display, f(&r.hazards[h])))
                    .collect(),
            )
        };
        series.push(curve("seen, display on", &HazardSeen::seen_on));
        series.push(curve("seen, display off", &HazardSeen::seen_off));
        series.push(curve("display visibility", &|s| s.frame.visibility));
    }
    Figure {
        title: "Hazard visibility, frame by frame".into(),
        x_label: "time (s)".into(),
        y_label: "fraction of its pixels".into(),
        x_range: (0.0, duration),
        y_range: (0.0, 1.05),
        series,
        bounds: vec![(HIDDEN_BELOW, "hidden below".into())],
        marks: Vec::new(),
        legend: SeriesLabelPosition::LowerLeft,
    }
}

/// Misregistration over time, one curve per sequence (label, records).
pub fn over_time_figure(sequences: &[(String, &[FrameRecord])], duration: f64) -> Figure {
    let series: Vec<Series> = sequences
        .iter()
        .map(|(label, records)| {
            Series::new(
                label.clone(),
                records
                    .iter()
                    .filter_map(|r| r.metrics.map(|m| (r.times.display, m.mean_arcmin)))
                    .collect(),
            )
        })
        .collect();
    let top = series
        .iter()
        .flat_map(|s| s.points.iter().map(|p| p.1))
        .filter(|v| v.is_finite())
        .fold(1.0, f64::max);
    Figure {
        title: "Mean misregistration over the display, frame by frame".into(),
        x_label: "time (s)".into(),
        y_label: "mean misregistration (arc-minutes)".into(),
        x_range: (0.0, duration),
        y_range: (0.0, top * 1.1),
        series,
        bounds: Vec::new(),
        marks: Vec::new(),
        legend: SeriesLabelPosition::UpperLeft,
    }
}

/// Mean and p95 misregistration against the camera latency: (latency ms, mean, p95).
pub fn latency_figure(points: &[(f64, f64, f64)]) -> Figure {
    let top = points
        .iter()
        .map(|p| p.2)
        .filter(|v| v.is_finite())
        .fold(1.0, f64::max);
    let right = points.iter().map(|p| p.0).fold(1.0, f64::max);
    Figure {
        title: "Misregistration against the camera latency".into(),
        x_label: "capture-to-display latency (ms)".into(),
        y_label: "misregistration (arc-minutes)".into(),
        x_range: (0.0, right * 1.05),
        y_range: (0.0, top * 1.1),
        series: vec![
            Series::new(
                "mean (of frame means)".into(),
                points.iter().map(|p| (p.0, p.1)).collect(),
            ),
            Series::new(
                "p95 (mean of frame p95)".into(),
                points.iter().map(|p| (p.0, p.2)).collect(),
            ),
        ],
        bounds: Vec::new(),
        marks: Vec::new(),
        legend: SeriesLabelPosition::UpperLeft,
    }
}

/// Longest side of a preview panel, pixels.
const PREVIEW_PANEL_MAX: u32 = 320;
/// Highest preview frame rate, Hz (frames beyond it are skipped).
const PREVIEW_MAX_FPS: f64 = 30.0;

/// Collects preview frames (truth | seethru | misregistration, cut to the window around the
/// display) and writes them as an APNG with one colour scale for the whole sequence, drawn as
/// a colour bar right of the panels.
pub struct Preview {
    every: usize,
    fps: f64,
    step: u32,
    size: (u32, u32),
    panels: Vec<PreviewFrame>,
    /// What every frame's caption says besides its time and misregistration (the latency);
    /// `None`: no caption.
    label: Option<String>,
    /// Top of the misregistration scale, arc-minutes (`--heatmap-max`); `None`: the 99th
    /// percentile of every frame's values.
    heat_max: Option<f32>,
}

/// How the preview's misregistration scale was chosen, for summary.json and the bar's title.
pub const PREVIEW_SCALE_FIXED: &str = "fixed (--heatmap-max)";
pub const PREVIEW_SCALE_P99: &str = "p99 of all frames";

/// One preview frame's panels, cut to the window: sRGB truth and seethru, and the
/// misregistration (arc-minutes; NaN on blank display pixels, −∞ outside the display).
struct PreviewFrame {
    truth: Vec<[u8; 3]>,
    shown: Vec<[u8; 3]>,
    misregistration: Vec<f32>,
    /// Display time, s, and the frame's mean misregistration, arc-minutes, for the caption.
    time: f64,
    mean_arcmin: Option<f64>,
}

impl Preview {
    pub fn new(fps: f64) -> Preview {
        let every = (fps / PREVIEW_MAX_FPS).ceil().max(1.0) as usize;
        Preview {
            every,
            fps: fps / every as f64,
            step: 1,
            size: (0, 0),
            panels: Vec::new(),
            label: None,
            heat_max: None,
        }
    }

    /// Fixes the top of the misregistration scale at `top` arc-minutes when given.
    pub fn heat_max(mut self, top: Option<f32>) -> Preview {
        self.heat_max = top;
        self
    }

    /// The top of the misregistration scale, arc-minutes, and how it was chosen: fixed, or
    /// clipped at the 99th percentile of every frame's values so that a few extreme pixels do
    /// not wash out the rest.
    pub fn heat_scale(&self) -> (f32, &'static str) {
        match self.heat_max {
            Some(top) => (top, PREVIEW_SCALE_FIXED),
            None => (
                p99_top(
                    self.panels
                        .iter()
                        .flat_map(|p| p.misregistration.iter().copied()),
                ),
                PREVIEW_SCALE_P99,
            ),
        }
    }

    /// Captions every frame above its panels: its time, `label` (e.g. the latency) and its
    /// mean misregistration.
    pub fn labelled(mut self, label: String) -> Preview {
        self.label = Some(label);
        self
    }

    pub fn add(&mut self, f: &FrameImages) {
        if !f.record.frame.is_multiple_of(self.every) {
            return;
        }
        let w = f.window;
        let (ww, wh) = (w.x1 - w.x0, w.y1 - w.y0);
        self.step = ww.max(wh).div_ceil(PREVIEW_PANEL_MAX).max(1);
        self.size = (ww.div_ceil(self.step), wh.div_ceil(self.step));
        let (mut truth, mut shown, mut mis) = (Vec::new(), Vec::new(), Vec::new());
        for y in (w.y0..w.y1).step_by(self.step as usize) {
            for x in (w.x0..w.x1).step_by(self.step as usize) {
                let i = f.truth.index(x, y);
                truth.push(encode_srgb8(f.truth.color[i]));
                shown.push(encode_srgb8(f.seethru.color[i]));
                mis.push(if f.maps.display[i] {
                    f.maps.misregistration[i]
                } else {
                    f32::NEG_INFINITY
                });
            }
        }
        self.panels.push(PreviewFrame {
            truth,
            shown,
            misregistration: mis,
            time: f.record.times.display,
            mean_arcmin: f.record.metrics.as_ref().map(|m| m.mean_arcmin),
        });
    }

    /// Writes the APNG, the scale's colour bar right of the panels. Returns the scale's top,
    /// arc-minutes, and how it was chosen ([`Preview::heat_scale`]).
    pub fn write(&self, path: &Path) -> Result<(f32, &'static str)> {
        let (top, chosen) = self.heat_scale();
        let (w, h) = self.size;
        let gap = 4;
        let panels_width = 3 * w + 2 * gap;
        // One bar for the whole animation, drawn once and pasted beside every frame.
        let (bar_w, bar_h, bar) = with_colour_bar(
            0,
            h,
            &[],
            &ColourBar {
                colours: heat_color,
                bottom: 0.0,
                top: top as f64,
                unit: "′",
                title: format!("arcmin, {chosen}"),
                legend: vec![([0, 0, 0], "blank".into())],
                clipped: true,
            },
        )?;
        debug_assert_eq!(bar_w, BAR_COLUMN);
        let width = panels_width + bar_w;
        let rows = h.max(bar_h);
        let captions = self.captions(width)?;
        let frames: Vec<Vec<u8>> = self
            .panels
            .iter()
            .map(
                |PreviewFrame {
                     truth,
                     shown,
                     misregistration: mis,
                     ..
                 }| {
                    let mut rgb = vec![255u8; (width * rows * 3) as usize];
                    for y in 0..bar_h {
                        let from = (y * bar_w * 3) as usize;
                        let to = ((y * width + panels_width) * 3) as usize;
                        rgb[to..to + (bar_w * 3) as usize]
                            .copy_from_slice(&bar[from..from + (bar_w * 3) as usize]);
                    }
                    for y in 0..h {
                        for x in 0..w {
                            let i = (y * w + x) as usize;
                            let heat = match mis[i] {
                                v if v.is_finite() => heat_color(v / top),
                                v if v == f32::NEG_INFINITY => {
                                    let g =
                                        (truth[i].iter().map(|&c| c as u32).sum::<u32>() / 6) as u8;
                                    [g, g, g]
                                }
                                // A display pixel without a misregistration: blank.
                                _ => [0, 0, 0],
                            };
                            for (panel, c) in [truth[i], shown[i], heat].into_iter().enumerate() {
                                let o = ((y * width + panel as u32 * (w + gap) + x) * 3) as usize;
                                rgb[o..o + 3].copy_from_slice(&c);
                            }
                        }
                    }
                    rgb
                },
            )
            .collect();
        let (frames, h) = match captions {
            Some((strips, strip_h)) => (
                strips
                    .into_iter()
                    .zip(frames)
                    .map(|(mut strip, frame)| {
                        strip.extend(frame);
                        strip
                    })
                    .collect(),
                rows + strip_h,
            ),
            None => (frames, rows),
        };
        write_apng(path, width, h, &frames, self.fps)?;
        Ok((top, chosen))
    }

    /// Each frame's caption strip (all of one height) and that height; `None` unlabelled.
    fn captions(&self, width: u32) -> Result<Option<(Vec<Vec<u8>>, u32)>> {
        let Some(label) = &self.label else {
            return Ok(None);
        };
        let parts = |p: &PreviewFrame| {
            vec![
                format!("t = {:.3} s", p.time),
                label.clone(),
                match p.mean_arcmin {
                    Some(m) if m.is_finite() => format!("mean misregistration {m:.1}′"),
                    _ => "mean misregistration undefined".to_string(),
                },
            ]
        };
        // One layout for the whole animation: the widest caption decides.
        let lines = self
            .panels
            .iter()
            .map(|p| caption_lines(&parts(p), width).map(|l| l.len()))
            .collect::<Result<Vec<_>>>()?
            .into_iter()
            .max()
            .unwrap_or(1);
        let strips = self
            .panels
            .iter()
            .map(|p| {
                let parts = parts(p);
                let text = if lines == 1 {
                    vec![parts.join("   ")]
                } else {
                    parts
                };
                caption_strip(&text, width)
            })
            .collect::<Result<Vec<_>>>()?;
        Ok(Some((strips, strip_height(lines))))
    }
}
