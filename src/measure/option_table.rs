//! Every option of a run, declared once: its name, type, unit, range or choices, default,
//! one-line help, the settings under which it is read and the commands that take it.
//!
//! The command line's flags (`--head-jitter-cm`) are made from this table, the Python
//! keywords (`head_jitter_cm=`) are read through it, and the stubs (`__init__.pyi`) and
//! `docs/reference/options.md` are checked against it by `tests/option_table.rs`, which fails
//! on drift. `measure/run_spec.rs` builds one validated run from the values. Adding an
//! option is a row here plus the line that stores it (`RunSpec::set`).
//!
//! The table sits in `measure/` because a run's options include its measurement's (`band`,
//! `hazard_bound_arcmin`); what only a front end has (output folders, EXR contents, threads,
//! progress) is that front end's.

pub use crate::measure::option_value::{Default, Kind, Value, choice_of, choice_values};
use crate::render::settings::MAX_SPP;
use crate::scene::limits::{MAX_COORDINATE, MIN_LENGTH};
use crate::scene::source::MAX_RESOLUTION;
use crate::system::depth_sensor::SensorKind;
use crate::system::display::{DisplayModel, Filter};
use crate::system::eyes::{Eye, MAX_IPD, Viewing};
use crate::system::options::{HeadSource, MAX_HEAD_BIAS_CM, Method, Outside};
use crate::system::scene_model_options::Fill;

/// The commands whose options the table declares (with the Python functions of the same
/// names).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Command {
    /// `seethru run`, `seethru.run`.
    Run,
    /// `seethru capture`, `seethru.capture`.
    Capture,
    /// `seethru compare`, `seethru.compare`.
    Compare,
    /// `seethru sequence`, `seethru.sequence`: the options it shares with a run (its own,
    /// the timeline's and the head's motion, are its front ends').
    Sequence,
    /// `seethru render`, `Scene.render`: the size, samples and memory bound of the views it
    /// renders.
    Render,
}

impl Command {
    pub const ALL: [Command; 5] = [
        Command::Run,
        Command::Capture,
        Command::Compare,
        Command::Sequence,
        Command::Render,
    ];

    /// `run`, `capture`, `compare`, `sequence`, `render`.
    pub fn name(self) -> &'static str {
        match self {
            Command::Run => "run",
            Command::Capture => "capture",
            Command::Compare => "compare",
            Command::Sequence => "sequence",
            Command::Render => "render",
        }
    }
}

/// One option.
#[derive(Clone, Copy, Debug)]
pub struct OptionSpec {
    /// The name: `head_jitter_cm` (Python's keyword; the flag is `--head-jitter-cm`).
    pub name: &'static str,
    pub kind: Kind,
    /// The unit of a number (`pixels`, `metres`, `cm`, `arcmin`, `GiB`), empty for none.
    pub unit: &'static str,
    pub default: Default,
    /// One line: what the option does.
    pub help: &'static str,
    /// Settings under which it is read (`method=depth`), empty for always; the rules
    /// themselves are `system::reads`'s, and a test holds each option read under these.
    pub read_with: &'static [(&'static str, &'static str)],
    /// The commands that take it.
    pub commands: &'static [Command],
}

impl OptionSpec {
    /// The command line's flag: `--head-jitter-cm`.
    pub fn flag(&self) -> String {
        crate::system::reads::flag_of(self.name)
    }

    /// Reads a value written as on the command line (spaces around it ignored); the error
    /// says what it must be: `must be an integer in [1, 16384]`.
    pub fn parse(&self, text: &str) -> Result<Value, String> {
        self.kind
            .parse(text)
            .ok_or_else(|| format!("must be {}", self.kind.need()))
    }

    /// The default value, `None` where it is derived.
    pub fn default_value(&self) -> Option<Value> {
        self.value_of_default(self.default)
    }

    /// What the option is when `command` is not given it: the table's default, or the
    /// command's own ([`COMMAND_DEFAULTS`]).
    pub fn default_for(&self, command: Command) -> Default {
        COMMAND_DEFAULTS
            .iter()
            .find(|(c, name, _)| *c == command && *name == self.name)
            .map_or(self.default, |(_, _, default)| *default)
    }

