//! Head tracking (paper §3.1): find the driver's eyes in the back camera's colour image and
//! turn them into an eye position with eqs. d1 and b_h (and the vertical counterpart).
//!
//! The detector works on the rendered 8-bit image only, never on the scene geometry: skin is
//! found by its chromaticity, the face is the largest skin region, and the pupils are the two
//! largest dark holes inside it. The known feature `A` is the interpupillary distance, whose
//! midpoint is the eye point the compensation needs, so no face-model offsets are involved.

use glam::{DAffine3, DMat3, DVec2, DVec3, Vec3};

use crate::analysis::paper::{head_distance, head_offset};
use crate::geometry::camera::Camera;
use crate::render::footprint::PixelRect;
use crate::render::frame::Frame;
pub use crate::system::head_confidence::{CONFIDENT_HEAD, HeadConfidence};
use crate::util::color::encode_srgb8;
use crate::util::sampling::{hash_words, unit_float};

/// What the detector found, in back-camera pixel coordinates (continuous). Two detections are
/// equal when every field is, the NaN padding of `outline_candidates` included (bit for bit).
#[derive(Clone, Copy, Debug, serde::Serialize)]
pub struct FaceDetection {
    /// Bounding box of the face region: [x0, y0, x1, y1), pixels.
    pub face_box: [u32; 4],
    /// Centroids of the left and right pupil (left = smaller x).
    pub pupils: [[f64; 2]; 2],
    /// Pixels in the left and right pupil's dark blob.
    pub pupil_areas_px: [u32; 2],
    /// The head's left and right edge on the line through the pupils (pixels): where the skin
    /// ends beyond each pupil; from the side-angle detector, the nearest outline candidates.
    pub row_edges: [[f64; 2]; 2],
    /// The side-angle detector's candidates for the head's outline on the pupils' line
    /// (`detect_turned` in `system/head_side.rs`): up to [`OUTLINE_CANDIDATES`] colour steps
    /// beyond each pupil (left, right), pixels, nearest first, NaN-padded; all NaN from
    /// [`detect`]. The pose fit (`system/head_pose.rs`) picks which one is the outline.
    #[serde(skip)]
    pub outline_candidates: [[[f64; 2]; OUTLINE_CANDIDATES]; 2],
    /// How far the detection can be trusted, from what it measured ([`HeadConfidence`]).
    pub confidence: HeadConfidence,
}

/// Outline candidates kept per side ([`FaceDetection::outline_candidates`]).
pub const OUTLINE_CANDIDATES: usize = 12;

impl PartialEq for FaceDetection {
    fn eq(&self, other: &Self) -> bool {
        let bits = |d: &FaceDetection| {
            d.outline_candidates
                .map(|side| side.map(|p| p.map(f64::to_bits)))
        };
        self.face_box == other.face_box
            && self.pupils == other.pupils
            && self.pupil_areas_px == other.pupil_areas_px
            && self.row_edges == other.row_edges
            && bits(self) == bits(other)
            && self.confidence == other.confidence
    }
}

impl FaceDetection {
    /// The feature width `A_px`: distance between the pupils, pixels.
    pub fn feature_px(&self) -> f64 {
        (DVec2::from(self.pupils[1]) - DVec2::from(self.pupils[0])).length()
    }

    /// Midpoint between the pupils, pixels.
    pub fn centre(&self) -> DVec2 {
        (DVec2::from(self.pupils[0]) + DVec2::from(self.pupils[1])) / 2.0
    }
}

#[derive(Clone, Debug, PartialEq)]
pub enum DetectError {
    NoFace,
    Pupils(usize),
}

impl std::fmt::Display for DetectError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            DetectError::NoFace => write!(
                f,
                "no face found in the back camera's image (is the head in its view?)"
            ),
            DetectError::Pupils(n) => write!(
                f,
                "found {n} pupil candidates in the face, need 2 (eyes hidden or too small at this resolution?)"
            ),
        }
    }
}

impl std::error::Error for DetectError {}

/// Skin by normalised chromaticity: reddish, with more green than blue, not too dark.
pub(crate) fn is_skin([r, g, b]: [u8; 3]) -> bool {
    let sum = r as f32 + g as f32 + b as f32;
    if sum < 90.0 || !(r > g && g > b) {
        return false;
    }
    let (rc, gc, bc) = (r as f32 / sum, g as f32 / sum, b as f32 / sum);
    (0.36..0.50).contains(&rc) && (0.28..0.37).contains(&gc) && bc > 0.20
}

/// The Rec. 709 luminance of 8-bit codes, [0, 255] ([`crate::util::color::luminance`]).
pub(crate) fn luminance([r, g, b]: [u8; 3]) -> f32 {
    crate::util::color::luminance(Vec3::new(r as f32, g as f32, b as f32))
}

/// Connected components (4-neighbour) of the pixels of `rect` where `mask` is true, as pixel
/// lists in the order of their first pixel (row by row). `mask` must be false outside `rect`.
pub(crate) fn components(mask: &[bool], w: usize, h: usize, rect: Rect) -> Vec<Vec<usize>> {
    let mut label = vec![false; mask.len()];
    let mut out = Vec::new();
    for start in (rect.y0..rect.y1).flat_map(|y| (rect.x0..rect.x1).map(move |x| y * w + x)) {
        if !mask[start] || label[start] {
            continue;
        }
        let mut stack = vec![start];
        let mut pixels = Vec::new();
        label[start] = true;
        while let Some(i) = stack.pop() {
            pixels.push(i);
            let (x, y) = (i % w, i / w);
            let neighbours = [
                (x > 0).then(|| i - 1),
                (x + 1 < w).then(|| i + 1),
                (y > 0).then(|| i - w),
                (y + 1 < h).then(|| i + w),
            ];
            for n in neighbours.into_iter().flatten() {
                if mask[n] && !label[n] {
                    label[n] = true;
                    stack.push(n);
                }
            }
        }
        out.push(pixels);
    }
    out
}

/// A rectangle of pixels, [x0, x1) × [y0, y1), in the detector's image.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) struct Rect {
    x0: usize,
    y0: usize,
    x1: usize,
    y1: usize,
}

