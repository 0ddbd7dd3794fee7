//! Argument groups that several commands share, and the thread pool they run on.

use anyhow::{Result, bail};

/// Image size, samples and threads: shared by `render` and `run`.
#[derive(clap::Args)]
pub struct RenderArgs {
    /// Image width in pixels (default: the camera's; height follows the aspect ratio if not given).
    #[arg(long)]
    pub width: Option<u32>,
    /// Image height in pixels.
    #[arg(long)]
    pub height: Option<u32>,
    /// Samples per pixel (anti-aliasing of the colour; AOVs are at pixel centres).
    #[arg(long, default_value_t = 4)]
    pub spp: u32,
    /// Worker threads (default: all cores). Images are identical for any value.
    #[arg(long)]
    pub threads: Option<usize>,
}

/// Runs `job` on a pool of `threads` workers (all cores if `None`). Images do not depend on it.
pub fn with_threads<T: Send>(threads: Option<usize>, job: impl FnOnce() -> T + Send) -> Result<T> {
    if let Some(n) = threads
        && !(1..=1024).contains(&n)
    {
        bail!("--threads {n} is out of range [1, 1024]");
    }
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads.unwrap_or(0))
        .build()?;
    Ok(pool.install(job))
}
