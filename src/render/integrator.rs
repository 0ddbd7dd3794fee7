//! The integrator: primary rays per pixel, Lambert shading with the sun (hard shadow ray)
//! and sky ambient, textures, and the AOVs of the pixel-centre ray.
//!
//! Frames are rendered in bands of rows on the rayon pool, each band written straight into
//! the frame's buffers; every pixel depends only on its own coordinates, so images are the
//! same for any number of threads. Views of one camera that differ only by a few primitives
//! (`truth`, `occluded`, `seethru`) are rendered once and re-rendered only where those
//! primitives can be seen ([`RenderContext::render_over`]).

use std::sync::Arc;
use std::time::Instant;

use anyhow::Result;
use glam::{DAffine3, Vec3};
use rayon::prelude::*;

use crate::geometry::camera::Camera;
use crate::render::accel::{Accel, Difference, make_ray};
use crate::render::bvh::Stack;
use crate::render::camera_rays::CameraRays;
use crate::render::footprint::{PixelRect, footprint};
use crate::render::frame::{Frame, Pixel};
use crate::render::moving::MovingLayer;
use crate::render::ray::TraceRay;
use crate::render::screen::{Screen, Shown};
use crate::render::settings::RenderSettings;
use crate::render::sky::SkyModel;
use crate::scene::Scene;
use crate::scene::texture::Texture;
use crate::scene::world::{SurfaceHit, SurfaceMaterial, World, view_bit};
use crate::util::progress::Progress;
use crate::util::sampling::pixel_offset;

thread_local! {
    /// The traversal stack of [`RenderContext::trace`].
    static STACK: std::cell::RefCell<Stack> = std::cell::RefCell::new(Stack::new());
}

/// Rows per rayon task: small enough to balance many threads, large enough to amortise.
const BAND_ROWS: u32 = 4;

#[derive(Clone, Copy, Debug, Default)]
pub struct RenderStats {
    pub primary_rays: u64,
    pub shadow_rays: u64,
    pub seconds: f64,
}

/// Everything needed to render a scene from any camera. The world, its hierarchy and the
/// sky are shared between contexts of scenes that differ only in their cameras
/// ([`RenderContext::with_scene`]).
pub struct RenderContext {
    pub scene: Scene,
    pub world: Arc<World>,
    pub accel: Arc<Accel>,
    pub sky: Arc<SkyModel>,
    /// What moves, at one instant of a sequence: traced beside `world` (which then holds only
    /// what stands still); `None` everywhere else.
    pub moving: Option<Arc<MovingLayer>>,
}

/// What every pixel of one render shares.
struct PixelJob<'a> {
    rays: CameraRays,
    camera_from_world: DAffine3,
    view: u8,
    display: Option<&'a dyn Screen>,
    spp: u32,
}

impl RenderContext {
    pub fn new(scene: Scene) -> Result<Self> {
        let world = World::build(&scene)?;
        let accel = Accel::build(&world)?;
        let sky = SkyModel::new(&scene.sky, &scene.sun);
        Ok(Self {
            scene,
            world: Arc::new(world),
            accel: Arc::new(accel),
            sky: Arc::new(sky),
            moving: None,
        })
    }

    /// A context for `scene`, reusing this one's world and hierarchy when `scene` differs
    /// from this context's only in its cameras, and its sky when sky and sun are the same.
    pub fn with_scene(&self, scene: Scene) -> Result<Self> {
        let sky = if (&scene.sky, &scene.sun) == (&self.scene.sky, &self.scene.sun) {
            self.sky.clone()
        } else {
            Arc::new(SkyModel::new(&scene.sky, &scene.sun))
        };
        let (world, accel) = if same_geometry(&scene, &self.scene) {
            (self.world.clone(), self.accel.clone())
        } else {
            let world = World::build(&scene)?;
            let accel = Accel::build(&world)?;
            (Arc::new(world), Arc::new(accel))
        };
        Ok(Self {
            scene,
            world,
            accel,
            sky,
            moving: None,
        })
    }

