//! `seethru reproduce`: the paper's §5 as report.md, report.html and report.json.

use std::path::PathBuf;

use anyhow::Result;

use crate::cli::args::{threads, with_threads};

#[derive(clap::Args)]
#[command(allow_negative_numbers = true)]
pub struct Reproduce {
    /// Output directory for report.md, report.html, report.json and the figures.
    #[arg(long)]
    out: PathBuf,
    /// Small renders (CI-sized).
    #[arg(long)]
    quick: bool,
    /// The driver-assistance scene.
    #[arg(long, default_value = "scenes/das.toml")]
    scene: PathBuf,
    /// Worker threads in [1, 1024] (default: all cores).
    #[arg(long, value_parser = threads)]
    threads: Option<usize>,
}

impl Reproduce {
    pub fn run(self) -> Result<()> {
        // Written whole or not at all: a failure leaves `--out` as it was.
        let staged = seethru::io::staged::StagedDir::new(&self.out)?;
        with_threads(self.threads, || {
            seethru::paper::reproduce::reproduce(&self.scene, staged.path(), self.quick)
        })??;
        staged.commit()?;
        seethru::util::progress::summary(format!(
            "wrote report.md, report.html and report.json to {}",
            self.out.display()
        ));
        Ok(())
    }
}
