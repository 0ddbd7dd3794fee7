//! A frame rendered over another: the pixels of a rectangle rendered anew, the rest shared
//! with the other frame instead of copied.
//!
//! `run`'s `occluded` and `seethru` views are its `truth` outside the obstacle's footprint (an
//! eighth of das's pixels): a copy of truth for each was 96 MB of fresh pages to fault in,
//! fill and unmap, a twentieth of a run's time. Readers that go row by row or pixel by pixel
//! read a [`FrameView`]; the whole [`Frame`] is made on first asking ([`FrameOver::whole`]).

use std::ops::Deref;
use std::sync::{Arc, OnceLock};

use crate::render::footprint::PixelRect;
use crate::render::frame::Frame;

/// `base` outside `rect`, `patch` inside it.
#[derive(Debug)]
pub struct FrameOver {
    /// The frame this one is outside `rect`.
    base: Arc<Frame>,
    /// The rendered rectangle, pixels of the image (x0..x1 columns, y0..y1 rows).
    rect: PixelRect,
    /// The rectangle's pixels: a frame of its size, its (0, 0) the image's (x0, y0).
    patch: Frame,
    /// The whole frame, made on first asking.
    whole: OnceLock<Frame>,
}

impl FrameOver {
    /// The frame that is `base` but inside `rect`, where it is `patch`.
    pub fn new(base: Arc<Frame>, rect: PixelRect, patch: Frame) -> FrameOver {
        assert!(rect.x0 <= rect.x1 && rect.x1 <= base.width);
        assert!(rect.y0 <= rect.y1 && rect.y1 <= base.height);
        assert_eq!(
            (patch.width, patch.height),
            (rect.x1 - rect.x0, rect.y1 - rect.y0)
        );
        FrameOver {
            base,
            rect,
            patch,
            whole: OnceLock::new(),
        }
    }

    pub fn base(&self) -> &Arc<Frame> {
        &self.base
    }

    pub fn rect(&self) -> PixelRect {
        self.rect
    }

    pub fn patch(&self) -> &Frame {
        &self.patch
    }

    /// The whole frame: made (a copy of the base with the patch in place) on the first call.
    pub fn whole(&self) -> &Frame {
        self.whole.get_or_init(|| {
            let mut whole = Frame::clone(&self.base);
            let (r, pw) = (self.rect, self.patch.width as usize);
            for y in r.y0..r.y1 {
                let from = (y - r.y0) as usize * pw;
                whole.copy_pixels(whole.index(r.x0, y), &self.patch, from, pw);
            }
            whole
        })
    }

    /// [`FrameOver::whole`], owned.
    pub fn into_whole(self) -> Frame {
        self.whole();
        self.whole.into_inner().expect("just made")
    }
}

/// Field access reads the whole frame ([`FrameOver::whole`]).
impl Deref for FrameOver {
    type Target = Frame;
    fn deref(&self) -> &Frame {
        self.whole()
    }
}

/// One AOV buffer of a frame, e.g. `|f| &f.depth`.
pub type Field<T> = for<'f> fn(&'f Frame) -> &'f [T];

/// A frame read row by row or pixel by pixel, whole or rendered over another.
#[derive(Clone, Copy, Debug)]
pub enum FrameView<'a> {
    Whole(&'a Frame),
    Over(&'a FrameOver),
}

impl<'a> From<&'a Frame> for FrameView<'a> {
    fn from(frame: &'a Frame) -> Self {
        FrameView::Whole(frame)
    }
}

impl<'a> From<&'a Arc<Frame>> for FrameView<'a> {
    fn from(frame: &'a Arc<Frame>) -> Self {
        FrameView::Whole(frame)
    }
}

impl<'a> From<&'a FrameOver> for FrameView<'a> {
    fn from(frame: &'a FrameOver) -> Self {
        FrameView::Over(frame)
    }
}

