//! The keyword arguments of `seethru.run`, with the ranges and choices of the command line's
//! flags of the same names (`seethru run --help`): unknown keywords are refused.

use clap::ValueEnum;
use pyo3::prelude::*;
use pyo3::types::PyDict;
use seethru::measure::compare::{Candidate, compare_reads};
use seethru::measure::hazard::HAZARD_BOUND_ARCMIN;
use seethru::render::settings::MAX_SPP;
use seethru::scene::source::MAX_RESOLUTION;
use seethru::system::depth_sensor::{SensorKind, SensorOptions};
use seethru::system::display::{DisplayModel, Filter};
use seethru::system::eyes::{Eye, Eyes, MAX_IPD};
use seethru::system::memory::DEFAULT_MAX_MEMORY_GIB;
use seethru::system::options::{
    HeadSource, MAX_HEAD_BIAS_CM, Outside, RunOptions, WorkingDistance,
};
use seethru::system::reads::{ReadWhen, capture_reads, first_ignored, run_reads};
use seethru::system::scene_model::{Fill, SceneModelOptions};

use crate::errors::bad_value;

/// Smallest positive size, distance or width accepted (as on the command line).
const MIN_POSITIVE: f64 = 1e-6;

pub fn int_in(key: &str, v: i64, min: i64, max: i64) -> PyResult<i64> {
    match (min..=max).contains(&v) {
        true => Ok(v),
        false => Err(bad_value(format!(
            "{key}={v} is out of range: must be an integer in [{min}, {max}]"
        ))),
    }
}

pub fn real_in(key: &str, v: f64, min: f64, max: f64) -> PyResult<f64> {
    match v.is_finite() && (min..=max).contains(&v) {
        true => Ok(v),
        false => Err(bad_value(format!(
            "{key}={v} is out of range: must be a number in [{min}, {max}]"
        ))),
    }
}

/// An optional image side, pixels in [1, 16384].
pub fn pixels(key: &str, v: Option<i64>) -> PyResult<Option<u32>> {
    v.map(|v| int_in(key, v, 1, MAX_RESOLUTION as i64).map(|v| v as u32))
        .transpose()
}

fn choice<T: ValueEnum>(key: &str, value: &str) -> PyResult<T> {
    let names = || {
        T::value_variants()
            .iter()
            .filter_map(|v| v.to_possible_value())
            .map(|p| p.get_name().to_string())
            .collect::<Vec<_>>()
    };
    T::value_variants()
        .iter()
        .find(|v| v.to_possible_value().is_some_and(|p| p.get_name() == value))
        .cloned()
        .ok_or_else(|| {
            bad_value(format!(
                "{key}={value:?} is not one of {}",
                names().join(", ")
            ))
        })
}

/// A working distance: a number of metres in [1e-6, 1e6], inf (a float or "inf") or "auto".
pub fn working_distance(key: &str, value: &Bound<'_, PyAny>) -> PyResult<WorkingDistance> {
    match value.extract::<f64>() {
        Ok(v) if v == f64::INFINITY => Ok(WorkingDistance::Infinity),
        Ok(v) => real_in(key, v, MIN_POSITIVE, 1e6).map(WorkingDistance::Metres),
        Err(_) => value
            .extract::<String>()
            .map_err(|_| bad_value(format!("{key}: a number, inf or auto is needed")))?
            .parse()
            .map_err(|e: String| bad_value(format!("{key}={e}"))),
    }
}

/// The keywords `seethru.run` accepts, in `seethru run`'s order (its flags less those that
/// name files, threads or progress).
pub const RUN_KEYS: [&str; 27] = [
    "method",
    "d2",
    "head",
    "head_bias_cm",
    "head_jitter_cm",
    "seed",
    "feature_width",
    "require_confident_head",
    "outside",
    "filter",
    "display",
    "frontal_width",
    "back_width",
    "eyes",
    "ipd",
    "target_eye",
    "band",
    "hazard_bound_arcmin",
    "depth_sensor",
    "depth_resolution",
    "depth_range",
    "depth_noise",
    "depth_quantum",
    "fill",
    "width",
    "height",
    "spp",
];

