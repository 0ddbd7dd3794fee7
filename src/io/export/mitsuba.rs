//! The export as Mitsuba 3 scenes: `<stem>.xml` with every object and the three sensors, and
//! one scene per seethru view (`<stem>.truth.xml`, `.occluded.xml`, `.frontal.xml`,
//! `.back.xml`) with that view's camera and only the objects it shows — Mitsuba cannot hide a
//! shape from one sensor, and the driver's eye sits inside the head that only the back camera
//! sees. Meshes (binary PLY with normals and UVs), textures and the sky map lie in
//! `<stem>_assets/`.
//!
//! Lighting (see [`crate::io::export::content::Lighting`]): the sun is a `directional` emitter with π ×
//! seethru's irradiance; seethru's ambient term is an `envmap` of two uniform hemispheres,
//! which gives an unoccluded surface exactly seethru's ambient light. Surfaces are `diffuse`
//! inside `twosided`, a glossy one a blend of a diffuse and a coat (`Coat`); the `direct`
//! integrator adds no interreflections, as seethru's diffuse shading (a glossy coat's
//! reflection of other objects, one ray in seethru, has no counterpart there).

use std::collections::BTreeMap;
use std::fmt::Write;
use std::path::{Path, PathBuf};

use anyhow::Result;
use glam::{DVec3, Vec3};

use crate::geometry::camera::Camera;
use crate::io::atomic::{write_atomically, write_text};
use crate::io::export::content::{
    CAMERA_ZNEAR, ExportLamp, ExportMaterial, ExportScene, Primitive, VIEWS, assets_dir, sanitize,
    write_asset,
};

/// Samples per pixel the scenes ask for by default (`mi.load_file(path, spp=…)` changes it).
pub const DEFAULT_SPP: u32 = 64;
/// Size of the sky map: constant along longitude, so narrow; tall, so that the step at the
/// horizon is sharp (0.35°).
const SKY_MAP: (usize, usize) = (16, 512);

/// The seethru views that get a scene file of their own (`seethru` needs a run's display
/// image, which an export does not have).
const VIEW_FILES: [&str; 4] = ["truth", "occluded", "frontal", "back"];

fn xml_escape(s: &str) -> String {
    s.replace('&', "&amp;")
        .replace('<', "&lt;")
        .replace('>', "&gt;")
        .replace('"', "&quot;")
}

fn triple(v: DVec3) -> String {
    format!("{}, {}, {}", v.x, v.y, v.z)
}

/// How a glossy material is written as Mitsuba's `blendbsdf` of a diffuse and a coat:
/// (1 − w) × diffuse(ρ') + w × coat(1/w) = (1 − F0) ρ/π + the lobe, with ρ' ≤ 1 (Mitsuba
/// refuses brighter reflectances).
#[derive(Clone, Copy)]
struct Coat {
    /// The coat's weight w in the blend, (0, 0.5].
    weight: f32,
    /// ρ'/ρ = (1 − F0)/(1 − w).
    diffuse_scale: f32,
}

impl Coat {
    fn of(m: &ExportMaterial) -> Coat {
        let brightest = match &m.texture {
            Some(t) => {
                (t.texels.iter()).fold(0.0f32, |a, &c| a.max((c * m.linear_color).max_element()))
            }
            None => m.linear_color.max_element(),
        };
        let diffuse = (1.0 - m.specular) * brightest;
        let weight = (1.0 - diffuse).min(0.5);
        Coat {
            weight,
            diffuse_scale: (1.0 - m.specular) / (1.0 - weight),
        }
    }
}

fn rgb(v: Vec3) -> String {
    format!("{}, {}, {}", v.x, v.y, v.z)
}

fn bsdf_id(index: usize, name: &str) -> String {
    format!("m{index}_{}", sanitize(name))
}

