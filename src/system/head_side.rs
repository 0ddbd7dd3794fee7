//! The side-angle pupil detector for the head mesh (`scene/head_model.rs`), as a pillar
//! camera sees it (the head turned up to about ±45° from facing it), with the same shape as
//! `system/head.rs`'s frontal `detect`. Its brows, hair and shadows are dark blobs too, so a
//! pupil is a dark, iris-sized blob with sclera beside it (bright, unsaturated pixels within
//! 0.08 face widths); blobs a lid's shadow split are merged, and the pair kept is the most
//! level one with the largest and best-framed blobs. Shadowed skin is greyish under a blue sky and not told from a grey
//! road by colour, so the head's outline is not segmented here: the colour steps beyond each
//! pupil along the pupils' line whose outer side is not skin are kept as candidates, and the
//! pose fit (`system/head_pose.rs`) picks the pair its head model explains.

use glam::{DVec2, Vec3};

use crate::render::frame::Frame;
use crate::system::head::{
    DetectError, FaceDetection, FaceRegion, HeadConfidence, OUTLINE_CANDIDATES, Rect, dark_mask,
    face_region, inner_blobs, is_skin, luminance, pupil_centroid,
};
use crate::system::head_confidence::IRIS_OVER_FACE;
use crate::util::color::{encode_srgb8, encode_srgb8_by_transfer};

/// Sclera: luminance over 0.45 × the face's, blue and green each over 0.8 × red (bright and nearly grey; the skin is red over blue by ~2 in sRGB).
fn is_white([r, g, b]: [u8; 3], face_lum: f32) -> bool {
    let l = luminance([r, g, b]);
    l > 0.45 * face_lum && (b as f32) > 0.8 * r as f32 && (g as f32) > 0.8 * r as f32
}

/// Blobs closer than this many face widths are one eye split by a lid's shadow.
const MERGE: f64 = 0.05;

/// A dark blob that may be a pupil (with its iris).
struct Candidate {
    /// Centroid, pixels.
    centre: DVec2,
    /// Pixels in the blob.
    area: usize,
    /// Sclera pixels within 0.08 face widths of the centre.
    whites: usize,
    /// The blob's pixel indices.
    pixels: Vec<usize>,
}

/// The face (the largest skin region, neck included), the two pupils and the outline's
/// candidates of a colour frame (8-bit sRGB as a camera delivers it).
///
/// Only the pixels the detection reads are encoded to sRGB ([`encode_srgb8`]): those whose linear colour could be skin (red over green over
/// blue), the pupil search box and the samples of the outline's scan;
/// [`detect_turned_reference`], which encodes every pixel, is its brute-force twin.
pub fn detect_turned(frame: &Frame) -> Result<FaceDetection, DetectError> {
    detect_turned_from(frame, false)
}

/// [`detect_turned`] encoding every pixel of the frame first, with the transfer function
/// itself rather than its table (the brute-force twin of its sparse reading; the same
/// detection bit for bit).
#[doc(hidden)]
pub fn detect_turned_reference(frame: &Frame) -> Result<FaceDetection, DetectError> {
    detect_turned_from(frame, true)
}

/// Whether a linear colour can encode to skin: [`is_skin`] needs r > g > b in 8-bit sRGB,
/// which a 0.1% smaller linear channel cannot give (the encoding is monotone).
fn may_be_skin(c: Vec3) -> bool {
    !(c.x <= 0.999 * c.y || c.y <= 0.999 * c.z)
}

