//! JUnit XML, as GitHub Actions (test-reporter, dorny), GitLab (`artifacts:reports:junit`)
//! and Jenkins (the JUnit plugin) read it: one `<testsuites>` with one `<testsuite>` per
//! file, one `<testcase>` per case, a `<failure>` per failed case and an `<error>` where a
//! case could not run.

use std::fmt::Write as _;

/// What became of one test case.
pub enum Outcome {
    Passed,
    /// Bounds not met: a one-line message and the details.
    Failed {
        message: String,
        details: String,
    },
    /// The case could not run (a bad scene, bad options).
    Error {
        message: String,
    },
}

/// One test case of a suite.
pub struct TestCase {
    pub name: String,
    pub classname: String,
    /// Wall time, seconds.
    pub seconds: f64,
    pub outcome: Outcome,
    /// Shown by the readers beside the case (the table of its bounds).
    pub output: String,
}

/// Text safe inside an XML attribute or element: the five markup characters escaped, and
/// the characters XML 1.0 cannot hold at all (control characters but tab, LF, CR) shown as
/// `\u{..}`.
pub fn escape(text: &str) -> String {
    let mut out = String::with_capacity(text.len());
    for c in text.chars() {
        match c {
            '&' => out.push_str("&amp;"),
            '<' => out.push_str("&lt;"),
            '>' => out.push_str("&gt;"),
            '"' => out.push_str("&quot;"),
            '\'' => out.push_str("&apos;"),
            '\t' | '\n' | '\r' => out.push(c),
            c if (c as u32) < 0x20 || c == '\u{FFFE}' || c == '\u{FFFF}' => {
                let _ = write!(out, "\\u{{{:x}}}", c as u32);
            }
            c => out.push(c),
        }
    }
    out
}

/// The JUnit XML of one suite named `suite` (the expectation file) holding `cases`.
pub fn junit_xml(suite: &str, cases: &[TestCase]) -> String {
    let failures = cases
        .iter()
        .filter(|c| matches!(c.outcome, Outcome::Failed { .. }))
        .count();
    let errors = cases
        .iter()
        .filter(|c| matches!(c.outcome, Outcome::Error { .. }))
        .count();
    let seconds: f64 = cases.iter().map(|c| c.seconds).sum();
    let mut xml = String::from("<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n");
    let counts = format!(
        "tests=\"{}\" failures=\"{failures}\" errors=\"{errors}\" time=\"{seconds:.3}\"",
        cases.len()
    );
    let _ = writeln!(xml, "<testsuites name=\"seethru check\" {counts}>");
    let _ = writeln!(
        xml,
        "  <testsuite name=\"{}\" {counts} skipped=\"0\">",
        escape(suite)
    );
    for case in cases {
        let _ = write!(
            xml,
            "    <testcase name=\"{}\" classname=\"{}\" time=\"{:.3}\"",
            escape(&case.name),
            escape(&case.classname),
            case.seconds
        );
        xml.push_str(">\n");
        match &case.outcome {
            Outcome::Passed => {}
            Outcome::Failed { message, details } => {
                let _ = writeln!(
                    xml,
                    "      <failure message=\"{}\" type=\"bound\">{}</failure>",
                    escape(message),
                    escape(details)
                );
            }
            Outcome::Error { message } => {
                let _ = writeln!(
                    xml,
                    "      <error message=\"{}\" type=\"error\">{}</error>",
                    escape(message),
                    escape(message)
                );
            }
        }
        if !case.output.is_empty() {
            let _ = writeln!(
                xml,
                "      <system-out>{}</system-out>",
                escape(&case.output)
            );
        }
        xml.push_str("    </testcase>\n");
    }
    xml.push_str("  </testsuite>\n</testsuites>\n");
    xml
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn markup_and_control_characters_are_escaped() {
        assert_eq!(
            escape("a<b & \"c\" 'd'>\u{1}"),
            "a&lt;b &amp; &quot;c&quot; &apos;d&apos;&gt;\\u{1}"
        );
        // XML 1.0 has no U+FFFE nor U+FFFF, nor control characters but tab and line breaks.
        assert_eq!(
            escape("\u{fffe}\u{ffff}\u{1f}\t\n"),
            "\\u{fffe}\\u{ffff}\\u{1f}\t\n"
        );
    }

    #[test]
    fn a_case_with_no_output_has_no_system_out() {
        let case = |name: &str, output: &str| TestCase {
            name: name.into(),
            classname: "seethru.check.e".into(),
            seconds: 0.5,
            outcome: Outcome::Passed,
            output: output.into(),
        };
        let xml = junit_xml("e.toml", &[case("quiet", ""), case("said", "a <= 1")]);
        let doc = roxmltree::Document::parse(&xml).unwrap();
        let outputs: Vec<(&str, usize)> = doc
            .descendants()
            .filter(|n| n.has_tag_name("testcase"))
            .map(|c| {
                let name = c.attribute("name").unwrap();
                (
                    name,
                    c.children()
                        .filter(|n| n.has_tag_name("system-out"))
                        .count(),
                )
            })
            .collect();
        assert_eq!(outputs, [("quiet", 0), ("said", 1)]);
    }

    #[test]
    fn counts_and_elements_follow_the_outcomes() {
        let case = |name: &str, outcome| TestCase {
            name: name.into(),
            classname: "seethru.check.e".into(),
            seconds: 0.5,
            outcome,
            output: "a <= 1".into(),
        };
        let xml = junit_xml(
            "e.toml",
            &[
                case("pass", Outcome::Passed),
                case(
                    "fail",
                    Outcome::Failed {
                        message: "a <= 1: measured 2".into(),
                        details: "see x".into(),
                    },
                ),
                case(
                    "fail too",
                    Outcome::Failed {
                        message: "b >= 1: measured 0".into(),
                        details: String::new(),
                    },
                ),
                case(
                    "broken",
                    Outcome::Error {
                        message: "no scene".into(),
                    },
                ),
            ],
        );
        let doc = roxmltree::Document::parse(&xml).unwrap();
        let suite = doc
            .descendants()
            .find(|n| n.has_tag_name("testsuite"))
            .unwrap();
        for (attribute, value) in [("tests", "4"), ("failures", "2"), ("errors", "1")] {
            assert_eq!(suite.attribute(attribute), Some(value), "{xml}");
        }
        let count = |tag: &str| doc.descendants().filter(|n| n.has_tag_name(tag)).count();
        assert_eq!(
            (count("testcase"), count("failure"), count("error")),
            (4, 2, 1)
        );
        let failure = doc
            .descendants()
            .find(|n| n.has_tag_name("failure"))
            .unwrap();
        assert_eq!(failure.attribute("message"), Some("a <= 1: measured 2"));
        assert_eq!(failure.parent().unwrap().attribute("name"), Some("fail"));
    }
}
