//! The display's surface: the obstacle's flat front face (the paper's case), or a curved
//! surface given by triangles with UVs — a mesh file's, or a procedural cylinder's — whose UVs
//! lay out the display's pixel grid: display pixel (x, y) of a W×H display is the surface
//! point whose UV is ((x + ½)/W, (y + ½)/H), u to the right, v down.

use glam::{DVec2, DVec3};

/// How the display's surface is shaped (the `display_shape` key of `[obstacle]`).
#[derive(Clone, Debug, PartialEq)]
pub enum DisplayShape {
    /// The rectangle `width` × `height` in the obstacle frame's plane z = 0.
    Flat,
    /// Triangles with UVs, in the obstacle frame.
    Curved(std::sync::Arc<CurvedSurface>),
}

impl DisplayShape {
    pub fn curved(&self) -> Option<&CurvedSurface> {
        match self {
            DisplayShape::Flat => None,
            DisplayShape::Curved(s) => Some(s),
        }
    }
}

/// One triangle of a curved display.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct UvTri {
    /// Corners, obstacle frame, metres.
    pub p: [DVec3; 3],
    /// Their texture coordinates in [0, 1]² (u right, v down the display's pixel grid).
    pub uv: [DVec2; 3],
}

/// Cells per side of the UV lookup grid.
const GRID: usize = 48;

/// A curved display surface, checked: UVs in [0, 1]², not folded, not overlapping, with area.
#[derive(Clone, Debug, PartialEq)]
pub struct CurvedSurface {
    /// What made it, for messages and `run.json` ("cylinder r = 0.1 m", a mesh path).
    pub source: String,
    pub tris: Vec<UvTri>,
    /// Triangle indices per cell of a GRID×GRID grid over UV space (row-major, v down).
    uv_cells: Vec<Vec<u32>>,
    /// The triangles by position, for [`CurvedSurface::uv_at_point`].
    point_grid: crate::scene::surface_grid::SurfaceGrid,
}

/// How far outside a triangle (in barycentric coordinates) a point may project and still be
/// taken as on it: the seam between two facets must belong to one of them.
const BARYCENTRIC_SLACK: f64 = 1e-4;

fn uv_area(t: &UvTri) -> f64 {
    let [a, b, c] = t.uv;
    (b - a).perp_dot(c - a) / 2.0
}

