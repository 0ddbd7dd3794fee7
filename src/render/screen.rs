//! What a display shows where the `seethru` view's rays meet it. The see-through system
//! decides the content (`system::display`); the renderer only asks.

use glam::Vec3;

use crate::render::frame::Pixel;

/// The display content at a world point on the display face.
pub enum Shown {
    /// A finished pixel (colour and AOVs).
    Pixel(Pixel),
    /// Trace this frontal-camera ray (origin, unit direction) to find it.
    FrontalRay(Vec3, Vec3),
}

/// A display face that the renderer looks up per ray.
pub trait Screen: Sync {
    /// What the display shows at `world`, a point on its face (world frame, metres).
    fn shown_at(&self, world: Vec3) -> Shown;
}