fn detect_turned_from(frame: &Frame, encode_all: bool) -> Result<FaceDetection, DetectError> {
    let (w, h) = (frame.width as usize, frame.height as usize);
    let encode = if encode_all {
        encode_srgb8_by_transfer
    } else {
        encode_srgb8
    };
    let mut rgb: Vec<[u8; 3]> = vec![[0; 3]; w * h];
    let mut skin: Vec<bool> = vec![false; w * h];
    for (i, &c) in frame.color.iter().enumerate() {
        if encode_all || may_be_skin(c) {
            rgb[i] = encode(c);
            skin[i] = is_skin(rgb[i]);
        }
    }
    let FaceRegion {
        face_box,
        face_lum,
        search,
        mut dark,
        ..
    } = face_region(&rgb, &skin, w, h, Rect::whole(w, h))?;
    let face_w = f64::from(face_box[2] - face_box[0]);
    let radius = (0.08 * face_w).max(2.5);
    if !encode_all {
        // Everything below reads the search box and, beyond it, at most the sclera disc's
        // radius (a blob one pixel inside the box) or 3 px (the centroids' rings); the
        // outline's scan encodes its own samples.
        let [x0, y0, x1, y1] = search;
        let grow = radius.ceil() as usize + 4;
        for y in y0.saturating_sub(grow)..(y1 + grow).min(h) {
            let row = y * w + x0.saturating_sub(grow)..y * w + (x1 + grow).min(w);
            for (out, &c) in rgb[row.clone()].iter_mut().zip(&frame.color[row]) {
                *out = encode(c);
            }
        }
        dark = dark_mask(&rgb, w, search, face_lum);
    }
    let iris_max = ((0.15 * face_w).powi(2) as usize).max(4);
    let mut candidates: Vec<Candidate> = inner_blobs(&dark, search, w, iris_max)
        .into_iter()
        .map(|pixels| {
            let centre = pixels.iter().fold(DVec2::ZERO, |a, &i| {
                a + DVec2::new((i % w) as f64 + 0.5, (i / w) as f64 + 0.5)
            }) / pixels.len() as f64;
            let r = radius.ceil() as i64;
            let mut whites = 0;
            for dy in -r..=r {
                for dx in -r..=r {
                    let (x, y) = (centre.x as i64 + dx, centre.y as i64 + dy);
                    if (dx * dx + dy * dy) as f64 <= radius * radius
                        && x >= 0
                        && y >= 0
                        && (x as usize) < w
                        && (y as usize) < h
                    {
                        whites += usize::from(is_white(rgb[y as usize * w + x as usize], face_lum));
                    }
                }
            }
            Candidate {
                centre,
                area: pixels.len(),
                whites,
                pixels,
            }
        })
        // An eye has sclera beside it.
        .filter(|c| c.whites > 0)
        .collect();
    // A blob split by a lid's shadow is one eye: blobs closer than an iris are merged.
    candidates.sort_by_key(|c| std::cmp::Reverse(c.area));
    let mut merged: Vec<Candidate> = Vec::new();
    for c in candidates {
        match merged
            .iter_mut()
            .find(|m| (m.centre - c.centre).length() < MERGE * face_w)
        {
            Some(m) => {
                let total = (m.area + c.area) as f64;
                m.centre = (m.centre * m.area as f64 + c.centre * c.area as f64) / total;
                m.area += c.area;
                m.whites = m.whites.max(c.whites);
                m.pixels.extend(c.pixels);
            }
            None => merged.push(c),
        }
    }
    let candidates = merged;
    let pool: Vec<&Candidate> = candidates.iter().collect();
    let mut best = (f64::NEG_INFINITY, 0, 1);
    for a in 0..pool.len() {
        for b in a + 1..pool.len() {
            let d = pool[b].centre - pool[a].centre;
            if d.length() < 0.1 * face_w || d.length() > 0.8 * face_w {
                continue;
            }
            let tilt = d.y.abs() / d.x.abs().max(1e-9);
            // A head rolled more than 31° against the camera is not a driver's.
            if tilt > 0.6 {
                continue;
            }
            let score = (pool[a].area.min(pool[b].area) as f64).sqrt()
                * ((pool[a].whites.min(pool[b].whites) + 1) as f64).sqrt()
                / (1.0 + 8.0 * tilt);
            if score > best.0 {
                best = (score, a, b);
            }
        }
    }
    if best.0 == f64::NEG_INFINITY {
        return Err(DetectError::Pupils(pool.len().min(1)));
    }
    // An iris is 12 mm of a 150 mm face: a blob much larger than one is an iris merged with
    // a lid's or the socket's shadow, and is cut down to the iris-sized disc around its
    // darkest part.
    let iris_radius = IRIS_OVER_FACE * face_w;
    let holes = [best.1, best.2].map(|k| iris_core(&pool[k].pixels, &rgb, w, iris_radius));
    let (a, b) = (
        pupil_centroid(&rgb, w, h, &holes[0], face_lum),
        pupil_centroid(&rgb, w, h, &holes[1], face_lum),
    );
    let areas = [holes[0].len() as u32, holes[1].len() as u32];
    let (pupils, pupil_areas_px) = if a.x <= b.x {
        ([a, b], areas)
    } else {
        ([b, a], [areas[1], areas[0]])
    };
    let baseline = (b - a).length();
    let candidates = edge_candidates(frame, encode, &skin, pupils, baseline, face_w);
    let mut outline_candidates = [[[f64::NAN; 2]; OUTLINE_CANDIDATES]; 2];
    for (side, list) in candidates.iter().enumerate() {
        for (slot, p) in outline_candidates[side].iter_mut().zip(list) {
            *slot = p.to_array();
        }
    }
    Ok(FaceDetection {
        face_box,
        pupils: pupils.map(|p| p.to_array()),
        pupil_areas_px,
        // The outline's nearest candidates stand in for the frontal detector's row edges.
        row_edges: [0, 1].map(|k| candidates[k].first().unwrap_or(&pupils[k]).to_array()),
        outline_candidates,
        confidence: HeadConfidence::of(face_box, pupils, pupil_areas_px),
    })
}