/// A Mitsuba `perspective` sensor with seethru's camera: `fov` is the full horizontal angle,
/// 2 θx, so the image spans exactly seethru's half angle; a box filter, like seethru's
/// averaging of samples within a pixel. `size` is the film's width and height: numbers, or
/// `$width`, `$height` parameters.
fn sensor_xml(s: &mut String, name: &str, c: &Camera, size: [String; 2]) {
    let fov = 2.0 * c.half_angle_x.to_degrees();
    let up = c.world_from_camera.matrix3.y_axis;
    let _ = write!(
        s,
        r#"
    <sensor type="perspective" id="{name}" name="{name}">
        <string name="fov_axis" value="x"/>
        <float name="fov" value="{fov}"/>
        <float name="near_clip" value="{CAMERA_ZNEAR}"/>
        <float name="far_clip" value="100000"/>
        <transform name="to_world">
            <lookat origin="{}" target="{}" up="{}"/>
        </transform>
        <sampler type="independent">
            <integer name="sample_count" value="$spp"/>
        </sampler>
        <film type="hdrfilm">
            <integer name="width" value="{}"/>
            <integer name="height" value="{}"/>
            <rfilter type="box"/>
        </film>
    </sensor>
"#,
        triple(c.position()),
        triple(c.position() + c.forward()),
        triple(up),
        size[0],
        size[1],
    );
}

/// One PLY shape of the export: an object's triangles of one material.
struct ShapeFile {
    id: String,
    file: String,
    bsdf: String,
    views: u8,
}

/// Binary little-endian PLY with positions, normals and UVs.
fn ply_bytes(p: &Primitive) -> Vec<u8> {
    let mut out = format!(
        "ply\nformat binary_little_endian 1.0\ncomment seethru export: world frame, metres\n\
         element vertex {}\nproperty float x\nproperty float y\nproperty float z\n\
         property float nx\nproperty float ny\nproperty float nz\nproperty float u\n\
         property float v\nelement face {}\nproperty list uchar int vertex_indices\nend_header\n",
        p.positions.len(),
        p.triangles.len()
    )
    .into_bytes();
    for i in 0..p.positions.len() {
        let (x, n, t) = (p.positions[i], p.normals[i], p.uvs[i]);
        for f in [x.x, x.y, x.z, n.x, n.y, n.z, t.x, t.y] {
            out.extend(f.to_le_bytes());
        }
    }
    for t in &p.triangles {
        out.push(3);
        for i in t {
            out.extend((*i as i32).to_le_bytes());
        }
    }
    out
}

/// Writes each object's PLY meshes (one per material) and returns their shapes.
fn write_meshes(
    content: &ExportScene,
    assets: &Path,
    files: &mut Vec<PathBuf>,
) -> Result<Vec<ShapeFile>> {
    let assets_name = assets.file_name().unwrap_or_default().to_string_lossy();
    let mut shapes = Vec::new();
    for o in &content.objects {
        let mut by_material: BTreeMap<usize, Primitive> = BTreeMap::new();
        for p in &o.primitives {
            by_material
                .entry(p.material)
                .or_insert_with(|| Primitive::new(p.part, p.material))
                .append(p);
        }
        for (material, mesh) in by_material {
            let id = format!("o{}_{}_m{material}", o.id, sanitize(&o.name));
            let file = format!("{id}.ply");
            files.push(write_asset(assets, &file, &ply_bytes(&mesh))?);
            shapes.push(ShapeFile {
                id,
                file: format!("{assets_name}/{file}"),
                bsdf: bsdf_id(material, &content.materials[material].name),
                views: o.views,
            });
        }
    }
    Ok(shapes)
}

fn write_exr(
    path: &Path,
    width: usize,
    height: usize,
    texel: impl Fn(usize, usize) -> Vec3 + Sync,
) -> Result<()> {
    use exr::prelude::{Image, SpecificChannels, Vec2, WritableImage};
    let channels = SpecificChannels::rgb(|Vec2(x, y)| {
        let c = texel(x, y);
        (c.x, c.y, c.z)
    });
    let image = Image::from_channels((width, height), channels);
    write_atomically(path, |file| Ok(image.write().to_buffered(file)?))
}

