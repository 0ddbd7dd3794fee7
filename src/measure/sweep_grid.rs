//! The grid of a sweep: which parameters can vary, their values as given on the command line,
//! every combination, and each combination applied to a scene and run options.

use anyhow::{Context, Result, bail};
use glam::DVec3;

use crate::scene::Scene;
use crate::scene::limits::{MAX_COORDINATE, MAX_RESOLUTION, out_of_world};
use crate::system::options::{RunOptions, WorkingDistance};
use crate::util::number::short;

/// What a sweep can vary.
pub const PARAMETERS: [(&str, &str); 7] = [
    ("theta_f", "frontal half angle θ_F, degrees in (0, 89]"),
    (
        "d2",
        "model working distance: inf, auto or metres in (0, 1e6]",
    ),
    (
        "display_width",
        "display width D, metres in (0, 100] (display pixels scale with it)",
    ),
    (
        "eye_x",
        "eye moved across the display (obstacle x), metres in [-1e6, 1e6]",
    ),
    (
        "eye_z",
        "eye moved along the display normal (d1 change), metres in [-1e6, 1e6]",
    ),
    (
        "head_bias_x_cm",
        "head-tracking bias across the display, centimetres in [-500, 500]",
    ),
    (
        "frontal_width",
        "frontal camera width, pixels in [1, 16384]",
    ),
];

/// One swept parameter and its values (as written on the command line, and parsed).
#[derive(Clone, Debug, PartialEq)]
pub struct Param {
    pub name: String,
    pub values: Vec<String>,
}

/// Parses `name=start:stop:step` or `name=v1,v2,...`.
pub fn parse_param(spec: &str) -> Result<Param> {
    let (name, values) = spec
        .split_once('=')
        .with_context(|| format!("`{spec}`: expected name=start:stop:step or name=v1,v2,..."))?;
    if !PARAMETERS.iter().any(|(n, _)| *n == name) {
        let known: Vec<&str> = PARAMETERS.iter().map(|(n, _)| *n).collect();
        bail!(
            "unknown sweep parameter `{name}` (known: {})",
            known.join(", ")
        );
    }
    let values: Vec<String> = if let [a, b, c] = values.split(':').collect::<Vec<_>>()[..] {
        let parse = |s: &str| {
            s.parse::<f64>()
                .with_context(|| format!("`{spec}`: `{s}` is not a number"))
        };
        let (start, stop, step) = (parse(a)?, parse(b)?, parse(c)?);
        if !(step > 0.0 && stop >= start && (stop - start) / step <= 10_000.0) {
            bail!("`{spec}`: need step > 0, stop ≥ start and at most 10000 values");
        }
        let n = ((stop - start) / step + 1e-9).floor() as usize + 1;
        (0..n)
            .map(|i| format!("{}", start + step * i as f64))
            .collect()
    } else {
        let values: Vec<String> = values.split(',').map(|v| v.trim().to_string()).collect();
        if values.len() > 1 && values.iter().any(String::is_empty) {
            bail!("`{spec}`: an empty value between commas");
        }
        values.into_iter().filter(|v| !v.is_empty()).collect()
    };
    if values.is_empty() {
        bail!("`{spec}`: no values");
    }
    for v in &values {
        check_value(name, v)?;
    }
    Ok(Param {
        name: name.to_string(),
        values,
    })
}

fn number(name: &str, v: &str) -> Result<f64> {
    let x: f64 = v
        .parse()
        .with_context(|| format!("{name}: `{v}` is not a number"))?;
    if !x.is_finite() {
        bail!("{name}: `{v}` is not finite");
    }
    Ok(x)
}

/// The admissible values of a numeric parameter: (low, low included, high, unit), high
/// included. The same ranges as the scene keys and flags they stand for.
fn range_of(name: &str) -> (f64, bool, f64, &'static str) {
    match name {
        "theta_f" => (0.0, false, 89.0, "degrees"),
        // The obstacle's width, as in the scene file.
        "display_width" => (0.0, false, 100.0, "m"),
        // The eye stays inside the world (checked again after the move).
        "eye_x" | "eye_z" => (-MAX_COORDINATE, true, MAX_COORDINATE, "m"),
        // As `run --head-bias-cm`.
        "head_bias_x_cm" => (-500.0, true, 500.0, "cm"),
        "frontal_width" => (1.0, true, MAX_RESOLUTION as f64, "pixels"),
        _ => (f64::NEG_INFINITY, true, f64::INFINITY, ""),
    }
}

