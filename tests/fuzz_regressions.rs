//! Inputs the fuzzers of `fuzz/` found a failure with, replayed through the same reader and
//! held to the same rule: an error of one line, or rows that are rows of the sweep.

use std::path::{Path, PathBuf};

use seethru::measure::sweep_csv::finished_rows;
use seethru::scene::mesh_io::parse_obj;

/// The inputs kept for one fuzz target, `tests/fuzz/<target>/`.
fn inputs(target: &str) -> Vec<(PathBuf, Vec<u8>)> {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/fuzz")
        .join(target);
    let mut found: Vec<(PathBuf, Vec<u8>)> = std::fs::read_dir(&dir)
        .unwrap()
        .flatten()
        .map(|e| (e.path(), std::fs::read(e.path()).unwrap()))
        .collect();
    found.sort();
    assert!(!found.is_empty(), "no inputs in {}", dir.display());
    found
}

/// The fuzz target's settings.
fn settings() -> Vec<String> {
    ["32", "1", "oracle", "5", "0123456789abcdef", "0.1.0"]
        .iter()
        .map(|s| s.to_string())
        .collect()
}

/// The fuzz target's configurations: θ_F ∈ {20, 40} × d2 ∈ {inf, 5}.
fn configs() -> Vec<Vec<(String, String)>> {
    ["20", "40"]
        .iter()
        .flat_map(|t| {
            ["inf", "5"].iter().map(move |d| {
                vec![
                    ("theta_f".to_string(), t.to_string()),
                    ("d2".to_string(), d.to_string()),
                ]
            })
        })
        .collect()
}

#[test]
fn sweep_csv_inputs_found_by_fuzzing_give_one_line_errors() {
    for (path, bytes) in inputs("sweep_csv") {
        let text = std::str::from_utf8(&bytes).unwrap();
        match finished_rows(
            text,
            Path::new("sweep.csv"),
            &["theta_f".into(), "d2".into()],
            &configs(),
            &settings(),
        ) {
            Ok(rows) => assert!(rows.iter().all(|(i, _)| *i < 4), "{rows:?}"),
            // A quoted field may hold line breaks: the message must not.
            Err(e) => {
                let shown = format!("{e:#}");
                assert!(!shown.contains('\n'), "{}: {shown}", path.display());
            }
        }
    }
}

#[test]
fn gltf_inputs_found_by_fuzzing_are_refused_in_one_line() {
    // An image with neither a uri nor a bufferView: the gltf crate's `Image::source`
    // unwrapped the uri (a panic), as it does a bufferView's missing mimeType.
    for (path, bytes) in inputs("gltf") {
        let read = |_: &Path| Err(std::io::ErrorKind::NotFound.into());
        let shown = format!(
            "{:#}",
            seethru::scene::mesh_io::parse_gltf(&bytes, Path::new("mesh.gltf"), &read)
                .expect_err("refused")
        );
        assert!(
            !shown.contains('\n') && shown.starts_with("image 0 "),
            "{}: {shown}",
            path.display()
        );
    }
}

#[test]
fn obj_inputs_found_by_fuzzing_are_refused_naming_the_line_and_in_time() {
    // As the fuzz target splits them: the OBJ, a NUL byte, the MTL its `mtllib` reads. Each
    // kept input is broken at a line of the OBJ or of its MTL, which the error names (tobj's
    // own errors name none, and its index arithmetic overflowed on some: a panic where
    // overflow checks are on). Some made the reader quadratic (an MTL read again for each of
    // 340 `mtllib` lines): each must be refused within seconds, under a watchdog.
    for (path, bytes) in inputs("obj") {
        let (send, receive) = std::sync::mpsc::channel();
        std::thread::spawn(move || {
            let (obj, mtl) = match bytes.iter().position(|&b| b == 0) {
                Some(i) => (&bytes[..i], bytes[i + 1..].to_vec()),
                None => (&bytes[..], Vec::new()),
            };
            let read = |_: &Path| Ok(mtl.clone());
            let result = parse_obj(obj, Path::new("mesh.obj"), &read);
            let _ = send.send(result.map(|_| ()).map_err(|e| format!("{e:#}")));
        });
        let shown = match receive.recv_timeout(std::time::Duration::from_secs(10)) {
            Err(_) => panic!("{}: not refused within 10 s", path.display()),
            Ok(Ok(())) => panic!("{}: accepted", path.display()),
            Ok(Err(shown)) => shown,
        };
        assert!(
            !shown.contains('\n')
                && (shown.starts_with("invalid OBJ: line ")
                    || (shown.starts_with("material library `") && shown.contains(": line "))),
            "{}: {shown}",
            path.display()
        );
    }
}

#[test]
fn display_map_inputs_found_by_fuzzing_are_refused_in_one_line() {
    // (2³², 2³², 2) multiplied to 2⁶⁴ pixels: a panic with overflow checks, and without them
    // the count wrapped to 0, which passed the size check and read as an empty 0×0 map. A
    // shape holding a line break and NULs was echoed raw by the "not a tuple" message.
    for (path, bytes) in inputs("display_map") {
        let shown = match seethru::io::display_map::parse_npy(&bytes) {
            Ok(m) => panic!("{}: read as a {}×{} map", path.display(), m.width, m.height),
            Err(e) => format!("{e:#}"),
        };
        assert!(
            !shown.chars().any(char::is_control)
                && (shown.contains("pixels") || shown.contains("is not a tuple of integers")),
            "{}: {shown}",
            path.display()
        );
    }
}

