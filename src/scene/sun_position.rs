//! Where the sun stands at a date, a time and a place: the algorithm of NOAA's solar
//! calculator (Meeus, *Astronomical Algorithms*, ch. 25, low precision: the sun's apparent
//! longitude, the obliquity, the declination and the equation of time from the Julian
//! century), good to about 0.01° between 1900 and 2100. Refraction is left out: it lifts the
//! sun by up to 0.6° at the horizon. (Spencer's 1971 Fourier series, simpler, is off by up to
//! 0.4° in declination in years away from its reference: a day of the leap-year cycle.)

/// A calendar date and a time of day in UTC.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct UtcInstant {
    pub year: i32,
    /// 1–12.
    pub month: u32,
    /// 1–31, within the month.
    pub day: u32,
    /// Seconds since midnight UTC, [0, 86400).
    pub seconds: f64,
}

/// Years the series is used for.
pub const YEARS: (i32, i32) = (1900, 2100);

fn is_leap(year: i32) -> bool {
    (year % 4 == 0 && year % 100 != 0) || year % 400 == 0
}

fn days_in_month(year: i32, month: u32) -> u32 {
    match month {
        2 if is_leap(year) => 29,
        2 => 28,
        4 | 6 | 9 | 11 => 30,
        _ => 31,
    }
}

/// `YYYY-MM-DD`, a real day of a year in [`YEARS`].
pub fn parse_date(text: &str) -> Result<(i32, u32, u32), String> {
    let bad = || {
        format!(
            "expected a date YYYY-MM-DD between {} and {}, got \"{text}\"",
            YEARS.0, YEARS.1
        )
    };
    let parts: Vec<&str> = text.split('-').collect();
    let [y, m, d] = parts[..] else {
        return Err(bad());
    };
    if y.len() != 4 || m.len() != 2 || d.len() != 2 {
        return Err(bad());
    }
    let (Ok(year), Ok(month), Ok(day)) = (y.parse::<i32>(), m.parse::<u32>(), d.parse::<u32>())
    else {
        return Err(bad());
    };
    if !(YEARS.0..=YEARS.1).contains(&year) || !(1..=12).contains(&month) {
        return Err(bad());
    }
    if !(1..=days_in_month(year, month)).contains(&day) {
        return Err(format!("{year}-{m} has no day {day}"));
    }
    Ok((year, month, day))
}

/// `HH:MM` or `HH:MM:SS` (24-hour), as seconds since midnight.
pub fn parse_time(text: &str) -> Result<f64, String> {
    let bad =
        || format!("expected a time HH:MM or HH:MM:SS from 00:00 to 23:59:59, got \"{text}\"");
    let parts: Vec<&str> = text.split(':').collect();
    if !(2..=3).contains(&parts.len()) || parts.iter().any(|p| p.len() != 2) {
        return Err(bad());
    }
    let numbers: Vec<u32> = parts
        .iter()
        .map(|p| p.parse::<u32>())
        .collect::<Result<_, _>>()
        .map_err(|_| bad())?;
    let (h, m, s) = (numbers[0], numbers[1], numbers.get(2).copied().unwrap_or(0));
    if h > 23 || m > 59 || s > 59 {
        return Err(bad());
    }
    Ok(f64::from(h * 3600 + m * 60 + s))
}

impl UtcInstant {
    /// Julian centuries since J2000.0 (UTC taken for terrestrial time: 70 s, 0.0002°).
    fn julian_century(&self) -> f64 {
        let a = (14 - self.month as i64) / 12;
        let y = i64::from(self.year) + 4800 - a;
        let m = self.month as i64 + 12 * a - 3;
        let day_number =
            i64::from(self.day) + (153 * m + 2) / 5 + 365 * y + y / 4 - y / 100 + y / 400 - 32045;
        let julian_day = day_number as f64 - 0.5 + self.seconds / 86_400.0;
        (julian_day - 2_451_545.0) / 36_525.0
    }
}