/// The pixels of a dark blob that are its iris: the whole blob when it is no larger than
/// 1.6 iris discs (`iris_radius`, pixels); otherwise those within 1.25 iris radii of the
/// blob pixel whose surrounding half-iris disc (of blob pixels) is darkest on average, the
/// iris and pupil being far darker than a shadow on skin.
fn iris_core(pixels: &[usize], rgb: &[[u8; 3]], w: usize, iris_radius: f64) -> Vec<usize> {
    let disc = std::f64::consts::PI * iris_radius * iris_radius;
    if (pixels.len() as f64) <= 1.6 * disc {
        return pixels.to_vec();
    }
    let at = |i: usize| DVec2::new((i % w) as f64, (i / w) as f64);
    let near = |c: DVec2, r: f64| {
        pixels
            .iter()
            .copied()
            .filter(move |&i| (at(i) - c).length_squared() <= r * r)
    };
    let mut darkest = (f32::INFINITY, pixels[0]);
    for &i in pixels {
        let (sum, n) = near(at(i), 0.5 * iris_radius)
            .fold((0.0, 0), |(s, n), j| (s + luminance(rgb[j]), n + 1));
        let mean = sum / n as f32;
        if mean < darkest.0 {
            darkest = (mean, i);
        }
    }
    near(at(darkest.1), 1.25 * iris_radius).collect()
}

/// Where the colour steps along the pupils' line beyond each pupil (outward, up to 1.2 face
/// widths, past the iris): the head's outline is one of them; the fit picks which.
fn edge_candidates(
    frame: &Frame,
    encode: fn(Vec3) -> [u8; 3],
    skin: &[bool],
    pupils: [DVec2; 2],
    baseline: f64,
    face_w: f64,
) -> [Vec<DVec2>; 2] {
    let (w, h) = (frame.width as usize, frame.height as usize);
    let along = (pupils[1] - pupils[0]).normalize_or(DVec2::X);
    let at = |p: DVec2| -> Option<[f32; 3]> {
        (p.x >= 0.0 && p.y >= 0.0 && (p.x as usize) < w && (p.y as usize) < h).then(|| {
            let c = encode(frame.color[p.y as usize * w + p.x as usize]);
            [c[0] as f32, c[1] as f32, c[2] as f32]
        })
    };
    let side = |from: DVec2, direction: DVec2| {
        let step = 0.5;
        let n = (1.2 * face_w / step) as usize;
        let start = (0.12 * baseline / step) as usize;
        let strength: Vec<f32> = (0..n)
            .map(|k| {
                let s = k as f64 * step;
                match (
                    at(from + direction * (s + 1.0)),
                    at(from + direction * (s - 1.0)),
                ) {
                    (Some(p), Some(q)) => (0..3).map(|c| (p[c] - q[c]).abs()).sum(),
                    _ => 0.0,
                }
            })
            .collect();
        let mut out = Vec::new();
        for k in start.max(1)..n.saturating_sub(1) {
            let outside = from + direction * (k as f64 * step + 1.5);
            let skin_outside = outside.x >= 0.0
                && outside.y >= 0.0
                && (outside.x as usize) < w
                && (outside.y as usize) < h
                && skin[outside.y as usize * w + outside.x as usize];
            // A step: the summed |ΔRGB| across 2 px at least 60 levels, a local maximum.
            if !skin_outside
                && strength[k] >= 60.0
                && strength[k] >= strength[k - 1]
                && strength[k] > strength[k + 1]
            {
                out.push(from + direction * (k as f64 * step));
            }
        }
        out
    };
    [side(pupils[0], -along), side(pupils[1], along)]
}

#[cfg(test)]
mod tests {
    //! Synthetic frames of flat colours painted as 8-bit sRGB codes (decoded to linear light,
    //! so that the detector's encoding gives the codes back), with every blob point-symmetric
    //! about a pixel centre so that its centroid, and the pupil weighed from it, is exactly
    //! there. The face is a 100 × 80 px skin rectangle, 100 px wide: the sclera is counted
    //! within 0.08 × 100 = 8 px of a blob, blobs closer than 5 px are one eye, a pair is 10 to
    //! 80 px apart, a dark blob is at most 15² = 225 px, and an iris's radius is 4 px.

    use super::*;
    use crate::util::color::decode_srgb8;

    /// Skin (`is_skin`), luminance 158.5: dark is under 47.5, sclera over 71.3.
    const SKIN: [u8; 3] = [200, 150, 120];
    /// Not skin (green = blue), not sclera (blue under 0.8 red), not dark (luminance 79).
    const BACKGROUND: [u8; 3] = [150, 60, 60];
    /// Bluish white: not `may_be_skin` (a grey is, within its 0.1 % margin), so the sparse
    /// reading encodes it only around the search box.
    const SCLERA: [u8; 3] = [225, 230, 235];
    /// Dark (luminance 31) and bluish, so not skin.
    const IRIS: [u8; 3] = [30, 30, 40];
    const W: usize = 160;
    const H: usize = 120;
    /// The face's skin rectangle, [x0, y0, x1, y1).
    const FACE: [usize; 4] = [30, 20, 130, 100];

    struct Canvas {
        w: usize,
        h: usize,
        px: Vec<[u8; 3]>,
    }

    impl Canvas {
        fn new(w: usize, h: usize) -> Canvas {
            Canvas {
                w,
                h,
                px: vec![BACKGROUND; w * h],
            }
        }

