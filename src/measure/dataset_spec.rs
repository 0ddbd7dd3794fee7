//! A dataset's specification (`seethru dataset SPEC.toml`): the scene, how many samples, the
//! seed, the options every sample shares and the draws that vary per sample. A TOML file read
//! like a scene file: typed, unknown keys refused, every error naming the file, line and key.
//!
//! ```toml
//! scene = "../../scenes/cabin.toml" # relative to this file
//! samples = 8
//! seed = 2026
//! [options]                         # every sample: the option table's names and values
//! width = 160
//! [draw]                            # per sample, each with the sample's own draw
//! eye = "eyellipse"                 # the scene's [eyellipse]
//! method = { one_of = ["planar", "plane-fit"] }
//! d2 = { one_of = ["inf", "auto"] }
//! theta_f = { uniform = [40, 60] }
//! head_jitter_cm = { normal = [0.5, 0.1] }
//! [draw.scene]                      # keys of the scene file (scene/key_override.rs)
//! sky.cloud_cover = { uniform = [0, 0.8] }
//! object.car.translate = { uniform = [[-2.5, 0, -14], [-1, 0, -7]] }
//! ```

use std::path::{Path, PathBuf};

use crate::measure::option_table::{Command, Kind, OptionSpec, option};
use crate::scene::source::{SceneError, SourceFile};
use crate::scene::table_reader::TableReader;

/// Most samples one dataset may have.
pub const MAX_SAMPLES: usize = 1_000_000;

/// The draws that move the scene (as `sweep --param` does), not an option of the run.
pub const SCENE_DRAWS: [&str; 6] = [
    "eye",
    "eye_x",
    "eye_z",
    "theta_f",
    "display_width",
    "head_bias_x_cm",
];

/// How one value is drawn per sample.
#[derive(Clone, Debug, PartialEq)]
pub enum Law {
    /// The driver's eye from the scene's `[eyellipse]` (the same eyes as `sweep --param
    /// eye=eyellipse` with the dataset's seed).
    Eyellipse,
    /// One of the values, each as likely.
    OneOf(Vec<String>),
    /// Uniform in [low, high].
    Uniform(f64, f64),
    /// Normal with a mean and a standard deviation (≥ 0).
    Normal(f64, f64),
    /// A vector, each component uniform in its [low, high] (a scene key's array).
    UniformVector(Vec<f64>, Vec<f64>),
    /// A vector, each component normal with its mean and standard deviation.
    NormalVector(Vec<f64>, Vec<f64>),
}

/// One drawn value: a scene draw ([`SCENE_DRAWS`]), a key of the scene file or a run option,
/// and its law.
#[derive(Clone, Debug)]
pub struct Draw {
    /// The manifest's column: the option's or scene draw's name, `scene.PATH` for a key.
    pub name: String,
    pub law: Law,
    /// The option drawn, `None` for a scene draw or key.
    pub option: Option<&'static OptionSpec>,
    /// The scene file's key drawn (`[draw.scene]`), `None` otherwise.
    pub scene_key: Option<SceneKey>,
}

/// A key of the scene file a draw sets (`scene/key_override.rs`).
#[derive(Clone, Debug)]
pub struct SceneKey {
    /// Its dotted path: `sun.time_utc`, `object.car.translate` (an element by its name).
    pub path: String,
    /// `one_of`'s values as written (strings stay strings, arrays arrays); empty otherwise.
    pub values: Vec<toml_edit::Value>,
}

/// The table of `[draw]` whose keys are the scene file's.
pub const SCENE_KEYS: &str = "scene";

