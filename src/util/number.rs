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

/// `text` with every number written with more than 24 digits (as a user or a script may
/// paste one: 800 digits of a float) cut to its first 12 characters and its length, so that a
/// message that repeats the input stays short.
pub fn clip_long_numbers(text: &str) -> String {
    let is_number_char = |c: char| c.is_ascii_digit() || matches!(c, '.' | 'e' | 'E' | '+' | '-');
    let mut out = String::with_capacity(text.len().min(1024));
    let mut run = String::new();
    let flush = |run: &mut String, out: &mut String| {
        if run.chars().filter(char::is_ascii_digit).count() > 24 {
            out.extend(run.chars().take(12));
            out.push_str(&format!("…({} characters)", run.chars().count()));
        } else {
            out.push_str(run);
        }
        run.clear();
    };
    for c in text.chars() {
        if is_number_char(c) {
            run.push(c);
        } else {
            flush(&mut run, &mut out);
            out.push(c);
        }
    }
    flush(&mut run, &mut out);
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn long_numbers_in_messages_are_clipped_and_others_kept() {
        let long = format!("1{}.5", "0".repeat(800));
        let clipped = clip_long_numbers(&format!("invalid value '{long}' for '--band <BAND>'"));
        assert_eq!(
            clipped,
            "invalid value '100000000000…(803 characters)' for '--band <BAND>'"
        );
        for kept in [
            "scenes/x.toml:32:10: must be in [1e-6, 100000], got 0",
            "run-2026-12-01/out.tmp-123456: 1234567890123456789012345 is 25 digits",
        ] {
            let expected =
                kept.replace("1234567890123456789012345", "123456789012…(25 characters)");
            assert_eq!(clip_long_numbers(kept), expected);
        }
    }

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