        /// The background with the face's skin rectangle.
        fn face() -> Canvas {
            let mut c = Canvas::new(W, H);
            c.rect(FACE, SKIN);
            c
        }

        fn set(&mut self, x: i64, y: i64, colour: [u8; 3]) {
            assert!(x >= 0 && y >= 0 && (x as usize) < self.w && (y as usize) < self.h);
            self.px[y as usize * self.w + x as usize] = colour;
        }

        /// Pixels [x0, x1) × [y0, y1).
        fn rect(&mut self, [x0, y0, x1, y1]: [usize; 4], colour: [u8; 3]) {
            for y in y0..y1 {
                for x in x0..x1 {
                    self.set(x as i64, y as i64, colour);
                }
            }
        }

        /// The pixels (x + dx, y + dy) with dx² + dy² ≤ r2, coloured by dx² + dy².
        fn disc(&mut self, (x, y): (i64, i64), r2: i64, colour: impl Fn(i64) -> [u8; 3]) {
            let r = (r2 as f64).sqrt() as i64;
            for dy in -r..=r {
                for dx in -r..=r {
                    if dx * dx + dy * dy <= r2 {
                        self.set(x + dx, y + dy, colour(dx * dx + dy * dy));
                    }
                }
            }
        }

        /// Eyes at these pixels: a 15 × 7 px sclera each, then an iris disc of radius 3
        /// (29 px) each.
        fn eyes(&mut self, at: &[(i64, i64)]) {
            for &(x, y) in at {
                self.rect([x - 7, y - 3, x + 8, y + 4].map(|v| v as usize), SCLERA);
            }
            for &(x, y) in at {
                self.disc((x, y), 9, |_| IRIS);
            }
        }

        fn frame(&self) -> Frame {
            let mut frame = Frame::new(self.w as u32, self.h as u32);
            for (out, &code) in frame.color.iter_mut().zip(&self.px) {
                *out = Vec3::from(code.map(decode_srgb8));
                assert_eq!(encode_srgb8(*out), code);
            }
            frame
        }
    }

    /// The centre of pixel (x, y).
    fn centre((x, y): (i64, i64)) -> [f64; 2] {
        [x as f64 + 0.5, y as f64 + 0.5]
    }

    /// `detect_turned` of the canvas, after checking that its brute-force twin (every pixel
    /// encoded by the transfer function) finds the same, bit for bit.
    fn detect(c: &Canvas) -> Result<FaceDetection, DetectError> {
        let frame = c.frame();
        let sparse = detect_turned(&frame);
        assert_eq!(
            sparse,
            detect_turned_reference(&frame),
            "the sparse reading"
        );
        sparse
    }

    /// The detection's pupils, each within `tolerance` px of the expected one (left first).
    fn assert_pupils(
        d: &Result<FaceDetection, DetectError>,
        expected: [[f64; 2]; 2],
        tolerance: f64,
    ) {
        let d = d.as_ref().expect("a detection");
        for (got, want) in d.pupils.iter().zip(expected) {
            let off = DVec2::from(*got) - DVec2::from(want);
            assert!(
                off.length() <= tolerance,
                "pupils {:?}, expected {expected:?}",
                d.pupils
            );
        }
    }

    /// Sclera is a pixel brighter than 0.45 × the face's luminance whose blue and green each
    /// exceed 0.8 × its red (nearly grey: skin's blue is about 0.6 of its red). Each
    /// threshold is strict: a pixel exactly at one is not sclera, one a code or an ulp past it
    /// is.
    #[test]
    fn a_pixel_is_sclera_only_past_each_threshold() {
        // 0.8 × 100 is 80 exactly in f32.
        assert!(is_white([100, 100, 100], 50.0));
        assert!(!is_white([100, 100, 80], 50.0) && is_white([100, 100, 81], 50.0));
        assert!(!is_white([100, 80, 100], 50.0) && is_white([100, 81, 100], 50.0));
        // A green or a blue well under 0.8 × red, however bright: a magenta, a yellow, skin.
        assert!(!is_white([200, 140, 200], 10.0));
        assert!(!is_white([200, 200, 140], 10.0));
        assert!(!is_white(SKIN, 10.0));
        // Brightness: the face luminance whose 0.45 is exactly the pixel's luminance (found
        // among the f32 values next to l / 0.45).
        let grey = [100, 100, 100];
        let l = luminance(grey);
        let guess = (l / 0.45).to_bits();
        let at = (guess - 4..=guess + 4)
            .map(f32::from_bits)
            .find(|&f| 0.45 * f == l)
            .expect("a face luminance whose 0.45 is l");
        assert!(!is_white(grey, at), "exactly at 0.45 × the face's");
        let dimmer_face = f32::from_bits(at.to_bits() - 1);
        assert!(0.45 * dimmer_face < l && is_white(grey, dimmer_face));
    }

