//! Hazard visibility: does the driver see the road user the pillar hides? For every object
//! marked `hazard = true`, among its truth pixels that lie where the driver sees the display
//! (hidden by the pillar), the fraction that the see-through view shows as that same object
//! within a misregistration bound, and how far the shown object's centroid is from where it
//! truly is.

use serde_json::json;

use crate::geometry::camera::Camera;
use crate::measure::luminance::WEBER_THRESHOLD;
use crate::measure::metrics::MetricMaps;
use crate::render::frame::Frame;
use crate::render::frame_over::FrameView;
use crate::render::integrator::RenderContext;
use crate::scene::Scene;
use crate::system::pipeline::RunResult;
use crate::util::color::luminance;

/// Default bound of `--hazard-bound-arcmin`: a pixel counts as showing the hazard when the
/// shown point is within this angle of the true one, arc-minutes.
pub const HAZARD_BOUND_ARCMIN: f64 = 30.0;

/// One hazard object in one frame.
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct HazardFrame {
    pub name: String,
    /// Object id (scene object index + 1).
    pub id: u32,
    /// Its pixels in the truth view.
    pub truth_pixels: u64,
    /// Of those, the pixels where the driver sees the display instead (hidden by the pillar).
    pub hidden_pixels: u64,
    /// Of the hidden pixels, those the see-through view shows as this object within the bound.
    pub shown_pixels: u64,
    /// shown / hidden, [0, 1]; NaN when nothing of it is hidden (then it is not counted).
    pub visibility: f64,
    /// Angle between the centroid of its hidden truth pixels and the centroid of the display
    /// pixels that show it (any misregistration), arc-minutes, at the view's central pixel
    /// pitch; NaN when either set is empty.
    pub centroid_error_arcmin: f64,
    /// Its luminance contrast, in a scene lit in physical units (`None` in any other).
    pub contrast: Option<HazardContrast>,
}

/// A hazard's luminance contrast against its surround where the display hides it: the
/// surround is the display region's pixels that do not show it (in the truth and in the
/// see-through view, each its own). Weber contrasts (Y_object − Y_surround) / Y_surround,
/// signed: negative for a dark pedestrian on a brighter road.
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct HazardContrast {
    /// The mean over its hidden truth pixels against the truth's surround; NaN without them.
    pub truth: f64,
    /// The mean over the display pixels that show it against the display's surround; NaN
    /// when the display shows none of it.
    pub seethru: f64,
    /// Of the shown pixels (within the bound), those whose own contrast against the
    /// display's surround clears [`WEBER_THRESHOLD`]: a driver can tell them from it.
    pub visible_pixels: u64,
    /// visible / hidden pixels, [0, 1]; NaN when nothing of it is hidden.
    pub visibility: f64,
}

