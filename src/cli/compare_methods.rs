//! `compare --methods`: the built-in methods by name and outside maps as `map:NAME=FILE`,
//! run in the order given.

use std::path::PathBuf;

use anyhow::Result;
use clap::ValueEnum;
use seethru::measure::compare::{Candidate, Compared, compare};
use seethru::measure::compare_external::compare_maps;
use seethru::render::integrator::RenderContext;
use seethru::system::options::RunOptions;

/// One entry of `--methods`.
#[derive(Clone, Debug)]
pub enum MethodSpec {
    Builtin(Candidate),
    /// `map:NAME=FILE`.
    Map {
        name: String,
        file: PathBuf,
    },
}

/// Parses one `--methods` entry.
pub fn method_spec(text: &str) -> Result<MethodSpec, String> {
    let text = text.trim();
    if let Some(rest) = text.strip_prefix("map:") {
        let (name, file) = rest.split_once('=').ok_or_else(|| {
            format!("`{text}`: an outside method is map:NAME=FILE (e.g. map:mine=mine.npy)")
        })?;
        let valid = |c: char| c.is_ascii_alphanumeric() || c == '-' || c == '_';
        if name.is_empty() || name.len() > 40 || !name.chars().all(valid) {
            return Err(format!(
                "`{text}`: the name `{name}` must be 1 to 40 letters, digits, - or _"
            ));
        }
        if file.is_empty() {
            return Err(format!("`{text}`: no FILE after `=`"));
        }
        return Ok(MethodSpec::Map {
            name: name.to_string(),
            file: PathBuf::from(file),
        });
    }
    Candidate::from_str(text, false)
        .map(MethodSpec::Builtin)
        .map_err(|_| {
            let names: Vec<&str> = Candidate::value_variants()
                .iter()
                .map(|c| c.name())
                .collect();
            format!("`{text}`: one of {} or map:NAME=FILE", names.join(", "))
        })
}

/// Every method's row, in the order of `specs`; the maps are read (and refused) before
/// anything is rendered.
pub fn compare_all(
    ctx: &RenderContext,
    specs: &[MethodSpec],
    base: &RunOptions,
    band: u32,
    hazard_bound_arcmin: f64,
) -> Result<Vec<Compared>> {
    let builtins: Vec<Candidate> = specs
        .iter()
        .filter_map(|s| match s {
            MethodSpec::Builtin(c) => Some(*c),
            _ => None,
        })
        .collect();
    let mut maps = Vec::new();
    for spec in specs {
        if let MethodSpec::Map { name, file } = spec {
            if maps.iter().any(|(n, _)| n == name) {
                anyhow::bail!("--methods: map:{name} is given twice");
            }
            maps.push((name.clone(), crate::cli::score::load_map(file)?));
        }
    }
    let mut built = compare(ctx, &builtins, base, band, hazard_bound_arcmin)?.into_iter();
    let mut external = compare_maps(ctx, &maps, base, band, hazard_bound_arcmin)?.into_iter();
    Ok(specs
        .iter()
        .filter_map(|s| match s {
            MethodSpec::Builtin(_) => built.next(),
            MethodSpec::Map { .. } => external.next(),
        })
        .collect())
}