    /// The value of [`OptionSpec::default_for`] `command`, `None` where it is derived.
    pub fn default_value_for(&self, command: Command) -> Option<Value> {
        self.value_of_default(self.default_for(command))
    }

    /// The value of `default` (one of this option's), `None` where it is derived.
    fn value_of_default(&self, default: Default) -> Option<Value> {
        match default {
            Default::Value(text) => Some(
                self.parse(text)
                    .unwrap_or_else(|e| panic!("the default of {}: {e}", self.name)),
            ),
            Default::Derived(_) => None,
        }
    }

    /// Whether `command` takes this option.
    pub fn taken_by(&self, command: Command) -> bool {
        self.commands.contains(&command)
    }
}

/// The option named `name`, if any.
pub fn option(name: &str) -> Option<&'static OptionSpec> {
    OPTIONS.iter().find(|o| o.name == name)
}

/// The options `command` takes, in the table's order.
pub fn options_of(command: Command) -> impl Iterator<Item = &'static OptionSpec> {
    OPTIONS.iter().filter(move |o| o.taken_by(command))
}

const PIXELS: Kind = Kind::Integer {
    min: 1,
    max: MAX_RESOLUTION as u64,
};
/// The commands that run the system: each but `render`.
/// Longest camera latency, ms: a run's, and each of a sequence's (which takes a list of
/// them with its own parser: one sequence per latency).
pub const MAX_LATENCY_MS: f64 = 10_000.0;

const RUNS: &[Command] = &[
    Command::Run,
    Command::Capture,
    Command::Compare,
    Command::Sequence,
];
/// Every command: an image's size, samples and memory bound.
const ALL: &[Command] = &[
    Command::Run,
    Command::Capture,
    Command::Compare,
    Command::Sequence,
    Command::Render,
];
/// Run, capture and compare: a sequence takes its head's source as `head_source`.
const SINGLE_FRAMES: &[Command] = &[Command::Run, Command::Capture, Command::Compare];
const RUN_SEQUENCE: &[Command] = &[Command::Run, Command::Sequence];
const RUN_CAPTURE: &[Command] = &[Command::Run, Command::Capture];
const RUN_CAPTURE_SEQUENCE: &[Command] = &[Command::Run, Command::Capture, Command::Sequence];
const RUN_COMPARE: &[Command] = &[Command::Run, Command::Compare];
const RUN_COMPARE_SEQUENCE: &[Command] = &[Command::Run, Command::Compare, Command::Sequence];
const CAPTURE: &[Command] = &[Command::Capture];

/// Where a command's default differs from the table's: a sequence renders many frames, so
/// smaller and with one sample, and a crop past the frontal view is shown black and counted
/// (a moving eye leaves it now and then) instead of stopping the sequence.
pub static COMMAND_DEFAULTS: &[(Command, &str, Default)] = &[
    (Command::Sequence, "outside", Default::Value("black")),
    (
        Command::Sequence,
        "frontal_width",
        Default::Derived("the driver views' width"),
    ),
    (Command::Sequence, "width", Default::Value("640")),
    (Command::Sequence, "spp", Default::Value("1")),
    (
        Command::Render,
        "width",
        Default::Derived("each view's camera's"),
    ),
    (
        Command::Render,
        "height",
        Default::Derived("from the width and each view's camera's aspect"),
    ),
];
const ESTIMATED: &[(&str, &str)] = &[("head", "estimated")];
/// The scene model's depth sensor is read by `method` depth in a run, by `depth` in a capture.
const DEPTH: &[(&str, &str)] = &[("method", "depth"), ("depth", "true")];
/// A sensor's settings: those of a noisy one (the ideal sensor has none).
const NOISY_DEPTH: &[(&str, &str)] = &[
    ("method", "depth"),
    ("depth", "true"),
    ("depth_sensor", "tof"),
];

