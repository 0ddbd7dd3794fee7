//! A placements CSV (`[[object]] instances = "placements.csv"`) → placements: no panic; a
//! kept file is one the world can place (at least one row, at most `MAX_INSTANCES`, every
//! value finite and within ±10⁶, every transform finite); an error is one line naming the
//! file.
#![no_main]

use glam::DAffine3;
use libfuzzer_sys::fuzz_target;
use seethru::scene::instances::{MAX_INSTANCES, parse_placements, world_from_object};

fuzz_target!(|data: &[u8]| {
    match parse_placements(data, "placements.csv") {
        Ok(rows) => {
            assert!(!rows.is_empty() && rows.len() <= MAX_INSTANCES);
            for row in rows {
                assert!(
                    row.iter().all(|v| v.is_finite() && v.abs() <= 1e6),
                    "{row:?}"
                );
                let m = world_from_object(row, &DAffine3::from_scale(glam::DVec3::splat(2.0)));
                assert!(m.is_finite(), "{row:?}");
            }
        }
        Err(e) => {
            let shown = format!("{e:#}");
            assert!(
                shown.starts_with("placements.csv") && !shown.contains('\n'),
                "{shown}"
            );
        }
    }
});
