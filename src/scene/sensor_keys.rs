//! `sensor` and its keys in `[camera.frontal]` and `[camera.back]`: the camera as an EMVA 1288
//! sensor (geometry/sensor.rs), in a scene lit in physical units.

use crate::geometry::sensor::Sensor;
use crate::geometry::shutter::Shutter;
use crate::scene::Photometry;
use crate::scene::source::SceneError;
use crate::scene::table_reader::TableReader;

pub const SENSORS: [&str; 2] = ["ideal", "emva"];

/// The keys of `sensor = "emva"`, refused with any other sensor.
const SENSOR_KEYS: [&str; 9] = [
    "f_number",
    "pixel_um",
    "quantum_efficiency",
    "full_well_e",
    "read_noise_e",
    "dark_current_e_s",
    "adc_bits",
    "gain_dn_per_e",
    "noise_seed",
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
    Ok(Some(Sensor {
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
    }))
}
