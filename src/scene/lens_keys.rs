//! The lens keys of `[camera.frontal]` and `[camera.back]` (`model`, `fx`, `fy`, `cx`, `cy`,
//! the distortion coefficients) and the `[calibration]` table: the compensation's own copy
//! of each camera. Documented in `scenes/reference.toml` and docs/reference/scene-format.md.

use glam::{DAffine3, DVec3};

use crate::geometry::calibration::{COEFFICIENT_NAMES, Calibration, CameraCalibration};
use crate::geometry::camera::{Camera, CameraError};
use crate::geometry::lens::{Distortion, Lens};
use crate::geometry::lens_check::LensError;
use crate::scene::source::SceneError;
use crate::scene::table_reader::TableReader;

/// Lens models of the `model` key.
pub const MODELS: [&str; 3] = ["pinhole", "brown", "fisheye"];
/// Largest focal length, pixels.
pub const MAX_FOCAL_PX: f64 = 1e7;
/// Largest principal point offset from the image, pixels.
const MAX_PRINCIPAL_PX: f64 = 1e6;

/// The coefficient keys of a model, in the scene file's order.
fn coefficient_keys(model: &str) -> &'static [&'static str] {
    match model {
        "brown" => &["k1", "k2", "k3", "p1", "p2"],
        "fisheye" => &["k1", "k2", "k3", "k4"],
        _ => &[],
    }
}

/// Largest magnitude of a distortion coefficient. Calibrated lenses stay far inside it (|k| of
/// a few units, tangential terms below 0.1); k1 = 1e10 is no lens, though nothing folds: the
/// image then sees a sliver of the scene.
pub const MAX_COEFFICIENT: f64 = 1e3;

/// A distortion coefficient, default 0, in [−MAX_COEFFICIENT, MAX_COEFFICIENT].
fn coefficient(t: &TableReader, key: &str) -> Result<f64, SceneError> {
    t.f64_in(key, 0.0, -MAX_COEFFICIENT, MAX_COEFFICIENT)
}

/// The key a lens error is about, for its file:line.
fn key_of(t: &TableReader, model: &str, error: &LensError) -> &'static str {
    match error {
        LensError::NotFinite(k) | LensError::FocalNotPositive(k, _) => k,
        LensError::Folds { .. } => coefficient_keys(model)
            .iter()
            .copied()
            .find(|k| t.has(k))
            .unwrap_or("model"),
        LensError::TooWide { .. } if t.has("fx") => "fx",
        LensError::TooWide { .. } => "half_angle_deg",
    }
}

/// A camera at `world_from_camera` with the table's lens: the ideal pinhole of
/// `half_angle()` unless the table gives a `model` with distortion or pixel intrinsics.
pub fn read_lens_camera(
    t: &TableReader,
    world_from_camera: DAffine3,
    half_angle: impl FnOnce() -> Result<f64, SceneError>,
    width: u32,
    height: u32,
) -> Result<Camera, SceneError> {
    let model = t.choice("model", "pinhole", &MODELS)?;
    let has_intrinsics = ["fx", "fy", "cx", "cy"].iter().any(|k| t.has(k));
    if has_intrinsics && t.has("half_angle_deg") {
        return Err(t.error(
            "half_angle_deg",
            "give either half_angle_deg or the pixel intrinsics fx, fy, cx, cy, not both",
        ));
    }
    if model == "pinhole" && !has_intrinsics {
        return Camera::new(world_from_camera, half_angle()?, width, height)
            .map_err(|e| t.error("half_angle_deg", e.to_string()));
    }
    let mut lens = if has_intrinsics {
        let fx = t
            .opt_f64("fx")?
            .ok_or_else(|| t.error("fx", "fx is required with fy, cx or cy (pixels, > 0)"))?;
        Lens {
            fx,
            fy: t.opt_f64("fy")?.unwrap_or(fx),
            cx: t.f64_in(
                "cx",
                width as f64 / 2.0 - 0.5,
                -MAX_PRINCIPAL_PX,
                MAX_PRINCIPAL_PX,
            )?,
            cy: t.f64_in(
                "cy",
                height as f64 / 2.0 - 0.5,
                -MAX_PRINCIPAL_PX,
                MAX_PRINCIPAL_PX,
            )?,
            distortion: Distortion::None,
        }
    } else {
        Lens::pinhole(half_angle()?, width, height)
    };
    for key in ["fx", "fy"] {
        let v = if key == "fx" { lens.fx } else { lens.fy };
        if !(v > 0.0 && v <= MAX_FOCAL_PX) {
            return Err(t.error(
                key,
                format!("focal length must be in (0, {MAX_FOCAL_PX}] pixels, got {v}"),
            ));
        }
    }
    let k: Vec<f64> = coefficient_keys(model)
        .iter()
        .map(|key| coefficient(t, key))
        .collect::<Result<_, _>>()?;
    lens.distortion = match model {
        "brown" => Distortion::Brown {
            k1: k[0],
            k2: k[1],
            k3: k[2],
            p1: k[3],
            p2: k[4],
        },
        "fisheye" => Distortion::Fisheye {
            k1: k[0],
            k2: k[1],
            k3: k[2],
            k4: k[3],
        },
        _ => Distortion::None,
    };
    Camera::with_lens(world_from_camera, lens, width, height).map_err(|e| match &e {
        CameraError::Lens(l) => t.error(key_of(t, model, l), e.to_string()),
        _ => t.error("model", e.to_string()),
    })
}