/// The sun's declination, radians, and the equation of time, minutes (apparent minus mean
/// solar time), at `at`.
pub fn declination_and_equation_of_time(at: &UtcInstant) -> (f64, f64) {
    let t = at.julian_century();
    let mean_longitude = (280.46646 + t * (36000.76983 + 0.0003032 * t)).rem_euclid(360.0);
    let mean_anomaly = 357.52911 + t * (35999.05029 - 0.0001537 * t);
    let eccentricity = 0.016708634 - t * (0.000042037 + 0.0000001267 * t);
    let m = mean_anomaly.to_radians();
    let centre = m.sin() * (1.914602 - t * (0.004817 + 0.000014 * t))
        + (2.0 * m).sin() * (0.019993 - 0.000101 * t)
        + (3.0 * m).sin() * 0.000289;
    let omega = (125.04 - 1934.136 * t).to_radians();
    let apparent_longitude =
        (mean_longitude + centre - 0.00569 - 0.00478 * omega.sin()).to_radians();
    let mean_obliquity =
        23.0 + (26.0 + (21.448 - t * (46.815 + t * (0.00059 - t * 0.001813))) / 60.0) / 60.0;
    let obliquity = (mean_obliquity + 0.00256 * omega.cos()).to_radians();
    let declination = (obliquity.sin() * apparent_longitude.sin()).asin();
    let y = (obliquity / 2.0).tan().powi(2);
    let l0 = mean_longitude.to_radians();
    let e = eccentricity;
    let eot = y * (2.0 * l0).sin() - 2.0 * e * m.sin() + 4.0 * e * y * m.sin() * (2.0 * l0).cos()
        - 0.5 * y * y * (4.0 * l0).sin()
        - 1.25 * e * e * (2.0 * m).sin();
    (declination, 4.0 * eot.to_degrees())
}

