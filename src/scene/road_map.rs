//! An ASAM OpenDRIVE map as the scene's road: read by the `xodr` crate (which bakes the
//! reference lines, lane widths, elevation and superelevation into lane strips), turned
//! here into triangles with the colours of what each lane is for, its painted marks, the
//! faces of its kerbs, and its roadside objects; and the pose of a lane at a road's `s`, to
//! place the ego vehicle.
//!
//! Everything here is in the map's own frame: OpenDRIVE's inertial x (east), y (north) and
//! z (up), metres. `scene/road_keys.rs` places it in the world.

use std::path::Path;
use std::sync::Arc;

use anyhow::{Context, Result, anyhow, bail};
use glam::{DVec3, Vec2, Vec3};
use xodr::{LaneType, RoadNetwork, RoadPosition};

use crate::scene::limits::MAX_MESH_BYTES;
use crate::scene::mesh_io::{FileMaterial, LoadedMesh};
use crate::scene::shapes::{Tri, cuboid};
use crate::scene::source::one_line;
use crate::util::color::srgb_to_linear3;
use crate::util::hash::Fnv64;
use crate::util::input_file::read_input_text;
use crate::util::message::printable;

/// The parts of a road map's object (the `part` id of its triangles, and of the hits on
/// them).
pub mod road_part {
    /// Lanes that carry vehicles, and every lane the colours below do not name.
    pub const ASPHALT: u32 = 0;
    /// Sidewalks and kerb lanes (OpenDRIVE `sidewalk`, `curb`): their top.
    pub const SIDEWALK: u32 = 1;
    /// Borders and medians.
    pub const VERGE: u32 = 2;
    /// Painted road marks.
    pub const MARKING: u32 = 3;
    /// The vertical faces along both edges of a sidewalk or kerb lane.
    pub const KERB: u32 = 4;
    /// The map's `<object>`s (poles, barriers, buildings the map describes).
    pub const OBJECT: u32 = 5;
    /// The boards of the map's `<signal>`s (signs, traffic lights).
    pub const SIGNAL: u32 = 6;
}

/// A signal board's size where the map gives none, metres: thickness along its heading,
/// width, height (a 60 cm sign).
pub const DEFAULT_SIGNAL_SIZE: [f32; 3] = [0.05, 0.6, 0.6];

/// How deep, metres, the vertical face along each edge of a sidewalk reaches below its top:
/// deeper than any kerb, so the face meets the road beside it; what lies below the road is
/// hidden by the road.
pub const KERB_FACE_DEPTH_M: f32 = 0.25;

/// How far, metres, paint is lifted off its lane's surface: enough that a ray never finds
/// the asphalt under it first, far less than any pixel of a driver's view.
pub const PAINT_LIFT_M: f32 = 0.005;

/// How a map's surfaces look: their colours (sRGB, [0, 1]; paint takes the colour the map
/// names) and the glossy coat of the paved ones.
#[derive(Clone, Debug, PartialEq)]
pub struct RoadLook {
    pub asphalt: [f64; 3],
    pub sidewalk: [f64; 3],
    pub verge: [f64; 3],
    pub object: [f64; 3],
    /// The boards of signs (static signals).
    pub signal: [f64; 3],
    /// The housings of traffic lights (dynamic signals).
    pub traffic_light: [f64; 3],
    /// The coat's reflectance at normal incidence F0 on the lanes, sidewalks, kerb faces and
    /// marks, [0, 1]: 0 dry, 0.02 wet (water); the verges and objects have none.
    pub specular: f64,
    /// The coat's GGX roughness α, [0.01, 1].
    pub roughness: f64,
}

impl Default for RoadLook {
    fn default() -> Self {
        RoadLook {
            asphalt: [0.32, 0.32, 0.33],
            sidewalk: [0.62, 0.6, 0.56],
            verge: [0.36, 0.52, 0.22],
            object: [0.55, 0.55, 0.55],
            signal: [0.85, 0.85, 0.85],
            traffic_light: [0.08, 0.08, 0.08],
            specular: 0.0,
            roughness: crate::scene::limits::DEFAULT_ROUGHNESS,
        }
    }
}

/// A map as the scene read it: baked once, when the scene file is read, and turned into
/// triangles from that when the world is built.
#[derive(Clone)]
pub struct ParsedMap {
    pub network: Arc<RoadNetwork>,
    /// FNV-1a of the texts read, each after its length (the map's, then each `<include>`'s
    /// in the order read): the parse is a function of them, so two maps of equal texts are
    /// equal.
    pub texts_hash: u64,
}

