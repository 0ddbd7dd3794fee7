//! `[sun]`, `[sky]` and `[photometry]`: the scene's light, in relative units (a multiplier
//! of the sun, one of the sky's ambient light) or, once `[sun] illuminance_lux` is given, in
//! physical ones (lux and cd/m²: [`Photometry`]).

use glam::DVec3;

use crate::scene::limits::{MAX_LENGTH, MIN_LENGTH};
use crate::scene::motion::MovesWith;
use crate::scene::source::SceneError;
use crate::scene::sun_position::{UtcInstant, parse_date, parse_time, sun_angles};
use crate::scene::table_reader::TableReader;
use crate::scene::{DisplayLight, Lamp, LampSampling, Photometry, Sky, Spot, Sun};
use crate::util::color::srgb_to_linear3;

/// Brightest sunlight at sea level (a clear zenith sun gives about 100–130 klx), lux.
pub const MAX_SUN_LUX: f64 = 150_000.0;
/// Brightest sky (a bright overcast or hazy sky near the sun reaches some 10⁴), cd/m².
pub const MAX_SKY_CD_M2: f64 = 100_000.0;
/// The range of the luminance shown as white: from below starlight to above the sun's disc.
pub const WHITE_CD_M2_RANGE: (f64, f64) = (1e-6, 1e10);

/// The unit direction towards a sun at `elevation_deg` above the horizon and `azimuth_deg`
/// clockwise from north seen from above, in the world frame: y up, north −z, east +x (the
/// axes OpenDRIVE's x east, y north map onto).
pub fn sun_direction(elevation_deg: f64, azimuth_deg: f64) -> DVec3 {
    let (el, az) = (elevation_deg.to_radians(), azimuth_deg.to_radians());
    DVec3::new(az.sin() * el.cos(), el.sin(), -az.cos() * el.cos())
}

/// The three ways `[sun]` places the sun, each a set of keys that go together.
const SUN_PLACEMENTS: [&[&str]; 3] = [
    &["direction"],
    &["elevation_deg", "azimuth_deg"],
    &["date", "time_utc", "latitude_deg", "longitude_deg"],
];

/// The direction towards the sun: `direction`, or its elevation and azimuth, or the date, the
/// time and the place (`scene/sun_position.rs`; north is −z); `default` without any.
fn read_sun_direction(t: &TableReader, default: DVec3) -> Result<DVec3, SceneError> {
    let given: Vec<&[&str]> = (SUN_PLACEMENTS.iter().copied())
        .filter(|keys| keys.iter().any(|k| t.has(k)))
        .collect();
    let keys = match given[..] {
        [] => return Ok(default),
        [keys] => keys,
        [a, b, ..] => {
            return Err(t.error(
                b.iter().find(|k| t.has(k)).expect("one is given"),
                format!(
                    "places the sun as `{}` does: give one of `direction`, `elevation_deg` with                      `azimuth_deg`, or `date`, `time_utc`, `latitude_deg` and `longitude_deg`",
                    a.iter().find(|k| t.has(k)).expect("one is given")
                ),
            ));
        }
    };
    if let Some(missing) = keys.iter().find(|k| !t.has(k)) {
        return Err(t.error(
            missing,
            format!(
                "is required with {}",
                keys.iter()
                    .filter(|k| t.has(k))
                    .map(|k| format!("`{k}`"))
                    .collect::<Vec<_>>()
                    .join(", ")
            ),
        ));
    }
    match keys.len() {
        1 => t.direction("direction", default.to_array()),
        2 => {
            let elevation = t.f64_in("elevation_deg", 0.0, -90.0, 90.0)?;
            let azimuth = t.f64_in("azimuth_deg", 0.0, 0.0, 360.0)?;
            Ok(sun_direction(elevation, azimuth))
        }
        _ => {
            let (year, month, day) =
                parse_date(t.required_str("date")?).map_err(|e| t.error("date", e))?;
            let seconds =
                parse_time(t.required_str("time_utc")?).map_err(|e| t.error("time_utc", e))?;
            let latitude = t.f64_in("latitude_deg", 0.0, -90.0, 90.0)?;
            let longitude = t.f64_in("longitude_deg", 0.0, -180.0, 180.0)?;
            let at = UtcInstant {
                year,
                month,
                day,
                seconds,
            };
            let (elevation, azimuth) = sun_angles(&at, latitude, longitude);
            Ok(sun_direction(elevation, azimuth))
        }
    }
}

