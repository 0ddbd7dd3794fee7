//! Mesh textures: a glTF base-colour texture (a data URI, a file beside the glTF, or a GLB
//! bufferView) and an OBJ `map_Kd`, bound to their material and sampled at the triangles'
//! uv, checked by ray casts against the texels the PNG was made of; a texture that cannot be
//! read is one `error:` line naming it.

mod common;

use base64::Engine;
use glam::{Vec2, Vec3};
use seethru::render::integrator::RenderContext;
use seethru::scene::Scene;
use seethru::scene::world::view_bit;
use seethru::util::color::srgb_to_linear;

/// A 2×2 PNG: red, green (top row), blue, grey (bottom row).
fn png() -> Vec<u8> {
    let codes = [[255, 0, 0], [0, 255, 0], [0, 0, 255], [128, 128, 128]];
    let image = image::RgbImage::from_fn(2, 2, |x, y| image::Rgb(codes[(y * 2 + x) as usize]));
    let mut bytes = Vec::new();
    image
        .write_to(
            &mut std::io::Cursor::new(&mut bytes),
            image::ImageFormat::Png,
        )
        .unwrap();
    bytes
}

/// A square 2 m a side at z = −5 facing +z, x ∈ [−1, 1], y ∈ [0, 2]: four corners (position,
/// then uv, little-endian f32) and two triangles, as one buffer.
fn square() -> Vec<u8> {
    let corners: [([f32; 3], [f32; 2]); 4] = [
        ([-1.0, 2.0, -5.0], [0.0, 0.0]),
        ([1.0, 2.0, -5.0], [1.0, 0.0]),
        ([-1.0, 0.0, -5.0], [0.0, 1.0]),
        ([1.0, 0.0, -5.0], [1.0, 1.0]),
    ];
    let mut bytes = Vec::new();
    for (p, _) in corners {
        bytes.extend(p.iter().flat_map(|v| v.to_le_bytes()));
    }
    for (_, uv) in corners {
        bytes.extend(uv.iter().flat_map(|v| v.to_le_bytes()));
    }
    for i in [0u16, 2, 1, 1, 2, 3] {
        bytes.extend(i.to_le_bytes());
    }
    bytes
}

/// The glTF JSON of the square with a base-colour texture whose image is `image` (a JSON
/// object), the geometry in buffer 0 given by `buffer` (a JSON object), and a factor that
/// halves green.
fn gltf_json(buffer: &str, image: &str, extra_views: &str) -> String {
    format!(
        r#"{{"asset":{{"version":"2.0"}},"scene":0,"scenes":[{{"nodes":[0]}}],
        "nodes":[{{"mesh":0}}],
        "meshes":[{{"primitives":[{{"attributes":{{"POSITION":0,"TEXCOORD_0":1}},"indices":2,"material":0}}]}}],
        "materials":[{{"pbrMetallicRoughness":{{"baseColorFactor":[1.0,0.5,1.0,1.0],"baseColorTexture":{{"index":0}}}}}}],
        "textures":[{{"source":0}}],
        "images":[{image}],
        "buffers":[{buffer}],
        "bufferViews":[{{"buffer":0,"byteOffset":0,"byteLength":48}},{{"buffer":0,"byteOffset":48,"byteLength":32}},{{"buffer":0,"byteOffset":80,"byteLength":12}}{extra_views}],
        "accessors":[{{"bufferView":0,"componentType":5126,"count":4,"type":"VEC3","min":[-1,0,-5],"max":[1,2,-5]}},
                     {{"bufferView":1,"componentType":5126,"count":4,"type":"VEC2"}},
                     {{"bufferView":2,"componentType":5123,"count":6,"type":"SCALAR"}}]}}"#
    )
}

fn data_uri(mime: &str, bytes: &[u8]) -> String {
    format!(
        "data:{mime};base64,{}",
        base64::engine::general_purpose::STANDARD.encode(bytes)
    )
}

