//! `seethru.compare`, `seethru.ratio` and `seethru.analyze`: the commands' results as Python
//! objects (their `--json` content), computed by the same library calls.

use numpy::PyArray;
use numpy::ndarray::Array3;
use pyo3::prelude::*;
use pyo3::types::PyDict;
use seethru::analysis::dynamic::error_budget;
use seethru::analysis::examples::das_geometry;
use seethru::analysis::paper::{ForeshorteningParams, OcclusionParams};
use seethru::measure::compare::{Candidate, coloured_strips, compare as compare_methods};
use seethru::measure::ratio::measure_ratio;
use seethru::measure::ratio_setup::{Compensation, Setup};
use seethru::paper::claims::{AnalyzeParams, evaluate, lens_and_eyes, paper_claims};
use seethru::render::settings::check_resolution;
use seethru::scene::source::MAX_RESOLUTION;
use seethru::system::memory::{check_memory, run_estimate};

use crate::errors::{bad_value, to_py};
use crate::interrupt::detached;
use crate::options::{choice_of, run_spec, spelled};
use crate::run::json_to_py;
use crate::scene::{PyScene, context_for};
use seethru::measure::compare::compare_reads;
use seethru::measure::option_table::Command;
use seethru::system::reads::hazard_bound_reads;

/// `seethru compare`: methods side by side, `{"rows": [...], "strips": {name: array}}`.
#[pyfunction]
#[pyo3(signature = (scene, methods=None, **options))]
pub fn compare<'py>(
    py: Python<'py>,
    scene: &Bound<'py, PyScene>,
    methods: Option<Vec<String>>,
    options: Option<&Bound<'py, PyDict>>,
) -> PyResult<Bound<'py, PyDict>> {
    let names = methods.unwrap_or_else(|| {
        [
            "planar-inf",
            "planar-auto",
            "plane-fit",
            "ground",
            "depth-ideal",
            "depth-tof",
        ]
        .map(String::from)
        .to_vec()
    });
    let candidates = names
        .iter()
        .map(|m| choice_of::<Candidate>("methods", m))
        .collect::<PyResult<Vec<_>>>()?;
    let choices = run_spec(options, Command::Compare, Vec::new())?;
    choices
        .refuse_ignored(&compare_reads(&candidates, false, &choices.options))
        .map_err(spelled)?;
    let (the_scene, cached) = {
        let s = scene.borrow();
        (s.scene.clone(), s.context.clone())
    };
    choices
        .refuse_ignored(&[hazard_bound_reads(&the_scene)])
        .map_err(spelled)?;
    let estimate = run_estimate(&the_scene, &choices.options).map_err(to_py)?;
    check_memory(&estimate, choices.max_memory_gib).map_err(to_py)?;
    let (context, rows) = detached(py, move || -> anyhow::Result<_> {
        let ctx = context_for(cached, the_scene)?;
        let rows = compare_methods(
            &ctx,
            &candidates,
            &choices.options,
            choices.measure.band,
            choices.measure.hazard_bound_arcmin,
        )?;
        Ok((ctx, rows))
    })?
    .map_err(to_py)?;
    scene.borrow_mut().context = Some(context);
    let out = PyDict::new(py);
    let strips = PyDict::new(py);
    let mut json_rows = Vec::new();
    let coloured = coloured_strips(&rows).map_err(to_py)?;
    for (r, strip) in rows.into_iter().zip(coloured) {
        // A method the scene does not admit has a row with its reason and no strip.
        if let Some((w, h, rgb)) = strip {
            let array = Array3::from_shape_vec((h as usize, w as usize, 3), rgb).expect("RGB8");
            strips.set_item(r.name, PyArray::from_owned_array(py, array))?;
        }
        json_rows.push(r.row);
    }
    out.set_item(
        "rows",
        json_to_py(py, &serde_json::Value::Array(json_rows))?,
    )?;
    out.set_item("strips", strips)?;
    Ok(out)
}

