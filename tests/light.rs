//! Light in physical units against analytic answers: a Lambertian floor of albedo ρ under a sun
//! of illuminance E has the luminance ρE/π (and ρ(E sin h/π + L) under a uniform sky of
//! luminance L), which the EXRs hold in cd/m²; the sun's angles; the keys' errors.

mod common;

use std::path::Path;

use common::parse;
use common::photometric::{WALL_SUN_LUX, exr_channels, lit_wall_scene, luminance, seethru_on};
use seethru::scene::light_keys::sun_direction;
use seethru::util::color::srgb_to_linear;

/// A grey floor (sRGB `grey`) filmed from 1.2 m, looking away from the obstacle towards +z,
/// so that neither the obstacle nor its shadow (the sun comes from the south, +z, behind the
/// view's far end) is in the picture; `light` holds the `[sun]`, `[sky]` and
/// `[photometry]` tables.
fn floor_scene(grey: f64, light: &str) -> String {
    format!(
        r#"{light}
[obstacle]
center = [0.0, 1.2, -0.8]
width = 0.3
height = 0.4

[camera.driver]
position = [0.0, 1.2, 0.0]
look_at = [0.0, 0.6, 10.0]
half_angle_deg = 30.0
resolution = [48, 32]

[camera.frontal]
resolution = [16, 12]

[camera.back]
resolution = [16, 12]

[[material]]
name = "grey"
color = [{grey}, {grey}, {grey}]

[[object]]
name = "floor"
kind = "plane"
material = "grey"
size = [100000.0, 100000.0]
"#
    )
}

/// The truth view's EXR, read with the exr crate alone: per pixel the luminance and whether
/// the pixel shows the floor (an object id that is not the sky's 0).
fn rendered_luminance(dir: &Path, scene: &str) -> Vec<(f64, bool)> {
    let out = seethru_on(dir, scene, "render", &["--view", "truth", "--exr", "lean"]);
    let channels = exr_channels(&out.join("truth.exr"));
    let ids = &channels["id.object"];
    (luminance(&channels).into_iter().enumerate())
        .map(|(i, y)| (y, ids[i] != 0.0))
        .collect()
}

fn relative_error(got: f64, want: f64) -> f64 {
    (got - want).abs() / want.abs().max(f64::MIN_POSITIVE)
}

#[test]
fn a_lambertian_floor_under_the_sun_has_the_luminance_rho_e_over_pi() {
    let dir = tempfile::tempdir().unwrap();
    let grey = 0.5;
    let rho = f64::from(srgb_to_linear(grey as f32));
    for (lux, elevation) in [(100_000.0, 90.0), (100_000.0, 60.0), (30_000.0, 25.0)] {
        let light = format!(
            "[sun]\nilluminance_lux = {lux}\nelevation_deg = {elevation}\nazimuth_deg = 180\n\
             [sky]\nzenith_luminance_cd_m2 = 0\ncloud_cover = 0\n\
             [photometry]\nwhite_cd_m2 = 5000\n"
        );
        let pixels = rendered_luminance(dir.path(), &floor_scene(grey, &light));
        let expected = rho * lux * f64::to_radians(elevation).sin() / std::f64::consts::PI;
        let floor: Vec<f64> = pixels.iter().filter(|p| p.1).map(|p| p.0).collect();
        assert!(floor.len() > 300, "{} floor pixels", floor.len());
        for &y in &floor {
            assert!(
                relative_error(y, expected) < 0.005,
                "elevation {elevation}°: Y = {y} cd/m², ρE sin h/π = {expected}"
            );
        }
        // The sky is black: no luminance where nothing is hit (the sun's disc is above the
        // picture).
        assert!(pixels.iter().filter(|p| !p.1).all(|p| p.0 == 0.0));
    }
}

#[test]
fn a_uniform_sky_adds_its_luminance_to_a_white_floor_and_shows_it() {
    let dir = tempfile::tempdir().unwrap();
    let (lux, elevation, sky) = (50_000.0, 40.0, 3_000.0);
    // A grey sky at the zenith and the horizon: uniform, so that a floor receives πL.
    let light = format!(
        "[sun]\nilluminance_lux = {lux}\nelevation_deg = {elevation}\nazimuth_deg = 180\n\
         [sky]\nzenith_luminance_cd_m2 = {sky}\nzenith_color = [0.6, 0.6, 0.6]\n\
         horizon_color = [0.6, 0.6, 0.6]\ncloud_cover = 0\n"
    );
    let pixels = rendered_luminance(dir.path(), &floor_scene(1.0, &light));
    let floor = lux * f64::to_radians(elevation).sin() / std::f64::consts::PI + sky;
    let (mut floors, mut skies) = (0, 0);
    for (y, is_floor) in pixels {
        let expected = if is_floor { floor } else { sky };
        assert!(
            relative_error(y, expected) < 0.005,
            "floor {is_floor}: Y = {y}, expected {expected}"
        );
        if is_floor { floors += 1 } else { skies += 1 }
    }
    assert!(
        floors > 300 && skies > 100,
        "{floors} floor, {skies} sky pixels"
    );
}

#[test]
fn the_white_defaults_to_a_white_floor_under_the_light() {
    let (lux, elevation, sky) = (80_000.0, 30.0, 2_000.0);
    let light = format!(
        "[sun]\nilluminance_lux = {lux}\nelevation_deg = {elevation}\nazimuth_deg = 0\n\
         [sky]\nzenith_luminance_cd_m2 = {sky}\nzenith_color = [0.5, 0.5, 0.5]\n\
         horizon_color = [0.5, 0.5, 0.5]\n"
    );
    let scene = parse(&floor_scene(0.5, &light)).unwrap();
    let white = scene.photometry.unwrap().white_cd_m2;
    let expected = lux * 0.5 / std::f64::consts::PI + sky;
    assert!(
        relative_error(white, expected) < 1e-6,
        "{white} vs {expected}"
    );
}

#[test]
fn the_sun_stands_where_its_elevation_and_azimuth_say() {
    // North is −z, east +x, up +y.
    let close = |a: glam::DVec3, b: [f64; 3]| (a - glam::DVec3::from_array(b)).length() < 1e-12;
    assert!(close(sun_direction(90.0, 123.0), [0.0, 1.0, 0.0]));
    assert!(close(sun_direction(0.0, 0.0), [0.0, 0.0, -1.0]));
    assert!(close(sun_direction(0.0, 90.0), [1.0, 0.0, 0.0]));
    assert!(close(sun_direction(0.0, 180.0), [0.0, 0.0, 1.0]));
    let h = 30f64.to_radians();
    assert!(close(sun_direction(30.0, 270.0), [-h.cos(), h.sin(), 0.0]));
    // Read from a scene, the same direction.
    let scene = parse(&floor_scene(
        0.5,
        "[sun]\nelevation_deg = 30\nazimuth_deg = 270\n",
    ))
    .unwrap();
    assert!(close(scene.sun.direction, [-h.cos(), h.sin(), 0.0]));
    assert!(scene.photometry.is_none());
    // From a date, a time and a place: Berlin (52.52° N, 13.40° E) at the March equinox's
    // solar noon has the sun due south (+z) at 90° − 52.52° = 37.5°.
    let scene = parse(&floor_scene(
        0.5,
        "[sun]\ndate = \"2026-03-20\"\ntime_utc = \"11:14\"\nlatitude_deg = 52.52\nlongitude_deg = 13.40\n",
    ))
    .unwrap();
    let noon = 37.5f64.to_radians();
    let expected = glam::DVec3::new(0.0, noon.sin(), noon.cos());
    let off = scene.sun.direction.angle_between(expected).to_degrees();
    assert!(
        off < 0.5,
        "{} is {off}° from {expected}",
        scene.sun.direction
    );
}

