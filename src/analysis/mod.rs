//! Closed forms: the paper's equations (as the geometry has them), the physical-unit
//! sensitivities derived from them, and where the driver perceives what the display shows.
//! Used by the system (head equations), the measurements (predictions) and the paper's claims
//! and figures, so they sit below all three.

pub mod binocular;
pub mod depth_error;
pub mod dynamic;
pub mod examples;
pub mod paper;
pub mod perceived;
pub mod physical;
