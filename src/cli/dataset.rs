//! `seethru dataset SPEC.toml --out DIR [--shard K/N]`: ground-truth / see-through pairs by
//! the thousand. Each sample is a `run` of the spec's scene with the sample's draws, written
//! whole into `DIR/samples/NNNNNN/` (every view, the system's inputs, the maps, run.json,
//! sample.json); samples already there are kept (a killed run resumes); the process that
//! finds every sample done writes `manifest.csv`, `manifest.parquet` and the grid `view.html`.

use std::path::PathBuf;
use std::time::Instant;

use anyhow::{Context, Result};
use rayon::prelude::*;
use seethru::io::atomic::write_text;
use seethru::io::frame_files::ExrContent;
use seethru::io::output_paths::{Input, Output, check_paths};
use seethru::io::staged::StagedDir;
use seethru::measure::dataset::{
    MANIFEST, Manifest, RECORD, SAMPLE_RECORD, check_record, is_done, record, sample_dir,
    sample_draws,
};
use seethru::measure::dataset_spec::{DatasetSpec, SCENE_DRAWS};
use seethru::measure::manifest_parquet::{MANIFEST_PARQUET, write_manifest_parquet};
use seethru::measure::option_table::{Command, Value};
use seethru::measure::run_spec::{RunSpec, SpecError};
use seethru::measure::sweep_grid::configure;
use seethru::measure::sweep_shard::Shard;
use seethru::measure::viewer::write_dataset_view;
use seethru::render::integrator::RenderContext;
use seethru::scene::Scene;
use seethru::system::memory::{check_memory, run_estimate};
use seethru::system::options::RunOptions;
use seethru::util::progress::Progress;
use serde_json::json;

use crate::cli::args::{choice, threads, with_threads};
use crate::cli::run::{RunWrites, write_run};

#[derive(clap::Args)]
pub struct Dataset {
    /// The dataset's specification (TOML): the scene, samples, seed, [options] and [draw]
    /// (docs/guide/datasets.md).
    spec: PathBuf,
    /// The dataset's folder: samples/NNNNNN/ per sample, dataset.json, and, once every sample
    /// is done, manifest.csv, manifest.parquet and view.html. Samples already in it are kept (a killed run
    /// resumes); it must hold the same spec's samples.
    #[arg(long)]
    out: PathBuf,
    /// Make only the samples i with i mod N = K (K in [0, N-1]), so that N processes or
    /// machines share a dataset; the last to finish writes the manifest.
    #[arg(long, value_name = "K/N")]
    shard: Option<Shard>,
    /// What each view's EXR holds, as `run --exr`.
    #[arg(long, value_enum, value_parser = choice::<ExrContent>(), default_value_t = ExrContent::Lean)]
    exr: ExrContent,
    /// Worker threads in [1, 1024] (default: all cores). Files are identical for any value.
    #[arg(long, value_parser = threads)]
    threads: Option<usize>,
}

impl Dataset {
    pub fn run(self) -> Result<()> {
        check_paths(
            &[Input::file("SPEC", &self.spec)],
            &[Output::folder("--out", &self.out)],
        )?;
        let spec = DatasetSpec::load(&self.spec)?;
        let base = Scene::load(&spec.scene)?;
        with_threads(self.threads, || self.make(&spec, base))?
    }

    fn make(&self, spec: &DatasetSpec, base: Scene) -> Result<()> {
        let start = Instant::now();
        let out = &self.out;
        // Every sample checked before anything is written: its draws, the run they make, the
        // scene they move and the memory it needs.
        for index in 0..spec.samples {
            prepared(spec, &base, index)?;
        }
        if !check_record(out, spec)? {
            write_text(
                &out.join(RECORD),
                &serde_json::to_string_pretty(&record(spec))?,
            )?;
        }
        let mine: Vec<usize> = (0..spec.samples)
            .filter(|i| {
                self.shard
                    .is_none_or(|s| i % s.count as usize == s.index as usize)
            })
            .collect();
        let todo: Vec<usize> = mine.iter().copied().filter(|&i| !is_done(out, i)).collect();
        let first = RenderContext::new(base.clone())?;
        let progress = Progress::new("samples", todo.len(), true);
        // Samples side by side (each run is parallel inside, but a small one leaves cores
        // idle at its start and end); every sample's files are the same in any order.
        todo.par_iter().try_for_each(|&index| {
            self.sample(spec, &base, &first, index)
                .with_context(|| format!("sample {index} of {}", spec.samples))?;
            progress.advance(1);
            anyhow::Ok(())
        })?;
        progress.finish();
        let seconds = start.elapsed().as_secs_f64();
        let done = (0..spec.samples).filter(|&i| is_done(out, i)).count();
        let rate = match todo.len() {
            0 => String::new(),
            n => format!(" in {seconds:.1} s ({:.2} samples/s)", n as f64 / seconds),
        };
        let mut line = format!(
            "made {} samples{rate}, kept {} already made; {done} of {} done",
            todo.len(),
            mine.len() - todo.len(),
            spec.samples
        );
        if done == spec.samples {
            let manifest = Manifest::read(out, spec)?;
            write_text(&out.join(MANIFEST), &manifest.csv())?;
            write_manifest_parquet(&out.join(MANIFEST_PARQUET), &manifest)?;
            write_dataset_view(out)?;
            line += &format!(
                "; wrote {}, {MANIFEST_PARQUET} and view.html",
                out.join(MANIFEST).display()
            );
        } else {
            line += " (the manifest is written when every sample is done)";
        }
        seethru::util::progress::summary(line);
        Ok(())
    }

