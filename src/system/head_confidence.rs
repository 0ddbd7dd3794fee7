//! How far a face detection can be trusted, from what the detector measured in the image
//! alone: the face's size, whether the distance the pupils give agrees with the distance the
//! face's width gives, whether the pupils sit where eyes sit (the face's upper part, about its
//! middle) and whether the two pupil blobs are alike; and, for the ellipsoid face whose
//! orientation is known (it faces the vehicle's forward), how obliquely the back camera sees
//! it.
//!
//! Each cue is scored in [0, 1] by a linear ramp from a "bad" limit (score 0) to a "good"
//! limit (score 1); the confidence is the product of the six scores, so any one cue that
//! fails sinks it. The limits were set on the shipped head (das at 640×480: every score 1)
//! against the slanted-pillar failures of issue 27 (docs/guide/hazards.md).

use glam::DVec2;

/// Confidence below which an estimate is called unreliable (a `warning:`, and an error with
/// `--require-confident-head`).
pub const CONFIDENT_HEAD: f64 = 0.5;

/// Face width over interpupillary distance of the shipped head model (a 0.15 m wide face,
/// pupils 0.064 m apart). Real adults: about 14 cm bizygomatic over 6.3 cm, 2.2.
pub const FACE_OVER_FEATURE: f64 = 0.15 / 0.064;

/// Iris radius over face width of the shipped head model (a 12 mm iris, a 0.15 m face).
pub const IRIS_OVER_FACE: f64 = 0.006 / 0.15;

/// The cue scores and what they were computed from.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
pub struct HeadConfidence {
    /// The product of the six scores below, in [0, 1]; below [`CONFIDENT_HEAD`] the estimate
    /// is unreliable.
    pub value: f64,
    /// Face width in pixels: score 0 at ≤ 12 px, 1 at ≥ 40 px.
    pub face_size: f64,
    /// Agreement of the distance from the pupils (eq. d1 with A) with the distance from the
    /// face width (eq. d1 with [`FACE_OVER_FEATURE`] · A): |ln ratio| 0 at ≥ 0.2, 1 at ≤ 0.06.
    pub distance_agreement: f64,
    /// The lower pupil's height in the face box (0 top, 1 bottom): 1 at ≤ 0.45, 0 at ≥ 0.7.
    pub pupil_height: f64,
    /// The pupils' midpoint off the face box's centre, in face widths: 1 at ≤ 0.35, 0 at
    /// ≥ 0.5 (the head seen from the side shifts it: das has 0.26).
    pub symmetry: f64,
    /// Smaller over larger pupil blob area: 0 at ≤ 0.2, 1 at ≥ 0.5 (with the fit: the smaller
    /// blob over an iris disc, [`HeadConfidence::with_fit`]).
    pub pupil_sizes: f64,
    /// How squarely the back camera sees the face ([`HeadConfidence::with_view`]): 1 at a
    /// view angle ≤ 40°, 0 at ≥ 55° (as the mesh's fitted yaw: beyond, the far pupil slips
    /// behind the head's curve and its centroid is biased); 1 where the angle is not known.
    pub view: f64,
    /// The angle at the face between its front and the direction to the back camera, degrees,
    /// [0, 180]: the ellipsoid face's known orientation against the pupils' rays (`None` for
    /// the mesh face, whose yaw is fitted instead).
    pub view_angle_deg: Option<f64>,
    /// Face box width, pixels.
    pub face_width_px: f64,
    /// Distance from the pupils over distance from the face width (1: they agree).
    pub distance_ratio: f64,
    /// The lower pupil's height in the face box, [0, 1] from the top.
    pub pupil_height_in_face: f64,
    /// |pupils' midpoint − face box centre| / face width.
    pub centre_offset_in_face: f64,
    /// Smaller over larger pupil blob area, (0, 1]; with the fit, the smaller blob's area
    /// over an iris disc's expected area, [0, ∞).
    pub pupil_area_ratio: f64,
    /// Whether the cues are the yaw fit's ([`HeadConfidence::with_fit`]): then
    /// `distance_ratio` holds the outline residual over the face width,
    /// `centre_offset_in_face` the fitted yaw in degrees and `pupil_height_in_face` the fit's
    /// margin.
    pub fitted: bool,
}