/// The sun's elevation above the horizon and its azimuth clockwise from north, degrees, seen
/// from `latitude_deg` (north positive) and `longitude_deg` (east positive) at `at`.
pub fn sun_angles(at: &UtcInstant, latitude_deg: f64, longitude_deg: f64) -> (f64, f64) {
    let (decl, eot) = declination_and_equation_of_time(at);
    // True solar time, minutes, and the hour angle (0 at solar noon, + in the afternoon).
    let solar_minutes = at.seconds / 60.0 + eot + 4.0 * longitude_deg;
    let hour_angle = (solar_minutes / 4.0 - 180.0).to_radians();
    let lat = latitude_deg.to_radians();
    let sin_elevation = lat.sin() * decl.sin() + lat.cos() * decl.cos() * hour_angle.cos();
    let elevation = sin_elevation.clamp(-1.0, 1.0).asin();
    // Clockwise from north: 180° (south) at solar noon north of the sun.
    let azimuth = hour_angle
        .sin()
        .atan2(hour_angle.cos() * lat.sin() - decl.tan() * lat.cos())
        .to_degrees()
        + 180.0;
    (elevation.to_degrees(), azimuth.rem_euclid(360.0))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn at(date: &str, time: &str) -> UtcInstant {
        let (year, month, day) = parse_date(date).unwrap();
        UtcInstant {
            year,
            month,
            day,
            seconds: parse_time(time).unwrap(),
        }
    }

    /// The instant of the day when the sun stands highest at `longitude`, found by scanning
    /// every second: the brute-force twin of solar noon = 12:00 − EoT − 4 min × longitude.
    fn scanned_noon(date: &str, latitude: f64, longitude: f64) -> (f64, f64) {
        let mut best = (f64::NEG_INFINITY, 0.0);
        for s in 0..86_400 {
            let mut i = at(date, "00:00");
            i.seconds = f64::from(s);
            let (elevation, _) = sun_angles(&i, latitude, longitude);
            if elevation > best.0 {
                best = (elevation, f64::from(s));
            }
        }
        best
    }

    #[test]
    fn the_noon_sun_stands_at_ninety_minus_latitude_plus_declination() {
        // The solstices and an equinox of 2026 (declination +23.44°, −23.44°, about 0°), at
        // Berlin, at the equator and in Sydney.
        for (date, declination) in [
            ("2026-06-21", 23.44),
            ("2026-12-21", -23.44),
            ("2026-03-20", 0.0),
        ] {
            for (latitude, longitude) in [(52.52, 13.40), (0.0, -60.0), (-33.87, 151.21)] {
                let (highest, _) = scanned_noon(date, latitude, longitude);
                let expected = 90.0 - (latitude - declination).abs();
                assert!(
                    (highest - expected).abs() < 0.25,
                    "{date} at {latitude}°: {highest} vs {expected}"
                );
            }
        }
    }

    #[test]
    fn solar_noon_moves_with_the_equation_of_time_and_the_longitude() {
        // The equation of time's extremes: about +16.4 min on 3 November, −14.2 min on
        // 11 February (the sun is then early, late); 4 minutes of clock per degree east.
        for (date, eot_minutes) in [("2026-11-03", 16.4), ("2026-02-11", -14.2)] {
            for longitude in [0.0, 15.0, -75.0] {
                let (_, noon) = scanned_noon(date, 40.0, longitude);
                let expected = (12.0 * 60.0 - eot_minutes - 4.0 * longitude) * 60.0;
                assert!(
                    (noon - expected).abs() < 60.0,
                    "{date} at {longitude}°E: noon at {noon} s vs {expected} s"
                );
            }
        }
    }

    #[test]
    fn the_sun_rises_in_the_east_culminates_south_and_sets_in_the_west() {
        // Berlin at the equinox: east at sunrise, south at noon, west at sunset; the sun is
        // north of the zenith at noon in Sydney.
        // Solar noon in Berlin that day: 12:00 + 7.4 min (EoT −7.4) − 53.6 min (13.4° E).
        let (e, az) = sun_angles(&at("2026-03-20", "05:14"), 52.52, 13.40);
        assert!(e.abs() < 1.0 && (az - 90.0).abs() < 2.0, "{e} {az}");
        let (_, az) = sun_angles(&at("2026-03-20", "11:14"), 52.52, 13.40);
        assert!((az - 180.0).abs() < 1.0, "{az}");
        let (e, az) = sun_angles(&at("2026-03-20", "17:14"), 52.52, 13.40);
        assert!(e.abs() < 1.0 && (az - 270.0).abs() < 2.0, "{e} {az}");
        // Sydney's noon: 12:00 − 1.7 min − 604.8 min; the sun 10° from the zenith, north.
        let (e, az) = sun_angles(&at("2026-12-21", "01:53"), -33.87, 151.21);
        assert!(
            (e - 79.6).abs() < 0.3 && !(3.0..=357.0).contains(&az),
            "{e} {az}"
        );
    }

    #[test]
    fn dates_and_times_are_read_strictly() {
        assert_eq!(parse_date("2024-02-29"), Ok((2024, 2, 29)));
        assert!(parse_date("2026-02-29").unwrap_err().contains("no day 29"));
        assert!(parse_date("1900-02-29").is_err()); // not a leap year
        for bad in [
            "2026-13-01",
            "2026-1-01",
            "26-01-01",
            "2026-01",
            "2201-01-01",
            "x",
        ] {
            assert!(parse_date(bad).is_err(), "{bad}");
        }
        assert_eq!(parse_time("11:30"), Ok(41_400.0));
        assert_eq!(parse_time("23:59:59"), Ok(86_399.0));
        for bad in ["24:00", "12:60", "1:30", "12:30:5", "12", "12:30:00:00"] {
            assert!(parse_time(bad).is_err(), "{bad}");
        }
    }
}
