//! The driver's head the back camera films (`assets/head.obj`, `cargo run --example
//! make_assets`): a skull and face with eye sockets, eyeballs with irises and pupils, a nose,
//! brows, hair, lips and a neck, in materials the scene's lights shade like any other mesh.
//!
//! Head frame (metres): the origin is the eye point — the midpoint of the two pupils, which is
//! what the see-through system needs and what `camera.driver.position` is — +y up, the face
//! looking along −z, +x to the driver's right. A scene places the head with `translate` at
//! the eye and turns it with `rotate_deg` = [pitch, yaw, 0] about that point; a turn about
//! the neck ([`NECK`]) is that turn plus the eye's move, `eye_turned_about_neck`.
//!
//! The head tracker (`system/head.rs`) uses the same shape as its face model, as a real
//! tracker fits a canonical face: [`eye_row_section`] is the skin's outline at eye height.

use std::fmt::Write;

use glam::{DMat3, DVec3};

/// Half the interpupillary distance, metres (the pupils at x = ±this).
pub const HALF_IPD: f64 = 0.032;
/// Eyeball radius, metres; the pupil is the eyeball's front pole.
pub const EYEBALL_RADIUS: f64 = 0.012;
/// Angular radius of the iris cap (a 12 mm iris) and of the pupil (4.2 mm), radians from the
/// eyeball's front pole.
pub const IRIS_ANGLE: f64 = std::f64::consts::FRAC_PI_6;
pub const PUPIL_ANGLE: f64 = 0.1745;
/// Centre of the skull's ellipsoid, metres from the eye point.
const SKULL_CENTRE: DVec3 = DVec3::new(0.0, 0.025, 0.085);
/// Skull semi-axes (half width, half height, half depth), metres.
const SKULL_AXES: DVec3 = DVec3::new(0.077, 0.115, 0.1);
/// The pivot of the neck, metres from the eye point: behind and below it, where the head
/// turns.
pub const NECK: DVec3 = DVec3::new(0.0, -0.1, 0.095);

/// Materials, in the order of `head.mtl` (the OBJ's `usemtl` parts).
pub const MATERIALS: [(&str, [f32; 3]); 8] = [
    ("skin", [0.58, 0.38, 0.27]),
    ("hair", [0.05, 0.032, 0.02]),
    ("brow", [0.09, 0.06, 0.04]),
    ("lips", [0.45, 0.17, 0.15]),
    ("sclera", [0.8, 0.78, 0.74]),
    ("iris", [0.035, 0.02, 0.012]),
    ("pupil", [0.008, 0.008, 0.008]),
    ("neck", [0.58, 0.38, 0.27]),
];
const SKIN: usize = 0;
const HAIR: usize = 1;
const BROW: usize = 2;
const LIPS: usize = 3;
const SCLERA: usize = 4;
const IRIS: usize = 5;
const PUPIL: usize = 6;
const NECK_PART: usize = 7;

fn smooth(edge0: f64, edge1: f64, x: f64) -> f64 {
    let t = ((x - edge0) / (edge1 - edge0)).clamp(0.0, 1.0);
    t * t * (3.0 - 2.0 * t)
}

/// The skin surface's point in direction `d` (unit, head frame) from the skull's centre:
/// the ellipsoid, narrowed towards the jaw, with the sockets, nose, brow ridges and lips
/// moved along `d`.
fn skin_point(d: DVec3) -> DVec3 {
    let a = SKULL_AXES;
    let base = SKULL_CENTRE + d / ((d / a).length());
    // The jaw: narrower below the cheekbones.
    let jaw = 1.0 - 0.22 * smooth(-0.02, -0.1, base.y);
    let p = DVec3::new(base.x * jaw, base.y, base.z);
    let front = smooth(0.02, -0.01, p.z); // 1 on the face, 0 at the sides and back
    let mut bump = 0.0;
    for side in [-1.0, 1.0] {
        // Socket: a steep dent where the eye opening is (11.5 mm × 5.2 mm half axes).
        let q = ((p.x - side * HALF_IPD) / 0.0115).powi(2) + (p.y / 0.0052).powi(2);
        bump -= 0.02 * (-q * q * q).exp() * front;
        // Brow ridge above the eye.
        let r = ((p.x - side * 0.035) / 0.024).powi(2) + ((p.y - 0.017) / 0.008).powi(2);
        bump += 0.004 * (-r).exp() * front;
        // Cheekbones.
        let c = ((p.x - side * 0.04) / 0.02).powi(2) + ((p.y + 0.03) / 0.015).powi(2);
        bump += 0.003 * (-c).exp() * front;
    }
    // Nose: a ridge from the bridge (y = 0.01) to the tip (y = −0.045), widening down.
    let along = smooth(0.012, -0.044, p.y) * (1.0 - smooth(-0.046, -0.056, p.y));
    let width = 0.006 + 0.01 * smooth(0.0, -0.05, p.y);
    bump += 0.02 * along * (-(p.x / width).powi(2)).exp() * front;
    // Lips.
    let l = (p.x / 0.024).powi(2) + ((p.y + 0.075) / 0.008).powi(2);
    bump += 0.004 * (-l).exp() * front;
    p + d * bump
}

