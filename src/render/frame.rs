//! A frame: the aligned per-pixel buffers (AOVs) of one render.
//!
//! Buffers are row-major with row 0 at the top of the image. Geometric AOVs come from the
//! ray through the pixel centre; colour is the average over all samples of the pixel.

use glam::Vec3;

#[derive(Clone, Debug, Default, PartialEq)]
pub struct Frame {
    pub width: u32,
    pub height: u32,
    /// Radiance, linear RGB (scene-referred; 1.0 is display white).
    pub color: Vec<Vec3>,
    /// The luminance of a `color` of 1.0 in a scene lit in physical units, cd/m² (the
    /// scene's [`crate::scene::Photometry::white_cd_m2`]; its EXRs hold `color` × this);
    /// `None` in a scene lit in relative units.
    pub white_cd_m2: Option<f32>,
    /// The exposure of a frame from a camera with a sensor: its gain, what its automatic
    /// exposure metered, its tone curve and codes (`None`: no sensor, the radiance as it is).
    pub exposure: Option<crate::geometry::sensor::Exposure>,
    /// Distance from the camera centre along the pixel-centre ray, metres; +∞ for sky.
    pub depth: Vec<f32>,
    /// Depth along the camera's viewing axis (−z in camera space), metres; +∞ for sky.
    pub camera_z: Vec<f32>,
    /// World position of the visible point, metres; NaN for sky.
    pub position: Vec<Vec3>,
    /// Unit geometric normal of the visible surface, world frame, facing the camera. For sky,
    /// the unit vector back along the pixel-centre ray (a sky at infinity facing the camera), so
    /// that the direction a display pixel shows travels with it; zero where nothing is shown.
    pub normal: Vec<Vec3>,
    /// Object id (index in the scene's object list + 1; the obstacle last); 0 for sky.
    pub object_id: Vec<u32>,
    /// Part of the object (box face, cylinder cap, mesh group); 0 for sky.
    pub part_id: Vec<u32>,
}

impl Frame {
    /// Bytes of one pixel's AOVs across the buffers.
    pub const BYTES_PER_PIXEL: u64 = (3 * std::mem::size_of::<Vec3>()
        + 2 * std::mem::size_of::<f32>()
        + 2 * std::mem::size_of::<u32>()) as u64;
}

/// All AOVs of one pixel.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Pixel {
    pub color: Vec3,
    pub depth: f32,
    pub camera_z: f32,
    pub position: Vec3,
    pub normal: Vec3,
    pub object_id: u32,
    pub part_id: u32,
}

impl Pixel {
    pub const SKY: Pixel = Pixel {
        color: Vec3::ZERO,
        depth: f32::INFINITY,
        camera_z: f32::INFINITY,
        position: Vec3::NAN,
        normal: Vec3::ZERO,
        object_id: 0,
        part_id: 0,
    };
}

/// A band of whole rows of a frame, writable on its own (one per worker task).
pub struct Rows<'a> {
    /// Image row of the band's first row.
    pub y: u32,
    /// Image column of the frame's first column (0 unless the frame is a rectangle of a
    /// larger image: the patch of a view rendered over another).
    x0: u32,
    width: usize,
    color: &'a mut [Vec3],
    depth: &'a mut [f32],
    camera_z: &'a mut [f32],
    position: &'a mut [Vec3],
    normal: &'a mut [Vec3],
    object_id: &'a mut [u32],
    part_id: &'a mut [u32],
}

impl Rows<'_> {
    /// Number of rows in the band.
    pub fn len(&self) -> u32 {
        (self.depth.len() / self.width) as u32
    }

    pub fn is_empty(&self) -> bool {
        self.depth.is_empty()
    }

    /// Writes the pixel of image column `x` in the band's row `row` (counted from the band's
    /// first).
    #[inline]
    pub fn set(&mut self, x: u32, row: u32, p: Pixel) {
        let i = row as usize * self.width + (x - self.x0) as usize;
        self.color[i] = p.color;
        self.depth[i] = p.depth;
        self.camera_z[i] = p.camera_z;
        self.position[i] = p.position;
        self.normal[i] = p.normal;
        self.object_id[i] = p.object_id;
        self.part_id[i] = p.part_id;
    }
}

impl Frame {
    /// A `width`×`height` frame of sky pixels.
    pub fn new(width: u32, height: u32) -> Frame {
        let n = width as usize * height as usize;
        let p = Pixel::SKY;
        Frame {
            width,
            height,
            color: vec![p.color; n],
            white_cd_m2: None,
            exposure: None,
            depth: vec![p.depth; n],
            camera_z: vec![p.camera_z; n],
            position: vec![p.position; n],
            normal: vec![p.normal; n],
            object_id: vec![p.object_id; n],
            part_id: vec![p.part_id; n],
        }
    }