/// das's cameras over nothing but the mesh at `mesh` (relative to the scene in `dir`), and,
/// out of the way, a sign textured by a scene material: the world's first texture, so that
/// the mesh's must be found past it.
fn scene_with_mesh(dir: &std::path::Path, mesh: &str) -> std::path::PathBuf {
    let path = dir.join("scene.toml");
    let street = common::repo_path("assets/street.png");
    std::fs::write(
        &path,
        format!(
            "{}\n[[material]]\nname = \"street\"\ntexture = \"{}\"\n\
             [[object]]\nname = \"sign\"\nkind = \"quad\"\nmaterial = \"street\"\n\
             translate = [30.0, 2.0, -40.0]\n\
             [[object]]\nname = \"square\"\nkind = \"mesh\"\npath = \"{mesh}\"\n",
            common::das_without_objects(),
            street.display()
        ),
    )
    .unwrap();
    path
}

/// The base colour seen at the centre of each quarter of the square: the texel there times
/// the factor, linear.
fn quarter_colours(scene: &std::path::Path) -> Vec<(Vec2, Vec3)> {
    let ctx = RenderContext::new(Scene::load(scene).unwrap_or_else(|e| panic!("{e}"))).unwrap();
    [(-0.5, 1.5), (0.5, 1.5), (-0.5, 0.5), (0.5, 0.5)]
        .into_iter()
        .map(|(x, y)| {
            let hit = ctx
                .trace(Vec3::new(x, y, 0.0), Vec3::NEG_Z, view_bit::TRUTH)
                .expect("the square");
            let material = &ctx.world.materials[hit.material as usize];
            let texture = &ctx.world.textures[material.texture.expect("a texture")];
            (hit.uv, material.albedo * texture.sample(hit.uv))
        })
        .collect()
}

fn expected() -> Vec<(Vec2, Vec3)> {
    let linear = |c: [u8; 3]| Vec3::from(c.map(|v| srgb_to_linear(f32::from(v) / 255.0)));
    let half_green = Vec3::new(1.0, 0.5, 1.0);
    [
        (Vec2::new(0.25, 0.25), [255, 0, 0]),
        (Vec2::new(0.75, 0.25), [0, 255, 0]),
        (Vec2::new(0.25, 0.75), [0, 0, 255]),
        (Vec2::new(0.75, 0.75), [128, 128, 128]),
    ]
    .into_iter()
    .map(|(uv, c)| (uv, linear(c) * half_green))
    .collect()
}

fn assert_colours(got: Vec<(Vec2, Vec3)>) {
    for ((uv, colour), (want_uv, want)) in got.into_iter().zip(expected()) {
        assert!(uv.abs_diff_eq(want_uv, 1e-5), "uv {uv} against {want_uv}");
        assert!(
            colour.abs_diff_eq(want, 1e-5),
            "colour {colour} against {want}"
        );
    }
}

