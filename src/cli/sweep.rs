//! `seethru sweep`: metrics for every combination of parameter values, as CSV and a plot.

use std::path::PathBuf;

use anyhow::Result;
use seethru::measure::sweep::{SweepOptions, sweep};
use seethru::measure::sweep_grid::parse_param;
use seethru::system::options::HeadSource;

use crate::cli::args::with_threads;

#[derive(clap::Args)]
pub struct Sweep {
    scene: PathBuf,
    /// name=start:stop:step or name=v1,v2,... (repeat for a grid).
    #[arg(long = "param", required = true)]
    params: Vec<String>,
    #[arg(long, default_value = "sweep.csv")]
    out: PathBuf,
    /// Driver-view width in pixels.
    #[arg(long, default_value_t = 320)]
    width: u32,
    #[arg(long, default_value_t = 1)]
    spp: u32,
    #[arg(long, value_enum, default_value_t = HeadSource::Oracle)]
    head: HeadSource,
    #[arg(long, default_value_t = 5)]
    band: u32,
    #[arg(long)]
    threads: Option<usize>,
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
        };
        let computed = with_threads(self.threads, || {
            sweep(&self.scene, &params, &self.out, &options)
        })??;
        eprintln!(
            "computed {computed} configurations; results in {}",
            self.out.display()
        );
        Ok(())
    }
}
