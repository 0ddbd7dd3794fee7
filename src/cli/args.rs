//! Argument groups that several commands share, the value parsers that give every numeric
//! argument its admissible range, and the thread pool commands run on.

use anyhow::{Result, bail};
use seethru::render::settings::MAX_SPP;
use seethru::scene::source::MAX_RESOLUTION;
use seethru::system::memory::DEFAULT_MAX_MEMORY_GIB;
use seethru::system::options::MAX_HEAD_BIAS_CM;
use seethru::util::number::short;

/// Most worker threads a command accepts.
pub const MAX_THREADS: u64 = 1024;

/// A finite real number in `[min, max]` (NaN and infinities refused). As a clap value parser
/// the error reads `invalid value 'X' for '--flag': must be a number in [min, max]`.
pub fn real(min: f64, max: f64) -> impl Fn(&str) -> Result<f64, String> + Clone + Send + Sync {
    move |text| match text.trim().parse::<f64>() {
        Ok(v) if v.is_finite() && (min..=max).contains(&v) => Ok(v),
        _ => Err(format!(
            "must be a number in [{}, {}]",
            short(min),
            short(max)
        )),
    }
}

/// Smallest value of a positive quantity (sizes, distances, rates, angles, durations), as in
/// scene files: a micrometre, a microsecond. Values like 1e-300 pass `> 0` and then make
/// the geometry degenerate (a panic inside the BVH build, found by an audit), or print as
/// 300-digit numbers.
pub const MIN_POSITIVE: f64 = 1e-6;

/// A finite real number in `[1e-6, max]`: sizes, distances, widths, rates.
pub fn positive(max: f64) -> impl Fn(&str) -> Result<f64, String> + Clone + Send + Sync {
    real(MIN_POSITIVE, max)
}

/// A working distance: `inf` (d2 → ∞) or metres in [1e-6, 1e6].
pub fn metres_or_inf(text: &str) -> Result<f64, String> {
    match text.trim() {
        "inf" | "infinity" => Ok(f64::INFINITY),
        _ => positive(1e6)(text).map_err(|e| format!("{e} or `inf`")),
    }
}

/// An integer in `[min, max]` of any unsigned type (no wrapping: `4000000000` is refused, not
/// read modulo 2³²).
pub fn integer<T: TryFrom<u64>>(
    min: u64,
    max: u64,
) -> impl Fn(&str) -> Result<T, String> + Clone + Send + Sync {
    move |text| {
        text.trim()
            .parse::<u64>()
            .ok()
            .filter(|v| (min..=max).contains(v))
            .and_then(|v| T::try_from(v).ok())
            .ok_or_else(|| format!("must be an integer in [{min}, {max}]"))
    }
}

/// An image side in pixels, `[1, MAX_RESOLUTION]`.
pub fn pixels(text: &str) -> Result<u32, String> {
    integer(1, MAX_RESOLUTION as u64)(text)
}

/// Samples per pixel, `[1, MAX_SPP]`.
pub fn samples(text: &str) -> Result<u32, String> {
    integer(1, MAX_SPP as u64)(text)
}

/// Worker threads, `[1, MAX_THREADS]`.
pub fn threads(text: &str) -> Result<usize, String> {
    integer(1, MAX_THREADS)(text)
}

/// Width of the border band of the mismatch metrics, display pixels, `[1, 1000]`.
pub fn band(text: &str) -> Result<u32, String> {
    integer(1, 1000)(text)
}

/// A head bias `x,y,z` in centimetres, each in `[−MAX_HEAD_BIAS_CM, MAX_HEAD_BIAS_CM]`
/// (`1,0,0`; a leading minus is fine: `-1,0,0`).
pub fn head_bias_cm(text: &str) -> Result<[f64; 3], String> {
    let parts: Vec<&str> = text.split(',').collect();
    let axis = real(-MAX_HEAD_BIAS_CM, MAX_HEAD_BIAS_CM);
    match parts.as_slice() {
        [x, y, z] => Ok([axis(x)?, axis(y)?, axis(z)?]),
        _ => Err(format!(
            "must be x,y,z: three numbers in [{}, {MAX_HEAD_BIAS_CM}] cm separated by commas",
            -MAX_HEAD_BIAS_CM
        )),
    }
}

/// `--max-memory` of a command that renders without the option table (`ratio`, `bench`,
/// `reproduce`).
#[derive(clap::Args, Clone, Copy, Debug)]
pub struct MemoryLimit {
    /// Refuse to start when the estimated memory exceeds this, GiB in [1e-6, 4096].
    #[arg(long = "max-memory", value_name = "GIB", default_value_t = DEFAULT_MAX_MEMORY_GIB, value_parser = max_memory)]
    pub max_memory: f64,
}

/// `--max-memory`, GiB in [1e-6, 4096].
pub fn max_memory(text: &str) -> Result<f64, String> {
    positive(4096.0)(text)
}

/// Runs `job` on a pool of `threads` workers (all cores if `None`). Images do not depend on it.
pub fn with_threads<T: Send>(threads: Option<usize>, job: impl FnOnce() -> T + Send) -> Result<T> {
    if let Some(n) = threads
        && !(1..=MAX_THREADS as usize).contains(&n)
    {
        bail!("--threads {n} is out of range [1, {MAX_THREADS}]");
    }
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads.unwrap_or(0))
        .build()?;
    Ok(pool.install(job))
}

/// A value from a fixed list (a clap `ValueEnum`), with spaces around it ignored as they are
/// around numbers: `--eyes ' both'` is `both`, and in a list (`value_delimiter = ','`) each
/// item is trimmed, `--methods 'planar-inf, ground'`. Every choice flag uses this parser,
/// so the rule holds everywhere; the possible values are clap's, for `--help` and errors.
#[derive(Clone)]
pub struct Choice<T>(std::marker::PhantomData<T>);

/// The value parser of a choice flag of type `T`: `value_parser = choice::<T>()`.
pub fn choice<T>() -> Choice<T> {
    Choice(std::marker::PhantomData)
}

impl<T: clap::ValueEnum + Clone + Send + Sync + 'static> clap::builder::TypedValueParser
    for Choice<T>
{
    type Value = T;

    fn parse_ref(
        &self,
        cmd: &clap::Command,
        arg: Option<&clap::Arg>,
        value: &std::ffi::OsStr,
    ) -> Result<T, clap::Error> {
        let trimmed = value
            .to_str()
            .map_or(value, |v| std::ffi::OsStr::new(v.trim()));
        clap::builder::EnumValueParser::<T>::new().parse_ref(cmd, arg, trimmed)
    }

    fn possible_values(
        &self,
    ) -> Option<Box<dyn Iterator<Item = clap::builder::PossibleValue> + '_>> {
        Some(Box::new(
            T::value_variants()
                .iter()
                .filter_map(clap::ValueEnum::to_possible_value),
        ))
    }
}

/// A flag read only under some of the other settings, for [`refuse_ignored`]; the rules are
/// the library's, shared with the Python package.
pub use seethru::system::reads::ReadWhen;

/// Refuses a flag given on the command line that the command would ignore under the other
/// settings given: the user's intent is not dropped without a word. One rule per flag that
/// is read only sometimes; the flags given are the parser's ([`crate::cli::given`]), so a
/// flag set to its default value is refused too.
pub fn refuse_ignored(rules: &[ReadWhen]) -> Result<()> {
    let given = |option: &str| crate::cli::given::given(&seethru::system::reads::flag_of(option));
    if let Some(rule) = seethru::system::reads::first_ignored(rules, given) {
        bail!("{}", rule.flag_refusal());
    }
    Ok(())
}
