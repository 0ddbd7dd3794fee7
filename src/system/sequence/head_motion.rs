//! How the driver's head moves relative to the vehicle during a sequence: still, a lateral
//! sway, a lean towards the pillar to look around it, or a recorded path.

use glam::DVec3;

use crate::scene::head_path::HeadPath;

/// `--head`: a head motion preset (a recorded path is `--head-path`).
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum HeadPreset {
    /// The eye stays where the scene puts it.
    Still,
    /// Lateral sinusoid across the display (--sway-cm, --sway-hz).
    Sway,
    /// Towards the display centre to look around the pillar (--lean-cm, --lean-s, --lean-at).
    Lean,
}

/// The eye's motion in the obstacle frame (at the rig's t = 0 pose), metres and seconds.
#[derive(Clone, Debug, PartialEq)]
pub enum HeadMotion {
    /// The eye stays where the scene puts it.
    Still,
    /// Lateral sinusoid along the display's x: `amplitude sin(2π frequency t)`.
    Sway { amplitude: f64, frequency: f64 },
    /// `distance` metres towards the display centre (horizontally), eased in and out
    /// (half a cosine) over `duration` seconds from `start`.
    Lean {
        distance: f64,
        duration: f64,
        start: f64,
    },
    /// The eye's own positions (obstacle frame), replacing the scene's eye.
    Path(HeadPath),
}

impl HeadMotion {
    /// The eye at time `t`, obstacle frame, for the scene's eye `eye0` (obstacle frame).
    pub fn eye(&self, eye0: DVec3, t: f64) -> DVec3 {
        match self {
            HeadMotion::Still => eye0,
            HeadMotion::Sway {
                amplitude,
                frequency,
            } => eye0 + DVec3::X * amplitude * (std::f64::consts::TAU * frequency * t).sin(),
            HeadMotion::Lean {
                distance,
                duration,
                start,
            } => {
                let s = ((t - start) / duration).clamp(0.0, 1.0);
                let eased = 0.5 * (1.0 - (std::f64::consts::PI * s).cos());
                eye0 + lean_direction(eye0) * distance * eased
            }
            HeadMotion::Path(path) => path.at(t),
        }
    }

    pub fn name(&self) -> &'static str {
        match self {
            HeadMotion::Still => "still",
            HeadMotion::Sway { .. } => "sway",
            HeadMotion::Lean { .. } => "lean",
            HeadMotion::Path(_) => "path",
        }
    }
}

/// Horizontal unit direction from the eye towards the display centre (obstacle frame): the
/// way a driver leans to look around the pillar. Straight at the display if the eye is
/// right in front of its centre.
pub fn lean_direction(eye0: DVec3) -> DVec3 {
    DVec3::new(-eye0.x, 0.0, -eye0.z)
        .try_normalize()
        .unwrap_or(DVec3::NEG_Z)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_lean_moves_its_distance_in_its_time() {
        let eye0 = DVec3::new(0.35, 0.0, 0.75);
        let lean = HeadMotion::Lean {
            distance: 0.1,
            duration: 0.3,
            start: 0.5,
        };
        assert_eq!(lean.eye(eye0, 0.2), eye0);
        assert!(((lean.eye(eye0, 0.8) - eye0).length() - 0.1).abs() < 1e-12);
        assert!(((lean.eye(eye0, 0.65) - eye0).length() - 0.05).abs() < 1e-12);
        // Towards the display centre: smaller d1 and |x|.
        let e = lean.eye(eye0, 1.0);
        assert!(e.z < eye0.z && e.x < eye0.x && e.y == eye0.y);
        let sway = HeadMotion::Sway {
            amplitude: 0.03,
            frequency: 0.5,
        };
        assert!((sway.eye(eye0, 0.5).x - 0.38).abs() < 1e-12);
    }

    #[test]
    fn a_motion_is_reported_by_its_flag_value() {
        // sequence.json's "head" is what the user typed after --head (a recorded path:
        // "path"), so that a report reads back as the command that made it.
        use clap::ValueEnum;
        let flag = |p: HeadPreset| p.to_possible_value().unwrap().get_name().to_string();
        let sway = HeadMotion::Sway {
            amplitude: 0.03,
            frequency: 0.5,
        };
        let lean = HeadMotion::Lean {
            distance: 0.1,
            duration: 0.3,
            start: 0.5,
        };
        assert_eq!(HeadMotion::Still.name(), flag(HeadPreset::Still));
        assert_eq!(sway.name(), flag(HeadPreset::Sway));
        assert_eq!(lean.name(), flag(HeadPreset::Lean));
        let path = HeadPath::parse(b"0,0.3,0,0.7", "path.csv").unwrap();
        assert_eq!(HeadMotion::Path(path).name(), "path");
    }
}
