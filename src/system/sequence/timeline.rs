//! The clock of a sequence and where everything is at each instant: displayed frames, the
//! display's refreshes (sample and hold), the capture and head-sample times behind each, and
//! the rig (vehicle, obstacle, cameras, the driver's eye and head) at any time.

use anyhow::{Result, bail};
use glam::{DAffine3, DVec3};

use crate::scene::Scene;
use crate::scene::motion::{MovesWith, VehicleMotion};
use crate::system::sequence::head_motion::HeadMotion;
use crate::util::number::short;

/// Longest sequence, seconds.
pub const MAX_DURATION_S: f64 = 3600.0;
/// Highest frame and display rate, Hz.
pub const MAX_RATE_HZ: f64 = 1000.0;
/// Most frames of one sequence.
pub const MAX_FRAMES: usize = 100_000;

/// Frame times and latencies, seconds.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Timeline {
    /// Length of the sequence, s, in (0, 3600].
    pub duration: f64,
    /// Frames measured per second (the times at which truth and display are compared), Hz.
    pub fps: f64,
    /// Display refresh rate, Hz: the display holds each image until the next refresh.
    pub display_hz: f64,
    /// Frontal capture to display, s (≥ 0, shorter than the sequence).
    pub latency_camera: f64,
    /// Back-camera capture to head estimate, s (≥ 0, shorter than the sequence).
    pub latency_tracking: f64,
}

/// The times behind one displayed frame.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FrameTimes {
    /// When the frame is looked at, s.
    pub display: f64,
    /// The display refresh whose image is shown then: its index and time, s.
    pub refresh: i64,
    pub refresh_time: f64,
    /// When the frontal image shown was captured, s.
    pub capture: f64,
    /// When the back image behind its head estimate was captured, s.
    pub head: f64,
}

impl Timeline {
    pub fn validate(&self) -> Result<()> {
        let rate = |name: &str, v: f64| -> Result<()> {
            if !(v > 0.0 && v <= MAX_RATE_HZ) {
                bail!("{name} must be in (0, {MAX_RATE_HZ}] Hz, got {}", short(v));
            }
            Ok(())
        };
        if !(self.duration > 0.0 && self.duration <= MAX_DURATION_S) {
            bail!(
                "option `duration` must be in (0, {MAX_DURATION_S}] s, got {}",
                short(self.duration)
            );
        }
        rate("option `fps`", self.fps)?;
        rate("option `display_hz`", self.display_hz)?;
        for (name, v) in [
            ("option `latency_camera`", self.latency_camera),
            ("option `latency_tracking`", self.latency_tracking),
        ] {
            if !(v >= 0.0 && v < self.duration) {
                bail!(
                    "{name} {} ms must be ≥ 0 and shorter than the sequence ({} ms)",
                    short(v * 1e3),
                    short(self.duration * 1e3)
                );
            }
        }
        if self.frames() > MAX_FRAMES {
            bail!(
                "option `duration` × option `fps` gives {} frames, more than the limit of {MAX_FRAMES}",
                self.frames()
            );
        }
        Ok(())
    }

    /// Frames in the sequence: one at t = 0 and every 1/fps before `duration`.
    pub fn frames(&self) -> usize {
        ((self.duration * self.fps - 1e-9).ceil().max(1.0)) as usize
    }

    pub fn times(&self, frame: usize) -> FrameTimes {
        let display = frame as f64 / self.fps;
        // A refresh at exactly the frame's time counts (the 1e-9 absorbs the rounding of k/fps).
        let refresh = (display * self.display_hz + 1e-9).floor() as i64;
        FrameTimes {
            display,
            ..self.refresh_times(refresh)
        }
    }

    /// The times of refresh `refresh` (negative: before the sequence), looked at as it is
    /// shown.
    pub fn refresh_times(&self, refresh: i64) -> FrameTimes {
        let refresh_time = refresh as f64 / self.display_hz;
        let capture = refresh_time - self.latency_camera;
        FrameTimes {
            display: refresh_time,
            refresh,
            refresh_time,
            capture,
            head: capture - self.latency_tracking,
        }
    }
}

