//! `seethru run --eyes both`: a run per eye into OUT/left and OUT/right (the same
//! compensation, for `--target-eye`), then the binocular mismatch and the anaglyph into OUT.

use std::path::Path;

use anyhow::{Context, Result};
use seethru::measure::binocular::{binocular_map, binocular_stats, write_binocular};
use seethru::render::integrator::RenderContext;
use seethru::system::eyes::{Eye, Eyes};
use seethru::system::options::RunOptions;
use seethru::system::pipeline::RunResult;

/// Runs each eye through `write_run(options, dir)` into `out` and writes the binocular
/// outputs there; returns the summary line, naming `shown_out` (where `out` will be moved).
pub fn run_both(
    ctx: &RenderContext,
    out: &Path,
    shown_out: &Path,
    options: &RunOptions,
    write_run: impl Fn(&RunOptions, &Path) -> Result<RunResult>,
) -> Result<String> {
    let mut results = Vec::new();
    for (eye, name) in [(Eye::Left, "left"), (Eye::Right, "right")] {
        let options = RunOptions {
            eyes: Eyes {
                view: eye,
                ..options.eyes
            },
            ..options.clone()
        };
        // Only what the binocular outputs need is kept while the other eye runs.
        let result = write_run(&options, &out.join(name))?;
        results.push((result.display, result.seethru));
    }
    let scene = &ctx.scene;
    let eyes = options.eyes;
    let (left, right) = (
        eyes.position(&scene.driver, Eye::Left),
        eyes.position(&scene.driver, Eye::Right),
    );
    // Both runs serve the same eye: their display images are the same.
    let map = binocular_map(&results[0].0, &scene.obstacle, left, right);
    let stats = binocular_stats(&map, &scene.obstacle, left, right);
    write_binocular(out, &map, &stats, [&results[0].1, &results[1].1])
        .with_context(|| format!("writing the binocular outputs to {}", out.display()))?;
    let m = &stats["mismatch_arcmin"];
    Ok(format!(
        "binocular mismatch: mean {:.1}′, p5 {:.1}′, p95 {:.1}′ over {} display pixels ({} missing); closed form {:.1}′ straight ahead, {:.1}′ at the display's angle; wrote binocular.json/.exr/.png and anaglyph.png to {}",
        m["mean"].as_f64().unwrap_or(f64::NAN),
        m["p5"].as_f64().unwrap_or(f64::NAN),
        m["p95"].as_f64().unwrap_or(f64::NAN),
        stats["measured_pixels"],
        stats["missing_pixels"],
        stats["closed_form_arcmin"].as_f64().unwrap_or(f64::NAN),
        stats["closed_form_off_axis_arcmin"]
            .as_f64()
            .unwrap_or(f64::NAN),
        shown_out.display()
    ))
}