/// The keywords `seethru.capture` accepts besides `depth`, in `seethru capture`'s order.
pub const CAPTURE_KEYS: [&str; 20] = [
    "head",
    "head_bias_cm",
    "head_jitter_cm",
    "seed",
    "feature_width",
    "require_confident_head",
    "frontal_width",
    "back_width",
    "eyes",
    "ipd",
    "target_eye",
    "depth_sensor",
    "depth_resolution",
    "depth_range",
    "depth_noise",
    "depth_quantum",
    "fill",
    "width",
    "height",
    "spp",
];

/// The keywords `seethru.compare` accepts besides `methods`, in `seethru compare`'s order.
pub const COMPARE_KEYS: [&str; 15] = [
    "head",
    "seed",
    "frontal_width",
    "back_width",
    "band",
    "hazard_bound_arcmin",
    "depth_sensor",
    "depth_resolution",
    "depth_range",
    "depth_noise",
    "depth_quantum",
    "fill",
    "width",
    "height",
    "spp",
];

/// The function whose keywords are read, with what decides which of them it reads: the
/// rules are the library's, those of the command of the same name.
pub enum Caller<'a> {
    Run,
    Capture { depth: bool },
    Compare { candidates: &'a [Candidate] },
}

impl Caller<'_> {
    fn keys(&self) -> &'static [&'static str] {
        match self {
            Caller::Run => &RUN_KEYS,
            Caller::Capture { .. } => &CAPTURE_KEYS,
            Caller::Compare { .. } => &COMPARE_KEYS,
        }
    }

    fn reads(&self, options: &RunOptions) -> Vec<ReadWhen> {
        match self {
            Caller::Run => run_reads(options, false),
            Caller::Capture { depth } => capture_reads(options, *depth),
            Caller::Compare { candidates } => compare_reads(candidates, false, options),
        }
    }
}

/// What `seethru.run` runs with: the pipeline's options, the border band and the memory limit.
pub struct RunChoices {
    pub options: RunOptions,
    pub band: u32,
    /// Hazard visibility's misregistration bound, arcmin.
    pub hazard_bound_arcmin: f64,
    pub max_memory: f64,
}