impl<'a> FrameView<'a> {
    /// The frame outside any patch.
    fn base(self) -> &'a Frame {
        match self {
            FrameView::Whole(f) => f,
            FrameView::Over(o) => &o.base,
        }
    }

    pub fn width(self) -> u32 {
        self.base().width
    }

    pub fn height(self) -> u32 {
        self.base().height
    }

    /// The whole frame (made on first asking for a frame rendered over another).
    pub fn whole(self) -> &'a Frame {
        match self {
            FrameView::Whole(f) => f,
            FrameView::Over(o) => o.whole(),
        }
    }

    /// `field` of image row `y`: the row is the three slices one after another (the base's
    /// left of the patch, the patch's, the base's right of it; empty where there is none).
    pub fn row<T>(self, field: Field<T>, y: u32) -> [&'a [T]; 3] {
        let base = self.base();
        let w = base.width as usize;
        let whole_row = &field(base)[y as usize * w..(y as usize + 1) * w];
        match self {
            FrameView::Over(o) if o.rect.y0 <= y && y < o.rect.y1 => {
                let (x0, x1) = (o.rect.x0 as usize, o.rect.x1 as usize);
                let pw = x1 - x0;
                let py = (y - o.rect.y0) as usize;
                [
                    &whole_row[..x0],
                    &field(&o.patch)[py * pw..(py + 1) * pw],
                    &whole_row[x1..],
                ]
            }
            _ => [whole_row, &[], &[]],
        }
    }

    /// `field` at pixel index `i` (row-major).
    pub fn get<T: Copy>(self, field: Field<T>, i: usize) -> T {
        match self {
            FrameView::Whole(f) => field(f)[i],
            FrameView::Over(o) => {
                let w = o.base.width as usize;
                let (x, y) = ((i % w) as u32, (i / w) as u32);
                let r = o.rect;
                if (r.x0..r.x1).contains(&x) && (r.y0..r.y1).contains(&y) {
                    field(&o.patch)[o.patch.index(x - r.x0, y - r.y0)]
                } else {
                    field(&o.base)[i]
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use glam::Vec3;

    use super::*;
    use crate::render::frame::Pixel;

    /// A `w`×`h` frame whose every buffer holds `seed` + the pixel index, so that each pixel
    /// of each buffer says where it came from.
    fn numbered(w: u32, h: u32, seed: u32) -> Frame {
        let mut f = Frame::new(w, h);
        for i in 0..(w * h) as usize {
            let v = (seed + i as u32) as f32;
            f.color[i] = Vec3::splat(v);
            f.depth[i] = v;
            f.camera_z[i] = v + 0.5;
            f.position[i] = Vec3::new(v, -v, 2.0 * v);
            f.normal[i] = Vec3::new(-v, v, 0.25 * v);
            f.object_id[i] = seed + i as u32;
            f.part_id[i] = 7 * (seed + i as u32);
        }
        f
    }

    /// The whole frame, each row read in three slices, and each pixel read alone agree with
    /// the base copied and overwritten pixel by pixel inside the rectangle.
    #[test]
    fn a_frame_over_another_reads_as_the_base_overwritten_inside_the_rectangle() {
        let (w, h) = (7, 5);
        let base = Arc::new(numbered(w, h, 0));
        let rect = |x0, y0, x1, y1| PixelRect { x0, y0, x1, y1 };
        for rect in [
            rect(2, 1, 5, 4),
            rect(0, 0, 7, 5),
            rect(0, 3, 1, 5),
            rect(6, 0, 7, 1),
            rect(3, 2, 3, 2),
        ] {
            let patch = numbered(rect.x1 - rect.x0, rect.y1 - rect.y0, 1000);
            let pixels: Vec<Pixel> = (0..w * h)
                .map(|i| {
                    let (x, y) = (i % w, i / w);
                    match (rect.x0..rect.x1).contains(&x) && (rect.y0..rect.y1).contains(&y) {
                        true => patch.pixel(x - rect.x0, y - rect.y0),
                        false => base.pixel(x, y),
                    }
                })
                .collect();
            let expected = Frame::from_pixels(w, h, &pixels);
            let over = FrameOver::new(base.clone(), rect, patch);
            let view = FrameView::Over(&over);
            assert_eq!((view.width(), view.height()), (w, h), "{rect:?}");
            for y in 0..h {
                let ids: Vec<u32> = view.row(|f| &f.object_id, y).concat();
                let row = expected.index(0, y)..expected.index(0, y + 1);
                assert_eq!(ids, expected.object_id[row.clone()], "{rect:?} row {y}");
                let normals: Vec<Vec3> = view.row(|f| &f.normal, y).concat();
                assert_eq!(normals, expected.normal[row], "{rect:?} row {y}");
            }
            for i in 0..(w * h) as usize {
                assert_eq!(view.get(|f| &f.part_id, i), expected.part_id[i]);
                assert_eq!(view.get(|f| &f.camera_z, i), expected.camera_z[i]);
            }
            assert!(over.whole().bit_identical(&expected), "{rect:?}");
            assert_eq!(over.depth, expected.depth, "through Deref");
            assert!(over.into_whole().bit_identical(&expected));
        }
    }

    /// A whole frame's view reads the frame itself.
    #[test]
    fn a_whole_frames_view_reads_the_frame() {
        let frame = numbered(4, 3, 5);
        let view = FrameView::from(&frame);
        assert_eq!((view.width(), view.height()), (4, 3));
        assert_eq!(view.row(|f| &f.depth, 2), [&frame.depth[8..12], &[], &[]]);
        assert_eq!(view.get(|f| &f.object_id, 6), 11);
        assert!(std::ptr::eq(view.whole(), &frame));
    }
}