fn check_value(name: &str, v: &str) -> Result<()> {
    if name == "d2" {
        return v
            .parse::<WorkingDistance>()
            .map(|_| ())
            .map_err(anyhow::Error::msg);
    }
    let x = number(name, v)?;
    let (lo, lo_in, hi, unit) = range_of(name);
    let inside = (x > lo || (lo_in && x == lo)) && x <= hi;
    if !inside || (name == "frontal_width" && x.fract() != 0.0) {
        let open = if lo_in { '[' } else { '(' };
        let what = if name == "frontal_width" {
            "an integer "
        } else {
            ""
        };
        bail!(
            "{name} = {}: must be {what}in {open}{}, {}] {unit}",
            short(x),
            short(lo),
            short(hi)
        );
    }
    Ok(())
}

/// Applies one configuration to the scene and the options.
pub fn configure(
    base: &Scene,
    base_options: &RunOptions,
    config: &[(String, String)],
) -> Result<(Scene, RunOptions)> {
    let mut scene = base.clone();
    let mut options = base_options.clone();
    for (name, v) in config {
        match name.as_str() {
            "theta_f" => scene.frontal.half_angle_x = number(name, v)?.to_radians(),
            "d2" => options.d2 = v.parse().map_err(anyhow::Error::msg)?,
            "display_width" => {
                let d = number(name, v)?;
                let scale = d / scene.obstacle.width;
                scene.obstacle.width = d;
                scene.obstacle.display_resolution[0] =
                    ((scene.obstacle.display_resolution[0] as f64 * scale).round() as u32)
                        .clamp(1, 16384);
            }
            "eye_x" | "eye_z" => {
                let axis = if name == "eye_x" { DVec3::X } else { DVec3::Z };
                let shift = scene
                    .obstacle
                    .world_from_obstacle
                    .transform_vector3(axis * number(name, v)?);
                scene.driver.world_from_camera.translation += shift;
            }
            "head_bias_x_cm" => options.head_bias_cm[0] = number(name, v)?,
            "frontal_width" => options.frontal_width = Some(number(name, v)? as u32),
            _ => bail!("unknown sweep parameter `{name}`"),
        }
    }
    if scene
        .obstacle
        .world_from_obstacle
        .inverse()
        .transform_point3(scene.eye())
        .z
        <= 0.0
    {
        bail!("configuration {config:?} puts the eye behind the display");
    }
    if let Some(why) = out_of_world(scene.eye()) {
        bail!("configuration {config:?} moves the eye outside the world: {why}");
    }
    Ok((scene, options))
}

/// Every combination of the parameters' values, first parameter slowest.
pub fn combinations(params: &[Param]) -> Vec<Vec<(String, String)>> {
    params.iter().fold(vec![Vec::new()], |acc, p| {
        acc.into_iter()
            .flat_map(|prefix| {
                p.values
                    .iter()
                    .map(move |v| [prefix.clone(), vec![(p.name.clone(), v.clone())]].concat())
            })
            .collect()
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ranges_lists_and_errors() {
        assert_eq!(
            parse_param("theta_f=20:80:20").unwrap().values,
            ["20", "40", "60", "80"]
        );
        assert_eq!(
            parse_param("d2=inf,5,auto").unwrap().values,
            ["inf", "5", "auto"]
        );
        assert!(
            parse_param("fov=1,2")
                .unwrap_err()
                .to_string()
                .contains("unknown sweep parameter")
        );
        assert!(
            parse_param("theta_f=95")
                .unwrap_err()
                .to_string()
                .contains("(0, 89]")
        );
        assert!(parse_param("d2=-1").is_err());
        assert!(parse_param("theta_f=80:20:5").is_err());
        let c = combinations(&[
            parse_param("theta_f=20,40").unwrap(),
            parse_param("d2=inf,5").unwrap(),
        ]);
        assert_eq!(c.len(), 4);
        assert_eq!(
            c[1],
            vec![
                ("theta_f".to_string(), "20".to_string()),
                ("d2".to_string(), "5".to_string())
            ]
        );
    }
}