impl Rect {
    /// Every pixel of a w × h image.
    pub(crate) fn whole(w: usize, h: usize) -> Rect {
        Rect {
            x0: 0,
            y0: 0,
            x1: w,
            y1: h,
        }
    }

    fn of(r: PixelRect, w: usize, h: usize) -> Rect {
        Rect {
            x0: (r.x0 as usize).min(w),
            y0: (r.y0 as usize).min(h),
            x1: (r.x1 as usize).min(w),
            y1: (r.y1 as usize).min(h),
        }
    }

    fn pixel_rect(self) -> PixelRect {
        PixelRect {
            x0: self.x0 as u32,
            y0: self.y0 as u32,
            x1: self.x1 as u32,
            y1: self.y1 as u32,
        }
    }

    fn contains(&self, other: &Rect) -> bool {
        other.x0 >= self.x0 && other.y0 >= self.y0 && other.x1 <= self.x1 && other.y1 <= self.y1
    }
}

/// Finds the face and the pupils in a colour frame (as a camera would deliver it, 8-bit sRGB).
/// The face box reported is the skin region's bounding box.
pub fn detect(frame: &Frame) -> Result<FaceDetection, DetectError> {
    let full = PixelRect {
        x0: 0,
        y0: 0,
        x1: frame.width,
        y1: frame.height,
    };
    detect_with(frame, full).map(|(d, _)| d)
}

/// [`detect`] reading only the pixels of `region` (a tracker's region of interest: the
/// pixels outside it need not even be rendered), with the rectangle of pixels the detection
/// depended on: the face region and the ring a pixel around it (where its skin ends), the
/// pupil search box and the rings of the centroids, and the samples of the skin walk beside
/// the pupils.
pub fn detect_in(frame: &Frame, region: PixelRect) -> Result<InRegion, DetectError> {
    let (w, h) = (frame.width as usize, frame.height as usize);
    let (detection, used) = detect_with(frame, region)?;
    Ok(InRegion {
        detection,
        used,
        whole: Rect::of(region, w, h).contains(&Rect::of(used, w, h)),
    })
}

/// What [`detect_in`] found.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct InRegion {
    pub detection: FaceDetection,
    /// The pixels the detection depended on, back-camera pixels, [x0, x1) × [y0, y1).
    pub used: PixelRect,
    /// Whether `used` lies inside the region searched. Then the detection is bit for bit what
    /// [`detect`] finds in the whole frame, unless a skin region larger than the face lies
    /// wholly outside the region (then [`detect`] would take that one for the face).
    pub whole: bool,
}

/// The face and the box its pupils are searched in, as both detectors find them.
pub(crate) struct FaceRegion {
    /// The face's pixels (the largest skin region, at least 20), image indices.
    pub face: Vec<usize>,
    /// The face's bounding box, [x0, y0, x1, y1), pixels.
    pub face_box: [u32; 4],
    /// The face's median luminance (sRGB 8-bit scale).
    pub face_lum: f32,
    /// The pupil search box: the face box grown by an eighth of its size (at least 2 px; an
    /// eye near the silhouette may touch the background), within the image, [x0, y0, x1, y1).
    pub search: [usize; 4],
    /// The search box's pixels (row by row within it) darker than 0.3 × `face_lum`.
    pub dark: Vec<bool>,
}

/// [`FaceRegion`] of an image's sRGB pixels and skin mask, from the pixels of `region`.
pub(crate) fn face_region(
    rgb: &[[u8; 3]],
    skin: &[bool],
    w: usize,
    h: usize,
    region: Rect,
) -> Result<FaceRegion, DetectError> {
    let face = components(skin, w, h, region)
        .into_iter()
        .max_by_key(Vec::len)
        .filter(|c| c.len() >= 20)
        .ok_or(DetectError::NoFace)?;
    let (mut x0, mut y0, mut x1, mut y1) = (w, h, 0, 0);
    for &i in &face {
        (x0, y0, x1, y1) = (
            x0.min(i % w),
            y0.min(i / w),
            x1.max(i % w + 1),
            y1.max(i / w + 1),
        );
    }
    let face_box = [x0 as u32, y0 as u32, x1 as u32, y1 as u32];
    let face_lum = {
        let mut l: Vec<f32> = face.iter().map(|&i| luminance(rgb[i])).collect();
        l.sort_by(f32::total_cmp);
        l[l.len() / 2]
    };
    let margin = ((x1 - x0).max(y1 - y0) / 8).max(2);
    let search = [
        x0.saturating_sub(margin),
        y0.saturating_sub(margin),
        (x1 + margin).min(w),
        (y1 + margin).min(h),
    ];
    let dark = dark_mask(rgb, w, search, face_lum);
    Ok(FaceRegion {
        face,
        face_box,
        face_lum,
        search,
        dark,
    })
}

/// The pixels of the box `[x0, y0, x1, y1)` (row by row within it) darker than
/// 0.3 × `face_lum` ([`FaceRegion::dark`]).
pub(crate) fn dark_mask(
    rgb: &[[u8; 3]],
    w: usize,
    [x0, y0, x1, y1]: [usize; 4],
    face_lum: f32,
) -> Vec<bool> {
    let bw = x1 - x0;
    (0..bw * (y1 - y0))
        .map(|k| luminance(rgb[(y0 + k / bw) * w + x0 + k % bw]) < 0.3 * face_lum)
        .collect()
}

/// The dark blobs of a search box (`dark`, as in [`FaceRegion`]) of at most `max_area`
/// pixels that do not touch the box's border, as image pixel indices (`w`: image width).
pub(crate) fn inner_blobs(
    dark: &[bool],
    [x0, y0, x1, y1]: [usize; 4],
    w: usize,
    max_area: usize,
) -> Vec<Vec<usize>> {
    let (bw, bh) = (x1 - x0, y1 - y0);
    components(dark, bw, bh, Rect::whole(bw, bh))
        .into_iter()
        .filter(|c| {
            c.len() <= max_area
                && c.iter()
                    .all(|&k| k % bw > 0 && k % bw + 1 < bw && k / bw > 0 && k / bw + 1 < bh)
        })
        .map(|c| {
            c.into_iter()
                .map(|k| (y0 + k / bw) * w + x0 + k % bw)
                .collect()
        })
        .collect()
}

