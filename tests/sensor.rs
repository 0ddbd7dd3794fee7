//! The frontal camera as an EMVA 1288 sensor, against the analytic answers: over a flat field
//! the mean code follows the exposure equation and the codes' variance is the photon-transfer
//! curve's (shot + dark + read + quantisation noise), at three light levels.

mod common;

use common::photometric::{WALL_SUN_LUX as LUX, exr_channels, lit_wall_scene, seethru_on};
use seethru::util::color::srgb_to_linear;

const WHITE: f64 = 5000.0;

/// The lit wall's flat field for the frontal camera (192 × 108 pixels, 30° half angle),
/// whose sensor takes `sensor` keys.
fn flat_field(exposure_ms: f64, sensor: &str) -> String {
    let frontal = format!(
        "half_angle_deg = 30.0\nresolution = [192, 108]\nexposure_ms = {exposure_ms}\nsensor = \"emva\"\n{sensor}"
    );
    lit_wall_scene(WHITE, "", &frontal)
}

/// The frontal view's green channel in cd/m², as the EXR holds it.
fn frontal_green(scene: &str) -> Vec<f64> {
    let dir = tempfile::tempdir().unwrap();
    let out = seethru_on(
        dir.path(),
        scene,
        "render",
        &["--view", "frontal", "--exr", "colour"],
    );
    exr_channels(&out.join("frontal.exr"))["G"].clone()
}

fn mean_and_variance(values: &[f64]) -> (f64, f64) {
    let n = values.len() as f64;
    let mean = values.iter().sum::<f64>() / n;
    let var = values.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / (n - 1.0);
    (mean, var)
}

#[test]
fn the_mean_code_follows_the_exposure_equation_and_the_variance_the_photon_transfer_curve() {
    // The sensor's keys, and the equation's terms.
    let (f_number, pixel_um, qe, full_well, read_noise, dark, bits) =
        (2.0, 3.0, 0.6, 10_000.0, 15.0, 10.0, 12);
    let gain = f64::from((1u32 << bits) - 1) / full_well;
    let keys = format!(
        "f_number = {f_number}\npixel_um = {pixel_um}\nquantum_efficiency = {qe}\n\
         full_well_e = {full_well}\nread_noise_e = {read_noise}\ndark_current_e_s = {dark}\n\
         adc_bits = {bits}\n"
    );
    let rho = f64::from(srgb_to_linear(0.6));
    let wall = rho * LUX * 60f64.to_radians().cos() / std::f64::consts::PI;
    // Photo-electrons per second of exposure for a radiance L: η · A · π L / (4 N²) · photons
    // of 555 nm per lx·s·µm² ((1/683 W/m²) / (h c / 555 nm) · 10⁻¹²).
    let photons_per_lux_s_um2 = (1.0 / 683.0) / (6.62607015e-34 * 299_792_458.0 / 555e-9) * 1e-12;
    let electrons_per_s = |l: f64| {
        qe * pixel_um * pixel_um * std::f64::consts::PI * l / (4.0 * f_number * f_number)
            * photons_per_lux_s_um2
    };
    // Three light levels: about 500, 2 000 and 8 000 electrons.
    for exposure_ms in [0.05, 0.2, 0.8] {
        let t = exposure_ms / 1e3;
        let signal = electrons_per_s(wall) * t;
        let dark_e = dark * t;
        let white_dn = gain * electrons_per_s(WHITE) * t;
        // Back from what the camera delivers (cd/m²) to its codes.
        let codes: Vec<f64> = frontal_green(&flat_field(exposure_ms, &keys))
            .iter()
            .map(|v| v / WHITE * white_dn + gain * dark_e)
            .collect();
        let (mean, var) = mean_and_variance(&codes);
        let expected_mean = gain * (signal + dark_e);
        assert!(
            (mean - expected_mean).abs() < 0.01 * expected_mean,
            "{exposure_ms} ms: mean code {mean} vs {expected_mean}"
        );
        let expected_var = gain * gain * (signal + dark_e + read_noise * read_noise) + 1.0 / 12.0;
        assert!(
            (var / expected_var - 1.0).abs() < 0.03,
            "{exposure_ms} ms: variance {var} vs {expected_var} DN²"
        );
    }
}

#[test]
fn a_saturated_sensor_delivers_its_full_well_and_the_seed_picks_the_noise() {
    let keys = "full_well_e = 1000\nnoise_seed = 1\n";
    // 8 ms: some 88 000 electrons, far above the well.
    let codes = frontal_green(&flat_field(8.0, keys));
    assert!(
        codes.windows(2).all(|w| w[0] == w[1]),
        "not flat: {:?}",
        &codes[..4]
    );
    let a = frontal_green(&flat_field(0.05, "noise_seed = 1\n"));
    let b = frontal_green(&flat_field(0.05, "noise_seed = 2\n"));
    assert_eq!(a, frontal_green(&flat_field(0.05, "noise_seed = 1\n")));
    assert!(a.iter().zip(&b).filter(|(x, y)| x != y).count() > a.len() / 2);
}

#[test]
fn sensor_keys_are_refused_where_they_cannot_apply() {
    let scene = |text: &str| {
        common::parse(&text.replace("sensor = \"emva\"\n", ""))
            .map(|_| ())
            .unwrap_err()
            .to_string()
    };
    let base = flat_field(1.0, "");
    // A key of the EMVA sensor without it.
    let e = scene(&base.replace("exposure_ms = 1\n", "exposure_ms = 1\nread_noise_e = 2\n"));
    assert!(
        e.contains("`camera.frontal.read_noise_e`") && e.contains("emva"),
        "{e}"
    );
    // No exposure.
    let e = common::parse(&flat_field(0.0, "")).unwrap_err().to_string();
    assert!(
        e.contains("`camera.frontal.sensor`") && e.contains("exposure_ms above 0"),
        "{e}"
    );
    // A relative scene.
    let relative = flat_field(1.0, "")
        .replace(&format!("illuminance_lux = {LUX}\n"), "")
        .replace("zenith_luminance_cd_m2 = 0\n", "")
        .replace(&format!("[photometry]\nwhite_cd_m2 = {WHITE}\n"), "");
    let e = common::parse(&relative).unwrap_err().to_string();
    assert!(
        e.contains("`camera.frontal.sensor`") && e.contains("physical units"),
        "{e}"
    );
}
