//! Where the driver perceives what the display shows, when the compensation's model plane is
//! not the scene plane or its eye is not the driver's: the prediction behind the observed
//! p_cam/p_user of `seethru ratio`.
//!
//! Top view of the paper's configuration (§4.2): lateral positions `x` across the display,
//! depths from the display plane; the frontal camera at the display centre (x = 0, depth 0),
//! its axis along the display normal. The display point `x` shows what the frontal camera
//! sees towards the model point `M(x)`, where the ray from the model's eye through `x` meets
//! the model plane; the driver, looking through `x`, perceives it where the driver's own ray
//! through `x` meets the scene plane. Both maps are affine in `x`, so the perception of a
//! scene-plane point is affine too, and exactly the identity when the model is right (the
//! paper's case, in which the observed widths are its closed forms). Lengths in metres.

/// One see-through configuration, top view. Depths are distances from the display plane.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PerceivedGeometry {
    /// The driver's eye: lateral position, and distance `d1` in front of the display (> 0).
    pub eye_x: f64,
    pub eye_d1: f64,
    /// The eye the compensation uses (the driver's plus the head-tracking error); in front
    /// of the display (> 0).
    pub model_eye_x: f64,
    pub model_eye_d1: f64,
    /// The compensation's model plane behind the display (> 0), or `f64::INFINITY` for the
    /// paper's `d2 → ∞` model.
    pub model_d2: f64,
    /// The scene plane behind the display (> 0), on which widths are measured.
    pub scene_d2: f64,
}

impl PerceivedGeometry {
    /// The paper's case: the compensation knows the eye and the scene plane.
    pub fn exact(eye_x: f64, d1: f64, d2: f64) -> Self {
        Self {
            eye_x,
            eye_d1: d1,
            model_eye_x: eye_x,
            model_eye_d1: d1,
            model_d2: d2,
            scene_d2: d2,
        }
    }

    /// The display point that shows the scene-plane point `q` as the frontal camera sees it:
    /// where `M(x)` lies on the camera's ray to `q` — `M = q·d_m/d2` on the model plane, or,
    /// for `d_m = ∞`, the model eye's ray parallel to the camera's.
    pub fn display_x_showing(&self, q: f64) -> f64 {
        let (e, d1) = (self.model_eye_x, self.model_eye_d1);
        let direction = q / self.scene_d2;
        if self.model_d2.is_infinite() {
            e + d1 * direction
        } else {
            let m = direction * self.model_d2;
            e + (m - e) * d1 / (d1 + self.model_d2)
        }
    }

    /// Where on the scene plane the driver perceives the point `q` of the scene plane (as the
    /// frontal camera sees it): the driver's ray through the display point that shows it.
    pub fn perceived(&self, q: f64) -> f64 {
        let x = self.display_x_showing(q);
        self.eye_x + (x - self.eye_x) * (self.eye_d1 + self.scene_d2) / self.eye_d1
    }

    /// A width the frontal camera sees from `b1` to `b1 + p` on the scene plane (the paper's
    /// p_cam), as the driver perceives it: from the true corner `b1` to where the driver sees
    /// the far edge.
    pub fn perceived_width(&self, b1: f64, p: f64) -> f64 {
        self.perceived(b1 + p) - b1
    }

    /// The most by which a shown edge can move on the scene plane (as the driver perceives
    /// it) through resampling: the driver's ray takes the nearest display pixel (pitch
    /// `display_px`, m) and that pixel the nearest frontal pixel (pitch `frontal_tan_px` in
    /// tangent units, uniform across a pinhole image): half of each, carried to the plane.
    pub fn resampling_quantum(&self, display_px: f64, frontal_tan_px: f64) -> f64 {
        let d1 = self.model_eye_d1;
        // A frontal pixel on the model plane, seen on the display from the model's eye.
        let frontal_on_display = if self.model_d2.is_infinite() {
            frontal_tan_px * d1
        } else {
            frontal_tan_px * self.model_d2 * d1 / (d1 + self.model_d2)
        };
        let to_plane = (self.eye_d1 + self.scene_d2) / self.eye_d1;
        0.5 * to_plane * (display_px + frontal_on_display)
    }
}
