//! Bad input as a careless user or script makes it, one test per class: each is refused with
//! one line on stderr starting `error:` that names the file (and line, key or flag), the value
//! and what is admissible; the exit code says usage (2) or input (1); nothing is left behind.

mod common;

use std::path::{Path, PathBuf};
use std::process::Command;

/// Runs seethru in `dir`; (exit code, stderr).
fn run_in(dir: &Path, args: &[&str]) -> (i32, String) {
    let out = Command::new(env!("CARGO_BIN_EXE_seethru"))
        .arg("--quiet")
        .args(args)
        .current_dir(dir)
        .output()
        .unwrap();
    (
        out.status.code().unwrap_or(-1),
        String::from_utf8_lossy(&out.stderr).into(),
    )
}

/// The command fails with `code` and one `error:` line holding every one of `words`.
fn refused(dir: &Path, args: &[&str], code: i32, words: &[&str]) -> String {
    let (got, err) = run_in(dir, args);
    assert_eq!(got, code, "{args:?}: exit code {got}: {err}");
    assert!(!err.contains("panicked"), "{args:?}: {err}");
    assert_eq!(err.lines().count(), 1, "{args:?}: one line: {err}");
    assert!(err.starts_with("error: "), "{args:?}: {err}");
    for w in words {
        assert!(
            err.contains(w),
            "{args:?}: `{}` lacks `{w}`",
            err.trim_end()
        );
    }
    err.trim_end().to_string()
}

/// Every entry under `dir`, recursively, as sorted relative paths.
fn listing(dir: &Path) -> Vec<String> {
    let mut out = Vec::new();
    let mut stack = vec![dir.to_path_buf()];
    while let Some(d) = stack.pop() {
        for e in std::fs::read_dir(&d).unwrap().flatten() {
            let p = e.path();
            out.push(p.strip_prefix(dir).unwrap().display().to_string());
            if p.is_dir() {
                stack.push(p);
            }
        }
    }
    out.sort();
    out
}

/// A scratch folder with the minimal scene plus `extra` TOML as `scene.toml`, and `files`.
fn scratch(extra: &str, files: &[(&str, &[u8])]) -> tempfile::TempDir {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(
        dir.path().join("scene.toml"),
        format!("{}{extra}", common::MINIMAL),
    )
    .unwrap();
    for (name, bytes) in files {
        let path = dir.path().join(name);
        std::fs::create_dir_all(path.parent().unwrap()).unwrap();
        std::fs::write(path, bytes).unwrap();
    }
    dir
}

const RENDER: &[&str] = &[
    "render",
    "scene.toml",
    "--out",
    "out",
    "--view",
    "truth",
    "--width",
    "8",
];

/// Renders the scene of `dir` and expects a refusal holding `words`; nothing new in `dir`.
fn render_refused(dir: &Path, words: &[&str]) -> String {
    let before = listing(dir);
    let err = refused(dir, RENDER, 1, words);
    assert_eq!(listing(dir), before, "the failed render left files behind");
    err
}

fn mesh_object(path: &str) -> String {
    format!(
        "\n[[object]]\nname = \"m\"\nkind = \"mesh\"\npath = \"{path}\"\ntranslate = [0.0, 0.0, -5.0]\n"
    )
}

const TRIANGLE: &str = "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n";

#[test]
fn obj_vertices_that_are_not_finite_or_outside_the_world_are_refused() {
    for (bad, shown) in [
        ("nan", "NaN"),
        ("inf", "inf"),
        ("-inf", "-inf"),
        ("1e30", "1e30"),
        ("1e300", "inf"),
        ("-2e6", "-2000000"),
    ] {
        let obj = TRIANGLE.replacen("v 1 0 0", &format!("v 1 {bad} 0"), 1);
        let dir = scratch(&mesh_object("m.obj"), &[("m.obj", obj.as_bytes())]);
        render_refused(
            dir.path(),
            &["mesh m.obj", shown, "within the world, [-1e6, 1e6] m"],
        );
    }
    // Inside the file's frame but placed outside the world by the object's transform.
    let dir = scratch(
        &mesh_object("m.obj").replace("[0.0, 0.0, -5.0]", "[1e6, 0.0, -5.0]"),
        &[("m.obj", TRIANGLE.as_bytes())],
    );
    render_refused(dir.path(), &["object `m`", "m.obj", "outside the world"]);
}

