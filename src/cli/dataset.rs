//! `seethru dataset SPEC.toml --out DIR [--shard K/N]`: ground-truth / see-through pairs by
//! the thousand. Each sample is a `run` of the spec's scene with the sample's draws, written
//! whole into `DIR/samples/NNNNNN/` (every view, the system's inputs, the maps, run.json,
//! sample.json); samples already there are kept (a killed run resumes); the process that
//! finds every sample done writes `manifest.csv`, `manifest.parquet` and the grid `view.html`.

use std::path::PathBuf;

use anyhow::Result;
use seethru::io::frame_files::ExrContent;
use seethru::io::output_paths::{Input, Output, check_paths};
use seethru::measure::dataset::MANIFEST;
use seethru::measure::dataset_make::{DatasetJob, make_dataset};
use seethru::measure::dataset_spec::DatasetSpec;
use seethru::measure::manifest_parquet::MANIFEST_PARQUET;
use seethru::measure::sweep_shard::Shard;
use seethru::util::option_words::as_flags;

use crate::cli::args::{choice, threads, with_threads};

#[derive(clap::Args)]
pub struct Dataset {
    /// The dataset's specification (TOML): the scene, samples, seed, [options], [draw] and
    /// [draw.scene] (the scene file's keys; docs/guide/datasets.md).
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
        let job = DatasetJob {
            spec: &spec,
            out: &self.out,
            shard: self.shard,
            exr: self.exr,
            scene_warning: &|warning| eprintln!("warning: {}", as_flags(warning)),
        };
        let made = with_threads(self.threads, || make_dataset(&job))??;
        for warning in &made.warnings {
            eprintln!("warning: {}", as_flags(warning));
        }
        let rate = match made.samples_per_second() {
            None => String::new(),
            Some(rate) => format!(" in {:.1} s ({rate:.2} samples/s)", made.seconds),
        };
        let mut line = format!(
            "made {} samples{rate}, kept {} already made; {} of {} done",
            made.made, made.kept, made.done, made.samples
        );
        if made.manifest {
            line += &format!(
                "; wrote {}, {MANIFEST_PARQUET} and view.html",
                self.out.join(MANIFEST).display()
            );
        } else {
            line += " (the manifest is written when every sample is done)";
        }
        seethru::util::progress::summary(line);
        Ok(())
    }
}