#[test]
fn light_keys_that_contradict_each_other_are_refused_with_the_key_named() {
    let cases: &[(&str, &str, &str)] = &[
        (
            "[sun]\nilluminance_lux = 1000\nintensity = 2\n",
            "sun.intensity",
            "relative multiplier",
        ),
        (
            "[sun]\nilluminance_lux = 1000\n[sky]\nambient = 0.5\n",
            "sky.ambient",
            "relative multiplier",
        ),
        (
            "[sky]\nzenith_luminance_cd_m2 = 100\n",
            "sky.zenith_luminance_cd_m2",
            "needs a sun in lux",
        ),
        (
            "[photometry]\nwhite_cd_m2 = 100\n",
            "photometry",
            "needs a sun in lux",
        ),
        (
            "[sun]\ndirection = [0, 1, 0]\nelevation_deg = 30\nazimuth_deg = 0\n",
            "sun.elevation_deg",
            "places the sun as `direction` does",
        ),
        (
            "[sun]\nelevation_deg = 30\n",
            "sun.azimuth_deg",
            "is required",
        ),
        (
            "[sun]\nilluminance_lux = 1000\ncolor = [0, 0, 0]\n",
            "sun.color",
            "black",
        ),
        (
            "[sun]\nilluminance_lux = 1000\n[sky]\nzenith_luminance_cd_m2 = 10\nzenith_color = [0, 0, 0]\n",
            "sky.zenith_color",
            "black",
        ),
        (
            "[sun]\nilluminance_lux = 0\n[sky]\nzenith_luminance_cd_m2 = 0\n",
            "photometry",
            "no light",
        ),
        (
            "[sun]\nilluminance_lux = 0\n[photometry]\n",
            "photometry.white_cd_m2",
            "is required",
        ),
        (
            "[sun]\nilluminance_lux = 1000\n[photometry]\nwhite_cd_m2 = 100\nblack = 1\n",
            "photometry.black",
            "unknown key",
        ),
        (
            "[sun]\nilluminance_lux = 1000\n[photometry]\nlamp_sampling = \"all\"\n",
            "photometry.lamp_sampling",
            "`all` is not one of: every, one",
        ),
    ];
    for (light, key, words) in cases {
        let e = parse(&floor_scene(0.5, light)).unwrap_err().to_string();
        assert!(
            e.contains(&format!("`{key}`")) && e.contains(words),
            "{light}: {e}"
        );
    }
}

#[test]
fn each_light_number_is_refused_outside_its_documented_range() {
    // (table text with X for the value, key, low, high): the bounds are admitted, values
    // just outside and NaN are not.
    let cases: &[(&str, &str, f64, f64)] = &[
        (
            "[sun]\nilluminance_lux = X\n[photometry]\nwhite_cd_m2 = 100\n",
            "sun.illuminance_lux",
            0.0,
            150_000.0,
        ),
        (
            "[sun]\nilluminance_lux = 1000\n[sky]\nzenith_luminance_cd_m2 = X\n",
            "sky.zenith_luminance_cd_m2",
            0.0,
            100_000.0,
        ),
        (
            "[sun]\nilluminance_lux = 1000\n[photometry]\nwhite_cd_m2 = X\n",
            "photometry.white_cd_m2",
            1e-6,
            1e10,
        ),
        (
            "[sun]\nelevation_deg = X\nazimuth_deg = 10\n",
            "sun.elevation_deg",
            -90.0,
            90.0,
        ),
        (
            "[sun]\nelevation_deg = 10\nazimuth_deg = X\n",
            "sun.azimuth_deg",
            0.0,
            360.0,
        ),
        (
            "[sun]\ndate = \"2026-06-01\"\ntime_utc = \"12:00\"\nlatitude_deg = X\nlongitude_deg = 0\n",
            "sun.latitude_deg",
            -90.0,
            90.0,
        ),
        (
            "[sun]\ndate = \"2026-06-01\"\ntime_utc = \"12:00\"\nlatitude_deg = 0\nlongitude_deg = X\n",
            "sun.longitude_deg",
            -180.0,
            180.0,
        ),
    ];
    for &(text, key, lo, hi) in cases {
        let with = |x: f64| {
            let value = if x.is_nan() {
                "nan".to_string()
            } else {
                format!("{x:?}")
            };
            parse(&floor_scene(0.5, &text.replace('X', &value)))
        };
        for x in [lo, hi] {
            with(x).unwrap_or_else(|e| panic!("{key} = {x} refused: {e}"));
        }
        let below = lo - lo.abs().max(1e-6) * 0.5;
        for x in [below, hi * 1.5, f64::NAN] {
            let e = with(x)
                .expect_err(&format!("{key} = {x} accepted"))
                .to_string();
            assert!(e.contains(&format!("`{key}`")), "{key} = {x}: {e}");
        }
    }
}

#[test]
fn a_photometric_exr_reads_back_in_units_of_the_white() {
    use seethru::io::frame_files::{read_exr, write_exr};
    use seethru::render::integrator::RenderContext;
    use seethru::render::render_job::RenderJob;
    use seethru::scene::world::view_bit;
    let light = "[sun]\nilluminance_lux = 20000\n[sky]\nzenith_luminance_cd_m2 = 4000\n\
                 [photometry]\nwhite_cd_m2 = 700\n";
    let ctx = RenderContext::new(parse(&floor_scene(0.4, light)).unwrap()).unwrap();
    let (frame, _) = ctx.render(RenderJob::new(&ctx.scene.driver, view_bit::TRUTH).label("test"));
    assert_eq!(frame.white_cd_m2, Some(700.0));
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("truth.exr");
    write_exr(&frame, &path).unwrap();
    let back = read_exr(&path).unwrap();
    assert_eq!(back.white_cd_m2, Some(700.0));
    for (a, b) in frame.color.iter().zip(&back.color) {
        assert!(
            (*a - *b).abs().max_element() <= 1e-6 * a.max_element().max(1.0),
            "{a} {b}"
        );
    }
    // The file's header says its RGB is in cd/m².
    let meta = exr::meta::MetaData::read_from_file(&path, false).unwrap();
    assert_eq!(meta.headers[0].own_attributes.white_luminance, Some(1.0));
}

/// The frontal camera of the display tests.
const FRONTAL: &str = "resolution = [64, 36]";

/// Per pixel of `run`'s seethru view where the driver sees the display (the occluded view's
/// id is the obstacle's), the luminance there and the truth's; and metrics.json.
fn display_luminance(dir: &Path, scene: &str) -> (Vec<(f64, f64)>, serde_json::Value) {
    let out = seethru_on(dir, scene, "run", &["--band", "30"]);
    let view = |name: &str| exr_channels(&out.join(format!("{name}.exr")));
    let (seethru, truth) = (luminance(&view("seethru")), luminance(&view("truth")));
    let occluded_ids = view("occluded")["id.object"].clone();
    let obstacle = occluded_ids.iter().copied().fold(0.0, f64::max);
    let pixels = (0..seethru.len())
        .filter(|&i| occluded_ids[i] == obstacle)
        .map(|i| (seethru[i], truth[i]))
        .collect();
    let metrics = std::fs::read_to_string(out.join("metrics.json")).unwrap();
    (pixels, serde_json::from_str(&metrics).unwrap())
}