#[test]
fn obj_texture_coordinates_that_are_not_finite_are_refused() {
    let obj = "v 0 0 0\nv 1 0 0\nv 0 1 0\nvt nan 0\nvt 0 0\nvt 1 1\nf 1/1 2/2 3/3\n";
    let dir = scratch(&mesh_object("m.obj"), &[("m.obj", obj.as_bytes())]);
    render_refused(dir.path(), &["mesh m.obj", "texture coordinate"]);
}

#[test]
fn mtl_colours_out_of_range_or_short_are_refused() {
    let obj = format!("mtllib m.mtl\nusemtl paint\n{TRIANGLE}");
    for (kd, words) in [
        (
            "nan 0.5 0.5",
            &["material `paint`", "[NaN, 0.5, 0.5]", "[0, 1]"][..],
        ),
        ("0.5 inf 0.5", &["material `paint`", "inf", "[0, 1]"]),
        ("0.5 1e300 0.5", &["material `paint`", "inf", "[0, 1]"]),
        ("0.5 -1 0.5", &["material `paint`", "-1", "[0, 1]"]),
        // tobj unwrapped these and panicked.
        (
            "0.5 0.5",
            &["m.mtl", "line 2", "`Kd` needs three numbers", "0.5 0.5"],
        ),
        ("", &["m.mtl", "line 2", "`Kd` needs three numbers"]),
        (
            "0.5 x 0.5",
            &["m.mtl", "line 2", "`Kd` needs three numbers"],
        ),
    ] {
        let mtl = format!("newmtl paint\nKd {kd}\n");
        let dir = scratch(
            &mesh_object("m.obj"),
            &[("m.obj", obj.as_bytes()), ("m.mtl", mtl.as_bytes())],
        );
        render_refused(dir.path(), words);
    }
}

#[test]
fn objs_without_faces_or_with_bad_indices_are_refused() {
    for (obj, words) in [
        (
            "v 0 0 0\nv 1 0 0\nv 0 1 0\nl 1 2\np 3\n",
            &["mesh m.obj", "no faces with an area", "lines are not drawn"][..],
        ),
        ("", &["mesh m.obj", "no faces"]),
        (
            "v 0 0 0\nv 0 0 0\nv 0 0 0\nf 1 2 3\n",
            &["no faces with an area"],
        ),
        // tobj names no line: the pre-scan that explains its refusals does.
        (
            "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 9\n",
            &[
                "mesh m.obj",
                "line 4",
                "`9` is not the index of a vertex (the file has 3)",
            ],
        ),
        (
            "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 0 1 2\n",
            &["mesh m.obj", "line 4", "`0` is not the index of a vertex"],
        ),
        (
            "v 0 0 0\nv 1 0 0\nf -1 -2 -3\nv 0 1 0\n",
            &["mesh m.obj", "line 3", "`-3` is not the index of a vertex"],
        ),
        (
            "v 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nf 1/1 2/2 3/1\n",
            &[
                "mesh m.obj",
                "line 5",
                "`2` is not the index of a texture coordinate",
            ],
        ),
        (
            "v 0 0 0\nv 0 0\nf 1 2 3\n",
            &["mesh m.obj", "line 2", "`v` needs 3 numbers, got `0 0`"],
        ),
        (
            "v 0 0 0\nvt x 0\n",
            &["mesh m.obj", "line 2", "`vt` needs 2 numbers"],
        ),
    ] {
        let dir = scratch(&mesh_object("m.obj"), &[("m.obj", obj.as_bytes())]);
        render_refused(dir.path(), words);
    }
}

#[test]
fn materials_an_obj_names_must_exist_once() {
    let obj = format!("mtllib m.mtl\nusemtl paint\n{TRIANGLE}");
    // A usemtl of a name no library defines (tobj drew it grey without a word).
    let mtl = "newmtl lacquer\nKd 0.5 0.5 0.5\n";
    let dir = scratch(
        &mesh_object("m.obj"),
        &[("m.obj", obj.as_bytes()), ("m.mtl", mtl.as_bytes())],
    );
    render_refused(
        dir.path(),
        &["mesh m.obj", "line 2", "`usemtl paint`", "defined: lacquer"],
    );
    // A material defined twice says which, and where.
    let mtl = "newmtl paint\nKd 0.5 0.5 0.5\n\nnewmtl paint\nKd 0.1 0.1 0.1\n";
    let dir = scratch(
        &mesh_object("m.obj"),
        &[("m.obj", obj.as_bytes()), ("m.mtl", mtl.as_bytes())],
    );
    render_refused(
        dir.path(),
        &[
            "m.mtl",
            "line 4",
            "material `paint` is defined twice",
            "line 1",
        ],
    );
}