    /// `may_be_skin` rules a linear colour out only when its encoding cannot be skin: every
    /// colour of a grid whose 8-bit encoding is skin passes it, and colours whose red is well
    /// under their green, or green under blue (a green, a sky blue, a violet; their codes
    /// have red ≤ green or green ≤ blue), are ruled out, so that the sparse detector need not
    /// encode them.
    #[test]
    fn only_colours_that_may_encode_to_skin_may_be_skin() {
        let levels: Vec<f32> = (0..=48).map(|k| (k as f32 / 48.0).powi(2)).collect();
        let mut skins = 0;
        for &r in &levels {
            for &g in &levels {
                for &b in &levels {
                    let c = Vec3::new(r, g, b);
                    if is_skin(encode_srgb8(c)) {
                        skins += 1;
                        assert!(may_be_skin(c), "{c}");
                    }
                }
            }
        }
        assert!(skins > 100, "{skins} skin colours in the grid");
        for c in [
            Vec3::new(0.1, 0.5, 0.05),
            Vec3::new(0.2, 0.4, 0.8),
            Vec3::new(0.4, 0.1, 0.6),
        ] {
            let [r, g, b] = encode_srgb8(c);
            assert!(r <= g || g <= b);
            assert!(!may_be_skin(c), "{c}");
        }
    }

    /// Two eyes level and 40 px apart: the pupils are the iris discs' centres, their areas
    /// the discs' 29 px, and the face box is the skin rectangle (the search box reaches the
    /// frame's top row).
    #[test]
    fn the_pupils_are_the_iris_discs_centres() {
        let mut c = Canvas::face();
        c.eyes(&[(60, 50), (100, 50)]);
        let d = detect(&c);
        assert_pupils(&d, [centre((60, 50)), centre((100, 50))], 1e-9);
        let d = d.unwrap();
        assert_eq!(d.pupil_areas_px, [29, 29]);
        assert_eq!(d.face_box, FACE.map(|v| v as u32));
    }

    /// A frame cut just below the eyes (the face running off its bottom edge): the eyes 5 px
    /// above that edge are found at their discs' centres, the sclera disc clipped at the edge.
    #[test]
    fn eyes_at_the_frames_bottom_edge_are_found() {
        let mut c = Canvas::new(W, H);
        c.rect([30, 40, 130, 120], SKIN);
        c.eyes(&[(60, 115), (100, 115)]);
        assert_pupils(&detect(&c), [centre((60, 115)), centre((100, 115))], 1e-9);
    }

    /// The far eye of a turned head lies beyond the cheek's skin: a 3 × 3 px pupil a pixel
    /// inside the search box (the face box grown by 12 px: x 18..142), whose only sclera lies
    /// 5 to 6 px outside the box but within 8 px of the pupil, on the left or on the right.
    /// It is found, the sparse reading encoding the sclera disc around a blob one pixel inside
    /// the box as its twin does.
    #[test]
    fn a_far_eye_at_the_search_boxs_edge_keeps_its_sclera_outside_it() {
        let mut c = Canvas::face();
        c.eyes(&[(60, 50)]);
        c.rect([19, 49, 22, 52], IRIS);
        c.rect([12, 49, 14, 52], SCLERA);
        assert_pupils(&detect(&c), [centre((20, 50)), centre((60, 50))], 1e-9);

        let mut c = Canvas::face();
        c.eyes(&[(100, 50)]);
        c.rect([138, 49, 141, 52], IRIS);
        c.rect([146, 49, 148, 52], SCLERA);
        assert_pupils(&detect(&c), [centre((100, 50)), centre((139, 50))], 1e-9);
    }

    /// A dark spot with no sclera within 0.08 face widths (a mole) is not a pupil: an eye and
    /// a mole at a pupil's distance leave one candidate and no pair. Also at the frame's right
    /// edge, where the columns of the sclera disc past the edge are not the next row's first
    /// pixels (a white column there, say a pillar's trim).
    #[test]
    fn a_dark_spot_without_sclera_is_not_a_pupil() {
        let mut c = Canvas::face();
        c.eyes(&[(60, 50)]);
        c.disc((100, 50), 2, |_| IRIS);
        assert_eq!(detect(&c), Err(DetectError::Pupils(1)));

        let mut c = Canvas::new(W, H);
        c.rect([60, 20, 160, 100], SKIN);
        c.rect([0, 0, 1, H], SCLERA);
        c.eyes(&[(110, 50)]);
        // A 2 × 2 mole a pixel inside the search box's right edge (x 157..=158).
        c.rect([157, 49, 159, 51], IRIS);
        assert_eq!(detect(&c), Err(DetectError::Pupils(1)));
    }

