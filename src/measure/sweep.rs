//! `seethru sweep`: the metrics of every combination of parameter values, as CSV and a plot.
//! Configurations render in parallel; the scene's world and BVH are built once per distinct
//! geometry and the truth once per driver's eye, shared by the configurations that have them.
//! The CSV is rewritten whole after every finished configuration, so an interrupted sweep
//! resumes without redoing finished rows.

use std::collections::HashSet;
use std::path::Path;
use std::sync::Mutex;

use anyhow::{Context, Result, bail};
use rayon::prelude::*;

use crate::io::atomic::write_text;
use crate::io::plot::{Figure, Series};
use crate::measure::metrics::measure;
use crate::measure::metrics_json::Metrics;
use crate::measure::sweep_csv::{
    MAX_SWEEP_CSV_BYTES, METRIC_COLUMNS, decode, encode, finished_rows, header,
};
use crate::measure::sweep_grid::{Param, check_grid_size, combinations, configure};
use crate::measure::sweep_shard::{Shard, join};
use crate::render::integrator::{RenderContext, same_geometry};
use crate::render::render_job::RenderJob;
use crate::render::settings::RenderSettings;
use crate::scene::Scene;
use crate::scene::fingerprint::fingerprint;
use crate::scene::world::view_bit;
use crate::system::options::{HeadSource, Outside, RunOptions};
use crate::system::pipeline::{RunResult, driver_camera, run_with_truth};
use crate::util::input_file::{not_a_file, read_input_text};
use crate::util::progress::Progress;

/// A row's metrics, in the order of the CSV's metric columns: the run `result`'s `metrics`.
fn metric_row(metrics: &Metrics, result: &RunResult) -> Vec<f64> {
    let (d, b) = (&metrics.display, &metrics.border);
    let ratios = result.crop.ratios();
    vec![
        d.misregistration_arcmin.mean,
        d.misregistration_arcmin.p95,
        d.misregistration_arcmin.max,
        b.misregistration_arcmin.mean,
        b.misregistration_arcmin.p95,
        d.psnr_db,
        d.ssim,
        metrics.missing.fraction,
        result.missing_fraction,
        ratios.left,
        ratios.right,
        metrics.coverage,
    ]
}

#[derive(Clone, Copy)]
pub struct SweepOptions {
    pub width: u32,
    pub spp: u32,
    pub head: HeadSource,
    pub band: u32,
    /// Compute only this part of the grid (the CSV then holds that part's rows and no plot
    /// is drawn; [`merge_parts`] joins the parts).
    pub shard: Option<Shard>,
    /// The misregistration bound of an `eye=eyellipse` sweep's share of drivers, arcmin.
    pub bound_arcmin: f64,
}

/// The default bound of the share of drivers, arcmin: the 1′ of the plots and the paper.
pub const DRIVER_SHARE_BOUND_ARCMIN: f64 = 1.0;

