//! The outcome of `diff` and `check` when their thresholds are not met: not an error (the
//! inputs were fine), but exit status 1, which CI reads as "worse".

/// Some thresholds or bounds were not met; the text says which (one line).
#[derive(Debug)]
pub struct ChecksFailed(pub String);

impl std::fmt::Display for ChecksFailed {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "FAIL: {}", self.0)
    }
}

impl std::error::Error for ChecksFailed {}
