//! `seethru bench`'s run figures: wall and CPU seconds of `seethru run` on the bench's scene
//! with its defaults (1280×720 driver views at 4 spp unless the scene says otherwise), and the
//! size of the folder it writes with each `--exr` choice.

use std::path::{Path, PathBuf};
use std::time::Instant;

use anyhow::{Context, Result};
use clap::{Args, FromArgMatches};
use seethru::util::cpu_time::process_cpu_seconds;
use serde_json::json;

use crate::cli::run::Run;

/// Bytes of the files under `dir`.
fn folder_bytes(dir: &Path) -> Result<u64> {
    let mut total = 0;
    for entry in std::fs::read_dir(dir).with_context(|| format!("reading {}", dir.display()))? {
        let entry = entry?;
        let meta = entry.metadata()?;
        total += match meta.is_dir() {
            true => folder_bytes(&entry.path())?,
            false => meta.len(),
        };
    }
    Ok(total)
}

/// One `seethru run SCENE --out OUT --exr EXR --threads N` (the bench's threads) as the command line would run it.
fn run_once(scene: &Path, out: &Path, exr: &str) -> Result<()> {
    let threads = rayon::current_num_threads().to_string();
    let command = Run::augment_args(clap::Command::new("run"));
    let matches = command.try_get_matches_from([
        "run".as_ref(),
        scene.as_os_str(),
        "--out".as_ref(),
        out.as_os_str(),
        "--exr".as_ref(),
        exr.as_ref(),
        "--threads".as_ref(),
        threads.as_ref(),
    ])?;
    Run::from_arg_matches(&matches)?.run()
}

/// The report lines and the JSON of the run benchmark: `repeat` (at most 3) timed runs with
/// the default `--exr lean`, then one each with `--exr all`, `colour` and `none`.
pub fn bench_run(scene: &Path, repeat: usize) -> Result<(Vec<String>, serde_json::Value)> {
    let scratch: PathBuf =
        std::env::temp_dir().join(format!("seethru-bench-run-{}", std::process::id()));
    let quiet = seethru::util::progress::is_quiet();
    seethru::util::progress::set_quiet(true);
    let result = (|| {
        let mut lines = vec![
            "run          seethru run SCENE (its defaults) into a scratch folder; wall s, CPU s (user + system, all threads), folder MB".to_string(),
        ];
        let mut out = serde_json::Map::new();
        let runs = [
            ("lean", repeat.clamp(1, 3)),
            ("all", 1),
            ("colour", 1),
            ("none", 1),
        ];
        for (exr, times) in runs {
            let (mut walls, mut cpus) = (Vec::new(), Vec::new());
            for _ in 0..times {
                let _ = std::fs::remove_dir_all(&scratch);
                let (wall, cpu) = (Instant::now(), process_cpu_seconds());
                run_once(scene, &scratch, exr)?;
                walls.push(wall.elapsed().as_secs_f64());
                cpus.push(cpu.zip(process_cpu_seconds()).map(|(a, b)| b - a));
            }
            let bytes = folder_bytes(&scratch)?;
            let wall = walls.iter().copied().fold(f64::INFINITY, f64::min);
            let cpu = cpus.iter().flatten().copied().fold(f64::INFINITY, f64::min);
            let cpu = cpu.is_finite().then_some(cpu);
            lines.push(format!(
                "  --exr {exr:<8} wall {wall:6.3} s  CPU {}  folder {:6.1} MB  (best of {times})",
                cpu.map_or("unknown".into(), |c| format!("{c:6.3} s")),
                bytes as f64 / 1e6
            ));
            out.insert(
                exr.into(),
                json!({"wall_s": wall, "cpu_s": cpu, "folder_bytes": bytes, "runs": times}),
            );
        }
        Ok((lines, serde_json::Value::Object(out)))
    })();
    seethru::util::progress::set_quiet(quiet);
    let _ = std::fs::remove_dir_all(&scratch);
    result
}