    /// The sclera is counted within 0.08 face widths (8 px) of a blob's centroid, the rim
    /// included: eyes whose only sclera is a pixel 8 px right of and one 8 px below the iris's
    /// centre are found at the discs' centres; eyes whose only sclera lies just past the rim
    /// (√65 px: 8 px one way and 1 px the other, on every side) are not pupils.
    #[test]
    fn the_sclera_counts_within_0_08_face_widths_of_a_blob_rim_included() {
        let irises = [(60, 50), (100, 50)];
        let mut c = Canvas::face();
        for (x, y) in irises {
            c.disc((x, y), 9, |_| IRIS);
            c.set(x + 8, y, SCLERA);
            c.set(x, y + 8, SCLERA);
        }
        assert_pupils(&detect(&c), irises.map(centre), 1e-9);

        let mut c = Canvas::face();
        for (x, y) in irises {
            c.disc((x, y), 9, |_| IRIS);
            for (dx, dy) in [(1, 8), (8, 1), (-1, -8), (-8, -1)] {
                c.set(x + dx, y + dy, SCLERA);
            }
        }
        assert_eq!(detect(&c), Err(DetectError::Pupils(0)));
    }

    /// An iris split in two by a lid's shadow (a row of sclera across its middle; the halves'
    /// centroids 3.3 px apart, under 0.05 face widths) is one eye: its pupil is the whole
    /// disc's centre and its area both halves'.
    #[test]
    fn an_iris_split_by_a_lids_shadow_is_one_pupil_at_its_centre() {
        let mut c = Canvas::face();
        c.eyes(&[(60, 50), (100, 50)]);
        c.rect([97, 50, 104, 51], SCLERA);
        let d = detect(&c);
        assert_pupils(&d, [centre((60, 50)), centre((100, 50))], 1e-9);
        assert_eq!(d.unwrap().pupil_areas_px, [29, 22]);
    }

    /// Blobs exactly 0.05 face widths (5 px) apart are not "closer than" that, so not merged:
    /// of two 2 × 2 px blobs in one sclera, 5 px apart, the pupil is one blob's centre, not
    /// the point between them.
    #[test]
    fn blobs_exactly_0_05_face_widths_apart_are_two() {
        let mut c = Canvas::face();
        c.eyes(&[(50, 50)]);
        c.rect([74, 45, 93, 55], SCLERA);
        c.rect([80, 49, 82, 51], IRIS);
        c.rect([85, 49, 87, 51], IRIS);
        let d = detect(&c).unwrap();
        assert_eq!(d.pupils[0], centre((50, 50)));
        assert!(
            [[81.0, 50.0], [86.0, 50.0]].contains(&d.pupils[1]),
            "{:?}",
            d.pupils
        );
    }

    /// A pair's pupils are 0.1 to 0.8 face widths (10 to 80 px) apart, both ends included,
    /// and rolled at most 0.6 (31°, a driver's head at most): eyes 10 or 80 px apart, or rolled
    /// by exactly 0.6, are found at the discs' centres; 9 or 81 px apart, or rolled by 0.65,
    /// they leave one candidate and no pair.
    #[test]
    fn a_pair_is_0_1_to_0_8_face_widths_apart_and_rolled_at_most_0_6() {
        for (a, b, pair) in [
            ((55, 50), (65, 50), true),
            ((55, 50), (64, 50), false),
            ((40, 50), (120, 50), true),
            ((40, 50), (121, 50), false),
            ((50, 40), (75, 55), true),
            ((50, 40), (70, 53), false),
        ] {
            let mut c = Canvas::face();
            c.eyes(&[a, b]);
            let d = detect(&c);
            if pair {
                assert_pupils(&d, [centre(a), centre(b)], 1e-9);
            } else {
                assert_eq!(d, Err(DetectError::Pupils(1)), "{a:?} {b:?}");
            }
        }
    }

    /// Of two level pairs, the eyes framed by sclera (76 px each) win over larger dark blobs
    /// (45 px) with a glint of white on each side (nostrils, moles): the pair kept has the
    /// best-framed blobs.
    #[test]
    fn eyes_framed_by_sclera_win_over_larger_blobs_with_a_glint() {
        let mut c = Canvas::face();
        c.eyes(&[(50, 40), (90, 40)]);
        for x in [50, 90] {
            c.disc((x, 75), 13, |_| IRIS);
            c.set(x - 5, 75, SCLERA);
            c.set(x + 5, 75, SCLERA);
        }
        assert_pupils(&detect(&c), [centre((50, 40)), centre((90, 40))], 1e-9);
    }

    /// A squinting driver's eyes, a single pixel of sclera beside each iris, are still eyes:
    /// their irises (29 px) win over level 2 × 2 px specks with two white pixels each.
    #[test]
    fn narrowed_eyes_win_over_specks_with_a_little_more_white() {
        let mut c = Canvas::face();
        for x in [50, 90] {
            c.disc((x, 40), 9, |_| IRIS);
            c.set(x + 5, 40, SCLERA);
            c.rect([x as usize, 75, x as usize + 2, 77], IRIS);
            c.set(x - 3, 75, SCLERA);
            c.set(x + 4, 75, SCLERA);
        }
        assert_pupils(&detect(&c), [centre((50, 40)), centre((90, 40))], 1e-9);
    }