#[test]
fn missing_mtl_bin_and_texture_are_named_as_written_and_as_resolved() {
    let obj = format!("mtllib lib/none.mtl\n{TRIANGLE}");
    let dir = scratch(
        &mesh_object("meshes/m.obj"),
        &[("meshes/m.obj", obj.as_bytes())],
    );
    render_refused(
        dir.path(),
        &["`lib/none.mtl`", "meshes/lib/none.mtl", "No such file"],
    );

    let gltf = gltf_json(&Gltf {
        uri: Some("bin/none.bin"),
        ..Gltf::default()
    });
    let dir = scratch(
        &mesh_object("meshes/m.gltf"),
        &[("meshes/m.gltf", gltf.as_bytes())],
    );
    render_refused(
        dir.path(),
        &[
            "buffer 0",
            "`bin/none.bin`",
            "meshes/bin/none.bin",
            "No such file",
        ],
    );

    let dir = scratch(
        "\n[[material]]\nname = \"t\"\ntexture = \"tex/none.png\"\n",
        &[],
    );
    render_refused(
        dir.path(),
        &[
            "scene.toml:",
            "material[1].texture",
            "`tex/none.png`",
            "resolved",
            "tex/none.png",
        ],
    );
}

/// A one-triangle glTF whose parts a test replaces.
#[derive(Default)]
struct Gltf<'a> {
    positions: Option<[f32; 9]>,
    color: Option<&'a str>,
    nodes: Option<&'a str>,
    uri: Option<&'a str>,
    attributes: Option<&'a str>,
    count: Option<usize>,
}

fn gltf_json(g: &Gltf) -> String {
    use base64::Engine;
    let positions = g
        .positions
        .unwrap_or([0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0, 0.0]);
    let bytes: Vec<u8> = positions.iter().flat_map(|p| p.to_le_bytes()).collect();
    let uri = g.uri.map_or_else(
        || {
            format!(
                "data:application/octet-stream;base64,{}",
                base64::engine::general_purpose::STANDARD.encode(&bytes)
            )
        },
        str::to_string,
    );
    format!(
        r#"{{"asset": {{"version": "2.0"}},
  "buffers": [{{"byteLength": 36, "uri": "{uri}"}}],
  "bufferViews": [{{"buffer": 0, "byteLength": 36}}],
  "accessors": [{{"bufferView": 0, "componentType": 5126, "count": {}, "type": "VEC3",
                  "min": [0, 0, 0], "max": [1, 1, 0]}}],
  "materials": [{{"name": "paint", "pbrMetallicRoughness": {{"baseColorFactor": {}}}}}],
  "meshes": [{{"name": "tri", "primitives": [{{"attributes": {}, "material": 0}}]}}],
  "nodes": {},
  "scenes": [{{"nodes": [0]}}], "scene": 0}}"#,
        g.count.unwrap_or(3),
        g.color.unwrap_or("[0.5, 0.5, 0.5, 1]"),
        g.attributes.unwrap_or(r#"{"POSITION": 0}"#),
        g.nodes.unwrap_or(r#"[{"mesh": 0}]"#),
    )
}

fn gltf_refused(g: &Gltf, words: &[&str]) {
    let dir = scratch(
        &mesh_object("m.gltf"),
        &[("m.gltf", gltf_json(g).as_bytes())],
    );
    let mut all = vec!["mesh m.gltf"];
    all.extend_from_slice(words);
    render_refused(dir.path(), &all);
}

