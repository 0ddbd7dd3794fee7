//! `seethru spec`: the run specification that `seethru run`, `capture`, `compare`,
//! `sequence` or `render` would make of these options, as JSON, after every check of them:
//! nothing is loaded or rendered. `seethru.spec` in Python returns the same, so a script can
//! check its options first.

use anyhow::Result;

use crate::cli::option_args::{self, OptionArgs};

#[derive(clap::Subcommand)]
pub enum Spec {
    /// `seethru run`'s options (less the scene, the output folder, the EXRs, the heatmap's
    /// scale and the threads).
    #[command(allow_negative_numbers = true)]
    Run(OptionArgs<option_args::Run>),
    /// `seethru capture`'s options.
    #[command(allow_negative_numbers = true)]
    Capture(OptionArgs<option_args::Capture>),
    /// `seethru compare`'s options (less `--methods`, whose rules on the others it does not
    /// apply).
    Compare(OptionArgs<option_args::Compare>),
    /// The options `seethru sequence` shares with a run, with its defaults (less its own:
    /// the timeline, the motions, the head's source; and less the rules that read those).
    #[command(allow_negative_numbers = true)]
    Sequence(OptionArgs<option_args::Sequence>),
    /// `seethru render`'s size, samples and memory bound.
    Render(OptionArgs<option_args::Render>),
}

impl Spec {
    pub fn run(self) -> Result<()> {
        let spec = match self {
            Spec::Run(options) => options.spec()?,
            Spec::Capture(options) => options.spec()?,
            Spec::Compare(options) => options.spec()?,
            Spec::Sequence(options) => options.spec()?,
            Spec::Render(options) => options.spec()?,
        };
        println!("{}", serde_json::to_string_pretty(&spec.to_json())?);
        Ok(())
    }
}