impl PartialEq for ParsedMap {
    fn eq(&self, other: &Self) -> bool {
        self.texts_hash == other.texts_hash
    }
}

/// Without the hash: a scene's fingerprint (`scene/fingerprint.rs`) hashes its `Debug` and
/// the map's baked triangles, which a comment or a space in the file does not change.
impl std::fmt::Debug for ParsedMap {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str("ParsedMap { .. }")
    }
}

/// Reads and bakes a map, its `<include>`s read from its folder, each within the mesh size
/// limit; with it, one line per thing the importer dropped or doubted (xodr's warnings: a
/// feature it skips, a road it could not bake). Errors name the problem; the caller names
/// the file.
pub fn read_network(path: &Path) -> Result<(ParsedMap, Vec<String>)> {
    let xml = read_input_text(path, MAX_MESH_BYTES).context("cannot read it")?;
    let folder = path.parent().unwrap_or(Path::new("")).to_path_buf();
    let mut hash = Fnv64::default();
    hash.bytes(&xml.len().to_le_bytes()).bytes(xml.as_bytes());
    let (network, warnings) = parse_network(&xml, |name: &str| {
        let text = read_input_text(&folder.join(name), MAX_MESH_BYTES)
            .map_err(|e| format!("{name}: {e}"))?;
        hash.bytes(&text.len().to_le_bytes()).bytes(text.as_bytes());
        Ok(text)
    })?;
    let map = ParsedMap {
        network: Arc::new(network),
        texts_hash: hash.finish(),
    };
    Ok((map, warnings))
}

/// Bakes a map's text, `read_include` giving the text of each file an `<include>` names;
/// with it, the importer's warnings, one line each.
pub fn parse_network(
    xml: &str,
    read_include: impl FnMut(&str) -> Result<String, String>,
) -> Result<(RoadNetwork, Vec<String>)> {
    let (network, provenance) = xodr::load_str_with(xml, read_include)
        .map_err(|e| anyhow!("not a usable OpenDRIVE map: {}", one_line(&e.to_string())))?;
    if network.lanes().is_empty() {
        bail!("the map has no lanes to draw");
    }
    // A map's ids and names reach the terminal: made inert as errors are.
    let warnings = (provenance.warnings.iter())
        .map(|w| printable(&one_line(&w.to_string())))
        .collect();
    Ok((network, warnings))
}

/// What each lane type is drawn as.
fn lane_part(kind: LaneType) -> u32 {
    match kind {
        LaneType::Sidewalk | LaneType::Curb => road_part::SIDEWALK,
        LaneType::Border | LaneType::Median => road_part::VERGE,
        _ => road_part::ASPHALT,
    }
}

/// A paint colour the map names (sRGB); `standard` and names OpenDRIVE does not list are
/// white.
fn paint_color(name: &str) -> [f64; 3] {
    match name.to_ascii_lowercase().as_str() {
        "yellow" => [0.93, 0.74, 0.12],
        "blue" => [0.12, 0.3, 0.75],
        "green" => [0.15, 0.55, 0.2],
        "red" => [0.8, 0.12, 0.1],
        "orange" => [0.93, 0.5, 0.1],
        "violet" => [0.5, 0.25, 0.65],
        "black" => [0.05, 0.05, 0.05],
        _ => [0.92, 0.92, 0.9],
    }
}

fn vec3(p: xodr::Point) -> Vec3 {
    Vec3::new(p.x, p.y, p.z)
}