/// 0 at `bad`, 1 at `good`, linear between, clamped (either order of the limits).
fn ramp(x: f64, bad: f64, good: f64) -> f64 {
    ((x - bad) / (good - bad)).clamp(0.0, 1.0)
}

impl HeadConfidence {
    /// The cues of a face box `[x0, y0, x1, y1)` and its `pupils` (left, right; pixels).
    pub fn of(face_box: [u32; 4], pupils: [DVec2; 2], areas: [u32; 2]) -> HeadConfidence {
        let [x0, y0, x1, y1] = face_box.map(f64::from);
        let (width, height) = ((x1 - x0).max(1.0), (y1 - y0).max(1.0));
        let feature_px = (pupils[1] - pupils[0]).length().max(1e-9);
        // d ∝ width / pixels (eq. d1): the ratio of the two distances.
        let distance_ratio = width / (FACE_OVER_FEATURE * feature_px);
        let lower = pupils[0].y.max(pupils[1].y);
        let pupil_height_in_face = (lower - y0) / height;
        let mid = (pupils[0] + pupils[1]) / 2.0;
        let centre_offset_in_face = (mid.x - (x0 + x1) / 2.0).abs() / width;
        let (small, large) = (areas[0].min(areas[1]), areas[0].max(areas[1]).max(1));
        let pupil_area_ratio = small as f64 / large as f64;
        let face_size = ramp(width, 12.0, 40.0);
        let distance_agreement = ramp(distance_ratio.ln().abs(), 0.2, 0.06);
        let pupil_height = ramp(pupil_height_in_face, 0.7, 0.45);
        let symmetry = ramp(centre_offset_in_face, 0.5, 0.35);
        let pupil_sizes = ramp(pupil_area_ratio, 0.2, 0.5);
        let mut c = HeadConfidence {
            value: 0.0,
            view: 1.0,
            view_angle_deg: None,
            face_size,
            distance_agreement,
            pupil_height,
            symmetry,
            pupil_sizes,
            face_width_px: width,
            distance_ratio,
            pupil_height_in_face,
            centre_offset_in_face,
            pupil_area_ratio,
            fitted: false,
        };
        c.value = c.product();
        c
    }

    /// The cues once the head's yaw is fitted (`system/head_pose.rs`), which explains the
    /// pupils' foreshortening and their place in the face: the distance cue becomes the
    /// outline's fit (`edge_rms_px`, the outline's RMS residual, over the face's width: 1 at
    /// ≤ 0.015, 0 at ≥ 0.04); the symmetry cue the fitted yaw (1 at |yaw| ≤ 40°, 0 at ≥ 55°:
    /// beyond, the far eye slips behind the nose) times the fit's `margin` (1 at ≥ 0.03, 0 at
    /// 0: another yaw fits as well); the pupil-height cue is set to 1 (the mesh's skin region
    /// includes its neck).
    /// In this form `distance_ratio` holds the residual over the face width,
    /// `centre_offset_in_face` the fitted yaw in degrees and `pupil_height_in_face` the margin.
    ///
    /// The pupil-size cue becomes the smaller pupil blob's area over an iris disc's expected
    /// area (a 12 mm iris on the 150 mm face: radius [`IRIS_OVER_FACE`] face widths), 0 at
    /// ≤ 0.25, 1 at ≥ 0.35: an iris under a third of its size is half hidden by a lid or the
    /// nose, and its centroid is biased (the ratio is held in `pupil_area_ratio`).
    pub fn with_fit(
        &self,
        edge_rms_px: f64,
        yaw_deg: f64,
        margin: f64,
        smaller_pupil_px: u32,
    ) -> Self {
        let mut c = *self;
        let iris_disc = std::f64::consts::PI * (IRIS_OVER_FACE * self.face_width_px).powi(2);
        c.pupil_area_ratio = f64::from(smaller_pupil_px) / iris_disc;
        c.pupil_sizes = ramp(c.pupil_area_ratio, 0.25, 0.35);
        c.distance_ratio = edge_rms_px / self.face_width_px;
        c.distance_agreement = ramp(c.distance_ratio, 0.04, 0.015);
        c.centre_offset_in_face = yaw_deg;
        c.pupil_height_in_face = margin;
        c.symmetry = ramp(yaw_deg.abs(), 55.0, 40.0) * ramp(margin, 0.0, 0.03);
        c.pupil_height = 1.0;
        c.fitted = true;
        c.value = c.product();
        c
    }