/// Which material a skin vertex's triangle takes, from its undeformed surface point.
fn skin_material(p: DVec3) -> usize {
    // Hairline: high on the forehead, lower at the sides and the back; always above the
    // eyes' row at the sides, so the head's outline at eye height is skin.
    let back = smooth(-0.02, 0.12, p.z);
    let hairline = 0.075 - 0.04 * back.min(1.0) - 0.03 * smooth(0.14, 0.18, p.z);
    if p.y > hairline {
        return HAIR;
    }
    let front = p.z < 0.015;
    if front {
        for side in [-1.0, 1.0] {
            // Brows: an arch over each eye.
            let dx = (p.x - side * 0.034) / 0.022;
            let arch = 0.021 - 0.004 * dx * dx;
            if dx.abs() < 1.0 && (p.y - arch).abs() < 0.0032 {
                return BROW;
            }
        }
        if (p.x / 0.022).powi(2) + ((p.y + 0.075) / 0.0055).powi(2) < 1.0 {
            return LIPS;
        }
    }
    SKIN
}

/// A warp of [0, 1] that puts more samples near `at` (also in [0, 1]): `strength` > 0.
fn dense_near(t: f64, at: f64, strength: f64) -> f64 {
    let s = |x: f64| x - strength * ((x - at) * std::f64::consts::PI).sin() / std::f64::consts::PI;
    // s is monotone for strength < 1, flattest at `at`; rescale to [0, 1].
    let (lo, hi) = (s(0.0), s(1.0));
    // Invert s by bisection: the samples at equal steps of s are dense where s' is large.
    let target = lo + t * (hi - lo);
    let (mut a, mut b) = (0.0, 1.0);
    for _ in 0..60 {
        let m = 0.5 * (a + b);
        if s(m) < target {
            a = m;
        } else {
            b = m;
        }
    }
    0.5 * (a + b)
}

/// A mesh under construction: shared vertices, triangles by part.
struct Mesh {
    vertices: Vec<DVec3>,
    parts: [Vec<[usize; 3]>; 8],
}

impl Mesh {
    fn vertex(&mut self, p: DVec3) -> usize {
        self.vertices.push(p);
        self.vertices.len() - 1
    }
}

/// Direction of the skin grid's node (i, j): azimuth from the face's front (−z) and
/// elevation, each warped to sample the eyes and nose finely.
fn grid_direction(i: usize, j: usize, columns: usize, rows: usize) -> DVec3 {
    use std::f64::consts::{PI, TAU};
    let u = dense_near(i as f64 / columns as f64, 0.5, 0.92);
    let v = dense_near(j as f64 / rows as f64, 0.5, 0.9);
    let azimuth = (u - 0.5) * TAU; // 0: straight ahead (−z)
    let elevation = (0.5 - v) * PI; // +π/2 at the top
    DVec3::new(
        elevation.cos() * azimuth.sin(),
        elevation.sin(),
        -elevation.cos() * azimuth.cos(),
    )
}

fn add_skin(mesh: &mut Mesh) {
    let (columns, rows) = (176usize, 120usize);
    let base = mesh.vertices.len();
    let mut undeformed = Vec::new();
    for j in 0..=rows {
        for i in 0..columns {
            // The eye row (elevation of y = 0 seen from the skull's centre) is near the
            // middle of the warp; the warp's centre is the equator, slightly above the eyes.
            let d = grid_direction(i, j, columns, rows);
            undeformed.push(SKULL_CENTRE + d / ((d / SKULL_AXES).length()));
            mesh.vertex(skin_point(d));
        }
    }
    let at = |i: usize, j: usize| base + j * columns + i % columns;
    for j in 0..rows {
        for i in 0..columns {
            let (a, b, c, d) = (at(i, j), at(i + 1, j), at(i + 1, j + 1), at(i, j + 1));
            let centre = (undeformed[a - base]
                + undeformed[b - base]
                + undeformed[c - base]
                + undeformed[d - base])
                / 4.0;
            let part = skin_material(centre);
            // Counter-clockwise seen from outside.
            mesh.parts[part].push([a, d, c]);
            mesh.parts[part].push([a, c, b]);
        }
    }
}

