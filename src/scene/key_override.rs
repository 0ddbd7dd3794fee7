//! A scene file with some of its keys set to other values, by dotted path: what a dataset's
//! `[draw.scene]` varies per sample (the time of day, a lamp, a camera's shutter, where a car
//! stands). The file's text is edited, not the parsed scene, so that every value goes through
//! the scene reader's own checks and errors.
//!
//! A path names tables by their keys (`sun.time_utc`, `camera.frontal.readout_ms`) and an
//! element of an array of tables by its `name` (`object.car.translate`, `light.left.
//! intensity_cd`). A key or table the file does not have is added (the reader then refuses
//! what the scene format does not know).

use toml_edit::{DocumentMut, Item, TableLike, Value};

use crate::scene::source::SourceFile;

/// `file` with each `(path, value)` set, in order; an error names the path and why it leads
/// nowhere (a name no element has, a value where a table should be).
pub fn with_keys(file: &SourceFile, keys: &[(&str, Value)]) -> Result<SourceFile, String> {
    let mut doc: DocumentMut = file
        .text()
        .parse()
        .map_err(|e| format!("{}: {e}", file.path.display()))?;
    for (path, value) in keys {
        let segments: Vec<&str> = path.split('.').collect();
        if segments.iter().any(|s| s.is_empty()) {
            return Err(format!("`{path}`: an empty part in the key's path"));
        }
        set(doc.as_table_mut(), &segments, value.clone(), path)?;
    }
    Ok(SourceFile::from_text(&file.path, doc.to_string()))
}

fn set(
    table: &mut dyn TableLike,
    segments: &[&str],
    value: Value,
    path: &str,
) -> Result<(), String> {
    let (key, rest) = segments.split_first().expect("a path has a part");
    if rest.is_empty() {
        match table.get_mut(key) {
            Some(item) if item.is_table_like() || item.is_array_of_tables() => Err(format!(
                "`{path}` is a table in the scene, not a value: name one of its keys"
            )),
            // The old value's comments and spacing kept: the file stays readable.
            Some(Item::Value(old)) => {
                let decor = old.decor().clone();
                *old = value;
                *old.decor_mut() = decor;
                Ok(())
            }
            _ => {
                table.insert(key, Item::Value(value));
                Ok(())
            }
        }
    } else {
        if table.get(key).is_none() {
            let mut new = toml_edit::Table::new();
            new.set_implicit(true);
            table.insert(key, Item::Table(new));
        }
        let item = table.get_mut(key).expect("just made");
        if let Some(elements) = item.as_array_of_tables_mut() {
            let (name, rest) = rest.split_first().expect("rest is not empty");
            if rest.is_empty() {
                return Err(format!(
                    "`{path}` names an element of [[{key}]], not a key of it: add the key (`{key}.{name}.KEY`)"
                ));
            }
            let named = |t: &toml_edit::Table| t.get("name").and_then(|n| n.as_str()) == Some(name);
            let names: Vec<String> = elements
                .iter()
                .filter_map(|t| t.get("name").and_then(|n| n.as_str()).map(String::from))
                .collect();
            let mut found = elements.iter_mut().filter(|t| named(t));
            let Some(element) = found.next() else {
                return Err(format!(
                    "`{path}`: no [[{key}]] is named `{name}` (the names: {})",
                    if names.is_empty() {
                        "none".into()
                    } else {
                        names.join(", ")
                    }
                ));
            };
            if found.next().is_some() {
                return Err(format!(
                    "`{path}`: more than one [[{key}]] is named `{name}`"
                ));
            }
            return set(element, rest, value, path);
        }
        match item.as_table_like_mut() {
            Some(inner) => set(inner, rest, value, path),
            None => Err(format!(
                "`{path}`: `{key}` is a {} in the scene, not a table",
                item.type_name()
            )),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::path::Path;

    const SCENE: &str = "# a scene\n[sun]\nelevation_deg = 30.0 # high\n\n[[object]]\nname = \"car\"\ntranslate = [0, 0, -10]\n\n[[object]]\nname = \"kerb\"\n";

    fn edited(keys: &[(&str, Value)]) -> Result<String, String> {
        let file = SourceFile::from_text(Path::new("s.toml"), SCENE.into());
        with_keys(&file, keys).map(|f| f.text().to_string())
    }

    #[test]
    fn a_value_is_replaced_in_place_keeping_its_comment_and_the_rest_of_the_file() {
        let text = edited(&[("sun.elevation_deg", Value::from(12.5))]).unwrap();
        assert_eq!(text, SCENE.replace("= 30.0 #", "= 12.5 #"));
    }

    #[test]
    fn an_element_of_an_array_of_tables_is_found_by_its_name() {
        let to = Value::Array([1.5, 0.0, -12.0].into_iter().collect());
        let text = edited(&[("object.car.translate", to)]).unwrap();
        assert_eq!(text, SCENE.replace("[0, 0, -10]", "[1.5, 0.0, -12.0]"));
        let text = edited(&[("object.kerb.hidden_from", Value::from("driver"))]).unwrap();
        assert!(
            text.ends_with("name = \"kerb\"\nhidden_from = \"driver\"\n"),
            "{text}"
        );
    }

    #[test]
    fn a_missing_key_or_table_is_added() {
        let text = edited(&[("sky.turbidity", Value::from(3))]).unwrap();
        let doc: DocumentMut = text.parse().unwrap();
        assert_eq!(doc["sky"]["turbidity"].as_integer(), Some(3));
        assert_eq!(doc["sun"]["elevation_deg"].as_float(), Some(30.0));
    }

    #[test]
    fn paths_that_lead_nowhere_are_refused_by_name() {
        let one = |path: &str| edited(&[(path, Value::from(1))]).unwrap_err();
        assert!(
            one("object.bus.translate")
                .contains("no [[object]] is named `bus` (the names: car, kerb)")
        );
        assert!(one("object.car").contains("names an element of [[object]]"));
        assert!(one("sun").contains("is a table in the scene"));
        assert!(one("sun.elevation_deg.x").contains("`elevation_deg` is a float"));
        assert!(one("sun..x").contains("empty part"));
    }
}