    /// The cues with the view angle of a face of known orientation (`view_angle_deg`, the
    /// angle at the face between its front and the back camera, degrees): the frontal
    /// equations are corrected for the camera's own yaw and pitch (`eye_facing` in
    /// `system/head.rs`), but not for a far pupil the head's curve half hides.
    pub fn with_view(&self, view_angle_deg: f64) -> Self {
        let mut c = *self;
        c.view_angle_deg = Some(view_angle_deg);
        c.view = ramp(view_angle_deg, 55.0, 40.0);
        c.value = c.product();
        c
    }

    /// The product of the six scores: any one of them at 0 sinks it.
    fn product(&self) -> f64 {
        self.face_size
            * self.distance_agreement
            * self.pupil_height
            * self.symmetry
            * self.pupil_sizes
            * self.view
    }

    /// Whether the estimate can be relied on (confidence ≥ [`CONFIDENT_HEAD`]).
    pub fn is_confident(&self) -> bool {
        self.is_confident_at(CONFIDENT_HEAD)
    }

    /// Whether the estimate can be relied on under the user's threshold `min` in [0, 1]
    /// (a run's `min_head_confidence`).
    pub fn is_confident_at(&self, min: f64) -> bool {
        self.value >= min
    }

    /// The cues that scored below 1, in words, e.g. "a pupil at 63% of the face's height".
    pub fn doubts(&self) -> String {
        let pct = |x: f64| format!("{:.0}%", 100.0 * x);
        let mut out = Vec::new();
        if self.face_size < 1.0 {
            out.push(format!("the face only {:.0} px wide", self.face_width_px));
        }
        if self.distance_agreement < 1.0 && self.fitted {
            out.push(format!(
                "the head's outline off the fitted pose by {} of the face's width",
                pct(self.distance_ratio)
            ));
        } else if self.distance_agreement < 1.0 {
            out.push(format!(
                "the distance from the pupils {} of the distance from the face width",
                pct(self.distance_ratio)
            ));
        }
        if self.symmetry < 1.0 && self.fitted && self.pupil_height_in_face < 0.03 {
            out.push(format!(
                "another yaw fits the outline nearly as well (margin {:.3} of the face's width)",
                self.pupil_height_in_face
            ));
        }
        if self.pupil_height < 1.0 {
            out.push(format!(
                "a pupil at {} of the face's height (eyes sit in its upper half)",
                pct(self.pupil_height_in_face)
            ));
        }
        if self.symmetry < 1.0 && self.fitted && self.centre_offset_in_face.abs() > 40.0 {
            out.push(format!(
                "a fitted yaw of {:.0}°",
                self.centre_offset_in_face
            ));
        } else if self.symmetry < 1.0 && !self.fitted {
            out.push(format!(
                "the pupils' midpoint {} of the face's width off its centre",
                pct(self.centre_offset_in_face)
            ));
        }
        if let (true, Some(angle)) = (self.view < 1.0, self.view_angle_deg) {
            out.push(format!(
                "the face seen {angle:.0}° off its front (beyond 40° the far pupil is half hidden)"
            ));
        }
        if self.pupil_sizes < 1.0 && self.fitted {
            out.push(format!(
                "a pupil blob only {} of an iris's area (half hidden by a lid or the nose)",
                pct(self.pupil_area_ratio)
            ));
        } else if self.pupil_sizes < 1.0 {
            out.push(format!(
                "one pupil blob {} the size of the other",
                pct(self.pupil_area_ratio)
            ));
        }
        out.join(", ")
    }

    /// The one-line `warning:` text for an unreliable estimate (without the prefix).
    pub fn warning(&self, context: &str) -> String {
        self.warning_at(context, CONFIDENT_HEAD)
    }

