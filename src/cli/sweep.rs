//! `seethru sweep`: metrics for every combination of parameter values, as CSV and a plot.

use std::path::PathBuf;

use anyhow::Result;
use seethru::measure::sweep::{SweepOptions, merge_parts, sweep};
use seethru::measure::sweep_grid::parse_param;
use seethru::measure::sweep_shard::Shard;
use seethru::scene::Scene;
use seethru::system::memory::{DEFAULT_MAX_MEMORY_GIB, MemoryEstimate, check_memory, run_estimate};
use seethru::system::options::{HeadSource, RunOptions};

use crate::cli::args::{band, choice, max_memory, pixels, samples, threads, with_threads};

#[derive(clap::Args)]
#[command(allow_negative_numbers = true)]
pub struct Sweep {
    /// Scene file (TOML).
    scene: PathBuf,
    /// name=start:stop:step or name=v1,v2,... (repeat for a grid).
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
}

impl SweepMerge {
    pub fn run(self) -> Result<()> {
        let parts: Vec<&std::path::Path> = self.parts.iter().map(PathBuf::as_path).collect();
        let rows = merge_parts(&parts, &self.out)?;
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
        let params = self
            .params
            .iter()
            .map(|p| parse_param(p))
            .collect::<Result<Vec<_>>>()?;
        let options = SweepOptions {
            width: self.width,
            spp: self.spp,
            head: self.head,
            band: self.band,
            shard: self.shard,
        };
        let computed = with_threads(self.threads, || -> Result<usize> {
            // Every worker thread runs a configuration at a time, each holding its frames.
            let scene = Scene::load(&self.scene)?;
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
            sweep(&self.scene, &params, &self.out, &options)
        })??;
        seethru::util::progress::summary(format!(
            "computed {computed} configurations; results in {}",
            self.out.display()
        ));
        Ok(())
    }
}
