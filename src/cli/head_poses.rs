//! `seethru head-poses`: the head tracker against the true eye over a grid of head poses
//! (yaw, pitch, distance), the error distribution of the frontal equations and of the yaw
//! fit as one Markdown table on stdout, and the fit's time per frame on stderr.

use crate::cli::load_scene;
use std::path::PathBuf;

use anyhow::Result;
use seethru::io::output_paths::{Input, check_paths};
use seethru::measure::head_poses::{fit_time_line, pose_grid, pose_table};
use seethru::system::head_pose::prepare_fit;

use crate::cli::args::{pixels, real, threads, with_threads};

#[derive(clap::Args)]
#[command(allow_negative_numbers = true)]
pub struct HeadPoses {
    /// Scene file (TOML) with a head (objects with moves_with = "head") and a back camera.
    scene: PathBuf,
    /// Head yaws about the neck from facing the back camera, degrees in [-89, 89],
    /// comma-separated (0: the face turned towards the camera; positive: turned further to the
    /// driver's left).
    #[arg(long, value_delimiter = ',', value_parser = real(-89.0, 89.0), default_value = "-45,-30,-15,0,15,30,45")]
    yaw: Vec<f64>,
    /// Head pitches about the neck, degrees in [-45, 45], comma-separated (positive: up).
    #[arg(long, value_delimiter = ',', value_parser = real(-45.0, 45.0), default_value = "-10,0,10")]
    pitch: Vec<f64>,
    /// Distances of the eye from the back camera, as multiples in [0.5, 2] of the scene's,
    /// comma-separated.
    #[arg(long = "distance-scale", value_delimiter = ',', value_parser = real(0.5, 2.0), default_value = "0.8,1,1.25")]
    distance_scale: Vec<f64>,
    /// Back camera width, pixels in [1, 16384] (aspect ratio kept; default: the scene's).
    #[arg(long = "back-width", value_parser = pixels)]
    back_width: Option<u32>,
    /// Worker threads in [1, 1024] (default: all cores).
    #[arg(long, value_parser = threads)]
    threads: Option<usize>,
}

impl HeadPoses {
    pub fn run(self) -> Result<()> {
        check_paths(&[Input::file("SCENE", &self.scene)], &[])?;
        let scene = load_scene(&self.scene)?;
        let started = std::time::Instant::now();
        prepare_fit();
        let setup_s = started.elapsed().as_secs_f64();
        let results = with_threads(self.threads, || {
            pose_grid(
                &scene,
                &self.yaw,
                &self.pitch,
                &self.distance_scale,
                self.back_width,
            )
        })??;
        print!("{}", pose_table(&results));
        if let Some(line) = fit_time_line(&results, setup_s) {
            seethru::util::progress::summary(line);
        }
        Ok(())
    }
}
