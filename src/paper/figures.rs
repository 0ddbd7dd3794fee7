//! The paper's three figures (Fig. 3–5 of §5.1) and a figure of the physical-unit
//! sensitivities, as PNG plots with their data as CSV beside them.

use std::path::Path;

use anyhow::Result;
use plotters::prelude::*;

use crate::analysis::paper::{CropParams, ForeshorteningParams, OcclusionParams, Side};
use crate::analysis::physical;
use crate::io::plot::{Figure, Series};

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