#[test]
fn a_display_emits_between_its_black_and_its_peak_and_reflects_the_light_on_it() {
    let dir = tempfile::tempdir().unwrap();
    let (lux, h) = (WALL_SUN_LUX, 60f64.to_radians());
    let rho = f64::from(srgb_to_linear(0.6));
    let wall = rho * lux * h.cos() / std::f64::consts::PI;
    let face = lux * h.cos() / std::f64::consts::PI;
    let (peak, black) = (500.0, 1.0);
    // (white, reflectance, expected display luminance)
    let cases = [
        // The wall at half the white: half the display's range above its black.
        (2.0 * wall, 0.0, black + (peak - black) * 0.5),
        // The wall at four times the white: the display's peak.
        (wall / 4.0, 0.0, peak),
        // And a face that reflects 5 % of the sunlight on it.
        (2.0 * wall, 0.05, black + (peak - black) * 0.5 + 0.05 * face),
    ];
    for (white, reflectance, expected) in cases {
        let display = format!(
            "display_peak_cd_m2 = {peak}\ndisplay_black_cd_m2 = {black}\n\
             display_reflectance = {reflectance}\n"
        );
        let (pixels, metrics) =
            display_luminance(dir.path(), &lit_wall_scene(white, &display, FRONTAL));
        assert!(pixels.len() > 20, "{} display pixels", pixels.len());
        // metrics.json: every display pixel's ratio is the analytic one, and a visible step.
        let lum = &metrics["luminance"]["display"];
        assert_eq!(lum["pixels"].as_u64(), Some(pixels.len() as u64), "{lum}");
        let stops = (expected / wall).log2();
        for stat in ["mean", "max"] {
            let got = lum["ratio_log2"][stat].as_f64().unwrap();
            assert!((got - stops).abs() < 0.01, "{stat}: {got} vs {stops} stops");
        }
        assert_eq!(lum["visible_share"].as_f64(), Some(1.0), "{lum}");
        let border = &metrics["luminance"]["border"];
        assert!(border["pixels"].as_u64().unwrap() > 0, "{border}");
        for (seen, truth) in pixels {
            assert!(
                relative_error(truth, wall) < 0.005,
                "truth {truth} vs {wall}"
            );
            assert!(
                relative_error(seen, expected) < 0.005,
                "white {white}, reflectance {reflectance}: {seen} vs {expected} cd/m²"
            );
        }
    }
    // A lamp of 100 cd half a metre in front of the display's centre: the face reflects 5 %
    // of its I cos θ / d² besides the sun's, pixel by pixel (the display's points from the
    // occluded view).
    let lamp = glam::DVec3::new(0.0, 1.2, -0.3);
    let display = format!(
        "display_peak_cd_m2 = {peak}\ndisplay_black_cd_m2 = {black}\ndisplay_reflectance = 0.05\n"
    );
    let scene = lit_wall_scene(2.0 * wall, &display, FRONTAL).replace(
        "[obstacle]",
        "[[light]]\nposition = [0.0, 1.2, -0.3]\nintensity_cd = 100.0\n\n[obstacle]",
    );
    let out = seethru_on(dir.path(), &scene, "run", &["--exr", "all"]);
    let occluded = exr_channels(&out.join("occluded.exr"));
    let seethru = luminance(&exr_channels(&out.join("seethru.exr")));
    let obstacle = occluded["id.object"].iter().copied().fold(0.0, f64::max);
    let mut checked = 0;
    for i in (0..seethru.len()).filter(|&i| occluded["id.object"][i] == obstacle) {
        let at = glam::DVec3::new(occluded["P.X"][i], occluded["P.Y"][i], occluded["P.Z"][i]);
        let to = lamp - at;
        let lamp_lux = 100.0 * (to.z / to.length()) / to.length_squared();
        let expected =
            black + (peak - black) * 0.5 + 0.05 * (face + lamp_lux / std::f64::consts::PI);
        assert!(
            relative_error(seethru[i], expected) < 0.005,
            "at {at}: {} vs {expected}",
            seethru[i]
        );
        checked += 1;
    }
    assert!(checked > 20, "{checked}");
    // Without the keys, an ideal display: the wall's luminance, whatever the white, and no
    // visible step.
    let (pixels, metrics) = display_luminance(dir.path(), &lit_wall_scene(wall / 4.0, "", FRONTAL));
    for (seen, _) in pixels {
        assert!(relative_error(seen, wall) < 0.005, "{seen} vs {wall}");
    }
    let lum = &metrics["luminance"]["display"];
    assert_eq!(lum["visible_share"].as_f64(), Some(0.0), "{lum}");
    assert!(
        lum["ratio_log2"]["max"].as_f64().unwrap().abs() < 0.01,
        "{lum}"
    );
}

/// A grey floor seen from 5 m straight above, lit only by `lamps` (no sun, a black sky, the
/// white at 10 cd/m²): per floor pixel, its world position and its luminance (cd/m²).
fn floor_under_lamps(grey: f64, lamps: &str, extra_objects: &str) -> Vec<(glam::DVec3, f64)> {
    floor_pixels(&floor_under_lamps_scene(grey, lamps, extra_objects))
}

/// The scene of [`floor_under_lamps`].
fn floor_under_lamps_scene(grey: f64, lamps: &str, extra_objects: &str) -> String {
    format!(
        r#"[sun]
illuminance_lux = 0
[sky]
zenith_luminance_cd_m2 = 0
cloud_cover = 0
[photometry]
white_cd_m2 = 10
{lamps}
[obstacle]
center = [0.0, 5.0, -0.8]
width = 0.3
height = 0.4

[camera.driver]
position = [0.0, 5.0, 0.0]
look_at = [0.0, 0.0, 0.0]
up = [0.0, 0.0, -1.0]
half_angle_deg = 40.0
resolution = [96, 96]

[camera.frontal]
resolution = [16, 12]

[camera.back]
resolution = [16, 12]

[[material]]
name = "grey"
color = [{grey}, {grey}, {grey}]

[[object]]
name = "floor"
kind = "plane"
material = "grey"
size = [100.0, 100.0]
{extra_objects}"#
    )
}

/// The floor's pixels (object 1) of `scene`'s truth view: per pixel, its world position and
/// its luminance (cd/m²).
fn floor_pixels(scene: &str) -> Vec<(glam::DVec3, f64)> {
    let dir = tempfile::tempdir().unwrap();
    let out = seethru_on(dir.path(), scene, "render", &["--view", "truth"]);
    let channels = exr_channels(&out.join("truth.exr"));
    let [px, py, pz, id] = ["P.X", "P.Y", "P.Z", "id.object"].map(|c| &channels[c]);
    (luminance(&channels).into_iter().enumerate())
        .filter(|&(i, _)| id[i] == 1.0)
        .map(|(i, y)| (glam::DVec3::new(px[i], py[i], pz[i]), y))
        .collect()
}

