//! Observed p_cam/p_user (paper §4.2 and §5): the paper's occlusion and foreshortening setups
//! built as scenes, rendered as `truth` and `seethru` under a compensation (its model plane
//! and its eye; by default the paper's: the scene plane and the true eye), and the widths
//! measured as the driver perceives them.
//!
//! Measurement: every display pixel of the driver's view is carried to the scene plane
//! z = −d2 along the driver's line of sight through it — where on the scene plane the driver
//! perceives what that pixel shows, in `truth` and in `seethru` alike. A wrong model plane or
//! a wrong eye moves what the display shows, and so the observation. The measured edge (the
//! box's front corner; the far end of the angled surface) lies between the last pixel on the
//! object and the next pixel beyond; the midpoint is the observation. Its uncertainty is half
//! that bracket and, for `seethru`, the resampling quantum: the display's nearest pixel, and
//! that pixel's nearest frontal pixel, can each move a shown edge by half a pixel.

use anyhow::Result;
use glam::DVec3;
use serde::Serialize;

use crate::measure::ratio_setup::{Compensation, Setup, build_scene};
use crate::render::frame::Frame;
use crate::render::integrator::RenderContext;
use crate::scene::shapes::box_face;
use crate::system::memory::{MemoryEstimate, run_estimate};
use crate::system::options::{RunOptions, WorkingDistance};
use crate::system::pipeline::{RunResult, run};

/// A measured width: the observation and its uncertainty (half-width of the interval it is
/// known to lie in), metres on the scene plane.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct Measured {
    pub value: f64,
    pub uncertainty: f64,
}

/// One quantity of the experiment, three ways.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct Quantity {
    /// The paper's closed form (eq. OCLUSION / FORESH1 and their widths): what the frontal
    /// camera and the eye see, i.e. the perception under the paper's compensation.
    pub paper: f64,
    /// The geometry's prediction of what the driver perceives under this compensation
    /// (`analysis::perceived`); equal to `paper` for the paper's compensation.
    pub predicted: f64,
    pub observed: f64,
    pub uncertainty: f64,
}

/// x where the ray from `viewer` through `point` meets the plane z = −d2.
fn plane_x(viewer: DVec3, point: DVec3, d2: f64) -> f64 {
    let t = (-d2 - viewer.z) / (point.z - viewer.z);
    viewer.x + t * (point.x - viewer.x)
}

/// The measured object's edge in one frame, as the bracket (last on the object, first beyond)
/// in plane coordinates `q` of the display pixels. `upper`: the edge is the object's largest
/// plane coordinate; otherwise its smallest.
fn bracket_edge(
    frame: &Frame,
    q: &[Option<f64>],
    is_object: impl Fn(u32, u32) -> bool,
    upper: bool,
) -> Option<(f64, f64)> {
    let sign = if upper { 1.0 } else { -1.0 };
    let (mut inner, mut on) = (f64::NEG_INFINITY, false);
    for (i, q) in q.iter().enumerate() {
        if let Some(q) = q
            && is_object(frame.object_id[i], frame.part_id[i])
        {
            inner = inner.max(sign * q);
            on = true;
        }
    }
    let outer = q
        .iter()
        .enumerate()
        .filter_map(|(i, q)| q.map(|q| (i, sign * q)))
        .filter(|&(i, q)| q > inner && !is_object(frame.object_id[i], frame.part_id[i]))
        .map(|(_, q)| q)
        .fold(f64::INFINITY, f64::min);
    (on && outer.is_finite()).then_some((sign * inner, sign * outer))
}

/// The result of one ratio experiment.
#[derive(Clone, Debug, Serialize)]
pub struct RatioResult {
    /// `occlusion` or `foreshortening`, and its parameters (metres, γ in degrees).
    pub setup: String,
    pub parameters: serde_json::Value,
    /// The compensation: model plane (metres, or "inf") and head bias (cm, obstacle frame).
    #[serde(serialize_with = "crate::util::json::finite_or_inf")]
    pub model_d2: f64,
    pub head_bias_cm: [f64; 3],
    /// Width of the driver view, the frontal image and the display, pixels.
    pub resolution: u32,
    pub p_cam: Quantity,
    pub p_user: Quantity,
    /// p_cam/p_user; its uncertainty is the worst case over the widths' intervals.
    pub ratio: Quantity,
    /// The part of p_cam's uncertainty that display and frontal resampling contribute, m.
    pub resampling_quantum_m: f64,
    /// The paper's printed predicted and Unity-measured ratios, for its two examples.
    pub paper_printed: Option<f64>,
    pub paper_unity: Option<f64>,
}

/// Renders a setup under a compensation and measures the observed widths and ratio.
pub fn measure_ratio(
    setup: &Setup,
    width: u32,
    compensation: &Compensation,
) -> Result<RatioResult> {
    Ok(measure_ratio_with_frames(setup, width, compensation)?.0)
}

