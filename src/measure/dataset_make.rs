//! Making a dataset: every sample of a spec (or of one shard of it) run and written whole into
//! its folder, samples already made kept, and, once every sample is done, the manifest (CSV and
//! Parquet) and the grid viewer. The command line's `seethru dataset` and Python's
//! `seethru.dataset` both call [`make_dataset`]; their files are the same bytes.

use std::borrow::Cow;
use std::path::Path;
use std::time::Instant;

use anyhow::{Context, Result};
use rayon::prelude::*;
use serde_json::json;

use crate::io::atomic::write_text;
use crate::io::frame_files::ExrContent;
use crate::io::staged::StagedDir;
use crate::measure::dataset::{
    MANIFEST, Manifest, RECORD, SAMPLE_RECORD, check_record, is_done, record, sample_dir,
    sample_draws,
};
use crate::measure::dataset_spec::{DatasetSpec, SCENE_DRAWS, SCENE_KEYS, SceneKey, value_text};
use crate::measure::manifest_parquet::{MANIFEST_PARQUET, write_manifest_parquet};
use crate::measure::option_table::{Command, Value};
use crate::measure::run_files::{RunWrites, write_run};
use crate::measure::run_spec::{RunSpec, SpecError};
use crate::measure::sweep_grid::configure;
use crate::measure::sweep_shard::Shard;
use crate::measure::viewer::write_dataset_view;
use crate::render::integrator::RenderContext;
use crate::scene::Scene;
use crate::scene::key_override::with_keys;
use crate::scene::source::SourceFile;
use crate::system::memory::{check_memory, run_estimate};
use crate::system::options::RunOptions;
use crate::util::progress::Progress;

/// One making of a dataset (or of its shard) into a folder.
pub struct DatasetJob<'a> {
    pub spec: &'a DatasetSpec,
    /// The dataset's folder: samples/NNNNNN/, dataset.json, the manifest, view.html.
    pub out: &'a Path,
    /// Only the samples i with i mod N = K; `None`: every sample.
    pub shard: Option<Shard>,
    /// What each view's EXR holds.
    pub exr: ExrContent,
    /// Told what reading the base scene doubted (an OpenDRIVE map's skipped features), in
    /// the library's words, as soon as the scene is read: before any sample is checked or
    /// made, so that a making that fails or runs for hours still says it first.
    pub scene_warning: &'a (dyn Fn(&str) + Sync),
}

/// What a making did.
#[derive(Debug)]
pub struct DatasetMade {
    /// Samples made by this call.
    pub made: usize,
    /// Samples of this call's share found already made, and kept.
    pub kept: usize,
    /// Samples of the whole dataset done now, of `samples`.
    pub done: usize,
    pub samples: usize,
    /// Wall-clock seconds of this call.
    pub seconds: f64,
    /// Whether every sample is done and the manifest and view.html were written.
    pub manifest: bool,
    /// Each made sample's warnings, as "sample N: …", in the library's words, in sample
    /// order (the base scene's went to [`DatasetJob::scene_warning`]).
    pub warnings: Vec<String>,
}

impl DatasetMade {
    /// Samples made per second of wall-clock time (`None` when none was made).
    pub fn samples_per_second(&self) -> Option<f64> {
        (self.made > 0).then(|| self.made as f64 / self.seconds)
    }
}

/// Makes `job`'s samples not yet made, each whole or not at all, then the manifest if every
/// sample is done. Every sample is checked (its draws, its run, its scene and the memory it
/// needs) before anything is written.
pub fn make_dataset(job: &DatasetJob) -> Result<DatasetMade> {
    let start = Instant::now();
    let DatasetJob {
        spec,
        out,
        shard,
        exr,
        scene_warning,
    } = *job;
    let base = BaseScene::load(&spec.scene)?;
    for warning in &base.scene.warnings {
        scene_warning(warning);
    }
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
        .filter(|i| shard.is_none_or(|s| i % s.count as usize == s.index as usize))
        .collect();
    let todo: Vec<usize> = mine.iter().copied().filter(|&i| !is_done(out, i)).collect();
    let first = RenderContext::new(base.scene.clone())?;
    let progress = Progress::new("samples", todo.len(), true);
    // Samples side by side (each run is parallel inside, but a small one leaves cores idle
    // at its start and end); every sample's files are the same in any order.
    let warnings: Vec<Vec<String>> = todo
        .par_iter()
        .map(|&index| {
            let warnings = sample(spec, out, exr, &base, &first, index)
                .with_context(|| format!("sample {index} of {}", spec.samples))?;
            progress.advance(1);
            anyhow::Ok(warnings)
        })
        .collect::<Result<_>>()?;
    progress.finish();
    let done = (0..spec.samples).filter(|&i| is_done(out, i)).count();
    let manifest = done == spec.samples;
    if manifest {
        let manifest = Manifest::read(out, spec)?;
        write_text(&out.join(MANIFEST), &manifest.csv())?;
        write_manifest_parquet(&out.join(MANIFEST_PARQUET), &manifest)?;
        write_dataset_view(out)?;
    }
    Ok(DatasetMade {
        made: todo.len(),
        kept: mine.len() - todo.len(),
        done,
        samples: spec.samples,
        seconds: start.elapsed().as_secs_f64(),
        manifest,
        warnings: warnings.into_iter().flatten().collect(),
    })
}

