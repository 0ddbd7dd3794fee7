//! The compensation methods that model the scene beyond one fronto-parallel plane: the road
//! plane (`ground`), a plane fitted to the depth sensor's points (`plane-fit`) and per-pixel
//! reprojection with the sensor's depth (`depth`). Each gives, for every display pixel, the
//! frontal point to show (or a hole, or nothing); the display image is the frontal frame
//! sampled there, as the planar crop samples it.

use anyhow::{Result, bail};
use glam::{DVec2, DVec3};
use rayon::prelude::*;
use serde_json::json;

use crate::geometry::camera::Camera;
use crate::render::frame::{Frame, Pixel};
use crate::render::integrator::RenderContext;
use crate::scene::Scene;
use crate::system::compensation::Crop;
use crate::system::depth_search::{Found, search};
use crate::system::depth_sensor::{DepthMap, SensorModel, sense_from};
use crate::system::display::{DisplayModel, MISSING_ID, sample};
use crate::system::options::{Method, RunOptions};
pub use crate::system::scene_model_options::{Fill, SceneModelOptions};
use crate::system::scene_plane::{ScenePlane, fit_plane, ground_plane};

impl Method {
    /// Whether the method models the scene per display pixel (not one crop of the frontal
    /// image): `ground`, `plane-fit`, `depth`.
    pub fn models_the_scene(self) -> bool {
        matches!(self, Method::Ground | Method::PlaneFit | Method::Depth)
    }
}

/// Checks the sensor options against the frontal camera, and that the scene admits the
/// method ([`scene_model_unavailable`]).
pub fn check_scene_model(scene: &Scene, options: &RunOptions) -> Result<()> {
    check_scene_model_options(scene, options)?;
    match scene_model_unavailable(scene, options.method) {
        Some(reason) => bail!("{reason}"),
        None => Ok(()),
    }
}

/// The checks of the options alone (a bad flag is an error whatever the scene): no ideal
/// display, and a sensor that fits the frontal camera (`plane-fit`, `depth`).
pub fn check_scene_model_options(scene: &Scene, options: &RunOptions) -> Result<()> {
    if options.display == DisplayModel::Ideal {
        bail!(
            "option `display` ideal works with option `method` none or planar (a crop); ground, plane-fit and depth model the physical display's pixels"
        );
    }
    if options.method != Method::Ground {
        SensorModel::resolve(&options.scene_model.sensor, &scene.frontal)?;
    }
    Ok(())
}

/// Why `method` cannot run on `scene` whatever the flags (`None`: it can): `ground` needs a
/// road, and every scene-model method the true frontal camera. `seethru compare` shows the
/// reason in the method's row.
pub fn scene_model_unavailable(scene: &Scene, method: Method) -> Option<String> {
    // A frontal lens is followed exactly (each reconstructed point is projected through it),
    // but the reconstruction itself uses the true frontal camera: a calibration error is the
    // planar crop's to study.
    let name = clap::ValueEnum::to_possible_value(&method)
        .map_or_else(String::new, |v| v.get_name().to_string());
    if !scene.calibration.frontal.is_exact() {
        return Some(format!(
            "option `method` {name}: the [calibration.frontal] is not exact; ground, plane-fit and depth use the true frontal camera (use option `method` planar to study calibration error)"
        ));
    }
    if method == Method::Ground {
        return ground_plane(scene).err().map(|e| format!("{e:#}"));
    }
    None
}

/// The display image of a scene-model method, its holes and what it used.
pub struct SceneModelDisplay {
    pub display: Frame,
    /// Display pixels (row-major) that are holes: disocclusions (`depth`), and points
    /// outside the frontal lens's domain (any of the three).
    pub holes: Vec<bool>,
    /// For `run.json`: the sensor, the plane, the holes.
    pub report: serde_json::Value,
}

fn blank() -> Pixel {
    Pixel {
        object_id: MISSING_ID,
        ..Pixel::SKY
    }
}