#[test]
fn gltf_values_that_are_not_finite_or_outside_the_world_are_refused() {
    // The valid file renders: the cases below differ from it in one part.
    let dir = scratch(
        &mesh_object("m.gltf"),
        &[("m.gltf", gltf_json(&Gltf::default()).as_bytes())],
    );
    let (code, err) = run_in(dir.path(), RENDER);
    assert_eq!(code, 0, "{err}");
    for p in [f32::NAN, f32::INFINITY, 1e30] {
        let mut positions = [0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0, 0.0];
        positions[4] = p;
        gltf_refused(
            &Gltf {
                positions: Some(positions),
                ..Gltf::default()
            },
            &["triangle 0 has a vertex", "within the world"],
        );
    }
    for color in [
        "[0.5, 1e300, 0.5, 1]",
        "[0.5, 1e39, 0.5, 1]",
        "[-1, 0.5, 0.5, 1]",
    ] {
        gltf_refused(
            &Gltf {
                color: Some(color),
                ..Gltf::default()
            },
            &["material `paint`", "components must be in [0, 1]"],
        );
    }
    // JSON has no NaN: the parser names the place.
    gltf_refused(
        &Gltf {
            color: Some("[NaN, 0.5, 0.5, 1]"),
            ..Gltf::default()
        },
        &["invalid glTF", "line"],
    );
    for node in [
        r#"[{"mesh": 0, "scale": [1e30, 1, 1]}]"#,
        r#"[{"mesh": 0, "translation": [0, 2e6, 0]}]"#,
        r#"[{"mesh": 0, "matrix": [1e38,0,0,0, 0,1e38,0,0, 0,0,1e38,0, 0,0,0,1]}]"#,
    ] {
        gltf_refused(
            &Gltf {
                nodes: Some(node),
                ..Gltf::default()
            },
            &["triangle 0 has a vertex", "within the world"],
        );
    }
}

