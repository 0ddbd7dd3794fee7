//! The choices of one run of the see-through system: method, working distance, head source,
//! injected head errors, sizes, and how the display is modelled.

use crate::geometry::camera::Camera;
use crate::render::settings::resized;
use crate::scene::Scene;
use crate::scene::limits::{MAX_COORDINATE, MIN_LENGTH};
use crate::scene::motion::VehicleMotion;
use crate::system::display::{DisplayModel, Filter};
use crate::system::eyes::Eyes;
use crate::system::scene_model_options::SceneModelOptions;
use crate::util::number::short;
use glam::DVec3;

/// How the display image is made.
#[derive(
    Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum, serde::Serialize, serde::Deserialize,
)]
#[serde(rename_all = "lowercase")]
pub enum Method {
    /// The whole frontal image scaled into the display: the naive baseline.
    None,
    /// The paper's planar compensation at working distance `d2`.
    Planar,
    /// The known road plane (d2 → ∞ above the horizon).
    Ground,
    /// A plane fitted to the depth sensor's points where the display is, tilted freely.
    #[serde(rename = "plane-fit")]
    PlaneFit,
    /// Per-pixel reprojection with the depth sensor's depth map.
    Depth,
}

/// The working distance of the planar model; written as `inf`, `auto` or the metres.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(try_from = "String", into = "String")]
pub enum WorkingDistance {
    /// `d2 → ∞`, the paper's proposal.
    Infinity,
    /// A fixed distance from the display plane, metres in [1e-6, 1e6].
    Metres(f64),
    /// The median frontal depth of the region the display covers (a range sensor's answer).
    Auto,
}

impl std::str::FromStr for WorkingDistance {
    type Err = String;
    fn from_str(text: &str) -> Result<Self, String> {
        // Spaces around the value are ignored, as by every numeric flag.
        let s = text.trim();
        match s {
            "inf" | "infinity" => Ok(WorkingDistance::Infinity),
            "auto" => Ok(WorkingDistance::Auto),
            _ => match s.parse::<f64>() {
                Ok(v) if (MIN_LENGTH..=MAX_COORDINATE).contains(&v) => {
                    Ok(WorkingDistance::Metres(v))
                }
                _ => Err(format!(
                    "`{s}`: must be inf, auto or a distance in metres in [{}, {}]",
                    short(MIN_LENGTH),
                    short(MAX_COORDINATE)
                )),
            },
        }
    }
}

impl TryFrom<String> for WorkingDistance {
    type Error = String;
    fn try_from(text: String) -> Result<Self, String> {
        text.parse()
    }
}

impl From<WorkingDistance> for String {
    fn from(d: WorkingDistance) -> String {
        match d {
            WorkingDistance::Infinity => "inf".into(),
            WorkingDistance::Auto => "auto".into(),
            // Rust's shortest round-trip form: the same f64 reads back.
            WorkingDistance::Metres(m) => m.to_string(),
        }
    }
}

/// Most centimetres of head bias on each axis (`--head-bias-cm`, a sweep's `head_bias_x_cm`).
pub const MAX_HEAD_BIAS_CM: f64 = 500.0;

/// Where the head position comes from.
#[derive(
    Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum, serde::Serialize, serde::Deserialize,
)]
#[serde(rename_all = "lowercase")]
pub enum HeadSource {
    /// The true eye position.
    Oracle,
    /// The back camera's image through the face detector and eqs. d1, b_h.
    Estimated,
    /// A statistical tracker: the true eye with a webcam landmark tracker's bias, noise,
    /// dropouts and latency (system/tracker_model.rs).
    Model,
}

/// What to do when the crop needs more than the frontal camera sees.
#[derive(
    Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum, serde::Serialize, serde::Deserialize,
)]
#[serde(rename_all = "lowercase")]
pub enum Outside {
    /// Stop with an error naming the side, the amount and the admissible head region.
    Error,
    /// Show the outside part black and count it as missing.
    Black,
}

fn default_min_head_confidence() -> f64 {
    crate::system::head_confidence::CONFIDENT_HEAD
}

