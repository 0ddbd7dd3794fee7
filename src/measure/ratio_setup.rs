//! The paper's occlusion and foreshortening setups (§4.2) as scenes: a display at the
//! origin, the frontal camera at its centre, the eye at (−b_h, 0, d1), the scene plane at
//! z = −d2 with the box or the angled surface on it.

use anyhow::{Result, bail};
use glam::{DAffine3, DVec3};

use crate::analysis::examples::{paper_foreshortening, paper_occlusion};
use crate::analysis::paper::{ForeshorteningParams, OcclusionParams};
use crate::geometry::camera::Camera;
use crate::scene::{Material, Object, Obstacle, Scene, Shape, Sky, Sun};

/// The two setups of the paper's §4.2.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Setup {
    Occlusion(OcclusionParams),
    Foreshortening(ForeshorteningParams),
}

impl Setup {
    pub(crate) fn common(&self) -> (f64, f64, f64, f64) {
        match *self {
            Setup::Occlusion(p) => (p.b1, p.d1, p.d2, p.b_h),
            Setup::Foreshortening(p) => (p.b1, p.d1, p.d2, p.b_h),
        }
    }

    /// Predicted (p_cam, p_user).
    pub fn predicted(&self) -> (f64, f64) {
        match self {
            Setup::Occlusion(p) => (p.p_cam(), p.p_user()),
            Setup::Foreshortening(p) => (p.p_cam(), p.p_user()),
        }
    }

    /// The paper's predicted and measured ratios, for its own two examples.
    pub fn paper_values(&self) -> Option<(f64, f64)> {
        match *self {
            Setup::Occlusion(p) if p == paper_occlusion() => Some((-0.73, -0.71)),
            Setup::Foreshortening(p) if p == paper_foreshortening() => Some((2.47, 2.64)),
            _ => None,
        }
    }

    fn validate(&self) -> Result<()> {
        let (b1, d1, d2, b_h) = self.common();
        if ![b1, d1, d2, b_h].iter().all(|v| v.is_finite()) || d1 <= 0.0 || d2 <= 0.0 {
            bail!("d1 and d2 must be > 0 and every parameter finite");
        }
        match *self {
            Setup::Occlusion(p) if !(p.l > 0.0 && p.l < p.d2) => {
                bail!("--L must be in (0, d2) = (0, {}), got {}", p.d2, p.l)
            }
            Setup::Foreshortening(p)
                if !(p.l > 0.0 && p.gamma > 0.0 && p.gamma <= std::f64::consts::FRAC_PI_2) =>
            {
                bail!("--l must be > 0 and --gamma in (0, 90] degrees")
            }
            _ => {}
        }
        let (pc, pu) = self.predicted();
        if pc.abs() < 1e-6 || pu.abs() < 1e-6 || !pc.is_finite() || !pu.is_finite() {
            bail!(
                "the predicted widths are zero or undefined for these parameters (p_cam = {pc}, p_user = {pu})"
            );
        }
        Ok(())
    }
}

fn material(name: &str, color: [f64; 3]) -> Material {
    Material {
        name: name.into(),
        color,
        texture: None,
        uv_repeat: [1.0, 1.0],
    }
}

fn object(name: &str, shape: Shape, material: usize, world_from_object: DAffine3) -> Object {
    Object {
        name: name.into(),
        shape,
        material: Some(material),
        world_from_object,
        visible_to: 0b111,
        casts_shadow: true,
    }
}

