//! The viewer (`view.html`, measure/viewer.rs): what `run` writes from memory and what `seethru
//! view` writes from the files are the same page; the values the page embeds are the EXRs'
//! bit for bit; bad folders are refused in one line; and, in headless Chromium
//! (tests/browser/viewer_in_chromium.py), the pointer over a display pixel reads the
//! misregistration of misregistration.exr, a scrubbed sequence reads its frames.csv row.

mod common;

use std::path::{Path, PathBuf};
use std::process::Command;

use base64::Engine;
use common::{exr_channels, seethru};
use serde_json::Value;

fn das() -> String {
    common::repo_path("scenes/das.toml").display().to_string()
}

fn run_into(out: &Path, extra: &[&str]) {
    let mut args = vec![
        "run".to_string(),
        das(),
        "--width".into(),
        "96".into(),
        "--frontal-width".into(),
        "160".into(),
        "--back-width".into(),
        "96".into(),
        "--spp".into(),
        "1".into(),
        "--quiet".into(),
        "--out".into(),
        out.display().to_string(),
    ];
    args.extend(extra.iter().map(|s| s.to_string()));
    let (ok, _, err) = seethru(&args);
    assert!(ok, "{err}");
}

/// The JSON the page embeds.
fn page_data(html: &str) -> Value {
    let start = html
        .find("type=\"application/json\">")
        .expect("the data script")
        + 24;
    let end = start + html[start..].find("</script>").expect("its end");
    serde_json::from_str(&html[start..end]).expect("valid JSON")
}

fn decoded(v: &Value) -> Vec<u8> {
    base64::engine::general_purpose::STANDARD
        .decode(v.as_str().expect("base64 text"))
        .unwrap()
}

fn f32s(channels: &[(String, exr::prelude::FlatSamples)], name: &str) -> Vec<f32> {
    match &channels.iter().find(|(n, _)| n == name).expect(name).1 {
        exr::prelude::FlatSamples::F32(v) => v.clone(),
        _ => panic!("{name} is not f32"),
    }
}

fn u32s(channels: &[(String, exr::prelude::FlatSamples)], name: &str) -> Vec<u32> {
    match &channels.iter().find(|(n, _)| n == name).expect(name).1 {
        exr::prelude::FlatSamples::U32(v) => v.clone(),
        _ => panic!("{name} is not u32"),
    }
}