/// The worst-case deviation of c/u from its value over c ± uc and u ± uu (infinite when the
/// interval of u contains zero).
pub fn ratio_uncertainty(c: Measured, u: Measured) -> f64 {
    if u.value.abs() <= u.uncertainty {
        return f64::INFINITY;
    }
    let r = c.value / u.value;
    [-1.0, 1.0]
        .into_iter()
        .flat_map(|a| [-1.0, 1.0].map(|b| (a, b)))
        .map(|(a, b)| ((c.value + a * c.uncertainty) / (u.value + b * u.uncertainty) - r).abs())
        .fold(0.0, f64::max)
}

/// The run a ratio measurement makes of its built scene: the compensation's model plane
/// and head bias, one sample per pixel.
fn run_options(setup: &Setup, compensation: &Compensation) -> RunOptions {
    let model_d2 = setup.geometry(compensation).model_d2;
    RunOptions {
        d2: if model_d2.is_finite() {
            WorkingDistance::Metres(model_d2)
        } else {
            WorkingDistance::Infinity
        },
        head_bias_cm: compensation.head_bias_cm,
        spp: 1,
        ..RunOptions::default()
    }
}

/// Memory [`measure_ratio`] needs at `width`: the run of the scene it builds.
pub fn ratio_estimate(
    setup: &Setup,
    width: u32,
    compensation: &Compensation,
) -> Result<MemoryEstimate> {
    let scene = build_scene(setup, width, compensation)?;
    run_estimate(&scene, &run_options(setup, compensation))
}

/// As [`measure_ratio`], also returning the rendered frames.
pub fn measure_ratio_with_frames(
    setup: &Setup,
    width: u32,
    compensation: &Compensation,
) -> Result<(RatioResult, RunResult)> {
    let scene = build_scene(setup, width, compensation)?;
    let (b1, _, d2, _) = setup.common();
    let eye = scene.eye();
    let geometry = setup.geometry(compensation);
    let quantum = geometry.resampling_quantum(
        scene.obstacle.width / scene.obstacle.display_resolution[0] as f64,
        2.0 * scene.frontal.tan_half_x() / scene.frontal.width as f64,
    );
    let ctx = RenderContext::new(scene)?;
    let result = run(&ctx, &run_options(setup, compensation))?;
    let obstacle_id = ctx.world.obstacle_id;
    // Each display pixel's line of sight, carried to the scene plane.
    let q: Vec<Option<f64>> = (0..result.occluded.object_id.len())
        .map(|i| {
            let on_display = result.occluded.object_id[i] == obstacle_id
                && result.occluded.part_id[i] == box_face::POS_Z;
            on_display.then(|| plane_x(eye, result.occluded.position[i].as_dvec3(), d2))
        })
        .collect();
    let is_object = |id: u32, part: u32| match setup {
        Setup::Occlusion(_) => id == 2 && part == box_face::POS_Z,
        Setup::Foreshortening(_) => id == 1,
    };
    let (pc, pu) = setup.predicted();
    let (pc_perceived, _) = setup.predicted_perceived(compensation);
    // The box's front face lies on the low side of its edge; the angled surface's far end is
    // on the side its projected width points to.
    let upper = |width: f64| matches!(setup, Setup::Occlusion(_)) || width > 0.0;
    let observe = |frame: &Frame, upper: bool, extra: f64, what: &str| -> Result<Measured> {
        let (inner, outer) = bracket_edge(frame, &q, is_object, upper).ok_or_else(|| {
            anyhow::anyhow!("the {what} frame shows no edge of the measured object in the display")
        })?;
        Ok(Measured {
            value: (inner + outer) / 2.0 - b1,
            uncertainty: (outer - inner).abs() / 2.0 + extra,
        })
    };
    let user = observe(&result.truth, upper(pu), 0.0, "truth")?;
    let cam = observe(&result.seethru, upper(pc_perceived), quantum, "seethru")?;
    let paper = setup.paper_values();
    let ratio = cam.value / user.value;
    let ratio_result = RatioResult {
        setup: setup.kind().to_string(),
        parameters: setup.parameters_json(),
        model_d2: geometry.model_d2,
        head_bias_cm: compensation.head_bias_cm,
        resolution: width,
        p_cam: Quantity {
            paper: pc,
            predicted: pc_perceived,
            observed: cam.value,
            uncertainty: cam.uncertainty,
        },
        p_user: Quantity {
            paper: pu,
            predicted: pu,
            observed: user.value,
            uncertainty: user.uncertainty,
        },
        ratio: Quantity {
            paper: pc / pu,
            predicted: pc_perceived / pu,
            observed: ratio,
            uncertainty: ratio_uncertainty(cam, user),
        },
        resampling_quantum_m: quantum,
        paper_printed: paper.map(|p| p.0),
        paper_unity: paper.map(|p| p.1),
    };
    Ok((ratio_result, result))
}