#[test]
fn a_data_uri_texture_is_sampled_at_the_primitives_uvs_times_the_factor() {
    let dir = tempfile::tempdir().unwrap();
    let buffer = format!(
        r#"{{"byteLength":92,"uri":"{}"}}"#,
        data_uri("application/octet-stream", &square())
    );
    let image = format!(r#"{{"uri":"{}"}}"#, data_uri("image/png", &png()));
    std::fs::write(
        dir.path().join("square.gltf"),
        gltf_json(&buffer, &image, ""),
    )
    .unwrap();
    assert_colours(quarter_colours(&scene_with_mesh(dir.path(), "square.gltf")));
}

#[test]
fn a_texture_file_beside_the_gltf_and_one_in_a_glb_bufferview_read_alike() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("square.bin"), square()).unwrap();
    std::fs::write(dir.path().join("my texture.png"), png()).unwrap();
    let json = gltf_json(
        r#"{"byteLength":92,"uri":"square.bin"}"#,
        r#"{"uri":"my%20texture.png"}"#,
        "",
    );
    std::fs::write(dir.path().join("square.gltf"), json).unwrap();
    assert_colours(quarter_colours(&scene_with_mesh(dir.path(), "square.gltf")));

    // A GLB: the geometry, then the PNG, in its binary chunk; the image names a bufferView.
    let mut bin = square();
    let png = png();
    let view = format!(
        r#",{{"buffer":0,"byteOffset":92,"byteLength":{}}}"#,
        png.len()
    );
    bin.extend(&png);
    while !bin.len().is_multiple_of(4) {
        bin.push(0);
    }
    let mut json = gltf_json(
        &format!(r#"{{"byteLength":{}}}"#, bin.len()),
        r#"{"bufferView":3,"mimeType":"image/png"}"#,
        &view,
    )
    .into_bytes();
    while !json.len().is_multiple_of(4) {
        json.push(b' ');
    }
    let mut glb = b"glTF".to_vec();
    glb.extend(2u32.to_le_bytes());
    glb.extend(((12 + 8 + json.len() + 8 + bin.len()) as u32).to_le_bytes());
    glb.extend((json.len() as u32).to_le_bytes());
    glb.extend(b"JSON");
    glb.extend(&json);
    glb.extend((bin.len() as u32).to_le_bytes());
    glb.extend(b"BIN\0");
    glb.extend(&bin);
    std::fs::write(dir.path().join("square.glb"), glb).unwrap();
    assert_colours(quarter_colours(&scene_with_mesh(dir.path(), "square.glb")));
}

#[test]
fn an_obj_map_kd_is_read_from_its_librarys_folder_and_sampled_at_the_vts() {
    let dir = tempfile::tempdir().unwrap();
    // OBJ's v runs up the image: the top corners have v = 1.
    let obj = "mtllib lib/square.mtl\n\
               v -1 2 -5\nv 1 2 -5\nv -1 0 -5\nv 1 0 -5\n\
               vt 0 1\nvt 1 1\nvt 0 0\nvt 1 0\n\
               usemtl paint\nf 1/1 3/3 2/2\nf 2/2 3/3 4/4\n";
    std::fs::create_dir_all(dir.path().join("lib/tex")).unwrap();
    std::fs::write(dir.path().join("square.obj"), obj).unwrap();
    std::fs::write(
        dir.path().join("lib/square.mtl"),
        "newmtl paint\nKd 1 0.5 1\nmap_Kd tex/square.png\n",
    )
    .unwrap();
    std::fs::write(dir.path().join("lib/tex/square.png"), png()).unwrap();
    assert_colours(quarter_colours(&scene_with_mesh(dir.path(), "square.obj")));
}