#[test]
fn gltf_references_that_point_nowhere_are_named() {
    // The gltf crate's own validation indexed this accessor unchecked and panicked.
    gltf_refused(
        &Gltf {
            attributes: Some(r#"{"POSITION": 9}"#),
            ..Gltf::default()
        },
        &[
            "meshes[0].primitives[0].attributes",
            "accessor 9 does not exist",
        ],
    );
    gltf_refused(
        &Gltf {
            count: Some(1000),
            ..Gltf::default()
        },
        &["accessor 0 (POSITION)", "beyond the end of bufferView 0"],
    );
    gltf_refused(
        &Gltf {
            nodes: Some(r#"[{"mesh": 0, "children": [4]}]"#),
            ..Gltf::default()
        },
        &[
            "invalid glTF",
            "nodes[0].children[0]",
            "Index out of bounds",
        ],
    );
}

#[test]
fn gltf_node_cycles_are_refused_not_followed() {
    // Followed, a cycle loops forever (one grew to 2.9 GB): the watchdog is generous.
    for nodes in [
        r#"[{"mesh": 0, "children": [1]}, {"children": [0]}]"#,
        r#"[{"mesh": 0, "children": [0]}]"#,
        r#"[{"mesh": 0, "children": [1, 1]}, {"mesh": 0}]"#,
    ] {
        let g = Gltf {
            nodes: Some(nodes),
            ..Gltf::default()
        };
        let json = gltf_json(&g);
        let (send, receive) = std::sync::mpsc::channel();
        std::thread::spawn(move || {
            let no_files = |_: &Path| Err(std::io::ErrorKind::NotFound.into());
            let result = seethru::scene::mesh_io::parse_gltf(
                json.as_bytes(),
                Path::new("m.gltf"),
                &no_files,
            );
            let _ = send.send(result.map(|m| m.tris.len()).map_err(|e| format!("{e:#}")));
        });
        let result = receive
            .recv_timeout(std::time::Duration::from_secs(60))
            .expect("a glTF node cycle must not hang");
        let err = result.expect_err(nodes);
        assert!(err.contains("reached twice"), "{err}");
    }
}

#[test]
fn scenes_past_the_object_limit_are_refused_quickly() {
    // 200 000 objects: twice the limit. Finding the line of a key was quadratic (40 000
    // objects took 29 s); the watchdog allows a minute, the parse takes well under one.
    let mut text = common::MINIMAL.to_string();
    for i in 0..200_000 {
        text.push_str(&format!(
            "\n[[object]]\nkind = \"sphere\"\nmaterial = \"grey\"\nradius = 0.1\ntranslate = [{}.0, 0.1, -20.0]\n",
            i % 1000
        ));
    }
    let (send, receive) = std::sync::mpsc::channel();
    std::thread::spawn(move || {
        let _ = send.send(common::parse(&text).map(|s| s.objects.len()));
    });
    let result = receive
        .recv_timeout(std::time::Duration::from_secs(60))
        .expect("parsing 200 000 objects must not hang");
    let err = result.expect_err("past the object limit");
    let shown = err.to_string();
    assert!(
        shown.contains("100000") && shown.contains("object"),
        "{shown}"
    );
    assert!(!shown.contains('\n'));
}

#[test]
fn usage_and_toml_syntax_errors_are_one_line() {
    let dir = scratch("", &[]);
    for (args, words) in [
        (
            &["render"][..],
            &["required arguments", "--out", "<SCENE>"][..],
        ),
        (&["render", "scene.toml", "--bogus", "1"], &["'--bogus'"]),
        (
            &["render", "scene.toml", "--out", "o", "--view", "rear"],
            &["'rear'", "possible values"],
        ),
        (
            &["render", "scene.toml", "--out", "o", "--width"],
            &["--width", "none was supplied"],
        ),
        (
            &["measure", "o", "--band", "4000000000"],
            &["--band", "[1, 1000]"],
        ),
        (&["frobnicate"], &["'frobnicate'"]),
    ] {
        refused(dir.path(), args, 2, words);
    }
    assert_eq!(listing(dir.path()), ["scene.toml"]);
    for (toml, words) in [
        ("\n[obstacle\n", &["scene.toml:", "invalid TOML"][..]),
        ("\nx = \"never closed\n", &["scene.toml:", "invalid TOML"]),
        (
            "\n[[object]]\nkind = = 1\n",
            &["scene.toml:", "invalid TOML"],
        ),
    ] {
        let dir = scratch(toml, &[]);
        let text = std::fs::read_to_string(dir.path().join("scene.toml")).unwrap();
        let last = toml.trim_end().lines().last().unwrap();
        let line = text
            .lines()
            .collect::<Vec<_>>()
            .iter()
            .rposition(|l| *l == last)
            .unwrap()
            + 1;
        let err = render_refused(dir.path(), words);
        assert!(
            err.contains(&format!("scene.toml:{line}:")),
            "{err} (line {line})"
        );
    }
}

#[test]
fn names_given_twice_say_which() {
    let dir = scratch(
        "\n[[material]]\nname = \"grey\"\ncolor = [0.1, 0.1, 0.1]\n",
        &[],
    );
    render_refused(
        dir.path(),
        &[
            "material[1].name",
            "material `grey` is defined twice",
            "line",
        ],
    );
    let dir = scratch(
        "\n[[object]]\nname = \"ball\"\nkind = \"sphere\"\nmaterial = \"grey\"\nradius = 0.5\n",
        &[],
    );
    render_refused(
        dir.path(),
        &[
            "object[2].name",
            "object `ball` is named twice",
            "object[2]",
            "line",
        ],
    );
    // Default names (the kind) may repeat.
    let dir = scratch(
        "\n[[object]]\nkind = \"sphere\"\nmaterial = \"grey\"\nradius = 0.5\n\n[[object]]\nkind = \"sphere\"\nmaterial = \"grey\"\nradius = 0.5\ntranslate = [2.0, 0.0, -10.0]\n",
        &[],
    );
    assert_eq!(run_in(dir.path(), RENDER).0, 0);
}

#[test]
fn numbers_in_messages_are_short_and_ranges_run_low_to_high() {
    for (from, to) in [
        ("width = 0.3", "width = 123456789012345678901234567890.5"),
        (
            "width = 0.3",
            "width = 0.30000000000000004440892098500626161694526672363281250000000001",
        ),
        ("radius = 1.0", "radius = -1e300"),
        ("size = [100.0, 100.0]", "size = [100.0, 1e-300]"),
    ] {
        let dir = tempfile::tempdir().unwrap();
        std::fs::write(
            dir.path().join("scene.toml"),
            common::MINIMAL
                .replacen(from, to, 1)
                .replace("width = 0.3", "width = 200.0"),
        )
        .unwrap();
        let err = render_refused(dir.path(), &["scene.toml:"]);
        let longest_number = err
            .split(|c: char| !(c.is_ascii_digit() || c == '.'))
            .map(str::len)
            .max()
            .unwrap_or(0);
        assert!(longest_number <= 12, "a long number in `{err}`");
        // Every `[lo, hi]` in the message has lo ≤ hi.
        for range in err.split('[').skip(1) {
            let Some((inside, _)) = range.split_once(']') else {
                continue;
            };
            let bounds: Vec<f64> = inside
                .split(',')
                .filter_map(|b| b.trim().parse().ok())
                .collect();
            if let [lo, hi] = bounds[..] {
                assert!(lo <= hi, "range [{inside}] runs high to low in `{err}`");
            }
        }
    }
}

/// A finished run of the minimal scene in `dir/run` (truth, seethru and occluded EXRs).
fn finished_run(dir: &Path) -> PathBuf {
    std::fs::write(dir.join("scene.toml"), common::MINIMAL).unwrap();
    let (code, err) = run_in(dir, &["run", "scene.toml", "--out", "run"]);
    assert_eq!(code, 0, "{err}");
    dir.join("run")
}

#[test]
fn measure_names_the_exr_and_what_is_wrong_with_it() {
    use exr::prelude::*;
    let dir = tempfile::tempdir().unwrap();
    let run = finished_run(dir.path());
    let good = std::fs::read(run.join("seethru.exr")).unwrap();
    let measure = ["measure", "run"];
    let restore = || std::fs::write(run.join("seethru.exr"), &good).unwrap();

    // Another size than truth.exr (this panicked).
    let (code, err) = run_in(
        dir.path(),
        &[
            "render",
            "scene.toml",
            "--out",
            "small",
            "--view",
            "truth",
            "--width",
            "32",
        ],
    );
    assert_eq!(code, 0, "{err}");
    std::fs::copy(dir.path().join("small/truth.exr"), run.join("seethru.exr")).unwrap();
    refused(
        dir.path(),
        &measure,
        1,
        &["run/seethru.exr is 32×18", "run/truth.exr is 64×36"],
    );

    // Truncated, and not an EXR at all.
    for (bytes, words) in [
        (
            &good[..good.len() / 2],
            &["run/seethru.exr", "truncated"][..],
        ),
        (&good[..40], &["run/seethru.exr", "not a readable EXR"]),
        (
            b"\x89PNG\r\n\x1a\n",
            &["run/seethru.exr", "not a readable EXR"],
        ),
    ] {
        std::fs::write(run.join("seethru.exr"), bytes).unwrap();
        refused(dir.path(), &measure, 1, words);
    }

    // A channel missing, and one of the wrong type.
    let plain = |channels: SmallVec<[AnyChannel<FlatSamples>; 4]>| {
        let layer = Layer::new(
            (64, 36),
            LayerAttributes::default(),
            Encoding::UNCOMPRESSED,
            AnyChannels::sort(channels),
        );
        Image::from_layer(layer)
            .write()
            .to_file(run.join("seethru.exr"))
            .unwrap();
    };
    let f32s = |name: &str| AnyChannel::new(name, FlatSamples::F32(vec![0.5; 64 * 36]));
    plain(SmallVec::from_vec(vec![f32s("R"), f32s("G"), f32s("B")]));
    refused(
        dir.path(),
        &measure,
        1,
        &["run/seethru.exr", "no channel `Z`"],
    );
    let mut channels: Vec<AnyChannel<FlatSamples>> = ["R", "G", "B", "Z", "camera_z.Z"]
        .into_iter()
        .chain(["P.X", "P.Y", "P.Z", "N.X", "N.Y", "N.Z", "id.part"])
        .map(f32s)
        .collect();
    channels.push(AnyChannel::new(
        "id.object",
        FlatSamples::F32(vec![0.0; 64 * 36]),
    ));
    plain(SmallVec::from_vec(channels));
    refused(
        dir.path(),
        &measure,
        1,
        &[
            "run/seethru.exr",
            "channel `id.object` is f32, expected u32",
        ],
    );
    restore();

    // An invalid run.json names that file.
    let json = std::fs::read_to_string(run.join("run.json")).unwrap();
    for (text, words) in [
        (
            &json[..json.len() / 2],
            &["run/run.json", "invalid JSON"][..],
        ),
        ("{}", &["run/run.json", "no `scene`"]),
        (
            "{\"scene\": 3}",
            &["run/run.json", "`scene` must be the path"],
        ),
    ] {
        std::fs::write(run.join("run.json"), text).unwrap();
        refused(dir.path(), &measure, 1, words);
    }
    std::fs::write(run.join("run.json"), &json).unwrap();
    let (code, err) = run_in(dir.path(), &measure);
    assert_eq!(code, 0, "restored, the run measures again: {err}");
}

#[test]
fn a_failed_command_leaves_the_output_location_as_it_found_it() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("scene.toml"), common::MINIMAL).unwrap();
    // An output folder with a previous file and a folder where a view's file goes: the run
    // renders everything, cannot place display.png, and moves nothing.
    let out = dir.path().join("out");
    std::fs::create_dir_all(out.join("display.png")).unwrap();
    std::fs::write(out.join("truth.png"), "an older truth").unwrap();
    let before = listing(dir.path());
    refused(
        dir.path(),
        &["run", "scene.toml", "--out", "out"],
        1,
        &["out/display.png", "in the way"],
    );
    assert_eq!(listing(dir.path()), before);
    assert_eq!(
        std::fs::read_to_string(out.join("truth.png")).unwrap(),
        "an older truth"
    );

    // A command that fails after it started its output creates no folder, nested or not.
    refused(
        dir.path(),
        &[
            "reproduce",
            "--quick",
            "--scene",
            "none.toml",
            "--out",
            "new/nested/report",
        ],
        1,
        &["none.toml"],
    );
    assert_eq!(listing(dir.path()), before);
}

