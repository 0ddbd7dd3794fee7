//! A uniform grid over a curved display's triangles (obstacle frame) for the display-hit
//! lookup: the `seethru` view asks, for every ray that meets the display, which triangle (and
//! so which UV, which display pixel) the hit point lies on. A linear scan over the triangles
//! per ray is the brute force this replaces; it stays as the fallback where the grid cannot
//! vouch for its answer, and as the twin the tests compare the grid with.

use glam::DVec3;

/// Most cells along one axis.
const MAX_CELLS_PER_AXIS: usize = 128;

#[derive(Clone, Debug, PartialEq)]
pub struct SurfaceGrid {
    /// Lower corner of the grid, obstacle frame, metres.
    origin: DVec3,
    /// Cell size along x, y, z, metres (> 0).
    cell: DVec3,
    dims: [usize; 3],
    /// Triangle indices (ascending) per cell, x fastest: every triangle whose bounding box
    /// grown by `margin` meets the cell.
    cells: Vec<Vec<u32>>,
    /// Metres: how far from a triangle a point may be and still find it in its cell.
    pub margin: f64,
}

impl SurfaceGrid {
    /// `margin` must exceed twice the slack of the lookup's barycentric test (how far outside a
    /// triangle a point may project and still be taken as on it), so that a triangle the grid
    /// leaves out of a point's cell can never be nearer than `margin / 2`.
    /// `tris` are the triangles' corners, obstacle frame, metres.
    pub fn new(tris: &[[DVec3; 3]], margin: f64) -> SurfaceGrid {
        let (lo, hi) = tris.iter().flatten().copied().fold(
            (DVec3::splat(f64::INFINITY), DVec3::splat(f64::NEG_INFINITY)),
            |(lo, hi), p| (lo.min(p), hi.max(p)),
        );
        let (origin, top) = (lo - DVec3::splat(margin), hi + DVec3::splat(margin));
        let extent = top - origin;
        // About two cells per triangle, cubes where the extents allow.
        let target = (2 * tris.len()).clamp(8, 65_536) as f64;
        let side = (extent.x * extent.y * extent.z / target).cbrt();
        let dims = extent
            .to_array()
            .map(|e| ((e / side).ceil() as usize).clamp(1, MAX_CELLS_PER_AXIS));
        let cell = extent / DVec3::new(dims[0] as f64, dims[1] as f64, dims[2] as f64);
        let mut grid = SurfaceGrid {
            origin,
            cell,
            dims,
            cells: vec![Vec::new(); dims[0] * dims[1] * dims[2]],
            margin,
        };
        for (i, t) in tris.iter().enumerate() {
            let tlo = t[0].min(t[1]).min(t[2]) - DVec3::splat(margin);
            let thi = t[0].max(t[1]).max(t[2]) + DVec3::splat(margin);
            let (a, b) = (grid.clamped_cell(tlo), grid.clamped_cell(thi));
            for z in a[2]..=b[2] {
                for y in a[1]..=b[1] {
                    for x in a[0]..=b[0] {
                        let c = grid.index([x, y, z]);
                        grid.cells[c].push(i as u32);
                    }
                }
            }
        }
        grid
    }

    fn index(&self, c: [usize; 3]) -> usize {
        (c[2] * self.dims[1] + c[1]) * self.dims[0] + c[0]
    }

    fn clamped_cell(&self, p: DVec3) -> [usize; 3] {
        let f = (p - self.origin) / self.cell;
        [0, 1, 2].map(|i| (f[i].max(0.0) as usize).min(self.dims[i] - 1))
    }

    /// The triangles (ascending indices) that may hold `p`; `None` when `p` is outside the
    /// grid (more than `margin` from every triangle's bounding box).
    pub fn candidates(&self, p: DVec3) -> Option<&[u32]> {
        let f = (p - self.origin) / self.cell;
        let inside = (0..3).all(|i| f[i] >= 0.0 && f[i] < self.dims[i] as f64);
        inside.then(|| self.cells[self.index(self.clamped_cell(p))].as_slice())
    }
}