/// Largest calibration errors accepted.
const MAX_FOCAL_ERROR_PERCENT: f64 = 50.0;
const MAX_ANGLE_ERROR_DEG: f64 = 10.0;
const MAX_POSITION_ERROR: f64 = 1.0;

fn read_camera_calibration(
    t: &TableReader,
    truth: &Camera,
) -> Result<CameraCalibration, SceneError> {
    let angle = |key: &str| -> Result<f64, SceneError> {
        Ok(
            t.f64_in(key, 0.0, -MAX_ANGLE_ERROR_DEG, MAX_ANGLE_ERROR_DEG)?
                .to_radians(),
        )
    };
    let truth_distortion = truth.lens_or_pinhole().distortion;
    let mut coefficients = [None; 6];
    for (i, name) in COEFFICIENT_NAMES.iter().enumerate() {
        if !t.has(name) {
            continue;
        }
        if !CameraCalibration::applicable(&truth_distortion).contains(&i) {
            return Err(t.error(
                name,
                format!(
                    "the true camera's lens (model = {}) has no coefficient {name}",
                    truth_distortion.model_name()
                ),
            ));
        }
        coefficients[i] = Some(coefficient(t, name)?);
    }
    let calibration = CameraCalibration {
        focal_error: t.f64_in(
            "focal_error_percent",
            0.0,
            -MAX_FOCAL_ERROR_PERCENT,
            MAX_FOCAL_ERROR_PERCENT,
        )? / 100.0,
        yaw_error: angle("yaw_error_deg")?,
        pitch_error: angle("pitch_error_deg")?,
        roll_error: angle("roll_error_deg")?,
        position_error: DVec3::from_array(t.array_in(
            "position_error",
            [0.0; 3],
            -MAX_POSITION_ERROR,
            MAX_POSITION_ERROR,
        )?),
        ignore_distortion: t.bool_or("ignore_distortion", false)?,
        coefficients,
    };
    if let Err(e) = calibration.apply(truth) {
        let key = COEFFICIENT_NAMES
            .iter()
            .copied()
            .find(|k| t.has(k))
            .unwrap_or("focal_error_percent");
        return Err(t.error(key, format!("the calibrated camera: {e}")));
    }
    Ok(calibration)
}

/// The `[calibration]` table (absent: exact), given the true cameras.
pub fn read_calibration(
    root: &TableReader,
    frontal: &Camera,
    back: &Camera,
) -> Result<Calibration, SceneError> {
    let Some(table) = root.table("calibration")? else {
        return Ok(Calibration::default());
    };
    let mut calibration = Calibration::default();
    if let Some(t) = table.table("frontal")? {
        calibration.frontal = read_camera_calibration(&t, frontal)?;
        t.finish()?;
    }
    if let Some(t) = table.table("back")? {
        calibration.back = read_camera_calibration(&t, back)?;
        t.finish()?;
    }
    table.finish()?;
    Ok(calibration)
}

/// A file holding only a `[calibration]` table (the scene file's format), for
/// `run --calibration`: it replaces the scene's calibration.
pub fn read_calibration_file(
    path: &std::path::Path,
    frontal: &Camera,
    back: &Camera,
) -> Result<Calibration, SceneError> {
    let file = crate::scene::source::SourceFile::read(path)?;
    calibration_from_source(&file, frontal, back)
}

/// [`read_calibration_file`] of a file already read (the fuzz target's entry).
pub fn calibration_from_source(
    file: &crate::scene::source::SourceFile,
    frontal: &Camera,
    back: &Camera,
) -> Result<Calibration, SceneError> {
    let doc = file.parse()?;
    let root = TableReader::root(file, &doc);
    let calibration = read_calibration(&root, frontal, back)?;
    root.finish()?;
    Ok(calibration)
}
