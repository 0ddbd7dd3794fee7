//! Golden-image comparison in the manner of the vello/wgpu tests: the reference PNG lives in
//! `golden/`, a failure writes `actual`, `expected` and `diff` images under
//! `target/golden-failures/`, `SEETHRU_BLESS=NAME[,NAME…]` (or `all`) accepts new images of
//! the goldens named, and a missing golden is a failure, never a silent write.
//!
//! Blessing rewrites only what was asked for: a name that is not one of [`GOLDENS`] (a typo)
//! fails every check with the list of known names, and each image written is named on the
//! test's real stderr, which the test harness does not capture, so a passing run still shows it.

use std::io::Write;
use std::path::{Path, PathBuf};

use image::RgbImage;

use super::repo_path;

/// Tolerances, justified: renders are bit-identical on one machine and toolchain (tested
/// separately), but glibc picks `tanf`/`powf` variants by CPU (FMA or not), which can move a
/// ray by an ulp and flip a pixel on a silhouette to the neighbouring object. So: at most
/// 0.5% of pixels may differ by more than 8/255 in a channel, and the mean absolute
/// difference stays under 0.5/255 — a real regression (a moved object, a shading change)
/// breaks one or the other by an order of magnitude.
const MAX_OUTLIER_FRACTION: f64 = 0.005;
const OUTLIER_LEVEL: u8 = 8;
const MAX_MEAN_ABS: f64 = 0.5;

fn failure_dir() -> PathBuf {
    repo_path("target/golden-failures")
}

/// Every golden image a test checks (`golden/NAME.png`): what `SEETHRU_BLESS` may name.
pub const GOLDENS: [&str; 7] = [
    "truth",
    "occluded",
    "frontal",
    "back",
    "display",
    "seethru",
    "frontal_fisheye",
];

/// The goldens a `SEETHRU_BLESS` value asks to rewrite: `all`, or names of [`GOLDENS`]
/// separated by commas (spaces around a name are ignored). Unset: none. Any other name is
/// an error that lists the known ones.
pub fn blessed(value: Option<&str>) -> Result<Vec<&'static str>, String> {
    let Some(value) = value else {
        return Ok(Vec::new());
    };
    if value.trim() == "all" {
        return Ok(GOLDENS.to_vec());
    }
    value
        .split(',')
        .map(|name| {
            let name = name.trim();
            GOLDENS.iter().copied().find(|g| *g == name).ok_or_else(|| {
                format!(
                    "SEETHRU_BLESS: unknown golden `{name}` (known: {}, or all)",
                    GOLDENS.join(", ")
                )
            })
        })
        .collect()
}

/// The goldens the environment's `SEETHRU_BLESS` asks to rewrite; a bad value fails the test.
fn blessed_by_env() -> Vec<&'static str> {
    let value = std::env::var("SEETHRU_BLESS").ok();
    blessed(value.as_deref()).unwrap_or_else(|e| panic!("{e}"))
}

/// Compares `actual` with `golden/NAME.png`, or rewrites it when `SEETHRU_BLESS` names it.
pub fn check(name: &str, actual: &RgbImage) {
    check_in(&repo_path("golden"), name, actual, &blessed_by_env());
}

/// [`check`] against the goldens in `dir`, rewriting `NAME.png` only when `bless` holds `name`.
pub fn check_in(dir: &Path, name: &str, actual: &RgbImage, bless: &[&str]) {
    assert!(
        GOLDENS.contains(&name),
        "golden `{name}` is not in GOLDENS (tests/common/golden.rs: {})",
        GOLDENS.join(", ")
    );
    let path = dir.join(format!("{name}.png"));
    if bless.contains(&name) {
        actual.save(&path).unwrap();
        // Past the harness's capture of eprintln!, so that a passing run lists what it wrote.
        let _ = writeln!(std::io::stderr(), "blessed {}", path.display());
        return;
    }
    let expected = match image::open(&path) {
        Ok(img) => img.to_rgb8(),
        Err(e) => {
            save_failure(name, actual, None);
            panic!(
                "golden {} missing or unreadable ({e}); inspect target/golden-failures/{name}-actual.png and bless with SEETHRU_BLESS={name}",
                path.display()
            );
        }
    };
    if let Err(why) = compare(actual, &expected) {
        save_failure(name, actual, Some(&expected));
        panic!(
            "golden {name}: {why}; see target/golden-failures/{name}-*.png, bless with SEETHRU_BLESS={name}"
        );
    }
}

/// Whether `actual` is within the tolerances of `expected`; the reason if not.
pub fn compare(actual: &RgbImage, expected: &RgbImage) -> Result<(), String> {
    if expected.dimensions() != actual.dimensions() {
        return Err(format!(
            "size {:?} differs from the golden's {:?}",
            actual.dimensions(),
            expected.dimensions()
        ));
    }
    let (mut outliers, mut sum) = (0usize, 0u64);
    for (a, e) in actual.pixels().zip(expected.pixels()) {
        let d = (0..3).map(|c| a[c].abs_diff(e[c])).max().unwrap();
        sum += (0..3).map(|c| a[c].abs_diff(e[c]) as u64).sum::<u64>();
        outliers += (d > OUTLIER_LEVEL) as usize;
    }
    let n = actual.pixels().len();
    let (outlier_fraction, mean_abs) = (outliers as f64 / n as f64, sum as f64 / (3 * n) as f64);
    if outlier_fraction > MAX_OUTLIER_FRACTION || mean_abs > MAX_MEAN_ABS {
        return Err(format!(
            "{:.3}% pixels off by > {OUTLIER_LEVEL}/255 (max {:.3}%), mean |diff| {mean_abs:.3}/255 (max {MAX_MEAN_ABS})",
            100.0 * outlier_fraction,
            100.0 * MAX_OUTLIER_FRACTION
        ));
    }
    Ok(())
}

fn save_failure(name: &str, actual: &RgbImage, expected: Option<&RgbImage>) {
    let dir = failure_dir();
    std::fs::create_dir_all(&dir).unwrap();
    actual.save(dir.join(format!("{name}-actual.png"))).unwrap();
    if let Some(expected) = expected {
        expected
            .save(dir.join(format!("{name}-expected.png")))
            .unwrap();
        let diff = RgbImage::from_fn(actual.width(), actual.height(), |x, y| {
            let (a, e) = (actual.get_pixel(x, y), expected.get_pixel(x, y));
            let d = (0..3)
                .map(|c| a[c].abs_diff(e[c]))
                .max()
                .unwrap()
                .saturating_mul(8);
            image::Rgb([d, d, d])
        });
        diff.save(dir.join(format!("{name}-diff.png"))).unwrap();
    }
}