/// The table: every option of `run`, `capture` and `compare`, and those `sequence` and
/// `render` share with them, in `seethru run --help`'s order.
pub static OPTIONS: &[OptionSpec] = &[
    OptionSpec {
        name: "method",
        kind: Kind::Choice(choice_values::<Method>),
        unit: "",
        default: Default::Value("planar"),
        help: "How the display image is made: none (the whole frontal image), planar (the paper's compensation), ground (the road plane), plane-fit (a plane fitted to the depth sensor's points) or depth (per-pixel reprojection with the depth sensor's depth).",
        read_with: &[],
        commands: RUN_SEQUENCE,
    },
    OptionSpec {
        name: "d2",
        kind: Kind::Distance {
            min: MIN_LENGTH,
            max: MAX_COORDINATE,
        },
        unit: "metres",
        default: Default::Value("inf"),
        help: "Working distance of the planar model: inf, auto (the median frontal depth behind the display) or metres.",
        read_with: &[],
        commands: RUN_SEQUENCE,
    },
    OptionSpec {
        name: "head",
        kind: Kind::Choice(choice_values::<HeadSource>),
        unit: "",
        default: Default::Value("oracle"),
        help: "Where the eye comes from: oracle (the true eye), estimated (face detection on the back camera's image) or model (a tracker's noise and dropouts).",
        read_with: &[],
        commands: SINGLE_FRAMES,
    },
    OptionSpec {
        name: "head_bias_cm",
        kind: Kind::Triple {
            max: MAX_HEAD_BIAS_CM,
        },
        unit: "cm",
        default: Default::Value("0,0,0"),
        help: "Head-tracking bias x,y,z in the obstacle's frame (e.g. 1,0,0 or -1,0,0).",
        read_with: &[],
        commands: RUN_CAPTURE_SEQUENCE,
    },
    OptionSpec {
        name: "head_jitter_cm",
        kind: Kind::Real {
            min: 0.0,
            max: 100.0,
        },
        unit: "cm",
        default: Default::Value("0"),
        help: "Head-tracking jitter: the standard deviation per axis of each estimate.",
        read_with: &[],
        commands: RUN_CAPTURE_SEQUENCE,
    },
    OptionSpec {
        name: "seed",
        kind: Kind::Integer {
            min: 0,
            max: u32::MAX as u64,
        },
        unit: "",
        default: Default::Value("1"),
        help: "Seed of the head jitter, the tracker model's noise, the depth sensor's noise and the plane fit.",
        read_with: &[("head_jitter_cm", "1")],
        commands: RUNS,
    },
    OptionSpec {
        name: "feature_width",
        kind: Kind::Real {
            min: MIN_LENGTH,
            max: 1.0,
        },
        unit: "metres",
        default: Default::Value("0.064"),
        help: "The face detector's known feature width A (the interpupillary distance).",
        read_with: ESTIMATED,
        commands: RUN_CAPTURE_SEQUENCE,
    },
    OptionSpec {
        name: "require_confident_head",
        kind: Kind::Switch,
        unit: "",
        default: Default::Value("false"),
        help: "Stop with an error when a head estimate's confidence is below 0.5 (else a warning); image-based head estimates only.",
        read_with: ESTIMATED,
        commands: RUN_CAPTURE_SEQUENCE,
    },
    OptionSpec {
        name: "min_head_confidence",
        kind: Kind::Real { min: 0.0, max: 1.0 },
        unit: "",
        default: Default::Value("0.5"),
        help: "The confidence below which a head estimate is unreliable: warned about, or refused with require_confident_head.",
        read_with: ESTIMATED,
        commands: RUN_CAPTURE_SEQUENCE,
    },
    OptionSpec {
        name: "speed",
        kind: Kind::Real {
            min: 0.0,
            max: 300.0,
        },
        unit: "km/h",
        default: Default::Value("0"),
        help: "Vehicle speed along the road (world -z); a single frame sees it through the frontal camera's rolling readout and exposure.",
        read_with: &[],
        commands: RUNS,
    },
    OptionSpec {
        name: "yaw_rate",
        kind: Kind::Real {
            min: -180.0,
            max: 180.0,
        },
        unit: "deg/s",
        default: Default::Value("0"),
        help: "Vehicle yaw rate about the driver's eye, > 0 turning left; a single frame sees it through the frontal camera's rolling readout and exposure.",
        read_with: &[],
        commands: RUNS,
    },
    OptionSpec {
        name: "latency_camera",
        kind: Kind::Real {
            min: 0.0,
            max: MAX_LATENCY_MS,
        },
        unit: "ms",
        default: Default::Value("0"),
        help: "Time from the frontal camera's capture to the instant the driver sees the display: the vehicle's motion (speed, yaw_rate) carries the camera on meanwhile. A sequence takes a list of them as its own flag.",
        read_with: &[],
        commands: SINGLE_FRAMES,
    },
    OptionSpec {
        name: "outside",
        kind: Kind::Choice(choice_values::<Outside>),
        unit: "",
        default: Default::Value("error"),
        help: "When the crop leaves the frontal view: error, or black (counted as missing).",
        read_with: &[],
        commands: RUN_SEQUENCE,
    },
    OptionSpec {
        name: "filter",
        kind: Kind::Choice(choice_values::<Filter>),
        unit: "",
        default: Default::Value("bilinear"),
        help: "Colour resampling of the display image.",
        read_with: &[],
        commands: RUN_SEQUENCE,
    },
    OptionSpec {
        name: "display",
        kind: Kind::Choice(choice_values::<DisplayModel>),
        unit: "",
        default: Default::Value("pixels"),
        help: "pixels: the physical display; ideal: unlimited display and frontal resolution, so that only the planar model's error remains.",
        read_with: &[],
        commands: RUN_SEQUENCE,
    },
    OptionSpec {
        name: "frontal_width",
        kind: PIXELS,
        unit: "pixels",
        default: Default::Derived("the scene's"),
        help: "Frontal camera width (aspect ratio kept).",
        read_with: &[],
        commands: RUNS,
    },
    OptionSpec {
        name: "back_width",
        kind: PIXELS,
        unit: "pixels",
        default: Default::Derived("the scene's"),
        help: "Back camera width (aspect ratio kept).",
        read_with: &[],
        commands: RUNS,
    },
    OptionSpec {
        name: "eyes",
        kind: Kind::Choice(choice_values::<Viewing>),
        unit: "",
        default: Default::Value("mono"),
        help: "The eyes the driver's views are rendered from: mono (the scene's driver camera), left, right, or both (each in turn, with their binocular mismatch; `seethru run` only).",
        read_with: &[],
        commands: RUN_CAPTURE,
    },
    OptionSpec {
        name: "ipd",
        kind: Kind::Real {
            min: MIN_LENGTH,
            max: MAX_IPD,
        },
        unit: "metres",
        default: Default::Value("0.064"),
        help: "Interpupillary distance.",
        read_with: &[("eyes", "left")],
        commands: RUN_CAPTURE,
    },
    OptionSpec {
        name: "target_eye",
        kind: Kind::Choice(choice_values::<Eye>),
        unit: "",
        default: Default::Value("cyclopean"),
        help: "The eye the compensation (a capture's head estimate) is for.",
        read_with: &[],
        commands: RUN_CAPTURE,
    },
    OptionSpec {
        name: "depth",
        kind: Kind::Switch,
        unit: "",
        default: Default::Value("false"),
        help: "Write the depth sensor's image (depth.npy, depth.exr), as method depth models it with depth_sensor and its settings.",
        read_with: &[],
        commands: CAPTURE,
    },
    OptionSpec {
        name: "band",
        kind: Kind::Integer { min: 1, max: 1000 },
        unit: "pixels",
        default: Default::Value("5"),
        help: "Width of the border band of the mismatch metrics, in display pixels.",
        read_with: &[],
        commands: RUN_COMPARE_SEQUENCE,
    },
    OptionSpec {
        name: "hazard_bound_arcmin",
        kind: Kind::Real {
            min: MIN_LENGTH,
            max: 10800.0,
        },
        unit: "arcmin",
        default: Default::Value(HAZARD_BOUND_ARCMIN_TEXT),
        help: "Hazard visibility: a hidden hazard pixel counts as shown when the display shows the same object within this misregistration.",
        read_with: &[],
        commands: RUN_COMPARE_SEQUENCE,
    },
    OptionSpec {
        name: "depth_sensor",
        kind: Kind::Choice(choice_values::<SensorKind>),
        unit: "",
        default: Default::Value("ideal"),
        help: "Depth sensor of plane-fit and depth: ideal (the frontal render's depth), tof (σ ∝ z, 320 px wide, 15 m range, 1 cm at 1 m, 1 mm steps) or stereo (σ ∝ z², half the frontal width, 80 m, 2 mm at 1 m, inverse-depth steps of 0.0005 /m).",
        read_with: DEPTH,
        commands: SINGLE_FRAMES,
    },
    OptionSpec {
        name: "depth_resolution",
        kind: PIXELS,
        unit: "pixels",
        default: Default::Derived("the sensor's"),
        help: "Depth sensor width, at most the frontal camera's (aspect kept; tof and stereo only).",
        read_with: NOISY_DEPTH,
        commands: SINGLE_FRAMES,
    },
    OptionSpec {
        name: "depth_range",
        kind: Kind::Real {
            min: MIN_LENGTH,
            max: MAX_COORDINATE,
        },
        unit: "metres",
        default: Default::Derived("the sensor's"),
        help: "Depth sensor range: no return past it (d2 → ∞ there; tof and stereo only).",
        read_with: NOISY_DEPTH,
        commands: SINGLE_FRAMES,
    },
    OptionSpec {
        name: "depth_noise",
        kind: Kind::Real {
            min: 0.0,
            max: 10.0,
        },
        unit: "metres",
        default: Default::Derived("the sensor's"),
        help: "Depth noise σ at 1 m, growing as z (tof) or z² (stereo), seeded by seed (tof and stereo only).",
        read_with: NOISY_DEPTH,
        commands: SINGLE_FRAMES,
    },
    OptionSpec {
        name: "depth_quantum",
        kind: Kind::Real {
            min: 0.0,
            max: 10.0,
        },
        unit: "metres",
        default: Default::Derived("the sensor's"),
        help: "Depth quantisation step at 1 m (0: none): constant for tof, growing as z² for stereo (tof and stereo only).",
        read_with: NOISY_DEPTH,
        commands: SINGLE_FRAMES,
    },
    OptionSpec {
        name: "fill",
        kind: Kind::Choice(choice_values::<Fill>),
        unit: "",
        default: Default::Value("none"),
        help: "Disocclusion holes of method depth: none (black, counted blank), background (the nearest farther surface on the epipolar line) or inpaint (diffused from around).",
        read_with: &[("method", "depth")],
        commands: RUN_COMPARE,
    },
    OptionSpec {
        name: "width",
        kind: PIXELS,
        unit: "pixels",
        default: Default::Derived("the driver camera's"),
        help: "Width of the views rendered (a run's: the driver's truth, occluded and seethru views).",
        read_with: &[],
        commands: ALL,
    },
    OptionSpec {
        name: "height",
        kind: PIXELS,
        unit: "pixels",
        default: Default::Derived("from the width and the driver camera's aspect"),
        help: "Height of the views rendered.",
        read_with: &[],
        commands: ALL,
    },
    OptionSpec {
        name: "spp",
        kind: Kind::Integer {
            min: 1,
            max: MAX_SPP as u64,
        },
        unit: "",
        default: Default::Value("4"),
        help: "Samples per pixel (anti-aliasing of the colour; AOVs are at pixel centres).",
        read_with: &[],
        commands: ALL,
    },
    OptionSpec {
        name: "max_memory",
        kind: Kind::Real {
            min: MIN_LENGTH,
            max: 4096.0,
        },
        unit: "GiB",
        default: Default::Value(DEFAULT_MAX_MEMORY_TEXT),
        help: "Refuse to start when the estimated memory exceeds this.",
        read_with: &[],
        commands: ALL,
    },
];

