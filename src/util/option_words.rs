//! How the library's messages name an option, and how each front end spells it.
//!
//! The library has two front ends that name the same option differently: the command line
//! (`--sway-cm`) and the Python package (`sway_cm`). A message of the library names an option
//! in neither's words but as the word `option` and the option's name in backticks:
//! "option `width` must be at least 1 (got 0)". A Rust caller reads that as it is; each front
//! end, at the one place it shows the library's text to its user (the command line's
//! `error:` and `warning:` lines and the files it writes, Python's exceptions and returned
//! reports), spells each such option its own way with [`spell_options`]: [`flag_of`] for the
//! command line, [`keyword_of`] for Python. So the library's words stay front-end neutral and
//! neither front end rewrites the other's spelling.

/// The command line's flag of the option `name`: `sway_cm` → `--sway-cm`.
pub fn flag_of(name: &str) -> String {
    format!("--{}", name.replace('_', "-"))
}

/// Python's keyword of the option `name`: the name itself, `sway_cm`.
pub fn keyword_of(name: &str) -> String {
    name.to_string()
}

/// `text` with each "option `name`" (name: a letter, then letters, digits or `_`: `width`,
/// `head_bias_cm`, `L`) replaced by `spell(name)`; everything else (a backticked word not after "option ",
/// a `--` inside a path) is left as it is.
pub fn spell_options(text: &str, spell: impl Fn(&str) -> String) -> String {
    const MARK: &str = "option `";
    let mut out = String::with_capacity(text.len());
    let mut rest = text;
    while let Some(at) = rest.find(MARK) {
        let after = &rest[at + MARK.len()..];
        let end = after
            .find(|c: char| !(c.is_ascii_alphanumeric() || c == '_'))
            .unwrap_or(after.len());
        let name = &after[..end];
        let valid = after[end..].starts_with('`')
            && name.starts_with(|c: char| c.is_ascii_alphabetic())
            && !rest[..at].ends_with(|c: char| c.is_alphanumeric() || c == '_');
        if valid {
            out.push_str(&rest[..at]);
            out.push_str(&spell(name));
            rest = &after[end + 1..];
        } else {
            out.push_str(&rest[..at + MARK.len()]);
            rest = after;
        }
    }
    out.push_str(rest);
    out
}

/// [`spell_options`] with the command line's flags: "option `sway_cm`" → `--sway-cm`.
pub fn as_flags(text: &str) -> String {
    spell_options(text, flag_of)
}

/// [`spell_options`] with Python's keywords: "option `sway_cm`" → `sway_cm`.
pub fn as_keywords(text: &str) -> String {
    spell_options(text, keyword_of)
}

/// Every string in `value` (a report, metrics) spelled with `spell`, as [`spell_options`]
/// does, for a front end that writes or returns the library's JSON.
pub fn spell_json(value: &mut serde_json::Value, spell: &impl Fn(&str) -> String) {
    match value {
        serde_json::Value::String(s) if s.contains("option `") => {
            *s = spell_options(s, spell);
        }
        serde_json::Value::Array(items) => items.iter_mut().for_each(|v| spell_json(v, spell)),
        serde_json::Value::Object(map) => map.values_mut().for_each(|v| spell_json(v, spell)),
        _ => {}
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn each_option_is_spelled_by_the_front_end() {
        let text =
            "option `sway_cm` is read only with option `head` sway (and no option `head_path`)";
        assert_eq!(
            as_flags(text),
            "--sway-cm is read only with --head sway (and no --head-path)"
        );
        assert_eq!(
            as_keywords(text),
            "sway_cm is read only with head sway (and no head_path)"
        );
    }

    #[test]
    fn a_name_at_the_end_is_spelled() {
        assert_eq!(as_flags("give option `param`"), "give --param");
        assert_eq!(as_flags("option `d2`"), "--d2");
        assert_eq!(as_flags("option `L` must be > 0"), "--L must be > 0");
    }

    #[test]
    fn other_backticks_and_dashes_are_left_alone() {
        let text = "`width` and the material `option` in runs--old/a.toml, -- --x, option `9x`, option `a-b`, option `a b`, myoption `x`";
        assert_eq!(as_flags(text), text);
        assert_eq!(as_keywords(text), text);
        assert_eq!(as_flags("an option `"), "an option `");
        assert_eq!(as_flags("option `unclosed"), "option `unclosed");
    }

    #[test]
    fn every_string_of_a_report_is_spelled() {
        let mut report = serde_json::json!({"warning": "option `seed` unused", "n": 1, "list": ["option `fill` x"]});
        spell_json(&mut report, &flag_of);
        assert_eq!(
            report,
            serde_json::json!({"warning": "--seed unused", "n": 1, "list": ["--fill x"]})
        );
    }
}