/// The rig over time: the vehicle's motion and the head's motion relative to it.
#[derive(Clone, Debug)]
pub struct Rig {
    pub vehicle: VehicleMotion,
    pub head: HeadMotion,
    /// The scene's eye, obstacle frame.
    pub eye0: DVec3,
    /// The scene at t = 0 (cameras already at the sizes used).
    pub base: Scene,
}

impl Rig {
    /// The rig of `base` carried by `vehicle`, the head moving by `head` within it.
    pub fn new(base: Scene, vehicle: VehicleMotion, head: HeadMotion) -> Rig {
        let eye0 = base.obstacle.in_obstacle_frame(base.eye());
        Rig {
            vehicle,
            head,
            eye0,
            base,
        }
    }

    pub fn world_from_rig(&self, t: f64) -> DAffine3 {
        self.vehicle.world_from_rig(t)
    }

    /// The true eye at `t`, in the obstacle frame (relative to the vehicle).
    pub fn eye_in_obstacle(&self, t: f64) -> DVec3 {
        self.head.eye(self.eye0, t)
    }

    /// The head's displacement at `t` from where the scene puts it, rig frame.
    fn head_offset(&self, t: f64) -> DVec3 {
        self.base
            .obstacle
            .world_from_obstacle
            .transform_vector3(self.eye_in_obstacle(t) - self.eye0)
    }

    /// The scene at `t`: obstacle and cameras carried by the vehicle, the driver's eye at
    /// the head's position (its viewing direction turns with the vehicle only).
    pub fn scene_at(&self, t: f64) -> Scene {
        let rig = self.world_from_rig(t);
        let mut s = self.base.clone();
        s.obstacle.world_from_obstacle = rig * s.obstacle.world_from_obstacle;
        s.frontal.world_from_camera = rig * s.frontal.world_from_camera;
        s.back.world_from_camera = rig * s.back.world_from_camera;
        s.driver.world_from_camera =
            rig * DAffine3::from_translation(self.head_offset(t)) * s.driver.world_from_camera;
        for lamp in s.lights.iter_mut() {
            if lamp.moves_with == MovesWith::Vehicle {
                lamp.position = rig.transform_point3(lamp.position);
                if let Some(spot) = &mut lamp.spot {
                    spot.direction = rig.transform_vector3(spot.direction).normalize();
                }
            }
        }
        s
    }

    /// The rigid world_from_world motion at `t` of object id `id` (objects numbered from 1,
    /// the obstacle last) from its t = 0 placement; `None` for what stands still.
    pub fn object_motion(&self, t: f64, id: u32) -> Option<DAffine3> {
        let objects = &self.base.objects;
        let Some(object) = objects.get(id as usize - 1) else {
            // The obstacle.
            return Some(self.world_from_rig(t));
        };
        match object.motion.moves_with {
            MovesWith::Vehicle => Some(self.world_from_rig(t)),
            MovesWith::Head => {
                Some(self.world_from_rig(t) * DAffine3::from_translation(self.head_offset(t)))
            }
            MovesWith::World => object
                .motion
                .world_from_object_at(t)
                .map(|at| at * object.world_from_object.inverse()),
        }
    }