/// The triangles of a baked map, in its frame, with one material per colour: the permanent
/// lanes' surface (each lane coloured by what it is for), a vertical face along both edges
/// of every sidewalk, the painted marks, and the map's objects.
pub fn road_triangles(network: &RoadNetwork, look: &RoadLook) -> LoadedMesh {
    let mut mesh = LoadedMesh::default();
    // A material by name; `paved` ones carry the look's coat.
    let mut material_of = |name: String, srgb: [f64; 3], paved: bool| -> u32 {
        if let Some(i) = mesh.materials.iter().position(|m| m.name == name) {
            return i as u32;
        }
        let mut material = FileMaterial::matte(name, srgb_to_linear3(srgb).to_array());
        if paved {
            material.specular = look.specular as f32;
            material.roughness = look.roughness as f32;
        }
        mesh.materials.push(material);
        mesh.materials.len() as u32 - 1
    };
    let mut tris = Vec::new();
    let mut push = |p: [Vec3; 3], part: u32, material: u32| {
        tris.push(Tri {
            p,
            uv: [Vec2::ZERO; 3],
            part,
            file_material: Some(material),
        });
    };
    let surface = network.surface_mesh();
    for span in &surface.lanes {
        let kind = network.lane(span.lane).map_or(LaneType::None, |l| l.kind);
        let part = lane_part(kind);
        let (name, color) = match part {
            road_part::SIDEWALK => ("sidewalk", look.sidewalk),
            road_part::VERGE => ("verge", look.verge),
            _ => ("asphalt", look.asphalt),
        };
        let material = material_of(name.to_string(), color, part != road_part::VERGE);
        let vertex = |i: u32| vec3(surface.vertices[i as usize]);
        for k in span.indices.clone().step_by(3) {
            let i = &surface.indices[k as usize..k as usize + 3];
            push([vertex(i[0]), vertex(i[1]), vertex(i[2])], part, material);
        }
        if part == road_part::SIDEWALK {
            // Ribs of two vertices, left edge first: each edge is every other vertex.
            let down = Vec3::new(0.0, 0.0, KERB_FACE_DEPTH_M);
            for edge in 0..2 {
                let points: Vec<Vec3> = (span.vertices.start + edge..span.vertices.end)
                    .step_by(2)
                    .map(vertex)
                    .collect();
                for w in points.windows(2) {
                    let (a, b) = (w[0], w[1]);
                    push([a, b, b - down], road_part::KERB, material);
                    push([a, b - down, a - down], road_part::KERB, material);
                }
            }
        }
    }
    let lift = Vec3::new(0.0, 0.0, PAINT_LIFT_M);
    for mark in network.road_marks() {
        for line in &mark.lines {
            let color = if line.color.is_empty() {
                &mark.color
            } else {
                &line.color
            };
            let material = material_of(format!("paint {color}"), paint_color(color), true);
            for piece in &line.pieces {
                let [a, b, c, d] = piece.map(|p| vec3(p) + lift);
                push([a, b, c], road_part::MARKING, material);
                push([a, c, d], road_part::MARKING, material);
            }
        }
    }
    let objects = network.object_mesh();
    if !objects.indices.is_empty() {
        let material = material_of("roadside object".to_string(), look.object, false);
        for i in objects.indices.chunks_exact(3) {
            let p = [0, 1, 2].map(|k| vec3(objects.vertices[i[k] as usize]));
            push(p, road_part::OBJECT, material);
        }
    }
    for signal in network.signals() {
        let (name, color) = if signal.dynamic {
            ("traffic light", look.traffic_light)
        } else {
            ("sign", look.signal)
        };
        let material = material_of(name.to_string(), color, false);
        for p in signal_board(signal) {
            push(p, road_part::SIGNAL, material);
        }
    }
    mesh.tris = tris;
    mesh
}

/// A signal's board as triangles in the map's frame: a box of the map's size (or
/// [`DEFAULT_SIGNAL_SIZE`]) whose bottom edge's middle is the signal's position, its face
/// toward its heading, turned by its heading about +z, then its pitch and roll. No pole:
/// the map gives the board's height above the road, not where a pole would stand.
fn signal_board(signal: &xodr::Signal) -> Vec<[Vec3; 3]> {
    let [t, w, h] = DEFAULT_SIGNAL_SIZE;
    let size = [
        signal.length.filter(|l| *l > 0.0).unwrap_or(t),
        signal.width.filter(|l| *l > 0.0).unwrap_or(w),
        signal.height.filter(|l| *l > 0.0).unwrap_or(h),
    ];
    // Pitch about the turned y, nose (+x) down for a positive angle; roll about the turned
    // x, left side (+y) up for a positive angle.
    let rotation = glam::Quat::from_rotation_z(signal.heading)
        * glam::Quat::from_rotation_y(signal.pitch)
        * glam::Quat::from_rotation_x(signal.roll);
    let lift = Vec3::new(0.0, 0.0, size[2] / 2.0);
    let at = vec3(signal.position);
    cuboid(size)
        .into_iter()
        .map(|tri| tri.p.map(|p| at + rotation * (p + lift)))
        .collect()
}

