//! Line plots (PNG, with their data as CSV beside them) drawn with plotters and the bundled
//! font.

use std::fmt::Write as _;
use std::path::Path;

use anyhow::{Context, Result, anyhow};
use plotters::coord::Shift;
use plotters::prelude::*;

use crate::io::atomic::{write_atomically, write_text};

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

const FONT: &[u8] = include_bytes!("../../assets/fonts/DejaVuSans.ttf");
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

/// Fraction of the chart's plotting area, across and up, that a legend of `entries` lines of
/// at most `chars` characters covers (the legend font at 15 px in the 900×600 figure).
fn legend_extent(entries: usize, chars: usize) -> (f64, f64) {
    const PLOT_PX: (f64, f64) = (800.0, 480.0);
    let across = (chars as f64 * 8.5 + 50.0) / PLOT_PX.0;
    let up = (entries as f64 * 22.0 + 16.0) / PLOT_PX.1;
    (across.min(1.0), up.min(1.0))
}

/// The corners a legend may take, in the order preferred when several are free.
const CORNERS: [SeriesLabelPosition; 4] = [
    SeriesLabelPosition::UpperRight,
    SeriesLabelPosition::UpperLeft,
    SeriesLabelPosition::LowerRight,
    SeriesLabelPosition::LowerLeft,
];