/// `[sun]`, with its illuminance in lux when the scene states it.
pub fn read_sun(root: &TableReader) -> Result<(Sun, Option<f64>), SceneError> {
    let d = Sun::default();
    let Some(t) = root.table("sun")? else {
        return Ok((d, None));
    };
    let lux = match t.has("illuminance_lux") {
        true => Some(t.f64_in("illuminance_lux", 0.0, 0.0, MAX_SUN_LUX)?),
        false => None,
    };
    if lux.is_some() && t.has("intensity") {
        return Err(t.error(
            "intensity",
            "is a relative multiplier: a scene with `illuminance_lux` states its sun in lux; \
             remove one of the two",
        ));
    }
    let direction = read_sun_direction(&t, d.direction)?;
    let sun = Sun {
        direction,
        color: t.color("color", d.color)?,
        intensity: t.f64_in("intensity", d.intensity, 0.0, 1000.0)?,
    };
    if lux.is_some_and(|lux| lux > 0.0) && srgb_to_linear3(sun.color).max_element() == 0.0 {
        return Err(t.error("color", "is black: a sun with illuminance needs a colour"));
    }
    t.finish()?;
    Ok((sun, lux))
}

/// `[sky]`, with its zenith luminance in cd/m² in a scene whose sun is in lux (`sun_lux`).
pub fn read_sky(root: &TableReader, sun_lux: Option<f64>) -> Result<(Sky, f64), SceneError> {
    let d = Sky::default();
    let Some(t) = root.table("sky")? else {
        return Ok((d, 0.0));
    };
    let zenith_key = "zenith_luminance_cd_m2";
    let zenith = match (sun_lux, t.has(zenith_key)) {
        (None, true) => {
            return Err(t.error(
                zenith_key,
                "needs a sun in lux: add `illuminance_lux` to [sun]",
            ));
        }
        (Some(_), true) => t.f64_in(zenith_key, 0.0, 0.0, MAX_SKY_CD_M2)?,
        _ => 0.0,
    };
    if sun_lux.is_some() && t.has("ambient") {
        return Err(t.error(
            "ambient",
            "is a relative multiplier: a scene with a sun in lux lights its surfaces with the \
             sky's luminance (`zenith_luminance_cd_m2`); remove `ambient`",
        ));
    }
    let sky = Sky {
        zenith_color: t.color("zenith_color", d.zenith_color)?,
        horizon_color: t.color("horizon_color", d.horizon_color)?,
        ground_color: t.color("ground_color", d.ground_color)?,
        ambient: t.f64_in("ambient", d.ambient, 0.0, 1000.0)?,
        cloud_cover: t.f64_in("cloud_cover", d.cloud_cover, 0.0, 1.0)?,
        cloud_height: t.f64_in("cloud_height", d.cloud_height, MIN_LENGTH, MAX_LENGTH)?,
        cloud_size: t.f64_in("cloud_size", d.cloud_size, MIN_LENGTH, MAX_LENGTH)?,
        cloud_seed: t.usize_in("cloud_seed", d.cloud_seed as usize, 0, u32::MAX as usize)? as u32,
    };
    if zenith > 0.0 && srgb_to_linear3(sky.zenith_color).max_element() == 0.0 {
        return Err(t.error(
            "zenith_color",
            format!("is black: it cannot have the luminance {zenith} cd/m² ({zenith_key})"),
        ));
    }
    t.finish()?;
    Ok((sky, zenith))
}

