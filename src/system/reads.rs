//! Settings read only under others: a run or a sequence refuses a setting it would ignore,
//! so the user's intent is not dropped without a word. The rules are the library's, so the
//! command line (`--sway-cm`) and the Python package (`sway_cm`) refuse the same settings
//! with the same words: the library's name the option ("option `sway_cm`",
//! `util::option_words`), each front end spells it.

use crate::scene::Scene;
use crate::system::eyes::Eye;
use crate::system::options::{HeadSource, Method, RunOptions};
use crate::system::sequence::head_motion::HeadPreset;

/// Where [`ReadWhen::when`] says a setting is read only by the methods that use the eye.
pub const EYE_METHODS: &str =
    "by the methods that compensate for the eye (not option `method` none)";

/// A setting that a command reads only under some of its other settings.
#[derive(Clone, Debug, PartialEq)]
pub struct ReadWhen {
    /// The option's name, `ipd`: each front end spells it (`--ipd`, `ipd=`).
    pub option: &'static str,
    /// Whether the command, with the settings given, reads it.
    pub read: bool,
    /// The settings that read it, for the message, in the library's words: "with option
    /// `eyes` left, right or both".
    pub when: &'static str,
}

pub use crate::util::option_words::flag_of;
use crate::util::option_words::{as_flags, as_keywords};

impl ReadWhen {
    /// The refusal of this setting when given, in the library's words ("option `ipd` is read
    /// only …"): `others` names the rest (`flags`, `options`).
    pub fn refusal(&self, others: &str) -> String {
        format!(
            "option `{}` is read only {}; with the other {others} given it would be ignored: remove it",
            self.option, self.when
        )
    }

    /// The refusal in the command line's words: `--ipd is read only …`.
    pub fn flag_refusal(&self) -> String {
        as_flags(&self.refusal("flags"))
    }

    /// The refusal in Python's words: keywords for options, `options` for the rest.
    pub fn keyword_refusal(&self) -> String {
        as_keywords(&self.refusal("options"))
    }
}

/// The head-tracking errors' rules, shared by `run` and `sequence`: none is read where the
/// method uses no eye (`eye_used` false: `--method none`); the feature width is the
/// detector's, read with `head` estimated only; the seed is read by a jitter (`jitter`), the
/// tracker model (`head` model: its noise and dropouts), or where `other_seed_reader` (a noisy
/// depth sensor, the plane fit) says so.
pub fn head_error_reads(
    eye_used: bool,
    head: HeadSource,
    jitter: bool,
    other_seed_reader: bool,
) -> Vec<ReadWhen> {
    let eye = EYE_METHODS;
    vec![
        ReadWhen {
            option: "head_bias_cm",
            read: eye_used,
            when: eye,
        },
        ReadWhen {
            option: "head_jitter_cm",
            read: eye_used,
            when: eye,
        },
        ReadWhen {
            option: "min_head_confidence",
            read: eye_used && head == HeadSource::Estimated,
            when: "with an estimated head (face detection: only its estimate has a confidence) and a method that compensates for the eye",
        },
        ReadWhen {
            option: "feature_width",
            read: eye_used && head == HeadSource::Estimated,
            when: "with an estimated head (face detection), not the oracle, and a method that compensates for the eye",
        },
        ReadWhen {
            option: "seed",
            read: (eye_used && (jitter || head == HeadSource::Model)) || other_seed_reader,
            when: "with option `head_jitter_cm` > 0, the tracker model's head, a noisy depth sensor or the plane fit",
        },
    ]
}

/// The scene-model settings' rules: the sensor's settings are read when `reads_depth`, its
/// kind when `reads_kind`, the fill when `fills`; `depth_when` and `fill_when` say by what.
pub fn scene_model_reads(
    reads_depth: bool,
    reads_kind: bool,
    fills: bool,
    depth_when: &'static str,
    fill_when: &'static str,
) -> Vec<ReadWhen> {
    let depth = |option| ReadWhen {
        option,
        read: reads_depth,
        when: depth_when,
    };
    vec![
        ReadWhen {
            option: "depth_sensor",
            read: reads_kind,
            when: depth_when,
        },
        depth("depth_resolution"),
        depth("depth_range"),
        depth("depth_noise"),
        depth("depth_quantum"),
        ReadWhen {
            option: "fill",
            read: fills,
            when: fill_when,
        },
    ]
}

/// The scene-model settings' rules for one run of `method`: a sensor or its settings for a
/// method that reads no depth, a fill for a method that leaves no holes, are ignored. (The
/// settings of the ideal sensor, which has none, are refused where the sensor is resolved.)
pub fn method_scene_model_reads(method: Method) -> Vec<ReadWhen> {
    let reads_depth = matches!(method, Method::PlaneFit | Method::Depth);
    scene_model_reads(
        reads_depth,
        reads_depth,
        method == Method::Depth,
        "by option `method` plane-fit and depth",
        "by option `method` depth (its disocclusion holes)",
    )
}

/// One run's rules (`seethru run`, `seethru.run`), in the order they are checked: `options`
/// as given; `both_eyes` when each eye is run in turn (`--eyes both`).
pub fn run_reads(options: &RunOptions, both_eyes: bool) -> Vec<ReadWhen> {
    let method = options.method;
    let noisy_sensor = method == Method::Depth
        && options.scene_model.sensor.kind != crate::system::depth_sensor::SensorKind::Ideal;
    let eye_used = method != Method::None;
    let mut rules = method_scene_model_reads(method);
    rules.extend(head_error_reads(
        eye_used,
        options.head,
        options.head_jitter_cm > 0.0,
        method == Method::PlaneFit || noisy_sensor,
    ));
    let eyes = &options.eyes;
    rules.extend([
        ReadWhen {
            option: "head",
            read: eye_used,
            when: EYE_METHODS,
        },
        ReadWhen {
            option: "target_eye",
            read: eye_used,
            when: EYE_METHODS,
        },
        ReadWhen {
            option: "ipd",
            read: both_eyes
                || eyes.view != Eye::Cyclopean
                || (eye_used && eyes.target != Eye::Cyclopean),
            when: "with option `eyes` left, right or both, or option `target_eye` left or right",
        },
        ReadWhen {
            option: "d2",
            read: !matches!(method, Method::None | Method::Depth),
            when: "by option `method` planar, ground and plane-fit",
        },
    ]);
    rules
}