/// The emitters and the materials: what every scene file of the export shares.
fn lights_and_materials(
    content: &ExportScene,
    assets: &Path,
    files: &mut Vec<PathBuf>,
) -> Result<String> {
    let assets_name = xml_escape(&assets.file_name().unwrap_or_default().to_string_lossy());
    let light = &content.lighting;
    let sky_path = assets.join("sky.exr");
    write_exr(&sky_path, SKY_MAP.0, SKY_MAP.1, |_, y| {
        if y < SKY_MAP.1 / 2 {
            light.sky_up
        } else {
            light.sky_down
        }
    })?;
    files.push(sky_path);
    let mut s = String::new();
    let _ = write!(
        s,
        r#"
    <emitter type="directional" id="sun">
        <vector name="direction" value="{}"/>
        <rgb name="irradiance" value="{}"/>
    </emitter>
    <!-- seethru's ambient light: the upper hemisphere sky_up, the lower sky_down. -->
    <emitter type="envmap" id="sky">
        <string name="filename" value="{assets_name}/sky.exr"/>
    </emitter>
"#,
        rgb(-light.sun_direction),
        rgb(light.sun_irradiance),
    );
    for lamp in &content.lamps {
        lamp_xml(&mut s, lamp);
    }
    for (i, m) in content.materials.iter().enumerate() {
        let id = bsdf_id(i, &m.name);
        let coat = (m.specular > 0.0).then(|| Coat::of(m));
        let scale = coat.map_or(1.0, |c| c.diffuse_scale);
        let reflectance = match &m.texture {
            // Colour × texture, linear, as the renderer multiplies them.
            Some(t) => {
                let file = format!("{id}.exr");
                let path = assets.join(&file);
                let w = t.width as usize;
                write_exr(&path, w, t.height as usize, |x, y| {
                    t.texels[y * w + x] * m.linear_color * scale
                })?;
                files.push(path);
                format!(
                    r#"<texture type="bitmap" name="reflectance">
                <string name="filename" value="{assets_name}/{file}"/>
                <string name="filter_type" value="bilinear"/>
                <string name="wrap_mode" value="repeat"/>
            </texture>"#
                )
            }
            None => format!(
                r#"<rgb name="reflectance" value="{}"/>"#,
                rgb(m.linear_color * scale)
            ),
        };
        let inner = match coat {
            // seethru's glossy material is a sum, (1 − F0) ρ/π + the coat's GGX lobe: a blend
            // of a diffuse and a conductor of the coat's real index (k = 0, whose Fresnel term
            // is a dielectric's), each scaled up by its weight's inverse.
            Some(coat) => format!(
                r#"<bsdf type="blendbsdf">
            <float name="weight" value="{w}"/>
            <bsdf type="diffuse">
            {reflectance}
            </bsdf>
            <bsdf type="roughconductor">
                <string name="distribution" value="ggx"/>
                <float name="alpha" value="{alpha}"/>
                <rgb name="eta" value="{n}, {n}, {n}"/>
                <rgb name="k" value="0, 0, 0"/>
                <float name="specular_reflectance" value="{s}"/>
            </bsdf>
        </bsdf>"#,
                w = coat.weight,
                alpha = m.roughness,
                n = m.coat_ior(),
                s = 1.0 / coat.weight,
            ),
            None => format!(
                r#"<bsdf type="diffuse">
            {reflectance}
        </bsdf>"#
            ),
        };
        let _ = write!(
            s,
            r#"
    <bsdf type="twosided" id="{id}">
        {inner}
    </bsdf>
"#
        );
    }
    Ok(s)
}

/// A `[[light]]` lamp: Mitsuba's `point` or `spot` emitter of the same radiant intensity.
/// Mitsuba's spot falls off linearly in angle between `beam_width` and `cutoff_angle`
/// (seethru's by a smoothstep of the cosine), and knows no cut-off line or lamp without
/// shadows: the comment says where the export differs.
fn lamp_xml(s: &mut String, lamp: &ExportLamp) {
    let name = xml_escape(&lamp.name).replace("--", "- -");
    let mut notes = Vec::new();
    if !lamp.casts_shadow {
        notes.push("casts_shadow = false in seethru: Mitsuba's lamps always cast shadows");
    }
    let p = lamp.position;
    match &lamp.spot {
        None => {
            let _ = write!(
                s,
                r#"
    <!-- lamp {name}{} -->
    <emitter type="point">
        <point name="position" x="{}" y="{}" z="{}"/>
        <rgb name="intensity" value="{}"/>
    </emitter>
"#,
                notes.iter().map(|n| format!(": {n}")).collect::<String>(),
                p.x,
                p.y,
                p.z,
                rgb(lamp.intensity)
            );
        }
        Some(spot) => {
            notes.push("Mitsuba's spot falls off linearly in angle between beam_width and cutoff_angle, seethru's by a smoothstep of the cosine");
            if spot.cutoff_deg.is_some() {
                notes
                    .push("its cut-off line (cutoff_deg) is not exported: Mitsuba's spot has none");
            }
            let target = p + spot.direction;
            let up = if spot.direction.cross(DVec3::Y).length() > 1e-6 {
                DVec3::Y
            } else {
                DVec3::Z
            };
            let _ = write!(
                s,
                r#"
    <!-- lamp {name}: {} -->
    <emitter type="spot">
        <transform name="to_world">
            <lookat origin="{}, {}, {}" target="{}, {}, {}" up="{}, {}, {}"/>
        </transform>
        <rgb name="intensity" value="{}"/>
        <float name="cutoff_angle" value="{}"/>
        <float name="beam_width" value="{}"/>
    </emitter>
"#,
                notes.join("; "),
                p.x,
                p.y,
                p.z,
                target.x,
                target.y,
                target.z,
                up.x,
                up.y,
                up.z,
                rgb(lamp.intensity),
                spot.cone_deg,
                spot.falloff_deg,
            );
        }
    }
}