/// One sample into its folder, whole or not at all; its warnings.
fn sample(
    spec: &DatasetSpec,
    out: &Path,
    exr: ExrContent,
    base: &BaseScene,
    first: &RenderContext,
    index: usize,
) -> Result<Vec<String>> {
    let Prepared {
        draws,
        run,
        scene,
        options,
    } = prepared(spec, base, index)?;
    let ctx = first.with_scene(scene)?;
    let writes = RunWrites {
        band: run.measure.band,
        exr,
        hazard_bound_arcmin: run.measure.hazard_bound_arcmin,
        heatmap_max_arcmin: None,
        timings: false,
    };
    let staged = StagedDir::new(&sample_dir(out, index))?;
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
    let written = write_run(&ctx, staged.path(), &options, writes)?;
    staged.commit()?;
    Ok(written
        .warnings
        .into_iter()
        .map(|w| format!("sample {index}: {w}"))
        .collect())
}

/// A sample's run before its scene is moved: the draws, the run they make, the scene draws
/// (as `sweep --param`'s) and the scene file's keys set.
struct SampleRun {
    draws: Vec<(String, String)>,
    run: RunSpec,
    scene_draws: Vec<(String, String)>,
    scene_keys: Vec<(String, toml_edit::Value)>,
}

/// Sample `index`'s draws made into a run: a draw a run refuses names the sample and value.
fn sample_run(spec: &DatasetSpec, index: usize) -> Result<SampleRun> {
    let draws = sample_draws(spec, index);
    let mut given = Vec::new();
    for (option, text) in &spec.options {
        given.push((*option, option.parse(text).map_err(anyhow::Error::msg)?));
    }
    let mut scene_draws = Vec::new();
    let mut scene_keys = Vec::new();
    for (draw, (name, text)) in spec.draws.iter().zip(&draws) {
        if let Some(key) = &draw.scene_key {
            scene_keys.push((key.path.clone(), key_value(key, text)));
            continue;
        }
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
        scene_keys,
    })
}

/// The value a scene key's draw sets: one_of's value as written (a string stays a string),
/// a number, or an array of numbers.
fn key_value(key: &SceneKey, text: &str) -> toml_edit::Value {
    if let Some(value) = key.values.iter().find(|v| value_text(v) == text) {
        return value.clone();
    }
    match text.parse::<f64>() {
        Ok(number) => toml_edit::Value::from(number),
        Err(_) => text
            .parse()
            .expect("a drawn vector is written as a TOML array of numbers"),
    }
}

/// The scene a spec's samples start from: its file (for the samples that set its keys) and
/// the scene it makes.
struct BaseScene {
    source: SourceFile,
    scene: Scene,
}

impl BaseScene {
    fn load(path: &Path) -> Result<BaseScene> {
        let source = SourceFile::read(path)?;
        let scene = Scene::from_source(&source)?;
        Ok(BaseScene { source, scene })
    }

    /// The scene with `keys` set in its file (the base itself when there are none).
    fn with_keys(&self, keys: &[(String, toml_edit::Value)]) -> Result<Cow<'_, Scene>> {
        if keys.is_empty() {
            return Ok(Cow::Borrowed(&self.scene));
        }
        let keys: Vec<(&str, toml_edit::Value)> =
            keys.iter().map(|(p, v)| (p.as_str(), v.clone())).collect();
        let file = with_keys(&self.source, &keys).map_err(anyhow::Error::msg)?;
        Ok(Cow::Owned(Scene::from_source(&file)?))
    }
}

/// A sample ready to render: its draws, its run, its moved scene and options.
struct Prepared {
    draws: Vec<(String, String)>,
    run: RunSpec,
    scene: Scene,
    options: RunOptions,
}

fn prepared(spec: &DatasetSpec, base: &BaseScene, index: usize) -> Result<Prepared> {
    let SampleRun {
        draws,
        run,
        scene_draws,
        scene_keys,
    } = sample_run(spec, index)?;
    let options = RunOptions {
        progress: false,
        ..run.options.clone()
    };
    let in_sample = || {
        format!(
            "{}: sample {index} of {}",
            spec.path.display(),
            spec.samples
        )
    };
    let keyed = base.with_keys(&scene_keys).with_context(|| {
        let set: Vec<String> = scene_keys
            .iter()
            .map(|(path, value)| format!("{SCENE_KEYS}.{path} = {}", value_text(value)))
            .collect();
        let draws = if set.len() == 1 { "draw" } else { "draws" };
        format!("{}: the {draws} {}", in_sample(), set.join(", "))
    })?;
    let (scene, options) = configure(&keyed, &options, &scene_draws).with_context(in_sample)?;
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
