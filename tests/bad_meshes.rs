//! Bad mesh files and textures, one test per class: NaN, infinite and huge numbers, bad
//! indices and references, missing files named as written and as resolved. Each is refused with
//! one `error:` line naming the file and what is wrong, and leaves nothing behind.

mod common;

use std::path::Path;

use common::refusal::{RENDER, render_refused, run_in, scratch};

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
            &[
                "m.mtl",
                "line 2",
                "material `paint`",
                "[NaN, 0.5, 0.5]",
                "[0, 1]",
            ][..],
        ),
        (
            "0.5 inf 0.5",
            &["m.mtl", "line 2", "material `paint`", "inf", "[0, 1]"],
        ),
        (
            "0.5 1e300 0.5",
            &["m.mtl", "line 2", "material `paint`", "inf", "[0, 1]"],
        ),
        (
            "0.5 -1 0.5",
            &["m.mtl", "line 2", "material `paint`", "-1", "[0, 1]"],
        ),
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
        // tobj reads an index 0 of a texture coordinate or normal as "none" without a word;
        // the scan runs before tobj, so it is refused.
        (
            "v 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nf 1/1 2/0 3/1\n",
            &[
                "mesh m.obj",
                "line 5",
                "`0` is not the index of a texture coordinate",
            ],
        ),
        (
            "v 0 0 0\nv 1 0 0\nv 0 1 0\nvn 0 0 1\nf 1//1 2//1 3//0\n",
            &["mesh m.obj", "line 5", "`0` is not the index of a normal"],
        ),
        // Far below the first element: tobj's index arithmetic overflowed (found by fuzzing).
        (
            "v 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nf 1/1 2/1 3/-9223372036854775807\n",
            &[
                "mesh m.obj",
                "line 5",
                "is not the index of a texture coordinate (the file has 1)",
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
        &["`lib/none.mtl`", "meshes/lib/none.mtl", "no such file"],
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
            "no such file",
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
            "index 4 is out of bounds",
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
        (&wide, &["material `t`", "tex.png", "16384 px a side"]),
    ] {
        let dir = scratch(
            "\n[[material]]\nname = \"t\"\ntexture = \"tex.png\"\n",
            &[("tex.png", bytes)],
        );
        render_refused(dir.path(), words);
    }
    // Textures and meshes are read side by side; a broken texture is still the error named
    // when a mesh is broken too, as if read in turn.
    let scene = format!(
        "\n[[material]]\nname = \"t\"\ntexture = \"tex.png\"\n{}",
        mesh_object("m.obj")
    );
    let obj = TRIANGLE.replacen("v 1 0 0", "v 1 nan 0", 1);
    let dir = scratch(
        &scene,
        &[
            ("tex.png", b"not an image at all"),
            ("m.obj", obj.as_bytes()),
        ],
    );
    render_refused(dir.path(), &["material `t`", "tex.png"]);
}

#[test]
fn a_byte_order_mark_on_an_obj_or_mtl_is_skipped_not_taken_for_the_first_line() {
    use seethru::scene::mesh_io::parse_obj;
    // tobj read `\u{FEFF}v` as an unknown keyword: the first vertex was lost and the face
    // drawn from the next three, without a word.
    let obj = "\u{FEFF}v 9 9 9\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n";
    let none = |_: &Path| -> std::io::Result<Vec<u8>> { unreachable!() };
    let mesh = parse_obj(obj.as_bytes(), Path::new("m.obj"), &none).unwrap();
    assert_eq!(mesh.tris[0].p[0].to_array(), [9.0, 9.0, 9.0]);
    // A first line `mtllib` was lost too ("usemtl a names no material"); an MTL's first
    // `newmtl` likewise.
    let obj = "\u{FEFF}mtllib m.mtl\nusemtl a\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n";
    let mtl = |_: &Path| Ok(b"\xEF\xBB\xBFnewmtl a\nKd 0.25 0.5 0.75\n".to_vec());
    let mesh = parse_obj(obj.as_bytes(), Path::new("m.obj"), &mtl).unwrap();
    assert_eq!(mesh.materials.len(), 1);
    assert_eq!(mesh.materials[0].name, "a");
    assert_eq!(mesh.materials[0].linear_color, [0.25, 0.5, 0.75]);
}