/// An eyeball at `centre` looking along −z: sclera, iris and pupil caps around its front pole.
fn add_eyeball(mesh: &mut Mesh, centre: DVec3) {
    use std::f64::consts::{PI, TAU};
    // Rings (angle from the front pole): fine over the iris, coarser behind.
    let mut rings: Vec<f64> = (0..=4).map(|k| PUPIL_ANGLE * k as f64 / 4.0).collect();
    rings.extend((1..=6).map(|k| PUPIL_ANGLE + (IRIS_ANGLE - PUPIL_ANGLE) * k as f64 / 6.0));
    rings.extend((1..=12).map(|k| IRIS_ANGLE + (PI - IRIS_ANGLE) * k as f64 / 12.0));
    let around = 40usize;
    let point = |polar: f64, k: usize| {
        let a = TAU * k as f64 / around as f64;
        centre
            + EYEBALL_RADIUS
                * DVec3::new(polar.sin() * a.cos(), polar.sin() * a.sin(), -polar.cos())
    };
    let front = mesh.vertex(point(0.0, 0));
    let mut previous: Vec<usize> = vec![front; around];
    for (r, &polar) in rings.iter().enumerate().skip(1) {
        let ring: Vec<usize> = (0..around).map(|k| mesh.vertex(point(polar, k))).collect();
        let part = if polar <= PUPIL_ANGLE + 1e-9 {
            PUPIL
        } else if polar <= IRIS_ANGLE + 1e-9 {
            IRIS
        } else {
            SCLERA
        };
        for k in 0..around {
            let (a, b) = (ring[k], ring[(k + 1) % around]);
            let (c, d) = (previous[k], previous[(k + 1) % around]);
            if r == 1 {
                mesh.parts[part].push([c, b, a]);
            } else {
                mesh.parts[part].push([c, b, a]);
                mesh.parts[part].push([c, d, b]);
            }
        }
        previous = ring;
    }
}

/// The neck: a tapered tube from inside the head down to 0.16 m below the eyes.
fn add_neck(mesh: &mut Mesh) {
    use std::f64::consts::TAU;
    let around = 48usize;
    let levels = [(-0.05, 0.05), (-0.1, 0.052), (-0.16, 0.058)];
    let mut rings = Vec::new();
    for (y, r) in levels {
        let ring: Vec<usize> = (0..around)
            .map(|k| {
                let a = TAU * k as f64 / around as f64;
                mesh.vertex(DVec3::new(r * a.sin(), y, NECK.z + 0.01 - r * a.cos()))
            })
            .collect();
        rings.push(ring);
    }
    for w in rings.windows(2) {
        for k in 0..around {
            let (a, b) = (w[0][k], w[0][(k + 1) % around]);
            let (c, d) = (w[1][k], w[1][(k + 1) % around]);
            mesh.parts[NECK_PART].push([a, c, d]);
            mesh.parts[NECK_PART].push([a, d, b]);
        }
    }
}

/// The head as OBJ text (objects by material, `mtllib head.mtl`), in the head frame.
pub fn head_obj() -> String {
    let mut mesh = Mesh {
        vertices: Vec::new(),
        parts: Default::default(),
    };
    add_skin(&mut mesh);
    for side in [-1.0, 1.0] {
        add_eyeball(&mut mesh, DVec3::new(side * HALF_IPD, 0.0, EYEBALL_RADIUS));
    }
    add_neck(&mut mesh);
    let mut obj = String::from(
        "# Procedural driver's head, generated by seethru::scene::head_model::head_obj\n\
         # Origin: the midpoint of the pupils; +y up; the face looks along -z.\n\
         mtllib head.mtl\n",
    );
    for v in &mesh.vertices {
        let _ = writeln!(obj, "v {:.5} {:.5} {:.5}", v.x, v.y, v.z);
    }
    for (part, tris) in mesh.parts.iter().enumerate() {
        let name = MATERIALS[part].0;
        let _ = writeln!(obj, "o {name}\nusemtl {name}");
        for t in tris {
            let _ = writeln!(obj, "f {} {} {}", t[0] + 1, t[1] + 1, t[2] + 1);
        }
    }
    obj
}

/// The head's materials (linear RGB diffuse colours).
pub fn head_mtl() -> String {
    let mut s = String::from("# Materials of the procedural head (Kd: linear RGB)\n");
    for (name, [r, g, b]) in MATERIALS {
        let _ = write!(s, "newmtl {name}\nKd {r} {g} {b}\n\n");
    }
    s.pop();
    s
}

