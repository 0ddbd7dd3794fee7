//! Loading triangle meshes from OBJ (tobj) and glTF/GLB (gltf) files.
//!
//! Colours in mesh files (OBJ `Kd`, glTF `baseColorFactor`) are taken as linear RGB, as the
//! exporters of Blender and most DCC tools write them. Part ids are the OBJ object/group
//! index or the glTF primitive index, so a measurement can tell a car's body from its wheels.
//!
//! Mesh files come from other programs, so nothing in them is trusted: every vertex and colour
//! must be finite and in range, every index and accessor must point inside its buffer, the glTF
//! node hierarchy must be a forest, and the triangle count stays within
//! [`MAX_TRIANGLES`]. The parsers take the file's bytes and a function that reads the files it
//! refers to (`.mtl`, `.bin`), so that they can be fuzzed without a file system.

use std::cell::RefCell;
use std::collections::HashMap;
use std::io::{BufReader, Cursor};
use std::path::{Path, PathBuf};

use anyhow::{Context, Result, anyhow, bail};
use base64::Engine;
use glam::{DAffine3, Mat4, Vec2, Vec3};

use crate::scene::limits::{MAX_MESH_BYTES, MAX_TRIANGLES, first_bad_vertex};
use crate::scene::mesh_checks::{
    check_glb_header, check_mtl_lines, check_usemtl_names, clipped, obj_error_line, validated,
};
use crate::scene::shapes::Tri;
use crate::scene::texture::Texture;
use crate::util::number::{short, short_list};

/// A material that a mesh file defines.
#[derive(Clone, Debug, PartialEq)]
pub struct FileMaterial {
    pub name: String,
    /// Base colour, linear RGB in [0, 1]; multiplied with the texture where there is one.
    pub linear_color: [f32; 3],
    /// Its base-colour texture: an index into [`LoadedMesh::textures`], sampled at the
    /// triangles' uv (a glTF `baseColorTexture`, repeating).
    pub texture: Option<usize>,
    /// A glossy coat's reflectance at normal incidence, [0, 1]: 0 (Lambertian) for every
    /// mesh file (their `Ks` and roughness are not a coat's); a road map's wet surfaces.
    pub specular: f32,
    /// The coat's GGX roughness α, [0.01, 1].
    pub roughness: f32,
}

impl FileMaterial {
    /// A Lambertian, untextured material of linear colour `linear_color`.
    pub fn matte(name: String, linear_color: [f32; 3]) -> FileMaterial {
        FileMaterial {
            name,
            linear_color,
            texture: None,
            specular: 0.0,
            roughness: crate::scene::limits::DEFAULT_ROUGHNESS as f32,
        }
    }
}

/// Triangles of a mesh file, in the file's own frame (glTF node transforms applied).
#[derive(Clone, Debug, Default)]
pub struct LoadedMesh {
    pub tris: Vec<Tri>,
    pub materials: Vec<FileMaterial>,
    /// The images its materials' textures use, each decoded once.
    pub textures: Vec<Texture>,
    /// glTF meshes that several nodes place, kept once (only [`load_mesh_sharing`] fills it;
    /// elsewhere they are in `tris`, placed at each node).
    pub shared: Vec<SharedMesh>,
}

/// A glTF mesh several nodes place: its triangles in its own frame and each node's placement.
#[derive(Clone, Debug)]
pub struct SharedMesh {
    pub tris: Vec<Tri>,
    /// File frame from the mesh's frame, per node that places it (the node hierarchy's
    /// transforms), in the order the nodes are reached.
    pub file_from_mesh: Vec<DAffine3>,
}

impl LoadedMesh {
    /// Every triangle in the file's frame: `tris`, then each shared mesh at each placement.
    pub fn flat_tris(&self) -> std::borrow::Cow<'_, [Tri]> {
        if self.shared.is_empty() {
            return std::borrow::Cow::Borrowed(&self.tris);
        }
        let mut all = self.tris.clone();
        for shared in &self.shared {
            for m in &shared.file_from_mesh {
                all.extend(shared.tris.iter().map(|t| Tri {
                    p: t.p.map(|p| m.transform_point3(p.as_dvec3()).as_vec3()),
                    ..*t
                }));
            }
        }
        std::borrow::Cow::Owned(all)
    }
}