impl CurvedSurface {
    /// Checks the triangles' UVs; the error says what is wrong, without the file's name.
    pub fn new(source: String, tris: Vec<UvTri>) -> Result<Self, String> {
        if tris.is_empty() {
            return Err("the display surface has no triangles".into());
        }
        if let Some((i, uv)) = tris.iter().enumerate().find_map(|(i, t)| {
            t.uv.iter()
                .find(|uv| {
                    !(uv.x >= -1e-9 && uv.y >= -1e-9 && uv.x <= 1.0 + 1e-9 && uv.y <= 1.0 + 1e-9)
                })
                .map(|uv| (i, *uv))
        }) {
            return Err(format!(
                "triangle {i} has the UV ({}, {}): a display's UVs must lie in [0, 1]² (they lay out its pixel grid)",
                crate::util::number::short(uv.x),
                crate::util::number::short(uv.y)
            ));
        }
        let total: f64 = tris.iter().map(|t| uv_area(t).abs()).sum();
        if total < 1e-12 {
            return Err("the display surface has no UVs (its texture coordinates cover no area, as a mesh without `vt` or TEXCOORD_0 has): a display needs UVs that lay out its pixel grid".into());
        }
        // A fold reverses a triangle's UV winding: the two sides of a fold would show the
        // same display pixels.
        let eps = 1e-12;
        let first = tris
            .iter()
            .position(|t| uv_area(t).abs() > eps)
            .expect("area > 0");
        let sign = uv_area(&tris[first]).signum();
        if let Some(i) = tris.iter().position(|t| uv_area(t) * sign < -eps) {
            return Err(format!(
                "folded UVs: triangle {i}'s UV winding is the reverse of triangle {first}'s, so two parts of the surface would show the same display pixels"
            ));
        }
        if total > 1.0 + 1e-6 {
            return Err(format!(
                "overlapping UVs: the triangles' UVs cover {} of the unit square, more than 1, so parts of the surface would show the same display pixels",
                crate::util::number::short(total)
            ));
        }
        let mut uv_cells = vec![Vec::new(); GRID * GRID];
        for (i, t) in tris.iter().enumerate() {
            let min = t.uv[0].min(t.uv[1]).min(t.uv[2]);
            let max = t.uv[0].max(t.uv[1]).max(t.uv[2]);
            let cell = |v: f64| ((v * GRID as f64) as usize).min(GRID - 1);
            for cy in cell(min.y)..=cell(max.y) {
                for cx in cell(min.x)..=cell(max.x) {
                    uv_cells[cy * GRID + cx].push(i as u32);
                }
            }
        }
        // A point outside a triangle by barycentric slack s is at most 2·s·(longest edge)
        // from it; the grid's margin is more than twice that (see SurfaceGrid::new).
        let longest = tris
            .iter()
            .flat_map(|t| [t.p[1] - t.p[0], t.p[2] - t.p[1], t.p[0] - t.p[2]])
            .map(DVec3::length)
            .fold(0.0, f64::max);
        let margin = 5.0 * BARYCENTRIC_SLACK * longest + 1e-9;
        let point_grid = crate::scene::surface_grid::SurfaceGrid::new(
            &tris.iter().map(|t| t.p).collect::<Vec<_>>(),
            margin,
        );
        Ok(CurvedSurface {
            source,
            tris,
            uv_cells,
            point_grid,
        })
    }

    /// A display wrapped round a cylinder whose axis is the obstacle frame's y axis moved to
    /// z = −`radius`: `width` metres of arc (centred on x = 0, where the surface touches the
    /// plane z = 0, bulging towards the driver) by `height` metres, as `segments` flat facets.
    pub fn cylinder(width: f64, height: f64, radius: f64, segments: usize) -> Result<Self, String> {
        let half_angle = width / (2.0 * radius);
        if half_angle > std::f64::consts::FRAC_PI_2 {
            return Err(format!(
                "a display {} m wide on a cylinder of radius {} m would wrap more than half way round (it needs radius ≥ width / π = {} m)",
                crate::util::number::short(width),
                crate::util::number::short(radius),
                crate::util::number::short(width / std::f64::consts::PI)
            ));
        }
        let column = |i: usize| {
            let u = i as f64 / segments as f64;
            let angle = (u - 0.5) * 2.0 * half_angle;
            (
                u,
                DVec3::new(radius * angle.sin(), 0.0, radius * angle.cos() - radius),
            )
        };
        let mut tris = Vec::with_capacity(2 * segments);
        let (top, bottom) = (DVec3::Y * height / 2.0, -DVec3::Y * height / 2.0);
        for i in 0..segments {
            let ((u0, p0), (u1, p1)) = (column(i), column(i + 1));
            let [tl, tr, br, bl] = [p0 + top, p1 + top, p1 + bottom, p0 + bottom];
            let uv = |u: f64, v: f64| DVec2::new(u, v);
            tris.push(UvTri {
                p: [tl, bl, br],
                uv: [uv(u0, 0.0), uv(u0, 1.0), uv(u1, 1.0)],
            });
            tris.push(UvTri {
                p: [tl, br, tr],
                uv: [uv(u0, 0.0), uv(u1, 1.0), uv(u1, 0.0)],
            });
        }
        Self::new(
            format!(
                "cylinder r = {} m, {segments} facets",
                crate::util::number::short(radius)
            ),
            tris,
        )
    }