/// Reads the keywords of `caller`; defaults are its command's. A keyword the call would
/// ignore under the others given is refused, in the command's words with keyword names.
pub fn run_choices(kwargs: Option<&Bound<'_, PyDict>>, caller: Caller) -> PyResult<RunChoices> {
    let mut options = RunOptions::default();
    let mut sensor = SensorOptions::default();
    let mut fill = Fill::None;
    let (mut band, mut max_memory) = (5u32, DEFAULT_MAX_MEMORY_GIB);
    let mut hazard_bound_arcmin = HAZARD_BOUND_ARCMIN;
    let mut given: Vec<String> = Vec::new();
    let (mut eyes, mut target, mut ipd) = ("mono".to_string(), Eye::Cyclopean, 0.064);
    if let Some(kwargs) = kwargs {
        for (key, value) in kwargs.iter() {
            let key: String = key.extract()?;
            // None stands for the default, as an absent flag does.
            let known = caller.keys().contains(&key.as_str()) || key == "max_memory";
            if !known {
                return Err(bad_value(format!(
                    "unknown option {key:?}: the options are {}, max_memory",
                    caller.keys().join(", ")
                )));
            }
            if value.is_none() {
                continue;
            }
            given.push(format!("--{}", key.replace('_', "-")));
            let text = || -> PyResult<String> {
                value
                    .extract::<String>()
                    .map_err(|_| bad_value(format!("{key}: a string is needed")))
            };
            let int = |min: i64, max: i64| -> PyResult<i64> {
                let v: i64 = value
                    .extract()
                    .map_err(|_| bad_value(format!("{key}: an integer is needed")))?;
                int_in(&key, v, min, max)
            };
            let real = |min: f64, max: f64| -> PyResult<f64> {
                let v: f64 = value
                    .extract()
                    .map_err(|_| bad_value(format!("{key}: a number is needed")))?;
                real_in(&key, v, min, max)
            };
            let side = || int(1, MAX_RESOLUTION as i64).map(|v| Some(v as u32));
            match key.as_str() {
                "method" => options.method = choice(&key, &text()?)?,
                "d2" => options.d2 = working_distance(&key, &value)?,
                "head" => options.head = choice::<HeadSource>(&key, &text()?)?,
                "head_bias_cm" => {
                    let v: [f64; 3] = value.extract().map_err(|_| {
                        bad_value("head_bias_cm: three numbers (x, y, z) are needed")
                    })?;
                    for (axis, c) in ["x", "y", "z"].iter().zip(v) {
                        real_in(
                            &format!("head_bias_cm {axis}"),
                            c,
                            -MAX_HEAD_BIAS_CM,
                            MAX_HEAD_BIAS_CM,
                        )?;
                    }
                    options.head_bias_cm = v;
                }
                "head_jitter_cm" => options.head_jitter_cm = real(0.0, 100.0)?,
                "seed" => options.seed = int(0, u32::MAX as i64)? as u32,
                "feature_width" => options.feature_width = real(MIN_POSITIVE, 1.0)?,
                "require_confident_head" => {
                    options.require_confident_head = value
                        .extract::<bool>()
                        .map_err(|_| bad_value(format!("{key}: True or False is needed")))?;
                }
                "hazard_bound_arcmin" => hazard_bound_arcmin = real(MIN_POSITIVE, 10800.0)?,
                "outside" => options.outside = choice::<Outside>(&key, &text()?)?,
                "filter" => options.filter = choice::<Filter>(&key, &text()?)?,
                "display" => options.display = choice::<DisplayModel>(&key, &text()?)?,
                "frontal_width" => options.frontal_width = side()?,
                "back_width" => options.back_width = side()?,
                "eyes" => {
                    eyes = text()?;
                    if !["mono", "left", "right"].contains(&eyes.as_str()) {
                        return Err(bad_value(format!(
                            "eyes={eyes:?} is not one of mono, left, right (for both eyes, run left and right)"
                        )));
                    }
                }
                "ipd" => ipd = real(MIN_POSITIVE, MAX_IPD)?,
                "target_eye" => target = choice::<Eye>(&key, &text()?)?,
                "band" => band = int(1, 1000)? as u32,
                "depth_sensor" => sensor.kind = choice::<SensorKind>(&key, &text()?)?,
                "depth_resolution" => sensor.width = side()?,
                "depth_range" => sensor.range_m = Some(real(MIN_POSITIVE, 1e6)?),
                "depth_noise" => sensor.noise_1m = Some(real(0.0, 10.0)?),
                "depth_quantum" => sensor.quantum_1m = Some(real(0.0, 10.0)?),
                "fill" => fill = choice::<Fill>(&key, &text()?)?,
                "width" => options.width = side()?,
                "height" => options.height = side()?,
                "spp" => options.spp = int(1, MAX_SPP as i64)? as u32,
                "max_memory" => max_memory = real(MIN_POSITIVE, 4096.0)?,
                _ => unreachable!("every key of {:?} is read", caller.keys()),
            }
        }
    }
    options.eyes = Eyes {
        view: match eyes.as_str() {
            "left" => Eye::Left,
            "right" => Eye::Right,
            _ => Eye::Cyclopean,
        },
        target,
        ipd,
    };
    options.scene_model = SceneModelOptions { sensor, fill };
    options.progress = false;
    if let Some(rule) = first_ignored(&caller.reads(&options), |flag| {
        given.iter().any(|g| g == flag)
    }) {
        return Err(bad_value(rule.keyword_refusal()));
    }
    Ok(RunChoices {
        options,
        band,
        hazard_bound_arcmin,
        max_memory,
    })
}

/// Keyword arguments read one by one with their ranges; [`Keywords::finish`] refuses the rest.
pub struct Keywords<'py> {
    given: Vec<(String, Bound<'py, PyAny>)>,
    read: Vec<&'static str>,
}

impl<'py> Keywords<'py> {
    pub fn new(kwargs: Option<&Bound<'py, PyDict>>) -> PyResult<Self> {
        let mut given = Vec::new();
        if let Some(kwargs) = kwargs {
            for (k, v) in kwargs.iter() {
                given.push((k.extract::<String>()?, v));
            }
        }
        Ok(Keywords {
            given,
            read: Vec::new(),
        })
    }