/// Reads a file that a mesh refers to, within [`MAX_MESH_BYTES`].
pub fn read_limited(path: &Path) -> std::io::Result<Vec<u8>> {
    crate::util::input_file::read_input(path, MAX_MESH_BYTES)
}

/// Loads an OBJ (with its MTL files) or a glTF/GLB (with its buffers). Errors name the file.
pub fn load_mesh(path: &Path) -> Result<LoadedMesh> {
    load(path, false)
}

/// [`load_mesh`], keeping a glTF mesh that several nodes place once, with its placements
/// ([`LoadedMesh::shared`]): what the world instances.
pub fn load_mesh_sharing(path: &Path) -> Result<LoadedMesh> {
    load(path, true)
}

fn load(path: &Path, share: bool) -> Result<LoadedMesh> {
    let lower = path.to_string_lossy().to_ascii_lowercase();
    let bytes = read_limited(path).context("cannot read it");
    let mesh = bytes.and_then(|bytes| {
        if lower.ends_with(".obj") {
            parse_obj(&bytes, path, &read_limited)
        } else if lower.ends_with(".gltf") || lower.ends_with(".glb") {
            parse_gltf_with(&bytes, path, &read_limited, share)
        } else {
            bail!("unsupported mesh format (use .obj, .gltf or .glb)")
        }
    });
    mesh.with_context(|| format!("mesh {}", path.display()))
}

/// The built-in head mesh: `assets/head.obj` and `head.mtl` as built into the binary (the
/// text `scene::head_model::head_obj` generates; `tests/assets.rs` checks they agree), parsed
/// once per process.
pub fn builtin_head() -> &'static LoadedMesh {
    static HEAD: std::sync::OnceLock<LoadedMesh> = std::sync::OnceLock::new();
    HEAD.get_or_init(|| {
        let [obj, mtl] = BUILTIN_HEAD;
        let read = |p: &Path| {
            if p.file_name() == Some(std::ffi::OsStr::new("head.mtl")) {
                Ok(mtl.to_vec())
            } else {
                Err(std::io::Error::from(std::io::ErrorKind::NotFound))
            }
        };
        parse_obj(obj, Path::new("head.obj"), &read).expect("the built-in head mesh parses")
    })
}

/// The built-in head mesh's files: OBJ, then MTL.
pub const BUILTIN_HEAD: [&[u8]; 2] = [
    include_bytes!("../../assets/head.obj"),
    include_bytes!("../../assets/head.mtl"),
];

/// Checks what every loader must deliver: some triangles with an area, within the limits,
/// finite vertices inside the world, colours in [0, 1].
fn checked(mesh: LoadedMesh) -> Result<LoadedMesh> {
    // Triangles are numbered as read: the file's own, then each shared mesh's once.
    let all: Vec<&Tri> = mesh
        .tris
        .iter()
        .chain(mesh.shared.iter().flat_map(|s| &s.tris))
        .collect();
    if all.len() > MAX_TRIANGLES {
        bail!(
            "{} triangles, more than the limit of {MAX_TRIANGLES}",
            all.len()
        );
    }
    if let Some((i, p)) = first_bad_vertex(all.iter().copied()) {
        bail!(
            "triangle {i} has a vertex at {}: coordinates must be finite and within the world, [-1e6, 1e6] m",
            short_list(&p.to_array().map(f64::from))
        );
    }
    if let Some(i) = all
        .iter()
        .position(|t| t.uv.iter().any(|uv| !uv.is_finite()))
    {
        bail!("triangle {i} has a texture coordinate that is not finite");
    }
    if !all.iter().any(|t| {
        let [a, b, c] = t.p;
        (b - a).cross(c - a).length_squared() > 0.0
    }) {
        bail!(
            "no faces with an area ({} triangles, all degenerate or none: points and lines are not drawn)",
            all.len()
        );
    }
    for shared in &mesh.shared {
        if let Some(m) = shared
            .file_from_mesh
            .iter()
            .find(|m| !m.to_cols_array().iter().all(|v| v.is_finite()))
        {
            bail!("a node places a mesh by a transform that is not finite: {m:?}");
        }
    }
    for m in &mesh.materials {
        if m.linear_color.iter().any(|c| !(0.0..=1.0).contains(c)) {
            bail!(
                "material `{}` has the colour {}: components must be in [0, 1]",
                m.name,
                short_list(&m.linear_color.map(f64::from))
            );
        }
    }
    Ok(mesh)
}