/// Runs the sweep over `base` (a scene as read, its map with it); writes `csv` (and
/// `<csv>.png`); returns the number of rows computed now.
pub fn sweep(base: &Scene, params: &[Param], csv: &Path, options: &SweepOptions) -> Result<usize> {
    check_out(csv)?;
    if params.is_empty() {
        bail!("give at least one option `param`");
    }
    let mut names: Vec<&str> = params.iter().map(|p| p.name.as_str()).collect();
    names.sort_unstable();
    if let Some(w) = names.windows(2).find(|w| w[0] == w[1]) {
        bail!(
            "the parameter `{}` is given twice (one option `param` per parameter, with all its values)",
            w[0]
        );
    }
    check_grid_size(params)?;
    let base_options = RunOptions {
        width: Some(options.width),
        spp: options.spp,
        head: options.head,
        outside: Outside::Black,
        back_width: Some(if options.head == HeadSource::Estimated {
            base.back.width
        } else {
            32
        }),
        ..RunOptions::default()
    };
    let configs = combinations(params);
    // Validate every configuration before rendering any.
    for c in &configs {
        configure(base, &base_options, c)?;
    }
    let names: Vec<String> = params.iter().map(|p| p.name.clone()).collect();
    let header_line = encode(&header(&names));
    // What every row depends on besides its parameter values (sweep_csv::SETTING_COLUMNS).
    let row_settings: Vec<String> = vec![
        options.width.to_string(),
        options.spp.to_string(),
        match options.head {
            HeadSource::Oracle => "oracle",
            HeadSource::Estimated => "estimated",
            HeadSource::Model => "model",
        }
        .to_string(),
        options.band.to_string(),
        fingerprint(base).with_context(|| format!("scene {}", base.path.display()))?,
        env!("CARGO_PKG_VERSION").to_string(),
    ];
    // Rows already done: this sweep's header, settings and grid; anything else is refused.
    let rows = if std::fs::symlink_metadata(csv).is_ok() {
        let text = read_input_text(csv, MAX_SWEEP_CSV_BYTES)
            .with_context(|| format!("cannot read {} to resume the sweep", csv.display()))?;
        finished_rows(&text, csv, &names, &configs, &row_settings)?
    } else {
        Vec::new()
    };
    let done: HashSet<usize> = rows.iter().map(|(i, _)| *i).collect();
    let todo: Vec<usize> = (0..configs.len())
        .filter(|i| !done.contains(i))
        .filter(|&i| options.shard.is_none_or(|s| s.owns(&configs[i])))
        .collect();
    let rows = Mutex::new(rows);
    let write = |rows: &mut Vec<(usize, String)>| -> Result<()> {
        rows.sort_by_key(|(i, _)| *i);
        let body: String = rows.iter().map(|(_, l)| format!("{l}\n")).collect();
        write_text(csv, &format!("{header_line}\n{body}"))
    };
    // The configurations still to compute; one world and hierarchy per distinct geometry
    // (only `display_width` changes it), shared by every configuration that has it.
    let jobs: Vec<(usize, Scene, RunOptions)> = todo
        .iter()
        .map(|&index| {
            let (scene, options) = configure(base, &base_options, &configs[index])?;
            Ok((index, scene, options))
        })
        .collect::<Result<_>>()?;
    let mut worlds: Vec<RenderContext> = Vec::new();
    let mut world_of = Vec::with_capacity(jobs.len());
    for (_, scene, _) in &jobs {
        let found = worlds.iter().position(|c| same_geometry(&c.scene, scene));
        world_of.push(match found {
            Some(w) => w,
            None => {
                worlds.push(match worlds.first() {
                    Some(first) => first.with_scene(scene.clone())?,
                    None => RenderContext::new(scene.clone())?,
                });
                worlds.len() - 1
            }
        });
    }
    // Configurations that share the driver's eye share its truth: the obstacle, the frontal
    // and back cameras and the compensation do not change what the truth shows.
    let truth_key = |scene: &Scene| {
        let mut key = scene.clone();
        (key.obstacle, key.frontal, key.back) = (base.obstacle.clone(), base.frontal, base.back);
        key
    };
    let mut groups: Vec<(Scene, Vec<usize>)> = Vec::new();
    for (j, (_, scene, _)) in jobs.iter().enumerate() {
        let key = truth_key(scene);
        match groups.iter_mut().find(|(k, _)| *k == key) {
            Some((_, members)) => members.push(j),
            None => groups.push((key, vec![j])),
        }
    }
    let progress = Progress::new("sweep", jobs.len(), true);
    groups
        .par_iter()
        .try_for_each(|(_, members)| -> Result<()> {
            let (_, scene, run_options) = &jobs[members[0]];
            let settings = RenderSettings {
                spp: run_options.spp,
                progress: false,
            };
            let driver = driver_camera(scene, run_options)?;
            let (truth, _) = worlds[world_of[members[0]]].render(
                RenderJob::new(&driver, view_bit::TRUTH)
                    .settings(settings)
                    .label("truth"),
            );
            members.par_iter().try_for_each(|&j| -> Result<()> {
                let (index, scene, run_options) = &jobs[j];
                let config = &configs[*index];
                let ctx = worlds[world_of[j]].with_scene(scene.clone())?;
                let result = run_with_truth(&ctx, run_options, Some(&truth))
                    .with_context(|| format!("configuration {config:?}"))?;
                let (_, metrics) = measure(
                    &ctx,
                    &ctx.scene,
                    ctx.scene.eye(),
                    result.measured_views(),
                    options.band,
                );
                let values = metric_row(&metrics, &result);
                let fields: Vec<String> = std::iter::once(index.to_string())
                    .chain(config.iter().map(|(_, v)| v.clone()))
                    .chain(values.iter().map(|v| format!("{v}")))
                    .chain(std::iter::once(configs.len().to_string()))
                    .chain(row_settings.iter().cloned())
                    .collect();
                let line = encode(&fields);
                let mut rows = rows
                    .lock()
                    .map_err(|_| anyhow::anyhow!("a sweep worker panicked"))?;
                rows.push((*index, line));
                progress.advance(1);
                write(&mut rows)
            })
        })?;
    progress.finish();
    let mut rows = rows
        .into_inner()
        .map_err(|_| anyhow::anyhow!("a sweep worker panicked"))?;
    write(&mut rows)?;
    if options.shard.is_none() {
        plot(csv, params, &rows)?;
        write_driver_shares(csv, params, &rows, options.bound_arcmin)?;
    }
    Ok(todo.len())
}