    /// The value of `key` unless absent or None.
    fn value(&mut self, key: &'static str) -> Option<Bound<'py, PyAny>> {
        self.read.push(key);
        self.given
            .iter()
            .find(|(k, v)| k == key && !v.is_none())
            .map(|(_, v)| v.clone())
    }

    pub fn real(&mut self, key: &'static str, default: f64, min: f64, max: f64) -> PyResult<f64> {
        match self.value(key) {
            None => Ok(default),
            Some(v) => {
                let v: f64 = v
                    .extract()
                    .map_err(|_| bad_value(format!("{key}: a number is needed")))?;
                real_in(key, v, min, max)
            }
        }
    }

    /// A number in [min, max] or infinity (a distance `inf`).
    pub fn real_or_inf(
        &mut self,
        key: &'static str,
        default: f64,
        min: f64,
        max: f64,
    ) -> PyResult<f64> {
        match self.value(key) {
            None => Ok(default),
            Some(v) => match v.extract::<f64>() {
                Ok(f) if f == f64::INFINITY => Ok(f),
                Ok(f) => real_in(key, f, min, max),
                Err(_) => match v.extract::<String>().as_deref() {
                    Ok("inf") => Ok(f64::INFINITY),
                    _ => Err(bad_value(format!(
                        "{key}: a number in [{min}, {max}] or inf is needed"
                    ))),
                },
            },
        }
    }

    pub fn required(&mut self, key: &'static str, min: f64, max: f64) -> PyResult<f64> {
        match self.value(key) {
            None => Err(bad_value(format!(
                "{key} is required: a number in [{min}, {max}]"
            ))),
            Some(_) => self.real(key, 0.0, min, max),
        }
    }

    pub fn int(&mut self, key: &'static str, default: i64, min: i64, max: i64) -> PyResult<i64> {
        match self.value(key) {
            None => Ok(default),
            Some(v) => {
                let v: i64 = v
                    .extract()
                    .map_err(|_| bad_value(format!("{key}: an integer is needed")))?;
                int_in(key, v, min, max)
            }
        }
    }

    /// Whether `key` was given (and not None).
    pub fn given(&self, key: &str) -> bool {
        self.given.iter().any(|(k, v)| k == key && !v.is_none())
    }

    /// The value of `key`, any type, unless absent or None.
    pub fn any(&mut self, key: &'static str) -> Option<Bound<'py, PyAny>> {
        self.value(key)
    }

    /// A choice among a clap value enum's names, `default` when absent.
    pub fn choice<T: ValueEnum>(&mut self, key: &'static str, default: T) -> PyResult<T> {
        match self.string(key)? {
            None => Ok(default),
            Some(v) => choice(key, &v),
        }
    }

    /// A switch (a command line flag without value): a bool, False when absent.
    pub fn flag(&mut self, key: &'static str) -> PyResult<bool> {
        match self.value(key) {
            None => Ok(false),
            Some(v) => v
                .extract::<bool>()
                .map_err(|_| bad_value(format!("{key}: True or False is needed"))),
        }
    }

    /// An optional image side, pixels in [1, 16384].
    pub fn side(&mut self, key: &'static str) -> PyResult<Option<u32>> {
        match self.value(key) {
            None => Ok(None),
            Some(_) => Ok(Some(self.int(key, 1, 1, MAX_RESOLUTION as i64)? as u32)),
        }
    }

    /// A string, or `None` when absent.
    pub fn string(&mut self, key: &'static str) -> PyResult<Option<String>> {
        self.value(key)
            .map(|v| {
                v.extract::<String>()
                    .map_err(|_| bad_value(format!("{key}: a string is needed")))
            })
            .transpose()
    }

    pub fn head_bias_cm(&mut self) -> PyResult<[f64; 3]> {
        match self.value("head_bias_cm") {
            None => Ok([0.0; 3]),
            Some(v) => {
                let v: [f64; 3] = v
                    .extract()
                    .map_err(|_| bad_value("head_bias_cm: three numbers (x, y, z) are needed"))?;
                for (axis, c) in ["x", "y", "z"].iter().zip(v) {
                    real_in(
                        &format!("head_bias_cm {axis}"),
                        c,
                        -MAX_HEAD_BIAS_CM,
                        MAX_HEAD_BIAS_CM,
                    )?;
                }
                Ok(v)
            }
        }
    }

    /// Refuses keywords that were not read.
    pub fn finish(self) -> PyResult<()> {
        match self
            .given
            .iter()
            .find(|(k, _)| !self.read.contains(&k.as_str()))
        {
            Some((k, _)) => Err(bad_value(format!(
                "unknown option {k:?}: the options are {}",
                self.read.join(", ")
            ))),
            None => Ok(()),
        }
    }
}

/// A choice among a clap value enum's names (as on the command line).
pub fn choice_of<T: ValueEnum>(key: &str, value: &str) -> PyResult<T> {
    choice(key, value)
}
