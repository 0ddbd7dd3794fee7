//! The side-angle pupil detector for the head mesh (`scene/head_model.rs`), as a pillar
//! camera sees it (the head turned up to about ±45° from facing it), with the same shape as
//! `system/head.rs`'s frontal `detect`. Its brows, hair and shadows are dark blobs too, so a
//! pupil is a dark, iris-sized blob with sclera beside it (bright, unsaturated pixels within
//! 0.08 face widths); blobs a lid's shadow split are merged, and the pair kept is the most
//! level one with the largest and best-framed blobs. Shadowed skin is greyish under a blue sky and not told from a grey
//! road by colour, so the head's outline is not segmented here: the colour steps beyond each
//! pupil along the pupils' line whose outer side is not skin are kept as candidates, and the
//! pose fit (`system/head_pose.rs`) picks the pair its head model explains.

use glam::DVec2;

use crate::render::frame::Frame;
use crate::system::head::{
    DetectError, FaceDetection, FaceRegion, HeadConfidence, OUTLINE_CANDIDATES, Rect, face_region,
    inner_blobs, is_skin, luminance, pupil_centroid,
};
use crate::util::color::encode_srgb8;

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
pub fn detect_turned(frame: &Frame) -> Result<FaceDetection, DetectError> {
    let (w, h) = (frame.width as usize, frame.height as usize);
    let rgb: Vec<[u8; 3]> = frame.color.iter().map(|&c| encode_srgb8(c)).collect();
    let skin: Vec<bool> = rgb.iter().map(|&c| is_skin(c)).collect();
    let FaceRegion {
        face_box,
        face_lum,
        search,
        dark,
        ..
    } = face_region(&rgb, &skin, w, h, Rect::whole(w, h))?;
    let face_w = f64::from(face_box[2] - face_box[0]);
    let iris_max = ((0.15 * face_w).powi(2) as usize).max(4);
    let radius = (0.08 * face_w).max(2.5);
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
    let holes = [&pool[best.1].pixels, &pool[best.2].pixels];
    let (a, b) = (
        pupil_centroid(&rgb, w, h, holes[0], face_lum),
        pupil_centroid(&rgb, w, h, holes[1], face_lum),
    );
    let areas = [holes[0].len() as u32, holes[1].len() as u32];
    let (pupils, pupil_areas_px) = if a.x <= b.x {
        ([a, b], areas)
    } else {
        ([b, a], [areas[1], areas[0]])
    };
    let baseline = (b - a).length();
    let candidates = edge_candidates(&rgb, &skin, w, h, pupils, baseline, face_w);
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

/// Where the colour steps along the pupils' line beyond each pupil (outward, up to 1.2 face
/// widths, past the iris): the head's outline is one of them; the fit picks which.
fn edge_candidates(
    rgb: &[[u8; 3]],
    skin: &[bool],
    w: usize,
    h: usize,
    pupils: [DVec2; 2],
    baseline: f64,
    face_w: f64,
) -> [Vec<DVec2>; 2] {
    let along = (pupils[1] - pupils[0]).normalize_or(DVec2::X);
    let at = |p: DVec2| -> Option<[f32; 3]> {
        (p.x >= 0.0 && p.y >= 0.0 && (p.x as usize) < w && (p.y as usize) < h).then(|| {
            let c = rgb[p.y as usize * w + p.x as usize];
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