#[test]
fn run_and_view_write_the_same_page_whose_values_are_the_exrs() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("run");
    run_into(&out, &["--heatmap-max", "90", "--exr", "all"]);
    let written = std::fs::read_to_string(out.join("view.html")).unwrap();
    std::fs::remove_file(out.join("view.html")).unwrap();
    let (ok, _, err) = seethru(&["view", out.to_str().unwrap(), "--quiet"]);
    assert!(ok, "{err}");
    let viewed = std::fs::read_to_string(out.join("view.html")).unwrap();
    assert!(
        written == viewed,
        "run's page (frames in memory) and view's (the files) differ"
    );
    // `measure` rewrites the metrics and the page beside them: the same page again.
    let (ok, _, err) = seethru(&["measure", out.to_str().unwrap(), "--quiet"]);
    assert!(ok, "{err}");
    assert!(std::fs::read_to_string(out.join("view.html")).unwrap() == written);

    let data = page_data(&written);
    let maps = exr_channels(&out.join("misregistration.exr"));
    let truth = exr_channels(&out.join("truth.exr"));
    let seethru_exr = exr_channels(&out.join("seethru.exr"));
    let (mis, display) = (f32s(&maps, "Y"), f32s(&maps, "display.mask"));
    let missing = f32s(&maps, "missing.mask");
    let (w, h) = (
        data["width"].as_u64().unwrap() as usize,
        data["height"].as_u64().unwrap() as usize,
    );
    assert_eq!(mis.len(), w * h);
    let b: Vec<usize> = data["box"]
        .as_array()
        .unwrap()
        .iter()
        .map(|v| v.as_u64().unwrap() as usize)
        .collect();
    let (x0, y0, bw, bh) = (b[0], b[1], b[2], b[3]);
    // The box is the display's bounding box: every display pixel inside, each edge touched.
    let on: Vec<(usize, usize)> = (0..w * h)
        .filter(|&i| display[i] > 0.5)
        .map(|i| (i % w, i / w))
        .collect();
    assert!(on.len() > 50, "the display covers pixels");
    assert_eq!(on.iter().map(|p| p.0).min(), Some(x0));
    assert_eq!(on.iter().map(|p| p.1).min(), Some(y0));
    assert_eq!(on.iter().map(|p| p.0).max(), Some(x0 + bw - 1));
    assert_eq!(on.iter().map(|p| p.1).max(), Some(y0 + bh - 1));
    let le_f32 = |bytes: Vec<u8>| -> Vec<f32> {
        bytes
            .chunks(4)
            .map(|c| f32::from_le_bytes(c.try_into().unwrap()))
            .collect()
    };
    let le_u32 = |bytes: Vec<u8>| -> Vec<u32> {
        bytes
            .chunks(4)
            .map(|c| u32::from_le_bytes(c.try_into().unwrap()))
            .collect()
    };
    let page_mis = le_f32(decoded(&data["misregistration"]));
    let page_depth = le_f32(decoded(&data["truth_depth"]));
    let page_should = le_u32(decoded(&data["truth_ids"]));
    let page_shown = le_u32(decoded(&data["shown_ids"]));
    let state = decoded(&data["state"]);
    assert_eq!(page_mis.len(), bw * bh);
    let (z, truth_ids, shown_ids) = (
        f32s(&truth, "Z"),
        u32s(&truth, "id.object"),
        u32s(&seethru_exr, "id.object"),
    );
    for j in 0..bh {
        for i in 0..bw {
            let (k, p) = (j * bw + i, (y0 + j) * w + x0 + i);
            assert_eq!(page_mis[k].to_bits(), mis[p].to_bits(), "pixel {p}");
            assert_eq!(page_depth[k].to_bits(), z[p].to_bits(), "pixel {p}");
            assert_eq!(page_should[k], truth_ids[p]);
            assert_eq!(page_shown[k], shown_ids[p]);
            let want = (display[p] > 0.5) as u8
                | ((mis[p].is_finite() as u8) << 1)
                | (((missing[p] > 0.5) as u8) << 2);
            assert_eq!(state[k], want, "state of pixel {p}");
        }
    }
    // The names the ids index, and the heatmap's fixed top, as the run recorded them.
    let run: Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("run.json")).unwrap()).unwrap();
    assert_eq!(data["object_names"], run["object_names"]);
    let names = run["object_names"].as_array().unwrap();
    assert!(names.iter().any(|n| n == "car") && names.iter().any(|n| n == "obstacle"));
    assert_eq!(data["heat_top"], 90.0);
    // The page's colours are the heatmap PNG's (a pixel well inside the top).
    let lut = decoded(&data["heat_lut"]);
    assert_eq!(lut.len(), 768);
    assert_eq!(&lut[..3], &seethru::measure::maps::heat_color(0.0));
    assert_eq!(&lut[765..], &seethru::measure::maps::heat_color(1.0));
}

#[test]
fn a_run_without_depth_or_ids_says_so_and_a_folder_without_outputs_is_refused() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("lean");
    run_into(&out, &["--exr", "none"]);
    let data = page_data(&std::fs::read_to_string(out.join("view.html")).unwrap());
    // From memory the run has them; from the files (no EXR) the page says what is absent.
    assert!(data["truth_depth"].is_string());
    let (ok, _, err) = seethru(&["view", out.to_str().unwrap(), "--quiet"]);
    assert!(ok, "{err}");
    let data = page_data(&std::fs::read_to_string(out.join("view.html")).unwrap());
    assert!(data["truth_depth"].is_null() && data["truth_ids"].is_null());
    assert!(
        data["notes"][0]
            .as_str()
            .unwrap()
            .contains("no depth or ids")
    );

    let empty = dir.path().join("empty");
    std::fs::create_dir(&empty).unwrap();
    let cases: [(PathBuf, &str); 3] = [
        (empty.clone(), "holds no seethru outputs"),
        (dir.path().join("absent"), "not a folder"),
        (out.join("run.json"), "not a folder"),
    ];
    for (path, says) in cases {
        let (ok, _, err) = seethru(&["view", path.to_str().unwrap()]);
        assert!(!ok);
        assert_eq!(err.lines().count(), 1, "{err}");
        assert!(err.starts_with("error: ") && err.contains(says), "{err}");
        assert!(err.contains(path.to_str().unwrap()), "{err}");
    }
    // A misregistration map that is not an EXR, and a truth PNG of another size.
    let broken = dir.path().join("broken");
    std::fs::create_dir(&broken).unwrap();
    for f in ["truth.png", "run.json", "metrics.json"] {
        std::fs::copy(out.join(f), broken.join(f)).unwrap();
    }
    std::fs::write(broken.join("misregistration.exr"), "not an exr").unwrap();
    let (ok, _, err) = seethru(&["view", broken.to_str().unwrap()]);
    assert!(
        !ok && err.starts_with("error: ") && err.contains("misregistration.exr"),
        "{err}"
    );
    std::fs::copy(
        out.join("misregistration.exr"),
        broken.join("misregistration.exr"),
    )
    .unwrap();
    std::fs::copy(out.join("frontal.png"), broken.join("truth.png")).unwrap();
    let (ok, _, err) = seethru(&["view", broken.to_str().unwrap()]);
    assert!(!ok && err.contains("truth.png is 160×"), "{err}");
    assert!(
        !broken.join("view.html").exists(),
        "nothing written on an error"
    );
}

