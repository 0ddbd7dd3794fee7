//! `seethru ratio`: the observed p_cam/p_user of the paper's occlusion or foreshortening setup.

use anyhow::{Result, bail};
use seethru::analysis::paper::{ForeshorteningParams, OcclusionParams};
use seethru::measure::ratio::{describe, measure_ratio};
use seethru::measure::ratio_setup::{Compensation, Setup};
use seethru::render::settings::check_resolution;

use crate::cli::args::with_threads;

#[derive(clap::Args)]
pub struct Ratio {
    #[command(subcommand)]
    setup: RatioSetup,
}

#[derive(clap::Subcommand)]
enum RatioSetup {
    /// A box of depth L standing on the scene plane at d2, its near edge at lateral b1.
    Occlusion {
        #[arg(long = "L")]
        l: f64,
        #[command(flatten)]
        at: RatioGeometry,
        #[command(flatten)]
        common: RatioCommon,
    },
    /// A surface of length l from its corner at b1 on the plane at d2, at angle γ to the plane.
    Foreshortening {
        #[arg(long = "l")]
        l: f64,
        /// Angle between the surface and the plane, degrees, in (0, 90].
        #[arg(long)]
        gamma: f64,
        #[command(flatten)]
        at: RatioGeometry,
        #[command(flatten)]
        common: RatioCommon,
    },
}

/// Where the object and the eye are (the paper's §4.2 parameters), metres.
#[derive(clap::Args)]
struct RatioGeometry {
    /// Lateral position of the object's corner.
    #[arg(long, allow_hyphen_values = true)]
    b1: f64,
    /// Distance of the scene plane from the display.
    #[arg(long)]
    d2: f64,
    /// Distance of the eye from the display.
    #[arg(long)]
    d1: f64,
    /// Eye offset b_h (the eye at lateral −b_h).
    #[arg(long = "bh", allow_hyphen_values = true)]
    b_h: f64,
}

#[derive(clap::Args)]
struct RatioCommon {
    /// The compensation's model plane behind the display, metres in (0, ∞), or `inf`
    /// (default: the scene plane, the paper's case).
    #[arg(
        long = "model-d2",
        value_name = "METRES|inf",
        allow_hyphen_values = true
    )]
    model_d2: Option<String>,
    /// Head-tracking bias of the compensation's eye, obstacle frame, centimetres: x,y,z.
    #[arg(
        long = "head-bias-cm",
        value_name = "X,Y,Z",
        allow_hyphen_values = true,
        default_value = "0,0,0"
    )]
    head_bias_cm: String,
    /// Width of the driver view, the frontal image and the display, pixels.
    #[arg(long, default_value_t = 1280)]
    width: u32,
    /// Print JSON.
    #[arg(long)]
    json: bool,
    #[arg(long)]
    threads: Option<usize>,
}

impl Ratio {
    pub fn run(self) -> Result<()> {
        let (setup, common) = match self.setup {
            RatioSetup::Occlusion {
                l,
                at: RatioGeometry { b1, d2, d1, b_h },
                common,
            } => (
                Setup::Occlusion(OcclusionParams { l, b1, d2, d1, b_h }),
                common,
            ),
            RatioSetup::Foreshortening {
                l,
                gamma,
                at: RatioGeometry { b1, d2, d1, b_h },
                common,
            } => {
                let gamma = gamma.to_radians();
                (
                    Setup::Foreshortening(ForeshorteningParams {
                        l,
                        b1,
                        d2,
                        d1,
                        b_h,
                        gamma,
                    }),
                    common,
                )
            }
        };
        check_resolution(common.width, common.width)?;
        let compensation = Compensation {
            model_d2: common.model_d2.as_deref().map(parse_model_d2).transpose()?,
            head_bias_cm: parse_bias(&common.head_bias_cm)?,
        };
        let result = with_threads(common.threads, || {
            measure_ratio(&setup, common.width, &compensation)
        })??;
        if common.json {
            println!("{}", serde_json::to_string_pretty(&result)?);
        } else {
            print!("{}", describe(&result));
        }
        Ok(())
    }
}

/// `--model-d2`: `inf` or a distance in metres in (0, ∞).
fn parse_model_d2(text: &str) -> Result<f64> {
    match text {
        "inf" | "infinity" => Ok(f64::INFINITY),
        _ => match text.parse::<f64>() {
            Ok(v) if v.is_finite() && v > 0.0 => Ok(v),
            _ => bail!("--model-d2 must be a distance in metres in (0, ∞) or `inf`, got `{text}`"),
        },
    }
}

/// `--head-bias-cm`: three finite numbers x,y,z.
fn parse_bias(text: &str) -> Result<[f64; 3]> {
    let values: Vec<f64> = text
        .split(',')
        .map(|v| v.trim().parse::<f64>())
        .collect::<Result<_, _>>()
        .unwrap_or_default();
    match values[..] {
        [x, y, z] if values.iter().all(|v| v.is_finite()) => Ok([x, y, z]),
        _ => bail!(
            "--head-bias-cm must be three finite numbers x,y,z in centimetres (the eye must stay in front of the display), got `{text}`"
        ),
    }
}