    /// Renders the frame seen by `camera`, showing the primitives visible in `view`
    /// (a [`view_bit`]).
    pub fn render(
        &self,
        camera: &Camera,
        view: u8,
        settings: RenderSettings,
        label: &str,
    ) -> (Frame, RenderStats) {
        let mut frame = Frame::new(camera.width, camera.height);
        let stats = self.render_into(camera, view, settings, &mut frame, label);
        (frame, stats)
    }

    /// [`RenderContext::render`] into an existing frame of the camera's size, so that a
    /// sequence of renders reuses its buffers.
    pub fn render_into(
        &self,
        camera: &Camera,
        view: u8,
        settings: RenderSettings,
        frame: &mut Frame,
        label: &str,
    ) -> RenderStats {
        let region = PixelRect::full(camera);
        self.render_rect(camera, view, None, settings, region, frame, label)
    }

    /// The `seethru` view: the driver's eye with the obstacle present and its display showing
    /// `display`. Where a ray meets the display face, the pixel takes the display pixel there
    /// — colour and every AOV, so the frame holds the world point and id the display shows.
    pub fn render_seethru(
        &self,
        camera: &Camera,
        display: &dyn Screen,
        settings: RenderSettings,
    ) -> (Frame, RenderStats) {
        let mut frame = Frame::new(camera.width, camera.height);
        let region = PixelRect::full(camera);
        let stats = self.render_rect(
            camera,
            view_bit::SEETHRU,
            Some(display),
            settings,
            region,
            &mut frame,
            "seethru",
        );
        (frame, stats)
    }

    /// Renders `view` (with `display` for the `seethru` view) from `camera`, given `base`, the
    /// same camera's frame in `base_view` with the same settings: only the pixels where the
    /// two views can differ are traced, the others are copied. The result is bit for bit
    /// the frame [`RenderContext::render`] (or [`RenderContext::render_seethru`]) gives.
    #[allow(clippy::too_many_arguments)]
    pub fn render_over(
        &self,
        camera: &Camera,
        base: &Frame,
        base_view: u8,
        view: u8,
        display: Option<&dyn Screen>,
        settings: RenderSettings,
        label: &str,
    ) -> (Frame, RenderStats) {
        assert_eq!((base.width, base.height), (camera.width, camera.height));
        let region = self.difference_region(camera, base_view, view);
        let mut frame = base.clone();
        let stats = self.render_rect(camera, view, display, settings, region, &mut frame, label);
        (frame, stats)
    }

    /// The pixels of `camera` where views `a` and `b` can differ (see [`Accel::difference`]).
    pub fn difference_region(&self, camera: &Camera, a: u8, b: u8) -> PixelRect {
        let difference = match &self.moving {
            Some(m) => self.accel.difference(a, b).union(m.accel.difference(a, b)),
            None => self.accel.difference(a, b),
        };
        match difference {
            Difference::None => PixelRect {
                x0: 0,
                y0: 0,
                x1: 0,
                y1: 0,
            },
            Difference::Within(bounds) => footprint(camera, &bounds),
            Difference::Everywhere => PixelRect::full(camera),
        }
    }

