//! An error message as it reaches the terminal: one line, short, and inert. Messages repeat
//! what the user wrote (names, paths, values), which may hold line breaks, terminal escape
//! sequences or 800-digit numbers.

use crate::util::number::clip_long_numbers;

/// `text` with every control character escaped (`\n`, `\u{1b}`: a name holding a line break
/// no longer splits the message, an escape sequence no longer reaches the terminal) and
/// every overlong number clipped.
pub fn printable(text: &str) -> String {
    let escaped: String = text
        .chars()
        .flat_map(|c| {
            let shown: Vec<char> = if c.is_control() {
                c.escape_default().collect()
            } else {
                vec![c]
            };
            shown
        })
        .collect();
    clip_long_numbers(&escaped)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn line_breaks_and_escapes_are_shown_not_obeyed() {
        let shown = printable("material `a\nb` and `\u{1b}[31mred` in x\ty");
        assert_eq!(shown, "material `a\\nb` and `\\u{1b}[31mred` in x\\ty");
        assert!(!shown.chars().any(char::is_control));
        // Text that is not ASCII stays as written.
        assert_eq!(printable("θ_F ∈ [0.01, 89]°"), "θ_F ∈ [0.01, 89]°");
    }
}