impl Figure {
    /// Puts the legend in a corner where no curve, bound or mark passes under it; where every
    /// corner holds data, raises the top of the y range until the upper right corner is
    /// clear. The curves are followed between their points (a line can cross a corner where
    /// it has no point).
    pub fn with_legend_clear_of_data(mut self) -> Self {
        let entries = self.series.iter().filter(|s| !s.dashed).count() + self.bounds.len();
        let chars = self
            .series
            .iter()
            .filter(|s| !s.dashed)
            .map(|s| s.label.chars().count())
            .chain(self.bounds.iter().map(|b| b.1.chars().count()))
            .max()
            .unwrap_or(0);
        let (across, up) = legend_extent(entries, chars);
        let (x0, x1) = self.x_range;
        let mut samples: Vec<(f64, f64)> = Vec::new();
        for series in &self.series {
            for pair in series.points.windows(2) {
                let ((xa, ya), (xb, yb)) = (pair[0], pair[1]);
                if !(ya.is_finite() && yb.is_finite()) {
                    continue;
                }
                samples.extend((0..=32).map(|k| {
                    let t = k as f64 / 32.0;
                    (xa + (xb - xa) * t, ya + (yb - ya) * t)
                }));
            }
            samples.extend(series.points.iter().copied().filter(|p| p.1.is_finite()));
        }
        samples.extend(self.marks.iter().map(|m| (m.0, m.1)));
        for &(y, _) in &self.bounds {
            samples.extend((0..=32).map(|k| (x0 + (x1 - x0) * k as f64 / 32.0, y)));
        }
        let under = |corner: &SeriesLabelPosition, y_range: (f64, f64)| {
            let (y0, y1) = y_range;
            let (left, right) = match corner {
                SeriesLabelPosition::UpperLeft | SeriesLabelPosition::LowerLeft => {
                    (x0, x0 + across * (x1 - x0))
                }
                _ => (x1 - across * (x1 - x0), x1),
            };
            let (bottom, top) = match corner {
                SeriesLabelPosition::LowerLeft | SeriesLabelPosition::LowerRight => {
                    (y0, y0 + up * (y1 - y0))
                }
                _ => (y1 - up * (y1 - y0), y1),
            };
            samples
                .iter()
                .any(|&(x, y)| (left..=right).contains(&x) && (bottom..=top).contains(&y))
        };
        if let Some(free) = CORNERS.iter().find(|c| !under(c, self.y_range)) {
            self.legend = free.clone();
            return self;
        }
        // Every corner holds data: make room above the highest value.
        let highest = samples.iter().map(|p| p.1).fold(self.y_range.0, f64::max);
        let span = (highest - self.y_range.0).max(1e-9);
        self.y_range.1 = self.y_range.0 + span / (1.0 - up).max(0.1) * 1.05;
        self.legend = SeriesLabelPosition::UpperRight;
        self
    }

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
        self.draw(BitMapBackend::with_buffer(&mut buffer, SIZE).into_drawing_area())?;
        Ok(buffer)
    }

    /// Renders the figure as SVG (text as text, lines as paths: sharp at any size).
    pub fn render_svg(&self) -> Result<String> {
        register_font()?;
        let mut svg = String::new();
        self.draw(SVGBackend::with_string(&mut svg, SIZE).into_drawing_area())?;
        Ok(svg)
    }

    /// Draws the figure on any plotters backend.
    fn draw<DB: DrawingBackend>(&self, root: DrawingArea<DB, Shift>) -> Result<()>
    where
        DB::ErrorType: 'static,
    {
        {
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
        Ok(())
    }

    /// Writes `<dir>/<name>.png`, `<dir>/<name>.svg` and `<dir>/<name>.csv`.
    pub fn write(&self, dir: &Path, name: &str) -> Result<()> {
        let rgb = self.render()?;
        let img = image::RgbImage::from_raw(SIZE.0, SIZE.1, rgb).context("plot buffer size")?;
        write_atomically(&dir.join(format!("{name}.png")), |file| {
            Ok(img.write_to(file, image::ImageFormat::Png)?)
        })?;
        write_text(&dir.join(format!("{name}.svg")), &self.render_svg()?)?;
        write_text(&dir.join(format!("{name}.csv")), &self.csv())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn figure(series: Vec<Vec<(f64, f64)>>, y_range: (f64, f64)) -> Figure {
        Figure {
            title: String::new(),
            x_label: String::new(),
            y_label: String::new(),
            x_range: (0.0, 10.0),
            y_range,
            series: series
                .into_iter()
                .enumerate()
                .map(|(i, p)| Series::new(format!("d2 = {i}"), p))
                .collect(),
            bounds: Vec::new(),
            marks: Vec::new(),
            legend: SeriesLabelPosition::UpperRight,
        }
    }

    fn is(a: &SeriesLabelPosition, b: SeriesLabelPosition) -> bool {
        std::mem::discriminant(a) == std::mem::discriminant(&b)
    }

    #[test]
    fn the_legend_goes_to_a_corner_the_curves_leave_free() {
        // Rising from the lower left to the upper right: only the other two corners are free.
        let rising = figure(vec![vec![(0.0, 0.0), (10.0, 10.0)]], (0.0, 10.0));
        let corner = rising.with_legend_clear_of_data().legend;
        assert!(is(&corner, SeriesLabelPosition::UpperLeft), "{corner:?}");
        // Flat near the top (a sweep of means that barely change): a lower corner.
        let flat = figure(vec![vec![(0.0, 9.6), (5.0, 9.8), (10.0, 9.7)]], (0.0, 10.0));
        let corner = flat.with_legend_clear_of_data().legend;
        assert!(is(&corner, SeriesLabelPosition::LowerRight), "{corner:?}");
        // A line whose two points lie outside the x range crosses both upper corners where
        // it has no point: a lower corner.
        let across = figure(vec![vec![(-5.0, 9.5), (15.0, 9.5)]], (0.0, 10.0));
        let corner = across.with_legend_clear_of_data().legend;
        assert!(is(&corner, SeriesLabelPosition::LowerRight), "{corner:?}");
    }

    #[test]
    fn where_every_corner_holds_data_the_y_range_grows_to_clear_the_top() {
        let zigzag: Vec<(f64, f64)> = (0..=20)
            .map(|k| (k as f64 / 2.0, if k % 2 == 0 { 0.0 } else { 10.0 }))
            .collect();
        let f = figure(vec![zigzag], (0.0, 10.0)).with_legend_clear_of_data();
        assert!(is(&f.legend, SeriesLabelPosition::UpperRight));
        let (_, up) = legend_extent(1, "d2 = 0".len());
        // The highest value lies below the legend's bottom edge.
        assert!(10.0 < f.y_range.1 - up * f.y_range.1, "{:?}", f.y_range);
    }
}
