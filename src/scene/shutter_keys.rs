//! The shutter keys of `[camera.frontal]` and `[camera.back]`: `shutter` (`global` or
//! `rolling`), `readout_ms` and `row_order` (a rolling shutter's), `exposure_ms`; and the
//! display's of `[obstacle]`: `scanout` (`global` or `rolling`), `persistence_ms`. Documented
//! in `scenes/reference.toml` and docs/reference/scene-format.md; what they do in
//! docs/guide/time.md.

use crate::geometry::shutter::{MAX_SHUTTER_S, RowOrder, Scanout, Shutter};
use crate::scene::source::SceneError;
use crate::scene::table_reader::TableReader;

/// Values of the `shutter` key.
pub const SHUTTERS: [&str; 2] = ["global", "rolling"];

/// A rolling shutter's readout when the file gives none, milliseconds: automotive CMOS
/// sensors read their rows over 10–30 ms.
pub const DEFAULT_READOUT_MS: f64 = 20.0;

/// Shortest readout of a rolling shutter, milliseconds (a shorter one is a global shutter).
pub const MIN_READOUT_MS: f64 = 1e-3;

/// The camera table's shutter ([`Shutter::INSTANT`] without any of its keys).
pub fn read_shutter(t: &TableReader) -> Result<Shutter, SceneError> {
    let max_ms = MAX_SHUTTER_S * 1e3;
    let rolling = t.choice("shutter", "global", &SHUTTERS)? == "rolling";
    let (readout_ms, row_order) = if rolling {
        let readout = t.f64_in("readout_ms", DEFAULT_READOUT_MS, MIN_READOUT_MS, max_ms)?;
        let order = match t.choice("row_order", "top_to_bottom", &RowOrder::NAMES)? {
            "bottom_to_top" => RowOrder::BottomToTop,
            _ => RowOrder::TopToBottom,
        };
        (readout, order)
    } else {
        for key in ["readout_ms", "row_order"] {
            if t.has(key) {
                return Err(t.error(
                    key,
                    "is a rolling shutter's: set shutter = \"rolling\" (a global shutter reads every row at once)",
                ));
            }
        }
        (0.0, RowOrder::TopToBottom)
    };
    let exposure_ms = t.f64_in("exposure_ms", 0.0, 0.0, max_ms)?;
    Ok(Shutter {
        readout_s: readout_ms / 1e3,
        exposure_s: exposure_ms / 1e3,
        row_order,
    })
}

/// Values of the `scanout` key.
pub const SCANOUTS: [&str; 2] = ["global", "rolling"];

/// The obstacle table's display scan-out (every row at once, held, without its keys).
pub fn read_scanout(t: &TableReader) -> Result<Scanout, SceneError> {
    let rolling = t.choice("scanout", "global", &SCANOUTS)? == "rolling";
    let persistence_s = match t.opt_f64("persistence_ms")? {
        None => None,
        Some(_) => {
            Some(t.f64_in("persistence_ms", 0.0, MIN_READOUT_MS, MAX_SHUTTER_S * 1e3)? / 1e3)
        }
    };
    Ok(Scanout {
        rolling,
        persistence_s,
    })
}