/// [`crate::measure::hazard::HAZARD_BOUND_ARCMIN`] as the table's default text (a test holds them equal).
const HAZARD_BOUND_ARCMIN_TEXT: &str = "30";
/// [`crate::system::memory::DEFAULT_MAX_MEMORY_GIB`] as the table's default text (a test holds them equal).
const DEFAULT_MAX_MEMORY_TEXT: &str = "8";

#[cfg(test)]
mod tests {
    use super::*;
    use crate::measure::hazard::HAZARD_BOUND_ARCMIN;
    use crate::system::memory::DEFAULT_MAX_MEMORY_GIB;

    #[test]
    fn every_default_is_a_value_of_its_option_and_the_constants_agree() {
        for o in OPTIONS {
            let _ = o.default_value();
        }
        let real = |name| match option(name).unwrap().default_value() {
            Some(Value::Real(v)) => v,
            other => panic!("{name}: {other:?}"),
        };
        assert_eq!(real("hazard_bound_arcmin"), HAZARD_BOUND_ARCMIN);
        assert_eq!(real("max_memory"), DEFAULT_MAX_MEMORY_GIB);
    }

    #[test]
    fn a_commands_own_default_is_of_an_option_it_takes_and_differs_from_the_tables() {
        for (command, name, default) in COMMAND_DEFAULTS {
            let o = option(name).unwrap_or_else(|| panic!("{name}"));
            assert!(o.taken_by(*command), "{} {name}", command.name());
            assert_ne!(*default, o.default, "{} {name}", command.name());
            assert_eq!(o.default_for(*command), *default);
            let _ = o.default_value_for(*command);
        }
        // The others keep the table's.
        let spp = option("spp").unwrap();
        assert_eq!(spp.default_for(Command::Run), spp.default);
        assert_eq!(
            spp.default_value_for(Command::Sequence),
            Some(Value::Integer(1))
        );
    }

