//! The back camera's head tracking over a sequence: each head sample renders and searches
//! only around the last face, falling back to the whole image. Apart from the loop
//! (system/sequence/system_loop.rs), which asks it for a detection per head sample: what it
//! renders and why its estimates equal the whole image's are its own.

use anyhow::Result;

use crate::geometry::camera::Camera;
use crate::render::footprint::PixelRect;
use crate::render::frame::Frame;
use crate::scene::DriverFace;
use crate::system::head::{DetectError, FaceDetection, detect_in};
use crate::system::head_estimate::{detect_face, turned_reads};

/// The back camera's image of the head, rendered only where the face can be: the pixels the
/// last detection depended on ([`detect_in`] reports them for the ellipsoid face; for the mesh
/// face [`turned_reads`] bounds what [`detect_face`] reads, and the pixels outside the region
/// are blanked), grown by a quarter of their size and 4 px on each side for the head's motion
/// until the next sample. When the face is not found there whole, or on the first sample, the
/// whole image is rendered and searched, as [`crate::system::head::detect`] does. So every
/// estimate is bit for bit the whole image's (but for a skin region larger than the face
/// wholly outside the region, which the whole image's detector would take for the face), and
/// each sample depends only on the one before: deterministic.
#[derive(Default)]
pub(crate) struct BackTracker {
    frame: Frame,
    pub(crate) region: Option<PixelRect>,
}

impl BackTracker {
    pub(crate) fn new(back: &Camera) -> BackTracker {
        BackTracker {
            frame: Frame::new(back.width, back.height),
            region: None,
        }
    }

    /// The head detection of `face` in the image of the true back camera `back` that
    /// `render` renders (the pixels of a region into a frame of the camera's size), and the
    /// pixels rendered for it.
    pub(crate) fn detect(
        &mut self,
        back: &Camera,
        face: DriverFace,
        render: &mut dyn FnMut(&mut Frame, PixelRect) -> Result<()>,
    ) -> Result<(Result<FaceDetection, DetectError>, u64)> {
        let back = *back;
        if (self.frame.width, self.frame.height) != (back.width, back.height) {
            self.frame = Frame::new(back.width, back.height);
            self.region = None;
        }
        // The detection in `region` and the pixels it depended on, if they lie inside it.
        let find = |frame: &mut Frame, region: PixelRect| match face {
            DriverFace::Ellipsoids => {
                detect_in(frame, region).map(|found| (found.detection, found.used, found.whole))
            }
            DriverFace::Mesh { .. } => {
                // Only the region's pixels: the rest blank (no skin, no colour step).
                blank_outside(frame, region);
                detect_face(face, frame).map(|d| {
                    let used = turned_reads(&d, &back);
                    (d, used, contains(region, used))
                })
            }
        };
        let mut pixels = 0;
        let mut tracked = None;
        if let Some(region) = self.region {
            render(&mut self.frame, region)?;
            pixels += region.pixels();
            tracked = find(&mut self.frame, region).ok().filter(|found| found.2);
        }
        let (detection, used) = match tracked {
            Some((detection, used, _)) => (detection, used),
            None => {
                self.region = None;
                let full = PixelRect::full(&back);
                render(&mut self.frame, full)?;
                pixels += full.pixels();
                match find(&mut self.frame, full) {
                    Ok((detection, used, _)) => (detection, used),
                    Err(e) => return Ok((Err(e), pixels)),
                }
            }
        };
        // The next search: the pixels used, grown by a quarter of their size and 4 px a side.
        self.region = Some(used.grown(4, 4, &back));
        Ok((Ok(detection), pixels))
    }
}

/// Sets the colour of every pixel outside `region` to black.
fn blank_outside(frame: &mut Frame, region: PixelRect) {
    let w = frame.width as usize;
    for (i, c) in frame.color.iter_mut().enumerate() {
        let (x, y) = ((i % w) as u32, (i / w) as u32);
        if x < region.x0 || x >= region.x1 || y < region.y0 || y >= region.y1 {
            *c = glam::Vec3::ZERO;
        }
    }
}

/// Whether `outer` holds every pixel of `inner`.
fn contains(outer: PixelRect, inner: PixelRect) -> bool {
    inner.x0 >= outer.x0 && inner.y0 >= outer.y0 && inner.x1 <= outer.x1 && inner.y1 <= outer.y1
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Every pixel outside the region is black, every pixel inside kept: each side's edge
    /// pixels on both sides of it.
    #[test]
    fn blanking_outside_a_region_keeps_exactly_the_region() {
        let mut frame = Frame::new(8, 6);
        frame.color.fill(glam::Vec3::ONE);
        let region = PixelRect {
            x0: 2,
            y0: 1,
            x1: 5,
            y1: 4,
        };
        blank_outside(&mut frame, region);
        for y in 0..6 {
            for x in 0..8 {
                let inside = (2..5).contains(&x) && (1..4).contains(&y);
                let expected = if inside {
                    glam::Vec3::ONE
                } else {
                    glam::Vec3::ZERO
                };
                assert_eq!(frame.color[frame.index(x, y)], expected, "({x}, {y})");
            }
        }
        assert!(contains(region, region));
        for (x0, y0, x1, y1) in [(1, 1, 4, 4), (2, 0, 5, 4), (2, 1, 6, 4), (2, 1, 5, 5)] {
            assert!(
                !contains(region, PixelRect { x0, y0, x1, y1 }),
                "{x0} {y0} {x1} {y1}"
            );
        }
    }
}