    /// An eye-like blob below the eyes, too steep from either to pair with it (a roll of
    /// 35/20), does not hide the eyes, whatever the blobs' sizes (here between the eyes').
    #[test]
    fn a_blob_that_pairs_with_neither_eye_leaves_the_eyes() {
        let mut c = Canvas::face();
        c.eyes(&[(50, 40), (90, 40), (70, 75)]);
        c.disc((50, 40), 13, |_| IRIS);
        c.disc((70, 75), 10, |_| IRIS);
        assert_pupils(&detect(&c), [centre((50, 40)), centre((90, 40))], 1e-9);
    }

    /// Level irises framed alike (18 px of sclera each) pair by their size: irises of 45 and
    /// 29 px win over either with an iris split by a lid's shadow, which weighs as its two
    /// 11 px halves together (22 px), no more.
    #[test]
    fn a_split_iris_weighs_as_its_halves_together() {
        let mut c = Canvas::face();
        for (x, r2) in [(40, 13), (70, 9), (100, 9)] {
            c.disc((x, 50), r2, |_| IRIS);
            for dx in [-7, -6, -5, 5, 6, 7] {
                for dy in -1..=1 {
                    c.set(x + dx, 50 + dy, SCLERA);
                }
            }
        }
        c.rect([97, 50, 104, 51], SKIN);
        assert_pupils(&detect(&c), [centre((40, 50)), centre((70, 50))], 1e-9);
    }

    /// A dark blob of at most (0.15 face widths)² = 225 px may be a pupil: a 15 × 15 px blob
    /// in sclera pairs with an eye 40 px away; with one pixel more it is no candidate.
    #[test]
    fn a_dark_blob_of_up_to_0_15_face_widths_squared_may_be_a_pupil() {
        for extra in [false, true] {
            let mut c = Canvas::face();
            c.eyes(&[(45, 50)]);
            c.rect([72, 38, 100, 63], SCLERA);
            c.rect([78, 43, 93, 58], IRIS);
            if extra {
                c.set(93, 50, IRIS);
                assert_eq!(detect(&c), Err(DetectError::Pupils(1)));
            } else {
                let d = detect(&c).unwrap();
                assert_eq!(d.pupils[0], centre((45, 50)));
                let [x, y] = d.pupils[1];
                assert!(
                    (78.0..93.0).contains(&x) && (43.0..58.0).contains(&y),
                    "{x} {y}"
                );
            }
        }
    }

    /// A `w` × `h` light grey image with these pixels set to these grey codes, and their
    /// indices (the blob).
    fn blob(w: usize, h: usize, pixels: &[((usize, usize), u8)]) -> (Vec<[u8; 3]>, Vec<usize>) {
        let mut rgb = vec![[200; 3]; w * h];
        let mut indices = Vec::new();
        for &((x, y), v) in pixels {
            rgb[y * w + x] = [v; 3];
            indices.push(y * w + x);
        }
        (rgb, indices)
    }

    /// A blob of at most 1.6 iris discs is all iris: with an iris radius of 4 px (1.6 discs
    /// are 80.4 px) an 8 × 10 px blob comes back whole, and a 9 × 9 px one (81 px), darkening
    /// towards its centre, is cut to its pixels within 1.25 iris radii (5 px) of the centre.
    #[test]
    fn a_blob_of_up_to_1_6_iris_discs_is_its_own_iris() {
        let w = 32;
        let small: Vec<_> = (10..20)
            .flat_map(|y| (10..18).map(move |x| ((x, y), 20)))
            .collect();
        let (rgb, pixels) = blob(w, w, &small);
        assert_eq!(iris_core(&pixels, &rgb, w, 4.0), pixels);

        let d2 = |x: usize, y: usize| (x as i64 - 14).pow(2) + (y as i64 - 14).pow(2);
        let square: Vec<_> = (10..19)
            .flat_map(|y| (10..19).map(move |x| ((x, y), (5 + 2 * d2(x, y)) as u8)))
            .collect();
        let (rgb, pixels) = blob(w, w, &square);
        let mut core = iris_core(&pixels, &rgb, w, 4.0);
        core.sort_unstable();
        let within: Vec<usize> = pixels
            .iter()
            .copied()
            .filter(|&i| d2(i % w, i / w) <= 25)
            .collect();
        assert_eq!(core, within);
        assert_eq!(core.len(), 77);
    }

    /// An iris merged with a lid's shadow is cut to the blob's pixels within 1.25 iris radii
    /// of the pixel whose half-iris disc of blob pixels is darkest on average: the iris's
    /// centre (the iris darkening towards it, the shadow lighter), not a single black speck
    /// in the shadow, whose disc is mostly shadow. So the iris disc (radius 4) and the one
    /// shadow pixel 5 px above its centre.
    #[test]
    fn a_large_blobs_iris_is_around_its_darkest_half_iris_disc() {
        let w = 40;
        let mut pixels = Vec::new();
        for dy in -4i64..=4 {
            for dx in -4i64..=4 {
                let d2 = dx * dx + dy * dy;
                if d2 <= 16 {
                    let v = 4 + 2 * d2;
                    pixels.push((((20 + dx) as usize, (20 + dy) as usize), v as u8));
                }
            }
        }
        for y in 10..=15 {
            for x in 12..=28 {
                let v = if (x, y) == (13, 11) { 0 } else { 44 };
                pixels.push(((x, y), v));
            }
        }
        let (rgb, pixels) = blob(w, w, &pixels);
        let mut core = iris_core(&pixels, &rgb, w, 4.0);
        core.sort_unstable();
        let mut expected: Vec<usize> = pixels[..49].to_vec();
        expected.push(15 * w + 20);
        expected.sort_unstable();
        assert_eq!(core, expected);
    }

