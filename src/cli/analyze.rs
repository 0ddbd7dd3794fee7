//! `seethru analyze`: the paper's claims beside seethru's values, and every closed form at a
//! parameter set.

use crate::cli::args::{metres_or_inf, pixels, positive, real};
use anyhow::Result;
use seethru::analysis::dynamic::{budget_text, error_budget};
use seethru::analysis::examples::das_geometry;
use seethru::paper::claims::{
    AnalyzeParams, claims_table, evaluate, head_error_table, head_error_text, lens_and_eyes,
    paper_claims,
};

#[derive(clap::Args)]
#[command(allow_negative_numbers = true)]
pub struct Analyze {
    /// Print JSON instead of tables.
    #[arg(long)]
    json: bool,
    /// Eye distance from the display d1, metres in [1e-6, 1000].
    #[arg(long, default_value_t = 1.0, value_parser = positive(1e3))]
    d1: f64,
    /// Working distance d2, metres in [1e-6, 1e6], or inf for the d2 → ∞ model.
    #[arg(long, default_value_t = 1.0, value_name = "METRES|inf", value_parser = metres_or_inf)]
    d2: f64,
    /// Lateral eye offset b_h, metres in [-100, 100] (> 0: the eye on the side of the left
    /// crop R1).
    #[arg(long = "bh", default_value_t = 0.125, allow_hyphen_values = true, value_parser = real(-100.0, 100.0))]
    b_h: f64,
    /// Display width D, metres in [1e-6, 100].
    #[arg(long, default_value_t = 0.5, value_parser = positive(100.0))]
    width: f64,
    /// Frontal half angle θ_F, degrees in [0.01, 89].
    #[arg(long = "theta-f", default_value_t = 80.0, value_parser = real(0.01, 89.0))]
    theta_f: f64,
    /// Frontal image width, pixels in [1, 16384].
    #[arg(long = "frontal-px", default_value_t = 1280, value_parser = pixels)]
    frontal_px: u32,
    /// Occluder depth L, metres in [1e-6, 1e4].
    #[arg(long = "L", default_value_t = 1.0, value_parser = positive(1e4))]
    occluder_depth: f64,
    /// Lateral position of the object's corner b1, metres in [-1e4, 1e4].
    #[arg(long, default_value_t = 0.25, allow_hyphen_values = true, value_parser = real(-1e4, 1e4))]
    b1: f64,
    /// Length of the angled surface l, metres in [1e-6, 1e4].
    #[arg(long = "l", default_value_t = 1.0, value_parser = positive(1e4))]
    surface_length: f64,
    /// Angle of the surface γ to the plane, degrees in [1e-6, 90].
    #[arg(long, default_value_t = 45.0, value_parser = positive(90.0))]
    gamma: f64,
    /// Tolerance of the d2_min bound, as a fraction of R(∞) in [1e-6, 1].
    #[arg(long, default_value_t = 0.05, value_parser = positive(1.0))]
    tolerance: f64,
    /// Display height H, metres in [1e-6, 100] (for the crop's corners).
    #[arg(long, default_value_t = 0.45, value_parser = positive(100.0))]
    height: f64,
    /// Radial distortion k1 of the frontal lens (Brown–Conrady) that the compensation
    /// ignores, in [-1, 1].
    #[arg(long, default_value_t = -0.1, allow_hyphen_values = true, value_parser = real(-1.0, 1.0))]
    k1: f64,
    /// Interpupillary distance, metres in [1e-6, 0.1].
    #[arg(long, default_value_t = 0.064, value_parser = positive(0.1))]
    ipd: f64,
}

impl Analyze {
    pub fn run(self) -> Result<()> {
        let params = AnalyzeParams {
            d1: self.d1,
            d2: self.d2,
            b_h: self.b_h,
            width: self.width,
            theta_f_deg: self.theta_f,
            frontal_px: self.frontal_px,
            occluder_depth: self.occluder_depth,
            b1: self.b1,
            surface_length: self.surface_length,
            gamma_deg: self.gamma,
            tolerance: self.tolerance,
        };
        params.validate().map_err(anyhow::Error::msg)?;
        let lens_eyes = lens_and_eyes(&params, self.height, self.k1, self.ipd);
        let claims = paper_claims();
        let values = evaluate(&params);
        let budget = error_budget(&das_geometry());
        if self.json {
            println!(
                "{}",
                serde_json::to_string_pretty(
                    &serde_json::json!({"claims": claims, "evaluation": values, "lens_and_eyes": lens_eyes, "error_budget_das": budget})
                )?
            );
        } else {
            print!("{}", claims_table(&claims));
            print!("\n{}", head_error_text(&params, &head_error_table(&params)));
            print!("\n{}", budget_text(&budget));
            println!(
                "\nEvery closed form at the given parameters:\n{}",
                serde_json::to_string_pretty(&values)?
            );
            println!(
                "\nReal cameras and two eyes (analysis/binocular.rs):\n{}",
                serde_json::to_string_pretty(&lens_eyes)?
            );
        }
        Ok(())
    }
}
