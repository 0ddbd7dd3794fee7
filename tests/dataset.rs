//! `seethru dataset`: the same files, byte for byte, made whole, in shards, on one thread or
//! resumed after a loss; the draws follow their laws and reach the runs they configure; the
//! manifest is the samples' metrics; bad specs are refused in one line naming file, line and key.

mod common;

use std::path::{Path, PathBuf};

use common::seethru;
use seethru::measure::dataset::sample_draws;
use seethru::measure::dataset_spec::DatasetSpec;
use serde_json::Value;

fn spec_in(dir: &Path, samples: usize, draw: &str) -> PathBuf {
    let das = common::repo_path("scenes/das.toml");
    let text = format!(
        "scene = {das:?}\nsamples = {samples}\nseed = 11\n[options]\nwidth = 48\nspp = 1\n[draw]\n{draw}"
    );
    let path = dir.join(format!("spec_{samples}.toml"));
    std::fs::write(&path, text).unwrap();
    path
}

const DRAWS: &str = "method = { one_of = [\"planar\", \"plane-fit\"] }\nd2 = { one_of = [\"inf\", \"6\"] }\ntheta_f = { uniform = [40, 60] }\neye_x = { normal = [0, 0.03] }\n";

fn make(spec: &Path, out: &Path, extra: &[&str]) -> String {
    let mut args = vec![
        "dataset",
        spec.to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
    ];
    args.extend(extra);
    let (ok, stdout, err) = seethru(&args);
    assert!(ok, "{err}");
    format!("{stdout}{err}")
}

/// Every file under `dir`, relative, with its bytes.
fn files(dir: &Path) -> Vec<(PathBuf, Vec<u8>)> {
    let mut out = Vec::new();
    let mut stack = vec![dir.to_path_buf()];
    while let Some(d) = stack.pop() {
        for e in std::fs::read_dir(&d).unwrap() {
            let p = e.unwrap().path();
            if p.is_dir() {
                stack.push(p);
            } else {
                out.push((
                    p.strip_prefix(dir).unwrap().to_path_buf(),
                    std::fs::read(&p).unwrap(),
                ));
            }
        }
    }
    out.sort();
    out
}

/// `seethru run` of `scene` with [`spec_in`]'s options, into `out`.
fn run_as_the_spec(scene: &Path, out: &Path) {
    let (ok, _, err) = seethru(&[
        "run",
        scene.to_str().unwrap(),
        "--width",
        "48",
        "--spp",
        "1",
        "--quiet",
        "--out",
        out.to_str().unwrap(),
    ]);
    assert!(ok, "{err}");
}

fn json(path: &Path) -> Value {
    serde_json::from_str(&std::fs::read_to_string(path).unwrap()).unwrap()
}

#[test]
fn whole_sharded_one_thread_and_resumed_datasets_are_the_same_bytes() {
    let dir = tempfile::tempdir().unwrap();
    let spec = spec_in(dir.path(), 5, DRAWS);
    let whole = dir.path().join("whole");
    make(&spec, &whole, &[]);
    let reference = files(&whole);
    assert!(
        reference.len() > 5 * 20,
        "every sample's files: {}",
        reference.len()
    );
    // Two shards, one on one thread: the first leaves the manifest unwritten.
    let sharded = dir.path().join("sharded");
    let said = make(&spec, &sharded, &["--shard", "0/2", "--threads", "1"]);
    assert!(
        said.contains("3 of 5 done") && !sharded.join("manifest.csv").exists(),
        "{said}"
    );
    make(&spec, &sharded, &["--shard", "1/2"]);
    assert!(
        files(&sharded) == reference,
        "the shards' files differ from one process's"
    );
    // A lost sample and a lost manifest: made again, the rest kept.
    std::fs::remove_dir_all(sharded.join("samples/000003")).unwrap();
    std::fs::remove_file(sharded.join("manifest.csv")).unwrap();
    let said = make(&spec, &sharded, &[]);
    assert!(
        said.contains("made 1 samples") && said.contains("kept 4"),
        "{said}"
    );
    assert!(files(&sharded) == reference, "the resumed dataset differs");
    // Another spec into the same folder is refused before anything is written.
    let other = spec_in(dir.path(), 6, DRAWS);
    let (ok, _, err) = seethru(&[
        "dataset",
        other.to_str().unwrap(),
        "--out",
        sharded.to_str().unwrap(),
    ]);
    assert!(
        !ok && err.starts_with("error: ") && err.contains("another spec"),
        "{err}"
    );
    assert!(!sharded.join("samples/000005").exists());
}