    #[test]
    fn names_are_unique_and_every_command_takes_some() {
        for (i, o) in OPTIONS.iter().enumerate() {
            assert!(OPTIONS[..i].iter().all(|p| p.name != o.name), "{}", o.name);
            assert!(!o.commands.is_empty(), "{}", o.name);
        }
    }

    #[test]
    fn values_at_the_ends_of_a_range_are_read_and_one_beyond_is_refused() {
        let width = option("width").unwrap();
        assert_eq!(width.parse(" 1 "), Ok(Value::Integer(1)));
        assert_eq!(width.parse("16384"), Ok(Value::Integer(16384)));
        for bad in ["0", "16385", "-1", "1.5", "x", "4294967297"] {
            assert_eq!(
                width.parse(bad),
                Err("must be an integer in [1, 16384]".into()),
                "{bad}"
            );
        }
        let bias = option("head_bias_cm").unwrap();
        assert_eq!(
            bias.parse("-500,0,1.5"),
            Ok(Value::Triple([-500.0, 0.0, 1.5]))
        );
        for bad in ["-500.1,0,0", "1,2", "1,2,3,4", "nan,0,0", "1,inf,0"] {
            assert!(bias.parse(bad).is_err(), "{bad}");
        }
        let d2 = option("d2").unwrap();
        assert_eq!(d2.parse("auto"), Ok(Value::Distance(None)));
        assert_eq!(d2.parse("inf"), Ok(Value::Distance(Some(f64::INFINITY))));
        assert_eq!(d2.parse("1e-6"), Ok(Value::Distance(Some(1e-6))));
        assert!(d2.parse("0").is_err() && d2.parse("1000001").is_err());
        let method = option("method").unwrap();
        assert_eq!(
            method.parse("plane-fit"),
            Ok(Value::Choice("plane-fit".into()))
        );
        assert_eq!(
            method.parse("plane_fit"),
            Err("must be one of none, planar, ground, plane-fit, depth".into())
        );
    }
}