/// The hazards of one frame: `truth` and `seethru` are the driver views, `maps` the metric
/// maps of the same frame (display mask, misregistration), `arcmin_per_px` the view's angle
/// per pixel at its centre.
pub fn hazard_frame(
    scene: &Scene,
    truth: &Frame,
    seethru: FrameView<'_>,
    maps: &MetricMaps,
    bound_arcmin: f64,
    arcmin_per_px: f64,
) -> Vec<HazardFrame> {
    let w = truth.width as usize;
    let mut out = Vec::new();
    for (index, object) in scene.objects.iter().enumerate() {
        if !object.hazard {
            continue;
        }
        let id = index as u32 + 1;
        let shows_it = |i| seethru.get(|f| &f.object_id, i) == id;
        let (mut truth_pixels, mut hidden, mut shown) = (0u64, 0u64, 0u64);
        let (mut hidden_sum, mut shown_sum, mut shown_any) = ([0.0f64; 2], [0.0f64; 2], 0u64);
        for i in 0..truth.object_id.len() {
            // Pixel corners: the half pixel to their centres cancels in the centroids' gap.
            let at = [(i % w) as f64, (i / w) as f64];
            if maps.display[i] && shows_it(i) {
                shown_any += 1;
                shown_sum = [shown_sum[0] + at[0], shown_sum[1] + at[1]];
            }
            if truth.object_id[i] != id {
                continue;
            }
            truth_pixels += 1;
            if !maps.display[i] {
                continue;
            }
            hidden += 1;
            hidden_sum = [hidden_sum[0] + at[0], hidden_sum[1] + at[1]];
            let error = maps.misregistration[i] as f64;
            if shows_it(i) && error <= bound_arcmin {
                shown += 1;
            }
        }
        let contrast = scene
            .photometry
            .as_ref()
            .map(|_| hazard_contrast(id, truth, seethru, maps, bound_arcmin, hidden));
        let centroid_error_arcmin = if hidden > 0 && shown_any > 0 {
            let (h, s) = (hidden as f64, shown_any as f64);
            let dx = hidden_sum[0] / h - shown_sum[0] / s;
            let dy = hidden_sum[1] / h - shown_sum[1] / s;
            dx.hypot(dy) * arcmin_per_px
        } else {
            f64::NAN
        };
        out.push(HazardFrame {
            name: object.name.clone(),
            id,
            truth_pixels,
            hidden_pixels: hidden,
            shown_pixels: shown,
            visibility: if hidden > 0 {
                shown as f64 / hidden as f64
            } else {
                f64::NAN
            },
            centroid_error_arcmin,
            contrast,
        });
    }
    out
}

/// [`HazardContrast`] of object `id`, `hidden` of whose truth pixels the display hides.
fn hazard_contrast(
    id: u32,
    truth: &Frame,
    seethru: FrameView<'_>,
    maps: &MetricMaps,
    bound_arcmin: f64,
    hidden: u64,
) -> HazardContrast {
    // Sums of luminance over (object, surround) in each view, display pixels only.
    let (mut t, mut s) = ([0.0f64; 2], [0.0f64; 2]);
    let (mut tn, mut sn) = ([0u64; 2], [0u64; 2]);
    for i in (0..truth.object_id.len()).filter(|&i| maps.display[i]) {
        let k = usize::from(truth.object_id[i] != id);
        t[k] += f64::from(luminance(truth.color[i]));
        tn[k] += 1;
        let k = usize::from(seethru.get(|f| &f.object_id, i) != id);
        s[k] += f64::from(luminance(seethru.get(|f| &f.color, i)));
        sn[k] += 1;
    }
    let weber = |sum: [f64; 2], n: [u64; 2]| {
        let (object, surround) = (sum[0] / n[0] as f64, sum[1] / n[1] as f64);
        (object - surround) / surround
    };
    let surround = s[1] / sn[1] as f64;
    let visible_pixels = (0..truth.object_id.len())
        .filter(|&i| {
            maps.display[i]
                && truth.object_id[i] == id
                && seethru.get(|f| &f.object_id, i) == id
                && maps.misregistration[i] as f64 <= bound_arcmin
        })
        .filter(|&i| {
            let y = f64::from(luminance(seethru.get(|f| &f.color, i)));
            ((y - surround) / surround).abs() >= WEBER_THRESHOLD
        })
        .count() as u64;
    HazardContrast {
        truth: weber(t, tn),
        seethru: weber(s, sn),
        visible_pixels,
        visibility: match hidden {
            0 => f64::NAN,
            h => visible_pixels as f64 / h as f64,
        },
    }
}