#[test]
fn the_draws_configure_each_run_and_the_manifest_is_its_metrics() {
    let dir = tempfile::tempdir().unwrap();
    let spec = spec_in(dir.path(), 4, DRAWS);
    let out = dir.path().join("d");
    make(&spec, &out, &[]);
    let manifest = std::fs::read_to_string(out.join("manifest.csv")).unwrap();
    let mut lines = manifest.lines();
    let header: Vec<&str> = lines.next().unwrap().split(',').collect();
    let col = |name: &str| header.iter().position(|h| *h == name).unwrap();
    // The base eye, from a run of the scene itself.
    let base = dir.path().join("base");
    run_as_the_spec(&common::repo_path("scenes/das.toml"), &base);
    let base_eye_x = json(&base.join("run.json"))["eye_true"]["obstacle_m"][0]
        .as_f64()
        .unwrap();
    for (i, line) in lines.enumerate() {
        let row: Vec<&str> = line.split(',').collect();
        assert_eq!(row[0], i.to_string());
        let folder = out.join(format!("samples/{i:06}"));
        let run = json(&folder.join("run.json"));
        let metrics = json(&folder.join("metrics.json"));
        let sample = json(&folder.join("sample.json"));
        assert_eq!(run["options"]["method"], row[col("method")]);
        let d2 = &run["options"]["d2"];
        assert!(
            d2 == row[col("d2")]
                || d2.as_f64().map(|v| v.to_string()) == Some(row[col("d2")].into()),
            "{d2} {}",
            row[col("d2")]
        );
        let theta: f64 = row[col("theta_f")].parse().unwrap();
        assert!((40.0..=60.0).contains(&theta));
        assert!((run["frontal_half_angle_deg"].as_f64().unwrap() - theta).abs() < 1e-9);
        let eye_x: f64 = row[col("eye_x")].parse().unwrap();
        let moved = run["eye_true"]["obstacle_m"][0].as_f64().unwrap() - base_eye_x;
        assert!(
            (moved - eye_x).abs() < 1e-9,
            "sample {i}: the eye moved {moved}, drawn {eye_x}"
        );
        assert_eq!(sample["draws"]["theta_f"], row[col("theta_f")]);
        let mean: f64 = row[col("misregistration_mean_arcmin")].parse().unwrap();
        assert_eq!(
            mean,
            metrics["display"]["misregistration_arcmin"]["mean"]
                .as_f64()
                .unwrap()
        );
        assert_eq!(
            row[col("seethru_png")],
            format!("samples/{i:06}/seethru.png")
        );
        // A sample's run.json has no timings: its bytes do not depend on the machine's load.
        assert!(run.get("timings_s").is_none() && run.get("peak_rss_bytes").is_none());
    }
}

