//! Malformed scene files give one error naming the file, the line and the key.

mod common;

use common::{MINIMAL, parse, parse_in, repo_path};

/// Replaces the first occurrence of `from` in the minimal scene (which must exist).
fn edited(from: &str, to: &str) -> String {
    assert!(
        MINIMAL.contains(from),
        "test bug: `{from}` not in the minimal scene"
    );
    MINIMAL.replacen(from, to, 1)
}

fn line_of(text: &str, needle: &str) -> usize {
    text.lines()
        .position(|l| l.contains(needle))
        .expect("needle in text")
        + 1
}

#[test]
fn the_minimal_scene_is_valid() {
    let scene = parse(MINIMAL).unwrap();
    assert_eq!(scene.objects.len(), 2);
    assert_eq!((scene.driver.width, scene.driver.height), (64, 36));
}

#[test]
fn errors_name_file_line_and_key() {
    let cases: &[(&str, &str, &str, &str)] = &[
        // (original, replacement, expected key, expected words in the message)
        (
            "radius = 1.0",
            "radius = -1.0",
            "object[1].radius",
            "must be in [1e-6,",
        ),
        (
            "radius = 1.0",
            "radius = \"big\"",
            "object[1].radius",
            "expected a number, found string",
        ),
        (
            "radius = 1.0",
            "radius = nan",
            "object[1].radius",
            "must be in [1e-6, 100000], got NaN",
        ),
        (
            "radius = 1.0",
            "radius = 1.0\ncolour = 3",
            "object[1].colour",
            "unknown key",
        ),
        (
            "kind = \"sphere\"",
            "kind = \"torus\"",
            "object[1].kind",
            "`torus` is not one of",
        ),
        (
            "material = \"grey\"\nradius",
            "material = \"gray\"\nradius",
            "object[1].material",
            "no material named `gray`",
        ),
        (
            "color = [0.5, 0.5, 0.5]",
            "color = [0.5, 1.5, 0.5]",
            "material[0].color",
            "must be in [0, 1]",
        ),
        (
            "color = [0.5, 0.5, 0.5]",
            "color = [0.5, 0.5]",
            "material[0].color",
            "expected 3 numbers",
        ),
        (
            "width = 0.3",
            "width = 0.0",
            "obstacle.width",
            "must be in [1e-6,",
        ),
        (
            "resolution = [64, 36]",
            "resolution = [64, 0]",
            "camera.driver.resolution",
            "integers in [1, 16384]",
        ),
        (
            "resolution = [64, 36]",
            "resolution = [1000000, 36]",
            "camera.driver.resolution",
            "integers in [1, 16384]",
        ),
        (
            "resolution = [64, 36]",
            "resolution = [16384, 16384]",
            "camera.driver.resolution",
            "at most 16384×8192 pixels in all",
        ),
        (
            "position = [0.0, 1.2, 0.0]",
            "position = [0.0, 1.2, -2.0]",
            "camera.driver.position",
            "d1 > 0",
        ),
        (
            "look_at = [0.0, 1.2, -10.0]",
            "look_at = [0.0, 1.2, 0.0]",
            "camera.driver.look_at",
            "viewing direction",
        ),
        (
            "[camera.frontal]\n",
            "[camera.frontal]\nhalf_angle_deg = 95\n",
            "camera.frontal.half_angle_deg",
            "must be in [0.01, 89]",
        ),
        (
            "[camera.frontal]\n",
            "[camera.frontal]\noffset = [0.0, 0.0, 0.5]\n",
            "camera.frontal.offset",
            "scene side",
        ),
        (
            "[camera.back]\n",
            "[camera.back]\nfov = 3\n",
            "camera.back.fov",
            "unknown key",
        ),
        (
            "size = [100.0, 100.0]",
            "size = [100.0, -1.0]",
            "object[0].size",
            "every element must be in [1e-6, 100000], got -1",
        ),
        (
            "[[object]]\nname = \"ground\"",
            "[[object]]\nname = \"ground\"\nhidden_from = [\"rear\"]",
            "object[0].hidden_from",
            "`rear` is not one of",
        ),
    ];
    for &(from, to, key, words) in cases {
        let text = edited(from, to);
        let err = parse(&text).expect_err(&format!("`{to}` must be rejected"));
        let shown = err.to_string();
        assert_eq!(err.key, key, "{shown}");
        assert!(shown.contains(words), "`{shown}` lacks `{words}`");
        assert!(shown.starts_with("test-scenes/scene.toml:"), "{shown}");
        assert!(!shown.contains('\n'), "one line: {shown}");
        // The line is the edited one (or the table it belongs to, for a missing value).
        let new_line = to.lines().find(|l| !from.lines().any(|f| f == *l)).unwrap();
        let edited_line = line_of(&text, new_line);
        assert_eq!(err.line, Some(edited_line), "{shown}");
    }
}