/// `bytes` without a leading UTF-8 byte order mark.
fn without_bom(bytes: &[u8]) -> &[u8] {
    bytes.strip_prefix(b"\xEF\xBB\xBF").unwrap_or(bytes)
}

/// Parses an OBJ file's bytes; `path` names it and anchors its `mtllib` files, which `read`
/// reads.
pub fn parse_obj(
    bytes: &[u8],
    path: &Path,
    read: &dyn Fn(&Path) -> std::io::Result<Vec<u8>>,
) -> Result<LoadedMesh> {
    // tobj reads a UTF-8 byte order mark as part of the first keyword and drops that line
    // without a word (a first vertex lost shifts every face onto the wrong vertices).
    let bytes = without_bom(bytes);
    let options = tobj::LoadOptions {
        triangulate: true,
        single_index: true,
        ignore_points: true,
        ignore_lines: true,
    };
    let dir = path.parent().unwrap_or(Path::new(""));
    // tobj's material errors carry no path: remember ours.
    let mtl_error: RefCell<Option<String>> = RefCell::new(None);
    // Each library is read and parsed once: tobj calls this for every `mtllib` line and
    // appends the library's materials again each time (a file of many `mtllib` lines of one
    // library was quadratic, found by fuzzing). The names each library defined, to refuse a
    // name that two libraries define (tobj would let the later one win without a word).
    let loaded: RefCell<Vec<PathBuf>> = RefCell::new(Vec::new());
    let defined_by: RefCell<HashMap<String, String>> = RefCell::new(HashMap::new());
    // The folder of the library that defines each material: its `map_Kd` is relative to it.
    let library_dir: RefCell<HashMap<String, PathBuf>> = RefCell::new(HashMap::new());
    let load_mtl = |written: &Path| -> tobj::MTLLoadResult {
        let resolved = dir.join(written);
        let nothing = || Ok((Vec::new(), Default::default()));
        if mtl_error.borrow().is_some() || loaded.borrow().contains(&resolved) {
            return nothing();
        }
        loaded.borrow_mut().push(resolved.clone());
        let fail = |why: String| {
            mtl_error.borrow_mut().get_or_insert(format!(
                "material library `{}` (resolved against the OBJ's folder: {}): {why}",
                written.display(),
                resolved.display()
            ));
            Err(tobj::LoadError::OpenFileFailed)
        };
        let mtl = match read(&resolved) {
            Ok(mtl) => without_bom(&mtl).to_vec(),
            Err(e) => return fail(e.to_string()),
        };
        if let Err(why) = check_mtl_lines(&mtl) {
            return fail(why);
        }
        let (materials, names) = match tobj::load_mtl_buf(&mut BufReader::new(Cursor::new(mtl))) {
            Ok(parsed) => parsed,
            Err(e) => return fail(e.to_string()),
        };
        let mut defined_by = defined_by.borrow_mut();
        for m in &materials {
            if let Some(first) = defined_by.get(&m.name) {
                return fail(format!(
                    "material `{}` is defined by the library `{first}` too: a name must be defined once",
                    clipped(&m.name)
                ));
            }
        }
        for m in &materials {
            defined_by.insert(m.name.clone(), written.display().to_string());
            let folder = resolved.parent().unwrap_or(Path::new("")).to_path_buf();
            library_dir.borrow_mut().insert(m.name.clone(), folder);
        }
        Ok((materials, names))
    };
    if let Some(why) = obj_error_line(bytes) {
        bail!("invalid OBJ: {why}");
    }
    let (models, materials) =
        tobj::load_obj_buf(&mut BufReader::new(Cursor::new(bytes)), &options, load_mtl)
            .map_err(|e| anyhow!("invalid OBJ: {e}"))?;
    let materials = match (materials, mtl_error.into_inner()) {
        (_, Some(why)) => bail!(why),
        (Err(e), None) => bail!("material library: {e}"),
        (Ok(m), None) => m,
    };
    let mut out = LoadedMesh::default();
    // Each texture file decoded once, however many materials name it.
    let mut decoded: HashMap<PathBuf, usize> = HashMap::new();
    for m in &materials {
        let texture = match &m.diffuse_texture {
            Some(name) => {
                let folder = library_dir
                    .borrow()
                    .get(&m.name)
                    .cloned()
                    .unwrap_or_default();
                let library = defined_by
                    .borrow()
                    .get(&m.name)
                    .cloned()
                    .unwrap_or_default();
                let material = format!("material `{}` of `{library}`", clipped(&m.name));
                let file = obj_texture(&material, name, &folder, read, &mut decoded, &mut out)?;
                Some(file)
            }
            None => None,
        };
        out.materials.push(FileMaterial {
            texture,
            ..FileMaterial::matte(m.name.clone(), m.diffuse.unwrap_or([0.8; 3]))
        });
    }
    let names: Vec<&str> = out.materials.iter().map(|m| m.name.as_str()).collect();
    check_usemtl_names(bytes, &names)?;
    let mut triangles = 0usize;
    for (part, model) in models.iter().enumerate() {
        let mesh = &model.mesh;
        triangles += mesh.indices.len() / 3;
        if triangles > MAX_TRIANGLES {
            bail!("more than the limit of {MAX_TRIANGLES} triangles");
        }
        let vertex = |i: usize| -> Option<Vec3> {
            Some(Vec3::from_slice(mesh.positions.get(3 * i..3 * i + 3)?))
        };
        let uv = |i: usize| match mesh.texcoords.get(2 * i..2 * i + 2) {
            // OBJ puts v = 0 at the image's bottom; ours is at the top.
            Some(t) => Vec2::new(t[0], 1.0 - t[1]),
            None => Vec2::ZERO,
        };
        if let Some(m) = mesh.material_id
            && m >= out.materials.len()
        {
            bail!(
                "object `{}` uses material {m}, which is not defined",
                model.name
            );
        }
        for idx in mesh.indices.chunks_exact(3) {
            let idx = [idx[0] as usize, idx[1] as usize, idx[2] as usize];
            let [Some(a), Some(b), Some(c)] = idx.map(vertex) else {
                bail!(
                    "object `{}` indexes a vertex that does not exist",
                    model.name
                );
            };
            out.tris.push(Tri {
                p: [a, b, c],
                uv: idx.map(uv),
                part: part as u32,
                file_material: mesh.material_id.map(|m| m as u32),
            });
        }
    }
    checked(out)
}