/// A dataset specification, checked.
#[derive(Clone, Debug)]
pub struct DatasetSpec {
    /// The spec file.
    pub path: PathBuf,
    /// The scene file, relative to the spec's folder as written, resolved.
    pub scene: PathBuf,
    /// Samples in [1, MAX_SAMPLES].
    pub samples: usize,
    /// The seed every sample's draws derive from.
    pub seed: u64,
    /// The options every sample shares: (option, its text as written).
    pub options: Vec<(&'static OptionSpec, String)>,
    /// The draws, in the file's order (the manifest's columns).
    pub draws: Vec<Draw>,
    /// The spec file's content hash: a dataset folder holds one spec's samples.
    pub source_hash: String,
}

impl DatasetSpec {
    /// Reads and checks `path`.
    pub fn load(path: &Path) -> Result<DatasetSpec, SceneError> {
        let file = SourceFile::read(path)?;
        let doc = file.parse()?;
        let root = TableReader::root(&file, &doc);
        let scene_text = root.required_str("scene")?;
        let scene = root.existing_asset("scene", scene_text)?;
        if !root.has("samples") {
            return Err(root.table_error(format!(
                "required key `samples` is missing: how many samples, in [1, {MAX_SAMPLES}]"
            )));
        }
        let samples = root.usize_in("samples", 1, 1, MAX_SAMPLES)?;
        let seed = root.opt_i64("seed", 0, i64::MAX)?.unwrap_or(0) as u64;
        let mut options = Vec::new();
        if let Some(table) = root.table("options")? {
            for key in table.keys() {
                let option = run_option(&table, key)?;
                let text = table.scalar_text(key)?;
                option
                    .parse(&text)
                    .map_err(|why| table.error(key, format!("`{text}` {why}")))?;
                options.push((option, text));
            }
            table.finish()?;
        }
        let mut draws = Vec::new();
        if let Some(table) = root.table("draw")? {
            for key in table.keys() {
                if options.iter().any(|(o, _)| o.name == key) {
                    return Err(table.error(key, "is also in [options]: give it in one of them"));
                }
                match key {
                    SCENE_KEYS => {
                        let keys = table.table(key)?.expect("a key of the table");
                        read_scene_keys(&keys, "", &mut draws)?;
                        keys.finish()?;
                    }
                    _ => draws.push(read_draw(&table, key)?),
                }
            }
            check_overlaps(&table, &draws)?;
            table.finish()?;
        }
        root.finish()?;
        Ok(DatasetSpec {
            path: path.to_path_buf(),
            scene,
            samples,
            seed,
            options,
            draws,
            source_hash: file.content_hash(),
        })
    }
}

/// The run option named `key` of `table`, or an error listing where the names come from.
fn run_option(table: &TableReader, key: &str) -> Result<&'static OptionSpec, SceneError> {
    option(key).filter(|o| o.taken_by(Command::Run)).ok_or_else(|| {
        table.error(
            key,
            "not an option of `seethru run` (the option table's names, as `seethru spec run` prints them)",
        )
    })
}

fn read_draw(table: &TableReader, key: &str) -> Result<Draw, SceneError> {
    let option = match SCENE_DRAWS.contains(&key) {
        true => None,
        false => Some(run_option(table, key).map_err(|e| SceneError {
            message: format!(
                "neither a scene draw ({}) nor an option of `seethru run`",
                SCENE_DRAWS.join(", ")
            ),
            ..e
        })?),
    };
    if key == "eye" {
        let text = table.scalar_text(key)?;
        if text != "eyellipse" {
            return Err(table.error(
                key,
                format!("`{text}`: the eye is drawn as \"eyellipse\" (the scene's [eyellipse]); eye_x and eye_z move it by numbers"),
            ));
        }
        return Ok(Draw {
            name: key.into(),
            law: Law::Eyellipse,
            option,
            scene_key: None,
        });
    }
    let law_table = table.table(key)?.ok_or_else(|| {
        table.error(
            key,
            "expected a table: { one_of = [...] }, { uniform = [low, high] } or { normal = [mean, sd] }",
        )
    })?;
    let given: Vec<&str> = law_table.keys();
    let law = match given[..] {
        ["one_of"] => {
            let values = law_table.scalar_texts("one_of")?;
            for v in &values {
                check_value(&law_table, "one_of", key, option, v)?;
            }
            Law::OneOf(values)
        }
        ["uniform"] => {
            let [low, high] = law_table.required_array::<2>("uniform")?;
            if low > high {
                return Err(law_table.error("uniform", format!("low {low} is above high {high}")));
            }
            numeric(&law_table, "uniform", key, option)?;
            Law::Uniform(low, high)
        }
        ["normal"] => {
            let [mean, sd] = law_table.required_array::<2>("normal")?;
            if sd < 0.0 {
                return Err(
                    law_table.error("normal", format!("the standard deviation {sd} is negative"))
                );
            }
            numeric(&law_table, "normal", key, option)?;
            Law::Normal(mean, sd)
        }
        _ => return Err(not_one_law(table, key, &given)),
    };
    law_table.finish()?;
    Ok(Draw {
        name: key.into(),
        law,
        option,
        scene_key: None,
    })
}

/// The scene file's key each scene draw sets: drawing both would let one silently undo the
/// other.
const SCENE_DRAW_KEYS: [(&str, &str); 5] = [
    ("theta_f", "camera.frontal.half_angle_deg"),
    ("display_width", "obstacle.width"),
    ("eye", "camera.driver.position"),
    ("eye_x", "camera.driver.position"),
    ("eye_z", "camera.driver.position"),
];