#[test]
fn a_point_lamp_lights_a_floor_by_the_inverse_square_and_cosine_laws() {
    let (grey, intensity) = (0.5, 500.0);
    let rho = f64::from(srgb_to_linear(grey as f32));
    let lamp = glam::DVec3::new(1.0, 2.0, -1.0);
    let lamps = format!(
        "[[light]]\nkind = \"point\"\nposition = [1.0, 2.0, -1.0]\nintensity_cd = {intensity}\ncolor = [1.0, 0.8, 0.6]\n"
    );
    let pixels = floor_under_lamps(grey, &lamps, "");
    assert!(pixels.len() > 5000, "{}", pixels.len());
    for (p, y) in pixels {
        let d = lamp - p;
        let expected =
            rho * intensity * (d.y / d.length()) / (std::f64::consts::PI * d.length_squared());
        assert!(
            relative_error(y, expected) < 0.005,
            "at {p}: {y} vs {expected} cd/m²"
        );
    }
}

/// Three point lamps of different colours and intensities over [`floor_under_lamps`]'s floor.
const THREE_LAMPS: &str = "\
[[light]]\nposition = [-1.5, 2.0, 0.0]\nintensity_cd = 500\ncolor = [1.0, 0.7, 0.4]\n
[[light]]\nposition = [1.5, 2.5, -1.0]\nintensity_cd = 800\ncolor = [0.5, 0.7, 1.0]\n
[[light]]\nposition = [0.0, 3.0, 1.5]\nintensity_cd = 300\n";

type Shade = (f64, [f64; 3]);

/// Per floor pixel of [`floor_under_lamps_scene`] under `lamps`, a sun of `sun_lux` and
/// `extra_objects` (by pixel index): its luminance and linear RGB, with every lamp's shadow ray and with one
/// drawn per sample, at `spp` samples each (the same sub-pixel positions).
fn every_and_one(
    lamps: &str,
    sun_lux: f64,
    extra_objects: &str,
    spp: &str,
) -> std::collections::BTreeMap<usize, (Shade, Shade)> {
    let every = floor_under_lamps_scene(0.5, lamps, extra_objects).replace(
        "illuminance_lux = 0\n",
        &format!("illuminance_lux = {sun_lux}\nelevation_deg = 55\nazimuth_deg = 100\n"),
    );
    let one = one_lamp_drawn(&every);
    let [every, one] = [every, one].map(|scene| {
        let dir = tempfile::tempdir().unwrap();
        let out = seethru_on(
            dir.path(),
            &scene,
            "render",
            &["--view", "truth", "--spp", spp],
        );
        let c = exr_channels(&out.join("truth.exr"));
        (luminance(&c).into_iter().enumerate())
            .filter(|&(i, _)| c["id.object"][i] == 1.0)
            .map(|(i, y)| (i, (y, ["R", "G", "B"].map(|k| c[k][i]))))
            .collect::<Vec<_>>()
    });
    assert!(every.len() > 5000, "{}", every.len());
    assert_eq!(every.len(), one.len());
    assert!(every.iter().zip(&one).all(|(a, b)| a.0 == b.0));
    (every.into_iter().zip(one))
        .map(|((i, a), (_, b))| (i, (a, b)))
        .collect()
}

#[test]
fn one_lamp_drawn_per_sample_gives_the_exact_luminance_where_every_lamp_is_seen() {
    // Unshadowed, the drawn lamp's light over its share of the luminance is the sum's
    // luminance at every pixel; only the colour is the drawn lamp's.
    // The sun, drawn with the lamps, too; and the sun alone (no lamp to draw it with).
    for (lamps, sun_lux) in [(THREE_LAMPS, 0.0), (THREE_LAMPS, 20.0), ("", 20.0)] {
        exact_where_every_lamp_is_seen(lamps, sun_lux);
    }
}

fn exact_where_every_lamp_is_seen(lamps: &str, sun_lux: f64) {
    let pixels = every_and_one(lamps, sun_lux, "", "1");
    let mut recoloured = 0;
    let (mut every_rgb, mut one_rgb) = ([0.0; 3], [0.0; 3]);
    for ((y_every, every), (y_one, one)) in pixels.values() {
        assert!(
            relative_error(*y_one, *y_every) < 1e-4,
            "{y_one} vs {y_every} cd/m²"
        );
        recoloured += usize::from((0..3).any(|k| relative_error(one[k], every[k]) > 0.05));
        for k in 0..3 {
            every_rgb[k] += every[k];
            one_rgb[k] += one[k];
        }
    }
    // Each pixel shows one lamp's colour (the draws differ), and on average the sum's.
    assert!(
        lamps.is_empty() || recoloured * 2 > pixels.len(),
        "{recoloured} of {}",
        pixels.len()
    );
    for k in 0..3 {
        assert!(
            relative_error(one_rgb[k], every_rgb[k]) < 0.02,
            "channel {k}: {} vs {}",
            one_rgb[k],
            every_rgb[k]
        );
    }
}

#[test]
fn one_lamp_drawn_per_sample_is_unbiased_in_the_shadows_of_some_lamps() {
    // A ball over the floor casts one shadow per lamp. Where some lamps are hidden, one drawn
    // lamp per sample averages, over many samples, to what every lamp's ray gives.
    let ball = "[[object]]\nname = \"ball\"\nkind = \"sphere\"\nmaterial = \"grey\"\n\
                radius = 0.4\ntranslate = [0.0, 1.0, 0.0]\n";
    // And with each lamp split into seven of a seventh of its intensity at its place: 21
    // lamps, a longer draw.
    let split: String = (THREE_LAMPS.split("\n\n").map(|lamp| lamp.trim()))
        .flat_map(|lamp| {
            let cd: f64 = lamp
                .split("intensity_cd = ")
                .nth(1)
                .unwrap()
                .split('\n')
                .next()
                .unwrap()
                .parse()
                .unwrap();
            let seventh = lamp.replace(
                &format!("intensity_cd = {cd}"),
                &format!("intensity_cd = {}", cd / 7.0),
            );
            std::iter::repeat_n(format!("{seventh}\n\n"), 7)
        })
        .collect();
    assert_eq!(split.matches("[[light]]").count(), 21);
    // The sun, drawn with them, casts one more shadow.
    for (lamps, sun_lux) in [(THREE_LAMPS, 0.0), (&split, 0.0), (THREE_LAMPS, 20.0)] {
        unbiased_in_the_shadows(lamps, sun_lux, ball);
    }
}

fn unbiased_in_the_shadows(lamps: &str, sun_lux: f64, ball: &str) {
    let unshadowed = every_and_one(lamps, sun_lux, "", "64");
    let pixels = every_and_one(lamps, sun_lux, ball, "64");
    let (mut every, mut one, mut n) = (0.0, 0.0, 0);
    let mut noisy = 0;
    for (i, ((y_every, _), (y_one, _))) in &pixels {
        let y_free = unshadowed[i].0.0;
        // Partly shadowed: some lamp hidden (selected on every lamp's image, not on the
        // drawn one's, so that the noise does not pick the pixels), some still seen.
        if *y_every < 0.95 * y_free && *y_every > 0.05 * y_free {
            every += y_every;
            one += y_one;
            n += 1;
            noisy += usize::from(relative_error(*y_one, *y_every) > 0.01);
        }
    }
    assert!(n > 300, "{n} partly shadowed pixels");
    assert!(noisy * 2 > n, "{noisy} of {n} differ: no lamp drawn?");
    assert!(
        relative_error(one, every) < 0.01,
        "{one} vs {every} over {n} pixels"
    );
}