#[test]
fn the_laws_are_those_the_spec_names() {
    let dir = tempfile::tempdir().unwrap();
    let spec = spec_in(
        dir.path(),
        4000,
        "method = { one_of = [\"none\", \"planar\", \"ground\", \"plane-fit\"] }\ntheta_f = { uniform = [40, 60] }\nhead_jitter_cm = { normal = [2, 0.5] }\nfrontal_width = { uniform = [100, 103] }\n[draw.scene]\n\"object.car.translate\" = { uniform = [[0, 10, -5], [1, 20, -5]] }\nsky.zenith_color = { normal = [[0.2, 0.5, 0.8], [0.01, 0.02, 0]] }\n",
    );
    let spec = DatasetSpec::load(&spec).unwrap();
    let rows: Vec<Vec<(String, String)>> = (0..4000).map(|i| sample_draws(&spec, i)).collect();
    let column = |k: usize| -> Vec<String> { rows.iter().map(|r| r[k].1.clone()).collect() };
    for choice in ["none", "planar", "ground", "plane-fit"] {
        let n = column(0).iter().filter(|v| *v == choice).count();
        // 1000 expected, σ = 27: within 5σ.
        assert!((865..=1135).contains(&n), "{choice}: {n} of 4000");
    }
    let theta: Vec<f64> = column(1).iter().map(|v| v.parse().unwrap()).collect();
    assert!(theta.iter().all(|t| (40.0..=60.0).contains(t)));
    let mean = theta.iter().sum::<f64>() / 4000.0;
    assert!((mean - 50.0).abs() < 0.5, "uniform mean {mean}"); // σ of the mean 0.09
    let jitter: Vec<f64> = column(2).iter().map(|v| v.parse().unwrap()).collect();
    let m = jitter.iter().sum::<f64>() / 4000.0;
    let sd = (jitter.iter().map(|j| (j - m).powi(2)).sum::<f64>() / 3999.0).sqrt();
    assert!(
        (m - 2.0).abs() < 0.04 && (sd - 0.5).abs() < 0.03,
        "normal: mean {m}, sd {sd}"
    );
    // An integer option's uniform draws: each integer of the range as likely (1000 each).
    for v in ["100", "101", "102", "103"] {
        let n = column(3).iter().filter(|c| *c == v).count();
        assert!((865..=1135).contains(&n), "frontal_width {v}: {n} of 4000");
    }
    assert!(
        column(3)
            .iter()
            .all(|v| ["100", "101", "102", "103"].contains(&v.as_str()))
    );
    // A vector law draws each component by its own bounds, independently of the others.
    let vectors = |k: usize| -> Vec<Vec<f64>> {
        column(k)
            .iter()
            .map(|v| serde_json::from_str(v).unwrap())
            .collect()
    };
    let (translate, zenith) = (vectors(4), vectors(5));
    let stats = |rows: &[Vec<f64>], c: usize| {
        let x: Vec<f64> = rows.iter().map(|r| r[c]).collect();
        let m = x.iter().sum::<f64>() / x.len() as f64;
        let sd = (x.iter().map(|v| (v - m).powi(2)).sum::<f64>() / (x.len() - 1) as f64).sqrt();
        (m, sd)
    };
    for (c, (low, high)) in [(0.0, 1.0), (10.0, 20.0), (-5.0, -5.0)]
        .into_iter()
        .enumerate()
    {
        assert!(
            translate
                .iter()
                .all(|t| t.len() == 3 && (low..=high).contains(&t[c]))
        );
        let (m, sd) = stats(&translate, c);
        let width = high - low;
        // A uniform's mean and deviation: (low + high) / 2 and width / √12; σ of the mean
        // width / 219.
        assert!(
            (m - (low + high) / 2.0).abs() <= width * 0.025,
            "component {c}: mean {m}"
        );
        assert!(
            (sd - width / 12f64.sqrt()).abs() <= width * 0.02,
            "component {c}: sd {sd}"
        );
    }
    for (c, (mean, sd_want)) in [(0.2, 0.01), (0.5, 0.02), (0.8, 0.0)]
        .into_iter()
        .enumerate()
    {
        let (m, sd) = stats(&zenith, c);
        assert!(
            (m - mean).abs() <= 5.0 * sd_want / 63.0 + 1e-12,
            "component {c}: mean {m}"
        );
        assert!(
            (sd - sd_want).abs() <= 0.06 * sd_want + 1e-12,
            "component {c}: sd {sd}"
        );
    }
    // Components from streams of their own: uncorrelated (|r| of 4000 pairs ≲ 0.016 per σ).
    let (mx, sx) = stats(&translate, 0);
    let (my, sy) = stats(&translate, 1);
    let r = translate
        .iter()
        .map(|t| (t[0] - mx) * (t[1] - my))
        .sum::<f64>()
        / (3999.0 * sx * sy);
    assert!(r.abs() < 0.08, "the components are correlated: r = {r}");
    // The same draws however often they are asked for, and per sample, not per call order.
    assert_eq!(sample_draws(&spec, 17), rows[17]);
}