    /// An eye whose iris (radius 4 px, 49 px, darkening to its centre) is merged with a lid's
    /// shadow above it (109 px in all, over 1.6 iris discs): the pupil is within a pixel of
    /// the iris's centre (the shadow pixels beside the cut-out core pull it a little), and
    /// its area is the core's, the iris and the one shadow pixel within 5 px of its centre.
    #[test]
    fn an_iris_merged_with_a_shadow_is_cut_out_of_it() {
        let mut c = Canvas::face();
        c.eyes(&[(50, 50)]);
        c.rect([82, 41, 99, 55], SCLERA);
        c.rect([83, 42, 98, 46], [40; 3]);
        c.disc((90, 50), 16, |d2| [(8 + 2 * d2) as u8; 3]);
        let d = detect(&c);
        assert_pupils(&d, [centre((50, 50)), centre((90, 50))], 1.0);
        assert_eq!(d.unwrap().pupil_areas_px, [29, 50]);
    }

    /// The outline's candidates are colour steps on the pupils' line past the irises and in
    /// the frame: none within an iris (radius 4 px, its pixels' outer edges 4.5 px from its
    /// centre; the black pupil in it, 1.5 px across, is no candidate) and none outside the
    /// frame (where the scan runs off its right edge), and the face's edges (x = 30 and 130)
    /// are among them.
    #[test]
    fn the_outline_candidates_lie_past_the_irises_and_in_the_frame() {
        let mut c = Canvas::face();
        let at = [(60, 50), (100, 50)];
        c.eyes(&at);
        for p in at {
            c.disc(p, 16, |_| IRIS);
            c.disc(p, 1, |_| [0; 3]);
        }
        let d = detect(&c).unwrap();
        assert_eq!(d.pupils, at.map(centre));
        for (side, list) in d.outline_candidates.iter().enumerate() {
            let found: Vec<DVec2> = list
                .iter()
                .filter(|p| !p[0].is_nan())
                .map(|&p| DVec2::from(p))
                .collect();
            for p in &found {
                assert!(
                    (0.0..W as f64).contains(&p.x) && (0.0..H as f64).contains(&p.y),
                    "side {side}: {p} outside the frame"
                );
                let from = DVec2::from(d.pupils[side]);
                assert!(
                    (*p - from).length() > 4.5,
                    "side {side}: {p} within the iris around {from}"
                );
            }
            let edge = [30.0, 130.0][side];
            assert!(
                found.iter().any(|p| (p.x - edge).abs() <= 1.0),
                "side {side}: {found:?}"
            );
        }
    }

    /// The outline's candidates on one grey row: skin up to x = 100, then an S-shaped fall
    /// over 10 px to a dark background, and a sharp step to bright at x = 127, 66.5 px (1.1
    /// face widths) past the right pupil. The fall gives candidates from its steepest point
    /// on (the 2-px differences sampled every half pixel come in equal pairs, so each pair's
    /// end on the falling side that still steps by 60 levels is one), none before it; and the
    /// scan, 1.2 face widths long, reaches the far step.
    #[test]
    fn a_blurred_edge_gives_candidates_from_its_steepest_point_and_the_scan_reaches_past_a_face_width()
     {
        let (w, h) = (220usize, 9usize);
        let fall = [200u8, 190, 170, 140, 110, 80, 60, 48, 42, 40];
        let grey = |x: usize| match x {
            0..100 => 200,
            100..110 => fall[x - 100],
            110..127 => 40,
            _ => 240,
        };
        let mut frame = Frame::new(w as u32, h as u32);
        for (i, c) in frame.color.iter_mut().enumerate() {
            *c = Vec3::splat(decode_srgb8(grey(i % w)));
        }
        let skin: Vec<bool> = (0..w * h).map(|i| i % w < 100).collect();
        let pupils = [DVec2::new(40.5, 4.5), DVec2::new(60.5, 4.5)];
        let [_, right] = edge_candidates(&frame, encode_srgb8, &skin, pupils, 20.0, 60.0);
        let xs: Vec<f64> = right.iter().map(|p| p.x).collect();
        // Steepest at 104.5 (pixels 103 and 105: 140 − 80 = 60 levels a channel, 180 summed),
        // then the pairs' ends at 105.5 (150) and 106.5 (96); 107.5 steps by 54, under 60.
        assert_eq!(xs, [104.5, 105.5, 106.5, 127.5], "{right:?}");
    }
}