#[test]
fn a_dark_black_lamp_gives_nothing() {
    // intensity 0 with a black colour is admitted; its light is 0, not 0 / 0, under either
    // way of spending the shadow rays.
    let lit = "[[light]]\nposition = [1.0, 2.0, -1.0]\nintensity_cd = 500\n";
    let dark = "[[light]]\nposition = [0.0, 1.0, 0.0]\nintensity_cd = 0\ncolor = [0, 0, 0]\n";
    let alone = floor_under_lamps(0.5, lit, "");
    for way in ["every", "one"] {
        let scene = floor_under_lamps_scene(0.5, &format!("{lit}\n{dark}"), "").replace(
            "[photometry]\n",
            &format!("[photometry]\nlamp_sampling = \"{way}\"\n"),
        );
        let both = floor_pixels(&scene);
        assert_eq!(both.len(), alone.len());
        for ((_, y), (_, y_alone)) in both.iter().zip(&alone) {
            assert!(
                relative_error(*y, *y_alone) < 1e-6,
                "{way}: {y} vs {y_alone}"
            );
        }
    }
}

#[test]
fn a_spot_lights_its_cone_and_an_object_shades_what_it_hides() {
    let (grey, intensity) = (0.8, 2000.0);
    let rho = f64::from(srgb_to_linear(grey as f32));
    // Straight down from 3 m: full within 20° of the axis, nothing beyond 30°.
    let lamp = glam::DVec3::new(1.5, 3.0, 0.0);
    let lamps = format!(
        "[[light]]\nkind = \"spot\"\nposition = [1.5, 3.0, 0.0]\ndirection = [0.0, -1.0, 0.0]\n\
         intensity_cd = {intensity}\ncone_deg = 30\nfalloff_deg = 20\n"
    );
    // A ball of radius 0.3 m, 1.5 m under the lamp and 0.3 m beside its axis: its shadow on
    // the floor is a disc inside the full beam, mostly beside where the ball hides the floor
    // from the camera.
    let ball = "[[object]]\nname = \"ball\"\nkind = \"sphere\"\nmaterial = \"grey\"\nradius = 0.3\n\
                translate = [1.2, 1.5, 0.0]\n";
    let centre = glam::DVec3::new(1.2, 1.5, 0.0);
    let (mut lit, mut dark, mut shaded) = (0, 0, 0);
    for (p, y) in floor_under_lamps(grey, &lamps, ball) {
        let to = lamp - p;
        let angle = (-to.normalize())
            .angle_between(glam::DVec3::NEG_Y)
            .to_degrees();
        // Does the segment from the floor point to the lamp pass through the ball?
        let dir = to.normalize();
        let oc = p - centre;
        let b = oc.dot(dir);
        let disc = b * b - (oc.length_squared() - 0.09);
        let blocked = disc > 0.0 && -b - disc.sqrt() > 0.0 && -b - disc.sqrt() < to.length();
        let margin = 0.02 * (p - lamp).length(); // pixels at a shadow's or a cone's edge
        let near_edge =
            (disc.abs() < margin) || (angle - 20.0).abs() < 0.5 || (angle - 30.0).abs() < 0.5;
        if near_edge {
            continue;
        }
        let expected = if blocked || angle > 30.0 {
            0.0
        } else {
            let profile = if angle < 20.0 {
                1.0
            } else {
                let (c, c0, c1) = (
                    angle.to_radians().cos(),
                    30f64.to_radians().cos(),
                    20f64.to_radians().cos(),
                );
                let t = (c - c0) / (c1 - c0);
                t * t * (3.0 - 2.0 * t)
            };
            rho * intensity * profile * (to.y / to.length())
                / (std::f64::consts::PI * to.length_squared())
        };
        if expected == 0.0 {
            assert_eq!(y, 0.0, "at {p} (angle {angle:.1}°, blocked {blocked})");
            if blocked && angle < 30.0 {
                shaded += 1
            } else {
                dark += 1
            }
        } else {
            assert!(
                relative_error(y, expected) < 0.005,
                "at {p} (angle {angle:.1}°): {y} vs {expected}"
            );
            lit += 1;
        }
    }
    assert!(
        lit > 500 && dark > 1000 && shaded > 30,
        "{lit} lit, {dark} dark, {shaded} in the shadow"
    );
}

#[test]
fn a_low_beams_cut_off_line_darkens_everything_above_it() {
    let (grey, intensity) = (0.8, 2000.0);
    let rho = f64::from(srgb_to_linear(grey as f32));
    // A spot 3 m up aimed 40° from straight down towards +x, its cone wide (60°); the cut-off
    // at −60° elevation: the floor is lit only within 3 m / tan 60° = 1.73 m of the lamp's foot.
    let lamp = glam::DVec3::new(0.0, 3.0, 0.0);
    let axis = glam::DVec3::new(40f64.to_radians().sin(), -40f64.to_radians().cos(), 0.0);
    let lamps = format!(
        "[[light]]\nkind = \"spot\"\nposition = [0.0, 3.0, 0.0]\ndirection = [{}, {}, 0.0]\n\
         intensity_cd = {intensity}\ncone_deg = 60\nfalloff_deg = 60\ncutoff_deg = -60\n",
        axis.x, axis.y
    );
    let (mut lit, mut cut) = (0, 0);
    for (p, y) in floor_under_lamps(grey, &lamps, "") {
        let to = (p - lamp).normalize();
        let elevation = to.y.asin().to_degrees();
        let off_axis = to.angle_between(axis).to_degrees();
        // Pixels straddling the cut-off line or the cone's edge hold both sides.
        if (elevation + 60.0).abs() < 1.0 || (off_axis - 60.0).abs() < 1.0 {
            continue;
        }
        let from = lamp - p;
        let expected = if elevation > -60.0 || off_axis > 60.0 {
            0.0
        } else {
            rho * intensity * (from.y / from.length())
                / (std::f64::consts::PI * from.length_squared())
        };
        if expected == 0.0 {
            assert_eq!(y, 0.0, "at {p} (elevation {elevation:.1}°)");
            cut += usize::from(off_axis < 60.0);
        } else {
            assert!(
                relative_error(y, expected) < 0.005,
                "at {p}: {y} vs {expected}"
            );
            lit += 1;
        }
    }
    // Both sides of the line inside the cone.
    assert!(
        lit > 300 && cut > 300,
        "{lit} lit, {cut} cut off inside the cone"
    );
}

#[test]
fn lamps_are_refused_where_they_cannot_shine() {
    let spot_key = parse(&floor_scene(
        0.5,
        "[sun]\nilluminance_lux = 100\n[[light]]\nposition = [0, 1, 0]\ncone_deg = 10\n",
    ))
    .unwrap_err()
    .to_string();
    assert!(
        spot_key.contains("`light[0].cone_deg`") && spot_key.contains("kind = \"spot\""),
        "{spot_key}"
    );
    let relative = parse(&floor_scene(0.5, "[[light]]\nposition = [0, 1, 0]\n"))
        .unwrap_err()
        .to_string();
    assert!(
        relative.contains("light") && relative.contains("physical units"),
        "{relative}"
    );
    let many: String = (0..65)
        .map(|_| "[[light]]\nposition = [0, 1, 0]\n")
        .collect();
    let e = parse(&floor_scene(
        0.5,
        &format!("[sun]\nilluminance_lux = 100\n{many}"),
    ))
    .unwrap_err()
    .to_string();
    assert!(e.contains("more than the limit of 64"), "{e}");
}

#[test]
fn lamps_and_glossy_coats_render_the_same_on_the_per_ray_and_the_packet_paths_and_on_any_thread_count()
 {
    // das_night's lamps, every lamp's shadow ray or one drawn per sample; left_turn_night's
    // lamps on its wet streets, also drawn.
    for (name, one) in [
        ("das_night.toml", false),
        ("das_night.toml", true),
        ("left_turn_night.toml", false),
        ("left_turn_night.toml", true),
    ] {
        lamps_render_the_same_on_every_path(name, one);
    }
}

