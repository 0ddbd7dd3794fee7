//! `seethru.dataset`: a dataset made as `seethru dataset SPEC --out DIR` makes it, to the same
//! bytes (a dataset begun from Python is resumed or finished by the command line, and shards
//! made by either merge).

use std::path::PathBuf;

use pyo3::prelude::*;
use pyo3::types::PyDict;
use seethru::io::frame_files::ExrContent;
use seethru::io::output_paths::{Input, Output, check_paths};
use seethru::measure::dataset::MANIFEST;
use seethru::measure::dataset_make::{DatasetJob, make_dataset};
use seethru::measure::dataset_spec::DatasetSpec;
use seethru::measure::sweep_shard::Shard;
use seethru::util::option_words::as_keywords;

use crate::errors::{bad_value, input_error, to_py};
use crate::interrupt::detached;
use crate::options::choice_of;

/// Most worker threads (as the command line's).
const MAX_THREADS: usize = 1024;

/// `shard` as the command line's `K/N`: the text "K/N" or a pair (K, N).
fn shard_of(shard: &Bound<'_, PyAny>) -> PyResult<Shard> {
    let text = match shard.extract::<(i64, i64)>() {
        Ok((k, n)) => format!("{k}/{n}"),
        Err(_) => shard.extract::<String>().map_err(|_| {
            bad_value(format!(
                "shard = {}: must be \"K/N\" or a pair (K, N)",
                shard.repr().map_or("?".into(), |r| r.to_string())
            ))
        })?,
    };
    text.parse::<Shard>()
        .map_err(|why| bad_value(format!("shard = {text:?}: {why}")))
}

/// Makes the dataset `spec` describes into `out` (or the samples of one shard of it); returns
/// what it did as a dict. See `seethru.dataset` in seethru/__init__.py.
#[pyfunction]
#[pyo3(signature = (spec, out, shard=None, exr="lean", threads=None))]
pub fn dataset(
    py: Python<'_>,
    spec: PathBuf,
    out: PathBuf,
    shard: Option<&Bound<'_, PyAny>>,
    exr: &str,
    threads: Option<usize>,
) -> PyResult<Py<PyDict>> {
    let shard = shard.map(shard_of).transpose()?;
    let exr: ExrContent = choice_of("exr", exr)?;
    if let Some(n) = threads
        && !(1..=MAX_THREADS).contains(&n)
    {
        return Err(bad_value(format!(
            "threads = {n} is out of range [1, {MAX_THREADS}]"
        )));
    }
    check_paths(
        &[Input::file("spec", &spec)],
        &[Output::folder("out", &out)],
    )
    .map_err(to_py)?;
    let spec = DatasetSpec::load(&spec).map_err(|e| input_error(&spec, e.into()))?;
    let scene_warnings = std::sync::Mutex::new(Vec::new());
    let made = detached(py, || -> anyhow::Result<_> {
        let job = DatasetJob {
            spec: &spec,
            out: &out,
            shard,
            exr,
            scene_warning: &|warning| {
                if let Ok(mut kept) = scene_warnings.lock() {
                    kept.push(warning.to_string());
                }
            },
        };
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads.unwrap_or(0))
            .build()?;
        pool.install(|| make_dataset(&job))
    })?;
    // The scene's warnings are raised even when the making failed (before its error).
    let warn = py.import("warnings")?;
    let scene_warnings: Vec<String> = (scene_warnings.into_inner().unwrap_or_default().iter())
        .map(|w| as_keywords(w))
        .collect();
    for warning in &scene_warnings {
        warn.call_method1("warn", (warning,))?;
    }
    let made = made.map_err(to_py)?;
    let sample_warnings: Vec<String> = made.warnings.iter().map(|w| as_keywords(w)).collect();
    for warning in &sample_warnings {
        warn.call_method1("warn", (warning,))?;
    }
    let warnings = [scene_warnings, sample_warnings].concat();
    let dict = PyDict::new(py);
    dict.set_item("made", made.made)?;
    dict.set_item("kept", made.kept)?;
    dict.set_item("done", made.done)?;
    dict.set_item("samples", made.samples)?;
    dict.set_item("seconds", made.seconds)?;
    dict.set_item("samples_per_second", made.samples_per_second())?;
    let manifest = made.manifest.then(|| out.join(MANIFEST));
    dict.set_item("manifest", manifest)?;
    dict.set_item("warnings", warnings)?;
    Ok(dict.unbind())
}