fn scene_xml(
    comment: &str,
    shared: &str,
    sensors: &[(&str, &Camera)],
    shapes: &[&ShapeFile],
) -> String {
    let mut s = format!(
        "<?xml version=\"1.0\" encoding=\"utf-8\"?>\n<!-- {} -->\n<scene version=\"3.0.0\">\n    \
         <default name=\"spp\" value=\"{DEFAULT_SPP}\"/>\n    <integrator type=\"direct\"/>\n",
        comment.replace("--", "- -")
    );
    match sensors {
        // One view: its size is a parameter, `mi.load_file(path, width=…, height=…)`.
        [(name, c)] => {
            let _ = write!(
                s,
                "    <default name=\"width\" value=\"{}\"/>\n    <default name=\"height\" value=\"{}\"/>\n",
                c.width, c.height
            );
            sensor_xml(&mut s, name, c, ["$width".into(), "$height".into()]);
        }
        _ => {
            for (name, c) in sensors {
                sensor_xml(&mut s, name, c, [c.width, c.height].map(|v| v.to_string()));
            }
        }
    }
    s.push_str(shared);
    for shape in shapes {
        let _ = write!(
            s,
            r#"
    <shape type="ply" id="{}">
        <string name="filename" value="{}"/>
        <ref id="{}"/>
    </shape>
"#,
            shape.id,
            xml_escape(&shape.file),
            shape.bsdf
        );
    }
    s.push_str("</scene>\n");
    s
}

/// Writes `path` (every object, three sensors), `<stem>.<view>.xml` per view, and the
/// meshes, textures and sky map in `<stem>_assets/`.
pub fn write_mitsuba(content: &ExportScene, path: &Path) -> Result<Vec<PathBuf>> {
    let assets = assets_dir(path);
    let mut files = vec![path.to_path_buf()];
    let shared = lights_and_materials(content, &assets, &mut files)?;
    let shapes = write_meshes(content, &assets, &mut files)?;
    let source = content.scene.path.display();
    let all: Vec<&ShapeFile> = shapes.iter().collect();
    let everything = format!(
        "seethru export of {source}: every object and the three sensors (driver, frontal, back). \
         The driver's eye is inside the head, which seethru hides from the driver: render a \
         view from its own file, e.g. the truth from the .truth.xml beside this one."
    );
    write_text(
        path,
        &scene_xml(&everything, &shared, &content.cameras(), &all),
    )?;
    let stem = path.file_stem().unwrap_or_default().to_string_lossy();
    for view in VIEW_FILES {
        let (_, bit, camera) = VIEWS.iter().find(|(v, _, _)| *v == view).unwrap();
        let sensor = content
            .cameras()
            .into_iter()
            .find(|(name, _)| name == camera)
            .unwrap();
        let visible: Vec<&ShapeFile> = shapes.iter().filter(|s| s.views & bit != 0).collect();
        let comment = format!(
            "seethru export of {source}: the `{view}` view, from the {camera} camera, with the \
             objects it shows"
        );
        let view_path = path.with_file_name(format!("{stem}.{view}.xml"));
        write_text(
            &view_path,
            &scene_xml(&comment, &shared, &[sensor], &visible),
        )?;
        files.insert(
            1 + VIEW_FILES.iter().position(|v| *v == view).unwrap(),
            view_path,
        );
    }
    Ok(files)
}
