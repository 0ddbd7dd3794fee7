//! `seethru sweep`: metrics for every combination of parameter values, as CSV and a plot.

use std::path::PathBuf;

use anyhow::Result;
use seethru::measure::sweep::{SweepOptions, merge_parts, sweep};
use seethru::measure::sweep_grid::parse_param;
use seethru::measure::sweep_shard::Shard;
use seethru::system::options::HeadSource;

use crate::cli::args::{band, pixels, samples, threads, with_threads};

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
    #[arg(long, value_enum, default_value_t = HeadSource::Oracle)]
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
        let computed = with_threads(self.threads, || {
            sweep(&self.scene, &params, &self.out, &options)
        })??;
        seethru::util::progress::summary(format!(
            "computed {computed} configurations; results in {}",
            self.out.display()
        ));
        Ok(())
    }
}
