//! The image metrics of `seethru` against the truth over the display's pixels: PSNR, SSIM and
//! FLIP on 8-bit sRGB. SSIM's windows and FLIP's filters see only the display's pixels (and
//! a shared surround), never what lies outside the display in either frame.

use crate::geometry::camera::Camera;
use crate::render::frame_over::FrameView;
use crate::util::color::{encode_srgb8, luma};

/// Whether the metrics (`measure_with`) compute FLIP, the costliest of their image metrics.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Flip {
    Computed,
    /// Every FLIP figure NaN (null in the JSON, which says so): a sequence's frames without
    /// `--flip`, where FLIP was a third of the metrics' time.
    Skipped,
}

impl Flip {
    /// FLIP computed when `asked` (a command's `--flip`), else skipped.
    pub fn asked(asked: bool) -> Flip {
        if asked { Flip::Computed } else { Flip::Skipped }
    }
}

/// The colours and image scores of the display pixels of the driver's view, one per pixel,
/// in the pixels' order.
pub(crate) struct DisplayImages<'a> {
    pub(crate) truth: Vec<[u8; 3]>,
    pub(crate) shown: Vec<[u8; 3]>,
    pub(crate) ssim: Vec<f64>,
    /// NaN where FLIP was skipped.
    pub(crate) flip: Vec<f64>,
    /// FLIP's observer: pixels per degree of the driver's camera.
    pub(crate) ppd: f32,
    bounds: DisplayBox<'a>,
}

impl<'a> DisplayImages<'a> {
    /// The scores of the pixels `on_display` (indices, in increasing order) of `seethru`
    /// against `truth`, frames of the `driver` camera.
    pub(crate) fn score(
        truth: FrameView<'_>,
        seethru: FrameView<'_>,
        on_display: &'a [usize],
        driver: &Camera,
        flip: Flip,
    ) -> DisplayImages<'a> {
        let w = truth.width() as usize;
        let count = on_display.len();
        // Colours of the display's pixels only.
        let srgb_t: Vec<[u8; 3]> = on_display
            .iter()
            .map(|&i| encode_srgb8(truth.get(|f| &f.color, i)))
            .collect();
        let srgb_s: Vec<[u8; 3]> = on_display
            .iter()
            .map(|&i| encode_srgb8(seethru.get(|f| &f.color, i)))
            .collect();
        // SSIM's windows and FLIP's filters see the display pixels in their bounding box, which
        // holds every pixel a window or filter of theirs would read.
        let bounds = DisplayBox::of(on_display, w);
        let lum = |srgb: &[[u8; 3]]| bounds.spread(srgb.iter().map(|&c| luma(c)), 0.0);
        // FLIP with the driver's eye as the observer: pixels per degree of the driver's camera.
        let ppd = w as f32 / (2.0 * driver.half_angle_x.to_degrees() as f32);
        // SSIM and FLIP side by side: FLIP (one thread's C++) was a third of the metrics' time.
        let (ssim, flip): (Vec<f64>, Vec<f64>) = rayon::join(
            || {
                let ssim_box = masked_ssim_map(
                    &lum(&srgb_t),
                    &lum(&srgb_s),
                    &bounds.mask(),
                    bounds.width,
                    bounds.height,
                );
                bounds.gather(&ssim_box)
            },
            || match flip {
                Flip::Computed if count > 0 => {
                    bounds.gather(&boxed_flip_map(&srgb_t, &srgb_s, &bounds, ppd))
                }
                _ => vec![f64::NAN; count],
            },
        );
        DisplayImages {
            truth: srgb_t,
            shown: srgb_s,
            ssim,
            flip,
            ppd,
            bounds,
        }
    }

    /// A frame of `len` pixels with `values` (one per display pixel, in order) at the display
    /// pixels, NaN elsewhere.
    pub(crate) fn scatter(&self, values: &[f64], len: usize) -> Vec<f64> {
        self.bounds.scatter(values, len)
    }
}

/// Pixels of a frame `frame_width` wide (indices in increasing order) and their bounding box:
/// SSIM's masked windows read nothing outside it, so its map over the box is its map over the
/// frame there; FLIP is taken over the box itself.
struct DisplayBox<'a> {
    pixels: &'a [usize],
    frame_width: usize,
    /// The box's first column and row in the frame, and its size, pixels (0 × 0 without pixels).
    x0: usize,
    y0: usize,
    width: usize,
    height: usize,
}