#[test]
fn missing_required_keys_and_tables_are_named() {
    let err = parse(&edited("center = [0.0, 1.2, -0.8]\n", "")).unwrap_err();
    assert_eq!(err.key, "obstacle.center");
    assert!(err.to_string().contains("required key is missing"));

    let text = MINIMAL.replace("[camera.back]\nresolution = [32, 24]\n", "");
    let err = parse(&text).unwrap_err();
    assert_eq!(err.key, "camera.back");
    assert!(err.to_string().contains("[camera.back]"));

    let err = parse(&edited("kind = \"plane\"\n", "")).unwrap_err();
    assert_eq!(err.key, "object[0].kind");
}

#[test]
fn invalid_toml_gives_the_line() {
    let text = edited("width = 0.3", "width = = 0.3");
    let err = parse(&text).unwrap_err();
    assert_eq!(err.line, Some(line_of(&text, "width = = 0.3")));
    assert!(err.to_string().contains("invalid TOML"), "{err}");
}

#[test]
fn missing_assets_name_their_path() {
    let text = edited(
        "radius = 1.0\n",
        "radius = 1.0\n\n[[object]]\nkind = \"mesh\"\npath = \"nowhere/car.obj\"\n",
    );
    let err = parse_in(&repo_path("scenes"), "x.toml", &text).unwrap_err();
    let shown = err.to_string();
    assert_eq!(err.key, "object[2].path");
    assert!(
        shown.contains("cannot read `nowhere/car.obj`")
            && shown.contains("no such file")
            && shown.contains("nowhere/car.obj"),
        "{shown}"
    );

    let text = edited(
        "color = [0.5, 0.5, 0.5]",
        "color = [0.5, 0.5, 0.5]\ntexture = \"missing.png\"",
    );
    let err = parse_in(&repo_path("scenes"), "x.toml", &text).unwrap_err();
    assert!(err.to_string().contains("missing.png"), "{err}");
}

#[test]
fn the_shipped_scenes_load() {
    for name in ["scenes/das.toml", "scenes/reference.toml"] {
        seethru::scene::Scene::load(&repo_path(name)).unwrap_or_else(|e| panic!("{e}"));
    }
}

#[test]
fn glb_headers_that_lie_about_their_length_are_errors_not_panics() {
    use seethru::scene::mesh_io::parse_gltf;
    let no_files = |p: &std::path::Path| -> std::io::Result<Vec<u8>> {
        Err(std::io::Error::new(
            std::io::ErrorKind::NotFound,
            p.display().to_string(),
        ))
    };
    // The first (found by fuzzing the glTF reader): version 8, length 0 — the gltf crate
    // computed `length − 12` before checking it. Then a version-2 header shorter than its
    // own chunk header, one longer than the file, and a file cut inside its header.
    let mut too_long = b"glTF\x02\0\0\0".to_vec();
    too_long.extend(4096u32.to_le_bytes());
    for bytes in [
        b"glTF\x08\0\0\0\0\0\0\0".to_vec(),
        b"glTF\x02\0\0\0\x04\0\0\0".to_vec(),
        too_long,
        b"glTF\x02\0".to_vec(),
    ] {
        let err = parse_gltf(&bytes, std::path::Path::new("x.glb"), &no_files)
            .unwrap_err()
            .to_string();
        assert!(err.starts_with("invalid GLB"), "{err}");
    }
}