#[test]
fn a_texture_that_cannot_be_read_is_one_error_line_naming_its_image() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("square.bin"), square()).unwrap();
    let cases = [
        // A JPEG (PNG only), a missing file, a data URI that is not base64, a PNG cut short.
        (
            format!(
                r#"{{"uri":"{}"}}"#,
                data_uri("image/jpeg", b"\xff\xd8\xff\xe0JFIF")
            ),
            vec!["image 0", "PNG"],
        ),
        (
            r#"{"uri":"gone.png"}"#.to_string(),
            vec!["image 0", "gone.png"],
        ),
        (
            r#"{"uri":"data:image/png,abc"}"#.to_string(),
            vec!["image 0", "base64"],
        ),
        // Found by fuzzing: the gltf crate unwrapped these.
        (
            r#"{"name":"none"}"#.to_string(),
            vec!["image 0", "neither a uri nor a bufferView"],
        ),
        (
            r#"{"bufferView":0}"#.to_string(),
            vec!["image 0", "without its mimeType"],
        ),
        (
            format!(r#"{{"uri":"{}"}}"#, data_uri("image/png", &png()[..20])),
            vec!["image 0"],
        ),
    ];
    for (image, words) in cases {
        let json = gltf_json(r#"{"byteLength":92,"uri":"square.bin"}"#, &image, "");
        std::fs::write(dir.path().join("square.gltf"), json).unwrap();
        scene_with_mesh(dir.path(), "square.gltf");
        let mut words = words;
        words.push("square.gltf");
        common::refusal::render_refused(dir.path(), &words);
    }
}

#[test]
fn a_scene_material_replaces_one_of_a_meshs_own_materials_by_name() {
    // car.mtl's body, glass and wheels: the body takes the scene's glossy `paint`, the others
    // stay the file's.
    let car = common::repo_path("assets/car.obj");
    let object = |keys: &str| {
        format!(
            "[[material]]\nname = \"paint\"\ncolor = [0.1, 0.2, 0.6]\nspecular = 0.04\nroughness = 0.1\n\n\
             [[object]]\nname = \"car\"\nkind = \"mesh\"\npath = \"{}\"\ntranslate = [0.0, 0.0, -8.0]\n{keys}\n",
            car.display()
        )
    };
    let load = |keys: &str| {
        let dir = common::refusal::scratch(&object(keys), &[]);
        seethru::scene::world::World::build(&Scene::load(&dir.path().join("scene.toml")).unwrap())
    };
    let world = load("materials = { body = \"paint\" }").unwrap();
    let plain = load("").unwrap();
    let car_id = 1 + world.objects.iter().position(|o| o.name == "car").unwrap() as u32;
    let file = seethru::scene::mesh_io::load_mesh(&car).unwrap();
    let body = file
        .materials
        .iter()
        .position(|m| m.name == "body")
        .unwrap();
    let (mut bodies, mut others) = (0, 0);
    for (attr, plain_attr) in
        (world.tri_attrs.iter().zip(&plain.tri_attrs)).filter(|(a, _)| a.object == car_id)
    {
        let m = &world.materials[attr.material as usize];
        let was = &plain.materials[plain_attr.material as usize];
        if was.albedo == Vec3::from_array(file.materials[body].linear_color) {
            assert_eq!((m.specular, m.roughness), (0.04, 0.1));
            assert_eq!(m.albedo, Vec3::new(0.1, 0.2, 0.6).map(srgb_to_linear));
            bodies += 1;
        } else {
            assert_eq!((m.specular, m.albedo), (0.0, was.albedo));
            others += 1;
        }
    }
    assert!(
        bodies > 100 && others > 100,
        "{bodies} body, {others} other triangles"
    );

    // Names the file does not define, or the scene does not, and keys that contradict.
    let refused = |keys: &str, words: &[&str]| {
        let scratch = common::refusal::scratch(&object(keys), &[]);
        common::refusal::render_refused(scratch.path(), words);
    };
    refused(
        "materials = { bonnet = \"paint\" }",
        &[
            "scene.toml",
            "materials.bonnet",
            "car.obj",
            "body, glass, wheels",
        ],
    );
    refused(
        "materials = { body = \"chrome\" }",
        &["materials.body", "chrome", "paint"],
    );
    refused(
        "material = \"paint\"\nmaterials = { body = \"paint\" }",
        &["materials", "one of the two"],
    );
    refused("materials = \"paint\"", &["materials", "table"]);
    let not_a_mesh = "[[object]]\nname = \"box\"\nkind = \"box\"\nmaterial = \"grey\"\n\
                      materials = { body = \"grey\" }\n";
    let scratch = common::refusal::scratch(not_a_mesh, &[]);
    common::refusal::render_refused(scratch.path(), &["materials", "only a `mesh` object"]);
    // A roughness with no coat to shape.
    let matte = "[[material]]\nname = \"matte\"\ncolor = [0.5, 0.5, 0.5]\nroughness = 0.3\n";
    let scratch = common::refusal::scratch(matte, &[]);
    common::refusal::render_refused(scratch.path(), &["material[1].roughness", "specular"]);
}