/// Refuses an `--out` that cannot be a CSV: empty, a folder (or a name ending in `/`), or
/// something there that is not a regular file (a device, a pipe, a link to one).
pub fn check_out(csv: &Path) -> Result<()> {
    let text = csv.to_string_lossy();
    if text.is_empty() {
        bail!("option `out` is empty: give the CSV's file name (e.g. sweep.csv)");
    }
    if csv.file_name().is_none() || text.ends_with('/') {
        bail!(
            "option `out` {text}: names a folder, not a file; give the CSV's file name (e.g. {}/sweep.csv)",
            text.trim_end_matches('/')
        );
    }
    if std::fs::symlink_metadata(csv).is_ok()
        && let Some(why) = not_a_file(csv)
    {
        bail!("option `out` {text}: {why}; give a regular file (a new name, or a CSV to resume)");
    }
    Ok(())
}

/// Joins the CSVs of a sharded sweep into `out` (byte for byte what one unsharded run writes)
/// and draws its plot; returns the number of rows.
pub fn merge_parts(parts: &[&Path], out: &Path) -> Result<usize> {
    merge_parts_with_bound(parts, out, None)
}

/// A bound of the share of drivers given for parts that sample no drivers' eyes: it would be
/// ignored. Holds the parts' parameter names.
#[derive(Debug)]
pub struct BoundIgnored(pub String);

impl std::fmt::Display for BoundIgnored {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "a bound of the share of drivers is read only for parts of a sweep of eye=eyellipse; these sweep {}",
            self.0
        )
    }
}

impl std::error::Error for BoundIgnored {}

/// [`merge_parts`], with the share of drivers of an `eye=eyellipse` sweep under
/// `bound_arcmin` (default [`DRIVER_SHARE_BOUND_ARCMIN`]); a bound given for parts that sample no
/// drivers is refused ([`BoundIgnored`]) before anything is written.
pub fn merge_parts_with_bound(
    parts: &[&Path],
    out: &Path,
    bound_arcmin: Option<f64>,
) -> Result<usize> {
    check_out(out)?;
    let merged = join(parts)?;
    if bound_arcmin.is_some() && !samples_drivers(&merged.params) {
        let names: Vec<&str> = merged.params.iter().map(|p| p.name.as_str()).collect();
        return Err(BoundIgnored(names.join(", ")).into());
    }
    write_text(out, &merged.text)?;
    plot(out, &merged.params, &merged.body)?;
    let bound = bound_arcmin.unwrap_or(DRIVER_SHARE_BOUND_ARCMIN);
    write_driver_shares(out, &merged.params, &merged.body, bound)?;
    Ok(merged.rows)
}

/// Whether a sweep's parameters sample drivers' eyes (`--param eye=eyellipse`).
pub fn samples_drivers(params: &[Param]) -> bool {
    params.iter().any(|p| p.name == "eye")
}

/// For an `eye=eyellipse` sweep: `<stem>_drivers.json` beside the CSV, with the share of
/// drivers under the bound, and its lines on stderr.
fn write_driver_shares(
    csv: &Path,
    params: &[Param],
    rows: &[(usize, String)],
    bound_arcmin: f64,
) -> Result<()> {
    let Some(shares) = crate::measure::driver_share::driver_shares(params, rows, bound_arcmin)
    else {
        return Ok(());
    };
    let stem = csv
        .file_stem()
        .map(|s| s.to_string_lossy().to_string())
        .unwrap_or_else(|| "sweep".into());
    let path = csv
        .parent()
        .unwrap_or(Path::new("."))
        .join(format!("{stem}_drivers.json"));
    write_text(
        &path,
        &format!("{}\n", serde_json::to_string_pretty(&shares)?),
    )?;
    for line in crate::measure::driver_share::summary_lines(&shares) {
        crate::util::progress::summary(line);
    }
    Ok(())
}

