//! The paper's three figures (Fig. 3–5 of §5.1) and a figure of the physical-unit
//! sensitivities, as PNG plots with their data as CSV beside them.

use std::fmt::Write as _;
use std::path::Path;

use anyhow::{Context, Result, anyhow};
use plotters::prelude::*;

use crate::analysis::{CropParams, ForeshorteningParams, OcclusionParams, Side, physical};
use crate::output::{write_atomically, write_text};

/// One curve of a figure.
pub struct Series {
    pub label: String,
    pub points: Vec<(f64, f64)>,
    /// Drawn dashed (bounds that vary per curve).
    pub dashed: bool,
}

impl Series {
    pub fn new(label: String, points: Vec<(f64, f64)>) -> Self {
        Self {
            label,
            points,
            dashed: false,
        }
    }
}

/// A line plot: curves, dashed horizontal bounds and marked points.
pub struct Figure {
    pub title: String,
    pub x_label: String,
    pub y_label: String,
    pub x_range: (f64, f64),
    pub y_range: (f64, f64),
    pub series: Vec<Series>,
    /// Horizontal dashed lines: (y, label).
    pub bounds: Vec<(f64, String)>,
    /// Points marked on the curves (e.g. the admissible d2): (x, y, curve index).
    pub marks: Vec<(f64, f64, usize)>,
    pub legend: SeriesLabelPosition,
}

const FONT: &[u8] = include_bytes!("../assets/fonts/DejaVuSans.ttf");
const SIZE: (u32, u32) = (900, 600);

pub fn register_font() -> Result<()> {
    plotters::style::register_font("sans-serif", FontStyle::Normal, FONT)
        .map_err(|_| anyhow!("the bundled font is invalid"))
}

fn color(i: usize) -> RGBColor {
    const PALETTE: [RGBColor; 6] = [
        RGBColor(31, 119, 180),
        RGBColor(255, 127, 14),
        RGBColor(44, 160, 44),
        RGBColor(214, 39, 40),
        RGBColor(148, 103, 189),
        RGBColor(140, 86, 75),
    ];
    PALETTE[i % PALETTE.len()]
}

impl Figure {
    /// The data as CSV: one row per x of the first series, one column per series.
    pub fn csv(&self) -> String {
        let mut s = String::from("x");
        for series in &self.series {
            let _ = write!(s, ",{}", series.label.replace(',', ";"));
        }
        s.push('\n');
        let rows = self.series.first().map_or(0, |f| f.points.len());
        for i in 0..rows {
            let _ = write!(s, "{}", self.series[0].points[i].0);
            for series in &self.series {
                let _ = write!(s, ",{}", series.points[i].1);
            }
            s.push('\n');
        }
        s
    }

    /// Renders the figure to an RGB buffer.
    pub fn render(&self) -> Result<Vec<u8>> {
        register_font()?;
        let mut buffer = vec![0u8; (SIZE.0 * SIZE.1 * 3) as usize];
        {
            let root = BitMapBackend::with_buffer(&mut buffer, SIZE).into_drawing_area();
            root.fill(&WHITE).map_err(|e| anyhow!("{e}"))?;
            let mut chart = ChartBuilder::on(&root)
                .caption(&self.title, ("sans-serif", 22))
                .margin(15)
                .x_label_area_size(45)
                .y_label_area_size(65)
                .build_cartesian_2d(
                    self.x_range.0..self.x_range.1,
                    self.y_range.0..self.y_range.1,
                )
                .map_err(|e| anyhow!("{e}"))?;
            chart
                .configure_mesh()
                .x_desc(&self.x_label)
                .y_desc(&self.y_label)
                .label_style(("sans-serif", 15))
                .axis_desc_style(("sans-serif", 17))
                .draw()
                .map_err(|e| anyhow!("{e}"))?;
            let mut curve = 0;
            for series in &self.series {
                let (lo, hi) = self.y_range;
                let visible: Vec<(f64, f64)> = series
                    .points
                    .iter()
                    .copied()
                    .filter(|(_, y)| (lo..=hi).contains(y))
                    .collect();
                if series.dashed {
                    // Same colour as the curve before it, short dashes, no legend entry.
                    let c = color(curve.max(1) - 1);
                    let dashes = visible
                        .chunks(6)
                        .map(|w| PathElement::new(w[..w.len().min(3)].to_vec(), c.stroke_width(1)));
                    chart.draw_series(dashes).map_err(|e| anyhow!("{e}"))?;
                    continue;
                }
                let c = color(curve);
                curve += 1;
                chart
                    .draw_series(LineSeries::new(visible, c.stroke_width(2)))
                    .map_err(|e| anyhow!("{e}"))?
                    .label(&series.label)
                    .legend(move |(x, y)| {
                        PathElement::new(vec![(x, y), (x + 20, y)], c.stroke_width(2))
                    });
            }
            for (y, label) in &self.bounds {
                let dashes = (0..200).map(|k| {
                    let x0 = self.x_range.0 + (self.x_range.1 - self.x_range.0) * k as f64 / 200.0;
                    let x1 = x0 + (self.x_range.1 - self.x_range.0) / 400.0;
                    PathElement::new(vec![(x0, *y), (x1, *y)], BLACK.stroke_width(1))
                });
                chart
                    .draw_series(dashes)
                    .map_err(|e| anyhow!("{e}"))?
                    .label(label)
                    .legend(|(x, y)| {
                        PathElement::new(
                            vec![(x, y), (x + 6, y), (x + 12, y)],
                            BLACK.stroke_width(1),
                        )
                    });
            }
            let inside = |x: f64| (self.x_range.0..=self.x_range.1).contains(&x);
            for &(x, y, i) in self.marks.iter().filter(|m| inside(m.0)) {
                chart
                    .draw_series(std::iter::once(Circle::new((x, y), 6, color(i).filled())))
                    .map_err(|e| anyhow!("{e}"))?;
            }
            chart
                .configure_series_labels()
                .background_style(WHITE.mix(0.85))
                .border_style(BLACK)
                .label_font(("sans-serif", 15))
                .position(self.legend.clone())
                .draw()
                .map_err(|e| anyhow!("{e}"))?;
            root.present().map_err(|e| anyhow!("{e}"))?;
        }
        Ok(buffer)
    }