/// The detection from the pixels of `region` only (the others read as black, not skin), and
/// the rectangle of pixels it depended on (see [`detect_in`]).
fn detect_with(
    frame: &Frame,
    region: PixelRect,
) -> Result<(FaceDetection, PixelRect), DetectError> {
    let (w, h) = (frame.width as usize, frame.height as usize);
    let region = Rect::of(region, w, h);
    let mut rgb: Vec<[u8; 3]> = vec![[0; 3]; w * h];
    let mut skin: Vec<bool> = vec![false; w * h];
    for y in region.y0..region.y1 {
        for i in y * w + region.x0..y * w + region.x1 {
            rgb[i] = encode_srgb8(frame.color[i]);
            skin[i] = is_skin(rgb[i]);
        }
    }
    let FaceRegion {
        face,
        face_box,
        face_lum,
        search: [x0, y0, x1, y1],
        dark,
    } = face_region(&rgb, &skin, w, h, region)?;
    // Pupil candidates: small, very dark blobs inside the search box. Hair is dark too, but
    // large: blobs over 3% of the face are not pupils.
    let max_area = (face.len() / 33).max(4);
    // What the detection reads: the pupil search box, and two pixels beyond it for the
    // rings of the centroids (a blob stays a pixel inside the box, its rim one more, the
    // ring two more), within the image.
    let mut used = Rect {
        x0: x0.saturating_sub(2),
        y0: y0.saturating_sub(2),
        x1: (x1 + 2).min(w),
        y1: (y1 + 2).min(h),
    };
    let mut holes: Vec<Vec<usize>> = inner_blobs(&dark, [x0, y0, x1, y1], w, max_area);
    holes.sort_by_key(|c| std::cmp::Reverse(c.len()));
    if holes.len() < 2 {
        return Err(DetectError::Pupils(holes.len()));
    }
    holes.truncate(2);
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
    let row_edges = row_edges(&skin, w, h, pupils, (x1 - x0) as f64, &mut used);
    let detection = FaceDetection {
        face_box,
        pupils: pupils.map(|p| p.to_array()),
        pupil_areas_px,
        row_edges: row_edges.map(|p| p.to_array()),
        outline_candidates: [[[f64::NAN; 2]; OUTLINE_CANDIDATES]; 2],
        confidence: HeadConfidence::of(face_box, pupils, pupil_areas_px),
    };
    Ok((detection, used.pixel_rect()))
}

/// A pixel set and its 4-neighbours.
fn grow(set: &[usize], w: usize, h: usize) -> Vec<usize> {
    let mut out: Vec<usize> = set.to_vec();
    for &i in set {
        let (x, y) = (i % w, i / w);
        for (nx, ny) in [
            (x.wrapping_sub(1), y),
            (x + 1, y),
            (x, y.wrapping_sub(1)),
            (x, y + 1),
        ] {
            if nx < w && ny < h {
                out.push(ny * w + nx);
            }
        }
    }
    out.sort_unstable();
    out.dedup();
    out
}

/// A pupil blob's sub-pixel centroid: each pixel of the blob and its one-pixel rim weighs by
/// how far it is from the local skin level (the median of a ring two pixels out) towards the
/// pupil's darkest value, so mixed edge pixels count in proportion and shading does not pull.
pub(crate) fn pupil_centroid(
    rgb: &[[u8; 3]],
    w: usize,
    h: usize,
    hole: &[usize],
    face_lum: f32,
) -> DVec2 {
    let rim = grow(hole, w, h);
    let outer = grow(&grow(&rim, w, h), w, h);
    let mut ring: Vec<f32> = outer
        .iter()
        .filter(|i| rim.binary_search(i).is_err())
        .map(|&i| luminance(rgb[i]))
        .collect();
    ring.sort_by(f32::total_cmp);
    let skin = ring.get(ring.len() / 2).copied().unwrap_or(face_lum);
    let darkest = hole
        .iter()
        .map(|&i| luminance(rgb[i]))
        .fold(f32::INFINITY, f32::min);
    let (mut sum, mut total) = (DVec2::ZERO, 0.0);
    for i in rim {
        let weight =
            ((skin - luminance(rgb[i])) / (skin - darkest).max(1.0)).clamp(0.0, 1.0) as f64;
        sum += weight * DVec2::new((i % w) as f64 + 0.5, (i / w) as f64 + 0.5);
        total += weight;
    }
    sum / total
}

/// Where the skin ends beyond each pupil along the line through both: walking outward in
/// quarter-pixel steps, the last skin sample before a gap of non-skin wider than the eye
/// opening could be (a tenth of the face's width, at least 3 px) — the eye's own white and
/// iris are crossed, the background is not.
/// `used` grows to every pixel the walks read.
fn row_edges(
    skin: &[bool],
    w: usize,
    h: usize,
    pupils: [DVec2; 2],
    face_px: f64,
    used: &mut Rect,
) -> [DVec2; 2] {
    let along = (pupils[1] - pupils[0]).normalize_or(DVec2::X);
    let gap = (0.1 * face_px).max(3.0);
    let mut is_skin = |p: DVec2| {
        let inside = p.x >= 0.0 && p.y >= 0.0 && (p.x as usize) < w && (p.y as usize) < h;
        if inside {
            let (x, y) = (p.x as usize, p.y as usize);
            *used = Rect {
                x0: used.x0.min(x),
                y0: used.y0.min(y),
                x1: used.x1.max(x + 1),
                y1: used.y1.max(y + 1),
            };
        }
        inside && skin[p.y as usize * w + p.x as usize]
    };
    let mut walk = |from: DVec2, direction: DVec2| {
        let (mut last, mut s) = (0.0, 0.0);
        while s < 1.5 * face_px && s - last <= gap {
            s += 0.25;
            if is_skin(from + direction * s) {
                last = s;
            }
        }
        from + direction * (last + 0.125)
    };
    [walk(pupils[0], -along), walk(pupils[1], along)]
}