/// Mean misregistration against the first parameter, one curve per value of the second;
/// configurations whose display is not fully covered (coverage < 1) are marked with a dot,
/// since their mean is over fewer pixels.
fn plot(csv: &Path, params: &[Param], rows: &[(usize, String)]) -> Result<()> {
    let Some(figure) = figure_of(params, rows) else {
        return Ok(());
    };
    let stem = csv
        .file_stem()
        .map(|s| s.to_string_lossy().to_string())
        .unwrap_or_else(|| "sweep".into());
    figure.write(
        csv.parent().unwrap_or(Path::new(".")),
        &format!("{stem}_plot"),
    )
}

/// The figure of [`plot`] for the CSV rows `rows`; `None` when there is nothing to draw: a
/// non-numeric first axis (d2 = inf, auto: the CSV is the result) or no finite mean.
fn figure_of(params: &[Param], rows: &[(usize, String)]) -> Option<Figure> {
    let x_of = |s: &str| s.parse::<f64>().ok().filter(|x| x.is_finite());
    if params[0].values.iter().any(|v| x_of(v).is_none()) {
        return None;
    }
    let column = 1 + params.len();
    let coverage_column = column + METRIC_COLUMNS.len() - 1;
    let mut series: Vec<Series> = Vec::new();
    let mut marks = Vec::new();
    let group_values = params
        .get(1)
        .map_or(vec![String::new()], |p| p.values.clone());
    for g in &group_values {
        let mut points = Vec::new();
        for (_, line) in rows {
            let f = decode(line);
            if f.len() <= coverage_column || (params.len() > 1 && f[2] != *g) {
                continue;
            }
            if let (Some(x), Ok(y)) = (x_of(&f[1]), f[column].parse::<f64>()) {
                points.push((x, y));
                if f[coverage_column].parse::<f64>().is_ok_and(|c| c < 1.0) {
                    marks.push((x, y, series.len()));
                }
            }
        }
        let label = if g.is_empty() {
            "mean misregistration".to_string()
        } else {
            format!("{} = {g}", params[1].name)
        };
        series.push(Series::new(label, points));
    }
    let xs: Vec<f64> = series
        .iter()
        .flat_map(|s| s.points.iter().map(|p| p.0))
        .collect();
    let ys: Vec<f64> = series
        .iter()
        .flat_map(|s| s.points.iter().map(|p| p.1))
        .filter(|y| y.is_finite())
        .collect();
    if xs.is_empty() || ys.is_empty() {
        return None;
    }
    let (x0, x1) = xs
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), &x| {
            (a.min(x), b.max(x))
        });
    let y1 = ys.iter().copied().fold(0.0, f64::max) * 1.1 + 1e-9;
    let figure = Figure {
        title: format!(
            "Sweep of {}{}",
            params
                .iter()
                .map(|p| p.name.as_str())
                .collect::<Vec<_>>()
                .join(" × "),
            if marks.is_empty() {
                ""
            } else {
                " (● coverage < 1: part of the display black)"
            }
        ),
        x_label: crate::measure::sweep_grid::axis_label(&params[0].name),
        y_label: "mean misregistration in the display [arcmin]".into(),
        x_range: (x0, if x1 > x0 { x1 } else { x0 + 1.0 }),
        y_range: (0.0, y1),
        series,
        bounds: vec![(1.0, "1′".into())],
        marks,
        legend: plotters::prelude::SeriesLabelPosition::UpperRight,
    }
    .with_legend_clear_of_data();
    Some(figure)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn outputs_that_cannot_be_a_csv_are_refused() {
        let dir = tempfile::tempdir().unwrap();
        for (out, words) in [
            (Path::new(""), "option `out` is empty"),
            (dir.path(), "it is a folder, not a file"),
            (Path::new("."), "names a folder, not a file"),
        ] {
            let err = check_out(out).unwrap_err().to_string();
            assert!(err.contains(words), "{err}");
        }
        assert!(check_out(&dir.path().join("new.csv")).is_ok());
    }

    fn param(spec: &str) -> Param {
        crate::measure::sweep_grid::parse_param(spec).unwrap()
    }

    /// A CSV row as `sweep` writes it: index, the values, the metric columns (mean
    /// misregistration `mean`, coverage `coverage`, the others 0), then what closes a row.
    fn row(index: usize, values: &[&str], mean: f64, coverage: f64) -> (usize, String) {
        let mut fields = vec![index.to_string()];
        fields.extend(values.iter().map(|v| v.to_string()));
        for (column, _, _) in METRIC_COLUMNS {
            fields.push(match column {
                "misregistration_mean_arcmin" => mean.to_string(),
                "coverage" => coverage.to_string(),
                _ => "0".into(),
            });
        }
        fields.extend(["4", "64", "1", "oracle", "3", "hash", "0.1.0"].map(String::from));
        (index, crate::measure::sweep_csv::encode(&fields))
    }

    #[test]
    fn the_plot_draws_each_rows_mean_and_marks_the_rows_not_fully_covered() {
        let params = [param("theta_f=30,60"), param("d2=inf,6")];
        // The 2 × 2 grid's means, with row 0's and row 3's displays partly covered.
        let rows_covered = |coverage: [f64; 4]| {
            [
                ("30", "inf", 20.0),
                ("30", "6", 50.0),
                ("60", "inf", 10.0),
                ("60", "6", 80.0),
            ]
            .iter()
            .zip(coverage)
            .enumerate()
            .map(|(i, (&(theta, d2, mean), c))| row(i, &[theta, d2], mean, c))
            .collect::<Vec<_>>()
        };
        let figure = figure_of(&params, &rows_covered([0.75, 1.0, 1.0, 0.5])).unwrap();
        let curves: Vec<(&str, &[(f64, f64)])> = figure
            .series
            .iter()
            .map(|s| (s.label.as_str(), s.points.as_slice()))
            .collect();
        assert_eq!(
            curves,
            [
                ("d2 = inf", &[(30.0, 20.0), (60.0, 10.0)][..]),
                ("d2 = 6", &[(30.0, 50.0), (60.0, 80.0)][..])
            ]
        );
        // The rows whose display is not fully covered, on their curve, and said so.
        assert_eq!(figure.marks, [(30.0, 20.0, 0), (60.0, 80.0, 1)]);
        assert!(figure.title.contains("coverage < 1"), "{}", figure.title);
        // The axes hold every point, the y axis from 0 with a tenth of room above.
        assert_eq!(figure.x_range, (30.0, 60.0));
        assert_eq!(figure.y_range.0, 0.0);
        let top = figure.y_range.1;
        assert!(
            top > 80.0 * 1.05 && top < 80.0 * 1.2,
            "{:?}",
            figure.y_range
        );
        // Fully covered rows: no marks, no note.
        let figure = figure_of(&params, &rows_covered([1.0; 4])).unwrap();
        assert!(figure.marks.is_empty() && !figure.title.contains("coverage"));
    }

    #[test]
    fn a_plot_of_one_parameter_or_one_value_has_one_curve_and_an_axis_of_some_width() {
        let params = [param("theta_f=40")];
        let rows = [row(0, &["40"], 3.0, 1.0)];
        let figure = figure_of(&params, &rows).unwrap();
        assert_eq!(figure.series.len(), 1);
        // All means 0 still give the y axis some height.
        let zero = figure_of(&params, &[row(0, &["40"], 0.0, 1.0)]).unwrap();
        assert!(zero.y_range.1 > zero.y_range.0, "{:?}", zero.y_range);
        assert_eq!(figure.series[0].points, [(40.0, 3.0)]);
        let (x0, x1) = figure.x_range;
        assert!(x0 <= 40.0 && 40.0 <= x1 && x1 > x0, "{x0}..{x1}");
    }

    #[test]
    fn nothing_is_plotted_without_a_numeric_axis_or_a_finite_mean() {
        let rows = [row(0, &["inf"], 3.0, 1.0)];
        assert!(figure_of(&[param("d2=inf")], &rows).is_none());
        let rows = [row(0, &["40"], f64::NAN, 1.0)];
        assert!(figure_of(&[param("theta_f=40")], &rows).is_none());
    }
}
