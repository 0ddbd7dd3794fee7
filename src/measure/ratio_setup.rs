//! The paper's occlusion and foreshortening setups (§4.2) as scenes: a display at the
//! origin, the frontal camera at its centre, the eye at (−b_h, 0, d1), the scene plane at
//! z = −d2 with the box or the angled surface on it; and the compensation that shows it,
//! with its model plane and its eye (the paper's case: the scene plane and the true eye).

use anyhow::{Result, bail};
use glam::{DAffine3, DVec3};

use crate::analysis::examples::{paper_foreshortening, paper_occlusion};
use crate::analysis::paper::{ForeshorteningParams, OcclusionParams};
use crate::analysis::perceived::PerceivedGeometry;
use crate::geometry::camera::Camera;
use crate::scene::{Material, Object, Obstacle, Scene, Shape, Sky, Sun};
use crate::util::number::short;

/// The two setups of the paper's §4.2.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Setup {
    Occlusion(OcclusionParams),
    Foreshortening(ForeshorteningParams),
}

/// The compensation of a ratio experiment: where its model plane is and which eye it uses.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Compensation {
    /// The model plane's distance behind the display, m, in (0, ∞], `f64::INFINITY` for the
    /// `d2 → ∞` model; `None`: the scene plane (the paper's case).
    pub model_d2: Option<f64>,
    /// Head-tracking bias added to the eye the compensation uses, obstacle frame (x across
    /// the display, y up, z towards the driver), centimetres.
    pub head_bias_cm: [f64; 3],
}

impl Setup {
    pub(crate) fn common(&self) -> (f64, f64, f64, f64) {
        match *self {
            Setup::Occlusion(p) => (p.b1, p.d1, p.d2, p.b_h),
            Setup::Foreshortening(p) => (p.b1, p.d1, p.d2, p.b_h),
        }
    }

    /// `occlusion` or `foreshortening`.
    pub fn kind(&self) -> &'static str {
        match self {
            Setup::Occlusion(_) => "occlusion",
            Setup::Foreshortening(_) => "foreshortening",
        }
    }

    /// The parameters by their names on the command line (metres; γ in degrees).
    pub fn parameters_json(&self) -> serde_json::Value {
        match *self {
            Setup::Occlusion(p) => {
                serde_json::json!({"L": p.l, "b1": p.b1, "d2": p.d2, "d1": p.d1, "b_h": p.b_h})
            }
            Setup::Foreshortening(p) => serde_json::json!({
                "l": p.l, "b1": p.b1, "d2": p.d2, "d1": p.d1, "b_h": p.b_h,
                "gamma": p.gamma.to_degrees(),
            }),
        }
    }

    /// The paper's closed forms of (p_cam, p_user): the widths the frontal camera and the eye
    /// see on the scene plane.
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

    /// The top-view geometry of this setup under `compensation`.
    pub fn geometry(&self, compensation: &Compensation) -> PerceivedGeometry {
        let (_, d1, d2, b_h) = self.common();
        let [bx, _, bz] = compensation.head_bias_cm.map(|c| c / 100.0);
        PerceivedGeometry {
            eye_x: -b_h,
            eye_d1: d1,
            model_eye_x: -b_h + bx,
            model_eye_d1: d1 + bz,
            model_d2: compensation.model_d2.unwrap_or(d2),
            scene_d2: d2,
        }
    }

    /// Predicted (p_cam, p_user) as the driver perceives them under `compensation`: p_cam
    /// from the true corner b1 to where the driver sees the displayed edge on the scene plane
    /// (equal to the paper's p_cam for the paper's compensation); p_user as the truth has it.
    pub fn predicted_perceived(&self, compensation: &Compensation) -> (f64, f64) {
        let (b1, ..) = self.common();
        let (pc, pu) = self.predicted();
        (self.geometry(compensation).perceived_width(b1, pc), pu)
    }

    /// Checks a compensation against this setup; the messages name the command-line flags.
    pub fn validate_compensation(&self, compensation: &Compensation) -> Result<()> {
        let (_, d1, ..) = self.common();
        if let Some(m) = compensation.model_d2
            && (m.is_nan() || m <= 0.0)
        {
            bail!("option `model_d2` must be a distance in metres in (0, ∞) or `inf`, got {m}");
        }
        let [bx, by, bz] = compensation.head_bias_cm;
        if ![bx, by, bz].iter().all(|v| v.is_finite()) {
            bail!(
                "option `head_bias_cm` must be three finite numbers x,y,z in centimetres, got {bx},{by},{bz}"
            );
        }
        if d1 + bz / 100.0 <= 0.0 {
            bail!(
                "option `head_bias_cm`: z = {bz} cm puts the compensation's eye behind the display (d1 = {d1} m); z must be in ({}, ∞) cm",
                -100.0 * d1
            );
        }
        Ok(())
    }

    fn validate(&self) -> Result<()> {
        let (b1, d1, d2, b_h) = self.common();
        if ![b1, d1, d2, b_h].iter().all(|v| v.is_finite()) || d1 <= 0.0 || d2 <= 0.0 {
            bail!("d1 and d2 must be > 0 and every parameter finite");
        }
        match *self {
            Setup::Occlusion(p) if !(p.l > 0.0 && p.l < p.d2) => {
                bail!("option `L` must be in (0, d2) = (0, {}), got {}", p.d2, p.l)
            }
            Setup::Foreshortening(p)
                if !(p.l > 0.0 && p.gamma > 0.0 && p.gamma <= std::f64::consts::FRAC_PI_2) =>
            {
                bail!("option `l` must be > 0 and option `gamma` in (0, 90] degrees")
            }
            _ => {}
        }
        let (pc, pu) = self.predicted();
        if pc.abs() < 1e-6 || pu.abs() < 1e-6 || !pc.is_finite() || !pu.is_finite() {
            bail!(
                "the predicted widths are zero or undefined for these parameters (p_cam = {}, p_user = {}): |p| must be at least 1e-6 m",
                short(pc),
                short(pu)
            );
        }
        Ok(())
    }
}

