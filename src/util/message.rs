//! An error message as it reaches the terminal: one line, short, and inert. Messages repeat
//! what the user wrote (names, paths, values), which may hold line breaks, terminal escape
//! sequences or 800-digit numbers.

use crate::util::number::clip_long_numbers;

/// `text` with every control character escaped (`\n`, `\u{1b}`: a name holding a line break
/// no longer splits the message, an escape sequence no longer reaches the terminal) and
/// every overlong number clipped.
pub fn printable(text: &str) -> String {
    clip_long_numbers(&controls_escaped(text))
}

/// `text` with every control character escaped (`\n`, `\u{1b}`), nothing else changed.
pub fn controls_escaped(text: &str) -> String {
    text.chars()
        .flat_map(|c| {
            let shown: Vec<char> = if c.is_control() {
                c.escape_default().collect()
            } else {
                vec![c]
            };
            shown
        })
        .collect()
}

/// An error and its causes as one line, `outer: inner: …`, each cause said once: a cause
/// whose text its outer message already ends with (an I/O error that a library wraps and also
/// gives as its source) is not repeated.
pub fn error_text(e: &anyhow::Error) -> String {
    let mut text = String::new();
    for cause in e.chain() {
        let cause = cause.to_string();
        if text.ends_with(&cause) {
            continue;
        }
        if !text.is_empty() {
            text += ": ";
        }
        text += &cause;
    }
    text
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn an_error_text_says_each_cause_once() {
        let os = std::io::Error::from_raw_os_error(28);
        let wrapped = anyhow::Error::new(exr::error::Error::from(os)).context("cannot write a");
        let text = error_text(&wrapped);
        let once = std::io::Error::from_raw_os_error(28).to_string();
        assert_eq!(text, format!("cannot write a: {once}"));
        let plain = anyhow::anyhow!("inner").context("outer");
        assert_eq!(error_text(&plain), "outer: inner");
    }

    #[test]
    fn line_breaks_and_escapes_are_shown_not_obeyed() {
        let shown = printable("material `a\nb` and `\u{1b}[31mred` in x\ty");
        assert_eq!(shown, "material `a\\nb` and `\\u{1b}[31mred` in x\\ty");
        assert!(!shown.chars().any(char::is_control));
        // Text that is not ASCII stays as written.
        assert_eq!(printable("θ_F ∈ [0.01, 89]°"), "θ_F ∈ [0.01, 89]°");
    }
}