/// The `hazards` block of metrics.json.
pub fn hazards_json(hazards: &[HazardFrame], bound_arcmin: f64) -> serde_json::Value {
    json!({
        "bound_arcmin": bound_arcmin,
        "definition": "per object with hazard = true: of its truth pixels where the driver sees the display (hidden by the pillar), the fraction the seethru view shows as the same object id within bound_arcmin of misregistration; visibility is null (NaN) when nothing of it is hidden",
        "objects": hazards.iter().map(|h| {
            let mut object = json!({
                "name": h.name,
                "id": h.id,
                "truth_pixels": h.truth_pixels,
                "hidden_pixels": h.hidden_pixels,
                "shown_pixels": h.shown_pixels,
                "visibility": h.visibility.is_finite().then_some(h.visibility),
                "centroid_error_arcmin": h.centroid_error_arcmin.is_finite().then_some(h.centroid_error_arcmin),
            });
            if let Some(c) = &h.contrast {
                object["contrast"] = json!({
                    "truth": c.truth.is_finite().then_some(c.truth),
                    "seethru": c.seethru.is_finite().then_some(c.seethru),
                    "visible_pixels": c.visible_pixels,
                    "visibility": c.visibility.is_finite().then_some(c.visibility),
                    "weber_threshold": WEBER_THRESHOLD,
                });
            }
            object
        }).collect::<Vec<_>>(),
    })
}

/// A hazard counts as hidden from the driver in a frame when the driver sees less than this
/// fraction of its truth pixels (see [`HazardSeen`]).
pub const HIDDEN_BELOW: f64 = 0.5;

/// One hazard in one frame of a sequence: [`HazardFrame`] and what the driver sees of it with
/// the display on and off. Every count is over the truth pixels the frame rendered (the
/// sequence's window around the pillar, or the whole view with full frames).
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct HazardSeen {
    pub frame: HazardFrame,
    /// Its truth pixels where the `occluded` view (display off) shows the same object.
    pub seen_off_pixels: u64,
    /// Its truth pixels where the `seethru` view shows the same object, within the bound of
    /// misregistration where the driver sees the display (the display's shown pixels plus
    /// those the pillar does not cover).
    pub seen_on_pixels: u64,
}

impl HazardSeen {
    /// seen_off / truth, [0, 1]; NaN when it is not in the view.
    pub fn seen_off(&self) -> f64 {
        ratio(self.seen_off_pixels, self.frame.truth_pixels)
    }
    /// seen_on / truth, [0, 1]; NaN when it is not in the view.
    pub fn seen_on(&self) -> f64 {
        ratio(self.seen_on_pixels, self.frame.truth_pixels)
    }
    /// Hidden from the driver with the display off: in the view, and less than
    /// [`HIDDEN_BELOW`] of it seen in the `occluded` view.
    pub fn hidden_off(&self) -> bool {
        self.frame.truth_pixels > 0 && self.seen_off() < HIDDEN_BELOW
    }
    /// Hidden from the driver with the display on: in the view, and less than
    /// [`HIDDEN_BELOW`] of it seen in the `seethru` view.
    pub fn hidden_on(&self) -> bool {
        self.frame.truth_pixels > 0 && self.seen_on() < HIDDEN_BELOW
    }
    /// Visible on the display: the display shows at least [`HIDDEN_BELOW`] of the pixels the
    /// pillar hides (visibility ≥ 0.5).
    pub fn visible_on_display(&self) -> bool {
        self.frame.visibility >= HIDDEN_BELOW
    }
}

fn ratio(a: u64, b: u64) -> f64 {
    if b == 0 {
        f64::NAN
    } else {
        a as f64 / b as f64
    }
}

/// [`hazard_frame`] with what the driver sees with the display on (`seethru`) and off
/// (`occluded`).
pub fn hazard_seen(
    scene: &Scene,
    [truth, seethru, occluded]: [&Frame; 3],
    maps: &MetricMaps,
    bound_arcmin: f64,
    arcmin_per_px: f64,
) -> Vec<HazardSeen> {
    hazard_frame(
        scene,
        truth,
        seethru.into(),
        maps,
        bound_arcmin,
        arcmin_per_px,
    )
    .into_iter()
    .map(|frame| {
        let id = frame.id;
        let (mut off, mut on) = (0u64, 0u64);
        for i in 0..truth.object_id.len() {
            if truth.object_id[i] != id {
                continue;
            }
            off += u64::from(occluded.object_id[i] == id);
            let within = !maps.display[i] || maps.misregistration[i] as f64 <= bound_arcmin;
            on += u64::from(seethru.object_id[i] == id && within);
        }
        HazardSeen {
            frame,
            seen_off_pixels: off,
            seen_on_pixels: on,
        }
    })
    .collect()
}

