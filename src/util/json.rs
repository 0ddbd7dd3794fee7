//! JSON for values that may be infinite: JSON has no infinity, so an infinite distance (the
//! paper's d2 → ∞) is written as the string "inf" instead of serde_json's `null`.

/// Serializes a finite number as itself and anything else as "inf"; for `serialize_with`.
pub fn finite_or_inf<S: serde::Serializer>(v: &f64, s: S) -> Result<S::Ok, S::Error> {
    if v.is_finite() {
        s.serialize_f64(*v)
    } else {
        s.serialize_str("inf")
    }
}