    /// The frame as bands of `rows` rows (the last may be shorter), top to bottom.
    pub fn bands_mut(&mut self, rows: u32) -> Vec<Rows<'_>> {
        self.bands_mut_at(rows, 0, 0)
    }

    /// [`Frame::bands_mut`] of a frame whose pixel (0, 0) is pixel (`x0`, `y0`) of a larger
    /// image: the bands are addressed in the image's rows and columns. A frame without pixels
    /// (no columns or no rows: a rectangle that covers nothing) has no bands.
    pub fn bands_mut_at(&mut self, rows: u32, x0: u32, y0: u32) -> Vec<Rows<'_>> {
        if self.width == 0 || self.height == 0 {
            return Vec::new();
        }
        let width = self.width as usize;
        let n = width * rows.max(1) as usize;
        self.color
            .chunks_mut(n)
            .zip(self.depth.chunks_mut(n))
            .zip(self.camera_z.chunks_mut(n))
            .zip(self.position.chunks_mut(n))
            .zip(self.normal.chunks_mut(n))
            .zip(self.object_id.chunks_mut(n))
            .zip(self.part_id.chunks_mut(n))
            .enumerate()
            .map(
                |(i, ((((((color, depth), camera_z), position), normal), object_id), part_id))| {
                    Rows {
                        y: y0 + i as u32 * rows.max(1),
                        x0,
                        width,
                        color,
                        depth,
                        camera_z,
                        position,
                        normal,
                        object_id,
                        part_id,
                    }
                },
            )
            .collect()
    }

    pub fn from_pixels(width: u32, height: u32, pixels: &[Pixel]) -> Frame {
        assert_eq!(pixels.len(), width as usize * height as usize);
        let n = pixels.len();
        let mut frame = Frame {
            width,
            height,
            color: Vec::with_capacity(n),
            white_cd_m2: None,
            exposure: None,
            depth: Vec::with_capacity(n),
            camera_z: Vec::with_capacity(n),
            position: Vec::with_capacity(n),
            normal: Vec::with_capacity(n),
            object_id: Vec::with_capacity(n),
            part_id: Vec::with_capacity(n),
        };
        for p in pixels {
            frame.color.push(p.color);
            frame.depth.push(p.depth);
            frame.camera_z.push(p.camera_z);
            frame.position.push(p.position);
            frame.normal.push(p.normal);
            frame.object_id.push(p.object_id);
            frame.part_id.push(p.part_id);
        }
        frame
    }

    /// Every AOV of `count` pixels of `from` (from its index `from_at`) into this frame's
    /// pixels from index `at`.
    pub fn copy_pixels(&mut self, at: usize, from: &Frame, from_at: usize, count: usize) {
        let (to, r) = (at..at + count, from_at..from_at + count);
        self.color[to.clone()].copy_from_slice(&from.color[r.clone()]);
        self.depth[to.clone()].copy_from_slice(&from.depth[r.clone()]);
        self.camera_z[to.clone()].copy_from_slice(&from.camera_z[r.clone()]);
        self.position[to.clone()].copy_from_slice(&from.position[r.clone()]);
        self.normal[to.clone()].copy_from_slice(&from.normal[r.clone()]);
        self.object_id[to.clone()].copy_from_slice(&from.object_id[r.clone()]);
        self.part_id[to].copy_from_slice(&from.part_id[r]);
    }

    pub fn index(&self, x: u32, y: u32) -> usize {
        y as usize * self.width as usize + x as usize
    }

    pub fn pixel(&self, x: u32, y: u32) -> Pixel {
        let i = self.index(x, y);
        Pixel {
            color: self.color[i],
            depth: self.depth[i],
            camera_z: self.camera_z[i],
            position: self.position[i],
            normal: self.normal[i],
            object_id: self.object_id[i],
            part_id: self.part_id[i],
        }
    }

    /// Bit-exact equality, treating NaN as equal to itself (sky positions are NaN).
    pub fn bit_identical(&self, other: &Frame) -> bool {
        let f = |a: &[f32], b: &[f32]| {
            a.len() == b.len() && a.iter().zip(b).all(|(x, y)| x.to_bits() == y.to_bits())
        };
        let v = |a: &[Vec3], b: &[Vec3]| {
            a.len() == b.len()
                && a.iter()
                    .zip(b)
                    .all(|(x, y)| f(&x.to_array(), &y.to_array()))
        };
        self.width == other.width
            && self.height == other.height
            && v(&self.color, &other.color)
            && f(&self.depth, &other.depth)
            && f(&self.camera_z, &other.camera_z)
            && v(&self.position, &other.position)
            && v(&self.normal, &other.normal)
            && self.object_id == other.object_id
            && self.part_id == other.part_id
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_frame_without_pixels_has_no_bands_and_a_frame_with_pixels_is_covered_by_its_bands() {
        // A rectangle that covers nothing (an eye that does not see the obstacle) is a frame
        // with no columns or no rows: it has no bands, whatever the band height.
        for (w, h) in [(0, 0), (0, 5), (7, 0)] {
            for rows in [0, 1, 16] {
                assert!(
                    Frame::new(w, h).bands_mut_at(rows, 3, 4).is_empty(),
                    "{w}×{h}"
                );
            }
        }
        // A frame with pixels: bands of `rows` rows (the last shorter), addressed in the
        // larger image's rows, that cover every row once.
        let mut frame = Frame::new(3, 7);
        let bands = frame.bands_mut_at(3, 10, 20);
        let spans: Vec<(u32, u32)> = bands.iter().map(|b| (b.y, b.len())).collect();
        assert_eq!(spans, [(20, 3), (23, 3), (26, 1)]);
    }
}
