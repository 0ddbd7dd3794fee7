//! `seethru figures`: the paper's Fig. 3–5 and the physical-unit sensitivity figure.

use seethru::io::output_paths::{Output, check_paths};
use std::path::PathBuf;

use anyhow::Result;

#[derive(clap::Args)]
#[command(allow_negative_numbers = true)]
pub struct Figures {
    /// Output directory for the figures (PNG, SVG and CSV).
    #[arg(long)]
    out: PathBuf,
}

impl Figures {
    pub fn run(self) -> Result<()> {
        check_paths(&[], &[Output::folder("--out", &self.out)])?;
        // Written whole or not at all: a failure leaves `--out` as it was.
        let staged = seethru::io::staged::StagedDir::new(&self.out)?;
        let names = seethru::paper::figures::write_all(staged.path())?;
        staged.commit()?;
        seethru::util::progress::summary(format!(
            "wrote {} figures (PNG, SVG and CSV) to {}",
            names.len(),
            self.out.display()
        ));
        Ok(())
    }
}