/// Parses a glTF (JSON) or GLB file's bytes; `path` names it and anchors its external
/// buffers, which `read` reads. Images are not loaded: only `baseColorFactor` is used.
pub fn parse_gltf(
    bytes: &[u8],
    path: &Path,
    read: &dyn Fn(&Path) -> std::io::Result<Vec<u8>>,
) -> Result<LoadedMesh> {
    parse_gltf_with(bytes, path, read, false)
}

/// [`parse_gltf`]; with `share`, a mesh several nodes place is kept once
/// ([`LoadedMesh::shared`]).
fn parse_gltf_with(
    bytes: &[u8],
    path: &Path,
    read: &dyn Fn(&Path) -> std::io::Result<Vec<u8>>,
    share: bool,
) -> Result<LoadedMesh> {
    let start = bytes.iter().position(|b| !b.is_ascii_whitespace());
    match start.map(|i| &bytes[i..]) {
        None => bail!("not a GLB/glTF: the file is empty (or only white space)"),
        Some(text) if !text.starts_with(b"{") && !bytes.starts_with(b"glTF") => bail!(
            "not a GLB/glTF: it starts with `{}`; a GLB starts with `glTF`, a glTF file is JSON starting with `{{`",
            clipped(&String::from_utf8_lossy(&text[..text.len().min(8)]))
        ),
        Some(_) => {}
    }
    check_glb_header(bytes)?;
    let gltf::Gltf { document, blob } = gltf::Gltf::from_slice_without_validation(bytes)
        .map_err(|e| anyhow!("invalid glTF: {e}"))?;
    let doc = validated(document.into_json())?;
    for m in doc.materials() {
        let name = m
            .name()
            .map_or_else(|| format!("#{}", m.index().unwrap_or(0)), String::from);
        let pbr = m.pbr_metallic_roughness();
        let alpha = pbr.base_color_factor()[3];
        if !(0.0..=1.0).contains(&alpha) {
            bail!(
                "material `{}` has the baseColorFactor alpha {}: it must be in [0, 1]",
                clipped(&name),
                short(f64::from(alpha))
            );
        }
        if let Some(t) = pbr.base_color_texture()
            && t.tex_coord() != 0
        {
            bail!(
                "material `{}` samples its baseColorTexture at TEXCOORD_{}: only TEXCOORD_0 is read",
                clipped(&name),
                t.tex_coord()
            );
        }
    }
    for node in doc.nodes() {
        if let gltf::scene::Transform::Decomposed { rotation, .. } = node.transform() {
            let length = rotation.iter().map(|q| q * q).sum::<f32>().sqrt();
            if !(length - 1.0).abs().le(&0.01) {
                bail!(
                    "node {} has the rotation {}, a quaternion of length {}: it must be a unit quaternion (length 1 ± 0.01)",
                    node.index(),
                    short_list(&rotation.map(f64::from)),
                    short(f64::from(length))
                );
            }
        }
    }
    let buffers = load_buffers(&doc, blob, path, read)?;
    let mut out = LoadedMesh::default();
    // Each image decoded once, however many materials use it.
    let mut decoded: Vec<Option<usize>> = vec![None; doc.images().len()];
    for m in doc.materials() {
        let pbr = m.pbr_metallic_roughness();
        let c = pbr.base_color_factor();
        let texture = match pbr.base_color_texture() {
            Some(t) => {
                let image = t.texture().source();
                let i = image.index();
                if decoded[i].is_none() {
                    let json = &doc.as_json().images[i];
                    out.textures
                        .push(gltf_image(&image, json, &buffers, path, read)?);
                    decoded[i] = Some(out.textures.len() - 1);
                }
                decoded[i]
            }
            None => None,
        };
        let name = (m.name()).map_or_else(|| format!("#{}", m.index().unwrap_or(0)), String::from);
        out.materials.push(FileMaterial {
            texture,
            ..FileMaterial::matte(name, [c[0], c[1], c[2]])
        });
    }
    let scene = doc.default_scene().or_else(|| doc.scenes().next());
    let Some(scene) = scene else {
        bail!("the file has no scene")
    };
    // The node hierarchy must be a forest: a node reached twice is a cycle or a node with two
    // parents, and following it would loop forever or duplicate geometry.
    let mut reached = vec![false; doc.nodes().len()];
    let mut stack: Vec<(gltf::Node, Mat4)> = scene.nodes().map(|n| (n, Mat4::IDENTITY)).collect();
    let mut placed: Vec<(gltf::Mesh, Mat4)> = Vec::new();
    while let Some((node, parent)) = stack.pop() {
        if std::mem::replace(&mut reached[node.index()], true) {
            bail!(
                "node {} is reached twice from scene {}: the node hierarchy has a cycle or a node with two parents",
                node.index(),
                scene.index()
            );
        }
        let world = parent * Mat4::from_cols_array_2d(&node.transform().matrix());
        if let Some(mesh) = node.mesh() {
            placed.push((mesh, world));
        }
        stack.extend(node.children().map(|c| (c, world)));
    }
    let mut uses = vec![0usize; doc.meshes().len()];
    for (mesh, _) in &placed {
        uses[mesh.index()] += 1;
    }
    // Where each shared mesh is in `out.shared`.
    let mut shared_at: Vec<Option<usize>> = vec![None; doc.meshes().len()];
    let mut part = 0u32;
    for (mesh, world) in placed {
        let read_all = |world: Mat4, part: &mut u32, tris: &mut Vec<Tri>| -> Result<()> {
            for primitive in mesh.primitives() {
                let name = format!(
                    "mesh {} (`{}`) primitive {}",
                    mesh.index(),
                    mesh.name().unwrap_or(""),
                    primitive.index()
                );
                read_primitive(&primitive, &buffers, world, *part, tris).with_context(|| name)?;
                *part += 1;
            }
            Ok(())
        };
        if !(share && uses[mesh.index()] > 1) {
            read_all(world, &mut part, &mut out.tris)?;
            continue;
        }
        let at = match shared_at[mesh.index()] {
            Some(at) => at,
            None => {
                let mut tris = Vec::new();
                read_all(Mat4::IDENTITY, &mut part, &mut tris)?;
                out.shared.push(SharedMesh {
                    tris,
                    file_from_mesh: Vec::new(),
                });
                shared_at[mesh.index()] = Some(out.shared.len() - 1);
                out.shared.len() - 1
            }
        };
        let m = world.as_dmat4();
        out.shared[at].file_from_mesh.push(DAffine3::from_mat4(m));
    }
    checked(out)
}

