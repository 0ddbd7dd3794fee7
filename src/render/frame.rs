//! A frame: the aligned per-pixel buffers (AOVs) of one render.
//!
//! Buffers are row-major with row 0 at the top of the image. Geometric AOVs come from the
//! ray through the pixel centre; colour is the average over all samples of the pixel.

use glam::Vec3;

#[derive(Clone, Debug, PartialEq)]
pub struct Frame {
    pub width: u32,
    pub height: u32,
    /// Radiance, linear RGB (scene-referred; 1.0 is display white).
    pub color: Vec<Vec3>,
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

impl Frame {
    pub fn from_pixels(width: u32, height: u32, pixels: &[Pixel]) -> Frame {
        assert_eq!(pixels.len(), width as usize * height as usize);
        let n = pixels.len();
        let mut frame = Frame {
            width,
            height,
            color: Vec::with_capacity(n),
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
