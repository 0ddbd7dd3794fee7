//! The integrator: primary rays per pixel, Lambert shading with the sun (hard shadow ray)
//! and sky ambient, textures, and the AOVs of the pixel-centre ray.

use std::sync::atomic::{AtomicU64, Ordering};
use std::time::Instant;

use anyhow::Result;
use glam::{DAffine3, Vec3};
use rayon::prelude::*;

use crate::geometry::camera::Camera;
use crate::render::accel::{Accel, make_ray};
use crate::render::bvh::TraceRay;
use crate::render::camera_rays::CameraRays;
use crate::render::frame::{Frame, Pixel};
use crate::render::screen::{Screen, Shown};
use crate::render::settings::RenderSettings;
use crate::render::sky::SkyModel;
use crate::scene::Scene;
use crate::scene::shapes::box_face;
use crate::scene::world::{SurfaceHit, World, view_bit};
use crate::util::progress::Progress;
use crate::util::sampling::pixel_offset;

#[derive(Clone, Copy, Debug, Default)]
pub struct RenderStats {
    pub primary_rays: u64,
    pub shadow_rays: u64,
    pub seconds: f64,
}

/// Everything needed to render a scene from any camera.
pub struct RenderContext {
    pub scene: Scene,
    pub world: World,
    pub accel: Accel,
    pub sky: SkyModel,
}

impl RenderContext {
    pub fn new(scene: Scene) -> Result<Self> {
        let world = World::build(&scene)?;
        let accel = Accel::build(&world)?;
        let sky = SkyModel::new(&scene.sky, &scene.sun);
        Ok(Self {
            scene,
            world,
            accel,
            sky,
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
        self.render_with_display(camera, view, None, settings, label)
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
        self.render_with_display(
            camera,
            view_bit::SEETHRU,
            Some(display),
            settings,
            "seethru",
        )
    }

    fn render_with_display(
        &self,
        camera: &Camera,
        view: u8,
        display: Option<&dyn Screen>,
        settings: RenderSettings,
        label: &str,
    ) -> (Frame, RenderStats) {
        let start = Instant::now();
        let (w, h) = (camera.width as usize, camera.height as usize);
        let mut pixels = vec![Pixel::SKY; w * h];
        let shadow_rays = AtomicU64::new(0);
        let progress = Progress::new(format!("rendering {label}"), h, settings.progress);
        let camera_from_world = camera.world_from_camera.inverse();
        let rays = CameraRays::new(camera);
        pixels.par_chunks_mut(w).enumerate().for_each(|(y, row)| {
            let mut shadows = 0;
            for (x, out) in row.iter_mut().enumerate() {
                let job = PixelJob {
                    rays: &rays,
                    camera_from_world: &camera_from_world,
                    view,
                    display,
                };
                *out = self.render_pixel(&job, x as u32, y as u32, settings.spp, &mut shadows);
            }
            shadow_rays.fetch_add(shadows, Ordering::Relaxed);
            progress.advance(1);
        });
        progress.finish();
        let stats = RenderStats {
            primary_rays: (w * h) as u64 * settings.spp as u64,
            shadow_rays: shadow_rays.into_inner(),
            seconds: start.elapsed().as_secs_f64(),
        };
        (
            Frame::from_pixels(camera.width, camera.height, &pixels),
            stats,
        )
    }

    fn render_pixel(&self, job: &PixelJob, x: u32, y: u32, spp: u32, shadows: &mut u64) -> Pixel {
        let mut pixel = Pixel::SKY;
        let mut sum = Vec3::ZERO;
        for sample in 0..spp {
            let (dx, dy) = pixel_offset(x, y, sample);
            let (origin, dir) = (
                job.rays.origin,
                job.rays.direction(x as f32 + dx, y as f32 + dy),
            );
            let hit = self.trace(origin, dir, job.view);
            let shown = match (&hit, job.display) {
                (Some(s), Some(d))
                    if s.object == self.world.obstacle_id && s.part == box_face::POS_Z =>
                {
                    Some(self.display_content(d, s.position, shadows))
                }
                _ => None,
            };
            // A display emits its image: no shading.
            sum += match (&hit, &shown) {
                (_, Some(d)) => d.color,
                (Some(s), None) => self.shade(s, job.view, shadows),
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
                            -job.camera_from_world
                                .transform_point3(d.position.as_dvec3())
                                .z as f32
                        } else {
                            f32::INFINITY
                        },
                        ..d
                    }
                }
                (Some(s), None) => Pixel {
                    color: Vec3::ZERO,
                    depth: s.t,
                    camera_z: -job
                        .camera_from_world
                        .transform_point3(s.position.as_dvec3())
                        .z as f32,
                    position: s.position,
                    normal: s.normal,
                    object_id: s.object,
                    part_id: s.part,
                },
                (None, None) => Pixel::SKY,
            };
        }
        pixel.color = sum / spp as f32;
        pixel
    }

    /// What the display shows at a world point on its face: a display pixel, or — for the
    /// ideal display — what the frontal camera's ray through the exact crop point meets.
    fn display_content(&self, display: &dyn Screen, at: Vec3, shadows: &mut u64) -> Pixel {
        match display.shown_at(at) {
            Shown::Pixel(p) => p,
            Shown::FrontalRay(origin, dir) => match self.trace(origin, dir, view_bit::FRONTAL) {
                Some(s) => Pixel {
                    color: self.shade(&s, view_bit::FRONTAL, shadows),
                    depth: s.t,
                    camera_z: s.t,
                    position: s.position,
                    normal: s.normal,
                    object_id: s.object,
                    part_id: s.part,
                },
                None => Pixel {
                    color: self.sky.radiance(dir),
                    ..Pixel::SKY
                },
            },
        }
    }

    /// The closest surface visible in `view` along a ray from `origin` (unit `dir`).
    pub fn trace(&self, origin: Vec3, dir: Vec3, view: u8) -> Option<SurfaceHit> {
        let hit = self
            .accel
            .closest(&make_ray(origin, dir, 0.0, f32::INFINITY), view)?;
        Some(self.world.surface(hit.prim, origin, dir, hit.t))
    }

    /// Lambert shading: albedo × (sun × cos × visibility + sky ambient).
    fn shade(&self, s: &SurfaceHit, view: u8, shadows: &mut u64) -> Vec3 {
        let material = &self.world.materials[s.material as usize];
        let mut albedo = material.albedo;
        if let Some(t) = material.texture {
            albedo *= self.world.textures[t].sample(s.uv * material.uv_repeat);
        }
        let mut light = self.sky.ambient(s.normal);
        let cos = s.normal.dot(self.sky.sun_direction);
        if cos > 0.0 {
            *shadows += 1;
            let ray = shadow_ray(s.position, s.normal, self.sky.sun_direction);
            if !self.accel.occluded(&ray, view) {
                light += self.sky.sun_irradiance * cos;
            }
        }
        albedo * light
    }
}

/// What every pixel of one render shares.
struct PixelJob<'a> {
    rays: &'a CameraRays,
    camera_from_world: &'a DAffine3,
    view: u8,
    display: Option<&'a dyn Screen>,
}

/// A ray leaving a surface point `position` (unit normal `normal`) in direction `dir`: its
/// origin is offset along the normal, scaled with the coordinates' magnitude to stay above
/// the f32 rounding of the hit point.
pub fn shadow_ray(position: Vec3, normal: Vec3, dir: Vec3) -> TraceRay {
    let eps = 2e-4 * (1.0 + position.abs().max_element());
    make_ray(position + normal * eps, dir, 0.0, f32::INFINITY)
}