#[test]
fn a_material_library_named_many_times_is_read_once() {
    use seethru::scene::mesh_io::parse_obj;
    // Found by fuzzing: tobj calls the loader for every `mtllib` line and appends the
    // library's materials again each time (N × the MTL's size: quadratic).
    let mtl: String = (0..2000)
        .map(|i| format!("newmtl m{i}\nKd 0.5 0.5 0.5\n"))
        .collect();
    let obj = format!("{}usemtl m7\n{TRIANGLE}", "mtllib m.mtl\n".repeat(3000));
    let reads = std::cell::Cell::new(0);
    let read = |_: &Path| {
        reads.set(reads.get() + 1);
        Ok(mtl.clone().into_bytes())
    };
    let mesh = parse_obj(obj.as_bytes(), Path::new("m.obj"), &read).unwrap();
    assert_eq!(reads.get(), 1);
    assert_eq!(mesh.materials.len(), 2000);
    assert_eq!(mesh.tris[0].file_material, Some(7));
}

#[test]
fn a_material_two_libraries_define_is_refused_naming_both() {
    // tobj let the later definition win without a word.
    let obj = format!("mtllib a.mtl\nmtllib b.mtl\nusemtl paint\n{TRIANGLE}");
    let dir = scratch(
        &mesh_object("m.obj"),
        &[
            ("m.obj", obj.as_bytes()),
            ("a.mtl", b"newmtl paint\nKd 0.5 0.5 0.5\n"),
            ("b.mtl", b"newmtl paint\nKd 0.1 0.1 0.1\n"),
        ],
    );
    render_refused(
        dir.path(),
        &["mesh m.obj", "`b.mtl`", "material `paint`", "`a.mtl`"],
    );
}

#[test]
fn obj_lines_tobj_reads_wrongly_or_without_a_line_are_refused_naming_it() {
    for (obj, words) in [
        (
            format!("{TRIANGLE}vn nan 0 1\n"),
            &["line 5", "`vn` nan 0 1", "NaN is not finite"][..],
        ),
        (
            format!("{TRIANGLE}vt 0 inf\n"),
            &["line 5", "inf is not finite"],
        ),
        // tobj drew the good face and dropped these without a word.
        (
            format!("{TRIANGLE}f 1\n"),
            &["line 5", "`f` has 1 index", "3 corners"],
        ),
        (
            format!("{TRIANGLE}f 1 2\n"),
            &["line 5", "`f` has 2 indices"],
        ),
        // tobj: "invalid polygon".
        (format!("{TRIANGLE}f\n"), &["line 5", "`f` has 0 indices"]),
        // tobj: "face vertex color index out of bounds".
        (
            "v 0 0 0 nan nan nan\nv 1 0 0\nv 0 1 0\nf 1 2 3\n".into(),
            &["line 1", "NaN is not finite", "colour r g b"],
        ),
        (
            "v 0 0 0 1 1 1\nv 1 0 0\nv 0 1 0\nf 1 2 3\n".into(),
            &[
                "line 2",
                "vertex colours",
                "line 1 has one",
                "every vertex or none",
            ],
        ),
        ("v 0 0 0 0\n".into(), &["line 1", "w = 0"]),
        ("v 0 0 0 1 1\n".into(), &["line 1", "`v` has 5 numbers"]),
        (
            format!("{TRIANGLE}usemtl\n"),
            &["line 5", "`usemtl` needs a material name"],
        ),
        (
            "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 18446744073709551616\n".into(),
            &["line 4", "`184467440737…(20 characters)` is not the index"],
        ),
    ] {
        let dir = scratch(&mesh_object("m.obj"), &[("m.obj", obj.as_bytes())]);
        let err = render_refused(dir.path(), words);
        assert!(err.contains("mesh m.obj"), "{err}");
    }
    for (obj, words) in [
        (
            [TRIANGLE.as_bytes(), b"\0\0\0\0"].concat(),
            &["line 5", "a NUL byte: not a text OBJ"][..],
        ),
        (
            // tobj: "read error".
            [TRIANGLE.as_bytes(), b"# caf\xe9\n"].concat(),
            &["line 5", "byte 6 of the line is not UTF-8"],
        ),
        // tobj: "color parse error (too many or too few components)".
        (
            TRIANGLE.replace('\n', "\r").into_bytes(),
            &["line 1", "CR line ends"],
        ),
    ] {
        let dir = scratch(&mesh_object("m.obj"), &[("m.obj", &obj)]);
        render_refused(dir.path(), words);
    }
}