#[test]
fn bad_specs_are_refused_in_one_line_naming_file_line_and_key() {
    let dir = tempfile::tempdir().unwrap();
    let das = common::repo_path("scenes/das.toml");
    let head = format!("scene = {das:?}\nsamples = 2\n");
    let cases: [(&str, &str); 18] = [
        ("scene = \"missing.toml\"\nsamples = 2\n", "missing.toml"),
        (&format!("scene = {das:?}\n"), "samples"),
        (&format!("{head}samples_x = 3\n"), "unknown key"),
        (&format!("{head}[options]\nwidth = 0\n"), "options.width"),
        (
            &format!("{head}[options]\nheadd = \"oracle\"\n"),
            "not an option",
        ),
        (
            &format!("{head}[draw]\nmethod = {{ one_of = [\"planar-inf\"] }}\n"),
            "draw.method.one_of",
        ),
        (
            &format!("{head}[draw]\ntheta_f = {{ uniform = [60, 40] }}\n"),
            "above high",
        ),
        (
            &format!("{head}[draw]\ntheta_f = {{ normal = [50, -1] }}\n"),
            "negative",
        ),
        (
            &format!("{head}[draw]\nmethod = {{ uniform = [0, 1] }}\n"),
            "not a number",
        ),
        (&format!("{head}[draw]\neye = \"random\"\n"), "eyellipse"),
        (
            &format!("{head}[draw]\ntheta_f = {{ uniform = [40, 60], normal = [1, 2] }}\n"),
            "exactly one",
        ),
        (
            &format!("{head}[options]\nspp = 2\n[draw]\nspp = {{ one_of = [1, 2] }}\n"),
            "also in [options]",
        ),
        (
            &format!("{head}[draw.scene]\nsun.intensity = {{ uniform = [[1, 2], [3]] }}\n"),
            "of one length",
        ),
        (&format!("{head}[draw.scene]\nsun = {{}}\n"), "found none"),
        (
            &format!(
                "{head}[draw.scene]\n\"object.bus.translate\" = {{ one_of = [[0, 0, -9]] }}\n"
            ),
            "no [[object]] is named `bus`",
        ),
        (
            &format!("{head}[draw.scene]\nsun.intensity = {{ uniform = [2000, 3000] }}\n"),
            "sun.intensity",
        ),
        (
            &format!(
                "{head}[draw]\ntheta_f = {{ uniform = [40, 50] }}\n[draw.scene]\ncamera.frontal.half_angle_deg = {{ one_of = [45] }}\n"
            ),
            "set the same thing",
        ),
        (
            &format!(
                "{head}[draw.scene]\nsun.intensity = {{ one_of = [1] }}\n\"sun.intensity\" = {{ one_of = [2] }}\n"
            ),
            "drawn twice",
        ),
    ];
    for (i, (text, says)) in cases.iter().enumerate() {
        let spec = dir.path().join(format!("bad{i}.toml"));
        std::fs::write(&spec, text).unwrap();
        let out = dir.path().join(format!("out{i}"));
        let (ok, _, err) = seethru(&[
            "dataset",
            spec.to_str().unwrap(),
            "--out",
            out.to_str().unwrap(),
        ]);
        assert!(!ok, "case {i} was accepted");
        assert_eq!(err.lines().count(), 1, "case {i}: {err}");
        assert!(
            err.starts_with("error: ") && err.contains(says),
            "case {i}: {err}"
        );
        assert!(
            err.contains(&format!("bad{i}.toml")),
            "case {i} names no file: {err}"
        );
        assert!(!out.exists(), "case {i} wrote {}", out.display());
    }
    // Both eyes, and a sample over its memory bound.
    for (options, says) in [
        ("eyes = \"both\"", "one eye's run"),
        ("max_memory = 0.001", "GiB"),
        (
            "[draw]\neye_z = { uniform = [-3, -2] }",
            "behind the display",
        ),
    ] {
        let spec = dir.path().join("options.toml");
        let table = if options.starts_with('[') {
            ""
        } else {
            "[options]\n"
        };
        std::fs::write(&spec, format!("{head}{table}{options}\n")).unwrap();
        let out = dir.path().join("options_out");
        let (ok, _, err) = seethru(&[
            "dataset",
            spec.to_str().unwrap(),
            "--out",
            out.to_str().unwrap(),
        ]);
        assert!(
            !ok && err.starts_with("error: ") && err.contains(says),
            "{options}: {err}"
        );
        assert_eq!(err.lines().count(), 1, "{err}");
    }
    // A draw that a run refuses names the sample and the value.
    let spec = spec_in(dir.path(), 2, "head_jitter_cm = { normal = [-50, 0] }\n");
    let out = dir.path().join("refused");
    let (ok, _, err) = seethru(&[
        "dataset",
        spec.to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
    ]);
    assert!(
        !ok && err.contains("sample 0 of 2") && err.contains("head_jitter_cm = -50"),
        "{err}"
    );
}

