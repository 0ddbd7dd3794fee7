//! Command line: parses arguments and dispatches to the library.
#![forbid(unsafe_code)]

use std::path::PathBuf;
use std::process::ExitCode;

use clap::{Parser, Subcommand};
use seethru::accel::BvhKind;
use seethru::analysis::{ForeshorteningParams, OcclusionParams};
use seethru::bench::{BenchOptions, bench};
use seethru::claims::{AnalyzeParams, claims_table, evaluate, paper_claims};
use seethru::commands::{RenderOptions, export_scene, render_views};
use seethru::display::{DisplayModel, Filter};
use seethru::options::{check_resolution, with_threads};
use seethru::pipeline::{
    HeadSource, Method, Outside, RunOptions, WorkingDistance, measure_command, run_command,
};
use seethru::ratio::{Setup, describe, measure_ratio};
use seethru::sweep::{SweepOptions, parse_param, sweep};
use seethru::views::View;

#[derive(Parser)]
#[command(
    name = "seethru",
    version,
    about = "Simulates video see-through displays for driver assistance and measures how well they work"
)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Render views of a scene: colour PNG, id PNG and an EXR with every AOV per view.
    Render {
        /// Scene file (TOML).
        scene: PathBuf,
        /// View to render; repeat for several. Default: all four.
        #[arg(long = "view", value_enum)]
        views: Vec<View>,
        /// Output directory.
        #[arg(long)]
        out: PathBuf,
        #[command(flatten)]
        render: RenderArgs,
    },
    /// Run the see-through system: truth, occluded, frontal, back, display and seethru views,
    /// each as PNG, ids PNG and EXR, and run.json with every parameter and the crop.
    Run {
        scene: PathBuf,
        #[arg(long)]
        out: PathBuf,
        /// none: the whole frontal image in the display; planar: the paper's compensation.
        #[arg(long, value_enum, default_value_t = Method::Planar)]
        method: Method,
        /// Working distance of the planar model: inf, auto (median frontal depth behind the
        /// display) or metres.
        #[arg(long, default_value = "inf")]
        d2: WorkingDistance,
        /// oracle: the true eye; estimated: face detection on the back camera's image.
        #[arg(long, value_enum, default_value_t = HeadSource::Oracle)]
        head: HeadSource,
        /// Head-tracking bias, obstacle frame, centimetres: x,y,z.
        #[arg(long = "head-bias-cm", value_delimiter = ',', num_args = 3, allow_hyphen_values = true, default_values_t = [0.0, 0.0, 0.0])]
        head_bias_cm: Vec<f64>,
        /// Head-tracking jitter, standard deviation per axis, centimetres.
        #[arg(long = "head-jitter-cm", default_value_t = 0.0)]
        head_jitter_cm: f64,
        /// Seed of the jitter.
        #[arg(long, default_value_t = 1)]
        seed: u32,
        /// The detector's known feature width A (interpupillary distance), metres.
        #[arg(long = "feature-width", default_value_t = 0.064)]
        feature_width: f64,
        /// When the crop leaves the frontal view: error, or black (flagged as missing).
        #[arg(long, value_enum, default_value_t = Outside::Error)]
        outside: Outside,
        /// Colour resampling of the display image.
        #[arg(long, value_enum, default_value_t = Filter::Bilinear)]
        filter: Filter,
        /// pixels: the physical display; ideal: unlimited display and frontal resolution, so
        /// that only the planar model's error remains.
        #[arg(long, value_enum, default_value_t = DisplayModel::Pixels)]
        display: DisplayModel,
        /// Frontal camera width in pixels (aspect ratio kept).
        #[arg(long = "frontal-width")]
        frontal_width: Option<u32>,
        /// Back camera width in pixels (aspect ratio kept).
        #[arg(long = "back-width")]
        back_width: Option<u32>,
        /// Width of the border band of the mismatch metrics, display pixels.
        #[arg(long, default_value_t = 5)]
        band: u32,
        /// Sizes (width and height: the driver views truth, occluded, seethru), samples, threads.
        #[command(flatten)]
        render: RenderArgs,
    },
    /// Observed p_cam/p_user of the paper's occlusion or foreshortening setup: predicted,
    /// observed and the uncertainty pixel quantisation leaves.
    Ratio {
        #[command(subcommand)]
        setup: RatioSetup,
    },
    /// Reproduce the paper's §5: report.md, a self-contained report.html and report.json.
    Reproduce {
        #[arg(long)]
        out: PathBuf,
        /// Small renders (CI-sized).
        #[arg(long)]
        quick: bool,
        /// The driver-assistance scene.
        #[arg(long, default_value = "scenes/das.toml")]
        scene: PathBuf,
        #[arg(long)]
        threads: Option<usize>,
    },
    /// Metrics for every combination of parameter values, as CSV and a plot; resumable.
    /// Parameters: theta_f, d2, display_width, eye_x, eye_z, head_bias_x_cm, frontal_width.
    Sweep {
        scene: PathBuf,
        /// name=start:stop:step or name=v1,v2,... (repeat for a grid).
        #[arg(long = "param", required = true)]
        params: Vec<String>,
        #[arg(long, default_value = "sweep.csv")]
        out: PathBuf,
        /// Driver-view width in pixels.
        #[arg(long, default_value_t = 320)]
        width: u32,
        #[arg(long, default_value_t = 1)]
        spp: u32,
        #[arg(long, value_enum, default_value_t = HeadSource::Oracle)]
        head: HeadSource,
        #[arg(long, default_value_t = 5)]
        band: u32,
        #[arg(long)]
        threads: Option<usize>,
    },
    /// Recompute metrics.json and the misregistration maps of a `run` directory from its EXRs.
    Measure {
        dir: PathBuf,
        #[arg(long, default_value_t = 5)]
        band: u32,
        #[arg(long, value_enum, default_value_t = BvhKind::Cwbvh)]
        bvh: BvhKind,
    },
    /// Write the scene's triangles (.obj or .glb) and its cameras (<name>.cameras.json).
    Export {
        scene: PathBuf,
        /// Output file, .obj or .glb.
        #[arg(long)]
        out: PathBuf,
    },
    /// Regenerate the paper's Fig. 3–5 and the physical-unit sensitivity figure (PNG + CSV).
    Figures {
        #[arg(long)]
        out: PathBuf,
    },
    /// The paper's numerical claims beside seethru's values; every closed form at a parameter set.
    Analyze {
        /// Print JSON instead of tables.
        #[arg(long)]
        json: bool,
        /// Eye distance from the display d1 [m].
        #[arg(long, default_value_t = 1.0)]
        d1: f64,
        /// Working distance d2 [m] (use inf for the d2 → ∞ model).
        #[arg(long, default_value_t = 1.0)]
        d2: f64,
        /// Lateral eye offset b_h [m] (> 0: the eye on the side of the left crop R1).
        #[arg(long = "bh", default_value_t = 0.125, allow_hyphen_values = true)]
        b_h: f64,
        /// Display width D [m].
        #[arg(long, default_value_t = 0.5)]
        width: f64,
        /// Frontal half angle θ_F [degrees].
        #[arg(long = "theta-f", default_value_t = 80.0)]
        theta_f: f64,
        /// Frontal image width [pixels].
        #[arg(long = "frontal-px", default_value_t = 1280)]
        frontal_px: u32,
        /// Occluder depth L [m].
        #[arg(long = "L", default_value_t = 1.0)]
        occluder_depth: f64,
        /// Lateral position of the object's corner b1 [m].
        #[arg(long, default_value_t = 0.25, allow_hyphen_values = true)]
        b1: f64,
        /// Length of the angled surface l [m].
        #[arg(long = "l", default_value_t = 1.0)]
        surface_length: f64,
        /// Angle of the surface γ [degrees].
        #[arg(long, default_value_t = 45.0, allow_hyphen_values = true)]
        gamma: f64,
        /// Tolerance of the d2_min bound, as a fraction of R(∞).
        #[arg(long, default_value_t = 0.05)]
        tolerance: f64,
    },
    /// Benchmark: BVH build time, rays per second, frame times; ends with one JSON line.
    Bench {
        scene: PathBuf,
        #[arg(long, default_value_t = 1280)]
        width: u32,
        #[arg(long, default_value_t = 720)]
        height: u32,
        /// Renders per view; the fastest counts.
        #[arg(long, default_value_t = 3)]
        repeat: usize,
        #[arg(long)]
        threads: Option<usize>,
        #[arg(long, value_enum, default_value_t = BvhKind::Cwbvh)]
        bvh: BvhKind,
    },
}

