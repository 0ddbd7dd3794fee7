//! `seethru score`: an outside method's display map (and/or display image) for a capture,
//! shown on the display and measured exactly as `run` measures a built-in method.

use crate::cli::{print_warnings, with_flags};
use std::path::{Path, PathBuf};

use anyhow::{Result, bail};
use glam::Vec3;
use rayon::prelude::*;
use seethru::io::atomic::write_text;
use seethru::io::display_map::{read_display_image, read_map};
use seethru::io::frame_files::{ExrContent, write_frame_like};
use seethru::io::output_paths::{Input, Output, check_paths};
use seethru::io::staged::StagedDir;
use seethru::measure::capture_files::recapture;
use seethru::measure::hazard::HAZARD_BOUND_ARCMIN;
use seethru::measure::maps::write_metrics;
use seethru::measure::measured_run::{MeasureSettings, MeasuredRun, measure_run};
use seethru::measure::viewer::{RunPixels, write_run_view};
use seethru::render::frame_over::FrameView;
use seethru::system::capture::{DisplayImage, DisplayMap, score};
use seethru::system::display::Filter;

use crate::cli::args::{band, choice, threads};

#[derive(clap::Args)]
pub struct Score {
    /// A folder written by `seethru capture` (its truth/ is read here, never by the method).
    inputs: PathBuf,
    /// The method's display map: .npy (display height, display width, 2) float32/float64,
    /// [..., 0] = x, [..., 1] = y in frontal pixels (OpenCV's remap convention, NaN shows
    /// nothing), or .exr with channels x, y.
    #[arg(long, value_name = "FILE")]
    map: Option<PathBuf>,
    /// The method's display image (.png sRGB or .exr linear RGB, at the display's
    /// resolution): shown instead of the map's colours; alone, only image metrics.
    #[arg(long = "display-image", value_name = "FILE")]
    display_image: Option<PathBuf>,
    /// The display image holds the display's codes, not linear light: what its transfer curve
    /// (`display_transfer`) turns into light, as a coded camera's image is shown (a PNG's 8 or
    /// 16 bits as code / top code, an EXR's values as they are).
    #[arg(long = "display-codes")]
    display_codes: bool,
    /// Output directory: the views, metrics.json, the heatmaps and run.json, as `run` writes.
    #[arg(long)]
    out: PathBuf,
    /// Colour resampling of the frontal image at the map's points.
    #[arg(long, value_enum, value_parser = choice::<Filter>(), default_value_t = Filter::Bilinear)]
    filter: Filter,
    /// Width of the border band of the mismatch metrics, display pixels in [1, 1000].
    #[arg(long, default_value_t = 5, value_parser = band)]
    band: u32,
    /// Worker threads in [1, 1024] (default: all cores). Results are identical for any value.
    #[arg(long, value_parser = threads)]
    threads: Option<usize>,
    /// What each view's EXR holds, as `run --exr`: all (every AOV, what `measure` reads),
    /// lean (R, G, B, Z, N and the ids), colour (R, G, B, A only) or none (the PNGs only).
    #[arg(long, value_enum, value_parser = choice::<ExrContent>(), default_value_t = ExrContent::All)]
    exr: ExrContent,
}

/// A map file as the system's map; errors name the file.
pub fn load_map(path: &Path) -> Result<DisplayMap> {
    let m = read_map(path)?;
    Ok(DisplayMap {
        width: m.width,
        height: m.height,
        xy: m.xy,
        fingerprint: m.fingerprint,
    })
}

fn load_image(path: &Path, codes: bool) -> Result<DisplayImage> {
    let i = read_display_image(path, codes)?;
    Ok(DisplayImage {
        width: i.width,
        height: i.height,
        color: i.color.into_iter().map(Vec3::from_array).collect(),
        codes,
    })
}

