//! Numbers in messages: short enough to read (no 300-digit floats), exact enough to act on.

/// `x` with at most 6 significant digits: plain notation for magnitudes in [1e-4, 1e6),
/// scientific beyond; integers below 1e15 exactly; `NaN`, `inf` and `-inf` by name.
pub fn short(x: f64) -> String {
    if x.is_nan() {
        return "NaN".into();
    }
    if x.is_infinite() {
        return if x > 0.0 { "inf" } else { "-inf" }.into();
    }
    let magnitude = x.abs();
    if x.fract() == 0.0 && magnitude < 1e15 {
        return format!("{x:.0}");
    }
    if (1e-4..1e6).contains(&magnitude) {
        let digits = (5 - magnitude.log10().floor() as i32).max(0) as usize;
        let text = format!("{x:.digits$}");
        let text = text.trim_end_matches('0').trim_end_matches('.');
        return text.to_string();
    }
    let text = format!("{x:.5e}");
    let (mantissa, exponent) = text.split_once('e').unwrap_or((&text, "0"));
    let mantissa = mantissa.trim_end_matches('0').trim_end_matches('.');
    format!("{mantissa}e{exponent}")
}

/// A list of numbers, each [`short`], as `[a, b, c]`.
pub fn short_list(xs: &[f64]) -> String {
    let items: Vec<String> = xs.iter().map(|&x| short(x)).collect();
    format!("[{}]", items.join(", "))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn numbers_are_short_and_round_trip_to_six_digits() {
        let cases = [
            (1e300, "1e300"),
            (-1e300, "-1e300"),
            (0.0, "0"),
            (-1.0, "-1"),
            (100000.0, "100000"),
            (1e15, "1e15"),
            (0.25, "0.25"),
            (1.0 / 3.0, "0.333333"),
            (-0.0001234567, "-0.000123457"),
            (1.5e-7, "1.5e-7"),
            (f64::NAN, "NaN"),
            (f64::NEG_INFINITY, "-inf"),
            (123456.7, "123457"),
        ];
        for (x, expected) in cases {
            assert_eq!(short(x), expected, "{x:e}");
        }
        for x in [1.234567e300, 7.0e-300, 0.5e-4, 9.99999e5, 12345.678] {
            let back: f64 = short(x).parse().unwrap();
            assert!((back - x).abs() <= 1e-5 * x.abs(), "{x:e} → {}", short(x));
            assert!(short(x).len() <= 13, "{}", short(x));
        }
        assert_eq!(short_list(&[1.0, f64::INFINITY]), "[1, inf]");
    }
}
