//! The export as Wavefront OBJ: `o` per object (positions, UVs, normals), `usemtl` per
//! material, and `<stem>.mtl` beside it (linear `Kd`, `map_Kd` textures in `<stem>_assets/`).
//! OBJ has no cameras, lights or ids: those are in `<stem>.cameras.json`, and the objects'
//! ids in the comment above each `o`.

use std::fmt::Write;
use std::path::{Path, PathBuf};

use anyhow::Result;

use crate::io::atomic::write_text;
use crate::io::export::content::{ExportScene, assets_dir, sanitize, texture_png, write_asset};

fn material_name(index: usize, name: &str) -> String {
    format!("m{index}_{}", sanitize(name))
}

fn obj_text(content: &ExportScene, mtl_name: &str) -> String {
    let mut s = String::new();
    let _ = writeln!(
        s,
        "# seethru export: world-space triangles, metres, +y up; normals as the renderer shades\n\
         # them; UVs include each material's uv_repeat\nmtllib {mtl_name}"
    );
    // OBJ indices are global and 1-based; position, UV and normal lists run in step.
    let mut base = 1;
    for o in &content.objects {
        let _ = writeln!(
            s,
            "# seethru_id {} kind {} hidden_from [{}]",
            o.id,
            o.kind,
            o.hidden_from().join(", ")
        );
        let _ = writeln!(s, "o {}", o.name.replace(char::is_whitespace, "_"));
        for p in &o.primitives {
            for v in &p.positions {
                let _ = writeln!(s, "v {} {} {}", v.x, v.y, v.z);
            }
            // OBJ puts v = 0 at the image's bottom.
            for t in &p.uvs {
                let _ = writeln!(s, "vt {} {}", t.x, 1.0 - t.y);
            }
            for n in &p.normals {
                let _ = writeln!(s, "vn {} {} {}", n.x, n.y, n.z);
            }
            let m = &content.materials[p.material];
            let _ = writeln!(s, "usemtl {}", material_name(p.material, &m.name));
            for t in &p.triangles {
                let [a, b, c] = t.map(|i| base + i as usize);
                let _ = writeln!(s, "f {a}/{a}/{a} {b}/{b}/{b} {c}/{c}/{c}");
            }
            base += p.positions.len();
        }
    }
    s
}

/// Writes `path` (.obj), `<stem>.mtl` and the textures in `<stem>_assets/`.
pub fn write_obj(content: &ExportScene, path: &Path) -> Result<Vec<PathBuf>> {
    let mtl_path = path.with_extension("mtl");
    let mtl_name = mtl_path.file_name().unwrap_or_default().to_string_lossy();
    let assets = assets_dir(path);
    let assets_name = assets.file_name().unwrap_or_default().to_string_lossy();
    let mut files = vec![path.to_path_buf(), mtl_path.clone()];
    let mut mtl = String::from(
        "# seethru materials: Kd is linear RGB (the scene's sRGB colours decoded); Lambertian\n",
    );
    for (i, m) in content.materials.iter().enumerate() {
        let name = material_name(i, &m.name);
        // Blinn–Phong adds Kd and Ks: a coat's diffuse part is (1 − F0) ρ, as seethru's.
        let c = m.linear_color * (1.0 - m.specular);
        let _ = writeln!(mtl, "\nnewmtl {name}\nKd {} {} {}", c.x, c.y, c.z);
        if m.specular > 0.0 {
            // A glossy lobe as Blinn–Phong's: the exponent of the same slope width (Walter
            // et al. 2007: α = √(2 / (Ns + 2))).
            let (f0, alpha) = (m.specular, m.roughness);
            let ns = 2.0 / (alpha * alpha) - 2.0;
            let _ = writeln!(mtl, "Ks {f0} {f0} {f0}\nNs {ns}\nillum 2");
        } else {
            let _ = writeln!(mtl, "Ks 0 0 0\nillum 1");
        }
        if let Some(t) = &m.texture {
            let file = format!("{name}.png");
            files.push(write_asset(&assets, &file, &texture_png(t)?)?);
            let _ = writeln!(mtl, "map_Kd {assets_name}/{file}");
        }
    }
    write_text(&mtl_path, &mtl)?;
    write_text(path, &obj_text(content, &mtl_name))?;
    Ok(files)
}
