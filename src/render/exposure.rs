//! Automatic exposure (geometry/sensor.rs's [`AutoExposure`]): a camera meters its view on a
//! coarse grid of zones, as a camera's statistics block does, and takes the gain that puts
//! the metered signal at its target; a sequence's camera moves towards that gain at its
//! adaptation speed.
//!
//! The metering image is the camera's view at [`METERING_COLUMNS`] zones across (one ray
//! through each zone's centre, the noise-free radiance), whatever the frame's own size or
//! region: the same gain for a frame rendered whole or in part, at any width.

use glam::Vec3;

use crate::geometry::camera::Camera;
use crate::geometry::sensor::{AutoExposure, Metering, Sensor};
use crate::util::color::luminance;

/// Zones across the metering image; its rows follow the camera's aspect.
pub const METERING_COLUMNS: u32 = 64;

/// Bisection steps for the settled gain: 2⁻⁶⁰ of its range in stops.
const BISECTION_STEPS: u32 = 60;

/// The metering image: each zone's weight and noise-free colour (linear, units of the
/// scene's white).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Zones {
    pub weight: Vec<f64>,
    pub colour: Vec<Vec3>,
}

/// An exposure and what the metering makes of it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Metered {
    /// The exposure time, s, [min_exposure_s, the shutter's exposure_ms].
    pub exposure_s: f64,
    /// The gain on top of K, [1, max_gain].
    pub gain: f64,
    /// The metered mean signal, a share of full scale, [0, 1].
    pub share: f64,
    /// Whether the settled exposure is at a bound short of the target.
    pub at_limit: bool,
}

/// The zones of the metering image of `camera`.
pub fn metering_camera(camera: &Camera) -> Camera {
    let rows = (f64::from(METERING_COLUMNS) * f64::from(camera.height) / f64::from(camera.width))
        .round()
        .max(1.0) as u32;
    Camera {
        sensor: None,
        ..camera.with_resolution(METERING_COLUMNS, rows)
    }
}

/// The sensor taking an exposure of `product` seconds at gain 1 (exposure time × gain): the
/// time first, up to the shutter's `exposure_ms` (less noise), then the gain.
pub fn taken(sensor: &Sensor, auto: &AutoExposure, product: f64) -> Sensor {
    let exposure_s = product.clamp(auto.min_exposure_s, auto.max_exposure_s);
    Sensor {
        exposure_s,
        exposure_gain: Some((product / exposure_s).max(1.0)),
        ..*sensor
    }
}

/// The metered mean signal of `zones` taken by `sensor` (its exposure time and gain): each
/// zone's luminance of its channels' mean signals, each clipped at the full well and at the
/// ADC's top code, as a share of full scale.
pub fn metered_share(sensor: &Sensor, zones: &Zones) -> f64 {
    let (k, top) = (sensor.gain(), sensor.max_dn());
    let signal = |v: f32| {
        let electrons = sensor.mean_electrons(f64::from(v.max(0.0)) * sensor.white_cd_m2);
        (k * electrons.min(sensor.full_well_e)).min(top) / top
    };
    let (mut sum, mut weights) = (0.0, 0.0);
    for (c, w) in zones.colour.iter().zip(&zones.weight) {
        let clipped = Vec3::new(signal(c.x) as f32, signal(c.y) as f32, signal(c.z) as f32);
        sum += w * f64::from(luminance(clipped));
        weights += w;
    }
    if weights > 0.0 { sum / weights } else { 0.0 }
}

/// [`Metered`] of `zones` at the exposure `product` (see [`taken`]).
fn metered_at(sensor: &Sensor, auto: &AutoExposure, zones: &Zones, product: f64) -> Metered {
    let s = taken(sensor, auto, product);
    Metered {
        exposure_s: s.exposure_s,
        gain: s.exposure_gain.expect("set"),
        share: metered_share(&s, zones),
        at_limit: false,
    }
}