/// Where a lane's centre lies at `s` metres along its road's reference line, and which way
/// its traffic runs there: the point on the road's surface (map frame, metres) and the unit
/// horizontal direction of travel.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LanePose {
    pub center: DVec3,
    pub travel: DVec3,
    /// The baked lane it is on.
    pub lane: xodr::LaneId,
}

/// The pose of lane `lane` (an OpenDRIVE lane id: negative right of the reference line,
/// positive left) of road `road` (its `<road id>`) at `s`. Errors say what the map has
/// instead.
/// Which input of [`lane_pose`] an error is about.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum PoseInput {
    Road,
    Lane,
    S,
}

/// Why [`lane_pose`] found no pose, and about which of its inputs.
#[derive(Clone, Debug, PartialEq)]
pub struct LanePoseError {
    pub about: PoseInput,
    pub message: String,
}

pub fn lane_pose(
    network: &RoadNetwork,
    road: &str,
    lane: i64,
    s: f64,
) -> Result<LanePose, LanePoseError> {
    let fail = |about: PoseInput, message: String| Err(LanePoseError { about, message });
    let Some(found) = network.road_by_od_id(road) else {
        let mut ids: Vec<&str> = network.roads().iter().map(|r| r.od_id()).take(20).collect();
        if network.roads().len() > ids.len() {
            ids.push("…");
        }
        return fail(
            PoseInput::Road,
            format!(
                "the map has no road `{road}` (its roads: {})",
                ids.join(", ")
            ),
        );
    };
    let length = found.length();
    if !(0.0..=length).contains(&s) {
        return fail(
            PoseInput::S,
            format!("road `{road}` runs from s = 0 to {length:.3} m, so s = {s} is off it"),
        );
    }
    // The lanes of that id, one per lane section; the one whose centre line passes nearest
    // the reference point at s is the section's.
    let no_surface = || LanePoseError {
        about: PoseInput::S,
        message: format!("road `{road}` has no surface at s = {s}"),
    };
    let reference = network
        .road_point(RoadPosition {
            road: found.id(),
            s,
            t: 0.0,
        })
        .ok_or_else(no_surface)?;
    let mut best: Option<(f32, &xodr::Lane)> = None;
    let mut there: Vec<i32> = Vec::new();
    for candidate in network.lanes() {
        let Some(at) = network.road_lane(candidate.id) else {
            continue;
        };
        if at.road != found.id() {
            continue;
        }
        let projection = candidate.center.project(reference);
        let gap = projection.point.distance_to(reference) - projection.offset.abs();
        // A lane of another section projects onto its end, well off the perpendicular.
        if gap.abs() < 0.05 && !there.contains(&at.od_id) {
            there.push(at.od_id);
        }
        if i64::from(at.od_id) == lane && best.is_none_or(|(g, _)| gap.abs() < g) {
            best = Some((gap.abs(), candidate));
        }
    }
    let lane_at = match best {
        Some((gap, l)) if gap < 0.05 => l,
        _ => {
            there.sort_unstable();
            let ids: Vec<String> = there.iter().map(i32::to_string).collect();
            return fail(
                PoseInput::Lane,
                format!(
                    "road `{road}` has no lane {lane} at s = {s} (its lanes there: {})",
                    ids.join(", ")
                ),
            );
        }
    };
    // The lane's centre offset t from its nearest baked centre point (the points are on the
    // lane's centre; the chords between them are not), then the point on the road at s.
    let points = lane_at.center.points();
    let nearest = points
        .iter()
        .min_by(|a, b| {
            a.distance_squared_to(reference)
                .total_cmp(&b.distance_squared_to(reference))
        })
        .copied()
        .unwrap_or(reference);
    let t = network
        .road_position_on(found.id(), nearest)
        .map_or(0.0, |p| p.t);
    let surface = |s: f64| {
        network
            .road_point(RoadPosition {
                road: found.id(),
                s,
                t,
            })
            .map(|p| DVec3::new(f64::from(p.x), f64::from(p.y), f64::from(p.z)))
            .ok_or_else(no_surface)
    };
    let center = surface(s)?;
    // The direction along the road from points half a metre apart (the surface is f32: a
    // shorter step would read its rounding as a turn): a central difference (exact on an
    // arc), or a one-sided three-point one at an end of the road.
    let h = 0.5_f64.min(length / 4.0);
    let along = if s - h < 0.0 {
        4.0 * surface(s + h)? - 3.0 * center - surface(s + 2.0 * h)?
    } else if s + h > length {
        3.0 * center - 4.0 * surface(s - h)? + surface(s - 2.0 * h)?
    } else {
        surface(s + h)? - surface(s - h)?
    };
    let forward = DVec3::new(along.x, along.y, 0.0).normalize_or_zero();
    if forward == DVec3::ZERO {
        return fail(
            PoseInput::S,
            format!("road `{road}` has no direction at s = {s}"),
        );
    }
    let travel = match lane_at.direction {
        xodr::Direction::Backward => -forward,
        _ => forward,
    };
    Ok(LanePose {
        center,
        travel,
        lane: lane_at.id,
    })
}