/// The skin's outline in the head's horizontal plane through the eyes (y = 0), head frame,
/// counter-clockwise seen from above, `samples` points: what a camera at eye height sees as
/// the head's edges on the pupils' row.
pub fn eye_row_section(samples: usize) -> Vec<DVec3> {
    use std::f64::consts::TAU;
    (0..samples)
        .map(|k| {
            let azimuth = TAU * k as f64 / samples as f64;
            let horizontal = DVec3::new(azimuth.sin(), 0.0, -azimuth.cos());
            // The direction from the skull's centre whose skin point lies on y = 0: bisect
            // the elevation (the skull's centre is above the eyes).
            let (mut lo, mut hi) = (-1.2f64, 0.6f64);
            let point =
                |e: f64| skin_point((horizontal * e.cos() + DVec3::Y * e.sin()).normalize());
            for _ in 0..50 {
                let m = 0.5 * (lo + hi);
                if point(m).y > 0.0 {
                    hi = m;
                } else {
                    lo = m;
                }
            }
            let p = point(0.5 * (lo + hi));
            DVec3::new(p.x, 0.0, p.z)
        })
        .collect()
}

/// The skin's wireframe for silhouette fits, head frame: the skull's skin grid at
/// `columns` × `rows` (the same surface as the mesh, coarser; hair quads left out) and the
/// neck's tube, as vertices and the edges of their quads (sides and one diagonal). The image
/// of a line crosses the projected wireframe exactly where it crosses the projected surface,
/// so the extreme crossings are the skin's outline on that line.
pub fn skin_wireframe(columns: usize, rows: usize) -> (Vec<DVec3>, Vec<[usize; 2]>) {
    let mut vertices = Vec::new();
    let mut undeformed = Vec::new();
    for j in 0..=rows {
        for i in 0..columns {
            let d = grid_direction(i, j, columns, rows);
            undeformed.push(SKULL_CENTRE + d / ((d / SKULL_AXES).length()));
            vertices.push(skin_point(d));
        }
    }
    let at = |i: usize, j: usize| j * columns + i % columns;
    let mut edges = Vec::new();
    for j in 0..rows {
        for i in 0..columns {
            let (a, b, c, d) = (at(i, j), at(i + 1, j), at(i + 1, j + 1), at(i, j + 1));
            let centre = (undeformed[a] + undeformed[b] + undeformed[c] + undeformed[d]) / 4.0;
            if skin_material(centre) != HAIR {
                edges.extend([[a, b], [a, d], [a, c]]);
            }
        }
    }
    // The neck (skin-coloured too): the tube of `add_neck`.
    let around = 24usize;
    let base = vertices.len();
    let levels = [(-0.05, 0.05), (-0.1, 0.052), (-0.16, 0.058)];
    for (y, r) in levels {
        for k in 0..around {
            let a = std::f64::consts::TAU * k as f64 / around as f64;
            vertices.push(DVec3::new(r * a.sin(), y, NECK.z + 0.01 - r * a.cos()));
        }
    }
    for level in 0..levels.len() - 1 {
        for k in 0..around {
            let (a, b) = (
                base + level * around + k,
                base + level * around + (k + 1) % around,
            );
            edges.extend([[a, b], [a, a + around], [a, b + around]]);
        }
    }
    (vertices, edges)
}

/// The head's rotation for a yaw (about +y, positive turns the face towards −x, the
/// driver's left) after a pitch (about +x, positive tips the face up), degrees: the
/// `rotate_deg = [pitch, yaw, 0]` of a scene.
pub fn head_rotation(yaw_deg: f64, pitch_deg: f64) -> DMat3 {
    DMat3::from_rotation_y(yaw_deg.to_radians()) * DMat3::from_rotation_x(pitch_deg.to_radians())
}

/// Where the eye goes when a head whose eye was at `eye` (facing −z, upright) turns by
/// `rotation` about its neck.
pub fn eye_turned_about_neck(eye: DVec3, rotation: DMat3) -> DVec3 {
    let neck = eye + NECK;
    neck + rotation * (-NECK)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_eye_row_outline_is_the_skin_at_eye_height() {
        let section = eye_row_section(90);
        // Every point lies on y = 0 and on the skin surface (within the bisection's tolerance).
        for p in &section {
            assert!(p.y.abs() < 1e-12);
        }
        let widest = section.iter().map(|p| p.x.abs()).fold(0.0, f64::max);
        assert!((0.06..0.09).contains(&widest), "{widest}");
        // The face's front at eye height is ahead of the pupils' plane except in the sockets.
        let ahead = section[0];
        assert!(ahead.z < 0.0 && ahead.z > -0.03, "{ahead}");
    }

    #[test]
    fn a_turn_about_the_neck_moves_the_eye_by_the_chord() {
        let eye = DVec3::new(1.0, 1.2, 0.0);
        let turned = eye_turned_about_neck(eye, head_rotation(90.0, 0.0));
        // The eye is 0.095 m in front of the neck axis (and 0.1 m above the pivot): a
        // quarter turn moves it by 0.095 √2 horizontally, none vertically.
        assert!(((turned - eye).length() - 0.095 * 2f64.sqrt()).abs() < 1e-12);
        assert!((turned.y - eye.y).abs() < 1e-12);
        assert_eq!(eye_turned_about_neck(eye, DMat3::IDENTITY), eye);
    }
}
