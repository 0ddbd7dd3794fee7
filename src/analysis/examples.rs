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

/// The das scene's geometry for the error budget: the eye 0.75 m in front of the display and
/// 0.35 m to its right (a bearing of atan(0.35 / 0.75) ≈ 25° left of the road), the display
/// 0.25 m wide, and the scene behind the display 6.4 m beyond it (the median depth `--d2
/// auto` finds there). `tests/sequence.rs` checks these against `scenes/das.toml`.
pub fn das_geometry() -> crate::analysis::dynamic::BudgetGeometry {
    crate::analysis::dynamic::BudgetGeometry {
        d1: 0.75,
        scene_depth: 6.4,
        bearing: (0.35f64 / 0.75).atan(),
        half_width: 0.125,
    }
}