/// `text` (a scene with a `[photometry]` table) with `lamp_sampling = "one"` in it.
fn one_lamp_drawn(text: &str) -> String {
    assert!(text.contains("[photometry]\n"));
    text.replace("[photometry]\n", "[photometry]\nlamp_sampling = \"one\"\n")
}

fn lamps_render_the_same_on_every_path(name: &str, one: bool) {
    use seethru::render::integrator::RenderContext;
    use seethru::render::render_job::{RenderJob, Tracer};
    use seethru::render::simd::Isa;
    use seethru::scene::world::view_bit;
    let mut text = std::fs::read_to_string(common::repo_path("scenes").join(name)).unwrap();
    if one {
        text = one_lamp_drawn(&text);
    }
    let scene = common::parse_in(&common::repo_path("scenes"), name, &text).unwrap();
    let drawn = (scene.photometry.as_ref()).map(|p| p.lamp_sampling);
    assert_eq!(drawn == Some(seethru::scene::LampSampling::One), one);
    assert!(scene.lights.len() >= 3);
    let ctx = RenderContext::new(scene).unwrap();
    let camera = ctx.scene.driver.with_resolution(96, 54);
    let render = |tracer: Tracer, threads: usize| {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap();
        pool.install(|| {
            let job = RenderJob::new(&camera, view_bit::TRUTH)
                .label("test")
                .tracer(tracer);
            ctx.render(job).0.color
        })
    };
    let twin = render(Tracer::PerRay, 1);
    assert!(twin.iter().any(|c| c.max_element() > 0.0), "a black night");
    for isa in Isa::ALL.into_iter().filter(|i| i.available()) {
        for threads in [1, 3] {
            let colour = render(Tracer::Packets(isa), threads);
            let same = twin
                .iter()
                .zip(&colour)
                .all(|(a, b)| a.to_array().map(f32::to_bits) == b.to_array().map(f32::to_bits));
            assert!(
                same,
                "{name} (one lamp drawn: {one}): {isa:?} on {threads} threads"
            );
        }
    }
}

#[test]
fn a_display_turns_a_coded_cameras_codes_into_light_by_its_transfer_curve() {
    let dir = tempfile::tempdir().unwrap();
    let (peak, black) = (500.0, 1.0);
    // A camera whose automatic exposure puts the wall at 0.3 of full scale, its codes
    // noise-free enough to be one code in every channel: no read noise or dark current, and
    // 3·10⁶ electrons (a shot noise of 0.06 %, a code's step 1.6 %).
    let camera = "resolution = [64, 36]\nexposure_ms = 300\nsensor = \"emva\"\n\
                  full_well_e = 10000000\nread_noise_e = 0\ndark_current_e_s = 0\n\
                  auto_exposure = \"average\"\nauto_target = 0.3\n";
    let srgb = |x: f64| {
        if x <= 0.0031308 {
            12.92 * x
        } else {
            1.055 * x.powf(1.0 / 2.4) - 0.055
        }
    };
    let srgb_decode = |v: f64| {
        if v <= 0.04045 {
            v / 12.92
        } else {
            ((v + 0.055) / 1.055).powf(2.4)
        }
    };
    // (camera curve and bits, display transfer, the share of the range the display gives)
    let code8 = |x: f64| (srgb(x) * 255.0).round() / 255.0;
    let code12 = |x: f64| (x.powf(1.0 / 2.2) * 4095.0).round() / 4095.0;
    let cases: [(&str, &str, f64); 4] = [
        // Matched curves: linear again, within the 8-bit code.
        (
            "tone_curve = \"srgb\"\noutput_bits = 8",
            "srgb",
            srgb_decode(code8(0.3)),
        ),
        // An sRGB camera on a 2.4-gamma display: the mid-tones darker.
        (
            "tone_curve = \"srgb\"\noutput_bits = 8",
            "gamma2.4",
            code8(0.3).powf(2.4),
        ),
        // A 2.2-gamma camera at 12 bits on a 2.2-gamma display.
        (
            "tone_curve = \"gamma2.2\"\noutput_bits = 12",
            "gamma2.2",
            code12(0.3).powf(2.2),
        ),
        // Codes shown as linear light: brighter.
        (
            "tone_curve = \"srgb\"\noutput_bits = 8",
            "linear",
            code8(0.3),
        ),
    ];
    for (coding, transfer, share) in cases {
        let display = format!(
            "display_peak_cd_m2 = {peak}\ndisplay_black_cd_m2 = {black}\ndisplay_transfer = \"{transfer}\"\n"
        );
        let scene = lit_wall_scene(5000.0, &display, &format!("{camera}{coding}\n"));
        let (pixels, _) = display_luminance(dir.path(), &scene);
        assert!(pixels.len() > 20, "{} display pixels", pixels.len());
        let expected = black + (peak - black) * share;
        for (seen, _) in pixels {
            assert!(
                relative_error(seen, expected) < 0.005,
                "{coding} on {transfer}: {seen} vs {expected} cd/m²"
            );
        }
    }
    // A coded camera needs a display that makes light of codes.
    let e = common::parse(&lit_wall_scene(
        5000.0,
        "",
        &format!("{camera}tone_curve = \"srgb\"\n"),
    ))
    .map(|_| ())
    .unwrap_err()
    .to_string();
    assert!(
        e.contains("`camera.frontal.tone_curve`") && e.contains("display_peak_cd_m2"),
        "{e}"
    );
}

#[test]
fn score_shows_a_methods_display_image_as_linear_light_or_as_the_displays_codes() {
    let dir = tempfile::tempdir().unwrap();
    let (peak, black) = (500.0, 1.0);
    let display = format!(
        "display_peak_cd_m2 = {peak}\ndisplay_black_cd_m2 = {black}\ndisplay_transfer = \"gamma2.2\"\n"
    );
    let scene = lit_wall_scene(5000.0, &display, FRONTAL);
    let capture = seethru_on(dir.path(), &scene, "capture", &[]);
    let calibration: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(capture.join("calibration.json")).unwrap())
            .unwrap();
    let size = &calibration["display"]["resolution_px"];
    let (w, h) = (
        size[0].as_u64().unwrap() as u32,
        size[1].as_u64().unwrap() as u32,
    );
    // One flat image: 8-bit value 128 everywhere.
    let png = dir.path().join("flat.png");
    image::RgbImage::from_pixel(w, h, image::Rgb([128, 128, 128]))
        .save(&png)
        .unwrap();
    let shown = |codes: bool| {
        let out = dir.path().join(if codes { "codes" } else { "linear" });
        let mut args = vec![
            "score".to_string(),
            capture.display().to_string(),
            "--display-image".into(),
            png.display().to_string(),
            "--quiet".into(),
            "--out".into(),
            out.display().to_string(),
        ];
        if codes {
            args.push("--display-codes".into());
        }
        let (ok, _, err) = common::seethru(&args);
        assert!(ok, "{err}");
        let occluded = exr_channels(&out.join("occluded.exr"))["id.object"].clone();
        let obstacle = occluded.iter().copied().fold(0.0, f64::max);
        let seen = luminance(&exr_channels(&out.join("seethru.exr")));
        let pixels: Vec<f64> = (0..seen.len())
            .filter(|&i| occluded[i] == obstacle)
            .map(|i| seen[i])
            .collect();
        assert!(pixels.len() > 20);
        pixels
    };
    // Linear light (the PNG's sRGB decoded): the display gives off that share of its range,
    // whatever its transfer curve.
    let linear = f64::from(srgb_to_linear(128.0 / 255.0));
    for seen in shown(false) {
        let expected = black + (peak - black) * linear;
        assert!(
            relative_error(seen, expected) < 0.005,
            "{seen} vs {expected}"
        );
    }
    // Codes: the display's 2.2 gamma of code 128.
    for seen in shown(true) {
        let expected = black + (peak - black) * (128.0f64 / 255.0).powf(2.2);
        assert!(
            relative_error(seen, expected) < 0.005,
            "{seen} vs {expected}"
        );
    }
    // Codes for a display that makes no light of codes: one line naming it.
    let ideal = seethru_on(
        dir.path(),
        &lit_wall_scene(5000.0, "", FRONTAL),
        "capture",
        &[],
    );
    let (ok, _, err) = common::seethru(&[
        "score",
        ideal.to_str().unwrap(),
        "--display-image",
        png.to_str().unwrap(),
        "--display-codes",
        "--out",
        dir.path().join("refused").to_str().unwrap(),
    ]);
    assert!(
        !ok && err.starts_with("error:") && err.contains("display_peak_cd_m2"),
        "{err}"
    );
}