/// Refuses a scene key drawn twice (`sun.x` and `"sun.x"`) or with the scene draw that sets it.
fn check_overlaps(table: &TableReader, draws: &[Draw]) -> Result<(), SceneError> {
    for (i, draw) in draws.iter().enumerate() {
        let Some(key) = &draw.scene_key else { continue };
        if draws[..i].iter().any(|d| d.name == draw.name) {
            return Err(table.error(
                SCENE_KEYS,
                format!("`{}` is drawn twice: give one law", key.path),
            ));
        }
        for (sweep, path) in SCENE_DRAW_KEYS {
            if key.path == path && draws.iter().any(|d| d.name == sweep) {
                return Err(table.error(
                    SCENE_KEYS,
                    format!("`{path}` and the draw {sweep} set the same thing: draw one of them"),
                ));
            }
        }
    }
    Ok(())
}

/// A law table with none or several of the laws.
fn not_one_law(table: &TableReader, key: &str, given: &[&str]) -> SceneError {
    let found = match given {
        [] => "none".to_string(),
        _ => given.join(", "),
    };
    table.error(
        key,
        format!("expected exactly one of {}, found {found}", LAWS.join(", ")),
    )
}

/// The laws' keys: a table with exactly one of them is a law, any other a table of keys.
const LAWS: [&str; 3] = ["one_of", "uniform", "normal"];

/// `[draw.scene]`'s draws, its nested tables flattened into dotted paths (`sun.time_utc =
/// {…}` and `"sun.time_utc" = {…}` are one key).
fn read_scene_keys(
    table: &TableReader,
    prefix: &str,
    draws: &mut Vec<Draw>,
) -> Result<(), SceneError> {
    for key in table.keys() {
        let path = match prefix {
            "" => key.to_string(),
            _ => format!("{prefix}.{key}"),
        };
        let inner = table.table(key)?.ok_or_else(|| {
            table.error(
                key,
                "expected a law for the scene key: { one_of = [...] }, { uniform = [low, high] } or { normal = [mean, sd] } (arrays of numbers for an array key)",
            )
        })?;
        let given = inner.keys();
        if !given.is_empty() && !given.iter().any(|k| LAWS.contains(k)) {
            read_scene_keys(&inner, &path, draws)?;
            inner.finish()?;
            continue;
        }
        let (law, values) = match given[..] {
            ["one_of"] => {
                let values = inner.values("one_of")?;
                let texts = values.iter().map(value_text).collect();
                (Law::OneOf(texts), values)
            }
            [law @ ("uniform" | "normal")] => {
                let ([a, b], length) = inner.number_pair_or_vectors(law)?;
                match (law, length) {
                    ("uniform", _) if a.iter().zip(&b).any(|(low, high)| low > high) => {
                        return Err(inner.error(law, "a low bound is above its high bound"));
                    }
                    ("normal", _) if b.iter().any(|&sd| sd < 0.0) => {
                        return Err(inner.error(law, "a standard deviation is negative"));
                    }
                    ("uniform", None) => (Law::Uniform(a[0], b[0]), Vec::new()),
                    ("normal", None) => (Law::Normal(a[0], b[0]), Vec::new()),
                    ("uniform", Some(_)) => (Law::UniformVector(a, b), Vec::new()),
                    _ => (Law::NormalVector(a, b), Vec::new()),
                }
            }
            _ => return Err(not_one_law(table, key, &given)),
        };
        inner.finish()?;
        draws.push(Draw {
            name: format!("{SCENE_KEYS}.{path}"),
            law,
            option: None,
            scene_key: Some(SceneKey { path, values }),
        });
    }
    Ok(())
}

/// A scene key's value as the manifest shows it: a string without its quotes, anything else
/// as TOML writes it.
pub fn value_text(value: &toml_edit::Value) -> String {
    match value {
        toml_edit::Value::String(s) => s.value().clone(),
        other => other.clone().decorated("", "").to_string(),
    }
}

/// A scene draw takes a number; an option's value must parse as the option's.
fn check_value(
    table: &TableReader,
    at: &str,
    name: &str,
    option: Option<&OptionSpec>,
    text: &str,
) -> Result<(), SceneError> {
    let why = match option {
        Some(o) => o.parse(text).err(),
        None => (!text.trim().parse::<f64>().is_ok_and(f64::is_finite))
            .then(|| "must be a finite number".to_string()),
    };
    match why {
        Some(why) => Err(table.error(at, format!("`{text}` for {name} {why}"))),
        None => Ok(()),
    }
}

/// uniform and normal draw numbers: a scene draw's, or an option's of a numeric kind.
fn numeric(
    table: &TableReader,
    at: &str,
    name: &str,
    option: Option<&OptionSpec>,
) -> Result<(), SceneError> {
    match option.map(|o| o.kind) {
        None | Some(Kind::Real { .. } | Kind::Integer { .. } | Kind::Distance { .. }) => Ok(()),
        Some(_) => Err(table.error(at, format!("{name} is not a number: draw it with one_of"))),
    }
}