/// The eye position from a detection: eq. d1 for the distance along the back camera's axis,
/// eq. b_h (and its vertical counterpart) for the offsets; then the back camera's pose
/// compensates its offset from the display centre. `feature_width` is `A` in metres.
/// With a lens, the pupils are first undistorted into the pinhole of the same fx
/// ([`Camera::ideal_pixel`]), where the equations hold.
pub fn eye_from_detection(detection: &FaceDetection, back: &Camera, feature_width: f64) -> DVec3 {
    let detection = &FaceDetection {
        pupils: detection
            .pupils
            .map(|p| back.ideal_pixel(DVec2::from(p)).to_array()),
        ..*detection
    };
    let image_px = back.width as f64;
    let d = head_distance(
        feature_width,
        detection.feature_px(),
        image_px,
        back.half_angle_x,
    );
    let c = detection.centre();
    let x = head_offset(c.x - image_px / 2.0, image_px, d, back.half_angle_x);
    // Vertical pixels are as wide as horizontal ones: the same normalisation by E_px.
    let y = head_offset(
        back.height as f64 / 2.0 - c.y,
        image_px,
        d,
        back.half_angle_x,
    );
    back.world_from_camera
        .transform_point3(DVec3::new(x, y, -d))
}

/// The eye from a detection of a face with a known orientation, `world_from_face` (the face
/// looks down its −z, +y up; the ellipsoid face faces the vehicle's forward): the pupils'
/// rays are turned from the back camera's frame into a virtual pinhole at the same place that
/// looks squarely at the face (its axis along the face's +z, the face's interpupillary line
/// parallel to its image plane), where eqs. d1 and b_h hold; the eye found there goes back
/// through the virtual camera's pose into the world. A back camera yawed or pitched on the
/// display is so corrected for: in its own image the pupils lie at different depths and their
/// distance is foreshortened, which the frontal equations would read as a farther face.
///
/// With the back camera already square to the face (das as shipped: within 1e-12 of it), the
/// frontal equations run on the camera's own pixels, bit for bit [`eye_from_detection`].
pub fn eye_facing(
    detection: &FaceDetection,
    back: &Camera,
    feature_width: f64,
    world_from_face: DMat3,
) -> FacingEye {
    // The virtual camera looks at the face from in front: half a turn about the face's y.
    let world_from_virtual = world_from_face * DMat3::from_rotation_y(std::f64::consts::PI);
    let world_from_back = back.world_from_camera.matrix3;
    // Rigid rotations: the transpose is the inverse.
    let virtual_from_back = world_from_virtual.transpose() * world_from_back;
    let rays = detection
        .pupils
        .map(|p| virtual_from_back * back.camera_direction(DVec2::from(p)));
    let towards_eye = rays[0].normalize_or_zero() + rays[1].normalize_or_zero();
    // The eye's ray off the virtual axis: the angle at the face between its front and the
    // camera, which the camera's own yaw or pitch does not change.
    let view_angle_deg = towards_eye.angle_between(DVec3::NEG_Z).to_degrees();
    if virtual_from_back.abs_diff_eq(DMat3::IDENTITY, 1e-12) {
        return FacingEye {
            eye: eye_from_detection(detection, back, feature_width),
            view_angle_deg,
        };
    }
    let square = Camera {
        world_from_camera: DAffine3 {
            matrix3: world_from_virtual,
            translation: back.world_from_camera.translation,
        },
        lens: None,
        ..*back
    };
    let eye = match rays.map(|r| square.project_camera(r)) {
        [Some(a), Some(b)] => {
            let rectified = FaceDetection {
                pupils: [a.to_array(), b.to_array()],
                ..*detection
            };
            eye_from_detection(&rectified, &square, feature_width)
        }
        // A pupil behind the square camera: the face is seen from behind its front, which
        // no equation corrects; the view angle (≥ 90°) sinks the confidence.
        _ => eye_from_detection(detection, back, feature_width),
    };
    FacingEye {
        eye,
        view_angle_deg,
    }
}

/// What [`eye_facing`] found.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FacingEye {
    /// The estimated eye (midpoint of the pupils), world frame, metres.
    pub eye: DVec3,
    /// The angle at the face between its front (the face's −z) and the direction to the back
    /// camera, degrees, [0, 180]; from the pupils' rays.
    pub view_angle_deg: f64,
}