impl<'a> DisplayBox<'a> {
    fn of(pixels: &'a [usize], frame_width: usize) -> DisplayBox<'a> {
        let (Some(&first), Some(&last)) = (pixels.first(), pixels.last()) else {
            return DisplayBox {
                pixels,
                frame_width,
                x0: 0,
                y0: 0,
                width: 0,
                height: 0,
            };
        };
        let (x0, x1) = pixels.iter().fold((usize::MAX, 0), |(x0, x1), &i| {
            (x0.min(i % frame_width), x1.max(i % frame_width + 1))
        });
        let (y0, y1) = (first / frame_width, last / frame_width + 1);
        DisplayBox {
            pixels,
            frame_width,
            x0,
            y0,
            width: x1 - x0,
            height: y1 - y0,
        }
    }

    /// The box's index of the frame's pixel `i` (one of the box's pixels).
    fn in_box(&self, i: usize) -> usize {
        (i / self.frame_width - self.y0) * self.width + i % self.frame_width - self.x0
    }

    /// A box-sized image: `values` (one per pixel, in order) at the pixels, `fill` elsewhere.
    fn spread<T: Copy>(&self, values: impl Iterator<Item = T>, fill: T) -> Vec<T> {
        let mut out = vec![fill; self.width * self.height];
        for (&i, v) in self.pixels.iter().zip(values) {
            out[self.in_box(i)] = v;
        }
        out
    }

    /// Which pixels of the box are the pixels.
    fn mask(&self) -> Vec<bool> {
        self.spread(std::iter::repeat(true), false)
    }

    /// A box-sized image's values at the pixels, in order.
    fn gather<T: Copy>(&self, boxed: &[T]) -> Vec<T> {
        self.pixels.iter().map(|&i| boxed[self.in_box(i)]).collect()
    }

    /// A frame of `len` pixels with `values` (one per pixel, in order) at the pixels, NaN
    /// elsewhere.
    fn scatter(&self, values: &[f64], len: usize) -> Vec<f64> {
        let mut out = vec![f64::NAN; len];
        for (&i, &v) in self.pixels.iter().zip(values) {
            out[i] = v;
        }
        out
    }
}

/// SSIM map on 8-bit luminance with 7×7 windows (Wang et al. 2004 constants) that see only
/// pixels of `mask`: near the mask's edge a window averages over its pixels inside the mask,
/// so nothing outside the mask reaches any score. NaN outside the mask.
pub fn masked_ssim_map(a: &[f64], b: &[f64], mask: &[bool], w: usize, h: usize) -> Vec<f64> {
    use rayon::prelude::*;
    let (c1, c2) = ((0.01f64 * 255.0).powi(2), (0.03f64 * 255.0).powi(2));
    let r = 3i64;
    let mut out = vec![f64::NAN; w * h];
    let inside: Vec<usize> = (0..w * h).filter(|&i| mask[i]).collect();
    // Each pixel's window on its own, in parallel: the same map for any number of threads.
    let score = |i: usize| {
        let (x, y) = ((i % w) as i64, (i / w) as i64);
        let (mut sa, mut sb, mut saa, mut sbb, mut sab, mut n) = (0.0, 0.0, 0.0, 0.0, 0.0, 0.0);
        for yy in (y - r).max(0)..=(y + r).min(h as i64 - 1) {
            for xx in (x - r).max(0)..=(x + r).min(w as i64 - 1) {
                let j = yy as usize * w + xx as usize;
                if !mask[j] {
                    continue;
                }
                let (va, vb) = (a[j], b[j]);
                sa += va;
                sb += vb;
                saa += va * va;
                sbb += vb * vb;
                sab += va * vb;
                n += 1.0;
            }
        }
        let (ma, mb) = (sa / n, sb / n);
        let (va, vb, cov) = (saa / n - ma * ma, sbb / n - mb * mb, sab / n - ma * mb);
        ((2.0 * ma * mb + c1) * (2.0 * cov + c2)) / ((ma * ma + mb * mb + c1) * (va + vb + c2))
    };
    let scores: Vec<f64> = inside.par_iter().map(|&i| score(i)).collect();
    for (&i, v) in inside.iter().zip(scores) {
        out[i] = v;
    }
    out
}

/// FLIP map (NVIDIA's ꟻLIP, via nv-flip) over the box of `bounds`, of its pixels' colours
/// `truth` and `shown` (one per pixel, in order), at `ppd` pixels per degree. FLIP filters each
/// image spatially before comparing, so a whole-frame FLIP lets what lies outside the display
/// leak into the display's border. Here both images are cut to the pixels' bounding box and
/// every other pixel of it is set to the same mid grey in both: the filters see the display's
/// content and a shared, featureless surround, never anything outside the display.
fn boxed_flip_map(truth: &[[u8; 3]], shown: &[[u8; 3]], bounds: &DisplayBox, ppd: f32) -> Vec<f64> {
    let cut = |colours: &[[u8; 3]]| -> Vec<u8> {
        bounds.spread(colours.iter().copied(), [128; 3]).concat()
    };
    let image = |colours| {
        nv_flip::FlipImageRgb8::with_data(bounds.width as u32, bounds.height as u32, &cut(colours))
    };
    nv_flip::flip(image(truth), image(shown), ppd)
        .to_vec()
        .into_iter()
        .map(f64::from)
        .collect()
}

/// PSNR (dB) of 8-bit sRGB colours over the pixels of `mask`.
pub fn psnr(a: &[[u8; 3]], b: &[[u8; 3]], mask: &[bool]) -> f64 {
    let pixels: Vec<usize> = (0..mask.len()).filter(|&i| mask[i]).collect();
    psnr_over(a, b, &pixels)
}

/// PSNR (dB) of 8-bit sRGB colours over the pixels `pixels` (indices, summed in this order).
pub(crate) fn psnr_over(a: &[[u8; 3]], b: &[[u8; 3]], pixels: &[usize]) -> f64 {
    let (mut sum, mut n) = (0.0, 0usize);
    for &i in pixels {
        let (x, y) = (a[i], b[i]);
        for c in 0..3 {
            sum += (x[c] as f64 - y[c] as f64).powi(2);
        }
        n += 3;
    }
    if n == 0 {
        return f64::NAN;
    }
    let mse = sum / n as f64;
    if mse == 0.0 {
        f64::INFINITY
    } else {
        10.0 * (255.0 * 255.0 / mse).log10()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_box_of_display_pixels() {
        let corners = |b: DisplayBox| (b.x0, b.y0, b.x0 + b.width, b.y0 + b.height);
        assert_eq!(corners(DisplayBox::of(&[], 5)), (0, 0, 0, 0));
        assert_eq!(
            corners(DisplayBox::of(&[5 + 1, 2 * 5 + 3], 5)),
            (1, 1, 4, 3)
        );
        // The first pixel in index order is the rightmost and the bottom row's only one is the
        // leftmost: the box spans both.
        assert_eq!(
            corners(DisplayBox::of(&[5 + 3, 2 * 5 + 1], 5)),
            (1, 1, 4, 3)
        );
        assert_eq!(corners(DisplayBox::of(&[2 * 5 + 2], 5)), (2, 2, 3, 3));
    }

    #[test]
    fn a_box_spreads_gathers_and_scatters_its_pixels_in_place() {
        // Pixels (3, 1), (1, 2) and (2, 2) of a 5 × 4 frame: a box 3 wide and 2 high at (1, 1).
        let pixels = [5 + 3, 2 * 5 + 1, 2 * 5 + 2];
        let b = DisplayBox::of(&pixels, 5);
        let boxed = b.spread([1.0, 2.0, 3.0].into_iter(), 0.0);
        assert_eq!(boxed, vec![0.0, 0.0, 1.0, 2.0, 3.0, 0.0]);
        assert_eq!(b.mask(), vec![false, false, true, true, true, false]);
        assert_eq!(b.gather(&boxed), vec![1.0, 2.0, 3.0]);
        let frame = b.scatter(&[1.0, 2.0, 3.0], 20);
        let set: Vec<(usize, f64)> = (0..20)
            .filter(|&i| !frame[i].is_nan())
            .map(|i| (i, frame[i]))
            .collect();
        assert_eq!(set, vec![(8, 1.0), (11, 2.0), (12, 3.0)]);
    }
}