/// How far behind the scene plane the setup's object reaches, m.
fn p_depth(setup: &Setup) -> f64 {
    match setup {
        Setup::Occlusion(_) => 0.0,
        Setup::Foreshortening(p) => p.l * p.gamma.sin(),
    }
}

fn object(name: &str, shape: Shape, material: usize, world_from_object: DAffine3) -> Object {
    Object {
        name: name.into(),
        shape,
        material: Some(material),
        file_materials: Vec::new(),
        world_from_object,
        visible_to: 0b111,
        casts_shadow: true,
        hazard: false,
        motion: Default::default(),
        instances: Vec::new(),
    }
}

/// The scene of a setup: display at the origin facing +z, frontal camera at its centre, the
/// eye at (−b_h, 0, d1) (the paper's convention), the scene plane at z = −d2. `width` is the
/// driver view's width in pixels; the frontal camera and the display get as many. The display
/// is wide enough to show the edges where the driver perceives them under `compensation`, and
/// the frontal camera wide enough to see every model point the display asks for.
pub fn build_scene(setup: &Setup, width: u32, compensation: &Compensation) -> Result<Scene> {
    setup.validate()?;
    setup.validate_compensation(compensation)?;
    let (b1, d1, d2, b_h) = setup.common();
    let eye = DVec3::new(-b_h, 0.0, d1);
    let (pc, pu) = setup.predicted();
    let (pc_perceived, _) = setup.predicted_perceived(compensation);
    if pc_perceived.abs() < 1e-6 || !pc_perceived.is_finite() {
        bail!(
            "the driver perceives no width for these parameters and this compensation (p_cam = {pc_perceived})"
        );
    }
    let geometry = setup.geometry(compensation);
    // Plane points the display must show, with a margin: the corner and the edges, where the
    // camera and the eye see them and where the driver perceives them.
    let span = pc.abs().max(pu.abs()).max(pc_perceived.abs());
    let qs = [
        b1,
        b1 + pc,
        b1 + pu,
        b1 + pc_perceived,
        geometry.perceived(b1),
    ];
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
        display_shape: crate::scene::display_surface::DisplayShape::Flat,
        scanout: crate::geometry::shutter::Scanout::default(),
        display_light: None,
    };
    // The frontal camera (half as tall as wide) must see the direction of every model point
    // the display can ask for: the model eye's ray through a display corner, continued to the
    // model plane (or taken as a direction for d2 → ∞).
    let [bx, by, bz] = compensation.head_bias_cm.map(|c| c / 100.0);
    let model_eye = eye + DVec3::new(bx, by, bz);
    let model_d2 = geometry.model_d2;
    let tangents = |corner: DVec3| {
        let ray = corner - model_eye;
        let m = if model_d2.is_infinite() {
            ray / -ray.z
        } else {
            (model_eye + ray * (model_eye.z + model_d2) / model_eye.z) / model_d2
        };
        m.x.abs().max(2.0 * m.y.abs())
    };
    let display_corners = [(-1.0, -1.0), (-1.0, 1.0), (1.0, -1.0), (1.0, 1.0)]
        .map(|(sx, sy)| DVec3::new(sx * half_width, sy * height / 2.0, 0.0));
    let tan_needed = display_corners
        .map(tangents)
        .into_iter()
        .fold(0.0, f64::max);
    let theta_f = (tan_needed * 1.05).atan().min(85f64.to_radians());
    let frontal = Camera::new(DAffine3::IDENTITY, theta_f, width, (width / 2).max(8))?;
    // The driver looks at the display centre, wide enough to see the whole display, and tall
    // enough: an eye near one edge of a wide display sees that edge's corners steeply.
    let look = -eye.normalize();
    let half_x = ([-half_width, half_width]
        .map(|x| (DVec3::new(x, 0.0, 0.0) - eye).normalize().dot(look).acos())
        .into_iter()
        .fold(0.0, f64::max)
        + 1f64.to_radians())
    .min(85f64.to_radians());
    let aim = Camera::look_at(eye, DVec3::ZERO, DVec3::Y, half_x, width, width)?;
    let camera_from_world = aim.world_from_camera.inverse();
    let tan_y_needed = display_corners
        .map(|c| {
            let p = camera_from_world.transform_point3(c);
            (p.y / -p.z).abs()
        })
        .into_iter()
        .fold(0.0, f64::max);
    let rows = (width as f64 * tan_y_needed * 1.05 / half_x.tan()).ceil() as u32;
    let driver = aim.with_resolution(width, rows.min(4 * width).max((width / 4).max(8)));
    let back = Camera::new(DAffine3::from_rotation_y(std::f64::consts::PI), 0.6, 8, 6)?;
    let materials = vec![
        Material::matte("background", [0.6, 0.6, 0.6]),
        Material::matte("object", [0.8, 0.2, 0.1]),
    ];
    // Tall enough that every display row sees the setup, from the eye and from the camera.
    let tall = 4.0 * height * (d1 + d2) / d1 + 2.0 * tan_needed * (d2 + p_depth(setup)) + 2.0;
    let far = d2 + 50.0;
    // Half the size a background at `depth` behind the display needs: every ray the views
    // cast hits it, the driver's through the display and the frontal camera's anywhere.
    let reach_at = |depth: f64| {
        let from_eye = display_corners
            .map(|c| {
                let p = eye + (c - eye) * (d1 + depth) / d1;
                p.x.abs().max(p.y.abs())
            })
            .into_iter()
            .fold(0.0, f64::max);
        from_eye.max(frontal.tan_half_x().max(frontal.tan_half_y()) * depth) * 1.1 + 1.0
    };
    let mut objects = Vec::new();
    match *setup {
        Setup::Occlusion(p) => {
            // Background on the scene plane; the box stands on it, its near edge at b1.
            objects.push(object(
                "plane",
                Shape::Quad {
                    size: [(4.0 * far).max(2.0 * reach_at(d2)); 2],
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
                    size: [(8.0 * far).max(2.0 * reach_at(far)); 2],
                },
                0,
                DAffine3::from_translation(DVec3::new(0.0, 0.0, -far)),
            ));
        }
    }
    Ok(Scene {
        path: "generated".into(),
        source_hash: String::new(),
        sun: Sun {
            direction: DVec3::new(0.3, 0.8, 0.5).normalize(),
            color: [1.0; 3],
            intensity: 1.5,
        },
        sky: Sky {
            cloud_cover: 0.0,
            ..Sky::default()
        },
        photometry: None,
        lights: Vec::new(),
        materials,
        objects,
        obstacle,
        driver,
        frontal,
        back,
        calibration: Default::default(),
        eyellipse: None,
        face: crate::scene::DriverFace::Ellipsoids,
        ego_route: None,
        warnings: Vec::new(),
    })
}
