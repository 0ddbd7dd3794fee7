//! `seethru reproduce`: the paper's §5 as report.md, report.html and report.json.

use std::path::{Path, PathBuf};

use anyhow::{Result, bail};
use seethru::io::output_paths::{Input, Output, check_paths};
use seethru::scene::builtin::{BuiltinDas, DAS_PATH};

use seethru::paper::reproduce::reproduce_estimate;
use seethru::system::memory::check_memory;

use crate::cli::args::{MemoryLimit, threads, with_threads};
use crate::cli::load_scene;

#[derive(clap::Args)]
#[command(allow_negative_numbers = true)]
pub struct Reproduce {
    /// Output directory for report.md, report.html, report.json and the figures.
    #[arg(long)]
    out: PathBuf,
    /// Small renders (CI-sized).
    #[arg(long)]
    quick: bool,
    /// The driver-assistance scene (default: scenes/das.toml of the current folder, else the
    /// copy built into seethru).
    #[arg(long)]
    scene: Option<PathBuf>,
    /// Worker threads in [1, 1024] (default: all cores).
    #[arg(long, value_parser = threads)]
    threads: Option<usize>,
    #[command(flatten)]
    memory: MemoryLimit,
}

impl Reproduce {
    pub fn run(self) -> Result<()> {
        let inputs: Vec<Input> = self
            .scene
            .as_deref()
            .map(|s| Input::file("--scene", s))
            .into_iter()
            .collect();
        check_paths(&inputs, &[Output::folder("--out", &self.out)])?;
        // Written whole or not at all: a failure leaves `--out` as it was.
        let (scene, label, _builtin) = match &self.scene {
            Some(path) if !path.exists() => bail!(
                "--scene {}: no such file (without --scene, reproduce reads scenes/das.toml \
                 of the current folder, or the copy built into seethru)",
                path.display()
            ),
            Some(path) => (path.clone(), path.display().to_string(), None),
            None if Path::new(DAS_PATH).exists() => {
                (PathBuf::from(DAS_PATH), DAS_PATH.into(), None)
            }
            None => {
                let builtin = BuiltinDas::write()?;
                let label = format!(
                    "{DAS_PATH} (built into seethru {})",
                    env!("CARGO_PKG_VERSION")
                );
                (builtin.scene(), label, Some(builtin))
            }
        };
        let base = load_scene(&scene)?;
        check_memory(
            &reproduce_estimate(&base, self.quick)?,
            self.memory.max_memory,
        )?;
        let staged = seethru::io::staged::StagedDir::new(&self.out)?;
        with_threads(self.threads, || {
            seethru::paper::reproduce::reproduce_named(&base, &label, staged.path(), self.quick)
        })??;
        staged.commit()?;
        seethru::util::progress::summary(format!(
            "wrote report.md, report.html and report.json to {}",
            self.out.display()
        ));
        Ok(())
    }
}