/// The scene of a setup: display at the origin facing +z, frontal camera at its centre, the
/// eye at (−b_h, 0, d1) (the paper's convention), the scene plane at z = −d2. `width` is the
/// driver view's width in pixels; the frontal camera and the display get as many.
pub fn build_scene(setup: &Setup, width: u32) -> Result<Scene> {
    setup.validate()?;
    let (b1, d1, d2, b_h) = setup.common();
    let eye = DVec3::new(-b_h, 0.0, d1);
    let (pc, pu) = setup.predicted();
    // Plane points the display must show, with a margin: the corner and both edges.
    let span = pc.abs().max(pu.abs());
    let qs = [b1, b1 + pc, b1 + pu];
    let (q_lo, q_hi) = (
        qs.iter().copied().fold(f64::INFINITY, f64::min) - 0.5 * span - 0.05,
        qs.iter().copied().fold(f64::NEG_INFINITY, f64::max) + 0.5 * span + 0.05,
    );
    // Display x of a plane point seen from the eye.
    let display_x = |q: f64| eye.x + (q - eye.x) * d1 / (d1 + d2);
    let half_width = display_x(q_lo).abs().max(display_x(q_hi).abs()) * 1.02;
    let height = 0.2 * half_width;
    let obstacle = Obstacle {
        world_from_obstacle: DAffine3::IDENTITY,
        width: 2.0 * half_width,
        height,
        thickness: 0.01,
        display_resolution: [
            width,
            ((width as f64 * height / (2.0 * half_width)).round() as u32).max(8),
        ],
        display_off_color: [0.0; 3],
        body_color: [0.2; 3],
    };
    // The frontal camera must see every plane point the display can ask for.
    let reach = [-half_width, half_width]
        .map(|x| (eye.x + (x - eye.x) * (d1 + d2) / d1).abs())
        .into_iter()
        .fold(0.0, f64::max);
    let theta_f = ((reach * 1.05 / d2).atan()).min(85f64.to_radians());
    let frontal = Camera::new(DAffine3::IDENTITY, theta_f, width, (width / 2).max(8))?;
    // The driver looks at the display centre, wide enough to see the whole display.
    let look = -eye.normalize();
    let half_x = [-half_width, half_width]
        .map(|x| (DVec3::new(x, 0.0, 0.0) - eye).normalize().dot(look).acos())
        .into_iter()
        .fold(0.0, f64::max)
        + 1f64.to_radians();
    let driver = Camera::look_at(
        eye,
        DVec3::ZERO,
        DVec3::Y,
        half_x.min(85f64.to_radians()),
        width,
        (width / 4).max(8),
    )?;
    let back = Camera::new(DAffine3::from_rotation_y(std::f64::consts::PI), 0.6, 8, 6)?;
    let materials = vec![
        material("background", [0.6, 0.6, 0.6]),
        material("object", [0.8, 0.2, 0.1]),
    ];
    // Tall enough that every display row sees the setup.
    let tall = 4.0 * height * (d1 + d2) / d1 + 2.0;
    let far = d2 + 50.0;
    let mut objects = Vec::new();
    match *setup {
        Setup::Occlusion(p) => {
            // Background on the scene plane; the box stands on it, its near edge at b1.
            objects.push(object(
                "plane",
                Shape::Quad {
                    size: [4.0 * far, 4.0 * far],
                },
                0,
                DAffine3::from_translation(DVec3::new(0.0, 0.0, -d2)),
            ));
            let box_width = 4.0 * span + 2.0;
            let centre = DVec3::new(b1 - box_width / 2.0, 0.0, -d2 + p.l / 2.0);
            objects.push(object(
                "occluder",
                Shape::Box {
                    size: [box_width, tall, p.l],
                },
                1,
                DAffine3::from_translation(centre),
            ));
        }
        Setup::Foreshortening(p) => {
            let dir = DVec3::new(p.gamma.cos(), 0.0, -p.gamma.sin());
            let centre = DVec3::new(b1, 0.0, -d2) + dir * (p.l / 2.0);
            let pose = DAffine3::from_translation(centre) * DAffine3::from_rotation_y(p.gamma);
            objects.push(object(
                "surface",
                Shape::Quad { size: [p.l, tall] },
                1,
                pose,
            ));
            objects.push(object(
                "backdrop",
                Shape::Quad {
                    size: [8.0 * far, 8.0 * far],
                },
                0,
                DAffine3::from_translation(DVec3::new(0.0, 0.0, -far)),
            ));
        }
    }
    Ok(Scene {
        path: "generated".into(),
        sun: Sun {
            direction: DVec3::new(0.3, 0.8, 0.5).normalize(),
            color: [1.0; 3],
            intensity: 1.5,
        },
        sky: Sky {
            cloud_cover: 0.0,
            ..Sky::default()
        },
        materials,
        objects,
        obstacle,
        driver,
        frontal,
        back,
    })
}