#[test]
fn a_low_beams_kerb_side_cut_off_rises_at_fifteen_degrees() {
    let (grey, intensity) = (0.8, 2000.0);
    let rho = f64::from(srgb_to_linear(grey as f32));
    // A beam 0.7 m up at z = 6 aimed along −z, its cone wide (80°), cut off at −10°, its kerb
    // to the right (+x). Below the flat line (elevation ≤ −10°) it lights everywhere; on the
    // kerb side (l > 0) also below the rising line, which on a screen across the axis
    // (forward f, height v) is v / f ≤ tan(−10°) + (l / f) tan 15°, as ECE R112 draws it.
    let lamp = glam::DVec3::new(0.0, 0.7, 6.0);
    let beam = |kerb: &str| {
        format!(
            "[[light]]\nkind = \"spot\"\nposition = [0.0, 0.7, 6.0]\ndirection = [0.0, 0.0, -1.0]\n\
             intensity_cd = {intensity}\ncone_deg = 80\nfalloff_deg = 80\ncutoff_deg = -10\n{kerb}"
        )
    };
    let (tan_c, tan_15) = ((-10f64).to_radians().tan(), 15f64.to_radians().tan());
    let mut stepped = 0;
    for (kerb, rises) in [("cutoff_kerb = \"right\"\n", 1.0), ("", 0.0)] {
        for (p, y) in floor_under_lamps(grey, &beam(kerb), "") {
            let to = p - lamp;
            let (f, l, v) = (-to.z, to.x, to.y);
            let sin_c = (-10f64).to_radians().sin();
            let flat = v / to.length() <= sin_c;
            let line = tan_c + (l / f) * tan_15;
            let step = rises > 0.0 && l > 0.0 && v / f <= line;
            // Pixels straddling either line, or the cone's edge, hold both sides.
            let near_line = (v / to.length() - sin_c).abs() * to.length() < 0.05
                || (rises > 0.0 && l > 0.0 && (v / f - line).abs() * f < 0.05);
            let off_axis = to.angle_between(glam::DVec3::NEG_Z).to_degrees();
            if f <= 0.0 || near_line || (off_axis - 80.0).abs() < 1.0 {
                continue;
            }
            let lit = off_axis < 80.0 && (flat || step);
            if lit {
                let from = -to;
                let expected = rho * intensity * (from.y / from.length())
                    / (std::f64::consts::PI * from.length_squared());
                assert!(
                    relative_error(y, expected) < 0.005,
                    "at {p}: {y} vs {expected}"
                );
                stepped += usize::from(rises > 0.0 && !flat);
            } else {
                assert_eq!(y, 0.0, "at {p} ({kerb:?})");
            }
        }
    }
    // The step-up lights a region of its own, beyond the flat line on the kerb side.
    assert!(stepped > 200, "{stepped} pixels lit by the step-up");
    // A step-up needs a cut-off line to raise.
    let e = parse(&floor_scene(
        0.5,
        "[sun]\nilluminance_lux = 0\n[sky]\nzenith_luminance_cd_m2 = 0\n[photometry]\nwhite_cd_m2 = 10\n\
         [[light]]\nkind = \"spot\"\nposition = [0.0, 1.0, 0.0]\ncutoff_kerb = \"right\"\n",
    ))
    .map(|_| ())
    .unwrap_err()
    .to_string();
    assert!(
        e.contains("`light[0].cutoff_kerb`") && e.contains("cutoff_deg"),
        "{e}"
    );
}

/// The GGX lobe's BRDF with Schlick's Fresnel and the height-correlated Smith term, as pbrt-v4
/// and Heitz (2014) write it, in f64: for light from `wi` seen from `wo` (unit vectors from a
/// surface of normal `n`).
fn ggx_brdf(f0: f64, alpha: f64, n: glam::DVec3, wi: glam::DVec3, wo: glam::DVec3) -> f64 {
    let h = (wi + wo).normalize();
    let a2 = alpha * alpha;
    let d = a2 / (std::f64::consts::PI * (n.dot(h).powi(2) * (a2 - 1.0) + 1.0).powi(2));
    let f = f0 + (1.0 - f0) * (1.0 - wo.dot(h)).powi(5);
    let lambda = |w: glam::DVec3| {
        let c = n.dot(w);
        ((1.0 + a2 * (1.0 - c * c) / (c * c)).sqrt() - 1.0) / 2.0
    };
    let g = 1.0 / (1.0 + lambda(wi) + lambda(wo));
    d * f * g / (4.0 * n.dot(wi) * n.dot(wo))
}

/// `scene` with keys added to its material `grey`.
fn grey_with(scene: &str, keys: &str) -> String {
    let named = "name = \"grey\"\n";
    assert!(scene.contains(named));
    scene.replacen(named, &format!("{named}{keys}\n"), 1)
}

#[test]
fn a_glossy_floor_under_a_lamp_adds_the_ggx_lobe_to_what_its_albedo_diffuses() {
    // A damp grey floor (F0 0.04, α 0.3) under a point lamp: per pixel, (1 − F0) ρ I cos/πd²
    // diffused and f I cos/d² reflected by the lobe, toward the camera 5 m above the origin.
    let (grey, intensity, f0, alpha) = (0.5, 500.0, 0.04, 0.3);
    let rho = f64::from(srgb_to_linear(grey as f32));
    let (lamp, eye) = (
        glam::DVec3::new(1.0, 2.0, -1.0),
        glam::DVec3::new(0.0, 5.0, 0.0),
    );
    let lamps = format!("[[light]]\nposition = [1.0, 2.0, -1.0]\nintensity_cd = {intensity}\n");
    let scene = grey_with(
        &floor_under_lamps_scene(grey, &lamps, ""),
        &format!("specular = {f0}\nroughness = {alpha}"),
    );
    let pixels = floor_pixels(&scene);
    assert!(pixels.len() > 5000, "{}", pixels.len());
    let mut glossiest: f64 = 0.0;
    for (p, y) in pixels {
        let (to_lamp, to_eye) = ((lamp - p).normalize(), (eye - p).normalize());
        let irradiance = intensity * to_lamp.y / (lamp - p).length_squared();
        let lobe = ggx_brdf(f0, alpha, glam::DVec3::Y, to_lamp, to_eye) * irradiance;
        let expected = (1.0 - f0) * rho * irradiance / std::f64::consts::PI + lobe;
        glossiest = glossiest.max(lobe / expected);
        assert!(
            relative_error(y, expected) < 0.005,
            "at {p}: {y} vs {expected} cd/m²"
        );
    }
    // The highlight is in the picture: somewhere the lobe gives a third of the light.
    assert!(glossiest > 0.3, "{glossiest}");
}

