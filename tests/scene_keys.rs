//! Every numeric value of the scene schema, as `scenes/reference.toml` documents it (scalars
//! and each element of the arrays), replaced in turn by NaN, ±inf, −1, 0 and 1e300: each is
//! refused with one line naming the file, the line and the key, or accepted where the
//! documentation admits it — and an accepted scene builds its world without a panic.

use std::ops::Range;
use std::path::Path;

use seethru::scene::Scene;
use seethru::scene::source::SourceFile;
use seethru::scene::world::World;
use toml_edit::{ImDocument, Item, Value};

const BAD: [(&str, f64); 6] = [
    ("nan", f64::NAN),
    ("inf", f64::INFINITY),
    ("-inf", f64::NEG_INFINITY),
    ("-1", -1.0),
    ("0", 0.0),
    ("1e300", 1e300),
];

/// A numeric value of the reference scene: its key as errors name it, its element index in
/// an array, and where its text is.
struct Leaf {
    key: String,
    element: Option<usize>,
    span: Range<usize>,
}

fn leaves_of_value(key: &str, value: &Value, out: &mut Vec<Leaf>) {
    match value {
        Value::Integer(_) | Value::Float(_) => out.push(Leaf {
            key: key.to_string(),
            element: None,
            span: value.span().expect("parsed values have spans"),
        }),
        Value::Array(array) => {
            for (i, element) in array.iter().enumerate() {
                if matches!(element, Value::Integer(_) | Value::Float(_)) {
                    out.push(Leaf {
                        key: key.to_string(),
                        element: Some(i),
                        span: element.span().expect("parsed values have spans"),
                    });
                }
            }
        }
        _ => {}
    }
}

fn leaves_of_table(prefix: &str, table: &toml_edit::Table, out: &mut Vec<Leaf>) {
    for (name, item) in table.iter() {
        let key = if prefix.is_empty() {
            name.to_string()
        } else {
            format!("{prefix}.{name}")
        };
        match item {
            Item::Value(value) => leaves_of_value(&key, value, out),
            Item::Table(t) => leaves_of_table(&key, t, out),
            Item::ArrayOfTables(tables) => {
                for (i, t) in tables.iter().enumerate() {
                    leaves_of_table(&format!("{key}[{i}]"), t, out);
                }
            }
            Item::None => {}
        }
    }
}

/// What the documentation admits for a key (its name without table indices), from the
/// comments of `scenes/reference.toml` and docs/reference/limits-and-errors.md.
enum Documented {
    /// Every value in the range is accepted and every other refused: (low, low included,
    /// high, high included).
    Range(f64, bool, f64, bool),
    /// A point or offset: finite and inside the world (±1e6 m), where a rule between keys (an
    /// eye behind the display, a camera looking at itself, the scene side) may still refuse.
    Point,
    /// A direction: any finite numbers, normalised on load; refused when zero or parallel to
    /// its partner (which may be the key named).
    Direction,
    /// A closed range, where a rule between keys (keyframe times must increase) may still
    /// refuse a value inside it.
    RangeAndRule(f64, f64),
}

fn documented(key: &str) -> Documented {
    use Documented::*;
    let closed = |lo, hi| Range(lo, true, hi, true);
    let left_open = |lo, hi| Range(lo, false, hi, true);
    match key {
        "sun.intensity" | "sky.ambient" => closed(0.0, 1000.0),
        "sky.cloud_cover" => closed(0.0, 1.0),
        "sky.cloud_height" | "sky.cloud_size" => left_open(0.0, 1e5),
        "sky.cloud_seed" => closed(0.0, 4294967295.0),
        k if k.ends_with("color") => closed(0.0, 1.0),
        "obstacle.width" | "obstacle.height" | "obstacle.thickness" => left_open(0.0, 100.0),
        "object.size" | "object.radius" | "object.height" | "object.scale" => left_open(0.0, 1e5),
        "object.rotate_deg" => closed(-360.0, 360.0),
        "object.segments" => closed(3.0, 4096.0),
        "material.uv_repeat" => left_open(0.0, 1e6),
        "material.specular" | "road.specular" => closed(0.0, 1.0),
        "material.roughness" | "road.roughness" => closed(0.01, 1.0),
        k if k.ends_with(".resolution") || k == "obstacle.display_resolution" => {
            closed(1.0, 16384.0)
        }
        k if k.ends_with("yaw_deg") || k.ends_with("pitch_deg") => closed(-80.0, 80.0),
        k if k.ends_with("half_angle_deg") => closed(0.01, 89.0),
        "sun.direction" | "obstacle.facing" | "obstacle.up" | "camera.driver.up" => Direction,
        "obstacle.center" | "camera.driver.position" | "camera.driver.look_at" => Point,
        k if k.ends_with(".offset")
            || k == "object.translate"
            || k == "object.keyframe.translate" =>
        {
            Point
        }
        k if k.ends_with("focal_error_percent") => closed(-50.0, 50.0),
        k if k.starts_with("calibration.") && k.ends_with("_error_deg") => closed(-10.0, 10.0),
        k if k.ends_with("position_error") => closed(-1.0, 1.0),
        "object.keyframe.t" => RangeAndRule(0.0, 3600.0),
        k if k.ends_with("exposure_ms") => closed(0.0, 1000.0),
        "object.keyframe.rotate_deg" => closed(-360.0, 360.0),
        other => panic!(
            "`{other}` is not documented in this test: add what docs/reference/scene-format.md says"
        ),
    }
}