/// One hazard over a sequence: when it was first hidden and first shown, and its longest
/// hidden stretch with the display on and off.
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct HazardTimes {
    pub name: String,
    /// Display time of the first frame hidden with the display off, s (`None`: never).
    pub first_hidden_s: Option<f64>,
    /// Display time of the first frame visible on the display, s (`None`: never).
    pub first_visible_on_display_s: Option<f64>,
    /// Longest run of consecutive hidden frames × the frame period, s.
    pub longest_hidden_display_on_s: f64,
    pub longest_hidden_display_off_s: f64,
    /// Frames hidden with the display on and off, and frames it is not in the view at all
    /// (not counted as hidden).
    pub frames_hidden_on: usize,
    pub frames_hidden_off: usize,
    pub frames_out_of_view: usize,
}

/// The times of every hazard over frames at display times `t[k]` (`seen[k]` the frame's
/// hazards, in the same order each frame), `period` s apart.
pub fn hazard_times(t: &[f64], seen: &[Vec<HazardSeen>], period: f64) -> Vec<HazardTimes> {
    let count = seen.first().map_or(0, Vec::len);
    (0..count)
        .map(|h| {
            let of = |k: usize| &seen[k][h];
            let first =
                |p: &dyn Fn(&HazardSeen) -> bool| (0..t.len()).find(|&k| p(of(k))).map(|k| t[k]);
            let longest = |p: &dyn Fn(&HazardSeen) -> bool| {
                let (mut best, mut run) = (0usize, 0usize);
                for k in 0..t.len() {
                    run = if p(of(k)) { run + 1 } else { 0 };
                    best = best.max(run);
                }
                best as f64 * period
            };
            let frames =
                |p: &dyn Fn(&HazardSeen) -> bool| (0..t.len()).filter(|&k| p(of(k))).count();
            HazardTimes {
                name: of(0).frame.name.clone(),
                first_hidden_s: first(&HazardSeen::hidden_off),
                first_visible_on_display_s: first(&HazardSeen::visible_on_display),
                longest_hidden_display_on_s: longest(&HazardSeen::hidden_on),
                longest_hidden_display_off_s: longest(&HazardSeen::hidden_off),
                frames_hidden_on: frames(&HazardSeen::hidden_on),
                frames_hidden_off: frames(&HazardSeen::hidden_off),
                frames_out_of_view: frames(&|s| s.frame.truth_pixels == 0),
            }
        })
        .collect()
}