/// Written whole (a capture folder's `truth/capture_spec.json`) and read back the same;
/// every field is required when read, an unknown one refused.
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RunOptions {
    pub method: Method,
    pub d2: WorkingDistance,
    pub head: HeadSource,
    /// Head-tracking bias added to the eye, obstacle frame, centimetres.
    pub head_bias_cm: [f64; 3],
    /// Standard deviation of Gaussian head-tracking jitter per axis, centimetres.
    pub head_jitter_cm: f64,
    /// Seed of the jitter.
    pub seed: u32,
    /// Refuse a head estimate whose confidence is below `head::CONFIDENT_HEAD` (`--head
    /// estimated` only).
    pub require_confident_head: bool,
    /// The confidence in [0, 1] below which a head estimate is unreliable: warned about, or
    /// refused with `require_confident_head`. Capture folders written before it existed hold
    /// none: theirs was [`crate::system::head_confidence::CONFIDENT_HEAD`].
    #[serde(default = "default_min_head_confidence")]
    pub min_head_confidence: f64,
    /// Feature width `A` the detector measures (interpupillary distance), metres.
    pub feature_width: f64,
    /// Driver-view resolution overrides (truth, occluded, seethru).
    pub width: Option<u32>,
    pub height: Option<u32>,
    /// Frontal and back camera width overrides (their aspect ratios are kept).
    pub frontal_width: Option<u32>,
    pub back_width: Option<u32>,
    pub spp: u32,
    pub outside: Outside,
    pub filter: Filter,
    /// How the `seethru` view models the display.
    pub display: DisplayModel,
    /// Which eye looks and which the compensation serves (system/eyes.rs).
    pub eyes: Eyes,
    /// The depth sensor and hole filling of `ground`, `plane-fit` and `depth`.
    pub scene_model: SceneModelOptions,
    /// The vehicle's speed along the road (world −z), km/h, [0, 300]: a single frame's
    /// frontal camera moves during its rolling readout and exposure (scene keys); a sequence's
    /// vehicle drives at it ([`RunOptions::vehicle_motion`]). Capture folders written before it
    /// existed hold none: 0.
    #[serde(default)]
    pub speed_kmh: f64,
    /// The vehicle's yaw rate about the driver's eye, °/s, [−180, 180], positive turning left.
    #[serde(default)]
    pub yaw_rate_deg_s: f64,
    /// A single frame's camera latency, ms, [0, 10000]: the frontal image was captured this long
    /// before the instant the driver sees the display, where the vehicle's motion had not yet
    /// carried the camera (a sequence has its own, per refresh). Capture folders written
    /// before it existed hold none: 0.
    #[serde(default)]
    pub latency_camera_ms: f64,
    /// Progress bars on stderr: the front end's, never written.
    #[serde(skip)]
    pub progress: bool,
}

impl RunOptions {
    /// The vehicle's motion at `speed_kmh`: along the scene's lane route where `[road]`
    /// places the vehicle in a lane (a yaw rate is then refused: the lane turns it), else
    /// along world −z turning at `yaw_rate_deg_s` about the driver's eye.
    pub fn vehicle_motion(&self, scene: &Scene) -> anyhow::Result<VehicleMotion> {
        if scene.ego_route.is_some() && self.yaw_rate_deg_s != 0.0 {
            anyhow::bail!(
                "option `yaw_rate` ({} °/s) would turn the vehicle off its lane: the scene's [road] places it in a lane, which it follows at option `speed`; leave the yaw rate out, or choose the way at junctions with [road] turns",
                short(self.yaw_rate_deg_s)
            );
        }
        Ok(VehicleMotion {
            speed: self.speed_kmh / 3.6,
            yaw_rate: self.yaw_rate_deg_s.to_radians(),
            forward: DVec3::NEG_Z,
            pivot: scene.eye(),
            route: scene.ego_route.clone().map(std::sync::Arc::new),
        })
    }

    /// The driver's camera (as given, before the eye is chosen) at `--width`/`--height`.
    pub fn sized_driver(&self, camera: Camera) -> anyhow::Result<Camera> {
        resized(
            camera,
            self.width,
            self.height,
            "option `width`/option `height`",
        )
    }

    /// The frontal camera at `--frontal-width`.
    pub fn sized_frontal(&self, camera: Camera) -> anyhow::Result<Camera> {
        resized(camera, self.frontal_width, None, "option `frontal_width`")
    }

    /// The back camera at `--back-width`.
    pub fn sized_back(&self, camera: Camera) -> anyhow::Result<Camera> {
        resized(camera, self.back_width, None, "option `back_width`")
    }
}

impl Default for RunOptions {
    fn default() -> Self {
        Self {
            method: Method::Planar,
            d2: WorkingDistance::Infinity,
            head: HeadSource::Oracle,
            head_bias_cm: [0.0; 3],
            head_jitter_cm: 0.0,
            seed: 1,
            require_confident_head: false,
            min_head_confidence: default_min_head_confidence(),
            feature_width: 0.064,
            width: None,
            height: None,
            frontal_width: None,
            back_width: None,
            spp: 4,
            outside: Outside::Error,
            filter: Filter::Bilinear,
            display: DisplayModel::Pixels,
            eyes: Eyes::default(),
            scene_model: SceneModelOptions::default(),
            speed_kmh: 0.0,
            yaw_rate_deg_s: 0.0,
            latency_camera_ms: 0.0,
            progress: false,
        }
    }
}
