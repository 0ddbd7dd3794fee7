//! `seethru ratio`: the observed p_cam/p_user of the paper's occlusion or foreshortening setup.

use anyhow::Result;
use seethru::analysis::paper::{ForeshorteningParams, OcclusionParams};
use seethru::measure::ratio::{describe, measure_ratio, ratio_estimate};
use seethru::measure::ratio_setup::{Compensation, Setup};
use seethru::render::settings::check_resolution;
use seethru::system::memory::check_memory;

use crate::cli::args::{
    MemoryLimit, head_bias_cm, metres_or_inf, pixels, positive, real, threads, with_threads,
};

#[derive(clap::Args)]
pub struct Ratio {
    #[command(subcommand)]
    setup: RatioSetup,
}

#[derive(clap::Subcommand)]
enum RatioSetup {
    /// A box of depth L standing on the scene plane at d2, its near edge at lateral b1.
    #[command(allow_negative_numbers = true)]
    Occlusion {
        /// Depth of the box L, metres in [1e-6, 1e4].
        #[arg(long = "L", value_parser = positive(1e4))]
        l: f64,
        #[command(flatten)]
        at: RatioGeometry,
        #[command(flatten)]
        common: RatioCommon,
    },
    /// A surface of length l from its corner at b1 on the plane at d2, at angle γ to the plane.
    #[command(allow_negative_numbers = true)]
    Foreshortening {
        /// Length of the surface l, metres in [1e-6, 1e4].
        #[arg(long = "l", value_parser = positive(1e4))]
        l: f64,
        /// Angle between the surface and the plane, degrees in [1e-6, 90].
        #[arg(long, value_parser = positive(90.0))]
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
    /// Lateral position of the object's corner b1, metres in [-1e4, 1e4].
    #[arg(long, allow_hyphen_values = true, value_parser = real(-1e4, 1e4))]
    b1: f64,
    /// Distance of the scene plane from the display d2, metres in [1e-6, 1e4].
    #[arg(long, value_parser = positive(1e4))]
    d2: f64,
    /// Distance of the eye from the display d1, metres in [1e-6, 1e3].
    #[arg(long, value_parser = positive(1e3))]
    d1: f64,
    /// Eye offset b_h (the eye at lateral −b_h), metres in [-1e3, 1e3].
    #[arg(long = "bh", allow_hyphen_values = true, value_parser = real(-1e3, 1e3))]
    b_h: f64,
}

#[derive(clap::Args)]
struct RatioCommon {
    /// The compensation's model plane behind the display, metres in [1e-6, 1e6], or `inf`
    /// (default: the scene plane, the paper's case).
    #[arg(
        long = "model-d2",
        value_name = "METRES|inf",
        allow_hyphen_values = true,
        value_parser = metres_or_inf
    )]
    model_d2: Option<f64>,
    /// Head-tracking bias of the compensation's eye, obstacle frame, centimetres: x,y,z, each
    /// in [-500, 500] (the eye must stay in front of the display).
    #[arg(
        long = "head-bias-cm",
        value_name = "X,Y,Z",
        allow_hyphen_values = true,
        default_value = "0,0,0",
        value_parser = head_bias_cm
    )]
    head_bias_cm: [f64; 3],
    /// Width of the driver view, the frontal image and the display, pixels in [1, 16384].
    #[arg(long, default_value_t = 1280, value_parser = pixels)]
    width: u32,
    /// Print JSON.
    #[arg(long)]
    json: bool,
    /// Worker threads in [1, 1024] (default: all cores).
    #[arg(long, value_parser = threads)]
    threads: Option<usize>,
    #[command(flatten)]
    memory: MemoryLimit,
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
            model_d2: common.model_d2,
            head_bias_cm: common.head_bias_cm,
        };
        check_memory(
            &ratio_estimate(&setup, common.width, &compensation)?,
            common.memory.max_memory,
        )?;
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
