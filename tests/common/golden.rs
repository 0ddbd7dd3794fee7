//! Golden-image comparison in the manner of the vello/wgpu tests: the reference PNG lives in
//! `golden/`, a failure writes `actual`, `expected` and `diff` images under
//! `target/golden-failures/`, `SEETHRU_BLESS=1` accepts new images, and a missing golden is
//! a failure, never a silent write.

use std::path::PathBuf;

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

pub fn check(name: &str, actual: &RgbImage) {
    let path = repo_path(&format!("golden/{name}.png"));
    if std::env::var("SEETHRU_BLESS").is_ok_and(|v| v == "1") {
        actual.save(&path).unwrap();
        eprintln!("blessed {}", path.display());
        return;
    }
    let expected = match image::open(&path) {
        Ok(img) => img.to_rgb8(),
        Err(e) => {
            save_failure(name, actual, None);
            panic!(
                "golden {} missing or unreadable ({e}); inspect target/golden-failures/{name}-actual.png and bless with SEETHRU_BLESS=1",
                path.display()
            );
        }
    };
    if let Err(why) = compare(actual, &expected) {
        save_failure(name, actual, Some(&expected));
        panic!(
            "golden {name}: {why}; see target/golden-failures/{name}-*.png, bless with SEETHRU_BLESS=1"
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