#[test]
#[cfg(target_os = "linux")]
fn staging_folders_of_killed_processes_are_removed_by_the_next_run() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("scene.toml"), common::MINIMAL).unwrap();
    // A process id above the kernel's maximum (2²²) never runs.
    let stale = dir.path().join(".out.tmp-4194305");
    std::fs::create_dir(&stale).unwrap();
    std::fs::write(stale.join("truth.png"), "half a run").unwrap();
    let (code, err) = run_in(dir.path(), RENDER);
    assert_eq!(code, 0, "{err}");
    assert_eq!(
        listing(&dir.path().join("out")).len(),
        3,
        "truth PNG, ids, EXR"
    );
    assert!(!stale.exists());
    assert_eq!(
        listing(dir.path())
            .iter()
            .filter(|n| n.contains(".tmp-"))
            .count(),
        0
    );
}

#[test]
#[cfg(unix)]
fn sigterm_removes_the_commands_temporaries() {
    // SIGTERM at several moments of a run: exit 130 with one line, and afterwards either a
    // whole output (the signal came too late) or none, and no temporary anywhere.
    let scratch = tempfile::tempdir().unwrap();
    let mut interrupted = 0;
    for (k, delay_ms) in [100u64, 300, 500, 800].into_iter().enumerate() {
        let out = scratch.path().join(format!("out{k}"));
        let child = Command::new(env!("CARGO_BIN_EXE_seethru"))
            .args([
                "run",
                "scenes/das.toml",
                "--quiet",
                "--out",
                out.to_str().unwrap(),
            ])
            .current_dir(env!("CARGO_MANIFEST_DIR"))
            .stderr(std::process::Stdio::piped())
            .spawn()
            .unwrap();
        std::thread::sleep(std::time::Duration::from_millis(delay_ms));
        let _ = Command::new("kill")
            .args(["-TERM", &child.id().to_string()])
            .status();
        let output = child.wait_with_output().unwrap();
        let err = String::from_utf8_lossy(&output.stderr);
        match output.status.code() {
            Some(130) => {
                interrupted += 1;
                assert_eq!(err.lines().count(), 1, "{err}");
                assert!(err.starts_with("error: interrupted;"), "{err}");
                assert!(!out.exists(), "an interrupted run left {}", out.display());
            }
            Some(0) => assert!(out.join("run.json").exists()),
            // Killed before the handler was installed (a loaded machine): nothing to check.
            None => {}
            Some(other) => panic!("exit {other}: {err}"),
        }
        let left: Vec<String> = listing(scratch.path())
            .into_iter()
            .filter(|n| n.contains(".tmp-"))
            .collect();
        assert!(left.is_empty(), "after {delay_ms} ms: {left:?}");
    }
    assert!(interrupted > 0, "no run was interrupted");
}

