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

use anyhow::Result;
use glam::DVec3;
use serde_json::json;

use crate::measure::ratio_setup::{Setup, build_scene};
use crate::render::frame::Frame;
use crate::render::integrator::RenderContext;
use crate::scene::shapes::box_face;
use crate::system::options::{RunOptions, WorkingDistance};
use crate::system::pipeline::{RunResult, run};

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
    let ctx = RenderContext::new(scene)?;
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