/// The data of every buffer: the GLB chunk, a `data:` URI, or a file next to the glTF.
fn load_buffers(
    doc: &gltf::Document,
    mut blob: Option<Vec<u8>>,
    path: &Path,
    read: &dyn Fn(&Path) -> std::io::Result<Vec<u8>>,
) -> Result<Vec<Vec<u8>>> {
    let dir = path.parent().unwrap_or(Path::new(""));
    let mut out = Vec::new();
    for buffer in doc.buffers() {
        let i = buffer.index();
        let data = match buffer.source() {
            gltf::buffer::Source::Bin => blob.take().with_context(|| {
                format!("buffer {i} refers to a GLB binary chunk the file does not have")
            })?,
            gltf::buffer::Source::Uri(uri) if uri.starts_with("data:") => {
                gltf::buffer::Data::from_source(buffer.source(), None)
                    .map_err(|e| anyhow!("buffer {i}: invalid data URI: {e}"))?
                    .0
            }
            gltf::buffer::Source::Uri(uri) => {
                let resolved = resolve_uri(dir, uri).with_context(|| {
                    format!(
                        "buffer {i}: unsupported URI `{uri}` (use a relative path or a data: URI)"
                    )
                })?;
                read(&resolved).with_context(|| {
                    format!(
                        "buffer {i}: cannot read `{uri}` (resolved against the glTF file's folder: {})",
                        resolved.display()
                    )
                })?
            }
        };
        if data.len() < buffer.length() {
            bail!(
                "buffer {i} has {} bytes, fewer than its byteLength of {}",
                data.len(),
                buffer.length()
            );
        }
        out.push(data);
    }
    Ok(out)
}