/// Image size, samples, threads and hierarchy: shared by `render` and `run`.
#[derive(clap::Args)]
struct RenderArgs {
    /// Image width in pixels (default: the camera's; height follows the aspect ratio if not given).
    #[arg(long)]
    width: Option<u32>,
    /// Image height in pixels.
    #[arg(long)]
    height: Option<u32>,
    /// Samples per pixel (anti-aliasing of the colour; AOVs are at pixel centres).
    #[arg(long, default_value_t = 4)]
    spp: u32,
    /// Worker threads (default: all cores). Images are identical for any value.
    #[arg(long)]
    threads: Option<usize>,
    #[arg(long, value_enum, default_value_t = BvhKind::Cwbvh)]
    bvh: BvhKind,
}

#[derive(Subcommand)]
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
    /// Width of the driver view, the frontal image and the display, pixels.
    #[arg(long, default_value_t = 1280)]
    width: u32,
    /// Print JSON.
    #[arg(long)]
    json: bool,
    #[arg(long)]
    threads: Option<usize>,
}

fn run(cli: Cli) -> anyhow::Result<()> {
    match cli.command {
        Command::Render {
            scene,
            views,
            out,
            render:
                RenderArgs {
                    width,
                    height,
                    spp,
                    threads,
                    bvh,
                },
        } => {
            let views = if views.is_empty() {
                View::ALL.to_vec()
            } else {
                views
            };
            let options = RenderOptions {
                width,
                height,
                spp,
                bvh,
                progress: true,
            };
            with_threads(threads, || render_views(&scene, &views, &out, &options))?
        }
        Command::Export { scene, out } => export_scene(&scene, &out),
        Command::Ratio { setup } => {
            let (setup, common) = match setup {
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
            let result = with_threads(common.threads, || measure_ratio(&setup, common.width))??;
            if common.json {
                println!("{}", serde_json::to_string_pretty(&result)?);
            } else {
                print!("{}", describe(&result));
            }
            Ok(())
        }
        Command::Reproduce {
            out,
            quick,
            scene,
            threads,
        } => {
            with_threads(threads, || {
                seethru::reproduce::reproduce(&scene, &out, quick)
            })??;
            eprintln!(
                "wrote report.md, report.html and report.json to {}",
                out.display()
            );
            Ok(())
        }
        Command::Sweep {
            scene,
            params,
            out,
            width,
            spp,
            head,
            band,
            threads,
        } => {
            let params = params
                .iter()
                .map(|p| parse_param(p))
                .collect::<anyhow::Result<Vec<_>>>()?;
            let options = SweepOptions {
                width,
                spp,
                head,
                band,
            };
            let computed = with_threads(threads, || sweep(&scene, &params, &out, &options))??;
            eprintln!(
                "computed {computed} configurations; results in {}",
                out.display()
            );
            Ok(())
        }
        Command::Measure { dir, band, bvh } => {
            let metrics = measure_command(&dir, band, bvh)?;
            println!("{}", serde_json::to_string_pretty(&metrics)?);
            Ok(())
        }
        Command::Run {
            scene,
            out,
            method,
            d2,
            head,
            head_bias_cm,
            head_jitter_cm,
            seed,
            feature_width,
            outside,
            filter,
            display,
            frontal_width,
            back_width,
            band,
            render:
                RenderArgs {
                    width,
                    height,
                    spp,
                    threads,
                    bvh,
                },
        } => {
            let options = RunOptions {
                method,
                d2,
                head,
                head_bias_cm: [head_bias_cm[0], head_bias_cm[1], head_bias_cm[2]],
                head_jitter_cm,
                seed,
                feature_width,
                width,
                height,
                frontal_width,
                back_width,
                spp,
                outside,
                filter,
                display,
                progress: true,
            };
            with_threads(threads, || run_command(&scene, &out, &options, band, bvh))?
        }
        Command::Figures { out } => {
            let names = seethru::figures::write_all(&out)?;
            eprintln!(
                "wrote {} figures (PNG + CSV) to {}",
                names.len(),
                out.display()
            );
            Ok(())
        }
        Command::Analyze {
            json,
            d1,
            d2,
            b_h,
            width,
            theta_f,
            frontal_px,
            occluder_depth,
            b1,
            surface_length,
            gamma,
            tolerance,
        } => {
            let params = AnalyzeParams {
                d1,
                d2,
                b_h,
                width,
                theta_f_deg: theta_f,
                frontal_px,
                occluder_depth,
                b1,
                surface_length,
                gamma_deg: gamma,
                tolerance,
            };
            params.validate().map_err(anyhow::Error::msg)?;
            let claims = paper_claims();
            let values = evaluate(&params);
            if json {
                println!(
                    "{}",
                    serde_json::to_string_pretty(
                        &serde_json::json!({"claims": claims, "evaluation": values})
                    )?
                );
            } else {
                print!("{}", claims_table(&claims));
                println!(
                    "\nEvery closed form at the given parameters:\n{}",
                    serde_json::to_string_pretty(&values)?
                );
            }
            Ok(())
        }
        Command::Bench {
            scene,
            width,
            height,
            repeat,
            threads,
            bvh,
        } => {
            check_resolution(width, height)?;
            let options = BenchOptions {
                width,
                height,
                repeat,
                bvh,
            };
            with_threads(threads, || bench(&scene, &options).map(|_| ()))?
        }
    }
}

fn main() -> ExitCode {
    match run(Cli::parse()) {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("error: {e:#}");
            ExitCode::FAILURE
        }
    }
}