    /// The surface point (obstacle frame) with texture coordinates `uv`, or `None` where no
    /// triangle's UVs cover it.
    pub fn point_at_uv(&self, uv: DVec2) -> Option<DVec3> {
        if !(uv.x >= 0.0 && uv.y >= 0.0 && uv.x <= 1.0 && uv.y <= 1.0) {
            return None;
        }
        let cell = |v: f64| ((v * GRID as f64) as usize).min(GRID - 1);
        let candidates = &self.uv_cells[cell(uv.y) * GRID + cell(uv.x)];
        candidates.iter().find_map(|&i| {
            let t = &self.tris[i as usize];
            let [a, b, c] = t.uv;
            let area = (b - a).perp_dot(c - a);
            if area == 0.0 {
                return None;
            }
            let wb = (uv - a).perp_dot(c - a) / area;
            let wc = (b - a).perp_dot(uv - a) / area;
            let wa = 1.0 - wb - wc;
            let eps = -1e-12;
            (wa >= eps && wb >= eps && wc >= eps).then(|| t.p[0] * wa + t.p[1] * wb + t.p[2] * wc)
        })
    }

    /// The texture coordinates of a point on the surface (obstacle frame): those of the
    /// triangle nearest to it. The same answer as [`CurvedSurface::uv_at_point_brute`]
    /// (tested), from the triangles of the point's grid cell: a triangle outside the cell is
    /// more than the grid's margin from the point, so it cannot beat one found within half
    /// of it; otherwise (a point off the surface) the brute force answers.
    pub fn uv_at_point(&self, p: DVec3) -> Option<DVec2> {
        self.uv_at_point_by_grid(p)
            .or_else(|| self.uv_at_point_brute(p))
    }

    /// The grid's answer to [`CurvedSurface::uv_at_point`], where it can vouch for it (the
    /// nearest triangle of the point's cell within half the grid's margin); `None` otherwise.
    pub fn uv_at_point_by_grid(&self, p: DVec3) -> Option<DVec2> {
        let cell = self.point_grid.candidates(p)?;
        let best = nearest(cell.iter().map(|&i| &self.tris[i as usize]), p);
        best.filter(|(d, _)| *d <= self.point_grid.margin / 2.0)
            .map(|(_, uv)| uv.clamp(DVec2::ZERO, DVec2::ONE))
    }

    /// [`CurvedSurface::uv_at_point`] by a scan over every triangle: its brute-force twin.
    pub fn uv_at_point_brute(&self, p: DVec3) -> Option<DVec2> {
        nearest(self.tris.iter(), p).map(|(_, uv)| uv.clamp(DVec2::ZERO, DVec2::ONE))
    }

    /// Obstacle-frame bounding box (min, max) of the surface.
    pub fn bounds(&self) -> (DVec3, DVec3) {
        self.tris.iter().flat_map(|t| t.p).fold(
            (DVec3::splat(f64::INFINITY), DVec3::splat(f64::NEG_INFINITY)),
            |(lo, hi), p| (lo.min(p), hi.max(p)),
        )
    }
}

/// The triangle of `tris` whose plane is nearest to `p` among those `p` projects into (within
/// the slack), first on ties: its plane distance and the UV of the projection.
fn nearest<'a>(tris: impl Iterator<Item = &'a UvTri>, p: DVec3) -> Option<(f64, DVec2)> {
    let mut best: Option<(f64, DVec2)> = None;
    for t in tris {
        let [a, b, c] = t.p;
        let (e1, e2) = (b - a, c - a);
        let n = e1.cross(e2);
        let nn = n.length_squared();
        if nn == 0.0 {
            continue;
        }
        let q = p - a;
        let dist = (q.dot(n)).abs() / nn.sqrt();
        if best.is_some_and(|(d, _)| d <= dist) {
            continue;
        }
        // Barycentric coordinates of p's projection onto the triangle's plane.
        let wb = q.cross(e2).dot(n) / nn;
        let wc = e1.cross(q).dot(n) / nn;
        let wa = 1.0 - wb - wc;
        let eps = -BARYCENTRIC_SLACK;
        if wa >= eps && wb >= eps && wc >= eps {
            best = Some((dist, t.uv[0] * wa + t.uv[1] * wb + t.uv[2] * wc));
        }
    }
    best
}

