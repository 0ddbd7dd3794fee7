//! Display pixel → frontal pixel. The crop's homography maps the display into the believed
//! frontal camera's *undistorted* pixels (a pinhole sees a plane through a homography); with a
//! lens, the believed lens then distorts that point into the frontal image, so the display is
//! no longer a homography of the frontal image. Without a lens the map is the crop's
//! homography exactly (bit for bit).

use glam::DVec2;

use crate::geometry::lens::Lens;
use crate::system::compensation::Crop;

/// Samples per display side for the bounds of a distorted map.
const BORDER_SAMPLES: u32 = 64;

#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FrontalMap {
    pub crop: Crop,
    /// The believed frontal lens; `None` for the ideal pinhole (and for `--method none`).
    pub lens: Option<Lens>,
    /// Display resolution, pixels.
    pub display_size: [u32; 2],
}

impl FrontalMap {
    /// Frontal pixel coordinates of continuous display pixel coordinates.
    pub fn frontal_point(&self, display: DVec2) -> DVec2 {
        let p = self.crop.frontal_point(display);
        match &self.lens {
            None => p,
            Some(lens) => lens.distort_pixel(p),
        }
    }

    /// Bounding box (min, max) in frontal pixels of the display's image: the crop's corners
    /// without a lens, the distorted border (sampled) with one.
    pub fn bounds(&self) -> (DVec2, DVec2) {
        if self.lens.is_none() {
            return self.crop.bounds();
        }
        let [w, h] = self.display_size.map(f64::from);
        let n = BORDER_SAMPLES;
        let mut min = DVec2::splat(f64::INFINITY);
        let mut max = DVec2::splat(f64::NEG_INFINITY);
        for i in 0..=n {
            let t = i as f64 / n as f64;
            for p in [
                DVec2::new(t * w, 0.0),
                DVec2::new(t * w, h),
                DVec2::new(0.0, t * h),
                DVec2::new(w, t * h),
            ] {
                let q = self.frontal_point(p);
                min = min.min(q);
                max = max.max(q);
            }
        }
        (min, max)
    }
}

/// run.json's `lenses`: the true and the believed lens of the frontal and back cameras
/// (OpenCV's intrinsics; `null`: the ideal pinhole of the half angle), and the calibration.
pub fn lenses_json(scene: &crate::scene::Scene) -> anyhow::Result<serde_json::Value> {
    let c = &scene.calibration;
    let camera = |truth: &crate::geometry::camera::Camera,
                  calibration: &crate::geometry::calibration::CameraCalibration|
     -> anyhow::Result<serde_json::Value> {
        let believed = calibration.apply(truth)?;
        Ok(serde_json::json!({
            "true": truth.lens,
            "believed": believed.lens,
            "calibration_exact": calibration.is_exact(),
            "believed_pose_error_m": (believed.position() - truth.position()).length(),
            "believed_axis_error_deg": believed.forward().angle_between(truth.forward()).to_degrees(),
        }))
    };
    Ok(serde_json::json!({
        "frontal": camera(&scene.frontal, &c.frontal)?,
        "back": camera(&scene.back, &c.back)?,
        "notes": "lenses in OpenCV's conventions (pixel centres at integers; null: the ideal pinhole of the half angle). With a believed frontal lens, crop.corners_frontal_px and the crop ratios are in the undistorted pixels of its pinhole (same fx, fy, cx, cy); the display maps each pixel on through the lens's distortion",
    }))
}