#[test]
fn mtl_lines_tobj_reads_wrongly_or_without_a_line_are_refused_naming_the_mtl_and_line() {
    let obj = format!("mtllib m.mtl\nusemtl paint\n{TRIANGLE}");
    for (mtl, words) in [
        // tobj read the first three numbers and ignored the rest.
        (
            "newmtl paint\nKd 0.5 0.5 0.5 0.5\n",
            &["line 2", "`Kd` needs three numbers", "0.5 0.5 0.5 0.5"][..],
        ),
        (
            "newmtl paint\nKd -0.1 0.5 0.5\n",
            &["line 2", "material `paint`", "-0.1", "[0, 1]"],
        ),
        (
            "newmtl paint\nKd 1.5 0.5 0.5\n",
            &["line 2", "1.5", "[0, 1]"],
        ),
        (
            "newmtl paint\nKd nan 0.5 0.5\n",
            &["line 2", "NaN", "[0, 1]"],
        ),
        // tobj: "material parse error", "invalid object name".
        ("newmtl paint\nNs\n", &["line 2", "`Ns` needs one number"]),
        (
            "newmtl paint\nmap_Kd\n",
            &["line 2", "`map_Kd` needs a texture"],
        ),
        ("newmtl\n", &["line 1", "`newmtl` needs a material name"]),
        (
            "newmtl paint\n\0\0",
            &["line 2", "a NUL byte: not a text MTL"],
        ),
        // A texture that is not there, and one with options: named with the material.
        (
            "newmtl paint\nKd 1 1 1\nmap_Kd tex/paint.png\n",
            &[
                "material `paint`",
                "`map_Kd tex/paint.png`",
                "cannot read it",
                "library's folder",
            ],
        ),
        (
            "newmtl paint\nKd 1 1 1\nmap_Kd -s 2 2 1 paint.png\n",
            &["material `paint`", "options", "file name alone"],
        ),
    ] {
        let dir = scratch(
            &mesh_object("m.obj"),
            &[("m.obj", obj.as_bytes()), ("m.mtl", mtl.as_bytes())],
        );
        render_refused(
            dir.path(),
            &[&["mesh m.obj", "`m.mtl`"][..], words].concat(),
        );
    }
}

