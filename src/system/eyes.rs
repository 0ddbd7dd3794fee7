//! The driver's two eyes: which one a run looks with, and which one the compensation serves.
//!
//! The scene's driver camera is the cyclopean eye (the midpoint of the pupils); the left and
//! right eyes sit `ipd / 2` from it along the driver camera's −x and +x.

use glam::DVec3;

use crate::geometry::camera::Camera;
use crate::scene::Obstacle;

/// Largest interpupillary distance accepted, metres.
pub const MAX_IPD: f64 = 0.1;

/// One eye of the driver.
#[derive(
    Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum, serde::Serialize, serde::Deserialize,
)]
#[serde(rename_all = "lowercase")]
pub enum Eye {
    /// The midpoint of the pupils: the scene's driver camera.
    Cyclopean,
    Left,
    Right,
}

impl Eye {
    /// −1, 0 or +1: the side along the driver's right axis.
    pub fn side(self) -> f64 {
        match self {
            Eye::Cyclopean => 0.0,
            Eye::Left => -1.0,
            Eye::Right => 1.0,
        }
    }
}

/// The eyes a run looks with (`eyes`).
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum Viewing {
    /// The scene's driver camera, the cyclopean eye.
    Mono,
    /// The left eye, ipd/2 left of the cyclopean eye.
    Left,
    /// The right eye.
    Right,
    /// Each eye in turn (`seethru run`: into OUT/left and OUT/right, with the binocular
    /// mismatch into OUT).
    Both,
}

impl Viewing {
    /// The eye a single run views from (`both` starts from the cyclopean eye and runs each).
    pub fn view(self) -> Eye {
        match self {
            Viewing::Left => Eye::Left,
            Viewing::Right => Eye::Right,
            Viewing::Mono | Viewing::Both => Eye::Cyclopean,
        }
    }
}

/// Which eye looks and which eye the compensation serves.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Eyes {
    /// The eye the driver views (truth, occluded, seethru) are rendered from.
    pub view: Eye,
    /// The eye the compensation serves (oracle: its true position; estimated: the detected
    /// midpoint moved by ipd / 2 along the display's x axis).
    pub target: Eye,
    /// Interpupillary distance, metres, in (0, [`MAX_IPD`]].
    pub ipd: f64,
}

impl Default for Eyes {
    fn default() -> Self {
        Eyes {
            view: Eye::Cyclopean,
            target: Eye::Cyclopean,
            ipd: 0.064,
        }
    }
}

impl Eyes {
    /// World position of `eye` of the driver whose cyclopean camera is `driver`.
    pub fn position(&self, driver: &Camera, eye: Eye) -> DVec3 {
        driver.position() + driver.world_from_camera.matrix3.x_axis * (eye.side() * self.ipd / 2.0)
    }

    /// The driver camera moved to the viewing eye (itself for the cyclopean eye).
    pub fn view_camera(&self, driver: &Camera) -> Camera {
        let mut camera = *driver;
        if self.view != Eye::Cyclopean {
            camera.world_from_camera.translation = self.position(driver, self.view);
        }
        camera
    }

    /// The target eye from an estimate of the cyclopean eye: moved along the display's x.
    pub fn target_from_estimate(&self, cyclopean: DVec3, obstacle: &Obstacle) -> DVec3 {
        cyclopean
            + obstacle.world_from_obstacle.matrix3.x_axis * (self.target.side() * self.ipd / 2.0)
    }

    pub fn check(&self) -> Result<(), String> {
        if !(self.ipd > 0.0 && self.ipd <= MAX_IPD) {
            return Err(format!(
                "option `ipd` must be in (0, {MAX_IPD}] m, got {}",
                self.ipd
            ));
        }
        Ok(())
    }
}