/// The browser check: a run, a sequence of two latencies with frame images, a compare and a
/// dataset, then the Python script drives Chromium over their pages.
#[test]
fn in_chromium_the_pointer_reads_the_exr_and_the_slider_reads_frames_csv() {
    let chromium = std::env::var("SEETHRU_CHROMIUM").unwrap_or("/usr/bin/chromium".into());
    let driver = std::env::var("SEETHRU_CHROMEDRIVER").unwrap_or("/usr/bin/chromedriver".into());
    if !Path::new(&chromium).exists() || !Path::new(&driver).exists() {
        match std::env::var("SEETHRU_SKIP_BROWSER") {
            Ok(reason) => {
                eprintln!("skipped: no browser ({chromium}, {driver}): {reason}");
                return;
            }
            Err(_) => panic!(
                "no browser at {chromium} and {driver}: install Debian's chromium and chromium-driver (.ci/run does), or set SEETHRU_SKIP_BROWSER to the reason none can be installed"
            ),
        }
    }
    let dir = tempfile::tempdir().unwrap();
    let (run, seq, cmp) = (
        dir.path().join("run"),
        dir.path().join("seq"),
        dir.path().join("cmp"),
    );
    run_into(&run, &[]);
    let (ok, _, err) = seethru(&[
        "sequence",
        &das(),
        "--width",
        "64",
        "--duration",
        "0.4",
        "--fps",
        "10",
        "--speed",
        "30",
        "--latency-camera",
        "0,50",
        "--frames",
        "png",
        "--quiet",
        "--out",
        seq.to_str().unwrap(),
    ]);
    assert!(ok, "{err}");
    let (ok, _, err) = seethru(&[
        "compare",
        &das(),
        "--width",
        "48",
        "--spp",
        "1",
        "--methods",
        "planar-inf,planar-auto",
        "--quiet",
        "--out",
        cmp.to_str().unwrap(),
    ]);
    assert!(ok, "{err}");
    let data = dir.path().join("data");
    let spec = dir.path().join("spec.toml");
    std::fs::write(
        &spec,
        format!(
            "scene = {:?}\nsamples = 4\n[options]\nwidth = 48\nspp = 1\n[draw]\ntheta_f = {{ uniform = [40, 60] }}\n[draw.scene]\n\"object.car.translate\" = {{ uniform = [[-2.5, 0, -14], [-1, 0, -7]] }}\n",
            das()
        ),
    )
    .unwrap();
    let (ok, _, err) = seethru(&[
        "dataset",
        spec.to_str().unwrap(),
        "--quiet",
        "--out",
        data.to_str().unwrap(),
    ]);
    assert!(ok, "{err}");
    let python = common::python_env::python_with(&["numpy", "OpenEXR", "selenium"]);
    let shots = PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join("browser-screenshots");
    let script = common::repo_path("tests/browser/viewer_in_chromium.py");
    let out = Command::new(python)
        .arg(script)
        .args([&run, &seq, &cmp, &data, &shots])
        .env("SEETHRU_CHROMIUM", &chromium)
        .env("SEETHRU_CHROMEDRIVER", &driver)
        .output()
        .unwrap();
    let text = format!(
        "{}\n{}",
        String::from_utf8_lossy(&out.stdout),
        String::from_utf8_lossy(&out.stderr)
    );
    eprintln!("{text}\nscreenshots in {}", shots.display());
    assert!(out.status.success(), "the browser check failed:\n{text}");
    assert!(
        text.contains("ok: run readout") && text.contains("ok: sequence"),
        "{text}"
    );
}