#[test]
fn a_stated_fingerprint_that_is_not_one_is_refused_where_it_is_read() {
    // A sidecar's capture_fingerprint is echoed by the mismatch message of `score`: one with
    // a line break made that message two lines. It is refused when read, escaped.
    let dir = tempfile::tempdir().unwrap();
    let map = dir.path().join("map.npy");
    seethru::io::display_map::write_npy_f32(&map, &[1, 1, 2], &[0.5, 0.5]).unwrap();
    let sidecar = dir.path().join("map.npy.json");
    for (stated, accepted) in [
        ("0123456789abcdef", true),
        ("0123456789abcde\n", false),
        ("0123456789ABCDEF0", false),
        ("", false),
    ] {
        std::fs::write(
            &sidecar,
            serde_json::json!({ "capture_fingerprint": stated }).to_string(),
        )
        .unwrap();
        match seethru::io::display_map::read_map(&map) {
            Ok(m) => {
                assert!(accepted, "{stated:?} accepted");
                assert_eq!(m.fingerprint.as_deref(), Some(stated));
            }
            Err(e) => {
                let shown = format!("{e:#}");
                assert!(!accepted, "{stated:?}: {shown}");
                assert!(
                    !shown.contains('\n') && shown.contains("16 hex digits"),
                    "{shown}"
                );
            }
        }
    }
}

#[test]
fn expectation_files_echoing_a_line_break_are_refused_in_one_line() {
    // A bound or a case name is echoed in its message: a TOML `\n` in it split the message.
    for (path, _) in inputs("expectations") {
        let shown = match seethru::measure::expectations::read_expectations(&path, &|_, _| None) {
            Ok(_) => panic!("{}: accepted", path.display()),
            Err(e) => e.to_string(),
        };
        assert!(
            shown.starts_with(&format!("{}:", path.display()))
                && !shown.contains(['\n', '\r', '\u{1b}'])
                && shown.contains("\\n"),
            "{}: {shown}",
            path.display()
        );
    }
}

#[test]
fn head_paths_echoing_a_line_break_are_refused_in_one_line() {
    // A quoted CSV field holding a line break (and a NUL) was echoed raw by the "must be a
    // finite number" message: two lines, and a control character on the terminal.
    for (path, bytes) in inputs("head_path") {
        let shown = match seethru::scene::head_path::HeadPath::parse(&bytes, "path.csv") {
            Ok(p) => panic!("{}: read as {} samples", path.display(), p.samples.len()),
            Err(e) => format!("{e:#}"),
        };
        assert!(
            shown.starts_with("path.csv:1: `x` must be a finite number")
                && !shown.chars().any(char::is_control)
                && shown.contains("\\n"),
            "{}: {shown}",
            path.display()
        );
    }
}

#[test]
fn scenes_echoing_a_line_break_are_refused_in_one_line() {
    // A choice (`kind = "pla\ne"`) was echoed raw by "is not one of": two lines.
    for (path, bytes) in inputs("scene") {
        let text = String::from_utf8(bytes).unwrap();
        let file = seethru::scene::source::SourceFile::from_text(Path::new("scene.toml"), text);
        let shown = match seethru::scene::Scene::from_source(&file) {
            Ok(_) => panic!("{}: accepted", path.display()),
            Err(e) => e.to_string(),
        };
        assert!(
            shown.starts_with("scene.toml:")
                && !shown.chars().any(char::is_control)
                && shown.contains("\\n"),
            "{}: {shown}",
            path.display()
        );
    }
}

#[test]
fn sweep_merge_shows_a_setting_cell_holding_a_line_break_in_one_line() {
    // The class of tests/fuzz/sweep_csv/setting_with_a_line_break.csv in the merge's own
    // message: two parts whose rows differ in a setting, one written as a quoted cell with a
    // line break and 60 more characters. The message shows it escaped and cut.
    let kept = inputs("sweep_csv");
    let text = std::str::from_utf8(
        &kept
            .iter()
            .find(|(p, _)| p.ends_with("setting_with_a_line_break.csv"))
            .unwrap()
            .1,
    )
    .unwrap()
    .to_string();
    let header = text.lines().next().unwrap();
    let row = |index: usize, theta: &str, version: &str| {
        format!(
            "{index},{theta},inf,28,0.033,4,2,11,5.9,0.5,0.32,0,0,0.9,0.6,4,32,1,oracle,5,0123456789abcdef,{version}\n"
        )
    };
    let dir = tempfile::tempdir().unwrap();
    let (a, b) = (dir.path().join("p0.csv"), dir.path().join("p1.csv"));
    std::fs::write(&a, format!("{header}\n{}", row(0, "20", "0.1.0"))).unwrap();
    let long = format!("\"0.1.0\n{}\"", "x".repeat(60));
    std::fs::write(&b, format!("{header}\n{}", row(1, "40", &long))).unwrap();
    let err = seethru::measure::sweep_shard::merge(&[&a, &b], &dir.path().join("m.csv"))
        .err()
        .expect("parts computed with other settings are refused");
    let shown = format!("{err:#}");
    assert!(!shown.contains('\n'), "{shown}");
    assert!(
        shown.contains("computed with seethru 0.1.0\\nxxx") && shown.contains("x…,"),
        "{shown}"
    );
    assert!(shown.len() < 400, "{shown}");
}
