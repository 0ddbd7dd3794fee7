//! The `[obstacle]` keys of a curved display: `display_shape` and the keys of each shape.

use std::sync::Arc;

use glam::{DVec2, DVec3};

use crate::scene::display_surface::{CurvedSurface, DisplayShape, UvTri};
use crate::scene::source::{SceneError, SourceFile};
use crate::scene::table_reader::TableReader;

pub const DISPLAY_SHAPES: [&str; 3] = ["flat", "cylinder", "mesh"];
/// Radius of a cylinder display, metres.
pub const RADIUS_RANGE: (f64, f64) = (0.01, 100.0);
/// Facets of a cylinder display.
pub const SEGMENTS_RANGE: (usize, usize) = (2, 1024);
/// Triangles of a display mesh (each renderer lookup on the display visits them all).
pub const MAX_DISPLAY_TRIANGLES: usize = 20_000;

/// Reads `display_shape` and its keys; `width`, `height` are the display's (metres).
pub fn read_display_shape(
    t: &TableReader,
    file: &SourceFile,
    width: f64,
    height: f64,
) -> Result<DisplayShape, SceneError> {
    let shape = t.choice("display_shape", "flat", &DISPLAY_SHAPES)?;
    // Keys the chosen shape would ignore are refused.
    let owners = [
        ("display_radius", "cylinder"),
        ("display_segments", "cylinder"),
        ("display_mesh", "mesh"),
    ];
    for (key, owner) in owners {
        if t.has(key) && shape != owner {
            return Err(t.error(
                key,
                format!("`{key}` is a key of display_shape = \"{owner}\", but the display_shape is \"{shape}\""),
            ));
        }
    }
    let surface = match shape {
        "flat" => return Ok(DisplayShape::Flat),
        "cylinder" => {
            let radius = t.f64_in("display_radius", 0.1, RADIUS_RANGE.0, RADIUS_RANGE.1)?;
            let segments =
                t.usize_in("display_segments", 32, SEGMENTS_RANGE.0, SEGMENTS_RANGE.1)?;
            CurvedSurface::cylinder(width, height, radius, segments)
                .map_err(|e| t.error("display_radius", e))?
        }
        _ => {
            let rel = t.required_str("display_mesh")?;
            let path = file.dir().join(rel);
            if let Some(why) = crate::util::input_file::not_a_file(&path) {
                return Err(t.error(
                    "display_mesh",
                    format!(
                        "cannot read `{rel}` (resolved against the scene's folder: {}): {why}",
                        path.display()
                    ),
                ));
            }
            let mesh = crate::scene::mesh_io::load_mesh(&path)
                .map_err(|e| t.error("display_mesh", format!("{e:#}")))?;
            if mesh.tris.len() > MAX_DISPLAY_TRIANGLES {
                return Err(t.error(
                    "display_mesh",
                    format!(
                        "`{rel}` has {} triangles, more than a display's limit of {MAX_DISPLAY_TRIANGLES}",
                        mesh.tris.len()
                    ),
                ));
            }
            let tris = mesh
                .tris
                .iter()
                .map(|tri| UvTri {
                    p: tri.p.map(|p| p.as_dvec3()),
                    uv: tri.uv.map(|uv| uv.as_dvec2()),
                })
                .filter(|tri| {
                    let [a, b, c] = tri.p;
                    (b - a).cross(c - a).length_squared() > 0.0
                })
                .collect();
            CurvedSurface::new(rel.to_string(), tris)
                .map_err(|e| t.error("display_mesh", format!("`{rel}`: {e}")))?
        }
    };
    Ok(DisplayShape::Curved(Arc::new(surface)))
}

/// The obstacle-frame points a curved surface reaches, for the world-bounds check.
pub fn surface_corners(shape: &DisplayShape) -> Vec<DVec3> {
    shape.curved().map_or_else(Vec::new, |s| {
        let (lo, hi) = s.bounds();
        vec![lo, hi]
    })
}

/// UV of the centre of display pixel (x, y) of a `size` display.
pub fn pixel_uv(x: f64, y: f64, size: [u32; 2]) -> DVec2 {
    DVec2::new(x / size[0] as f64, y / size[1] as f64)
}