#[test]
fn scene_key_draws_make_the_scene_an_edit_of_its_file_by_hand_makes() {
    let dir = tempfile::tempdir().unwrap();
    let das_path = common::repo_path("scenes/das.toml");
    let das = std::fs::read_to_string(&das_path).unwrap();
    let (car, sun) = ("translate = [-1.75, 0.0, -8.5]", "intensity = 2.6");
    for line in [car, sun, "cloud_seed = 3\n"] {
        assert_eq!(das.matches(line).count(), 1, "{line}");
    }
    let spec = spec_in(
        dir.path(),
        2,
        "[draw.scene]\n\"object.car.translate\" = { uniform = [[-2.5, 0, -12], [-1, 0.01, -7]] }\nsun.intensity = { normal = [2, 0.5] }\nsky.ground_color = { one_of = [[0.3, 0.3, 0.3], [0.5, 0.4, 0.3]] }\n",
    );
    let out = dir.path().join("d");
    make(&spec, &out, &["--quiet"]);
    let base = dir.path().join("base");
    for i in 0..2 {
        let folder = out.join(format!("samples/{i:06}"));
        let draws = &json(&folder.join("sample.json"))["draws"];
        let text = |k: &str| draws[k].as_str().unwrap().to_string();
        let translate: Vec<f64> =
            serde_json::from_str(&text("scene.object.car.translate")).unwrap();
        for (c, (low, high)) in translate
            .iter()
            .zip([(-2.5, -1.0), (0.0, 0.01), (-12.0, -7.0)])
        {
            assert!((low..=high).contains(c), "{translate:?}");
        }
        // The same scene, edited as a person would, at another place (its assets absolute).
        let edited = das
            .replace(
                car,
                &format!("translate = {}", text("scene.object.car.translate")),
            )
            .replace(sun, &format!("intensity = {}", text("scene.sun.intensity")))
            .replace(
                "\"../assets/",
                &format!("\"{}/", common::repo_path("assets").display()),
            );
        // A key the file lacks is added to its table.
        assert!(!das.contains("ground_color"));
        let ground = text("scene.sky.ground_color");
        let edited = edited.replace(
            "cloud_seed = 3\n",
            &format!("cloud_seed = 3\nground_color = {ground}\n"),
        );
        let scene = dir.path().join(format!("edited{i}.toml"));
        std::fs::write(&scene, edited).unwrap();
        run_as_the_spec(&scene, &base);
        for file in ["truth.png", "seethru.png", "frontal.png", "metrics.json"] {
            assert!(
                std::fs::read(folder.join(file)).unwrap()
                    == std::fs::read(base.join(file)).unwrap(),
                "sample {i}: {file} differs from the hand-edited scene's"
            );
        }
        std::fs::remove_dir_all(&base).unwrap();
    }
}