/// The texture a material's `map_Kd` names (relative to its library's folder), decoded into
/// `out.textures` once per file: its index there. `material` names the material and its
/// library for errors.
fn obj_texture(
    material: &str,
    name: &str,
    folder: &Path,
    read: &dyn Fn(&Path) -> std::io::Result<Vec<u8>>,
    decoded: &mut HashMap<PathBuf, usize>,
    out: &mut LoadedMesh,
) -> Result<usize> {
    let what = || format!("{material}: `map_Kd {}`", clipped(name));
    if name.starts_with('-') {
        bail!(
            "{}: its options (`-s`, `-o`, `-clamp`, …) are not read; give the file name alone",
            what()
        );
    }
    let path = folder.join(name);
    if let Some(&index) = decoded.get(&path) {
        return Ok(index);
    }
    let bytes = read(&path).with_context(|| {
        format!(
            "{}: cannot read it (resolved against its library's folder: {})",
            what(),
            path.display()
        )
    })?;
    out.textures
        .push(Texture::decode(&bytes).with_context(what)?);
    decoded.insert(path, out.textures.len() - 1);
    Ok(out.textures.len() - 1)
}

/// The texture of glTF image `image`: a bufferView, a base64 `data:` URI or a file beside the
/// glTF; PNG only.
fn gltf_image(
    image: &gltf::Image,
    json: &gltf::json::Image,
    buffers: &[Vec<u8>],
    path: &Path,
    read: &dyn Fn(&Path) -> std::io::Result<Vec<u8>>,
) -> Result<Texture> {
    let i = image.index();
    // What the gltf crate's `source` unwraps unchecked (found by fuzzing): an image names a
    // uri or a bufferView, and a bufferView comes with its mimeType.
    match (&json.uri, &json.buffer_view, &json.mime_type) {
        (None, None, _) => bail!("image {i} has neither a uri nor a bufferView"),
        (Some(_), Some(_), _) => bail!("image {i} has both a uri and a bufferView"),
        (None, Some(_), None) => bail!("image {i} is a bufferView without its mimeType"),
        _ => {}
    }
    let bytes = match image.source() {
        gltf::image::Source::View { view, .. } => {
            let buffer = &buffers[view.buffer().index()];
            let range = view.offset()..view.offset().saturating_add(view.length());
            buffer
                .get(range)
                .with_context(|| {
                    format!(
                        "image {i}: bufferView {} reaches past the end of buffer {} ({} bytes)",
                        view.index(),
                        view.buffer().index(),
                        buffer.len()
                    )
                })?
                .to_vec()
        }
        gltf::image::Source::Uri { uri, .. } if uri.starts_with("data:") => {
            let (_, payload) = uri.split_once(";base64,").with_context(|| {
                format!("image {i}: its data URI is not base64 (`data:…;base64,…`)")
            })?;
            base64::engine::general_purpose::STANDARD
                .decode(payload)
                .map_err(|e| anyhow!("image {i}: its data URI is not valid base64: {e}"))?
        }
        gltf::image::Source::Uri { uri, .. } => {
            let dir = path.parent().unwrap_or(Path::new(""));
            let resolved = resolve_uri(dir, uri).with_context(|| {
                format!(
                    "image {i}: unsupported URI `{}` (use a relative path, a data: URI or a bufferView)",
                    clipped(uri)
                )
            })?;
            read(&resolved).with_context(|| {
                format!(
                    "image {i}: cannot read `{}` (resolved against the glTF file's folder: {})",
                    clipped(uri),
                    resolved.display()
                )
            })?
        }
    };
    Texture::decode(&bytes).with_context(|| format!("image {i}"))
}