/// [`hazards_json`] of a run's driver views (`driver`: their camera) at `bound_arcmin`: what
/// `run` writes as hazards.json and every `compare` row carries.
pub fn run_hazards_json(
    ctx: &RenderContext,
    driver: &Camera,
    result: &RunResult,
    maps: &MetricMaps,
    bound_arcmin: f64,
) -> serde_json::Value {
    let hazards = hazard_frame(
        &ctx.scene,
        &result.truth,
        FrameView::Over(&result.seethru),
        maps,
        bound_arcmin,
        driver.central_pixel_arcmin(),
    );
    hazards_json(&hazards, bound_arcmin)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A 4 × 3 frame of left_turn's pedestrian (P) and cyclist (C, nowhere in the truth),
    /// by hand. Display columns x ≥ 1, misregistration 0.5′ but at (1,1) 1′ and (2,1) 100′.
    /// Truth P at (0,0), (1,0), (1,1), (2,1), (3,1), (0,2): 6 pixels, 4 hidden. The
    /// see-through view shows P at (0,0), (1,1), (2,1), (3,1) and (2,2); the occluded view
    /// at (0,0), (1,0) and (0,2).
    #[test]
    fn hazards_count_hidden_and_shown_pixels_and_their_centroids_by_hand() {
        let scene = Scene::bundled("left_turn.toml");
        let id_of =
            |name: &str| scene.objects.iter().position(|o| o.name == name).unwrap() as u32 + 1;
        let (p, cyclist) = (id_of("pedestrian"), id_of("cyclist"));
        let (w, h) = (4u32, 3u32);
        let at = |x: u32, y: u32| (y * w + x) as usize;
        let mut truth = Frame::new(w, h);
        let mut seethru = Frame::new(w, h);
        let mut occluded = Frame::new(w, h);
        for (x, y) in [(0, 0), (1, 0), (1, 1), (2, 1), (3, 1), (0, 2)] {
            truth.object_id[at(x, y)] = p;
        }
        for (x, y) in [(0, 0), (1, 1), (2, 1), (3, 1), (2, 2)] {
            seethru.object_id[at(x, y)] = p;
        }
        for (x, y) in [(0, 0), (1, 0), (0, 2)] {
            occluded.object_id[at(x, y)] = p;
        }
        let n = (w * h) as usize;
        let display = (0..n).map(|i| i % w as usize >= 1).collect();
        let mut maps = MetricMaps::of_masks([w, h], vec![f32::NAN; n], display, vec![false; n]);
        for i in 0..n {
            if maps.display[i] {
                maps.misregistration[i] = 0.5;
            }
        }
        maps.misregistration[at(1, 1)] = 1.0;
        maps.misregistration[at(2, 1)] = 100.0;
        let (bound, arcmin_per_px) = (10.0, 2.0);
        let seen = hazard_seen(
            &scene,
            [&truth, &seethru, &occluded],
            &maps,
            bound,
            arcmin_per_px,
        );
        let names: Vec<&str> = seen.iter().map(|s| s.frame.name.as_str()).collect();
        assert_eq!(names, ["pedestrian", "cyclist"]);
        let ped = &seen[0];
        assert_eq!(ped.frame.id, p);
        // Shown within the bound: (1,1) and (3,1), half the hidden pixels.
        assert_eq!(
            [
                ped.frame.truth_pixels,
                ped.frame.hidden_pixels,
                ped.frame.shown_pixels
            ],
            [6, 4, 2]
        );
        assert_eq!(ped.frame.visibility, 0.5);
        // Pixel corners: hidden (1,0), (1,1), (2,1), (3,1); shown anywhere on the display
        // (1,1), (2,1), (3,1), (2,2).
        let hidden: [f64; 2] = [7.0 / 4.0, 3.0 / 4.0];
        let shown = [2.0, 5.0 / 4.0];
        let px = (hidden[0] - shown[0]).hypot(hidden[1] - shown[1]);
        assert!((ped.frame.centroid_error_arcmin - px * arcmin_per_px).abs() < 1e-12);
        // Seen with the display off: (0,0), (1,0), (0,2); on: (0,0) beside the display, and
        // (1,1), (3,1) within the bound. Half of it seen is not hidden, and half of its
        // hidden pixels shown is visible on the display.
        assert_eq!([ped.seen_off_pixels, ped.seen_on_pixels], [3, 3]);
        assert_eq!([ped.seen_off(), ped.seen_on()], [0.5, 0.5]);
        assert!(!ped.hidden_off() && !ped.hidden_on() && ped.visible_on_display());
        let c = &seen[1];
        assert_eq!(c.frame.id, cyclist);
        assert_eq!([c.frame.truth_pixels, c.seen_on_pixels], [0, 0]);
        assert!(c.frame.visibility.is_nan() && c.frame.centroid_error_arcmin.is_nan());
        assert!(c.seen_on().is_nan() && !c.hidden_on() && !c.hidden_off());
    }

    /// Seven frames 0.1 s apart by hand: out of view, then hidden with the display off for
    /// three frames (two of them also with it on), seen again, out of view, and hidden once
    /// more with the display on.
    #[test]
    fn hazard_times_follow_the_frames_by_hand() {
        let seen = |truth: u64, off: u64, on: u64, visibility: f64| HazardSeen {
            frame: HazardFrame {
                name: "pedestrian".into(),
                id: 3,
                truth_pixels: truth,
                hidden_pixels: 0,
                shown_pixels: 0,
                visibility,
                centroid_error_arcmin: f64::NAN,
                contrast: None,
            },
            seen_off_pixels: off,
            seen_on_pixels: on,
        };
        let frames = [
            seen(0, 0, 0, f64::NAN),
            seen(10, 2, 8, 0.8),
            seen(10, 2, 2, 0.2),
            seen(10, 2, 3, 0.4),
            seen(10, 9, 9, f64::NAN),
            seen(0, 0, 0, f64::NAN),
            seen(10, 9, 1, 0.6),
        ];
        let t: Vec<f64> = (0..7).map(|k| 1.0 + 0.1 * k as f64).collect();
        let per_frame: Vec<Vec<HazardSeen>> = frames.iter().map(|f| vec![f.clone()]).collect();
        let times = hazard_times(&t, &per_frame, 0.1);
        assert_eq!(
            times,
            [HazardTimes {
                name: "pedestrian".into(),
                first_hidden_s: Some(t[1]),
                first_visible_on_display_s: Some(t[1]),
                longest_hidden_display_on_s: 2.0 * 0.1,
                longest_hidden_display_off_s: 3.0 * 0.1,
                frames_hidden_on: 3,
                frames_hidden_off: 3,
                frames_out_of_view: 2,
            }]
        );
    }

    /// The frame of the test above, with luminance: in the truth the pedestrian is 0.2 and
    /// the display's other pixels 1; on the display its pixels are 1, but 1.99 at (3,1), and
    /// the rest 2.
    #[test]
    fn a_hazards_contrast_is_its_weber_contrast_against_the_rest_of_the_display() {
        let (w, h) = (4u32, 3u32);
        let at = |x: u32, y: u32| (y * w + x) as usize;
        let p = 7;
        let (mut truth, mut seethru) = (Frame::new(w, h), Frame::new(w, h));
        let n = (w * h) as usize;
        truth.color = vec![glam::Vec3::ONE; n];
        seethru.color = vec![glam::Vec3::splat(2.0); n];
        for (x, y) in [(0, 0), (1, 0), (1, 1), (2, 1), (3, 1), (0, 2)] {
            truth.object_id[at(x, y)] = p;
            truth.color[at(x, y)] = glam::Vec3::splat(0.2);
        }
        for (x, y) in [(0, 0), (1, 1), (2, 1), (3, 1), (2, 2)] {
            seethru.object_id[at(x, y)] = p;
            seethru.color[at(x, y)] = glam::Vec3::ONE;
        }
        seethru.color[at(3, 1)] = glam::Vec3::splat(1.99);
        let display = (0..n).map(|i| i % w as usize >= 1).collect();
        let mut maps = MetricMaps::of_masks([w, h], vec![0.5; n], display, vec![false; n]);
        maps.misregistration[at(2, 1)] = 100.0;
        let c = hazard_contrast(p, &truth, (&seethru).into(), &maps, 10.0, 4);
        let close = |a: f64, b: f64| (a - b).abs() < 1e-6;
        assert!(close(c.truth, (0.2 - 1.0) / 1.0), "{}", c.truth);
        let shown_mean = (1.0 + 1.0 + 1.99 + 1.0) / 4.0;
        assert!(close(c.seethru, (shown_mean - 2.0) / 2.0), "{}", c.seethru);
        // Shown within the bound: (1,1), a contrast of −0.5, and (3,1), of −0.005: one
        // pixel a driver can tell from the road, a quarter of the hidden ones.
        assert_eq!(c.visible_pixels, 1);
        assert_eq!(c.visibility, 0.25);
    }
}
