//! `seethru view DIR`: writes the viewer (`DIR/view.html`) of an output folder that `run`,
//! `score`, `measure`, `sequence` or `compare` wrote, including folders older than the viewer.

use std::path::PathBuf;

use anyhow::Result;
use seethru::measure::viewer::write_view;

#[derive(clap::Args)]
pub struct View {
    /// Output folder of run, score, measure, sequence or compare; the viewer is written into
    /// it as view.html (it shows the images beside it)
    pub dir: PathBuf,
}

impl View {
    pub fn run(self) -> Result<()> {
        let path = write_view(&self.dir)?;
        seethru::util::progress::summary(format!(
            "wrote {} (open it in a browser; it needs no server)",
            path.display()
        ));
        Ok(())
    }
}