/// `[photometry]` of a scene whose sun is in lux; refused in any other scene.
pub fn read_photometry(
    root: &TableReader,
    sun: &Sun,
    sky: &Sky,
    sun_lux: Option<f64>,
    zenith_cd_m2: f64,
) -> Result<Option<Photometry>, SceneError> {
    let table = root.table("photometry")?;
    let Some(sun_lux) = sun_lux else {
        if table.is_some() {
            return Err(root.error(
                "photometry",
                "needs a sun in lux: add `illuminance_lux` to [sun]",
            ));
        }
        return Ok(None);
    };
    let mut photometry = Photometry {
        sun_illuminance_lux: sun_lux,
        sky_zenith_cd_m2: zenith_cd_m2,
        white_cd_m2: 0.0,
        lamp_sampling: LampSampling::Every,
    };
    let lit_white = photometry.lit_white_cd_m2(sun, sky);
    let (min, max) = WHITE_CD_M2_RANGE;
    photometry.white_cd_m2 = match table {
        Some(t) => {
            let white = match t.has("white_cd_m2") {
                true => t.f64_in("white_cd_m2", 0.0, min, max)?,
                false => lit_white,
            };
            if white < min {
                return Err(t.error(
                    "white_cd_m2",
                    format!(
                        "is required where the sun and the sky give no light to a white \
                         surface (it would be {lit_white} cd/m²): give the luminance the \
                         images show as white, in [{min}, {max}]"
                    ),
                ));
            }
            photometry.lamp_sampling = read_lamp_sampling(&t)?;
            t.finish()?;
            white
        }
        None if lit_white >= min => lit_white,
        None => {
            return Err(root.error(
                "photometry",
                format!(
                    "a [photometry] table with `white_cd_m2` is required where the sun and the \
                     sky give no light to a white surface (it would be {lit_white} cd/m²): \
                     give the luminance the images show as white, in [{min}, {max}]"
                ),
            ));
        }
    };
    Ok(Some(photometry))
}

/// `[photometry] lamp_sampling`: "every" (the default) or "one" ([`LampSampling`]).
fn read_lamp_sampling(t: &TableReader) -> Result<LampSampling, SceneError> {
    Ok(
        match t.choice("lamp_sampling", "every", &["every", "one"])? {
            "one" => LampSampling::One,
            _ => LampSampling::Every,
        },
    )
}

/// The display's luminance range, cd/m²: automotive displays give some 500–1 500, HDR
/// panels up to 10 000.
pub const DISPLAY_PEAK_RANGE: (f64, f64) = (0.01, 100_000.0);

/// The `[obstacle]` keys of the display as a light source, in a scene whose light is in
/// physical units (`photometry`): refused in any other scene. `None` when none is given: an
/// ideal display, which emits the frontal camera's radiance as it is.
pub fn read_display_light(
    t: &TableReader,
    photometry: Option<&Photometry>,
) -> Result<Option<DisplayLight>, SceneError> {
    let keys = [
        "display_peak_cd_m2",
        "display_black_cd_m2",
        "display_reflectance",
        "display_transfer",
    ];
    let Some(first) = keys.iter().find(|k| t.has(k)) else {
        return Ok(None);
    };
    if photometry.is_none() {
        return Err(t.error(
            first,
            "needs a sun in lux: add `illuminance_lux` to [sun] (the display's light is in cd/m²)",
        ));
    }
    let (lo, hi) = DISPLAY_PEAK_RANGE;
    let peak = t.f64_in("display_peak_cd_m2", 1000.0, lo, hi)?;
    let black = t.f64_in("display_black_cd_m2", 0.0, 0.0, peak)?;
    if black >= peak {
        return Err(t.error(
            "display_black_cd_m2",
            format!("must be below display_peak_cd_m2 ({peak}), got {black}"),
        ));
    }
    Ok(Some(DisplayLight {
        peak_cd_m2: peak,
        black_cd_m2: black,
        reflectance: t.f64_in("display_reflectance", 0.0, 0.0, 1.0)?,
        transfer: crate::scene::DisplayTransfer::from_name(t.choice(
            "display_transfer",
            "linear",
            &crate::scene::DisplayTransfer::NAMES,
        )?)
        .expect("a listed name"),
    }))
}

