//! The parameter sets of the paper's own examples (Fig. 3, §5.2), shared by the claims table,
//! the figures and the observed ratios.

use crate::analysis::paper::{CropParams, ForeshorteningParams, OcclusionParams};

/// The Fig. 3 configuration at d2 = 1 m.
pub fn fig3_params(theta_deg: f64) -> CropParams {
    CropParams {
        d1: 1.0,
        d2: 1.0,
        b_h: 0.125,
        width: 0.5,
        theta_f: theta_deg.to_radians(),
    }
}

pub fn paper_occlusion() -> OcclusionParams {
    OcclusionParams {
        l: 5.0,
        b1: -0.35,
        d2: 6.3,
        d1: 2.5,
        b_h: 1.75,
    }
}

pub fn paper_foreshortening() -> ForeshorteningParams {
    ForeshorteningParams {
        l: 5.0,
        b1: -1.5,
        d2: 1.3,
        d1: 2.0,
        b_h: 0.7,
        gamma: 90f64.to_radians(),
    }
}