/// The exposure that puts `zones`' metered signal at the target: its product found by
/// bisection in stops between the shortest time at gain 1 and the longest at the most gain
/// (the metered signal grows with it), or the bound it is pinned at.
pub fn settled(sensor: &Sensor, auto: &AutoExposure, zones: &Zones) -> Metered {
    let (least, most) = (auto.min_exposure_s, auto.max_exposure_s * auto.max_gain);
    let (low, high) = (
        metered_at(sensor, auto, zones, least),
        metered_at(sensor, auto, zones, most),
    );
    if low.share >= auto.target {
        return Metered {
            at_limit: low.share > auto.target,
            ..low
        };
    }
    if high.share <= auto.target {
        return Metered {
            at_limit: high.share < auto.target,
            ..high
        };
    }
    let (mut lo, mut hi) = (least.log2(), most.log2());
    for _ in 0..BISECTION_STEPS {
        let mid = 0.5 * (lo + hi);
        if metered_at(sensor, auto, zones, mid.exp2()).share < auto.target {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    metered_at(sensor, auto, zones, (0.5 * (lo + hi)).exp2())
}

/// The exposure product a sequence's camera takes `dt` seconds after a frame taken at
/// `previous`: towards `settled`, by at most the adaptation speed × `dt` stops.
pub fn adapted(previous: f64, settled: f64, auto: &AutoExposure, dt: f64) -> f64 {
    let step = auto.adaptation_ev_s * dt.max(0.0);
    let stops = settled.log2() - previous.log2();
    if stops.abs() <= step {
        return settled;
    }
    (previous.log2() + step.copysign(stops)).exp2()
}

/// `camera` taking the exposure of `metered`: its sensor's time and gain, and its shutter's
/// time (which sets the motion blur).
pub fn with_exposure(camera: &Camera, metered: &Metered) -> Camera {
    let mut camera = *camera;
    if let Some(sensor) = camera.sensor.as_mut() {
        sensor.exposure_s = metered.exposure_s;
        sensor.exposure_gain = Some(metered.gain);
        camera.shutter.exposure_s = metered.exposure_s;
    }
    camera
}

/// A sequence's camera with an automatic exposure: each frame meters, and the exposure moves
/// from the last frame's towards the settled one at the adaptation speed; the first frame
/// settles (the camera has been running before the sequence starts).
#[derive(Clone, Copy, Debug, Default)]
pub struct Adapting {
    /// The last frame's exposure product (time × gain, s) and its time, s.
    last: Option<(f64, f64)>,
}

impl Adapting {
    /// `camera` exposed for its frame at `t` seconds, `meter` giving the frame's metering
    /// image (called only for a camera with an automatic exposure), and what it metered; any
    /// other camera as it is. Frames of one `t` (a region rendered again) share one exposure.
    pub fn exposed(
        &mut self,
        camera: &Camera,
        meter: impl FnOnce(Metering) -> Zones,
        t: f64,
    ) -> (Camera, Option<Metered>) {
        let Some((sensor, auto)) = camera.sensor.and_then(|s| Some((s, s.auto_exposure?))) else {
            return (*camera, None);
        };
        let zones = meter(auto.metering);
        let settled = settled(&sensor, &auto, &zones);
        let product = settled.exposure_s * settled.gain;
        let product = match self.last {
            None => product,
            Some((last, at)) => adapted(last, product, &auto, t - at),
        };
        self.last = Some((product, t));
        let metered = Metered {
            at_limit: settled.at_limit,
            ..metered_at(&sensor, &auto, &zones, product)
        };
        (with_exposure(camera, &metered), Some(metered))
    }
}

/// The weight of zone (`x`, `y`) of a metering image `w` × `h` zones.
pub fn zone_weight(metering: Metering, x: u32, y: u32, w: u32, h: u32) -> f64 {
    match metering {
        Metering::Average => 1.0,
        Metering::Center => {
            let (w, h) = (f64::from(w), f64::from(h));
            let sigma = 0.25 * w;
            let (dx, dy) = (f64::from(x) + 0.5 - 0.5 * w, f64::from(y) + 0.5 - 0.5 * h);
            (-(dx * dx + dy * dy) / (2.0 * sigma * sigma)).exp()
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::sensor::{Coding, ToneCurve};

    fn sensor() -> Sensor {
        Sensor {
            full_well_e: 10_000.0,
            dark_current_e_s: 0.0,
            gain_dn_per_e: 4095.0 / 10_000.0,
            exposure_s: 0.004,
            coding: Some(Coding {
                curve: ToneCurve::Srgb,
                bits: 8,
            }),
            auto_exposure: Some(AUTO),
            exposure_gain: None,
            ..crate::geometry::sensor::tests::sensor()
        }
    }

    const AUTO: AutoExposure = AutoExposure {
        metering: Metering::Average,
        min_exposure_s: 1e-5,
        max_exposure_s: 0.004,
        target: 0.18,
        max_gain: 64.0,
        adaptation_ev_s: 6.0,
    };

    fn flat(value: f32, n: usize) -> Zones {
        Zones {
            weight: vec![1.0; n],
            colour: vec![Vec3::splat(value); n],
        }
    }

    #[test]
    fn a_flat_field_settles_where_the_exposure_equation_puts_the_target() {
        let s = sensor();
        // Bright (a short time), mid (a longer one), dark (the longest, and gain).
        for value in [3.0f32, 0.3, 0.003] {
            let m = settled(&s, &AUTO, &flat(value, 10));
            // target · top = gain · K · electrons(time), electrons linear in the time.
            let per_s = Sensor {
                exposure_s: 1.0,
                ..s
            }
            .mean_electrons(f64::from(value) * s.white_cd_m2);
            let product = AUTO.target * s.max_dn() / (s.gain_dn_per_e * per_s);
            assert!(
                (m.exposure_s * m.gain / product - 1.0).abs() < 1e-6,
                "{value}: {m:?}"
            );
            // The time first, then the gain.
            let time = product.min(AUTO.max_exposure_s);
            assert!((m.exposure_s / time - 1.0).abs() < 1e-6, "{value}: {m:?}");
            assert!((m.share - AUTO.target).abs() < 1e-6 && !m.at_limit);
        }
    }

    #[test]
    fn a_field_too_bright_or_too_dark_pins_the_exposure_at_its_bound() {
        let s = sensor();
        let bright = settled(&s, &AUTO, &flat(1e6, 4));
        assert_eq!((bright.exposure_s, bright.gain), (AUTO.min_exposure_s, 1.0));
        assert!(bright.at_limit && bright.share > AUTO.target);
        let dark = settled(&s, &AUTO, &flat(1e-7, 4));
        assert_eq!(
            (dark.exposure_s, dark.gain),
            (AUTO.max_exposure_s, AUTO.max_gain)
        );
        assert!(dark.at_limit && dark.share < AUTO.target);
    }

    #[test]
    fn clipped_zones_meter_at_full_scale_and_weights_count() {
        let s = taken(&sensor(), &AUTO, 0.001);
        // Half the zones far above full scale meter 1: the mean is about a half.
        let mut zones = flat(0.0001, 4);
        zones.colour[0] = Vec3::splat(1e4);
        zones.colour[1] = Vec3::splat(1e4);
        assert!((metered_share(&s, &zones) - 0.5).abs() < 0.01);
        // A zone of weight 3 against one of weight 1.
        let zones = Zones {
            weight: vec![3.0, 1.0],
            colour: vec![Vec3::splat(0.01), Vec3::splat(0.03)],
        };
        let share = |v: f32| metered_share(&s, &flat(v, 1));
        let expected = (3.0 * share(0.01) + share(0.03)) / 4.0;
        assert!((metered_share(&s, &zones) - expected).abs() < 1e-12);
    }

    #[test]
    fn adaptation_moves_at_its_speed_and_stops_at_the_settled_exposure() {
        // 3 stops at 6 stops/s in frames of 1/30 s: 15 frames, not 14.
        let mut product = 1.0;
        let mut frames = 0;
        while product != 8.0 {
            let next = adapted(product, 8.0, &AUTO, 1.0 / 30.0);
            assert!(next > product && (next / product).log2() <= 0.2 + 1e-12);
            product = next;
            frames += 1;
            assert!(frames < 100);
        }
        assert_eq!(frames, 15);
        // Downwards too, and no overshoot.
        assert_eq!(adapted(8.0, 4.0, &AUTO, 1.0), 4.0);
        assert!((adapted(8.0, 1.0, &AUTO, 0.1).log2() - (3.0 - 0.6)).abs() < 1e-12);
    }
}