/// The result as a table: the paper's closed form, the prediction for this compensation,
/// the observation and its uncertainty.
pub fn describe(r: &RatioResult) -> String {
    let parameters = r
        .parameters
        .as_object()
        .map(|m| {
            m.iter()
                .map(|(k, v)| format!("{k} = {v}"))
                .collect::<Vec<_>>()
                .join(", ")
        })
        .unwrap_or_default();
    let scene_d2 = r.parameters["d2"].as_f64().unwrap_or(f64::NAN);
    let model = if r.model_d2.is_infinite() {
        "at infinity (d2 → ∞)".to_string()
    } else if r.model_d2 == scene_d2 {
        format!("at {} m (the scene plane)", r.model_d2)
    } else {
        format!("at {} m (the scene plane is at {scene_d2} m)", r.model_d2)
    };
    let [bx, by, bz] = r.head_bias_cm;
    let mut s = format!("{}: {parameters} (metres; γ in degrees)\n", r.setup);
    s += &format!(
        "compensation: model plane {model}, head bias ({bx}, {by}, {bz}) cm; driver view, frontal image and display {} px wide\n\n",
        r.resolution
    );
    s += &format!(
        "{:<14} {:>10} {:>10} {:>10} {:>12}\n",
        "", "paper", "predicted", "observed", "uncertainty"
    );
    for (name, q) in [
        ("p_cam [m]", r.p_cam),
        ("p_user [m]", r.p_user),
        ("p_cam/p_user", r.ratio),
    ] {
        s += &format!(
            "{name:<14} {:>+10.4} {:>+10.4} {:>+10.4} {:>12}\n",
            q.paper,
            q.predicted,
            q.observed,
            format!("±{:.4}", q.uncertainty)
        );
    }
    s += "\npaper: the closed forms (what the frontal camera and the eye see on the scene plane); \
          predicted: where the driver perceives the edges under this compensation; observed: \
          along the driver's line of sight through each display pixel, ± the pixel bracket and, \
          for p_cam, the resampling quantum ";
    s += &format!("(±{:.4} m).\n", r.resampling_quantum_m);
    if let (Some(pp), Some(pm)) = (r.paper_printed, r.paper_unity) {
        s += &format!("The paper's own numbers: predicted {pp:+.2}, measured in Unity {pm:+.2}.\n");
    }
    s
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_ratio_uncertainty_is_the_worst_corner() {
        let m = |value, uncertainty| Measured { value, uncertainty };
        // 1 ± 0.1 over 2 ± 0.2: the worst corner is 1.1 / 1.8 (0.1111 above 0.5); 0.9 / 2.2
        // is only 0.0909 below.
        let u = ratio_uncertainty(m(1.0, 0.1), m(2.0, 0.2));
        assert!((u - (1.1 / 1.8 - 0.5)).abs() < 1e-15, "{u}");
        // Signs do not matter: −1 ± 0.1 over 2 ± 0.2.
        assert!((ratio_uncertainty(m(-1.0, 0.1), m(2.0, 0.2)) - u).abs() < 1e-15);
        // A denominator interval containing zero bounds nothing.
        assert!(ratio_uncertainty(m(1.0, 0.1), m(0.1, 0.2)).is_infinite());
        assert_eq!(ratio_uncertainty(m(1.0, 0.0), m(2.0, 0.0)), 0.0);
    }

    /// `rows` rows of six pixels, the object (id 7) on the first row's pixels 1..3.
    fn rows_of_six(rows: u32) -> Frame {
        let pixels: Vec<_> = (0..6 * rows)
            .map(|i| crate::render::frame::Pixel {
                object_id: if (1..4).contains(&i) { 7 } else { 1 },
                ..crate::render::frame::Pixel::SKY
            })
            .collect();
        Frame::from_pixels(6, rows, &pixels)
    }

    #[test]
    fn edges_are_bracketed_from_the_side_asked_for() {
        // Six display pixels along a row at plane coordinates 0..6; the object (id 7) on 1..3.
        let frame = rows_of_six(1);
        let q: Vec<Option<f64>> = (0..6).map(|i| Some(i as f64)).collect();
        let is_object = |id: u32, _: u32| id == 7;
        assert_eq!(bracket_edge(&frame, &q, is_object, true), Some((3.0, 4.0)));
        assert_eq!(bracket_edge(&frame, &q, is_object, false), Some((1.0, 0.0)));
        // Pixels off the display (None) are not brackets; an edge with nothing beyond is none.
        let q: Vec<Option<f64>> = (0..6).map(|i| (i < 4).then_some(i as f64)).collect();
        assert_eq!(bracket_edge(&frame, &q, is_object, true), None);
        // A second row, off the object, at the same plane coordinates (a column of the view
        // above the object sees the same line of the plane): a pixel level with the object's
        // edge is not beyond it.
        let two_rows = rows_of_six(2);
        let q: Vec<Option<f64>> = (0..12).map(|i| Some((i % 6) as f64)).collect();
        assert_eq!(
            bracket_edge(&two_rows, &q, is_object, true),
            Some((3.0, 4.0))
        );
        assert_eq!(
            bracket_edge(&two_rows, &q, is_object, false),
            Some((1.0, 0.0))
        );
    }
}
