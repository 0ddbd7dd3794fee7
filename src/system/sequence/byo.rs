//! Bring your own method over time: each refresh's inputs kept for `sequence --capture`, and
//! the outside method's display maps shown instead of the built-in compensation for
//! `sequence --maps`.

use std::collections::BTreeMap;
use std::sync::Arc;

use serde_json::Value;

use crate::geometry::camera::Camera;
use crate::render::frame::Frame;
use crate::system::capture::{DisplayMap, HeadEstimate};

/// What the sequence does besides its built-in compensation.
#[derive(Clone, Debug, Default)]
pub struct Byo {
    /// Keep every refresh's inputs ([`RefreshInputs`]) for the caller.
    pub capture: bool,
    /// Display maps by refresh index, shown instead of the built-in compensation.
    pub maps: Option<Arc<BTreeMap<i64, NamedMap>>>,
}

impl Byo {
    /// Whether each refresh renders the whole frontal image and the back image and computes
    /// the capture's fingerprint.
    pub fn needs_inputs(&self) -> bool {
        self.capture || self.maps.is_some()
    }
}

/// A map with the file it came from and the displayed frame it is for (for messages).
#[derive(Clone, Debug)]
pub struct NamedMap {
    pub file: String,
    pub frame: usize,
    pub map: DisplayMap,
}

/// What the system's algorithm receives at one refresh, as `seethru capture` writes it.
#[derive(Clone, Debug)]
pub struct RefreshInputs {
    /// The whole frontal image of the capture time.
    pub frontal: Frame,
    /// The back camera's image of the head-sample time (at least `BACK_MIN_SPP` samples).
    pub back: Frame,
    /// The head estimate the compensation used (predicted to the refresh time when asked).
    pub head: HeadEstimate,
    /// `calibration.json` of the compensation's geometry: the display where it was at capture
    /// (at the refresh with `--reproject`), the frontal camera at capture, world frame.
    pub calibration: Value,
    pub fingerprint: String,
    /// The true back camera at the head-sample time (for `truth/`).
    pub back_true: Camera,
}