    /// One sample into its folder, whole or not at all.
    fn sample(
        &self,
        spec: &DatasetSpec,
        base: &Scene,
        first: &RenderContext,
        index: usize,
    ) -> Result<()> {
        let Prepared {
            draws,
            run,
            scene,
            options,
        } = prepared(spec, base, index)?;
        let ctx = first.with_scene(scene)?;
        let writes = RunWrites {
            band: run.measure.band,
            exr: self.exr,
            hazard_bound_arcmin: run.measure.hazard_bound_arcmin,
            heatmap_max_arcmin: None,
            timings: false,
        };
        let staged = StagedDir::new(&sample_dir(&self.out, index))?;
        let record = json!({
            "sample": index,
            "seed": spec.seed,
            "draws": draws.iter().map(|(n, t)| (n.clone(), json!(t))).collect::<serde_json::Map<_, _>>(),
            "options": spec.options.iter().map(|(o, t)| (o.name.to_string(), json!(t))).collect::<serde_json::Map<_, _>>(),
        });
        write_text(
            &staged.path().join(SAMPLE_RECORD),
            &serde_json::to_string_pretty(&record)?,
        )?;
        write_run(&ctx, staged.path(), &options, writes)?;
        staged.commit()
    }
}

/// A sample's run before its scene is moved: the draws, the run they make, the scene draws.
struct SampleRun {
    draws: Vec<(String, String)>,
    run: RunSpec,
    scene_draws: Vec<(String, String)>,
}

/// Sample `index`'s draws made into a run: a draw a run refuses names the sample and value.
fn sample_run(spec: &DatasetSpec, index: usize) -> Result<SampleRun> {
    let draws = sample_draws(spec, index);
    let mut given = Vec::new();
    for (option, text) in &spec.options {
        given.push((*option, option.parse(text).map_err(anyhow::Error::msg)?));
    }
    let mut scene_draws = Vec::new();
    for (draw, (name, text)) in spec.draws.iter().zip(&draws) {
        match draw.option {
            Some(option) => {
                let value: Value = option.parse(text).map_err(|why| {
                    anyhow::anyhow!(
                        "{}: sample {index} of {}: the draw {name} = {text} {why} (narrow its law in [draw])",
                        spec.path.display(),
                        spec.samples
                    )
                })?;
                given.push((option, value));
            }
            None => {
                debug_assert!(SCENE_DRAWS.contains(&name.as_str()));
                scene_draws.push((name.clone(), text.clone()));
            }
        }
    }
    let run = RunSpec::build(Command::Run, &given).map_err(|e| in_spec(spec, e))?;
    if run.both_eyes {
        anyhow::bail!(
            "{}: `eyes` = both: a sample is one eye's run (draw eyes = {{ one_of = [\"left\", \"right\"] }} instead)",
            spec.path.display()
        );
    }
    Ok(SampleRun {
        draws,
        run,
        scene_draws,
    })
}

/// A sample ready to render: its draws, its run, its moved scene and options.
struct Prepared {
    draws: Vec<(String, String)>,
    run: RunSpec,
    scene: Scene,
    options: RunOptions,
}

fn prepared(spec: &DatasetSpec, base: &Scene, index: usize) -> Result<Prepared> {
    let SampleRun {
        draws,
        run,
        scene_draws,
    } = sample_run(spec, index)?;
    let options = RunOptions {
        progress: false,
        ..run.options.clone()
    };
    let (scene, options) = configure(base, &options, &scene_draws).with_context(|| {
        format!(
            "{}: sample {index} of {}",
            spec.path.display(),
            spec.samples
        )
    })?;
    // As `run` does, per sample (its draws may size it).
    check_memory(&run_estimate(&scene, &options)?, run.max_memory_gib)?;
    Ok(Prepared {
        draws,
        run,
        scene,
        options,
    })
}

/// A run's refusal in the spec's words: its keys, not the command line's flags.
fn in_spec(spec: &DatasetSpec, error: SpecError) -> anyhow::Error {
    let file = spec.path.display();
    match error {
        SpecError::Value { option, value, why } => {
            anyhow::anyhow!("{file}: `{option}` = {value}: {why}")
        }
        SpecError::Unknown { option, .. } => {
            anyhow::anyhow!("{file}: `{option}` is not an option of a run")
        }
        SpecError::Ignored(rule) => anyhow::anyhow!(
            "{file}: `{}` is read only {}; with the other options and draws given it would be ignored: remove it",
            rule.option,
            rule.when
        ),
    }
}