    /// Renders only the pixels of `region` of `view` (with `display` for `seethru`) into
    /// `frame`, a frame of the camera's size; the other pixels keep what they held. Each
    /// pixel is what [`RenderContext::render`] gives it.
    #[allow(clippy::too_many_arguments)]
    pub fn render_rect(
        &self,
        camera: &Camera,
        view: u8,
        display: Option<&dyn Screen>,
        settings: RenderSettings,
        region: PixelRect,
        frame: &mut Frame,
        label: &str,
    ) -> RenderStats {
        assert_eq!((frame.width, frame.height), (camera.width, camera.height));
        let start = Instant::now();
        let job = PixelJob {
            rays: CameraRays::new(camera),
            camera_from_world: camera.world_from_camera.inverse(),
            view,
            display,
            spp: settings.spp,
        };
        let bands: Vec<_> = frame
            .bands_mut(BAND_ROWS)
            .into_iter()
            .filter(|b| b.y < region.y1 && b.y + b.len() > region.y0)
            .collect();
        let progress = Progress::new(format!("rendering {label}"), bands.len(), settings.progress);
        let shadow_rays: u64 = bands
            .into_par_iter()
            .map_init(Stack::new, |stack, mut band| {
                let mut shadows = 0;
                // A cancelled render (render/cancel.rs) leaves its remaining bands as they are.
                if crate::render::cancel::requested() {
                    return shadows;
                }
                for row in 0..band.len() {
                    let y = band.y + row;
                    if y < region.y0 || y >= region.y1 {
                        continue;
                    }
                    for x in region.x0..region.x1 {
                        let pixel = self.render_pixel(&job, x, y, stack, &mut shadows);
                        band.set(x, row, pixel);
                    }
                }
                progress.advance(1);
                shadows
            })
            .sum();
        progress.finish();
        RenderStats {
            primary_rays: region.pixels() * u64::from(settings.spp),
            shadow_rays,
            seconds: start.elapsed().as_secs_f64(),
        }
    }

    fn render_pixel(
        &self,
        job: &PixelJob,
        x: u32,
        y: u32,
        stack: &mut Stack,
        shadows: &mut u64,
    ) -> Pixel {
        let mut pixel = Pixel::SKY;
        let mut sum = Vec3::ZERO;
        for sample in 0..job.spp {
            let (dx, dy) = pixel_offset(x, y, sample);
            let origin = job.rays.origin;
            let dir = job.rays.direction(x as f32 + dx, y as f32 + dy);
            let hit = self.trace_with(origin, dir, job.view, stack);
            let shown = match (&hit, job.display) {
                (Some(s), Some(d)) if self.world.is_display(s.object, s.part) => {
                    Some(self.display_content(d, s.position, stack, shadows))
                }
                _ => None,
            };
            // A display emits its image: no shading.
            sum += match (&hit, &shown) {
                (_, Some(d)) => d.color,
                (Some(s), None) => self.shade(s, job.view, stack, shadows),
                (None, None) => self.sky.radiance(dir),
            };
            if sample != 0 {
                continue;
            }
            pixel = match (hit, shown) {
                (_, Some(d)) => {
                    // The AOVs of what the display shows, measured from this eye.
                    let finite = d.position.is_finite();
                    Pixel {
                        depth: if finite {
                            (d.position - origin).length()
                        } else {
                            f32::INFINITY
                        },
                        camera_z: if finite {
                            axial_depth(&job.camera_from_world, d.position)
                        } else {
                            f32::INFINITY
                        },
                        ..d
                    }
                }
                (Some(s), None) => Pixel {
                    color: Vec3::ZERO,
                    depth: s.t,
                    camera_z: axial_depth(&job.camera_from_world, s.position),
                    position: s.position,
                    normal: s.normal,
                    object_id: s.object,
                    part_id: s.part,
                },
                // The sky direction travels with the pixel, as a world point does.
                (None, None) => Pixel {
                    normal: -dir,
                    ..Pixel::SKY
                },
            };
        }
        pixel.color = sum / job.spp as f32;
        pixel
    }

    /// What the display shows at a world point on its face: a display pixel, or — for the
    /// ideal display — what the frontal camera's ray through the exact crop point meets.
    fn display_content(
        &self,
        display: &dyn Screen,
        at: Vec3,
        stack: &mut Stack,
        shadows: &mut u64,
    ) -> Pixel {
        match display.shown_at(at) {
            Shown::Pixel(p) => p,
            Shown::FrontalRay(origin, dir) => {
                match self.trace_with(origin, dir, view_bit::FRONTAL, stack) {
                    Some(s) => Pixel {
                        color: self.shade(&s, view_bit::FRONTAL, stack, shadows),
                        depth: s.t,
                        camera_z: s.t,
                        position: s.position,
                        normal: s.normal,
                        object_id: s.object,
                        part_id: s.part,
                    },
                    None => Pixel {
                        color: self.sky.radiance(dir),
                        normal: -dir,
                        ..Pixel::SKY
                    },
                }
            }
        }
    }