#[test]
fn a_wet_black_floor_mirrors_the_low_sun_where_the_angles_of_incidence_and_reflection_meet() {
    // A black floor with a smooth coat (F0 0.5, α 0.05) under a sun 15° high in the south
    // (+z), filmed from 1.2 m looking south: the only light is the lobe's, f E cos θ, and it
    // peaks where the view's ray meets the floor 15° below the horizon, at z = 1.2 / tan 15°.
    let (lux, elevation, f0, alpha) = (100_000.0, 15.0, 0.5, 0.05);
    let light = format!(
        "[sun]\nilluminance_lux = {lux}\nelevation_deg = {elevation}\nazimuth_deg = 180\n\
         [sky]\nzenith_luminance_cd_m2 = 0\ncloud_cover = 0\n\
         [photometry]\nwhite_cd_m2 = 5000\n"
    );
    let scene = grey_with(
        &floor_scene(0.0, &light),
        &format!("specular = {f0}\nroughness = {alpha}"),
    );
    let sun = sun_direction(elevation, 180.0);
    let eye = glam::DVec3::new(0.0, 1.2, 0.0);
    let pixels = floor_pixels(&scene);
    assert!(pixels.len() > 300, "{}", pixels.len());
    for &(p, y) in &pixels {
        let expected =
            ggx_brdf(f0, alpha, glam::DVec3::Y, sun, (eye - p).normalize()) * lux * sun.y;
        assert!(
            (y - expected).abs() < 0.005 * expected + 1e-9 * lux,
            "at {p}: {y} vs {expected} cd/m²"
        );
    }
    let (peak, _) = (pixels.iter()).fold((glam::DVec3::ZERO, 0.0), |best, &(p, y)| {
        if y > best.1 { (p, y) } else { best }
    });
    let mirror = glam::DVec3::new(0.0, 0.0, 1.2 / elevation.to_radians().tan());
    // A pixel here spans some 0.1 m across and 0.4 m along the view.
    assert!(
        (peak.x - mirror.x).abs() < 0.15 && (peak.z - mirror.z).abs() < 0.5,
        "the highlight at {peak}, the mirror point at {mirror}"
    );
    // A wall 2 m high and 1 m wide at z = 8 m shades the floor up to 2 m / tan 15° = 7.5 m
    // before it, the mirror point too: there the lobe gets no sun.
    let wall = "[[object]]\nname = \"wall\"\nkind = \"box\"\nmaterial = \"grey\"\n\
                size = [1.0, 2.0, 0.2]\ntranslate = [0.0, 1.0, 8.0]\n";
    let shaded: Vec<(glam::DVec3, f64)> = floor_pixels(&format!("{scene}{wall}"))
        .into_iter()
        .filter(|(p, _)| p.x.abs() < 0.4 && p.z > 1.0 && p.z < 7.4)
        .collect();
    assert!(shaded.len() > 20, "{}", shaded.len());
    assert!(shaded.iter().all(|&(_, y)| y == 0.0), "{shaded:?}");
}

#[test]
fn a_mirror_floor_shows_the_lit_wall_before_it_and_the_black_sky_around_it() {
    // A black floor under a perfect, smooth coat (F0 1, α 0.01) before a white wall 4 m wide
    // and 3 m high whose face is at z = 7.9 m, lit by a sun 30° high behind the camera,
    // under a black sky; 16 samples a pixel. Where a floor point's mirror ray (the view's
    // ray reflected about the floor) meets the wall at least 0.4 m inside its edges, the
    // floor shows the wall's luminance, less what GGX's long tail sends past the wall (0.4 %
    // on average here) and never more (the weight G2/G1 is at most 1, and the sun's disc,
    // behind the camera, is not gathered); where it passes the wall by 0.4 m, the sky's black
    // but for that tail. Without reflection rays the whole floor would be black; a reflection
    // mirrored the wrong way across or along the view would swap the two sets.
    let light = "[sun]\nilluminance_lux = 100000\nelevation_deg = 30\nazimuth_deg = 0\n\
                 [sky]\nzenith_luminance_cd_m2 = 0\ncloud_cover = 0\n\
                 [photometry]\nwhite_cd_m2 = 5000\n";
    let wall = "[[material]]\nname = \"white\"\ncolor = [0.8, 0.8, 0.8]\n\
                [[object]]\nname = \"wall\"\nkind = \"box\"\nmaterial = \"white\"\n\
                size = [4.0, 3.0, 0.2]\ntranslate = [0.0, 1.5, 8.0]\n";
    let scene = grey_with(&floor_scene(0.0, light), "specular = 1\nroughness = 0.01");
    let dir = tempfile::tempdir().unwrap();
    let out = seethru_on(
        dir.path(),
        &format!("{scene}{wall}"),
        "render",
        &["--view", "truth", "--width", "160", "--spp", "16"],
    );
    let channels = exr_channels(&out.join("truth.exr"));
    let [px, py, pz, id] = ["P.X", "P.Y", "P.Z", "id.object"].map(|c| &channels[c]);
    let y = luminance(&channels);
    let mut wall: Vec<f64> = (0..y.len())
        .filter(|&i| id[i] == 2.0)
        .map(|i| y[i])
        .collect();
    assert!(wall.len() > 500, "{}", wall.len());
    wall.sort_by(f64::total_cmp);
    let lw = wall[wall.len() / 2];
    assert!(lw > 1000.0, "{lw}");
    let eye = glam::DVec3::new(0.0, 1.2, 0.0);
    let (mut inside, mut outside) = (Vec::new(), Vec::new());
    for i in (0..y.len()).filter(|&i| id[i] == 1.0) {
        let p = glam::DVec3::new(px[i], py[i], pz[i]);
        let view = (p - eye).normalize();
        let mirror = glam::DVec3::new(view.x, -view.y, view.z);
        let t = (7.9 - p.z) / mirror.z;
        let q = p + mirror * t;
        assert!(
            y[i] <= 1.01 * lw,
            "at {p}: {} brighter than the wall's {lw}",
            y[i]
        );
        if t > 0.0 && q.x.abs() < 1.6 && q.y > 0.4 && q.y < 2.6 {
            inside.push(y[i] / lw);
        } else if t <= 0.0 || q.x.abs() > 2.4 || q.y > 3.4 {
            outside.push(y[i] / lw);
        }
    }
    assert!(
        inside.len() > 100 && outside.len() > 100,
        "{} inside, {} outside",
        inside.len(),
        outside.len()
    );
    let mean = |v: &[f64]| v.iter().sum::<f64>() / v.len() as f64;
    let bright = inside.iter().filter(|&&r| r > 0.8).count() as f64 / inside.len() as f64;
    assert!(
        mean(&inside) > 0.97 && bright > 0.95,
        "inside: mean {}, {bright} above 0.8",
        mean(&inside)
    );
    assert!(mean(&outside) < 0.05, "outside: mean {}", mean(&outside));
}