#[test]
fn every_sweep_parameter_refuses_values_outside_its_documented_range() {
    use seethru::measure::sweep_grid::{PARAMETERS, parse_param};
    // (name, documented low, low included, high): the ranges of PARAMETERS' descriptions.
    let documented = |name: &str| match name {
        "theta_f" => (0.0, false, 89.0),
        "d2" => (0.0, false, 1e6),
        "display_width" => (0.0, false, 100.0),
        "eye_x" | "eye_z" => (-1e6, true, 1e6),
        "head_bias_x_cm" => (-500.0, true, 500.0),
        "frontal_width" => (1.0, true, 16384.0),
        other => panic!("`{other}` is not in this test"),
    };
    for (name, description) in PARAMETERS {
        let (lo, lo_in, hi) = documented(name);
        for (written, x) in [
            ("nan", f64::NAN),
            ("-inf", f64::NEG_INFINITY),
            ("-1", -1.0),
            ("0", 0.0),
            ("1", 1.0),
            ("1e300", 1e300),
        ] {
            let admissible = (x > lo || (lo_in && x == lo)) && x <= hi;
            match parse_param(&format!("{name}={written}")) {
                Ok(_) => assert!(admissible, "{name}={written} accepted ({description})"),
                Err(e) => {
                    let shown = format!("{e:#}");
                    assert!(!admissible, "{name}={written} refused: {shown}");
                    assert!(
                        !shown.contains('\n') && (shown.contains(name) || shown.contains(written)),
                        "{shown}"
                    );
                }
            }
        }
        // `inf` is d2's name for no planar correction; for every other parameter it is refused.
        assert_eq!(parse_param(&format!("{name}=inf")).is_ok(), name == "d2");
    }
    // The value that panicked in the BVH build (a 1e300 m display), through the command.
    let dir = scratch("", &[]);
    refused(
        dir.path(),
        &[
            "sweep",
            "scene.toml",
            "--param",
            "display_width=1e300",
            "--out",
            "s.csv",
        ],
        1,
        &["display_width = 1e300", "(0, 100] m"],
    );
    refused(
        dir.path(),
        &[
            "sweep",
            "scene.toml",
            "--param",
            "eye_x=1,2,,3",
            "--out",
            "s.csv",
        ],
        1,
        &["empty value"],
    );
    refused(
        dir.path(),
        &[
            "sweep",
            "scene.toml",
            "--param",
            "eye_x=1",
            "--param",
            "eye_x=2",
            "--out",
            "s.csv",
        ],
        1,
        &["`eye_x` is given twice"],
    );
    assert_eq!(listing(dir.path()), ["scene.toml"]);
}