fn admits(documented: &Documented, x: f64) -> bool {
    match *documented {
        Documented::Range(lo, lo_in, hi, hi_in) => {
            (x > lo || (lo_in && x == lo)) && (x < hi || (hi_in && x == hi))
        }
        Documented::Point => x.is_finite() && x.abs() <= 1e6,
        Documented::Direction => x.is_finite(),
        Documented::RangeAndRule(lo, hi) => (lo..=hi).contains(&x),
    }
}

fn line_of(text: &str, offset: usize) -> usize {
    text[..offset].matches('\n').count() + 1
}

#[test]
fn every_numeric_key_refuses_nan_infinities_and_huge_values_in_one_line() {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/reference.toml");
    let text = std::fs::read_to_string(&path).unwrap();
    let doc = ImDocument::parse(text.as_str()).unwrap();
    let mut leaves = Vec::new();
    leaves_of_table("", doc.as_table(), &mut leaves);
    assert!(
        leaves.len() > 80,
        "only {} numeric values found",
        leaves.len()
    );
    let shown_path = path.display().to_string();
    let mut failures = Vec::new();
    let (mut refused, mut accepted) = (0, 0);
    for leaf in &leaves {
        // `object[3].size` → `object.size`, the key's documented name.
        let name: String = {
            let mut s = leaf.key.clone();
            while let (Some(a), Some(b)) = (s.find('['), s.find(']')) {
                s.replace_range(a..=b, "");
            }
            s
        };
        let line = line_of(&text, leaf.span.start);
        for (written, value) in BAD {
            let edited = format!(
                "{}{written}{}",
                &text[..leaf.span.start],
                &text[leaf.span.end..]
            );
            let what = format!(
                "{}{} = {written} (line {line})",
                leaf.key,
                leaf.element.map_or(String::new(), |i| format!("[{i}]"))
            );
            let parsed = Scene::from_source(&SourceFile::from_text(&path, edited));
            let doc = documented(&name);
            let strict = matches!(doc, Documented::Range(..));
            match parsed {
                Err(e) => {
                    refused += 1;
                    let shown = e.to_string();
                    // A rule between keys names the key it checks, at that key's line.
                    let line_shown = if e.key == leaf.key {
                        line
                    } else {
                        e.line.unwrap_or(0)
                    };
                    let prefix = format!("{shown_path}:{line_shown}:");
                    let key_ok = e.key == leaf.key || (!strict && !e.key.is_empty());
                    if !key_ok || !shown.starts_with(&prefix) || shown.contains('\n') {
                        failures.push(format!("{what}: refused as `{shown}` (key `{}`)", e.key));
                    } else if strict && admits(&doc, value) {
                        failures.push(format!(
                            "{what}: documented as admissible, refused: {shown}"
                        ));
                    }
                }
                Ok(scene) => {
                    accepted += 1;
                    if !admits(&doc, value) {
                        failures.push(format!("{what}: accepted, outside what is documented"));
                    } else if let Err(e) = World::build(&scene) {
                        let shown = format!("{e:#}");
                        if shown.contains('\n') {
                            failures.push(format!("{what}: world error of several lines: {shown}"));
                        }
                    }
                }
            }
        }
    }
    assert!(
        failures.is_empty(),
        "{} of {} substitutions ({refused} refused, {accepted} accepted) are wrong:\n{}",
        failures.len(),
        leaves.len() * BAD.len(),
        failures.join("\n")
    );
}