    /// [`Self::warning`] under the threshold `min`.
    pub fn warning_at(&self, context: &str, min: f64) -> String {
        format!(
            "{context}head estimate unreliable: confidence {:.2} < {} ({}); the eye may be centimetres off (option `require_confident_head` makes this an error)",
            self.value,
            crate::util::number::short(min),
            self.doubts()
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn das_like() -> ([u32; 4], [DVec2; 2], [u32; 2]) {
        // das at 640×480: a 91×86 px face, pupils 38.6 px apart at 29% of its height.
        (
            [85, 352, 176, 438],
            [DVec2::new(87.2, 377.3), DVec2::new(125.8, 377.6)],
            [40, 44],
        )
    }

    /// The six frontal scores of `c`, named, in the order of the product.
    fn scores(c: &HeadConfidence) -> [(&'static str, f64); 6] {
        [
            ("face_size", c.face_size),
            ("distance_agreement", c.distance_agreement),
            ("pupil_height", c.pupil_height),
            ("symmetry", c.symmetry),
            ("pupil_sizes", c.pupil_sizes),
            ("view", c.view),
        ]
    }

    /// Which of the sentences of [`HeadConfidence::doubts`] `c` gets, each by a phrase of it.
    fn sentences(c: &HeadConfidence) -> Vec<&'static str> {
        const PHRASES: [&str; 10] = [
            "px wide",
            "outline off the fitted pose",
            "distance from the pupils",
            "another yaw",
            "of the face's height",
            "a fitted yaw",
            "midpoint",
            "off its front",
            "of an iris's area",
            "the size of the other",
        ];
        let doubts = c.doubts();
        PHRASES.into_iter().filter(|p| doubts.contains(p)).collect()
    }

    /// `cue` alone failed: its score 0, every other score 1, the confidence below
    /// [`CONFIDENT_HEAD`] (a product that left that cue out would be caught here), and the
    /// warning names that cue alone, in the `sentence` that contains the given phrase.
    fn sunk_by_alone(c: &HeadConfidence, cue: &str, sentence: &str) {
        for (name, score) in scores(c) {
            let expected = if name == cue { 0.0 } else { 1.0 };
            assert_eq!(score, expected, "{name} with {cue} failing: {c:?}");
        }
        assert!(
            c.value < CONFIDENT_HEAD && !c.is_confident(),
            "{cue} alone should sink the confidence: {c:?}"
        );
        assert_eq!(sentences(c), [sentence], "{cue}: {}", c.doubts());
    }

    #[test]
    fn a_well_seen_face_is_trusted_and_each_cue_alone_sinks_it() {
        let (b, p, a) = das_like();
        let c = HeadConfidence::of(b, p, a);
        assert!(c.value > 0.95 && c.is_confident(), "{c:?}");
        assert_eq!(c.doubts(), "", "every score 1: nothing to doubt");
        assert!((c.distance_ratio - 91.0 / (FACE_OVER_FEATURE * 38.6)).abs() < 1e-3);
        // das's own view angle (29°) changes nothing.
        assert_eq!(c.with_view(29.0).value, c.value);
        // Tiny face (same proportions, a sixth the size).
        let small = HeadConfidence::of(
            [0, 0, 15, 14],
            [DVec2::new(0.4, 4.0), DVec2::new(6.8, 4.0)],
            a,
        );
        assert!(small.face_size < 0.2 && !small.is_confident(), "{small:?}");
        let tiny = HeadConfidence::of(
            [0, 0, 12, 12],
            [DVec2::new(1.0, 3.0), DVec2::new(6.1, 3.0)],
            a,
        );
        sunk_by_alone(&tiny, "face_size", "px wide");
        // Pupils 30% closer than the face's width says: the distances disagree.
        let close = [p[0], p[0] + (p[1] - p[0]) * 0.7];
        sunk_by_alone(
            &HeadConfidence::of(b, close, a),
            "distance_agreement",
            "distance from the pupils",
        );
        // "Pupils" near the chin (both: one alone would also lengthen their distance).
        let chin = 352.0 + 0.8 * 86.0;
        let low = [DVec2::new(p[0].x, chin), DVec2::new(p[1].x, chin)];
        let c = HeadConfidence::of(b, low, a);
        sunk_by_alone(&c, "pupil_height", "of the face's height");
        assert!(
            c.doubts().contains("of the face's height"),
            "{}",
            c.doubts()
        );
        // Both pupils at the face's right edge.
        let right = [DVec2::new(170.0, 377.0), DVec2::new(208.6, 377.0)];
        sunk_by_alone(&HeadConfidence::of(b, right, a), "symmetry", "midpoint");
        // One blob a sixth of the other.
        sunk_by_alone(
            &HeadConfidence::of(b, p, [8, 48]),
            "pupil_sizes",
            "the size of the other",
        );
        // The face seen 60° off its front (a camera far to its side).
        let c = HeadConfidence::of(b, p, a).with_view(60.0);
        sunk_by_alone(&c, "view", "off its front");
        assert!(c.doubts().contains("60° off its front"), "{}", c.doubts());
        // The ramp's limits: 1 up to 40°, 0 from 55°.
        assert_eq!(HeadConfidence::of(b, p, a).with_view(40.0).view, 1.0);
        assert_eq!(HeadConfidence::of(b, p, a).with_view(55.0).view, 0.0);
    }

    #[test]
    fn a_good_yaw_fit_is_trusted_and_each_of_its_cues_alone_sinks_it() {
        let (b, p, a) = das_like();
        let c = HeadConfidence::of(b, p, a);
        // The good fit: outline 1% of the 91 px face off, 20° of yaw, a 0.05 margin, the
        // smaller pupil 40 px (an iris disc there: π (0.04 · 91)² = 41.6 px²).
        let (rms, yaw, margin, iris) = (0.91, 20.0, 0.05, 40);
        let good = c.with_fit(rms, yaw, margin, iris);
        assert!(good.fitted && good.value == 1.0, "{good:?}");
        assert_eq!(good.doubts(), "", "every score 1: nothing to doubt");
        // The outline 5% of the face's width off the fitted pose.
        sunk_by_alone(
            &c.with_fit(0.05 * 91.0, yaw, margin, iris),
            "distance_agreement",
            "outline off the fitted pose",
        );
        // A fitted yaw of 60°: beyond 55° the far eye is behind the nose.
        sunk_by_alone(
            &c.with_fit(rms, 60.0, margin, iris),
            "symmetry",
            "a fitted yaw",
        );
        sunk_by_alone(
            &c.with_fit(rms, -60.0, margin, iris),
            "symmetry",
            "a fitted yaw",
        );
        // Another yaw fits as well (no margin).
        let c0 = c.with_fit(rms, yaw, 0.0, iris);
        sunk_by_alone(&c0, "symmetry", "another yaw");
        assert!(c0.doubts().contains("another yaw"), "{}", c0.doubts());
        // The smaller pupil an eighth of an iris disc: half hidden by a lid.
        sunk_by_alone(
            &c.with_fit(rms, yaw, margin, 5),
            "pupil_sizes",
            "of an iris's area",
        );
    }

    #[test]
    fn the_view_angle_is_a_doubt_only_where_it_lowers_the_confidence() {
        let (face_box, pupils, areas) = das_like();
        let c = HeadConfidence::of(face_box, pupils, areas);
        // At 40° and below the far pupil is seen whole: a full score, no word of it.
        for angle in [0.0, 20.0, 40.0] {
            let seen = c.with_view(angle);
            assert_eq!(seen.view, 1.0);
            assert!(
                !seen.doubts().contains("off its front"),
                "{}",
                seen.doubts()
            );
        }
        let far = c.with_view(50.0);
        assert!(far.view < 1.0);
        assert!(
            far.doubts().contains("the face seen 50° off its front"),
            "{}",
            far.doubts()
        );
    }

    #[test]
    fn the_warning_names_each_cue_only_below_its_full_score() {
        let (b, p, a) = das_like();
        let c = HeadConfidence::of(b, p, a);
        // Just below each full score, its sentence alone: the face 39 px wide (every
        // proportion kept), the distances' ratio e^0.065, the pupils at 46% of the
        // face's height, their midpoint 0.36 face widths off centre, one blob 0.49 of the
        // other, the face seen 41° off its front.
        let scale = 39.0 / 91.0;
        let scaled = |v: DVec2| (v - DVec2::new(85.0, 352.0)) * scale;
        let narrow = HeadConfidence::of([0, 0, 39, 37], p.map(scaled), a);
        let apart = [
            p[0],
            p[0] + (p[1] - p[0]) * c.distance_ratio * (-0.065f64).exp(),
        ];
        let lower = p.map(|v| DVec2::new(v.x, 352.0 + 0.46 * 86.0));
        // The midpoint moved to `offset` face widths right of the box's centre (x = 130.5).
        let off_centre = |q: [DVec2; 2], offset: f64| {
            let shift = 130.5 + offset * 91.0 - (q[0].x + q[1].x) / 2.0;
            q.map(|v| v + DVec2::new(shift, 0.0))
        };
        let aside = off_centre(p, 0.36);
        for (case, c, cue, sentence) in [
            ("narrow", narrow, "face_size", "px wide"),
            (
                "apart",
                HeadConfidence::of(b, apart, a),
                "distance_agreement",
                "distance from the pupils",
            ),
            (
                "lower",
                HeadConfidence::of(b, lower, a),
                "pupil_height",
                "of the face's height",
            ),
            (
                "aside",
                HeadConfidence::of(b, aside, a),
                "symmetry",
                "midpoint",
            ),
            (
                "blobs",
                HeadConfidence::of(b, p, [49, 100]),
                "pupil_sizes",
                "the size of the other",
            ),
            ("view", c.with_view(41.0), "view", "off its front"),
        ] {
            for (name, score) in scores(&c) {
                let below = name == cue;
                assert!(
                    if below {
                        score > 0.9 && score < 1.0
                    } else {
                        score == 1.0
                    },
                    "{case}: {name} = {score}: {c:?}"
                );
            }
            assert_eq!(sentences(&c), [sentence], "{case}: {}", c.doubts());
        }
        // Pupils high in the face box (2% of its height) are not the fit's margin: no doubt,
        // and off centre, the midpoint's sentence alone.
        let high = p.map(|v| DVec2::new(v.x, 352.0 + 0.02 * 86.0));
        assert_eq!(HeadConfidence::of(b, high, a).doubts(), "");
        let high_aside = off_centre(high, 0.4);
        assert_eq!(
            sentences(&HeadConfidence::of(b, high_aside, a)),
            ["midpoint"]
        );
        // The fit: a yaw of 50° with a margin of exactly 0.03 (a full margin score) is
        // doubted for its yaw alone; the outline just off, for the outline alone.
        let (rms, margin, iris) = (0.91, 0.05, 40);
        let turned = c.with_fit(rms, 50.0, 0.03, iris);
        assert!(turned.symmetry > 0.0 && turned.symmetry < 1.0, "{turned:?}");
        assert_eq!(sentences(&turned), ["a fitted yaw"]);
        let rough = c.with_fit(0.016 * 91.0, 20.0, margin, iris);
        assert!(rough.distance_agreement < 1.0, "{rough:?}");
        assert_eq!(sentences(&rough), ["outline off the fitted pose"]);
        // A yaw of exactly 40° is not doubted, whatever else lowers the symmetry score.
        let at_limit = c.with_fit(rms, 40.0, 0.02, iris);
        assert!(at_limit.symmetry < 1.0, "{at_limit:?}");
        assert_eq!(sentences(&at_limit), ["another yaw"]);
        // The warning: the context, the value against the threshold, the doubts.
        let warning = turned.warning("at t = 1 s: ");
        let expected = format!(
            "at t = 1 s: head estimate unreliable: confidence {:.2} < 0.5 ({});",
            turned.value,
            turned.doubts()
        );
        assert!(warning.starts_with(&expected), "{warning}");
    }

    #[test]
    fn ramps_are_linear_between_their_limits() {
        assert_eq!(ramp(26.0, 12.0, 40.0), 0.5);
        assert!((ramp(0.13, 0.2, 0.06) - 0.5).abs() < 1e-12);
        assert_eq!(ramp(-1.0, 0.2, 0.06), 1.0);
        assert_eq!(ramp(100.0, 12.0, 40.0), 1.0);
    }
}
