//! `seethru compare`: compensation methods side by side on one scene — one table (Markdown,
//! JSON, HTML) and one image strip per method.

use std::path::{Path, PathBuf};

use anyhow::Result;
use seethru::io::atomic::write_text;
use seethru::io::frame_files::write_png;
use seethru::io::output_paths::{Input, Output, check_paths};
use seethru::io::staged::StagedDir;
use seethru::measure::compare::{
    Candidate, coloured_strips, compare_reads, html_page, markdown_table,
};
use seethru::measure::hazard::HAZARD_BOUND_ARCMIN;
use seethru::render::integrator::RenderContext;
use seethru::scene::Scene;
use seethru::system::memory::{check_memory, run_estimate};
use seethru::system::options::{HeadSource, Outside, RunOptions};

use crate::cli::args::{
    ReadWhen, RenderArgs, band, choice, integer, pixels, positive, refuse_ignored, with_threads,
};
use crate::cli::scene_model_args::SceneModelArgs;

#[derive(clap::Args)]
pub struct Compare {
    /// Scene file (TOML).
    scene: PathBuf,
    /// Methods, comma-separated, in the table's order: none, planar-inf, planar-auto,
    /// plane-fit, ground, depth-ideal, depth-tof, depth-stereo, or map:NAME=FILE (your
    /// method's display map for the capture of these settings, see `seethru score`).
    #[arg(
        long,
        value_name = "METHOD",
        value_delimiter = ',',
        value_parser = crate::cli::compare_methods::method_spec,
        default_value = "planar-inf,planar-auto,plane-fit,ground,depth-ideal,depth-tof"
    )]
    methods: Vec<crate::cli::compare_methods::MethodSpec>,
    /// Output directory: compare.md, compare.json, compare.html and strip_<method>.png.
    #[arg(long, default_value = "compare")]
    out: PathBuf,
    /// oracle: the true eye; estimated: face detection on the back camera's image.
    #[arg(long, value_enum, value_parser = choice::<HeadSource>(), default_value_t = HeadSource::Oracle)]
    head: HeadSource,
    /// Seed of the depth noise and the plane fit, an integer in [0, 4294967295].
    #[arg(long, default_value_t = 1, value_parser = integer::<u32>(0, u32::MAX as u64))]
    seed: u32,
    /// Frontal camera width, pixels in [1, 16384] (aspect ratio kept; default: the scene's).
    #[arg(long = "frontal-width", value_parser = pixels)]
    frontal_width: Option<u32>,
    /// Back camera width, pixels in [1, 16384] (aspect ratio kept; default: the scene's).
    #[arg(long = "back-width", value_parser = pixels)]
    back_width: Option<u32>,
    /// Width of the border band of the mismatch metrics, display pixels in [1, 1000].
    #[arg(long, default_value_t = 5, value_parser = band)]
    band: u32,
    /// Hazard visibility: a hidden hazard pixel counts as shown when the display shows the
    /// same object within this misregistration, arc-minutes in [1e-6, 10800] (a scene with
    /// an object marked `hazard = true` only).
    #[arg(long = "hazard-bound-arcmin", default_value_t = HAZARD_BOUND_ARCMIN, value_parser = positive(10800.0))]
    hazard_bound_arcmin: f64,
    /// The depth sensor (its kind is the method's for depth-tof and depth-stereo) and fill.
    #[command(flatten)]
    scene_model: SceneModelArgs,
    /// Sizes of the driver views, samples, threads.
    #[command(flatten)]
    render: RenderArgs,
}

impl Compare {
    pub fn run(self) -> Result<()> {
        check_paths(
            &[Input::file("SCENE", &self.scene)],
            &[Output::folder("--out", &self.out)],
        )?;
        let base = RunOptions {
            head: self.head,
            seed: self.seed,
            width: self.render.width,
            height: self.render.height,
            frontal_width: self.frontal_width,
            back_width: self.back_width,
            spp: self.render.spp,
            // A crop past the frontal view is shown black and counted, not an error: every
            // method gets its row.
            outside: Outside::Black,
            scene_model: self.scene_model.options(),
            progress: true,
            ..RunOptions::default()
        };
        self.refuse_ignored(&base)?;
        with_threads(self.render.threads, || self.write(&base))?
    }