/// The number after `key` on the line of `text` that has it (`completions: 4` → 4).
fn number_after(text: &str, key: &str) -> usize {
    let line = text
        .lines()
        .find(|l| l.contains(key))
        .unwrap_or_else(|| panic!("no {key}"));
    let rest = &line[line.find(key).unwrap() + key.len()..];
    rest.trim_matches(|c: char| !c.is_ascii_digit())
        .split(|c: char| !c.is_ascii_digit())
        .next()
        .unwrap()
        .parse()
        .unwrap()
}

#[test]
fn the_kubernetes_job_and_the_slurm_array_make_what_one_process_makes() {
    let repo = common::repo_path("");
    let dir = tempfile::tempdir().unwrap();
    // A folder that looks like the repository root (as the image's workingDir and the
    // submit folder are), the binary where the Slurm script calls it.
    let root = dir.path().join("root");
    std::fs::create_dir_all(root.join("target/release")).unwrap();
    for folder in ["examples", "scenes", "assets"] {
        std::os::unix::fs::symlink(repo.join(folder), root.join(folder)).unwrap();
    }
    let bin = PathBuf::from(env!("CARGO_BIN_EXE_seethru"));
    std::os::unix::fs::symlink(&bin, root.join("target/release/seethru")).unwrap();
    let spec = "examples/dataset/das_pairs.toml";
    let (ok, _, err) = common::seethru_in(&root, &["dataset", spec, "--quiet", "--out", "one"]);
    assert!(ok, "{err}");
    let reference = files(&root.join("one"));
    assert!(!reference.is_empty());

    let sbatch = std::fs::read_to_string(repo.join("examples/slurm/dataset.sbatch")).unwrap();
    let tasks = number_after(&sbatch, "--array=0-") + 1;
    assert_eq!(
        tasks,
        number_after(&sbatch, "PARTS="),
        "the array and PARTS disagree"
    );
    for k in 0..tasks {
        let out = std::process::Command::new("bash")
            .arg(repo.join("examples/slurm/dataset.sbatch"))
            .current_dir(&root)
            .env("SLURM_ARRAY_TASK_ID", k.to_string())
            .env("SLURM_CPUS_PER_TASK", "1")
            .output()
            .unwrap();
        assert!(
            out.status.success(),
            "task {k}: {}",
            String::from_utf8_lossy(&out.stderr)
        );
    }
    assert!(
        files(&root.join("das_pairs")) == reference,
        "the Slurm array's dataset differs"
    );

    let job = std::fs::read_to_string(repo.join("examples/k8s/dataset-job.yaml")).unwrap();
    let pods = number_after(&job, "completions:");
    let parts = number_after(&job, "value: \"");
    assert_eq!(pods, parts, "completions and PARTS disagree");
    // The pod's command: the folded block after `- >-`, its lines joined by spaces.
    let lines: Vec<&str> = job.lines().collect();
    let at = lines
        .iter()
        .position(|l| l.trim() == "- >-")
        .expect("the args block");
    let indent = |l: &str| l.len() - l.trim_start().len();
    let command: Vec<&str> = lines[at + 1..]
        .iter()
        .take_while(|l| indent(l) > indent(lines[at]))
        .map(|l| l.trim())
        .collect();
    let results = dir.path().join("results");
    let command = command
        .join(" ")
        .replace("/results", results.to_str().unwrap());
    let path = format!(
        "{}:{}",
        bin.parent().unwrap().display(),
        std::env::var("PATH").unwrap_or_default()
    );
    for k in 0..pods {
        let out = std::process::Command::new("sh")
            .args(["-c", &command])
            .current_dir(&root)
            .env("JOB_COMPLETION_INDEX", k.to_string())
            .env("PARTS", parts.to_string())
            .env("PATH", &path)
            .output()
            .unwrap();
        assert!(
            out.status.success(),
            "pod {k}: {command}: {}",
            String::from_utf8_lossy(&out.stderr)
        );
    }
    assert!(
        files(&results.join("das_pairs")) == reference,
        "the Indexed Job's dataset differs"
    );
}
