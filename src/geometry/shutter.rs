//! When a camera's pixels see the world: the shutter (all rows at once, or rows read out one
//! after another), the exposure each row integrates over, and the order the rows are read in;
//! and its mirror, when a display's rows show an image: the scan-out and the persistence.
//!
//! A frame is named by one instant `t`: when it is complete, its last row read out (a
//! camera's latency counts from there, as a driver delivers the image then). Row `r`, the
//! `k`-th of `rows` read, is read at `t − readout · (rows − 1 − k) / (rows − 1)`, and its
//! exposure ends there: it spans the `exposure` before. A pixel's `spp` samples are spread over
//! that exposure at the midpoints of `spp` equal slices, the same slices for every pixel. So a
//! frame is exactly the mean of `spp` instantaneous renders (one per slice) taken row by row,
//! which is what the renderer's twin checks; a global shutter with no exposure is one instant,
//! `t`, today's image bit for bit.

/// Longest readout or exposure, seconds: a second is a very long exposure for a moving car.
pub const MAX_SHUTTER_S: f64 = 1.0;

/// Which rows a camera reads first.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "snake_case")]
pub enum RowOrder {
    /// Row 0 (the image's top) first, as most CMOS sensors read.
    #[default]
    TopToBottom,
    /// The last row first (a sensor mounted upside down).
    BottomToTop,
}

impl RowOrder {
    pub const NAMES: [&'static str; 2] = ["top_to_bottom", "bottom_to_top"];
}

/// How a camera's rows and samples spread over time.
#[derive(Clone, Copy, Debug, Default, PartialEq, serde::Serialize)]
pub struct Shutter {
    /// Time from the first row's exposure to the last row's, seconds, in [0, 1]; 0 is a
    /// global shutter (every row at once).
    pub readout_s: f64,
    /// Time each row integrates light over, seconds, in [0, 1]; 0 is an instant.
    pub exposure_s: f64,
    /// The order the rows are read in (matters only with a readout).
    pub row_order: RowOrder,
}

impl Shutter {
    /// A global shutter with an instantaneous exposure: the whole image at one instant.
    pub const INSTANT: Shutter = Shutter {
        readout_s: 0.0,
        exposure_s: 0.0,
        row_order: RowOrder::TopToBottom,
    };

    /// Whether every pixel and sample is at the frame's instant.
    pub fn is_instant(&self) -> bool {
        self.readout_s == 0.0 && self.exposure_s == 0.0
    }

    /// Whether rows are read at different instants (a rolling shutter).
    pub fn is_rolling(&self) -> bool {
        self.readout_s > 0.0
    }

    /// Seconds after the frame's instant (≤ 0) at which row `row` of an image `height` rows
    /// high is read out, the end of its exposure.
    pub fn row_time(&self, row: u32, height: u32) -> f64 {
        if !self.is_rolling() || height < 2 {
            return 0.0;
        }
        // Rows still to be read after this one.
        let after = match self.row_order {
            RowOrder::TopToBottom => height - 1 - row,
            RowOrder::BottomToTop => row,
        };
        -self.readout_s * f64::from(after) / f64::from(height - 1)
    }

    /// Seconds from a row's readout (≤ 0) at which sample `sample` of `spp` is traced: the
    /// midpoint of one of `spp` equal slices of the exposure before it, slice
    /// `(sample + spp / 2) mod spp`, so that sample 0 (the pixel's centre, whose AOVs the
    /// frame keeps) is in the middle slice: exactly the exposure's middle for an odd `spp`.
    pub fn sample_time(&self, sample: u32, spp: u32) -> f64 {
        if self.exposure_s == 0.0 {
            return 0.0;
        }
        let spp = spp.max(1);
        let slice = (sample + spp / 2) % spp;
        self.exposure_s * ((f64::from(slice) + 0.5) / f64::from(spp) - 1.0)
    }

    /// Seconds after the frame's instant of sample `sample` (of `spp`) of row `row` (of
    /// `height`).
    pub fn instant(&self, row: u32, height: u32, sample: u32, spp: u32) -> f64 {
        self.row_time(row, height) + self.sample_time(sample, spp)
    }

    /// Each row's exposure as (start, end), seconds after the frame's instant (`height` of
    /// them, from the top).
    pub fn row_exposures(&self, height: u32) -> Vec<(f64, f64)> {
        (0..height)
            .map(|row| {
                let t = self.row_time(row, height);
                (t - self.exposure_s, t)
            })
            .collect()
    }
}

/// How a display's rows take a new image: all at once, or scanned top to bottom over the
/// refresh period; and how long a row stays lit after it is scanned.
#[derive(Clone, Copy, Debug, Default, PartialEq, serde::Serialize)]
pub struct Scanout {
    /// Whether the rows are scanned top to bottom over the refresh period (`false`: every row
    /// takes the new image at the refresh's instant).
    pub rolling: bool,
    /// How long a row stays lit after it is scanned, seconds, in (0, 1] (a strobed or
    /// low-persistence display); `None`: until it is scanned again (a hold display).
    pub persistence_s: Option<f64>,
}

/// What one display row shows at an instant.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum RowShows {
    /// The image of the latest refresh.
    Latest,
    /// The image of the refresh before it: the scan has not reached the row yet.
    Previous,
    /// Nothing: the row's light has gone out (its persistence is over), or no image has
    /// reached it yet.
    Dark,
}

