//! Observed p_cam/p_user (paper §4.2 and §5): the paper's occlusion and foreshortening setups
//! built as scenes, rendered as `truth` and `seethru` with the model plane at the paper's d2,
//! and the widths measured from the id and position buffers.
//!
//! Measurement: every display pixel's world point is carried to the scene plane z = −d2 along
//! the ray of the viewer it was seen from — the eye for `truth`, the frontal camera for
//! `seethru` (whose display maps plane points to the eye's lines of sight). The measured
//! object's edge lies between the last pixel on it and the next pixel beyond, in plane
//! coordinates; the midpoint is the observation, half the gap its uncertainty (pixel
//! quantisation), which shrinks with resolution.

use anyhow::{Result, bail};
use glam::{DAffine3, DVec3};
use serde_json::json;

use crate::accel::BvhKind;
use crate::analysis::{ForeshorteningParams, OcclusionParams};
use crate::camera::Camera;
use crate::claims::{paper_foreshortening, paper_occlusion};
use crate::frame::Frame;
use crate::pipeline::{RunOptions, RunResult, WorkingDistance, run};
use crate::render::RenderContext;
use crate::scene::{Material, Object, Obstacle, Scene, Shape, Sky, Sun};
use crate::shapes::box_face;

/// The two setups of the paper's §4.2.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Setup {
    Occlusion(OcclusionParams),
    Foreshortening(ForeshorteningParams),
}

impl Setup {
    fn common(&self) -> (f64, f64, f64, f64) {
        match *self {
            Setup::Occlusion(p) => (p.b1, p.d1, p.d2, p.b_h),
            Setup::Foreshortening(p) => (p.b1, p.d1, p.d2, p.b_h),
        }
    }

    /// Predicted (p_cam, p_user).
    pub fn predicted(&self) -> (f64, f64) {
        match self {
            Setup::Occlusion(p) => (p.p_cam(), p.p_user()),
            Setup::Foreshortening(p) => (p.p_cam(), p.p_user()),
        }
    }

    /// The paper's predicted and measured ratios, for its own two examples.
    pub fn paper_values(&self) -> Option<(f64, f64)> {
        match *self {
            Setup::Occlusion(p) if p == paper_occlusion() => Some((-0.73, -0.71)),
            Setup::Foreshortening(p) if p == paper_foreshortening() => Some((2.47, 2.64)),
            _ => None,
        }
    }

    fn validate(&self) -> Result<()> {
        let (b1, d1, d2, b_h) = self.common();
        if ![b1, d1, d2, b_h].iter().all(|v| v.is_finite()) || d1 <= 0.0 || d2 <= 0.0 {
            bail!("d1 and d2 must be > 0 and every parameter finite");
        }
        match *self {
            Setup::Occlusion(p) if !(p.l > 0.0 && p.l < p.d2) => {
                bail!("--L must be in (0, d2) = (0, {}), got {}", p.d2, p.l)
            }
            Setup::Foreshortening(p)
                if !(p.l > 0.0 && p.gamma > 0.0 && p.gamma <= std::f64::consts::FRAC_PI_2) =>
            {
                bail!("--l must be > 0 and --gamma in (0, 90] degrees")
            }
            _ => {}
        }
        let (pc, pu) = self.predicted();
        if pc.abs() < 1e-6 || pu.abs() < 1e-6 || !pc.is_finite() || !pu.is_finite() {
            bail!(
                "the predicted widths are zero or undefined for these parameters (p_cam = {pc}, p_user = {pu})"
            );
        }
        Ok(())
    }
}

fn material(name: &str, color: [f64; 3]) -> Material {
    Material {
        name: name.into(),
        color,
        texture: None,
        uv_repeat: [1.0, 1.0],
    }
}

fn object(name: &str, shape: Shape, material: usize, world_from_object: DAffine3) -> Object {
    Object {
        name: name.into(),
        shape,
        material: Some(material),
        world_from_object,
        visible_to: 0b111,
        casts_shadow: true,
    }
}

