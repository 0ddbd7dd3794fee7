//! The `[eyellipse]` table: a seat package from which the SAE J941 eyellipse is placed (and the
//! driver's eye, its centre, unless `[camera.driver] position` gives one).

use crate::scene::eyellipse::{Eyellipse, SeatPackage};
use crate::scene::limits::MAX_COORDINATE;
use crate::scene::source::SceneError;
use crate::scene::table_reader::TableReader;

/// L6, the steering-wheel centre's fore-aft distance from the ball of foot: metres, and the
/// default (a mid-size car's).
pub const L6_RANGE: (f64, f64) = (0.0, 1.5);
pub const L6_DEFAULT: f64 = 0.45;
/// H30, the SgRP's height above the heel: J941's Class A vehicles (passenger cars) have it in
/// 127–405 mm, the range its centroid formula was fitted on. Metres, and the default.
pub const H30_RANGE: (f64, f64) = (0.127, 0.405);
pub const H30_DEFAULT: f64 = 0.27;

/// Reads `[eyellipse]`, if the scene has one.
pub fn read_eyellipse(root: &TableReader) -> Result<Option<Eyellipse>, SceneError> {
    let Some(t) = root.table("eyellipse")? else {
        return Ok(None);
    };
    let sgrp = t.point("sgrp", None)?;
    let Some(ball_of_foot_z) = t.opt_f64("ball_of_foot_z")? else {
        return Err(t.error(
            "ball_of_foot_z",
            "the [eyellipse] table needs `ball_of_foot_z` (world z of the ball of foot on the accelerator, metres)",
        ));
    };
    let ball_of_foot_z = t.f64_in(
        "ball_of_foot_z",
        ball_of_foot_z,
        -MAX_COORDINATE,
        MAX_COORDINATE,
    )?;
    if ball_of_foot_z >= sgrp.z {
        return Err(t.error(
            "ball_of_foot_z",
            format!(
                "the ball of foot must be ahead of the SgRP (the car faces −z): need ball_of_foot_z < sgrp z = {}, got {}",
                crate::util::number::short(sgrp.z),
                crate::util::number::short(ball_of_foot_z)
            ),
        ));
    }
    let seat = SeatPackage {
        sgrp,
        ball_of_foot_z,
        steering_l6: t.f64_in("steering_l6", L6_DEFAULT, L6_RANGE.0, L6_RANGE.1)?,
        seat_height_h30: t.f64_in("seat_height_h30", H30_DEFAULT, H30_RANGE.0, H30_RANGE.1)?,
        clutch: t.bool_or("clutch", false)?,
    };
    t.finish()?;
    Ok(Some(Eyellipse::j941_95(&seat)))
}