impl Score {
    pub fn run(self) -> Result<()> {
        let mut inputs = vec![Input::folder("INPUTS", &self.inputs)];
        inputs.extend(self.map.as_deref().map(|m| Input::file("--map", m)));
        inputs.extend(
            self.display_image
                .as_deref()
                .map(|m| Input::file("--display-image", m)),
        );
        check_paths(&inputs, &[Output::folder("--out", &self.out)])?;
        if self.map.is_none() && self.display_image.is_none() {
            bail!("score needs --map FILE, --display-image FILE or both");
        }
        // Given even at its default, --filter without a map would be ignored.
        crate::cli::args::refuse_ignored(&[
            crate::cli::args::ReadWhen {
                option: "filter",
                read: self.map.is_some() && self.display_image.is_none(),
                when: "with --map and no --display-image (it resamples the frontal image's colours at the map's points; a display image replaces them)",
            },
            crate::cli::args::ReadWhen {
                option: "display_codes",
                read: self.display_image.is_some(),
                when: "with --display-image (it says what the image holds)",
            },
        ])?;
        crate::cli::args::with_threads(self.threads, || self.write())?
    }

    fn write(&self) -> Result<()> {
        // The files first: a bad map fails before anything is rendered.
        let map = self.map.as_deref().map(load_map).transpose()?;
        let image = self
            .display_image
            .as_deref()
            .map(|p| load_image(p, self.display_codes))
            .transpose()?;
        let mut r = recapture(&self.inputs)?;
        print_warnings(&r.ctx.scene);
        r.options.filter = self.filter;
        let name = |p: &Option<PathBuf>| p.as_ref().map(|p| p.display().to_string());
        let in_file = |e: anyhow::Error| {
            let file = name(&self.map)
                .or(name(&self.display_image))
                .unwrap_or_default();
            anyhow::anyhow!("{file}: {e}")
        };
        seethru::system::capture::check_display_input(
            r.ctx.scene.obstacle.display_resolution,
            Some([r.capture.frontal.width, r.capture.frontal.height]),
            &r.capture.fingerprint,
            map.as_ref(),
            image.as_ref(),
        )
        .map_err(in_file)?;
        let scored = score(&r.ctx, &r.options, &r.capture, map.as_ref(), image.as_ref())?;
        let result = &scored.run;
        let staged = StagedDir::new(&self.out)?;
        let out = staged.path();
        let views = [
            ("truth", FrameView::Whole(&result.truth)),
            ("occluded", FrameView::Over(&result.occluded)),
            ("display", FrameView::Whole(&result.display)),
            ("seethru", FrameView::Over(&result.seethru)),
        ];
        views
            .par_iter()
            .try_for_each(|&(name, frame)| write_frame_like(frame, out, name, self.exr, None))?;
        let MeasuredRun {
            maps,
            metrics,
            hazards,
            ..
        } = measure_run(
            &r.ctx,
            &r.options,
            result,
            MeasureSettings {
                band: self.band,
                hazard_bound_arcmin: HAZARD_BOUND_ARCMIN,
            },
        )?;
        write_metrics(out, &maps, &result.truth, &with_flags(&metrics.to_json()))?;
        // As `run` writes it, at its default bound.
        write_text(
            &out.join("hazards.json"),
            &serde_json::to_string_pretty(&hazards)?,
        )?;
        write_text(
            &out.join("run.json"),
            &serde_json::to_string_pretty(&with_flags(&result.report))?,
        )?;
        let pixels = RunPixels::of_run(&maps, &result.truth, FrameView::from(&result.seethru));
        write_run_view(out, out, &pixels)?;
        staged.commit()?;
        let (d, b) = (&metrics.display, &metrics.border);
        let misregistration = match scored.has_map {
            true => format!(
                "misregistration mean {:.3} arcmin (p95 {:.3}) over {} pixels",
                d.misregistration_arcmin.mean,
                d.misregistration_arcmin.p95,
                d.misregistration_arcmin.count
            ),
            false => "misregistration needs a map (image only)".to_string(),
        };
        seethru::util::progress::summary(format!(
            "scored {}: {misregistration}, coverage {:.2} %, border mean {:.3} arcmin, PSNR {:.2} dB, SSIM {:.4}; wrote {}",
            name(&self.map)
                .or(name(&self.display_image))
                .unwrap_or_default(),
            100.0 * metrics.coverage,
            b.misregistration_arcmin.mean,
            d.psnr_db,
            d.ssim,
            self.out.display()
        ));
        Ok(())
    }
}
