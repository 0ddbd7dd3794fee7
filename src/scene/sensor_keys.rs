//! `sensor` and its keys in `[camera.frontal]` and `[camera.back]`: the camera as an EMVA 1288
//! sensor (geometry/sensor.rs), in a scene lit in physical units.

use crate::geometry::sensor::{AutoExposure, Coding, Metering, Sensor, ToneCurve};
use crate::geometry::shutter::Shutter;
use crate::scene::Photometry;
use crate::scene::source::SceneError;
use crate::scene::table_reader::TableReader;

pub const SENSORS: [&str; 2] = ["ideal", "emva"];

/// `tone_curve`'s values: "none" (linear light) or a [`ToneCurve`].
pub const TONE_CURVES: [&str; 5] = ["none", "linear", "srgb", "bt709", "gamma2.2"];
/// `output_bits`'s values.
pub const OUTPUT_BITS: [usize; 3] = [8, 10, 12];
/// `auto_exposure`'s values: "off" (manual) or the metering.
pub const AUTO_EXPOSURES: [&str; 3] = ["off", "average", "center"];

/// The keys of `sensor = "emva"`, refused with any other sensor.
const SENSOR_KEYS: [&str; 16] = [
    "f_number",
    "pixel_um",
    "quantum_efficiency",
    "full_well_e",
    "read_noise_e",
    "dark_current_e_s",
    "adc_bits",
    "gain_dn_per_e",
    "noise_seed",
    "tone_curve",
    "output_bits",
    "auto_exposure",
    "auto_target",
    "auto_max_gain",
    "auto_min_exposure_ms",
    "adaptation_ev_s",
];

/// The camera's sensor: `None` for the ideal one (the renderer's radiance as it is).
pub fn read_sensor(
    t: &TableReader,
    shutter: &Shutter,
    photometry: Option<&Photometry>,
) -> Result<Option<Sensor>, SceneError> {
    if t.choice("sensor", "ideal", &SENSORS)? == "ideal" {
        if let Some(key) = SENSOR_KEYS.iter().find(|k| t.has(k)) {
            return Err(t.error(
                key,
                "is a key of sensor = \"emva\", but the sensor is \"ideal\"",
            ));
        }
        return Ok(None);
    }
    let Some(photometry) = photometry else {
        return Err(t.error(
            "sensor",
            "\"emva\" counts photons: it needs a scene lit in physical units (add `illuminance_lux` to [sun])",
        ));
    };
    if shutter.exposure_s <= 0.0 {
        return Err(t.error(
            "sensor",
            "\"emva\" needs an exposure: set exposure_ms above 0",
        ));
    }
    let full_well_e = t.f64_in("full_well_e", 10_000.0, 1.0, 1e7)?;
    let adc_bits = t.usize_in("adc_bits", 12, 1, 16)? as u32;
    let top = f64::from((1u32 << adc_bits) - 1);
    Ok(Some(
        Sensor {
            f_number: t.f64_in("f_number", 2.0, 0.5, 64.0)?,
            pixel_um: t.f64_in("pixel_um", 3.0, 0.1, 100.0)?,
            quantum_efficiency: t.f64_in("quantum_efficiency", 0.6, 1e-6, 1.0)?,
            full_well_e,
            read_noise_e: t.f64_in("read_noise_e", 3.0, 0.0, 1e4)?,
            dark_current_e_s: t.f64_in("dark_current_e_s", 10.0, 0.0, 1e7)?,
            adc_bits,
            gain_dn_per_e: t.f64_in("gain_dn_per_e", top / full_well_e, 1e-9, 1e4)?,
            noise_seed: t.usize_in("noise_seed", 0, 0, u32::MAX as usize)? as u32,
            exposure_s: shutter.exposure_s,
            white_cd_m2: photometry.white_cd_m2,
            coding: read_coding(t)?,
            exposure_gain: None,
            auto_exposure: read_auto_exposure(t, shutter.exposure_s)?,
        }
        .with_manual_gain(),
    ))
}

/// `tone_curve` and `output_bits`.
fn read_coding(t: &TableReader) -> Result<Option<Coding>, SceneError> {
    let curve = t.choice("tone_curve", "none", &TONE_CURVES)?;
    let Some(curve) = ToneCurve::from_name(curve) else {
        if t.has("output_bits") {
            return Err(t.error(
                "output_bits",
                "is the bits of a tone curve's codes, but tone_curve is \"none\" (linear light): set tone_curve",
            ));
        }
        return Ok(None);
    };
    let bits = t.usize_in("output_bits", 8, 8, 12)?;
    if !OUTPUT_BITS.contains(&bits) {
        return Err(t.error("output_bits", format!("must be 8, 10 or 12, got {bits}")));
    }
    Ok(Some(Coding {
        curve,
        bits: bits as u32,
    }))
}

/// `auto_exposure` and its keys.
fn read_auto_exposure(
    t: &TableReader,
    max_exposure_s: f64,
) -> Result<Option<AutoExposure>, SceneError> {
    let metering = match t.choice("auto_exposure", "off", &AUTO_EXPOSURES)? {
        "average" => Metering::Average,
        "center" => Metering::Center,
        _ => {
            let keys = [
                "auto_target",
                "auto_max_gain",
                "auto_min_exposure_ms",
                "adaptation_ev_s",
            ];
            if let Some(key) = keys.iter().find(|k| t.has(k)) {
                return Err(t.error(
                    key,
                    "is a key of the automatic exposure, but auto_exposure is \"off\": set it to \"average\" or \"center\"",
                ));
            }
            return Ok(None);
        }
    };
    let target = t.f64_in("auto_target", 0.18, 1e-6, 1.0)?;
    if target >= 1.0 {
        return Err(t.error(
            "auto_target",
            format!("must be below 1 (the full scale), got {target}"),
        ));
    }
    let max_ms = max_exposure_s * 1e3;
    let min_ms = t.f64_in("auto_min_exposure_ms", 0.02_f64.min(max_ms), 1e-6, max_ms)?;
    Ok(Some(AutoExposure {
        metering,
        min_exposure_s: min_ms / 1e3,
        max_exposure_s,
        target,
        max_gain: t.f64_in("auto_max_gain", 64.0, 1.0, 1e4)?,
        adaptation_ev_s: t.f64_in("adaptation_ev_s", 8.0, 0.01, 1e3)?,
    }))
}
