//! Closed forms: the paper's equations (as the geometry has them) and the physical-unit
//! sensitivities derived from them. Used by the system (head equations), the measurements
//! (predictions) and the paper's claims and figures, so they sit below all three.

pub mod examples;
pub mod paper;
pub mod physical;