/// `cutoff_kerb` of a spot of axis `direction` and cut-off `cutoff` (degrees): the side whose
/// cut-off line rises at [`crate::scene::KERB_STEP_DEG`].
fn read_kerb_step(
    t: &TableReader,
    direction: glam::DVec3,
    cutoff: Option<f64>,
) -> Result<Option<crate::scene::KerbStep>, SceneError> {
    let side = t.choice("cutoff_kerb", "none", &["none", "right", "left"])?;
    if side == "none" {
        return Ok(None);
    }
    let Some(cutoff) = cutoff else {
        return Err(t.error(
            "cutoff_kerb",
            "raises the cut-off line on the kerb side: it needs cutoff_deg",
        ));
    };
    let forward = glam::DVec3::new(direction.x, 0.0, direction.z);
    if forward.length() < 1e-6 || cutoff.abs() >= 45.0 {
        return Err(t.error(
            "cutoff_kerb",
            "needs a beam aimed near the horizontal (cutoff_deg within ±45° and a direction not straight up or down)",
        ));
    }
    let forward = forward.normalize();
    // Right of the axis, seen from above with +y up: forward × up.
    let right = forward.cross(glam::DVec3::Y);
    Ok(Some(crate::scene::KerbStep {
        forward,
        kerb: if side == "right" { right } else { -right },
        cutoff_tan: cutoff.to_radians().tan(),
    }))
}

/// Most `[[light]]` tables a scene may have (each lit point traces a shadow ray per light).
pub const MAX_LIGHTS: usize = 64;
/// Brightest lamp: a high beam's axis gives some 100 000 cd.
pub const MAX_INTENSITY_CD: f64 = 1e7;

/// The `[[light]]` tables: point and spot lamps, in a scene lit in physical units.
pub fn read_lights(
    root: &TableReader,
    photometry: Option<&Photometry>,
) -> Result<Vec<Lamp>, SceneError> {
    let tables = root.array_of_tables("light")?;
    if let Some(t) = tables.first()
        && photometry.is_none()
    {
        return Err(t.table_error(
            "a [[light]] gives candelas: it needs a scene lit in physical units (add `illuminance_lux` to [sun])",
        ));
    }
    if tables.len() > MAX_LIGHTS {
        return Err(tables[MAX_LIGHTS].table_error(format!(
            "the scene has {} [[light]] tables, more than the limit of {MAX_LIGHTS}",
            tables.len()
        )));
    }
    let mut lamps = Vec::with_capacity(tables.len());
    for t in tables {
        let kind = t.choice("kind", "point", &["point", "spot"])?;
        let spot_keys = [
            "direction",
            "cone_deg",
            "falloff_deg",
            "cutoff_deg",
            "cutoff_kerb",
        ];
        let spot = if kind == "spot" {
            let cone = t.f64_in("cone_deg", 30.0, 0.01, 90.0)?;
            let falloff = t.f64_in("falloff_deg", cone, 0.0, cone)?;
            let cutoff = t.opt_f64("cutoff_deg")?;
            if let Some(c) = cutoff.filter(|c| !(-90.0..=90.0).contains(c)) {
                return Err(t.error(
                    "cutoff_deg",
                    crate::scene::table_reader::range_message(c, -90.0, 90.0),
                ));
            }
            let direction = t.direction("direction", [0.0, 0.0, -1.0])?;
            Some(Spot {
                direction,
                cos_cone: cone.to_radians().cos(),
                cos_falloff: falloff.to_radians().cos(),
                cutoff_sin: cutoff.map(|c| c.to_radians().sin()),
                kerb_step: read_kerb_step(&t, direction, cutoff)?,
            })
        } else {
            if let Some(key) = spot_keys.iter().find(|k| t.has(k)) {
                return Err(t.error(key, "is a key of kind = \"spot\", but the light is a point"));
            }
            None
        };
        let color = t.color("color", [1.0, 1.0, 1.0])?;
        let intensity = t.f64_in("intensity_cd", 1000.0, 0.0, MAX_INTENSITY_CD)?;
        if intensity > 0.0 && srgb_to_linear3(color).max_element() == 0.0 {
            return Err(t.error("color", "is black: a lamp with intensity needs a colour"));
        }
        lamps.push(Lamp {
            name: t.opt_str("name")?.unwrap_or(kind).to_string(),
            position: t.point("position", None)?,
            intensity_cd: intensity,
            color,
            spot,
            casts_shadow: t.bool_or("casts_shadow", true)?,
            moves_with: match t.choice("moves_with", "world", &["world", "vehicle"])? {
                "vehicle" => MovesWith::Vehicle,
                _ => MovesWith::World,
            },
        });
        t.finish()?;
    }
    Ok(lamps)
}
