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

/// The frontal view's codes of a coded camera (frontal.png: 8 bits as they are, 10 and 12 in
/// a 16-bit PNG scaled by 65535 / the top code), back to codes.
fn frontal_codes(scene: &str, bits: u32) -> Vec<f64> {
    let dir = tempfile::tempdir().unwrap();
    let out = seethru_on(dir.path(), scene, "render", &["--view", "frontal"]);
    let image = image::open(out.join("frontal.png")).unwrap();
    let top = f64::from((1u32 << bits) - 1);
    match bits {
        8 => (image.to_rgb8().pixels())
            .map(|p| f64::from(p[1]))
            .collect(),
        // A 16-bit sample is a code within half a 16-bit step: the code, rounded.
        _ => (image.to_rgb16().pixels())
            .map(|p| {
                let code = f64::from(p[1]) * top / 65535.0;
                assert!((code - code.round()).abs() <= 0.5 * top / 65535.0, "{code}");
                code.round()
            })
            .collect(),
    }
}

/// The camera curves, as their standards write them (not the library's).
fn curve(name: &str, x: f64) -> f64 {
    match name {
        "linear" => x,
        "srgb" if x <= 0.0031308 => 12.92 * x,
        "srgb" => 1.055 * x.powf(1.0 / 2.4) - 0.055,
        "bt709" if x < 0.018 => 4.5 * x,
        "bt709" => 1.099 * x.powf(0.45) - 0.099,
        "gamma2.2" => x.powf(1.0 / 2.2),
        other => panic!("{other}"),
    }
}

#[test]
fn a_tone_curve_codes_the_signal_share_of_full_scale_at_its_bits() {
    // No read noise or dark current, a deep well: the codes scatter by the shot noise alone
    // (under 1 %), and their mean is the curve of the mean signal's share of full scale.
    let (full_well, exposure_ms) = (100_000.0, 0.8);
    let rho = f64::from(srgb_to_linear(0.6));
    let wall = rho * LUX * 60f64.to_radians().cos() / std::f64::consts::PI;
    let photons_per_lux_s_um2 = (1.0 / 683.0) / (6.62607015e-34 * 299_792_458.0 / 555e-9) * 1e-12;
    let electrons =
        0.6 * 9.0 * std::f64::consts::PI * wall / 16.0 * photons_per_lux_s_um2 * exposure_ms / 1e3;
    let share = electrons / full_well;
    assert!(share > 0.01 && share < 0.5, "{share}");
    for (name, bits) in [("srgb", 8), ("bt709", 10), ("gamma2.2", 12), ("linear", 12)] {
        let keys = format!(
            "full_well_e = {full_well}\nread_noise_e = 0\ndark_current_e_s = 0\n\
             tone_curve = \"{name}\"\noutput_bits = {bits}\n"
        );
        let scene = flat_field(exposure_ms, &keys)
            .replace("[obstacle]\n", "[obstacle]\ndisplay_peak_cd_m2 = 1000\n");
        let codes = frontal_codes(&scene, bits);
        let (mean, _) = mean_and_variance(&codes);
        let top = f64::from((1u32 << bits) - 1);
        let expected = curve(name, share) * top;
        assert!(
            (mean - expected).abs() < 0.01 * expected,
            "{name} {bits} bits: mean code {mean} vs {expected}"
        );
    }
}

#[test]
fn the_automatic_exposure_puts_the_flat_fields_mean_at_its_target_by_time_then_gain() {
    let keys = |max_ms: f64| {
        "read_noise_e = 0\ndark_current_e_s = 0\ntone_curve = \"linear\"\noutput_bits = 12\n\
         auto_exposure = \"average\"\nauto_target = 0.3\n"
            .to_string()
            + if max_ms < 0.1 {
                "auto_max_gain = 4\n"
            } else {
                ""
            }
    };
    let with_display =
        |s: String| s.replace("[obstacle]\n", "[obstacle]\ndisplay_peak_cd_m2 = 1000\n");
    // Time enough: the exposure time settles, gain 1, the mean code at 0.3 of full scale.
    let codes = frontal_codes(&with_display(flat_field(50.0, &keys(50.0))), 12);
    let (mean, _) = mean_and_variance(&codes);
    assert!((mean / 4095.0 - 0.3).abs() < 0.003, "{}", mean / 4095.0);
    // The longest time 0.02 ms, which gives a tenth of the target or so: the gain makes up
    // the rest up to its limit of 4, and the exposure stays short of its target, by the
    // exposure equation.
    let short = frontal_codes(&with_display(flat_field(0.02, &keys(0.02))), 12);
    let (mean_short, _) = mean_and_variance(&short);
    let at_longest =
        mean / 4095.0 * 0.02 / settled_time_ms(&with_display(flat_field(50.0, &keys(50.0))));
    assert!(
        (mean_short / 4095.0 / (4.0 * at_longest) - 1.0).abs() < 0.02,
        "{} vs {}",
        mean_short / 4095.0,
        4.0 * at_longest
    );
}