    /// The closest surface visible in `view` along a ray from `origin` (unit `dir`).
    pub fn trace(&self, origin: Vec3, dir: Vec3, view: u8) -> Option<SurfaceHit> {
        STACK.with_borrow_mut(|stack| self.trace_with(origin, dir, view, stack))
    }

    #[inline]
    fn trace_with(
        &self,
        origin: Vec3,
        dir: Vec3,
        view: u8,
        stack: &mut Stack,
    ) -> Option<SurfaceHit> {
        let mut ray = make_ray(origin, dir, 0.0, f32::INFINITY);
        let hit = self.accel.closest_with(&ray, view, stack);
        if let Some(m) = &self.moving {
            if let Some(h) = hit {
                ray.tmax = h.t;
            }
            // A moving primitive only where it is strictly nearer: ties go to the static one.
            if let Some(h) = m.accel.closest_with(&ray, view, stack)
                && hit.is_none_or(|s| h.t < s.t)
            {
                let mut s = m.world.surface(h.prim, origin, dir, h.t);
                // The moving world's materials are numbered after the static world's.
                s.material += self.world.materials.len() as u32;
                return Some(s);
            }
        }
        hit.map(|h| self.world.surface(h.prim, origin, dir, h.t))
    }

    /// A material of [`SurfaceHit::material`] and the textures it indexes.
    fn material(&self, index: u32) -> (&SurfaceMaterial, &[Texture]) {
        let own = self.world.materials.len() as u32;
        match &self.moving {
            Some(m) if index >= own => (
                &m.world.materials[(index - own) as usize],
                &m.world.textures,
            ),
            _ => (&self.world.materials[index as usize], &self.world.textures),
        }
    }

    /// Lambert shading: albedo × (sun × cos × visibility + sky ambient).
    fn shade(&self, s: &SurfaceHit, view: u8, stack: &mut Stack, shadows: &mut u64) -> Vec3 {
        let (material, textures) = self.material(s.material);
        let mut albedo = material.albedo;
        if let Some(t) = material.texture {
            albedo *= textures[t].sample(s.uv * material.uv_repeat);
        }
        let mut light = self.sky.ambient(s.normal);
        let cos = s.normal.dot(self.sky.sun_direction);
        if cos > 0.0 {
            *shadows += 1;
            let ray = shadow_ray(s.position, s.normal, self.sky.sun_direction);
            let blocked = self.accel.occluded_with(&ray, view, stack)
                || self
                    .moving
                    .as_ref()
                    .is_some_and(|m| m.accel.occluded_with(&ray, view, stack));
            if !blocked {
                light += self.sky.sun_irradiance * cos;
            }
        }
        albedo * light
    }
}

/// Whether two scenes have the same world (objects, materials, obstacle): they may differ
/// in their cameras, sky and sun.
pub fn same_geometry(a: &Scene, b: &Scene) -> bool {
    let mut a = a.clone();
    (a.driver, a.frontal, a.back) = (b.driver, b.frontal, b.back);
    (a.sky, a.sun) = (b.sky.clone(), b.sun.clone());
    a == *b
}

/// Depth along the camera's viewing axis of a world point: the z row of `camera_from_world`,
/// in f64 as `DAffine3::transform_point3` computes it.
#[inline]
fn axial_depth(camera_from_world: &DAffine3, p: Vec3) -> f32 {
    let m = &camera_from_world.matrix3;
    let p = p.as_dvec3();
    let z = m.x_axis.z * p.x + m.y_axis.z * p.y + m.z_axis.z * p.z;
    -(z + camera_from_world.translation.z) as f32
}

/// A ray leaving a surface point `position` (unit normal `normal`) in direction `dir`: its
/// origin is offset along the normal, scaled with the coordinates' magnitude to stay above
/// the f32 rounding of the hit point.
pub fn shadow_ray(position: Vec3, normal: Vec3, dir: Vec3) -> TraceRay {
    let eps = 2e-4 * (1.0 + position.abs().max_element());
    make_ray(position + normal * eps, dir, 0.0, f32::INFINITY)
}