#[cfg(test)]
mod tests {
    use super::*;

    fn quad(uvs: [[f64; 2]; 4]) -> Vec<UvTri> {
        let p = [(-1.0, 1.0), (1.0, 1.0), (1.0, -1.0), (-1.0, -1.0)]
            .map(|(x, y)| DVec3::new(x, y, 0.0));
        let uv = uvs.map(DVec2::from_array);
        vec![
            UvTri {
                p: [p[0], p[3], p[2]],
                uv: [uv[0], uv[3], uv[2]],
            },
            UvTri {
                p: [p[0], p[2], p[1]],
                uv: [uv[0], uv[2], uv[1]],
            },
        ]
    }

    #[test]
    fn a_flat_quad_maps_uv_to_the_point_and_back() {
        let s = CurvedSurface::new(
            "q".into(),
            quad([[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]]),
        )
        .unwrap();
        let p = s.point_at_uv(DVec2::new(0.25, 0.75)).unwrap();
        assert!(p.abs_diff_eq(DVec3::new(-0.5, -0.5, 0.0), 1e-12), "{p}");
        let uv = s.uv_at_point(p).unwrap();
        assert!(uv.abs_diff_eq(DVec2::new(0.25, 0.75), 1e-12));
    }

    #[test]
    fn bad_uvs_are_refused() {
        let none = CurvedSurface::new("q".into(), quad([[0.0, 0.0]; 4])).unwrap_err();
        assert!(none.contains("no UVs"), "{none}");
        // The second triangle mirrored in u: a fold.
        let folded = CurvedSurface::new(
            "q".into(),
            quad([[0.5, 0.0], [0.0, 0.0], [0.0, 1.0], [0.5, 1.0]]),
        );
        let mut tris = quad([[0.0, 0.0], [0.5, 0.0], [0.5, 1.0], [0.0, 1.0]]);
        tris[1].uv = [
            DVec2::new(0.0, 0.0),
            DVec2::new(0.5, 1.0),
            DVec2::new(0.0, 1.0),
        ];
        assert!(
            folded.is_ok(),
            "a mirrored but consistent layout is not a fold"
        );
        let fold = CurvedSurface::new("q".into(), tris).unwrap_err();
        assert!(fold.contains("folded"), "{fold}");
        let outside = CurvedSurface::new(
            "q".into(),
            quad([[0.0, 0.0], [1.5, 0.0], [1.5, 1.0], [0.0, 1.0]]),
        )
        .unwrap_err();
        assert!(outside.contains("[0, 1]²"), "{outside}");
    }

    #[test]
    fn the_cylinder_keeps_its_arc_length_and_radius() {
        let (w, h, r) = (0.12, 0.5, 0.08);
        let s = CurvedSurface::cylinder(w, h, r, 64).unwrap();
        // Every vertex lies on the cylinder (the facets are chords).
        for t in &s.tris {
            for p in t.p {
                assert!(((p.x.powi(2) + (p.z + r).powi(2)).sqrt() - r).abs() < 1e-12);
            }
        }
        // The centre column touches z = 0; the edges are an arc of w / r radians apart.
        let centre = s.point_at_uv(DVec2::new(0.5, 0.5)).unwrap();
        assert!(centre.abs_diff_eq(DVec3::ZERO, 1e-12));
        let edge = s.point_at_uv(DVec2::new(1.0, 0.5)).unwrap();
        assert!((edge.x - r * (w / (2.0 * r)).sin()).abs() < 1e-12);
        assert!(CurvedSurface::cylinder(1.0, h, 0.1, 8).is_err());
    }
}