/// The frontal exposure time a run of `scene` settles at (run.json).
fn settled_time_ms(scene: &str) -> f64 {
    let dir = tempfile::tempdir().unwrap();
    let out = seethru_on(dir.path(), scene, "run", &["--width", "32"]);
    let run: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("run.json")).unwrap()).unwrap();
    let e = &run["exposure"]["frontal"];
    assert_eq!(e["gain"], 1.0, "{e}");
    e["exposure_ms"].as_f64().unwrap()
}

/// frames.csv of a 2 s sequence at 15 fps turning at 20°/s (the frontal camera sweeps a
/// wall half lit, half black) with a frontal camera whose automatic exposure adapts at
/// `speed` stops/s: per frame, the capture time (s), the exposure product (ms × gain) and
/// the metered share.
fn adapting_sequence(speed: f64) -> Vec<(f64, f64, f64)> {
    let frontal = format!(
        "half_angle_deg = 30.0\nresolution = [64, 36]\nexposure_ms = 4\nsensor = \"emva\"\n\
         tone_curve = \"srgb\"\nauto_exposure = \"average\"\nadaptation_ev_s = {speed}\n"
    );
    let scene = lit_wall_scene(WHITE, "display_peak_cd_m2 = 1000\n", &frontal)
        + "\n[[material]]\nname = \"black\"\ncolor = [0.02, 0.02, 0.02]\n\n[[object]]\n\
           name = \"shade\"\nkind = \"quad\"\nmaterial = \"black\"\nsize = [100.0, 200.0]\n\
           translate = [-50.0, 0.0, -19.0]\n";
    let dir = tempfile::tempdir().unwrap();
    let out = common::photometric::seethru_on(
        dir.path(),
        &scene,
        "sequence",
        &[
            "--duration",
            "2",
            "--fps",
            "15",
            "--yaw-rate",
            "20",
            "--speed",
            "1",
            "--width",
            "32",
            "--frames",
            "none",
        ],
    );
    let text = std::fs::read_to_string(out.join("latency_0ms/frames.csv")).unwrap();
    let mut lines = text.lines();
    let header: Vec<&str> = lines.next().unwrap().split(',').collect();
    let column = |name: &str| header.iter().position(|h| *h == name).unwrap();
    lines
        .map(|l| {
            l.split(',')
                .map(|v| v.parse::<f64>().unwrap())
                .collect::<Vec<_>>()
        })
        .map(|r| {
            (
                r[column("capture_s")],
                r[column("frontal_exposure_ms")] * r[column("frontal_gain")],
                r[column("frontal_metered")],
            )
        })
        .collect()
}

#[test]
fn a_sequences_automatic_exposure_follows_the_light_at_its_adaptation_speed() {
    // Fast: every frame settled, at the target.
    let fast = adapting_sequence(1000.0);
    assert_eq!(fast.len(), 30);
    assert!(fast.iter().all(|f| (f.2 - 0.18).abs() < 1e-4), "{fast:?}");
    // The turn changes the light by more than a stop.
    let (lo, hi) = fast.iter().fold((f64::INFINITY, 0.0f64), |(lo, hi), f| {
        (lo.min(f.1), hi.max(f.1))
    });
    assert!((hi / lo).log2() > 1.0, "{lo} … {hi}");
    // Slow: the first frame settled, each next one at most 0.3 stops/s × its interval away,
    // held at that step while it lags, so off its target then.
    let slow = adapting_sequence(0.3);
    assert!((slow[0].1 / fast[0].1 - 1.0).abs() < 1e-9 && (slow[0].2 - 0.18).abs() < 1e-4);
    let mut lagging = 0;
    for (a, b) in slow.iter().zip(&slow[1..]) {
        let step = (b.1 / a.1).log2().abs();
        let most = 0.3 * (b.0 - a.0);
        assert!(step <= most + 1e-9, "{step} > {most} stops");
        if step > most - 1e-9 {
            lagging += 1;
            assert!((b.2 - 0.18).abs() > 1e-3, "{b:?}");
        }
    }
    assert!(lagging > 10, "{lagging} of {} frames lag", slow.len());
}