/// `seethru ratio occlusion|foreshortening ... --json`: the observed p_cam/p_user.
#[pyfunction]
#[pyo3(signature = (setup, **options))]
pub fn ratio(
    py: Python<'_>,
    setup: &str,
    options: Option<&Bound<'_, PyDict>>,
) -> PyResult<Py<PyAny>> {
    let mut k = crate::options::Keywords::new(options)?;
    let setup = match setup {
        "occlusion" => {
            let l = k.required("L", 1e-6, 1e4)?;
            let (b1, d2, d1, b_h) = geometry(&mut k)?;
            Setup::Occlusion(OcclusionParams { l, b1, d2, d1, b_h })
        }
        "foreshortening" => {
            let l = k.required("l", 1e-6, 1e4)?;
            let gamma = k.required("gamma", 1e-6, 90.0)?.to_radians();
            let (b1, d2, d1, b_h) = geometry(&mut k)?;
            Setup::Foreshortening(ForeshorteningParams {
                l,
                b1,
                d2,
                d1,
                b_h,
                gamma,
            })
        }
        _ => {
            return Err(bad_value(format!(
                "setup {setup:?} is not one of occlusion, foreshortening"
            )));
        }
    };
    let model_d2 = match k.real_or_inf("model_d2", f64::NAN, 1e-6, 1e6)? {
        v if v.is_nan() => None,
        v => Some(v),
    };
    let head_bias_cm = k.head_bias_cm()?;
    let width = k.int("width", 1280, 1, MAX_RESOLUTION as i64)? as u32;
    k.finish()?;
    check_resolution(width, width).map_err(to_py)?;
    let compensation = Compensation {
        model_d2,
        head_bias_cm,
    };
    let result =
        detached(py, move || measure_ratio(&setup, width, &compensation))?.map_err(to_py)?;
    json_to_py(
        py,
        &serde_json::to_value(&result).map_err(|e| to_py(e.into()))?,
    )
}

/// b1, d2, d1, bh of a ratio setup: each required.
fn geometry(k: &mut crate::options::Keywords<'_>) -> PyResult<(f64, f64, f64, f64)> {
    let values = (
        k.required("b1", -1e4, 1e4)?,
        k.required("d2", 1e-6, 1e4)?,
        k.required("d1", 1e-6, 1e3)?,
        k.required("bh", -1e3, 1e3)?,
    );
    Ok(values)
}

/// `seethru analyze --json`: the paper's claims, every closed form at the parameters, the
/// lens and eyes block ([`lens_and_eyes`], shared with the command) and the error budget of
/// the DAS geometry.
#[pyfunction]
#[pyo3(signature = (**options))]
pub fn analyze(py: Python<'_>, options: Option<&Bound<'_, PyDict>>) -> PyResult<Py<PyAny>> {
    let mut k = crate::options::Keywords::new(options)?;
    let params = AnalyzeParams {
        d1: k.real("d1", 1.0, 1e-6, 1e3)?,
        d2: k.real_or_inf("d2", 1.0, 1e-6, 1e6)?,
        b_h: k.real("bh", 0.125, -100.0, 100.0)?,
        width: k.real("width", 0.5, 1e-6, 100.0)?,
        theta_f_deg: k.real("theta_f", 80.0, 0.01, 89.0)?,
        frontal_px: k.int("frontal_px", 1280, 1, MAX_RESOLUTION as i64)? as u32,
        occluder_depth: k.real("L", 1.0, 1e-6, 1e4)?,
        b1: k.real("b1", 0.25, -1e4, 1e4)?,
        surface_length: k.real("l", 1.0, 1e-6, 1e4)?,
        gamma_deg: k.real("gamma", 45.0, 1e-6, 90.0)?,
        tolerance: k.real("tolerance", 0.05, 1e-6, 1.0)?,
    };
    let height = k.real("height", 0.45, 1e-6, 100.0)?;
    let k1 = k.real("k1", -0.1, -1.0, 1.0)?;
    let ipd = k.real("ipd", 0.064, 1e-6, 0.1)?;
    k.finish()?;
    params.validate().map_err(bad_value)?;
    let json = serde_json::json!({
        "claims": paper_claims(),
        "evaluation": evaluate(&params),
        "lens_and_eyes": lens_and_eyes(&params, height, k1, ipd),
        "error_budget_das": error_budget(&das_geometry()),
    });
    json_to_py(py, &json)
}