/// The scene of a setup: display at the origin facing +z, frontal camera at its centre, the
/// eye at (−b_h, 0, d1) (the paper's convention), the scene plane at z = −d2. `width` is the
/// driver view's width in pixels; the frontal camera and the display get as many.
pub fn build_scene(setup: &Setup, width: u32) -> Result<Scene> {
    setup.validate()?;
    let (b1, d1, d2, b_h) = setup.common();
    let eye = DVec3::new(-b_h, 0.0, d1);
    let (pc, pu) = setup.predicted();
    // Plane points the display must show, with a margin: the corner and both edges.
    let span = pc.abs().max(pu.abs());
    let qs = [b1, b1 + pc, b1 + pu];
    let (q_lo, q_hi) = (
        qs.iter().copied().fold(f64::INFINITY, f64::min) - 0.5 * span - 0.05,
        qs.iter().copied().fold(f64::NEG_INFINITY, f64::max) + 0.5 * span + 0.05,
    );
    // Display x of a plane point seen from the eye.
    let display_x = |q: f64| eye.x + (q - eye.x) * d1 / (d1 + d2);
    let half_width = display_x(q_lo).abs().max(display_x(q_hi).abs()) * 1.02;
    let height = 0.2 * half_width;
    let obstacle = Obstacle {
        world_from_obstacle: DAffine3::IDENTITY,
        width: 2.0 * half_width,
        height,
        thickness: 0.01,
        display_resolution: [
            width,
            ((width as f64 * height / (2.0 * half_width)).round() as u32).max(8),
        ],
        display_off_color: [0.0; 3],
        body_color: [0.2; 3],
    };
    // The frontal camera must see every plane point the display can ask for.
    let reach = [-half_width, half_width]
        .map(|x| (eye.x + (x - eye.x) * (d1 + d2) / d1).abs())
        .into_iter()
        .fold(0.0, f64::max);
    let theta_f = ((reach * 1.05 / d2).atan()).min(85f64.to_radians());
    let frontal = Camera::new(DAffine3::IDENTITY, theta_f, width, (width / 2).max(8))?;
    // The driver looks at the display centre, wide enough to see the whole display.
    let look = -eye.normalize();
    let half_x = [-half_width, half_width]
        .map(|x| (DVec3::new(x, 0.0, 0.0) - eye).normalize().dot(look).acos())
        .into_iter()
        .fold(0.0, f64::max)
        + 1f64.to_radians();
    let driver = Camera::look_at(
        eye,
        DVec3::ZERO,
        DVec3::Y,
        half_x.min(85f64.to_radians()),
        width,
        (width / 4).max(8),
    )?;
    let back = Camera::new(DAffine3::from_rotation_y(std::f64::consts::PI), 0.6, 8, 6)?;
    let materials = vec![
        material("background", [0.6, 0.6, 0.6]),
        material("object", [0.8, 0.2, 0.1]),
    ];
    // Tall enough that every display row sees the setup.
    let tall = 4.0 * height * (d1 + d2) / d1 + 2.0;
    let far = d2 + 50.0;
    let mut objects = Vec::new();
    match *setup {
        Setup::Occlusion(p) => {
            // Background on the scene plane; the box stands on it, its near edge at b1.
            objects.push(object(
                "plane",
                Shape::Quad {
                    size: [4.0 * far, 4.0 * far],
                },
                0,
                DAffine3::from_translation(DVec3::new(0.0, 0.0, -d2)),
            ));
            let box_width = 4.0 * span + 2.0;
            let centre = DVec3::new(b1 - box_width / 2.0, 0.0, -d2 + p.l / 2.0);
            objects.push(object(
                "occluder",
                Shape::Box {
                    size: [box_width, tall, p.l],
                },
                1,
                DAffine3::from_translation(centre),
            ));
        }
        Setup::Foreshortening(p) => {
            let dir = DVec3::new(p.gamma.cos(), 0.0, -p.gamma.sin());
            let centre = DVec3::new(b1, 0.0, -d2) + dir * (p.l / 2.0);
            let pose = DAffine3::from_translation(centre) * DAffine3::from_rotation_y(p.gamma);
            objects.push(object(
                "surface",
                Shape::Quad { size: [p.l, tall] },
                1,
                pose,
            ));
            objects.push(object(
                "backdrop",
                Shape::Quad {
                    size: [8.0 * far, 8.0 * far],
                },
                0,
                DAffine3::from_translation(DVec3::new(0.0, 0.0, -far)),
            ));
        }
    }
    Ok(Scene {
        path: "generated".into(),
        sun: Sun {
            direction: DVec3::new(0.3, 0.8, 0.5).normalize(),
            color: [1.0; 3],
            intensity: 1.5,
        },
        sky: Sky {
            cloud_cover: 0.0,
            ..Sky::default()
        },
        materials,
        objects,
        obstacle,
        driver,
        frontal,
        back,
    })
}

