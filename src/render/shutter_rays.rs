//! A camera's primary rays at the instants its shutter traces (geometry/shutter.rs): one set
//! for a camera that does not move or a global shutter with no exposure; else one per row
//! (a rolling shutter) and per sample (an exposure), from the camera's pose at that instant.

use glam::DAffine3;

use crate::geometry::camera::Camera;
use crate::render::camera_rays::CameraRays;

/// The camera where one instant of its shutter sees it.
pub struct CameraAt {
    pub rays: CameraRays,
    pub camera_from_world: DAffine3,
}

impl CameraAt {
    fn new(camera: &Camera) -> Self {
        Self {
            rays: CameraRays::new(camera),
            camera_from_world: camera.world_from_camera.inverse(),
        }
    }
}

/// The camera's pose `dt` seconds after the frame's instant: its world_from_camera.
pub type PoseAt<'a> = &'a (dyn Fn(f64) -> DAffine3 + Sync);

/// The camera of one render at each of its instants.
pub struct ShutterRays {
    instants: Vec<CameraAt>,
    /// Whether each row has its own instants (a rolling shutter).
    per_row: bool,
    /// Instants per row: `spp` with an exposure, else 1.
    per_sample: u32,
}

impl ShutterRays {
    /// `camera` (at the frame's instant) with its shutter, moving along `pose_at` (`None`:
    /// still), traced with `spp` samples per pixel.
    pub fn new(camera: &Camera, pose_at: Option<PoseAt>, spp: u32) -> Self {
        let shutter = camera.shutter;
        let Some(pose_at) = pose_at.filter(|_| !shutter.is_instant()) else {
            return Self {
                instants: vec![CameraAt::new(camera)],
                per_row: false,
                per_sample: 1,
            };
        };
        let per_row = shutter.is_rolling();
        let rows = if per_row { camera.height } else { 1 };
        let per_sample = if shutter.exposure_s > 0.0 { spp } else { 1 };
        let instants = (0..rows)
            .flat_map(|row| (0..per_sample).map(move |sample| (row, sample)))
            .map(|(row, sample)| {
                let dt = shutter.instant(row, camera.height, sample, spp);
                CameraAt::new(&Camera {
                    world_from_camera: pose_at(dt),
                    ..*camera
                })
            })
            .collect();
        Self {
            instants,
            per_row,
            per_sample,
        }
    }

    /// The camera of every row and sample, where there is one instant.
    #[inline]
    pub fn single(&self) -> Option<&CameraAt> {
        (self.instants.len() == 1).then(|| &self.instants[0])
    }

    /// The camera where sample `sample` of row `y` sees it.
    #[inline]
    pub fn at(&self, y: u32, sample: u32) -> &CameraAt {
        let row = if self.per_row { y as usize } else { 0 };
        let sample = if self.per_sample > 1 {
            sample as usize
        } else {
            0
        };
        &self.instants[row * self.per_sample as usize + sample]
    }
}
