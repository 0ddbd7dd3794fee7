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

/// Sclera: bright and nearly grey (the skin is red over blue by ~2 in sRGB).
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