/// A measured width: the observation and its quantisation uncertainty (half-width of the
/// bracket), metres on the scene plane.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
pub struct Measured {
    pub value: f64,
    pub uncertainty: f64,
}

/// Where the ray from `viewer` through `point` meets the plane z = −d2 (x coordinate).
fn plane_x(viewer: DVec3, point: DVec3, d2: f64) -> f64 {
    let t = (-d2 - viewer.z) / (point.z - viewer.z);
    viewer.x + t * (point.x - viewer.x)
}

/// The measured object's edge in plane coordinates from one frame, as seen from `viewer`.
/// `upper`: the edge is the object's largest plane coordinate (the box's front face, which
/// occupies x ≤ b1 and runs off the display the other way); otherwise the end farther from
/// the corner b1 (the angled surface, whose other end is the corner itself).
fn measure_edge(
    frame: &Frame,
    display: &[bool],
    is_object: impl Fn(u32, u32) -> bool,
    viewer: DVec3,
    d2: f64,
    b1: f64,
    upper: bool,
) -> Option<Measured> {
    let mut on: Vec<f64> = Vec::new();
    let mut off: Vec<f64> = Vec::new();
    for i in (0..display.len()).filter(|&i| display[i]) {
        let p = frame.position[i];
        if !p.is_finite() {
            continue;
        }
        let q = plane_x(viewer, p.as_dvec3(), d2);
        if is_object(frame.object_id[i], frame.part_id[i]) {
            on.push(q)
        } else {
            off.push(q)
        }
    }
    if on.is_empty() {
        return None;
    }
    let (lo, hi) = on
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), &q| {
            (a.min(q), b.max(q))
        });
    let (inner, outer) = if upper || (hi - b1).abs() >= (lo - b1).abs() {
        (
            hi,
            off.iter()
                .copied()
                .filter(|&q| q > hi)
                .fold(f64::INFINITY, f64::min),
        )
    } else {
        (
            lo,
            off.iter()
                .copied()
                .filter(|&q| q < lo)
                .fold(f64::NEG_INFINITY, f64::max),
        )
    };
    outer.is_finite().then(|| Measured {
        value: (inner + outer) / 2.0 - b1,
        uncertainty: (outer - inner).abs() / 2.0,
    })
}

/// The result of one ratio experiment.
#[derive(Clone, Debug, serde::Serialize)]
pub struct RatioResult {
    pub setup: String,
    pub resolution: u32,
    pub p_cam_predicted: f64,
    pub p_user_predicted: f64,
    pub p_cam_observed: Measured,
    pub p_user_observed: Measured,
    pub ratio_predicted: f64,
    pub ratio_observed: f64,
    /// Worst-case propagation of the width uncertainties to the ratio.
    pub ratio_uncertainty: f64,
    /// The paper's predicted and Unity-measured ratios, for its two examples.
    pub paper_predicted: Option<f64>,
    pub paper_measured: Option<f64>,
}