#[test]
fn gltf_files_tobj_or_the_gltf_crate_misread_are_refused_naming_what_is_wrong() {
    // Each differs from the valid file in one part.
    let base = gltf_json(&Gltf::default());
    for (json, words) in [
        // The last index was dropped without a word.
        (
            base.replace(r#""count": 3"#, r#""count": 2"#),
            &["POSITION (accessor 0, no indices) has 2 elements, not a multiple of 3"][..],
        ),
        (
            base.replace("[0.5, 0.5, 0.5, 1]", "[0.5, 0.5, 0.5, 7]"),
            &["material `paint`", "alpha 7", "[0, 1]"],
        ),
        (
            base.replace(
                r#"[{"mesh": 0}]"#,
                r#"[{"mesh": 0, "rotation": [0, 0, 0, 0]}]"#,
            ),
            &["node 0", "[0, 0, 0, 0]", "length 0", "unit quaternion"],
        ),
        (
            base.replace(r#"[{"mesh": 0}]"#, r#"[{"mesh": 0, "children": [4]}]"#),
            &[
                "nodes[0].children[0]",
                "index 4 is out of bounds",
                "1 nodes",
            ],
        ),
        // A texture whose image is missing: named, with where it was looked for.
        (
            base.replace(
                r#""pbrMetallicRoughness": {"baseColorFactor": [0.5, 0.5, 0.5, 1]}"#,
                r#""pbrMetallicRoughness": {"baseColorTexture": {"index": 0}}"#,
            )
            .replace(
                r#""meshes""#,
                r#""textures": [{"source": 0}], "images": [{"uri": "paint.png"}], "meshes""#,
            ),
            &["image 0", "cannot read `paint.png`", "glTF file's folder"],
        ),
        // Another texture coordinate set than TEXCOORD_0.
        (
            base.replace(
                r#""pbrMetallicRoughness": {"baseColorFactor": [0.5, 0.5, 0.5, 1]}"#,
                r#""pbrMetallicRoughness": {"baseColorTexture": {"index": 0, "texCoord": 1}}"#,
            )
            .replace(
                r#""meshes""#,
                r#""textures": [{"source": 0}], "images": [{"uri": "paint.png"}], "meshes""#,
            ),
            &["material `paint`", "TEXCOORD_1", "only TEXCOORD_0"],
        ),
        (String::new(), &["not a GLB/glTF", "empty"]),
        ("PK\u{3}\u{4}zip".into(), &["not a GLB/glTF", "`PK"]),
    ] {
        let dir = scratch(&mesh_object("m.gltf"), &[("m.gltf", json.as_bytes())]);
        render_refused(dir.path(), &[&["mesh m.gltf"][..], words].concat());
    }
    // GLBs: a wrong magic, and chunks that do not fit.
    let glb = |json_length: u32, json: &[u8]| {
        let total = 20 + json.len() as u32;
        [
            &b"glTF"[..],
            &2u32.to_le_bytes(),
            &total.to_le_bytes(),
            &json_length.to_le_bytes(),
            b"JSON",
            json,
        ]
        .concat()
    };
    let json = b"{\"asset\":{\"version\":\"2.0\"}}".to_vec();
    let padded = [&json[..], &[b' '; 4][..4 - json.len() % 4]].concat();
    for (bytes, words) in [
        (b"gltf\x02\0\0\0".to_vec(), &["not a GLB/glTF", "`gltf"][..]),
        (
            glb(1000, &padded),
            &["JSON chunk declares 1000 bytes", "follow its header"],
        ),
        (
            glb(0, &padded),
            &["JSON chunk is 0 bytes long", "multiple of 4"],
        ),
        (glb(7, &padded), &["JSON chunk is 7 bytes long"]),
    ] {
        let dir = scratch(&mesh_object("m.glb"), &[("m.glb", &bytes)]);
        render_refused(dir.path(), &[&["mesh m.glb"][..], words].concat());
    }
    // The crate's "Image size exceeds limit" named no size, and its PNG errors came twice.
    let wide = {
        let mut png = Vec::new();
        image::RgbImage::new(16385, 1)
            .write_to(&mut std::io::Cursor::new(&mut png), image::ImageFormat::Png)
            .unwrap();
        png
    };
    for (bytes, words) in [
        (&wide[..], &["16385×1 px", "16384 px a side"][..]),
        (b"\x89PNG\r\n\x1a\x00 not one", &["material `t`"]),
    ] {
        let dir = scratch(
            "\n[[material]]\nname = \"t\"\ntexture = \"tex.png\"\n",
            &[("tex.png", bytes)],
        );
        let err = render_refused(dir.path(), words);
        let tail = err.rsplit(": ").next().unwrap();
        assert!(!err[..err.len() - tail.len()].contains(tail), "{err}");
    }
}