    /// Writes `<dir>/<name>.png` and `<dir>/<name>.csv`.
    pub fn write(&self, dir: &Path, name: &str) -> Result<()> {
        let rgb = self.render()?;
        let img = image::RgbImage::from_raw(SIZE.0, SIZE.1, rgb).context("plot buffer size")?;
        write_atomically(&dir.join(format!("{name}.png")), |tmp| {
            Ok(img.save_with_format(tmp, image::ImageFormat::Png)?)
        })?;
        write_text(&dir.join(format!("{name}.csv")), &self.csv())
    }
}

/// `n` values from `a` to `b` evenly spaced.
fn linspace(a: f64, b: f64, n: usize) -> Vec<f64> {
    (0..n)
        .map(|i| a + (b - a) * i as f64 / (n - 1) as f64)
        .collect()
}

/// Fig. 3: the left cutting ratio R1 against d2 for several θ_F, with the 0.95·R(∞) bounds
/// and each curve's admissible d2 (d1 = 1, b_h = 0.125, D = 0.5).
pub fn cutting_ratio_figure() -> Figure {
    let d2s = linspace(0.1, 5.0, 491);
    let thetas = [20.0, 40.0, 60.0, 80.0f64];
    let mut fig = Figure {
        title: "Left cutting ratio R1(d2) (d1 = 1 m, b_h = 0.125 m, D = 0.5 m)".into(),
        x_label: "working distance d2 [m]".into(),
        y_label: "R1 [fraction of the frontal image width]".into(),
        x_range: (0.0, 5.0),
        y_range: (0.0, 0.5),
        series: Vec::new(),
        bounds: Vec::new(),
        marks: Vec::new(),
        legend: SeriesLabelPosition::LowerRight,
    };
    for (i, &theta) in thetas.iter().enumerate() {
        let p = |d2| CropParams {
            d1: 1.0,
            d2,
            b_h: 0.125,
            width: 0.5,
            theta_f: theta.to_radians(),
        };
        let points = d2s
            .iter()
            .map(|&d2| (d2, p(d2).cutting_ratio(Side::Left)))
            .collect();
        let bound = 0.95 * p(1.0).cutting_ratio_at_infinity(Side::Left);
        let admissible = p(1.0).d2_min(Side::Left, 0.05).unwrap_or(f64::NAN);
        fig.series.push(Series::new(
            format!("θ_F = {theta}°: d2 > {admissible:.2} m admissible"),
            points,
        ));
        let bound_points = d2s.iter().map(|&d2| (d2, bound)).collect();
        fig.series.push(Series {
            label: format!("0.95·R1(∞) at θ_F = {theta}°"),
            points: bound_points,
            dashed: true,
        });
        fig.marks.push((admissible, bound, i));
    }
    fig
}