/// A capture's rules (`seethru capture`, `seethru.capture`): `options` as given, `depth`
/// whether the capture records the depth sensor's map. A capture serves every method, so
/// the head settings are read whatever the method; it has no holes to fill.
pub fn capture_reads(options: &RunOptions, depth: bool) -> Vec<ReadWhen> {
    let noisy_depth =
        depth && options.scene_model.sensor.kind != crate::system::depth_sensor::SensorKind::Ideal;
    let mut rules = scene_model_reads(
        depth,
        depth,
        false,
        "with option `depth` (the capture's depth map)",
        "by option `method` depth, not by a capture (it has no holes to fill)",
    );
    rules.extend(head_error_reads(
        true,
        options.head,
        options.head_jitter_cm > 0.0,
        noisy_depth,
    ));
    let eyes = &options.eyes;
    rules.extend([
        ReadWhen {
            option: "require_confident_head",
            read: options.head == HeadSource::Estimated,
            when: "with option `head` estimated (only the face detector's estimate has a confidence)",
        },
        ReadWhen {
            option: "ipd",
            read: eyes.view != Eye::Cyclopean || eyes.target != Eye::Cyclopean,
            when: "with option `eyes` left or right, or option `target_eye` left or right",
        },
    ]);
    rules
}

/// The first rule of `rules` whose setting is given (`given`, by its option's name) but not
/// read.
pub fn first_ignored(rules: &[ReadWhen], given: impl Fn(&str) -> bool) -> Option<&ReadWhen> {
    rules.iter().find(|r| !r.read && given(r.option))
}

/// A sequence's rules, in the order they are checked: `run` holds its pipeline's options,
/// `head` the head motion preset (`None`: a recorded head path), `maps` whether an outside
/// method's maps are shown.
pub fn sequence_reads(run: &RunOptions, head: Option<HeadPreset>, maps: bool) -> Vec<ReadWhen> {
    let preset = |p: HeadPreset| head == Some(p);
    let sway = "with option `head` sway (and no option `head_path`)";
    let lean = "with option `head` lean (and no option `head_path`)";
    let eye_used = run.method != Method::None;
    let estimated = run.head == HeadSource::Estimated;
    let mut rules = head_error_reads(eye_used, run.head, run.head_jitter_cm > 0.0, false);
    let eye = |option| ReadWhen {
        option,
        read: eye_used,
        when: EYE_METHODS,
    };
    let with = |option, read, when| ReadWhen { option, read, when };
    rules.extend([
        eye("head_source"),
        eye("predict"),
        eye("latency_tracking"),
        with(
            "reproject",
            run.method == Method::Planar,
            "by option `method` planar (none shows the whole frontal image as captured)",
        ),
        with(
            "back_width",
            eye_used && estimated,
            "with option `head_source` estimated (the back camera is rendered for the face detector only)",
        ),
        with("sway_cm", preset(HeadPreset::Sway), sway),
        with("sway_hz", preset(HeadPreset::Sway), sway),
        with("lean_cm", preset(HeadPreset::Lean), lean),
        with("lean_s", preset(HeadPreset::Lean), lean),
        with("lean_at", preset(HeadPreset::Lean), lean),
        with(
            "d2",
            run.method == Method::Planar && !maps,
            "by option `method` planar without option `maps`",
        ),
        with("method", !maps, "without option `maps` (the maps are the method)"),
        with(
            "display",
            !maps,
            "without option `maps` (a map is shown on the display's pixels)",
        ),
    ]);
    rules
}

/// `--hazard-bound-arcmin`'s rule: read for a scene with hazard objects only.
pub fn hazard_bound_reads(scene: &Scene) -> ReadWhen {
    ReadWhen {
        option: "hazard_bound_arcmin",
        read: scene.objects.iter().any(|o| o.hazard),
        when: "for a scene with an object marked `hazard = true`",
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_runs_seed_is_read_by_a_noisy_sensor_of_the_depth_method() {
        use crate::system::depth_sensor::SensorKind;
        let seed_read = |method, kind| {
            let mut options = RunOptions {
                method,
                ..RunOptions::default()
            };
            options.scene_model.sensor.kind = kind;
            run_reads(&options, false)
                .into_iter()
                .find(|r| r.option == "seed")
                .unwrap()
                .read
        };
        assert!(seed_read(Method::Depth, SensorKind::Tof));
        assert!(seed_read(Method::Depth, SensorKind::Stereo));
        assert!(!seed_read(Method::Depth, SensorKind::Ideal));
        assert!(seed_read(Method::PlaneFit, SensorKind::Ideal));
        assert!(!seed_read(Method::Planar, SensorKind::Tof));
    }

    #[test]
    fn the_sway_settings_are_read_with_sway_only() {
        let run = RunOptions::default();
        let read = |head| {
            sequence_reads(&run, head, false)
                .into_iter()
                .find(|r| r.option == "sway_hz")
                .unwrap()
                .read
        };
        assert!(read(Some(HeadPreset::Sway)));
        assert!(!read(Some(HeadPreset::Lean)));
        assert!(!read(None));
    }
}
