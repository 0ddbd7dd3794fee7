//! Small pieces every layer uses: sRGB transfer functions, deterministic hashing for
//! sampling, short numbers for messages, the progress line, JSON for infinite distances and
//! the process's peak memory; an error as one line.

pub mod color;
pub mod input_file;
pub mod json;
pub mod memory;
pub mod number;
pub mod progress;
pub mod sampling;

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
    #[test]
    fn an_error_text_says_each_cause_once() {
        let os = std::io::Error::from_raw_os_error(28);
        let wrapped = anyhow::Error::new(exr::error::Error::from(os)).context("cannot write a");
        let text = super::error_text(&wrapped);
        let once = std::io::Error::from_raw_os_error(28).to_string();
        assert_eq!(text, format!("cannot write a: {once}"));
        let plain = anyhow::anyhow!("inner").context("outer");
        assert_eq!(super::error_text(&plain), "outer: inner");
    }
}