/// Fig. 4: the occlusion ratio against d2 for several b1 (d1 = 1, b_h = 0.25, L = 1).
pub fn occlusion_figure() -> Figure {
    let d2s = linspace(1.5, 20.0, 371);
    let series = [0.25, 0.5, 1.0, 2.0, 4.0f64]
        .iter()
        .map(|&b1| {
            let points = d2s
                .iter()
                .map(|&d2| {
                    (
                        d2,
                        OcclusionParams {
                            l: 1.0,
                            b1,
                            d2,
                            d1: 1.0,
                            b_h: 0.25,
                        }
                        .ratio(),
                    )
                })
                .collect();
            Series::new(format!("b1 = {b1} m"), points)
        })
        .collect();
    Figure {
        title: "Occluded widths p_cam / p_user (d1 = 1 m, b_h = 0.25 m, L = 1 m)".into(),
        x_label: "working distance d2 [m]".into(),
        y_label: "p_cam / p_user".into(),
        x_range: (1.5, 20.0),
        y_range: (0.4, 2.0),
        series,
        bounds: vec![(0.95, "0.95".into()), (1.05, "1.05".into())],
        marks: Vec::new(),
        legend: SeriesLabelPosition::UpperRight,
    }
}

/// Fig. 5: the foreshortening ratio against d2 for several l (d1 = 1, b_h = 0.125, b1 = 0.25,
/// γ = 45°).
pub fn foreshortening_figure() -> Figure {
    let d2s = linspace(0.2, 20.0, 397);
    let series = [0.5, 1.0, 2.0, 5.0, 10.0f64]
        .iter()
        .map(|&l| {
            let ratio = |d2| {
                ForeshorteningParams {
                    l,
                    b1: 0.25,
                    d2,
                    d1: 1.0,
                    b_h: 0.125,
                    gamma: 45f64.to_radians(),
                }
                .ratio()
            };
            Series::new(
                format!("l = {l} m"),
                d2s.iter().map(|&d2| (d2, ratio(d2))).collect(),
            )
        })
        .collect();
    Figure {
        title:
            "Foreshortened widths p_cam / p_user (d1 = 1 m, b_h = 0.125 m, b1 = 0.25 m, γ = 45°)"
                .into(),
        x_label: "working distance d2 [m]".into(),
        y_label: "p_cam / p_user".into(),
        x_range: (0.0, 20.0),
        y_range: (-0.5, 1.5),
        series,
        bounds: vec![(0.95, "0.95".into()), (1.05, "1.05".into())],
        marks: Vec::new(),
        legend: SeriesLabelPosition::LowerRight,
    }
}

/// The physical-unit sensitivities: misregistration at the eye, in arc-minutes, for 1 cm of
/// lateral head error and for 1 m of d2 error at the display edge (D = 0.25 m), against d2,
/// for several d1. Neither depends on θ_F.
pub fn physical_figure() -> Figure {
    let d2s = linspace(0.5, 40.0, 396);
    let mut series = Vec::new();
    for &d1 in &[0.6, 0.8, 1.0] {
        let head = d2s.iter().map(|&d2| {
            (
                d2,
                0.01 * physical::per_lateral_head_error(d1, d2) * physical::ARCMIN_PER_RAD,
            )
        });
        series.push(Series::new(
            format!("1 cm head error, d1 = {d1} m"),
            head.collect(),
        ));
        let plane = d2s.iter().map(|&d2| {
            (
                d2,
                physical::per_d2_error(0.125, d1, d2) * physical::ARCMIN_PER_RAD,
            )
        });
        series.push(Series::new(
            format!("1 m d2 error at the edge (D = 0.25 m), d1 = {d1} m"),
            plane.collect(),
        ));
    }
    Figure {
        title: "Misregistration at the driver's eye per unit error (independent of θ_F)".into(),
        x_label: "working distance d2 [m]".into(),
        y_label: "misregistration [arcmin] (1′ ≈ visual acuity)".into(),
        x_range: (0.0, 40.0),
        y_range: (0.0, 70.0),
        series,
        bounds: vec![(1.0, "1′".into())],
        marks: Vec::new(),
        legend: SeriesLabelPosition::UpperRight,
    }
}

/// Writes the four figures and their CSVs into `dir`.
pub fn write_all(dir: &Path) -> Result<Vec<String>> {
    std::fs::create_dir_all(dir).with_context(|| format!("cannot create {}", dir.display()))?;
    let figures = [
        ("fig3_cutting_ratio", cutting_ratio_figure()),
        ("fig4_occlusion", occlusion_figure()),
        ("fig5_foreshortening", foreshortening_figure()),
        ("physical_sensitivity", physical_figure()),
    ];
    for (name, fig) in &figures {
        fig.write(dir, name)?;
    }
    Ok(figures.iter().map(|(n, _)| n.to_string()).collect())
}
