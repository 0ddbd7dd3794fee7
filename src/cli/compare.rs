//! `seethru compare`: compensation methods side by side on one scene — one table (Markdown,
//! JSON, HTML) and one image strip per method.

use crate::cli::load_scene;
use crate::cli::with_flags;
use std::path::{Path, PathBuf};

use anyhow::Result;
use seethru::io::atomic::write_text;
use seethru::io::frame_files::write_png;
use seethru::io::output_paths::{Input, Output, check_paths};
use seethru::io::staged::StagedDir;
use seethru::measure::compare::{
    Candidate, coloured_strips, compare_reads, html_page, markdown_table,
};
use seethru::measure::run_spec::RunSpec;
use seethru::render::integrator::RenderContext;
use seethru::system::memory::{check_memory, run_estimate};
use seethru::system::options::RunOptions;
use seethru::system::reads::hazard_bound_reads;

use crate::cli::args::{refuse_ignored, threads, with_threads};
use crate::cli::option_args::{self, OptionArgs};

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
    /// The run's options: the option table's (`seethru::measure::option_table`).
    #[command(flatten)]
    options: OptionArgs<option_args::Compare>,
    /// Worker threads in [1, 1024] (default: all cores). Images are identical for any value.
    #[arg(long, value_parser = threads)]
    threads: Option<usize>,
}

impl Compare {
    pub fn run(self) -> Result<()> {
        check_paths(
            &[Input::file("SCENE", &self.scene)],
            &[Output::folder("--out", &self.out)],
        )?;
        let spec = self.options.spec()?;
        let base = RunOptions {
            progress: true,
            ..spec.options
        };
        self.refuse_ignored(&base)?;
        with_threads(self.threads, || self.write(&spec, &base))?
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

    fn write(&self, spec: &RunSpec, base: &RunOptions) -> Result<()> {
        let (band, hazard_bound_arcmin) = (spec.measure.band, spec.measure.hazard_bound_arcmin);
        let scene = load_scene(&self.scene)?;
        refuse_ignored(&[hazard_bound_reads(&scene)])?;
        check_memory(&run_estimate(&scene, base)?, spec.max_memory_gib)?;
        let ctx = RenderContext::new(scene)?;
        let rows = crate::cli::compare_methods::compare_all(
            &ctx,
            &self.methods,
            base,
            band,
            hazard_bound_arcmin,
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
                hazard_bound_arcmin
            ),
            false => String::new(),
        };
        let title = format!("Compensation methods compared on {}", self.scene.display());
        let md = format!(
            "# {title}\n\nMisregistration in arc-minutes at the true eye over the display (mean, p95, and the border band of {} display pixels); coverage: fraction of display pixels that show the scene; holes: disocclusions of the depth methods (fill: {:?}); ms/frame: the method's own work (sensor, fit or search, resampling); not run because: why a method cannot run on this scene (its row is otherwise empty).{hazards}\n\n{table}\n{}",
            band,
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
            &serde_json::to_string_pretty(&with_flags(&json))?,
        )?;
        seethru::measure::viewer::write_compare_view(out)?;
        staged.commit()?;
        seethru::util::progress::summary(format!(
            "compared {} methods; compare.md, compare.json, compare.html, the strips and view.html in {}",
            rows.len(),
            self.out.display()
        ));
        if !seethru::util::progress::is_quiet() {
            print!("{table}");
        }
        Ok(())
    }
}