impl Scanout {
    /// Seconds after a refresh begins at which row `row` (of `rows`, from the top) takes its
    /// image, the refresh period `period` s.
    pub fn row_time(&self, row: u32, rows: u32, period: f64) -> f64 {
        if self.rolling {
            period * f64::from(row) / f64::from(rows.max(1))
        } else {
            0.0
        }
    }

    /// What row `row` (of `rows`) shows `since` s after the latest refresh began (whose
    /// period is `period` s); `has_previous`: whether a refresh came before it.
    pub fn row_shows(
        &self,
        row: u32,
        rows: u32,
        since: f64,
        period: f64,
        has_previous: bool,
    ) -> RowShows {
        let scanned = self.row_time(row, rows, period);
        let (shows, lit_for) = if since >= scanned {
            (RowShows::Latest, since - scanned)
        } else if has_previous {
            (RowShows::Previous, since - scanned + period)
        } else {
            return RowShows::Dark;
        };
        match self.persistence_s {
            Some(p) if lit_for >= p => RowShows::Dark,
            _ => shows,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_rolling_scanout_shows_the_latest_image_above_the_scan_line() {
        let rolling = Scanout {
            rolling: true,
            persistence_s: None,
        };
        let period = 0.04;
        // 10 ms into a 40 ms refresh of 100 rows: rows 0..=25 scanned (row 25 at 10 ms).
        let shows: Vec<RowShows> = (0..100)
            .map(|r| rolling.row_shows(r, 100, 0.01, period, true))
            .collect();
        assert!(shows[..=25].iter().all(|s| *s == RowShows::Latest));
        assert!(shows[26..].iter().all(|s| *s == RowShows::Previous));
        // No refresh before: the unscanned rows are dark.
        assert_eq!(
            rolling.row_shows(26, 100, 0.01, period, false),
            RowShows::Dark
        );
        // A global scan-out: every row the latest at once.
        let global = Scanout::default();
        assert!((0..100).all(|r| global.row_shows(r, 100, 0.0, period, true) == RowShows::Latest));
        // A 5 ms persistence: lit only within 5 ms of its scan.
        let flash = Scanout {
            persistence_s: Some(0.005),
            ..rolling
        };
        let lit: Vec<u32> = (0..100)
            .filter(|&r| flash.row_shows(r, 100, 0.01, period, true) != RowShows::Dark)
            .collect();
        // Rows scanned in (5 ms, 10 ms]: 13..=25.
        assert_eq!(lit, (13..=25).collect::<Vec<_>>());
        let global_flash = Scanout {
            persistence_s: Some(0.005),
            ..global
        };
        assert_eq!(
            global_flash.row_shows(7, 100, 0.004, period, true),
            RowShows::Latest
        );
        assert_eq!(
            global_flash.row_shows(7, 100, 0.006, period, true),
            RowShows::Dark
        );
    }

    #[test]
    fn rows_are_spread_over_the_readout_in_their_order() {
        let rolling = Shutter {
            readout_s: 0.03,
            ..Shutter::INSTANT
        };
        // The top row read first, 30 ms before the frame is complete; the last at its instant.
        assert!((rolling.row_time(0, 481) + 0.03).abs() < 1e-15);
        assert!((rolling.row_time(240, 481) + 0.015).abs() < 1e-15);
        assert_eq!(rolling.row_time(480, 481), 0.0);
        let flipped = Shutter {
            row_order: RowOrder::BottomToTop,
            ..rolling
        };
        assert_eq!(flipped.row_time(0, 481), 0.0);
        assert!((flipped.row_time(480, 481) + 0.03).abs() < 1e-15);
        // One row, or a global shutter: the frame's instant.
        assert_eq!(rolling.row_time(0, 1), 0.0);
        assert_eq!(Shutter::INSTANT.row_time(100, 200), 0.0);
        assert!(Shutter::INSTANT.is_instant() && !rolling.is_instant());
    }

    #[test]
    fn samples_sit_at_the_midpoints_of_equal_slices_of_the_exposure() {
        let s = Shutter {
            exposure_s: 0.02,
            ..Shutter::INSTANT
        };
        // Sample 0 in the middle slice (the third of four), the others after it in turn.
        let times: Vec<f64> = (0..4).map(|k| s.sample_time(k, 4)).collect();
        let expected = [-0.0075, -0.0025, -0.0175, -0.0125];
        for (t, e) in times.iter().zip(expected) {
            assert!((t - e).abs() < 1e-15, "{times:?}");
        }
        // The exposure ends at the row's readout: their mean is half an exposure before it.
        assert!((times.iter().sum::<f64>() / 4.0 + 0.01).abs() < 1e-15);
        assert_eq!(s.sample_time(0, 1), -0.01);
        // An odd count: sample 0 at the exposure's middle.
        assert!((s.sample_time(0, 5) + 0.01).abs() < 1e-15);
        assert_eq!(s.row_exposures(3), vec![(-0.02, 0.0); 3]);
        assert!(!s.is_instant() && !s.is_rolling());
    }
}