/// A relative URI (percent-encoded) resolved against `dir`; `None` for schemes and absolute
/// paths.
fn resolve_uri(dir: &Path, uri: &str) -> Option<PathBuf> {
    if uri.contains(':') || uri.starts_with('/') {
        return None;
    }
    let bytes = uri.as_bytes();
    let mut decoded = Vec::with_capacity(bytes.len());
    let mut i = 0;
    while i < bytes.len() {
        if bytes[i] == b'%' {
            let hex = std::str::from_utf8(bytes.get(i + 1..i + 3)?).ok()?;
            decoded.push(u8::from_str_radix(hex, 16).ok()?);
            i += 3;
        } else {
            decoded.push(bytes[i]);
            i += 1;
        }
    }
    Some(dir.join(String::from_utf8(decoded).ok()?))
}

/// Checks that `accessor` has the type a reader of `what` expects and lies inside its buffer,
/// so that reading it can neither panic nor read garbage.
fn check_accessor(
    accessor: &gltf::Accessor,
    what: &str,
    dimensions: gltf::accessor::Dimensions,
    types: &[gltf::accessor::DataType],
    buffers: &[Vec<u8>],
) -> Result<()> {
    let i = accessor.index();
    if accessor.dimensions() != dimensions || !types.contains(&accessor.data_type()) {
        bail!(
            "accessor {i} ({what}) is {:?} of {:?}; expected {dimensions:?} of one of {types:?}",
            accessor.dimensions(),
            accessor.data_type()
        );
    }
    if accessor.sparse().is_some() {
        bail!("accessor {i} ({what}) is sparse, which is not supported");
    }
    let view = accessor
        .view()
        .with_context(|| format!("accessor {i} ({what}) has no bufferView"))?;
    let size = accessor.size();
    let stride = view.stride().unwrap_or(size);
    if accessor.count() == 0 || stride < size {
        bail!(
            "accessor {i} ({what}) has {} elements of {size} bytes with a stride of {stride} bytes",
            accessor.count()
        );
    }
    let end = (accessor.count() - 1)
        .checked_mul(stride)
        .and_then(|n| n.checked_add(accessor.offset()))
        .and_then(|n| n.checked_add(size));
    if end.is_none_or(|end| end > view.length()) {
        bail!(
            "accessor {i} ({what}) reaches beyond the end of bufferView {} ({} bytes)",
            view.index(),
            view.length()
        );
    }
    let buffer = &buffers[view.buffer().index()];
    if view
        .offset()
        .checked_add(view.length())
        .is_none_or(|end| end > buffer.len())
    {
        bail!(
            "bufferView {} reaches beyond the end of buffer {} ({} bytes)",
            view.index(),
            view.buffer().index(),
            buffer.len()
        );
    }
    Ok(())
}