    /// Refuses the flags no listed method would read ([`refuse_ignored`]).
    fn refuse_ignored(&self, base: &RunOptions) -> Result<()> {
        use crate::cli::compare_methods::MethodSpec;
        let candidates: Vec<Candidate> = self
            .methods
            .iter()
            .filter_map(|m| match m {
                MethodSpec::Builtin(c) => Some(*c),
                MethodSpec::Map { .. } => None,
            })
            .collect();
        let maps = candidates.len() < self.methods.len();
        refuse_ignored(&compare_reads(&candidates, maps, base))
    }

    fn write(&self, base: &RunOptions) -> Result<()> {
        let scene = Scene::load(&self.scene)?;
        refuse_ignored(&[ReadWhen {
            flag: "--hazard-bound-arcmin",
            read: scene.objects.iter().any(|o| o.hazard),
            when: "for a scene with an object marked `hazard = true`",
        }])?;
        check_memory(&run_estimate(&scene, base)?, self.render.max_memory)?;
        let ctx = RenderContext::new(scene)?;
        let rows = crate::cli::compare_methods::compare_all(
            &ctx,
            &self.methods,
            base,
            self.band,
            self.hazard_bound_arcmin,
        )?;
        // Written whole or not at all: a failure leaves `--out` as it was.
        let staged = StagedDir::new(&self.out)?;
        let out: &Path = staged.path();
        let mut strips = Vec::new();
        for (r, strip) in rows.iter().zip(coloured_strips(&rows)?) {
            // A method that did not run has no strip; its row says why.
            let Some((w, h, rgb)) = strip else {
                continue;
            };
            let file = format!("strip_{}.png", r.name);
            write_png(&out.join(&file), w, h, rgb)?;
            strips.push((r.name.as_str(), file));
        }
        let table = markdown_table(&rows);
        let hazards = match ctx.scene.objects.iter().any(|o| o.hazard) {
            true => format!(
                " Per `hazard = true` object: visibility, the fraction of its pixels hidden by the pillar that the display shows as that object within {}′ (— when none is hidden), and the centroid error ′ of what the display shows of it.",
                self.hazard_bound_arcmin
            ),
            false => String::new(),
        };
        let title = format!("Compensation methods compared on {}", self.scene.display());
        let md = format!(
            "# {title}\n\nMisregistration in arc-minutes at the true eye over the display (mean, p95, and the border band of {} display pixels); coverage: fraction of display pixels that show the scene; holes: disocclusions of the depth methods (fill: {:?}); ms/frame: the method's own work (sensor, fit or search, resampling); not run because: why a method cannot run on this scene (its row is otherwise empty).{hazards}\n\n{table}\n{}",
            self.band,
            base.scene_model.fill,
            strips
                .iter()
                .map(|(name, file)| format!("## {name}\n\n![{name}]({file})\n\n"))
                .collect::<String>()
        );
        write_text(&out.join("compare.md"), &md)?;
        write_text(
            &out.join("compare.html"),
            &html_page(&title, &table, &strips),
        )?;
        let json = serde_json::json!({
            "scene": self.scene.display().to_string(),
            "rows": rows.iter().map(|r| r.row.clone()).collect::<Vec<_>>(),
        });
        write_text(
            &out.join("compare.json"),
            &serde_json::to_string_pretty(&json)?,
        )?;
        staged.commit()?;
        seethru::util::progress::summary(format!(
            "compared {} methods; compare.md, compare.json, compare.html and the strips in {}",
            rows.len(),
            self.out.display()
        ));
        if !seethru::util::progress::is_quiet() {
            print!("{table}");
        }
        Ok(())
    }
}
