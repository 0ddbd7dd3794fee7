//! The grid of a sweep: which parameters can vary, their values as given on the command line,
//! every combination, and each combination applied to a scene and run options.

use anyhow::{Context, Result, bail};
use glam::DVec3;

use crate::scene::Scene;
use crate::scene::limits::{
    MAX_COORDINATE, MAX_DISPLAY_SIZE, MAX_RESOLUTION, MIN_LENGTH, out_of_world,
};
use crate::scene::read::{MAX_HALF_ANGLE_DEG, MIN_HALF_ANGLE_DEG};
use crate::system::options::{MAX_HEAD_BIAS_CM, RunOptions};
use crate::util::number::short;

/// What a sweep can vary, each with the range of the scene key or option it sets.
pub const PARAMETERS: [(&str, &str); 8] = [
    (
        "theta_f",
        "frontal half angle θ_F (camera.frontal.half_angle_deg), degrees in [0.01, 89]",
    ),
    (
        "d2",
        "model working distance: inf, auto or metres in [1e-6, 1e6]",
    ),
    (
        "display_width",
        "display width D (obstacle.width), metres in [1e-6, 100] (display pixels scale with it)",
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
        "eye",
        "eyellipse: driver eyes drawn from the scene's [eyellipse] (sweep option `samples` N option `seed` S)",
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

/// Most configurations in one sweep's grid (the product of the parameters' value counts).
pub const MAX_CONFIGURATIONS: usize = 100_000;

/// Most values of one parameter.
pub const MAX_VALUES: usize = 10_000;

/// The value of `--param eye=eyellipse` before [`eyellipse_param`] draws its samples.
pub const EYELLIPSE: &str = "eyellipse";

/// The `eye` parameter of `samples` eyes drawn with `seed`: values `eyellipse:<seed>:<i>` for
/// i in 0..samples, each naming its eye wholly (so shards and resumed sweeps agree on it).
pub fn eyellipse_param(samples: usize, seed: u64) -> Param {
    Param {
        name: "eye".into(),
        values: (0..samples)
            .map(|i| format!("{EYELLIPSE}:{seed}:{i}"))
            .collect(),
    }
}

/// The (seed, index) of an `eye` value `eyellipse:<seed>:<i>`.
fn eyellipse_sample(v: &str) -> Result<(u64, u64)> {
    let parts: Vec<&str> = v.split(':').collect();
    match parts[..] {
        [EYELLIPSE, seed, index] => Ok((
            seed.parse()
                .with_context(|| format!("eye = {v}: bad seed"))?,
            index
                .parse()
                .with_context(|| format!("eye = {v}: bad sample index"))?,
        )),
        _ => bail!("eye = {v}: expected eyellipse:<seed>:<index>"),
    }
}

/// One swept parameter and its values (normalised: numbers as Rust writes the `f64` they
/// parse to, `inf` for `infinity`).
#[derive(Clone, Debug, PartialEq)]
pub struct Param {
    pub name: String,
    pub values: Vec<String>,
}

/// Parses `name=start:stop:step` or `name=v1,v2,...`. Spaces around the name and the values
/// are ignored, as around every number of the command line (`cli/args.rs`); a value given
/// twice (`d2=5,5`, or `5,5.0`) is an error naming it.
pub fn parse_param(spec: &str) -> Result<Param> {
    let (name, values) = spec
        .split_once('=')
        .with_context(|| format!("`{spec}`: expected name=start:stop:step or name=v1,v2,..."))?;
    let name = name.trim();
    if name == "eye" {
        // The samples are made by [`eyellipse_param`] once --samples and --seed are known.
        if values.trim() != "eyellipse" {
            bail!(
                "eye = `{}`: the only value is eyellipse (eyes sampled from the scene's [eyellipse] table; choose how many with option `samples` and their seed with option `seed`)",
                values.trim()
            );
        }
        return Ok(Param {
            name: name.to_string(),
            values: vec![EYELLIPSE.to_string()],
        });
    }
    if !PARAMETERS.iter().any(|(n, _)| *n == name) {
        let known: Vec<&str> = PARAMETERS.iter().map(|(n, _)| *n).collect();
        bail!(
            "unknown sweep parameter `{name}` (known: {})",
            known.join(", ")
        );
    }
    let values: Vec<String> = if let [a, b, c] = values.split(':').collect::<Vec<_>>()[..] {
        let parse = |s: &str| {
            s.trim()
                .parse::<f64>()
                .ok()
                .filter(|x| x.is_finite())
                .with_context(|| format!("`{spec}`: `{}` is not a finite number", s.trim()))
        };
        let (start, stop, step) = (parse(a)?, parse(b)?, parse(c)?);
        if !(step > 0.0 && stop >= start && (stop - start) / step < MAX_VALUES as f64) {
            bail!("`{spec}`: need step > 0, stop ≥ start and at most {MAX_VALUES} values");
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
    if values.len() > MAX_VALUES {
        bail!(
            "`{name}`: {} values, more than the limit of {MAX_VALUES}",
            values.len()
        );
    }
    let mut seen: Vec<(Value, &str)> = Vec::with_capacity(values.len());
    let mut normal = Vec::with_capacity(values.len());
    for v in &values {
        let value = check_value(name, v)?;
        if let Some((_, earlier)) = seen.iter().find(|(x, _)| *x == value) {
            let same = if earlier == v {
                format!("the value {v} is given twice")
            } else {
                format!("{v} is the value {earlier} again")
            };
            bail!("{name}: {same} (each configuration once: give each value once)");
        }
        seen.push((value, v));
        normal.push(value.text());
    }
    Ok(Param {
        name: name.to_string(),
        values: normal,
    })
}

/// A parameter value, parsed.
#[derive(Clone, Copy, PartialEq)]
enum Value {
    Number(f64),
    Inf,
    Auto,
}

impl Value {
    /// How the CSV and the configuration hold it.
    fn text(self) -> String {
        match self {
            Value::Number(x) => format!("{x}"),
            Value::Inf => "inf".into(),
            Value::Auto => "auto".into(),
        }
    }
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

/// The admissible values of a numeric parameter: `[low, high]` and the unit. The ranges of
/// the scene keys and options they set; a model distance is a length like the scene's.
fn range_of(name: &str) -> (f64, f64, &'static str) {
    match name {
        "theta_f" => (MIN_HALF_ANGLE_DEG, MAX_HALF_ANGLE_DEG, "degrees"),
        "d2" => (MIN_LENGTH, MAX_COORDINATE, "m"),
        // The obstacle's width, as in the scene file.
        "display_width" => (MIN_LENGTH, MAX_DISPLAY_SIZE, "m"),
        // The eye stays inside the world (checked again after the move).
        "eye_x" | "eye_z" => (-MAX_COORDINATE, MAX_COORDINATE, "m"),
        // As `run --head-bias-cm`.
        "head_bias_x_cm" => (-MAX_HEAD_BIAS_CM, MAX_HEAD_BIAS_CM, "cm"),
        "frontal_width" => (1.0, MAX_RESOLUTION as f64, "pixels"),
        _ => (f64::NEG_INFINITY, f64::INFINITY, ""),
    }
}

/// A parameter's name with its unit, for a plot's axis: `theta_f (°)`, `d2 (m)`.
pub fn axis_label(name: &str) -> String {
    match range_of(name).2 {
        "" => name.to_string(),
        "degrees" => format!("{name} (°)"),
        "pixels" => format!("{name} (px)"),
        unit => format!("{name} ({unit})"),
    }
}

fn check_value(name: &str, v: &str) -> Result<Value> {
    let (lo, hi, unit) = range_of(name);
    let integer = name == "frontal_width";
    let what = if integer { "an integer" } else { "a number" };
    let or_names = if name == "d2" { "inf, auto or " } else { "" };
    if name == "d2" {
        match v {
            "inf" | "infinity" => return Ok(Value::Inf),
            "auto" => return Ok(Value::Auto),
            _ => {}
        }
    }
    let x = v.parse::<f64>().ok();
    let inside =
        x.is_some_and(|x| x.is_finite() && x >= lo && x <= hi && (!integer || x.fract() == 0.0));
    match x {
        Some(x) if inside => Ok(Value::Number(x)),
        _ => {
            // A number too long for f64 reads as ±inf: show it as written (clipped when printed).
            let shown = x
                .filter(|x| x.is_finite())
                .map_or_else(|| format!("`{v}`"), short);
            bail!(
                "{name} = {shown}: must be {or_names}{what} in [{}, {}] {unit}",
                short(lo),
                short(hi)
            )
        }
    }
}

/// Refuses a grid of more than [`MAX_CONFIGURATIONS`] before any is made, naming each
/// parameter's count and their product.
pub fn check_grid_size(params: &[Param]) -> Result<usize> {
    let product = params
        .iter()
        .map(|p| p.values.len() as f64)
        .product::<f64>();
    if product > MAX_CONFIGURATIONS as f64 {
        let counts: Vec<String> = params
            .iter()
            .map(|p| format!("{} {}", p.name, p.values.len()))
            .collect();
        bail!(
            "the grid has {} = {} configurations, more than the limit of {MAX_CONFIGURATIONS}: sweep fewer values, or split the grid over several option `out` files",
            counts.join(" × "),
            short(product)
        );
    }
    Ok(product as usize)
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
                // The driver's head moves with the eye (`--head estimated` measures it).
                scene.move_eye(scene.eye() + shift);
            }
            "eye" => {
                let (seed, index) = eyellipse_sample(v)?;
                let ellipse = scene.eyellipse.with_context(|| {
                    format!(
                        "option `param` eye=eyellipse: the scene {} has no [eyellipse] table to draw eyes from",
                        base.path.display()
                    )
                })?;
                // The driver's view keeps its orientation; the eye and the head move, as for eye_x.
                scene.move_eye(ellipse.sample(seed, index));
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
    fn plot_axes_name_the_parameter_and_its_unit() {
        for (name, label) in [
            ("theta_f", "theta_f (°)"),
            ("d2", "d2 (m)"),
            ("display_width", "display_width (m)"),
            ("eye_x", "eye_x (m)"),
            ("head_bias_x_cm", "head_bias_x_cm (cm)"),
            ("frontal_width", "frontal_width (px)"),
        ] {
            assert_eq!(axis_label(name), label);
        }
    }

    fn refused(spec: &str) -> String {
        match parse_param(spec) {
            Ok(p) => panic!("{spec} gave {:?}", p.values),
            Err(e) => e.to_string(),
        }
    }

    #[test]
    fn an_eyellipse_value_names_its_seed_and_sample() {
        assert_eq!(eyellipse_sample("eyellipse:7:3").unwrap(), (7, 3));
        assert_eq!(
            eyellipse_param(2, 9).values,
            ["eyellipse:9:0", "eyellipse:9:1"]
        );
        for bad in [
            "eyellipse:x:3",
            "eyellipse:7:-1",
            "eyellipse:7",
            "ellipse:7:3",
        ] {
            assert!(eyellipse_sample(bad).is_err(), "{bad}");
        }
        assert_eq!(
            parse_param(" eye = eyellipse ").unwrap().values,
            [EYELLIPSE]
        );
        assert!(refused("eye=0.1").contains("the only value is eyellipse"));
    }

    /// The limits of a parameter's values, at their edges: a step of −0 is no step, at most
    /// [`MAX_VALUES`] values however given, an empty value named as such.
    #[test]
    fn the_value_limits_hold_at_their_edges() {
        let steps = "need step > 0, stop ≥ start and at most 10000 values";
        for spec in [
            "theta_f=20:80:-0",
            "theta_f=20:80:0",
            "theta_f=20:80:-5",
            "theta_f=80:20:5",
            // 10001 values: one too many, said before any is made.
            "frontal_width=1:10001:1",
            "theta_f=0.01:89:0.001",
            "eye_x=0:1e9:1",
        ] {
            assert!(refused(spec).contains(steps), "{spec}");
        }
        let range = parse_param("frontal_width=1:10000:1").unwrap();
        assert_eq!(range.values.len(), MAX_VALUES);
        assert_eq!(range.values[MAX_VALUES - 1], "10000");
        let even = parse_param("theta_f=1:79.1171875:0.0078125").unwrap();
        assert_eq!(
            (even.values.len(), even.values[1].as_str()),
            (MAX_VALUES, "1.0078125")
        );
        let list = |n: usize| {
            let values: Vec<String> = (0..n).map(|i| format!("{}", 1 + i)).collect();
            format!("frontal_width={}", values.join(","))
        };
        assert_eq!(
            parse_param(&list(MAX_VALUES)).unwrap().values.len(),
            MAX_VALUES
        );
        assert!(
            refused(&list(MAX_VALUES + 1)).contains("10001 values, more than the limit of 10000")
        );
        assert!(refused("theta_f=").contains("no values"));
        assert!(refused("theta_f= , ").contains("an empty value between commas"));
        assert!(refused("theta_f=20,,40").contains("an empty value between commas"));
        assert!(refused("theta_f=20,").contains("an empty value between commas"));
        assert!(refused("d2=5,5").contains("the value 5 is given twice"));
        assert!(refused("d2=5,5.0").contains("5.0 is the value 5 again"));
        assert!(refused("d2=inf,infinity").contains("infinity is the value inf again"));
    }

    /// A grid of exactly [`MAX_CONFIGURATIONS`] is made; one more is refused, naming each
    /// parameter's count and the product.
    #[test]
    fn the_grid_size_limit_is_inclusive() {
        let param = |name: &str, n: usize| Param {
            name: name.into(),
            values: (0..n).map(|i| i.to_string()).collect(),
        };
        let exact = [param("theta_f", 10), param("d2", 10_000)];
        assert_eq!(check_grid_size(&exact).unwrap(), MAX_CONFIGURATIONS);
        assert_eq!(
            check_grid_size(&[param("eye_x", 7), param("eye_z", 3)]).unwrap(),
            21
        );
        let over = [param("theta_f", 11), param("d2", 9091)];
        let err = check_grid_size(&over).unwrap_err().to_string();
        assert!(
            err.contains(
                "theta_f 11 × d2 9091 = 100001 configurations, more than the limit of 100000"
            ),
            "{err}"
        );
    }

    /// A bad value's message gives its parameter's admissible values: the names only for d2.
    #[test]
    fn a_bad_value_names_the_admissible_ones() {
        assert_eq!(
            refused("d2=-1"),
            "d2 = -1: must be inf, auto or a number in [1e-6, 1000000] m"
        );
        assert_eq!(
            refused("theta_f=inf"),
            "theta_f = `inf`: must be a number in [0.01, 89] degrees"
        );
        assert_eq!(
            refused("frontal_width=2.5"),
            "frontal_width = 2.5: must be an integer in [1, 16384] pixels"
        );
        assert_eq!(
            refused("head_bias_x_cm=-501"),
            "head_bias_x_cm = -501: must be a number in [-500, 500] cm"
        );
    }

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
                .contains("[0.01, 89] degrees")
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