#[test]
fn textures_that_are_not_images_or_too_large_name_the_material_and_the_file() {
    let wide = {
        let mut png = Vec::new();
        image::RgbImage::new(16385, 1)
            .write_to(&mut std::io::Cursor::new(&mut png), image::ImageFormat::Png)
            .unwrap();
        png
    };
    for (bytes, words) in [
        (
            &b"\x89PNG\r\n\x1a\n truncated"[..],
            &["material `t`", "tex.png"][..],
        ),
        (b"not an image at all", &["material `t`", "tex.png"]),
        (&wide, &["material `t`", "tex.png", "limit"]),
    ] {
        let dir = scratch(
            "\n[[material]]\nname = \"t\"\ntexture = \"tex.png\"\n",
            &[("tex.png", bytes)],
        );
        render_refused(dir.path(), words);
    }
}

#[test]
fn scenes_past_the_triangle_limit_are_refused_before_building() {
    // 1 300 cylinders of 4 096 segments are about 21 million triangles: past the limit of
    // 20 million, refused while parsing (no mesh, no BVH built).
    let mut text = common::MINIMAL.to_string();
    for i in 0..1300 {
        text.push_str(&format!(
            "\n[[object]]\nkind = \"cylinder\"\nmaterial = \"grey\"\nsegments = 4096\ntranslate = [{i}.0, 0.0, -30.0]\n"
        ));
    }
    let (send, receive) = std::sync::mpsc::channel();
    std::thread::spawn(move || {
        let _ = send.send(common::parse(&text).map(|s| s.objects.len()));
    });
    let err = receive
        .recv_timeout(std::time::Duration::from_secs(60))
        .expect("must not hang")
        .expect_err("past the triangle limit");
    let shown = err.to_string();
    assert!(
        shown.contains("20000000") && shown.contains("triangles"),
        "{shown}"
    );
    assert!(
        shown.starts_with("test-scenes/scene.toml:") && !shown.contains('\n'),
        "{shown}"
    );
}

#[test]
fn numbers_pasted_with_hundreds_of_digits_are_not_repeated_in_full() {
    let long = format!("1{}.5", "0".repeat(800));
    let dir = scratch("", &[]);
    for (args, code) in [
        (vec!["measure", "run", "--band", long.as_str()], 2),
        (
            vec![
                "render",
                "scene.toml",
                "--out",
                "o",
                "--width",
                long.as_str(),
            ],
            2,
        ),
        (
            vec!["run", "scene.toml", "--out", "o", "--d2", long.as_str()],
            2,
        ),
    ] {
        let err = refused(dir.path(), &args, code, &["100000000000…(803 characters)"]);
        assert!(err.len() < 300, "{err}");
    }
    let param = format!("theta_f={long}");
    let err = refused(
        dir.path(),
        &["sweep", "scene.toml", "--param", &param, "--out", "s.csv"],
        1,
        &["theta_f", "(803 characters)"],
    );
    assert!(err.len() < 300, "{err}");
    assert_eq!(listing(dir.path()), ["scene.toml"]);
}
