//! `seethru sweep`: metrics for every combination of parameter values, as CSV and a plot.

use crate::cli::load_scene;
use std::path::PathBuf;

use anyhow::Result;
use seethru::io::output_paths::{Input, Output, check_paths};
use seethru::measure::sweep::{
    BoundIgnored, DRIVER_SHARE_BOUND_ARCMIN, SweepOptions, merge_parts_with_bound, samples_drivers,
    sweep,
};
use seethru::measure::sweep_grid::{EYELLIPSE, MAX_VALUES, eyellipse_param, parse_param};
use seethru::measure::sweep_shard::Shard;
use seethru::system::memory::{DEFAULT_MAX_MEMORY_GIB, MemoryEstimate, check_memory, run_estimate};
use seethru::system::options::{HeadSource, RunOptions};

use crate::cli::args::{
    ReadWhen, band, choice, integer, max_memory, pixels, positive, refuse_ignored, samples,
    threads, with_threads,
};

#[derive(clap::Args)]
#[command(allow_negative_numbers = true)]
pub struct Sweep {
    /// Scene file (TOML).
    scene: PathBuf,
    /// name=start:stop:step or name=v1,v2,... (repeat for a grid); eye=eyellipse: --samples
    /// drivers' eyes from the scene's [eyellipse].
    #[arg(long = "param", required = true)]
    params: Vec<String>,
    /// Output CSV (a plot goes beside it); an existing one is resumed.
    #[arg(long, default_value = "sweep.csv")]
    out: PathBuf,
    /// Driver-view width, pixels in [1, 16384].
    #[arg(long, default_value_t = 320, value_parser = pixels)]
    width: u32,
    /// Samples per pixel in [1, 4096].
    #[arg(long, default_value_t = 1, value_parser = samples)]
    spp: u32,
    /// oracle: the true eye; estimated: face detection on the back camera's image.
    #[arg(long, value_enum, value_parser = choice::<HeadSource>(), default_value_t = HeadSource::Oracle)]
    head: HeadSource,
    /// Width of the border band of the mismatch metrics, display pixels in [1, 1000].
    #[arg(long, default_value_t = 5, value_parser = band)]
    band: u32,
    /// Worker threads in [1, 1024] (default: all cores).
    #[arg(long, value_parser = threads)]
    threads: Option<usize>,
    /// Compute only part K of N (K in [0, N-1]): the configurations are split by a hash of
    /// their values, so N machines can share a sweep; `seethru sweep-merge` joins the parts.
    #[arg(long, value_name = "K/N")]
    shard: Option<Shard>,
    /// Refuse to start when the estimated memory of the configurations computed at once
    /// exceeds this, GiB in [1e-6, 4096].
    #[arg(long = "max-memory", value_name = "GIB", default_value_t = DEFAULT_MAX_MEMORY_GIB, value_parser = max_memory)]
    max_memory: f64,
    /// With --param eye=eyellipse: how many drivers' eyes to draw from the scene's
    /// [eyellipse], an integer in [1, 10000]; each is a row.
    #[arg(long = "samples", default_value_t = 100, value_parser = integer::<usize>(1, MAX_VALUES as u64))]
    eye_samples: usize,
    /// With --param eye=eyellipse: the seed of those eyes, an integer in [0, 4294967295] (as every seed of seethru); eye i
    /// of seed s is the same in every sweep, shard and resumed run.
    #[arg(long, default_value_t = 1, value_parser = integer::<u64>(0, u32::MAX as u64))]
    seed: u64,
    /// With --param eye=eyellipse: the misregistration bound of the share of drivers
    /// (`<out stem>_drivers.json`), arcmin in [1e-6, 10800].
    #[arg(long = "bound-arcmin", default_value_t = DRIVER_SHARE_BOUND_ARCMIN, value_parser = positive(10800.0))]
    bound_arcmin: f64,
}

/// `seethru sweep-merge`: the CSVs of a sharded sweep joined into one.
#[derive(clap::Args)]
pub struct SweepMerge {
    /// The parts' CSVs (each written by `seethru sweep --shard K/N`).
    #[arg(required = true)]
    parts: Vec<PathBuf>,
    /// The merged CSV (its plot goes beside it), byte for byte what one unsharded run writes.
    #[arg(long)]
    out: PathBuf,
    /// For a sweep of --param eye=eyellipse: the misregistration bound of the share of
    /// drivers, arcmin in [1e-6, 10800] (default: 1).
    #[arg(long = "bound-arcmin", value_parser = positive(10800.0))]
    bound_arcmin: Option<f64>,
}

impl SweepMerge {
    pub fn run(self) -> Result<()> {
        let inputs: Vec<Input> = self.parts.iter().map(|p| Input::file("PARTS", p)).collect();
        check_paths(&inputs, &[Output::file("--out", &self.out)])?;
        let parts: Vec<&std::path::Path> = self.parts.iter().map(PathBuf::as_path).collect();
        let rows =
            merge_parts_with_bound(&parts, &self.out, self.bound_arcmin).map_err(|e| {
                match e.downcast_ref::<BoundIgnored>() {
                    Some(ignored) => anyhow::anyhow!(
                        "{}",
                        ReadWhen {
                            option: "bound_arcmin",
                            read: false,
                            when: "for parts of a sweep of --param eye=eyellipse",
                        }
                        .refusal(&format!("parameters ({})", ignored.0))
                    ),
                    None => e,
                }
            })?;
        seethru::util::progress::summary(format!(
            "merged {rows} configurations from {} parts into {}",
            parts.len(),
            self.out.display()
        ));
        Ok(())
    }
}

impl Sweep {
    pub fn run(self) -> Result<()> {
        check_paths(
            &[Input::file("SCENE", &self.scene)],
            &[Output::file("--out", &self.out)],
        )?;
        let params = self
            .params
            .iter()
            .map(|p| {
                let param = parse_param(p)?;
                Ok(if param.values == [EYELLIPSE] {
                    eyellipse_param(self.eye_samples, self.seed)
                } else {
                    param
                })
            })
            .collect::<Result<Vec<_>>>()?;
        let drivers = samples_drivers(&params);
        let when = "with --param eye=eyellipse";
        refuse_ignored(&[
            ReadWhen {
                option: "samples",
                read: drivers,
                when,
            },
            ReadWhen {
                option: "seed",
                read: drivers,
                when,
            },
            ReadWhen {
                option: "bound_arcmin",
                read: drivers,
                when,
            },
        ])?;
        let options = SweepOptions {
            width: self.width,
            spp: self.spp,
            head: self.head,
            band: self.band,
            shard: self.shard,
            bound_arcmin: self.bound_arcmin,
        };
        let computed = with_threads(self.threads, || -> Result<usize> {
            // Every worker thread runs a configuration at a time, each holding its frames.
            let scene = load_scene(&self.scene)?;
            let one = run_estimate(
                &scene,
                &RunOptions {
                    width: Some(self.width),
                    ..RunOptions::default()
                },
            )?;
            let at_once = rayon::current_num_threads() as u64;
            let all = MemoryEstimate {
                bytes: one.bytes * at_once,
                what: format!("{at_once} configurations at once, each with {}", one.what),
            };
            check_memory(&all, self.max_memory)?;
            sweep(&scene, &params, &self.out, &options)
        })??;
        seethru::util::progress::summary(format!(
            "computed {computed} configurations; results in {}",
            self.out.display()
        ));
        Ok(())
    }
}