    /// Checks that the eye stays in front of the display at every `times`.
    pub fn check_eye(&self, times: impl Iterator<Item = f64>) -> Result<()> {
        for t in times {
            let d1 = self.eye_in_obstacle(t).z;
            if d1 <= 0.0 || !d1.is_finite() {
                bail!(
                    "the head path puts the eye behind the display at t = {} s (d1 = {} m; it must stay > 0)",
                    short(t),
                    short(d1)
                );
            }
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn lamps_on_the_vehicle_ride_with_it_and_street_lamps_stay() {
        let base = Scene::bundled("das_night.toml");
        let vehicle = VehicleMotion {
            speed: 50.0 / 3.6,
            yaw_rate: 0.3,
            forward: DVec3::NEG_Z,
            pivot: base.eye(),
            route: None,
        };
        let rig = Rig::new(base.clone(), vehicle, HeadMotion::Still);
        let (start, later) = (rig.scene_at(0.0), rig.scene_at(2.0));
        let in_vehicle =
            |s: &Scene, p: DVec3| s.obstacle.world_from_obstacle.inverse().transform_point3(p);
        let mut riding = 0;
        for ((lamp, a), b) in base.lights.iter().zip(&start.lights).zip(&later.lights) {
            assert_eq!(
                a.position, lamp.position,
                "{}: where the file puts it at t = 0",
                lamp.name
            );
            if lamp.moves_with == MovesWith::Vehicle {
                riding += 1;
                // The same place and aim in the vehicle's frame, 27.8 m on in the world's.
                let (pa, pb) = (
                    in_vehicle(&start, a.position),
                    in_vehicle(&later, b.position),
                );
                assert!(pa.distance(pb) < 1e-9, "{}", lamp.name);
                assert!(a.position.distance(b.position) > 20.0, "{}", lamp.name);
                if let (Some(sa), Some(sb)) = (a.spot, b.spot) {
                    let frame = |s: &Scene| s.obstacle.world_from_obstacle.matrix3.inverse();
                    let (da, db) = (frame(&start) * sa.direction, frame(&later) * sb.direction);
                    assert!(da.distance(db) < 1e-9 && (sb.direction.length() - 1.0).abs() < 1e-12);
                }
            } else {
                assert_eq!(b.position, lamp.position, "{} stays", lamp.name);
            }
        }
        // das_night's low beams and its instrument cluster ride; its street lamps stay.
        assert_eq!((riding, base.lights.len()), (3, 6));
    }

    #[test]
    fn frames_refreshes_and_latencies() {
        let tl = Timeline {
            duration: 1.0,
            fps: 60.0,
            display_hz: 30.0,
            latency_camera: 0.05,
            latency_tracking: 0.01,
        };
        assert_eq!(tl.frames(), 60);
        let f = tl.times(3);
        assert_eq!((f.refresh, f.refresh_time), (1, 1.0 / 30.0));
        assert!((f.capture - (1.0 / 30.0 - 0.05)).abs() < 1e-15);
        assert!((f.head - (f.capture - 0.01)).abs() < 1e-15);
        // Refreshes at every frame when the display runs at the frame rate.
        let same = Timeline {
            display_hz: 60.0,
            ..tl
        };
        assert!((0..60).all(|k| same.times(k).refresh == k as i64));
        assert!(
            Timeline {
                latency_camera: 1.0,
                ..tl
            }
            .validate()
            .is_err()
        );
        assert!(Timeline { fps: 0.0, ..tl }.validate().is_err());
    }

    #[test]
    fn a_timeline_is_valid_up_to_each_bound_and_not_beyond() {
        // The library's own check (Python and byo steps build timelines without the CLI's
        // parsers): every bound is inclusive where documented, exclusive where not.
        let tl = Timeline {
            duration: 1.0,
            fps: 60.0,
            display_hz: 60.0,
            latency_camera: 0.0,
            latency_tracking: 0.0,
        };
        let valid = |t: Timeline| t.validate().is_ok();
        assert!(valid(tl));
        for duration in [0.0, -1.0, f64::NAN, MAX_DURATION_S * (1.0 + 1e-12)] {
            let err = Timeline { duration, ..tl }
                .validate()
                .unwrap_err()
                .to_string();
            assert!(
                err.starts_with("option `duration` must be in (0, 3600]"),
                "{err}"
            );
        }
        // The longest sequence, at a rate that keeps it within the frame limit.
        let longest = Timeline {
            duration: MAX_DURATION_S,
            fps: 1.0,
            display_hz: 1.0,
            ..tl
        };
        assert!(valid(longest));
        // Exactly the most frames (at 1000 Hz for 100 s), then one more.
        let most = Timeline {
            duration: 100.0,
            fps: 1000.0,
            ..tl
        };
        assert_eq!(most.frames(), MAX_FRAMES);
        assert!(valid(most));
        let over = Timeline {
            duration: 100.001,
            ..most
        };
        assert_eq!(over.frames(), MAX_FRAMES + 1);
        let err = over.validate().unwrap_err().to_string();
        assert!(
            err.contains("100001 frames, more than the limit of 100000"),
            "{err}"
        );
    }
}