/// The display image for `run.method` (one of [`Method::models_the_scene`]) at the eye
/// `eye`; `crop` is the d2 → ∞ crop (its region is where the plane is fitted). The sensor,
/// fill, filter and seed are the run's; the sensor senses from `captured_from`, the frontal
/// camera where it captured `frontal` (pipeline.rs's `FrontalCapture`).
pub fn scene_model_display(
    ctx: &RenderContext,
    scene: &Scene,
    eye: DVec3,
    frontal: &Frame,
    crop: &Crop,
    run: &RunOptions,
    captured_from: &Camera,
) -> Result<SceneModelDisplay> {
    let (method, options, filter, seed) = (run.method, &run.scene_model, run.filter, run.seed);
    let camera = &scene.frontal;
    let sensor = || -> Result<DepthMap> {
        let model = SensorModel::resolve(&options.sensor, camera)?;
        Ok(sense_from(ctx, captured_from, camera, frontal, model, seed))
    };
    let mut report = serde_json::Map::new();
    let found: Box<dyn Fn(DVec3) -> Found + Sync> = match method {
        Method::Ground | Method::PlaneFit => {
            let plane = if method == Method::Ground {
                ground_plane(scene)?
            } else {
                let map = sensor()?;
                // The crop's region in sensor pixels (same field of view, other resolution).
                let to_sensor = DVec2::new(
                    map.camera.width as f64 / camera.width as f64,
                    map.camera.height as f64 / camera.height as f64,
                );
                let (min, max) = crop.bounds();
                let (plane, inliers) = fit_plane(&map, min * to_sensor, max * to_sensor, seed)?;
                report.insert("sensor".into(), json!(map.model));
                report.insert("plane_fit_inliers".into(), json!(inliers));
                plane
            };
            report.insert("plane".into(), plane_json(&plane));
            Box::new(
                move |on_display| match plane.frontal_point(eye, on_display, camera) {
                    Some(p) => Found::Seen(p),
                    // A pinhole fails only behind itself: nothing to show, as before lenses.
                    None if camera.lens.is_none() => Found::Outside,
                    None => Found::BeyondLens,
                },
            )
        }
        Method::Depth => {
            let map = sensor()?;
            report.insert("sensor".into(), json!(map.model));
            report.insert("search".into(), json!("backward search along the epipolar line in half sensor-pixel steps; sensor pixels as fronto-parallel tiles; a jump nearer by more than 25 % in depth is a silhouette"));
            let camera = *camera;
            Box::new(move |on_display| search(&map, &camera, eye, on_display))
        }
        _ => bail!("{method:?} is not a scene-model method"),
    };
    let [dw, dh] = scene.obstacle.display_resolution;
    // Each display pixel's point on the display's surface, flat or curved.
    let points = crate::system::surface_map::display_points(&scene.obstacle);
    let looks: Vec<Found> = points
        .par_iter()
        .map(|p| p.map_or(Found::Outside, &found))
        .collect();
    // A point outside the frontal lens's domain is a hole too (blank, or inpainted), with no
    // farther surface for the background fill.
    let holes: Vec<bool> = looks
        .iter()
        .map(|f| matches!(f, Found::Hole(_) | Found::BeyondLens))
        .collect();
    let beyond_lens = looks
        .iter()
        .filter(|f| matches!(f, Found::BeyondLens))
        .count();
    let mut pixels: Vec<Pixel> = looks
        .par_iter()
        .map(|f| match *f {
            Found::Seen(p) => sample(frontal, p, filter),
            Found::Hole(p) if options.fill == Fill::Background => sample(frontal, p, filter),
            _ => blank(),
        })
        .collect();
    if options.fill == Fill::Inpaint {
        inpaint(&mut pixels, &holes, dw as usize);
    }
    let hole_count = holes.iter().filter(|&&h| h).count();
    if method == Method::Depth || beyond_lens > 0 {
        report.insert(
            "holes".into(),
            json!({
                "display_pixels": hole_count,
                "fraction_of_display": hole_count as f64 / holes.len() as f64,
                "beyond_frontal_lens_display_pixels": beyond_lens,
                "fill": options.fill,
            }),
        );
    }
    Ok(SceneModelDisplay {
        display: Frame::from_pixels(dw, dh, &pixels),
        holes,
        report: serde_json::Value::Object(report),
    })
}

fn plane_json(plane: &ScenePlane) -> serde_json::Value {
    json!({
        "normal_world": plane.normal.to_array(),
        "offset_m": plane.offset,
        "tilt_from_horizontal_deg": plane.tilt_from_horizontal_deg(),
        "convention": "points p (world, metres) with normal · p = offset",
    })
}