/// Which way to go where a lane has several lanes after it.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Turn {
    Left,
    Straight,
    Right,
}

impl Turn {
    pub const NAMES: [&'static str; 3] = ["left", "straight", "right"];

    pub fn parse(name: &str) -> Option<Turn> {
        match name {
            "left" => Some(Turn::Left),
            "straight" => Some(Turn::Straight),
            "right" => Some(Turn::Right),
            _ => None,
        }
    }
}

/// The longest route [`route_points`] follows, metres.
pub const MAX_ROUTE_M: f64 = 5000.0;

/// A lane's centre line in the order its traffic runs.
fn travel_points(lane: &xodr::Lane) -> Vec<DVec3> {
    let mut points: Vec<DVec3> = lane
        .center
        .points()
        .iter()
        .map(|p| DVec3::new(f64::from(p.x), f64::from(p.y), f64::from(p.z)))
        .collect();
    if lane.direction == xodr::Direction::Backward {
        points.reverse();
    }
    points
}

/// The horizontal direction, radians from +x towards +y, from `a` to `b`.
fn bearing(a: DVec3, b: DVec3) -> f64 {
    (b.y - a.y).atan2(b.x - a.x)
}

/// The route from `pose` along its lane and the lanes after it (map frame, in travel order):
/// where a lane has several successors, the next of `turns` picks one (the one turning
/// most to the left, the least, or most to the right), and `straight` once `turns` are
/// used up. It ends where the lane graph does, or at [`MAX_ROUTE_M`].
pub fn route_points(network: &RoadNetwork, pose: &LanePose, turns: &[Turn]) -> Vec<DVec3> {
    let Some(mut lane) = network.lane(pose.lane) else {
        return Vec::new();
    };
    let mut points = vec![pose.center];
    // The start lane from the ego's point on: the points ahead of it along the travel.
    let ahead = travel_points(lane);
    let from = ahead
        .windows(2)
        .position(|w| (w[1] - w[0]).dot(pose.center - w[1]) < 0.0)
        .map_or(ahead.len(), |i| i + 1);
    points.extend(&ahead[from..]);
    let (mut length, mut lanes) = (0.0, 1usize);
    for w in points.windows(2) {
        length += w[0].distance(w[1]);
    }
    let mut turns = turns.iter();
    while length < MAX_ROUTE_M && lanes < 10_000 {
        let next: Vec<&xodr::Lane> = lane
            .successors
            .iter()
            .filter_map(|id| network.lane(*id))
            .filter(|l| l.center.points().len() >= 2)
            .collect();
        let Some(&first) = next.first() else {
            break;
        };
        let chosen = if next.len() == 1 {
            first
        } else {
            let n = points.len();
            let entry = bearing(points[n.saturating_sub(2)], points[n - 1]);
            let turn_of = |l: &xodr::Lane| {
                let p = travel_points(l);
                let exit = bearing(p[p.len() - 2], p[p.len() - 1]);
                let d = exit - entry;
                d.sin().atan2(d.cos())
            };
            let by = |score: &dyn Fn(f64) -> f64| {
                *next
                    .iter()
                    .max_by(|a, b| score(turn_of(a)).total_cmp(&score(turn_of(b))))
                    .expect("several")
            };
            match turns.next().copied().unwrap_or(Turn::Straight) {
                Turn::Left => by(&|d| d),
                Turn::Right => by(&|d| -d),
                Turn::Straight => by(&|d| -d.abs()),
            }
        };
        for p in travel_points(chosen) {
            length += points.last().expect("one").distance(p);
            points.push(p);
        }
        lane = chosen;
        lanes += 1;
    }
    points
}