fn read_primitive(
    primitive: &gltf::Primitive,
    buffers: &[Vec<u8>],
    world: Mat4,
    part: u32,
    tris: &mut Vec<Tri>,
) -> Result<()> {
    use gltf::accessor::{DataType, Dimensions};
    if primitive.mode() != gltf::mesh::Mode::Triangles {
        bail!("not a triangle list (mode {:?})", primitive.mode());
    }
    let positions = primitive
        .get(&gltf::Semantic::Positions)
        .context("no POSITION attribute")?;
    check_accessor(
        &positions,
        "POSITION",
        Dimensions::Vec3,
        &[DataType::F32],
        buffers,
    )?;
    let texcoords = primitive.get(&gltf::Semantic::TexCoords(0));
    if let Some(t) = &texcoords {
        check_accessor(
            t,
            "TEXCOORD_0",
            Dimensions::Vec2,
            &[DataType::F32, DataType::U8, DataType::U16],
            buffers,
        )?;
    }
    let indices = primitive.indices();
    if let Some(i) = &indices {
        check_accessor(
            i,
            "indices",
            Dimensions::Scalar,
            &[DataType::U8, DataType::U16, DataType::U32],
            buffers,
        )?;
    }
    let corners = indices.as_ref().map_or(positions.count(), |i| i.count());
    if !corners.is_multiple_of(3) {
        let what = match &indices {
            Some(i) => format!("its indices (accessor {})", i.index()),
            None => format!("its POSITION (accessor {}, no indices)", positions.index()),
        };
        bail!(
            "{what} has {corners} elements, not a multiple of 3: a triangle list takes three a triangle"
        );
    }
    let count = corners / 3;
    if tris.len() + count > MAX_TRIANGLES {
        bail!("more than the limit of {MAX_TRIANGLES} triangles");
    }
    let reader = primitive.reader(|b| buffers.get(b.index()).map(Vec::as_slice));
    let positions: Vec<Vec3> = reader
        .read_positions()
        .context("cannot read POSITION")?
        .map(|p| world.transform_point3(Vec3::from_array(p)))
        .collect();
    let uvs: Vec<Vec2> = match reader.read_tex_coords(0) {
        Some(t) => t.into_f32().map(Vec2::from_array).collect(),
        None => vec![Vec2::ZERO; positions.len()],
    };
    if uvs.len() < positions.len() {
        bail!(
            "TEXCOORD_0 has {} elements, fewer than POSITION's {}",
            uvs.len(),
            positions.len()
        );
    }
    let indices: Vec<u32> = match reader.read_indices() {
        Some(i) => i.into_u32().collect(),
        None => (0..positions.len() as u32).collect(),
    };
    let material = primitive.material().index().map(|m| m as u32);
    for idx in indices.chunks_exact(3) {
        let [a, b, c] = [idx[0] as usize, idx[1] as usize, idx[2] as usize];
        if a.max(b).max(c) >= positions.len() {
            bail!(
                "index {} points past the {} vertices",
                a.max(b).max(c),
                positions.len()
            );
        }
        tris.push(Tri {
            p: [positions[a], positions[b], positions[c]],
            uv: [uvs[a], uvs[b], uvs[c]],
            part,
            file_material: material,
        });
    }
    Ok(())
}