/// Fills hole pixels layer by layer from their known 4-neighbours (the known pixels of the
/// previous layer only, so the result does not depend on the scan order): colour their mean,
/// every other AOV from the farthest of them (the background side of a silhouette).
fn inpaint(pixels: &mut [Pixel], holes: &[bool], width: usize) {
    let height = pixels.len() / width;
    let mut known: Vec<bool> = holes.iter().map(|h| !h).collect();
    loop {
        let mut layer: Vec<(usize, Pixel)> = Vec::new();
        for i in (0..pixels.len()).filter(|&i| !known[i]) {
            let (x, y) = (i % width, i / width);
            let neighbours = [
                (x > 0).then(|| i - 1),
                (x + 1 < width).then(|| i + 1),
                (y > 0).then(|| i - width),
                (y + 1 < height).then(|| i + width),
            ];
            let around: Vec<&Pixel> = neighbours
                .iter()
                .flatten()
                .filter(|&&j| known[j] && pixels[j].object_id != MISSING_ID)
                .map(|&j| &pixels[j])
                .collect();
            if let Some(farthest) = around.iter().max_by(|a, b| a.depth.total_cmp(&b.depth)) {
                let mut p = **farthest;
                p.color = around.iter().map(|q| q.color).sum::<glam::Vec3>() / around.len() as f32;
                layer.push((i, p));
            }
        }
        if layer.is_empty() {
            return;
        }
        for (i, p) in layer {
            pixels[i] = p;
            known[i] = true;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn inpainting_fills_a_hole_from_its_rim_whatever_the_order() {
        let w = 5;
        let mut pixels: Vec<Pixel> = (0..25)
            .map(|i| Pixel {
                color: glam::Vec3::splat((i % w) as f32),
                depth: (i % w) as f32,
                object_id: 1,
                ..Pixel::SKY
            })
            .collect();
        let mut holes = vec![false; 25];
        for i in [6, 7, 8, 11, 12, 13, 16, 17, 18] {
            holes[i] = true;
            pixels[i] = blank();
        }
        inpaint(&mut pixels, &holes, w);
        assert!(pixels.iter().all(|p| p.object_id == 1));
        // The first layer: every hole pixel beside the rim, from its rim neighbours only
        // (pixel 11 has one: colour 0); the second, the centre from the first layer's 0, 4, 2, 2.
        assert_eq!(pixels[11].color.x, 0.0);
        assert_eq!(pixels[12].color.x, 2.0);
        // AOVs come from the farthest known neighbour.
        assert_eq!(pixels[13].depth, 4.0);
        assert_eq!(pixels[12].depth, 4.0);
    }

    /// The fill as the doc comment states it, written out on (x, y) with signed coordinates:
    /// a brute-force twin of `inpaint` for any hole pattern.
    fn inpaint_by_layers(pixels: &[Pixel], holes: &[bool], width: usize) -> Vec<Pixel> {
        let height = pixels.len() / width;
        let mut out = pixels.to_vec();
        let mut known: Vec<Vec<bool>> = (0..height)
            .map(|y| (0..width).map(|x| !holes[y * width + x]).collect())
            .collect();
        loop {
            let mut layer = Vec::new();
            for y in 0..height as i64 {
                for x in 0..width as i64 {
                    if known[y as usize][x as usize] {
                        continue;
                    }
                    let mut around: Vec<Pixel> = Vec::new();
                    for (nx, ny) in [(x - 1, y), (x + 1, y), (x, y - 1), (x, y + 1)] {
                        let inside =
                            (0..width as i64).contains(&nx) && (0..height as i64).contains(&ny);
                        if inside && known[ny as usize][nx as usize] {
                            let q = out[ny as usize * width + nx as usize];
                            if q.object_id != MISSING_ID {
                                around.push(q);
                            }
                        }
                    }
                    if around.is_empty() {
                        continue;
                    }
                    let mut p = around[0];
                    for q in &around {
                        if q.depth > p.depth {
                            p = *q;
                        }
                    }
                    let mut sum = glam::Vec3::ZERO;
                    for q in &around {
                        sum += q.color;
                    }
                    p.color = sum / around.len() as f32;
                    layer.push((y as usize * width + x as usize, p));
                }
            }
            if layer.is_empty() {
                return out;
            }
            for (i, p) in layer {
                out[i] = p;
                known[i / width][i % width] = true;
            }
        }
    }

    #[test]
    fn inpainting_equals_its_twin_at_the_borders_and_beside_pixels_outside_the_frontal_image() {
        // 7 × 5, holes (H) on every border and in two corners, known pixels outside the
        // frontal image (O, MISSING_ID) beside holes, and a hole (h) walled in by those that
        // no known pixel reaches:
        //   H H . . . O H
        //   H . . O . . H
        //   . . H H O O O
        //   . O . H O h O
        //   H . . . . O O
        let rows = ["HH...OH", "H..O..H", "..HHOOO", ".O.HOhO", "H....OO"];
        let width = 7;
        let mut pixels = Vec::new();
        let mut holes = Vec::new();
        for (y, row) in rows.iter().enumerate() {
            for (x, c) in row.chars().enumerate() {
                let i = (y * width + x) as f32;
                // Distinct colours and depths: a neighbour taken from the wrong place, or a
                // farthest one chosen wrongly, shows.
                let known = Pixel {
                    color: glam::Vec3::new(i, 2.0 * i + 1.0, 35.0 - i),
                    depth: 1.0 + ((7 * y + 3 * x) % 11) as f32 + 0.01 * i,
                    object_id: 1 + (x + y) as u32,
                    ..Pixel::SKY
                };
                pixels.push(match c {
                    '.' => known,
                    _ => blank(),
                });
                holes.push(matches!(c, 'H' | 'h'));
            }
        }
        let expected = inpaint_by_layers(&pixels, &holes, width);
        inpaint(&mut pixels, &holes, width);
        for (i, (got, want)) in pixels.iter().zip(&expected).enumerate() {
            assert_eq!(got.object_id, want.object_id, "pixel {i}");
            assert_eq!(got.depth, want.depth, "pixel {i}");
            assert!(
                (got.color - want.color).abs().max_element() < 1e-5,
                "pixel {i}: {} vs {}",
                got.color,
                want.color
            );
        }
        // Every hole a known pixel reaches is filled; the walled-in one stays blank, as do
        // the pixels outside the frontal image.
        let layout: String = rows.concat();
        for (i, c) in layout.chars().enumerate() {
            let blank_after = matches!(c, 'O' | 'h');
            assert_eq!(pixels[i].object_id == MISSING_ID, blank_after, "pixel {i}");
            assert_eq!(pixels[i].depth.is_finite(), !blank_after, "pixel {i}");
        }
    }
}