/// Renders a setup and measures the observed widths and ratio.
pub fn measure_ratio(setup: &Setup, width: u32) -> Result<RatioResult> {
    Ok(measure_ratio_with_frames(setup, width)?.0)
}

/// As [`measure_ratio`], also returning the rendered frames.
pub fn measure_ratio_with_frames(setup: &Setup, width: u32) -> Result<(RatioResult, RunResult)> {
    let scene = build_scene(setup, width)?;
    let (b1, _, d2, _) = setup.common();
    let eye = scene.eye();
    let camera = scene.frontal.position();
    let ctx = RenderContext::new(scene, BvhKind::Cwbvh)?;
    let options = RunOptions {
        d2: WorkingDistance::Metres(d2),
        spp: 1,
        ..RunOptions::default()
    };
    let result = run(&ctx, &options)?;
    let obstacle_id = ctx.world.obstacle_id;
    let display: Vec<bool> = result
        .occluded
        .object_id
        .iter()
        .zip(&result.occluded.part_id)
        .map(|(&o, &p)| o == obstacle_id && p == box_face::POS_Z)
        .collect();
    let is_object = |id: u32, part: u32| match setup {
        Setup::Occlusion(_) => id == 2 && part == box_face::POS_Z,
        Setup::Foreshortening(_) => id == 1,
    };
    let missing = |what: &str| {
        anyhow::anyhow!("the {what} frame shows no edge of the measured object in the display")
    };
    let upper = matches!(setup, Setup::Occlusion(_));
    let user = measure_edge(&result.truth, &display, is_object, eye, d2, b1, upper)
        .ok_or_else(|| missing("truth"))?;
    let cam = measure_edge(&result.seethru, &display, is_object, camera, d2, b1, upper)
        .ok_or_else(|| missing("seethru"))?;
    let (pc, pu) = setup.predicted();
    let ratio = cam.value / user.value;
    let paper = setup.paper_values();
    let ratio_result = RatioResult {
        setup: format!("{setup:?}"),
        resolution: width,
        p_cam_predicted: pc,
        p_user_predicted: pu,
        p_cam_observed: cam,
        p_user_observed: user,
        ratio_predicted: pc / pu,
        ratio_observed: ratio,
        ratio_uncertainty: ratio.abs()
            * (cam.uncertainty / cam.value.abs() + user.uncertainty / user.value.abs()),
        paper_predicted: paper.map(|p| p.0),
        paper_measured: paper.map(|p| p.1),
    };
    Ok((ratio_result, result))
}

/// The result as lines of text, each value labelled.
pub fn describe(r: &RatioResult) -> String {
    let mut s = format!("{}\n", r.setup);
    s += &format!("  driver view width    {} px\n", r.resolution);
    s += &format!(
        "  p_cam   predicted {:+.4} m   observed {:+.4} m   uncertainty ±{:.4} m\n",
        r.p_cam_predicted, r.p_cam_observed.value, r.p_cam_observed.uncertainty
    );
    s += &format!(
        "  p_user  predicted {:+.4} m   observed {:+.4} m   uncertainty ±{:.4} m\n",
        r.p_user_predicted, r.p_user_observed.value, r.p_user_observed.uncertainty
    );
    s += &format!(
        "  p_cam/p_user  predicted {:+.4}   observed {:+.4}   uncertainty ±{:.4}\n",
        r.ratio_predicted, r.ratio_observed, r.ratio_uncertainty
    );
    if let (Some(pp), Some(pm)) = (r.paper_predicted, r.paper_measured) {
        s += &format!("  the paper: predicted {pp:+.2}, measured in Unity {pm:+.2}\n");
    }
    s
}

/// The JSON of a result.
pub fn to_json(r: &RatioResult) -> serde_json::Value {
    json!(r)
}