/// A standard normal deviate from (seed, index), by Box–Muller on hashed uniforms.
pub fn gaussian(seed: u32, index: u32) -> f64 {
    let u1 = (unit_float(hash_words(&[seed, index, 1])) as f64).max(1e-12);
    let u2 = unit_float(hash_words(&[seed, index, 2])) as f64;
    (-2.0 * u1.ln()).sqrt() * (std::f64::consts::TAU * u2).cos()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn gaussian_deviates_have_unit_variance() {
        let n = 20_000;
        let xs: Vec<f64> = (0..n).map(|i| gaussian(7, i)).collect();
        let mean = xs.iter().sum::<f64>() / n as f64;
        let var = xs.iter().map(|x| (x - mean).powi(2)).sum::<f64>() / n as f64;
        // Standard errors: 0.007 for the mean, 0.01 for the variance; 5 sigma.
        assert!(
            mean.abs() < 0.035 && (var - 1.0).abs() < 0.05,
            "{mean} {var}"
        );
        assert_eq!(gaussian(7, 3), gaussian(7, 3));
    }

    /// A deterministic mask: about `density` of the pixels set.
    fn mask(w: usize, h: usize, seed: u32, density: f32) -> Vec<bool> {
        (0..w * h)
            .map(|i| {
                let x = crate::util::sampling::hash_u32(seed.wrapping_mul(0x9e37_79b9) ^ i as u32);
                crate::util::sampling::unit_float(x) < density
            })
            .collect()
    }

    /// The brute-force twin of [`components`]: every set pixel of `rect` takes the least
    /// label of itself and its 4 neighbours until nothing changes; components are the pixels
    /// of one label, ordered by their first pixel row by row, each in row order.
    fn components_by_relaxation(mask: &[bool], w: usize, rect: Rect) -> Vec<Vec<usize>> {
        let inside = |x: usize, y: usize| {
            x >= rect.x0 && x < rect.x1 && y >= rect.y0 && y < rect.y1 && mask[y * w + x]
        };
        let mut label: Vec<usize> = (0..mask.len()).collect();
        loop {
            let mut changed = false;
            for y in rect.y0..rect.y1 {
                for x in rect.x0..rect.x1 {
                    if !inside(x, y) {
                        continue;
                    }
                    let i = y * w + x;
                    let mut least = label[i];
                    for (nx, ny) in [
                        (x.wrapping_sub(1), y),
                        (x + 1, y),
                        (x, y.wrapping_sub(1)),
                        (x, y + 1),
                    ] {
                        if nx < w && inside(nx, ny) {
                            least = least.min(label[ny * w + nx]);
                        }
                    }
                    if least < label[i] {
                        label[i] = least;
                        changed = true;
                    }
                }
            }
            if !changed {
                break;
            }
        }
        let mut groups: std::collections::BTreeMap<usize, Vec<usize>> = Default::default();
        for y in rect.y0..rect.y1 {
            for x in rect.x0..rect.x1 {
                if inside(x, y) {
                    groups.entry(label[y * w + x]).or_default().push(y * w + x);
                }
            }
        }
        // A label is its component's least index: its first pixel row by row.
        groups.into_values().collect()
    }

    /// [`components`] against its twin on masks from sparse to dense (many small regions to
    /// one that winds through the image), over the whole image and over a rectangle within
    /// it (the mask false outside, as the function requires): the same components, in the
    /// same order, each pixel once.
    #[test]
    fn components_are_their_brute_force_twins() {
        let (w, h) = (37, 23);
        for (seed, density) in [(1, 0.2), (2, 0.45), (3, 0.6), (4, 0.9)] {
            let whole = mask(w, h, seed, density);
            let inner = Rect {
                x0: 5,
                y0: 3,
                x1: 30,
                y1: 20,
            };
            let clipped: Vec<bool> = whole
                .iter()
                .enumerate()
                .map(|(i, &m)| m && i % w >= 5 && i % w < 30 && i / w >= 3 && i / w < 20)
                .collect();
            for (m, rect) in [(&whole, Rect::whole(w, h)), (&clipped, inner)] {
                let mut fast = components(m, w, h, rect);
                for c in &mut fast {
                    c.sort_unstable();
                }
                let twin = components_by_relaxation(m, w, rect);
                assert_eq!(fast, twin, "seed {seed}, density {density}, {rect:?}");
                let count: usize = fast.iter().map(Vec::len).sum();
                assert_eq!(count, m.iter().filter(|&&b| b).count());
            }
        }
    }

    /// A blob is kept when it has at most `max_area` pixels and touches none of the search
    /// box's four borders; its pixels are given as image indices.
    #[test]
    fn inner_blobs_are_small_and_clear_of_the_boxs_border() {
        // A 10 × 8 box at (3, 2) of a 20-pixel-wide image.
        let (x0, y0, x1, y1, w) = (3, 2, 13, 10, 20);
        let (bw, bh) = (x1 - x0, y1 - y0);
        let mut dark = vec![false; bw * bh];
        let mut set = |x: usize, y: usize| dark[y * bw + x] = true;
        // Inside: a 2 × 2 blob (4 pixels) and a 3 × 2 one (6 pixels).
        for (x, y) in [(2, 2), (3, 2), (2, 3), (3, 3)] {
            set(x, y);
        }
        for (x, y) in [(6, 4), (7, 4), (8, 4), (6, 5), (7, 5), (8, 5)] {
            set(x, y);
        }
        // One pixel touching each border.
        for (x, y) in [(0, 4), (bw - 1, 2), (5, 0), (4, bh - 1)] {
            set(x, y);
        }
        let image = |bx: usize, by: usize| (y0 + by) * w + x0 + bx;
        // components() lists a blob's pixels in flood order: compare each as a set.
        let sorted = |blobs: Vec<Vec<usize>>| -> Vec<Vec<usize>> {
            blobs
                .into_iter()
                .map(|mut b| {
                    b.sort_unstable();
                    b
                })
                .collect()
        };
        let small = vec![image(2, 2), image(3, 2), image(2, 3), image(3, 3)];
        let large = vec![
            image(6, 4),
            image(7, 4),
            image(8, 4),
            image(6, 5),
            image(7, 5),
            image(8, 5),
        ];
        let found = sorted(inner_blobs(&dark, [x0, y0, x1, y1], w, 6));
        assert_eq!(found, vec![small.clone(), large]);
        // One pixel less of room: the 6-pixel blob is too large.
        let found = sorted(inner_blobs(&dark, [x0, y0, x1, y1], w, 5));
        assert_eq!(found, vec![small]);
    }

    /// The face is the largest skin region of at least 20 pixels; its box is its pixels'
    /// bounds, its luminance their median, and the pupil search box the face box grown by
    /// an eighth of its larger side (at least 2 pixels), cut at the image's edges.
    #[test]
    fn the_face_region_is_the_largest_skin_region_and_its_box() {
        let (w, h) = (40, 30);
        let mut skin = vec![false; w * h];
        let mut rgb = vec![[0u8; 3]; w * h];
        // A 6 × 5 region (30 pixels) from (1, 2), grey levels rising along its rows; a 5 × 5
        // one (25 pixels) apart from it.
        for y in 2..7 {
            for x in 1..7 {
                skin[y * w + x] = true;
                let v = (10 * (y * 6 + x)) as u8;
                rgb[y * w + x] = [v, v, v];
            }
        }
        for y in 20..25 {
            for x in 30..35 {
                skin[y * w + x] = true;
            }
        }
        let r = face_region(&rgb, &skin, w, h, Rect::whole(w, h)).unwrap();
        assert_eq!(r.face.len(), 30);
        assert_eq!(r.face_box, [1, 2, 7, 7]);
        let mut lums: Vec<f32> = r.face.iter().map(|&i| luminance(rgb[i])).collect();
        lums.sort_by(f32::total_cmp);
        assert_eq!(r.face_lum, lums[15]);
        // 6 / 8 rounds to 0: the least margin, 2 pixels, cut at the image's left edge.
        assert_eq!(r.search, [0, 0, 9, 9]);
        assert_eq!(r.dark.len(), 81);
        // A larger face: a margin of a 24-pixel side is 3.
        let mut big = vec![false; w * h];
        for y in 3..27 {
            for x in 10..20 {
                big[y * w + x] = true;
            }
        }
        let r = face_region(&rgb, &big, w, h, Rect::whole(w, h)).unwrap();
        assert_eq!((r.face_box, r.search), ([10, 3, 20, 27], [7, 0, 23, 30]));
        // The same face further right and down: the margin is the face's size's, not its
        // place's (3 again).
        let mut moved = vec![false; w * h];
        for y in 5..29 {
            for x in 24..34 {
                moved[y * w + x] = true;
            }
        }
        let r = face_region(&rgb, &moved, w, h, Rect::whole(w, h)).unwrap();
        assert_eq!((r.face_box, r.search), ([24, 5, 34, 29], [21, 2, 37, 30]));
        // 19 pixels are no face; 20 are.
        let mut few = vec![false; w * h];
        for i in 0..19 {
            few[5 * w + 10 + i] = true;
        }
        let none = face_region(&rgb, &few, w, h, Rect::whole(w, h));
        assert!(matches!(none, Err(DetectError::NoFace)));
        few[5 * w + 29] = true;
        assert!(face_region(&rgb, &few, w, h, Rect::whole(w, h)).is_ok());
    }

    /// Skin needs a sum of at least 90 and red > green > blue, strictly: a sum of 89, or red
    /// equal to green, is not skin even where the chromaticities are.
    #[test]
    fn skin_has_its_thresholds_where_its_doc_puts_them() {
        // 40 : 30 : 20 of 90: chromaticities 0.444, 0.333, 0.222, all within their bands.
        assert!(is_skin([40, 30, 20]));
        // The same chromaticities within their bands, a sum of 89.
        assert!(!is_skin([39, 30, 20]));
        // Chromaticities within their bands (0.36, 0.36, 0.28; 0.4, 0.3, 0.3), but red
        // equal to green, or green to blue.
        assert!(!is_skin([36, 36, 28]) && !is_skin([40, 30, 30]));
        assert!(!is_skin([80, 80, 80]));
        // Blue's chromaticity must exceed 0.20: 40 of 200 is not enough, 41 of 201 is.
        assert!(!is_skin([90, 70, 40]) && is_skin([90, 70, 41]));
    }

    /// The detector's errors say what went wrong and what to look at, as the run's error
    /// line prints them.
    #[test]
    fn detection_errors_say_what_is_missing() {
        let no_face = DetectError::NoFace.to_string();
        assert!(
            no_face.contains("no face found") && no_face.contains("in its view"),
            "{no_face}"
        );
        let pupils = DetectError::Pupils(3).to_string();
        assert!(
            pupils.contains("found 3 pupil candidates") && pupils.contains("need 2"),
            "{pupils}"
        );
    }

    /// A w × h image of skin at luminance `skin` (grey, plus `slope` per pixel to the
    /// right) with a dark disc of radius `r` at `centre`, each pixel mixed by the share of
    /// it the disc covers (16 × 16 samples); and the disc's blob as the detector finds it
    /// (pixels darker than 0.3 × the skin level).
    fn pupil_image(
        (w, h): (usize, usize),
        centre: DVec2,
        r: f64,
        skin: f64,
        slope: f64,
    ) -> (Vec<[u8; 3]>, Vec<usize>) {
        let dark = 20.0;
        let rgb: Vec<[u8; 3]> = (0..w * h)
            .map(|i| {
                let (x, y) = ((i % w) as f64, (i / w) as f64);
                let inside = (0..256)
                    .filter(|k| {
                        let p = DVec2::new(
                            x + (f64::from(k % 16) + 0.5) / 16.0,
                            y + (f64::from(k / 16) + 0.5) / 16.0,
                        );
                        p.distance(centre) < r
                    })
                    .count() as f64
                    / 256.0;
                let level = skin + slope * x;
                let v = (level + (dark - level) * inside).round() as u8;
                [v, v, v]
            })
            .collect();
        let hole = (0..w * h)
            .filter(|&i| luminance(rgb[i]) < 0.3 * skin as f32)
            .collect();
        (rgb, hole)
    }

    /// A round pupil's centroid is its centre: the rim's mixed pixels weigh by how dark they
    /// are, so the sub-pixel position is kept to a twentieth of a pixel, at any offset within
    /// a pixel; and a shading across the face (a tenth of the skin level over the pupil's
    /// width) moves it by less than a tenth.
    #[test]
    fn a_round_pupils_centroid_is_its_centre() {
        for (dx, dy) in [(0.0, 0.0), (0.25, 0.5), (0.5, 0.125), (0.8, 0.3)] {
            let centre = DVec2::new(10.0 + dx, 9.0 + dy);
            let (rgb, hole) = pupil_image((21, 19), centre, 2.6, 180.0, 0.0);
            let c = pupil_centroid(&rgb, 21, 19, &hole, 180.0);
            assert!(c.distance(centre) < 0.05, "{centre} found at {c}");
            let (rgb, hole) = pupil_image((21, 19), centre, 2.6, 180.0, 3.5);
            let c = pupil_centroid(&rgb, 21, 19, &hole, 180.0 + 35.0);
            assert!(c.distance(centre) < 0.1, "shaded: {centre} found at {c}");
        }
    }

    /// The walk from each pupil outward along the line through both ends where the skin
    /// does, within a quarter pixel (its step), crossing a non-skin gap narrower than the
    /// allowance (the eye's white) and stopping at one wider (the background); `used` grows
    /// to every pixel it read.
    #[test]
    fn the_row_edges_are_where_the_skin_ends() {
        let (w, h) = (80, 30);
        let mut skin = vec![false; w * h];
        // Skin on rows 10..20 from x = 12 to 61, with the eyes' whites (2 px) beside the
        // pupils, and a stray skin pixel 12 px beyond the right edge (past the allowance).
        for y in 10..20 {
            for x in 12..61 {
                skin[y * w + x] = true;
            }
            for x in [24, 25, 47, 48] {
                skin[y * w + x] = false;
            }
            skin[y * w + 73] = true;
        }
        let pupils = [DVec2::new(26.5, 15.5), DVec2::new(45.5, 15.5)];
        let mut used = Rect {
            x0: 20,
            y0: 12,
            x1: 50,
            y1: 18,
        };
        let [left, right] = row_edges(&skin, w, h, pupils, 49.0, &mut used);
        assert!((left.x - 12.0).abs() <= 0.25 && left.y == 15.5, "{left}");
        assert!((right.x - 61.0).abs() <= 0.25 && right.y == 15.5, "{right}");
        // Each walk reads a quarter pixel past a gap of 4.9 px (a tenth of the face) beyond
        // its last skin: from x = 12.0 to 7.0 on the left, 60.75 to 65.75 on the right.
        let read = Rect {
            x0: 7,
            y0: 12,
            x1: 66,
            y1: 18,
        };
        assert_eq!(used, read);
    }

    /// On a rolled face (the pupils' line at 45°) the walks run diagonally: each stops a
    /// quarter pixel past its last skin sample, and `used` grows down and to the right as
    /// well as up and to the left, to the last pixel read. Skin fills the square
    /// [10, 50)²; from the pupils at (20.5, 20.5) and (30.5, 30.5), with an allowance of 4 px
    /// (a tenth of a 40 px face): the left walk's last skin sample is at s = 14.75 (x = y =
    /// 20.5 − 14.75/√2 = 10.07), its last read at s = 19 (7.07); the right walk's at
    /// s = 27.5 (49.95) and 31.75 (52.95).
    #[test]
    fn a_rolled_faces_walks_run_along_its_pupils_line_and_grow_what_they_read() {
        let (w, h) = (64, 64);
        let mut skin = vec![false; w * h];
        for y in 10..50 {
            for x in 10..50 {
                skin[y * w + x] = true;
            }
        }
        let pupils = [DVec2::new(20.5, 20.5), DVec2::new(30.5, 30.5)];
        let mut used = Rect {
            x0: 20,
            y0: 20,
            x1: 31,
            y1: 31,
        };
        let [left, right] = row_edges(&skin, w, h, pupils, 40.0, &mut used);
        let diagonal = DVec2::ONE / 2f64.sqrt();
        let expected = [
            pupils[0] - diagonal * (14.75 + 0.125),
            pupils[1] + diagonal * (27.5 + 0.125),
        ];
        for (edge, want) in [left, right].iter().zip(expected) {
            assert!(edge.distance(want) < 1e-9, "{edge} against {want}");
        }
        let read = Rect {
            x0: 7,
            y0: 7,
            x1: 53,
            y1: 53,
        };
        assert_eq!(used, read);

        // Skin over the whole image, the right pupil near its bottom edge: the right walk
        // leaves through the bottom border after s = 2 (y = 63.91; at s = 2.25, y = 64.09 is
        // outside, not the row past the image), the left walk through the left border after
        // s = 57.25 (x = 0.02).
        let skin = vec![true; w * h];
        let pupils = [DVec2::new(40.5, 52.5), DVec2::new(50.5, 62.5)];
        let mut used = Rect {
            x0: 40,
            y0: 52,
            x1: 51,
            y1: 63,
        };
        let [left, right] = row_edges(&skin, w, h, pupils, 40.0, &mut used);
        let expected = [
            pupils[0] - diagonal * (57.25 + 0.125),
            pupils[1] + diagonal * (2.0 + 0.125),
        ];
        for (edge, want) in [left, right].iter().zip(expected) {
            assert!(edge.distance(want) < 1e-9, "{edge} against {want}");
        }
        let read = Rect {
            x0: 0,
            y0: 12,
            x1: 52,
            y1: 64,
        };
        assert_eq!(used, read);
    }

    /// Through a lens, the frontal equations run on the pupils undistorted into the pinhole
    /// of the same focal length: a face square to a back camera with strong barrel distortion
    /// (k1 = −0.3), 14 cm right of and 6 cm below its axis, comes back to a micrometre (the
    /// equations are exact for a face parallel to the image). On the distorted pixels
    /// themselves the eye would be 2.8 cm off.
    #[test]
    fn a_lens_back_cameras_pupils_are_undistorted_before_the_equations() {
        use crate::geometry::lens::{Distortion, Lens};
        let (w, h) = (640, 480);
        let pinhole = Camera::look_at(
            DVec3::new(0.3, 1.2, 0.4),
            DVec3::new(0.3, 1.2, -1.0),
            DVec3::Y,
            35f64.to_radians(),
            w,
            h,
        )
        .unwrap();
        let lens = Lens {
            distortion: Distortion::Brown {
                k1: -0.3,
                k2: 0.1,
                k3: 0.0,
                p1: 0.0,
                p2: 0.0,
            },
            ..Lens::pinhole(35f64.to_radians(), w, h)
        };
        let back = Camera::with_lens(pinhole.world_from_camera, lens, w, h).unwrap();
        let eye = back
            .world_from_camera
            .transform_point3(DVec3::new(0.14, -0.06, -0.7));
        let across = back.world_from_camera.transform_vector3(DVec3::X) * 0.032;
        let pupils = [eye - across, eye + across].map(|p| back.project_point(p).unwrap());
        let detection = FaceDetection {
            face_box: [300, 250, 420, 400],
            pupils: pupils.map(|p| p.to_array()),
            pupil_areas_px: [20, 20],
            row_edges: [[0.0; 2]; 2],
            outline_candidates: [[[f64::NAN; 2]; OUTLINE_CANDIDATES]; 2],
            confidence: HeadConfidence::of([300, 250, 420, 400], pupils, [20, 20]),
        };
        let found = eye_from_detection(&detection, &back, 0.064);
        assert!(found.distance(eye) < 1e-6, "{found} against {eye}");
        let read_as_pinhole = eye_from_detection(&detection, &pinhole, 0.064);
        assert!(
            read_as_pinhole.distance(eye) > 0.01,
            "the lens is too weak to tell: {read_as_pinhole}"
        );
    }

    /// Through skin that never ends, each walk stops after 1.5 face widths (15 px for a
    /// 10 px face; the quarter-pixel steps reach 15 exactly), its edge a quarter step beyond.
    #[test]
    fn a_walk_through_endless_skin_stops_at_one_and_a_half_face_widths() {
        let (w, h) = (64, 64);
        let skin = vec![true; w * h];
        let pupils = [DVec2::new(20.5, 30.5), DVec2::new(30.5, 30.5)];
        let mut used = Rect {
            x0: 20,
            y0: 30,
            x1: 31,
            y1: 31,
        };
        let [left, right] = row_edges(&skin, w, h, pupils, 10.0, &mut used);
        assert_eq!(left, DVec2::new(20.5 - 15.125, 30.5));
        assert_eq!(right, DVec2::new(30.5 + 15.125, 30.5));
        let read = Rect {
            x0: 5,
            y0: 30,
            x1: 46,
            y1: 31,
        };
        assert_eq!(used, read);
    }

    /// On a whole detection, the walks' allowance is a tenth of the face's width (its search
    /// box's, 12.4 px): the eye's white beside each pupil (about 5 px of non-skin walked from
    /// the pupil's centre) is crossed, and a patch of skin 20 px beyond the face's right edge
    /// (a hand) is not reached. The face stands 138 px from the image's left edge,
    /// so a width measured from the image's edge, not the box's, moves the edges.
    #[test]
    fn a_whole_detections_walk_allows_a_tenth_of_the_face() {
        let (w, h) = (320, 120);
        let mut frame = Frame::new(w as u32, h as u32);
        let code = |c: [u8; 3]| {
            Vec3::from_array(c.map(|v| crate::util::color::srgb_to_linear(f32::from(v) / 255.0)))
        };
        let (skin, white, pupil) = ([200, 150, 120], [235, 235, 235], [20, 20, 20]);
        let pupils = [DVec2::new(180.5, 55.5), DVec2::new(220.5, 55.5)];
        for y in 0..h {
            for x in 0..w {
                let p = DVec2::new(x as f64 + 0.5, y as f64 + 0.5);
                let in_face = (150..250).contains(&x) && (30..90).contains(&y);
                let in_hand = (270..285).contains(&x) && (45..70).contains(&y);
                let c = if pupils.iter().any(|q| q.distance(p) < 2.0) {
                    code(pupil)
                } else if in_face
                    && (50..62).contains(&y)
                    && ((173..178).contains(&x) || (223..228).contains(&x))
                {
                    code(white)
                } else if in_face || in_hand {
                    code(skin)
                } else {
                    Vec3::ZERO
                };
                frame.color[y * w + x] = c;
            }
        }
        let d = detect(&frame).unwrap();
        assert_eq!(d.face_box, [150, 30, 250, 90]);
        let [left, right] = d.row_edges;
        assert!((left[0] - 150.0).abs() <= 0.25, "left edge {left:?}");
        assert!((right[0] - 250.0).abs() <= 0.25, "right edge {right:?}");
    }

    /// Where the face meets the image's edges, the walks stop there: skin to the left and
    /// right borders on the pupils' row gives the edges 0 and w, and the pixels read stay
    /// inside the image (no column read from the next row, no row below it).
    #[test]
    fn the_row_edges_stop_at_the_images_borders() {
        let (w, h) = (40, 12);
        let mut skin = vec![false; w * h];
        for y in 6..12 {
            for x in 0..w {
                skin[y * w + x] = !(14..16).contains(&x) && !(24..26).contains(&x);
            }
        }
        // The pupils on the bottom row, so that a walk that wandered down would leave the
        // image.
        let pupils = [DVec2::new(15.0, 11.5), DVec2::new(25.0, 11.5)];
        let mut used = Rect {
            x0: 14,
            y0: 11,
            x1: 26,
            y1: 12,
        };
        let [left, right] = row_edges(&skin, w, h, pupils, 20.0, &mut used);
        assert!((left.x - 0.0).abs() <= 0.25 && left.y == 11.5, "{left}");
        assert!(
            (right.x - w as f64).abs() <= 0.25 && right.y == 11.5,
            "{right}"
        );
        assert_eq!(
            used,
            Rect {
                x0: 0,
                y0: 11,
                x1: w,
                y1: 12
            }
        );
    }

    /// A pixel set grows by its 4-neighbours within the image: a pixel on the right or the
    /// bottom edge gains no neighbour across it (not the next row's first pixel, nor a row
    /// below the image), as the brute force over every pixel says.
    #[test]
    fn a_set_grows_by_its_neighbours_within_the_image() {
        let (w, h): (usize, usize) = (7, 5);
        for set in [
            vec![6],
            vec![34],
            vec![13, 14, 20],
            vec![0, 28, 34],
            vec![30],
        ] {
            let brute: Vec<usize> = (0..w * h)
                .filter(|&j| {
                    set.iter().any(|&i| {
                        let (dx, dy) = ((i % w).abs_diff(j % w), (i / w).abs_diff(j / w));
                        dx + dy <= 1
                    })
                })
                .collect();
            assert_eq!(grow(&set, w, h), brute, "{set:?}");
        }
    }

    #[test]
    fn skin_is_told_from_hair_grass_asphalt_and_sky() {
        assert!(is_skin([222, 173, 140]) && is_skin([120, 92, 76]));
        for other in [
            [51, 33, 20],
            [92, 133, 56],
            [128, 128, 131],
            [120, 170, 230],
            [13, 10, 10],
        ] {
            assert!(!is_skin(other), "{other:?}");
        }
    }
}
