//! The integrator: primary rays per pixel, Lambert shading with the sun (hard shadow ray)
//! and sky ambient, textures, and the AOVs of the pixel-centre ray. A render job
//! (render/render_job.rs) runs it over the bands of a frame.
//!
//! A pixel is traced on its own (`render_pixel`), or with the others of its 4×4 tile
//! (`render_tile`): the tile's camera rays as one packet ([`crate::render::bvh_packet`]), then
//! the shadow rays toward the sun from its lit hits as another. Both give the same image bit
//! for bit; the per-ray path is the packets' twin in tests.

use std::ops::Range;
use std::sync::Arc;

use anyhow::Result;
use glam::{DAffine3, Vec3};

use crate::geometry::camera::Camera;
use crate::render::accel::{Accel, make_ray};
use crate::render::bvh::Stack;
use crate::render::bvh_packet::{PACKET, PacketStack, RayPacket};
use crate::render::frame::{Pixel, Rows};
use crate::render::moving::MovingLayer;
use crate::render::ray::{Hit, TraceRay};
use crate::render::screen::{Screen, Shown};
use crate::render::shutter_rays::{CameraAt, PoseAt, ShutterRays};
use crate::render::simd::Isa;
use crate::render::sky::SkyModel;
use crate::render::specular;
use crate::scene::texture::Texture;
use crate::scene::world::{SurfaceHit, SurfaceMaterial, World, view_bit};
use crate::scene::{DisplayLight, LampSampling, Scene};
use crate::util::color::luminance;
use crate::util::color::srgb_to_linear3;
use crate::util::sampling::{hash_u32, hash_words, pixel_offset, unit_float};

thread_local! {
    /// The traversal stack of [`RenderContext::trace`].
    static STACK: std::cell::RefCell<Stack> = std::cell::RefCell::new(Stack::new());
}

/// The parts of the shading known before the sun's shadow ray is traced.
#[derive(Clone, Copy)]
struct Shading {
    /// The diffuse albedo: the material's (textured), × (1 − F0) under a glossy lobe.
    albedo: Vec3,
    /// Sky ambient.
    light: Vec3,
    /// Cosine of the sun to the normal: a shadow ray is traced where it is positive (0 where
    /// the sun is drawn with the lamps, [`LampSampling::One`]).
    cos: f32,
    /// The lamps' light (`[[light]]`), as the sky's: irradiance over π, shadows applied.
    lamps: Vec3,
    /// The material's glossy lobe, if it has one.
    lobe: Option<Lobe>,
}

/// A glossy lobe ([`specular`]) at one surface point, seen from one direction.
#[derive(Clone, Copy)]
struct Lobe {
    f0: f32,
    alpha: f32,
    normal: Vec3,
    /// Unit vector from the surface toward the eye (the ray's origin).
    to_eye: Vec3,
    /// The lamps' highlights (radiance, in units of the white; shadows applied).
    lamps: Vec3,
    /// π × the lobe's BRDF toward the sun (0 where the sun is below the surface).
    sun: f32,
    /// What the sample's reflection ray gathered (the sky, or the surface it met, lit
    /// directly), times its weight: radiance in units of the white.
    reflected: Vec3,
}

impl Lobe {
    /// π × the lobe's BRDF for light from `to_light`.
    #[inline]
    fn pi_brdf(&self, to_light: Vec3) -> f32 {
        specular::pi_brdf(self.f0, self.alpha, self.normal, to_light, self.to_eye)
    }
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
    /// The scene's lamps ready for shading ([`lamps_of`]).
    pub lamps: Arc<[LampShading]>,
    /// How their shadow rays are spent: the scene's `[photometry] lamp_sampling`.
    pub lamp_sampling: LampSampling,
}

/// A `[[light]]` lamp as the shading reads it, computed once per context rather than per
/// lit point.
#[derive(Clone, Copy, Debug)]
pub struct LampShading {
    position: Vec3,
    /// Linear colour × intensity / (π × white × the colour's luminance): times cos θ / d²,
    /// the lamp's irradiance over π in units of the white.
    per_unit: Vec3,
    spot: Option<crate::scene::Spot>,
    casts_shadow: bool,
}

impl LampShading {
    /// Linear colour × intensity / (π × white × the colour's luminance).
    pub fn per_unit(&self) -> Vec3 {
        self.per_unit
    }

    /// Its unshadowed light on `s` (irradiance over π, in units of the white), with the
    /// direction and the distance to it; `None` where it gives `s` nothing (behind the
    /// surface, outside a spot's beam).
    #[inline]
    fn light_at(&self, s: &SurfaceHit) -> Option<DrawnLamp> {
        let to = self.position - s.position;
        let d2 = to.length_squared();
        let cos = s.normal.dot(to);
        if d2 <= 0.0 || cos <= 0.0 {
            return None;
        }
        let d = d2.sqrt();
        let dir = to / d;
        let profile = self.spot.map_or(1.0, |spot| spot.profile(-dir.as_dvec3())) as f32;
        if profile == 0.0 {
            return None;
        }
        let light = self.per_unit * (profile * (cos / d) / d2);
        Some(DrawnLamp { light, dir, d })
    }
}

/// A lamp's light on a surface point (irradiance over π, in units of the white) once its
/// shadow ray reaches it, the unit direction to it and its distance.
#[derive(Clone, Copy)]
struct DrawnLamp {
    light: Vec3,
    dir: Vec3,
    d: f32,
}

impl DrawnLamp {
    /// The shadow ray from `s` to the lamp, stopping just short of it.
    #[inline]
    fn shadow_ray(&self, s: &SurfaceHit) -> TraceRay {
        let mut ray = shadow_ray(s.position, s.normal, self.dir);
        ray.tmax = self.d * (1.0 - 1e-4);
        ray
    }

    /// Adds its light to `sum`, and its highlight to `lobe`.
    #[inline]
    fn add_to(&self, sum: &mut Vec3, lobe: Option<&mut Lobe>) {
        *sum += self.light;
        if let Some(lobe) = lobe {
            lobe.lamps += self.light * lobe.pi_brdf(self.dir);
        }
    }
}

/// One light drawn among those offered in proportion to their weights (the luminance of
/// their unshadowed light), in one pass: weighted reservoir sampling with a reservoir of one,
/// its one number, hashed from the point as the reflection's are, rescaled to [0, 1) after
/// each light.
struct Reservoir {
    u: f32,
    total: f32,
    drawn: Option<(DrawnLamp, f32)>,
}

impl Reservoir {
    #[inline]
    fn new(s: &SurfaceHit) -> Self {
        let bits = s.position.to_array().map(f32::to_bits);
        Self {
            u: unit_float(hash_words(&[bits[0], bits[1], bits[2], LAMP_SALT])),
            total: 0.0,
            drawn: None,
        }
    }

    #[inline]
    fn offer(&mut self, light: DrawnLamp) {
        let weight = luminance(light.light);
        // Not a NaN, not so close to a lamp that its light overflowed.
        if !(weight > 0.0 && weight.is_finite()) {
            return;
        }
        self.total += weight;
        let p = weight / self.total;
        if self.u < p {
            self.drawn = Some((light, weight));
            self.u /= p;
        } else {
            self.u = (self.u - p) / (1.0 - p);
        }
        self.u = self.u.min(1.0 - f32::EPSILON);
    }

    /// The drawn light over the probability of its draw, weight / total.
    #[inline]
    fn drawn(self) -> Option<DrawnLamp> {
        let total = self.total;
        self.drawn.map(|(lamp, weight)| DrawnLamp {
            light: lamp.light * (total / weight),
            ..lamp
        })
    }
}

/// Salt of the number that draws a lamp ([`LampSampling::One`]), so that it is not the
/// reflection ray's, hashed from the same point.
const LAMP_SALT: u32 = 0x6c61_6d70;

/// How `scene`'s lamps' shadow rays are spent: its `lamp_sampling` where a lamp casts
/// shadows; every light's otherwise (outside a photometric scene, and where the sun alone
/// would be drawn: its own ray is then exact, for the same one ray).
pub fn lamp_sampling_of(scene: &Scene) -> LampSampling {
    match &scene.photometry {
        Some(p) if scene.lights.iter().any(|lamp| lamp.casts_shadow) => p.lamp_sampling,
        _ => LampSampling::Every,
    }
}

/// The lamps of `scene` ready for shading (none outside a photometric scene).
pub fn lamps_of(scene: &Scene) -> Arc<[LampShading]> {
    let Some(photometry) = &scene.photometry else {
        return Arc::from([]);
    };
    (scene.lights.iter())
        .map(|lamp| {
            let colour = srgb_to_linear3(lamp.color);
            // A dark lamp may be black (0 / 0): it gives nothing.
            let scale = match lamp.intensity_cd {
                0.0 => 0.0,
                cd => {
                    cd / (std::f64::consts::PI
                        * photometry.white_cd_m2
                        * f64::from(luminance(colour)))
                }
            };
            LampShading {
                position: lamp.position.as_vec3(),
                per_unit: colour * scale as f32,
                spot: lamp.spot,
                casts_shadow: lamp.casts_shadow,
            }
        })
        .collect()
}

/// What every pixel of one render shares.
pub(super) struct PixelJob<'a> {
    /// The camera at each instant of its shutter.
    rays: ShutterRays,
    view: u8,
    display: Option<&'a dyn Screen>,
    /// The samples traced (of the pixel's `0..spp`): all of them, or one of a render split
    /// by instant (render/render_job.rs); the AOVs are the first one's.
    samples: Range<u32>,
}

impl<'a> PixelJob<'a> {
    /// The pixels of `camera` (moving along `pose_at`, `None`: still) in `view` (`display`:
    /// what the display shows, for `seethru`), samples `samples` of `spp` each.
    pub(super) fn new(
        camera: &Camera,
        pose_at: Option<PoseAt>,
        view: u8,
        display: Option<&'a dyn Screen>,
        spp: u32,
        samples: Range<u32>,
    ) -> PixelJob<'a> {
        PixelJob {
            rays: ShutterRays::new(camera, pose_at, spp),
            view,
            display,
            samples,
        }
    }

    /// The number of samples traced.
    fn count(&self) -> f32 {
        self.samples.len() as f32
    }
}

impl RenderContext {
    pub fn new(scene: Scene) -> Result<Self> {
        // The sky's cloud table is made while the meshes are read.
        let (built, sky) = rayon::join(
            || -> Result<_> {
                let world = World::build(&scene)?;
                let accel = Accel::build(&world)?;
                Ok((world, accel))
            },
            || SkyModel::new(&scene.sky, &scene.sun, scene.photometry.as_ref()),
        );
        let (world, accel) = built?;
        let lamps = lamps_of(&scene);
        Ok(Self {
            world: Arc::new(world),
            accel: Arc::new(accel),
            sky: Arc::new(sky),
            moving: None,
            lamp_sampling: lamp_sampling_of(&scene),
            lamps,
            scene,
        })
    }

    /// This context with its world flattened ([`World::flattened`]) and its hierarchy built
    /// anew: the same images, from one flat hierarchy instead of two levels.
    pub fn flattened(self) -> Result<Self> {
        let world = World::build(&self.scene)?.flattened();
        let accel = Accel::build(&world)?;
        Ok(Self {
            world: Arc::new(world),
            accel: Arc::new(accel),
            ..self
        })
    }

    /// A context for `scene`, reusing this one's world and hierarchy when `scene` differs
    /// from this context's only in its cameras, and its sky when sky and sun are the same.
    pub fn with_scene(&self, scene: Scene) -> Result<Self> {
        let sky = if (&scene.sky, &scene.sun, &scene.photometry)
            == (&self.scene.sky, &self.scene.sun, &self.scene.photometry)
        {
            self.sky.clone()
        } else {
            Arc::new(SkyModel::new(
                &scene.sky,
                &scene.sun,
                scene.photometry.as_ref(),
            ))
        };
        let (world, accel) = if same_geometry(&scene, &self.scene) {
            (self.world.clone(), self.accel.clone())
        } else {
            let world = World::build(&scene)?;
            let accel = Accel::build(&world)?;
            (Arc::new(world), Arc::new(accel))
        };
        let lamps = lamps_of(&scene);
        Ok(Self {
            world,
            accel,
            sky,
            moving: None,
            lamp_sampling: lamp_sampling_of(&scene),
            lamps,
            scene,
        })
    }

    /// One pixel: its `spp` samples, each ray traced on its own.
    pub(super) fn render_pixel(
        &self,
        job: &PixelJob,
        x: u32,
        y: u32,
        stack: &mut Stack,
        shadows: &mut u64,
    ) -> Pixel {
        let mut pixel = Pixel::SKY;
        let mut sum = Vec3::ZERO;
        for sample in job.samples.clone() {
            let (dx, dy) = pixel_offset(x, y, sample);
            let at = job.rays.at(y, sample);
            let origin = at.rays.origin;
            let dir = at.rays.direction(x as f32 + dx, y as f32 + dy);
            let hit = self.trace_with(origin, dir, job.view, stack);
            let shown = match (&hit, job.display) {
                (Some(s), Some(d)) if self.world.is_display(s.object, s.part) => {
                    Some(self.display_content(d, s, job.view, stack, shadows))
                }
                _ => None,
            };
            // A display emits its image: no shading.
            sum += match (&hit, &shown) {
                (_, Some(d)) => d.color,
                (Some(s), None) => self.shade(s, dir, job.view, stack, shadows, true),
                (None, None) => self.sky.radiance(dir),
            };
            if sample == job.samples.start {
                pixel = sample_aovs(at, origin, dir, hit, shown);
            }
        }
        pixel.color = sum / job.count();
        pixel
    }

    /// The pixels of `tile` of `band`, as [`RenderContext::render_pixel`] gives each: its
    /// camera rays traced as one packet, then the sun's shadow rays from its lit hits as
    /// another (or, under [`LampSampling::One`], the drawn lights' rays), sample by sample.
    pub(super) fn render_tile(
        &self,
        job: &PixelJob,
        tile: &Tile,
        band: &mut Rows,
        stack: &mut Stack,
        packet_stack: &mut PacketStack,
        shadows: &mut u64,
    ) {
        let mut at = [(0u32, 0u32); PACKET];
        let mut n = 0;
        for row in tile.rows.clone() {
            for x in tile.columns.clone() {
                at[n] = (x, row);
                n += 1;
            }
        }
        let mut pixels = [Pixel::SKY; PACKET];
        let mut sums = [Vec3::ZERO; PACKET];
        let mut dirs = [Vec3::ZERO; PACKET];
        let mut origins = [Vec3::ZERO; PACKET];
        let mut cameras = [job.rays.at(tile.y, 0); PACKET];
        let mut camera = RayPacket::new();
        let mut shadow = RayPacket::new();
        // The shadow rays toward the lamps drawn under `LampSampling::One`, one per lane.
        let mut lamp_rays = RayPacket::new();
        // One instant (a still camera, an instant shutter): one camera for every lane, its
        // constants loaded once.
        let single = job.rays.single();
        if let Some(c) = single {
            origins = [c.rays.origin; PACKET];
        }
        for sample in job.samples.clone() {
            if let Some(c) = single {
                let rays = &c.rays;
                for (lane, &(x, row)) in at[..n].iter().enumerate() {
                    let y = tile.y + row;
                    let (dx, dy) = pixel_offset(x, y, sample);
                    dirs[lane] = rays.direction(x as f32 + dx, y as f32 + dy);
                }
                camera.set_from_zero(n, |lane| (rays.origin, dirs[lane]));
            } else {
                for (lane, &(x, row)) in at[..n].iter().enumerate() {
                    let y = tile.y + row;
                    let (dx, dy) = pixel_offset(x, y, sample);
                    cameras[lane] = job.rays.at(y, sample);
                    origins[lane] = cameras[lane].rays.origin;
                    dirs[lane] = cameras[lane].rays.direction(x as f32 + dx, y as f32 + dy);
                }
                camera.set_from_zero(n, |lane| (origins[lane], dirs[lane]));
            }
            let moving_hits = self.trace_packet_hits(&mut camera, job.view, tile.isa, packet_stack);
            let mut shown = [None; PACKET];
            let mut shading = [None; PACKET];
            let mut drawn_lamps = [None; PACKET];
            shadow.clear();
            lamp_rays.clear();
            // Each lane's surface is shaded as soon as it is known: an array of sixteen
            // surfaces, written then read back, cost about 3 % of a run's CPU.
            for lane in 0..n {
                let hit = self.lane_surface(&camera, &moving_hits, lane, dirs[lane]);
                match (&hit, job.display) {
                    (Some(s), Some(d)) if self.world.is_display(s.object, s.part) => {
                        shown[lane] = Some(self.display_content(d, s, job.view, stack, shadows));
                    }
                    (Some(s), _) => {
                        let mut sh = self.shade_begin(s, dirs[lane]);
                        let (lamps, drawn) =
                            self.lamps_but_drawn(s, sh.lobe.as_mut(), job.view, stack, shadows);
                        sh.lamps = lamps;
                        if let Some(lamp) = drawn {
                            *shadows += 1;
                            lamp_rays.set(lane, &lamp.shadow_ray(s));
                            drawn_lamps[lane] = Some(lamp);
                        }
                        if let Some(lobe) = sh.lobe.as_mut() {
                            self.reflection_at(s, lobe, job.view, stack, shadows);
                        }
                        if sh.cos > 0.0 {
                            *shadows += 1;
                            let ray = shadow_ray(s.position, s.normal, self.sky.sun_direction);
                            shadow.set(lane, &ray);
                        }
                        shading[lane] = Some(sh);
                    }
                    (None, _) => {}
                }
                if sample == job.samples.start {
                    pixels[lane] =
                        sample_aovs(cameras[lane], origins[lane], dirs[lane], hit, shown[lane]);
                }
            }
            let blocked = self.occluded_packet(&shadow, job.view, tile.isa, packet_stack);
            if lamp_rays.active != 0 {
                let lamps_blocked =
                    self.occluded_packet(&lamp_rays, job.view, tile.isa, packet_stack);
                let reached = lamp_rays.active & !lamps_blocked;
                for lane in 0..n {
                    if let (Some(lamp), Some(sh)) = (drawn_lamps[lane], shading[lane].as_mut())
                        && reached >> lane & 1 != 0
                    {
                        lamp.add_to(&mut sh.lamps, sh.lobe.as_mut());
                    }
                }
            }
            for lane in 0..n {
                // A display emits its image: no shading.
                sums[lane] += match (&shown[lane], shading[lane]) {
                    (Some(d), _) => d.color,
                    (None, Some(sh)) => {
                        self.shade_end(sh, (shadow.active & !blocked) >> lane & 1 != 0)
                    }
                    (None, None) => self.sky.radiance(dirs[lane]),
                };
            }
        }
        for (lane, &(x, row)) in at[..n].iter().enumerate() {
            let mut pixel = pixels[lane];
            pixel.color = sums[lane] / job.count();
            band.set(x, row, pixel);
        }
    }

    /// The static layer's hits of `packet`'s rays, traced in place into `packet`, and the
    /// moving layer's (those from the static hit on, kept apart; `None` without one).
    #[inline(always)]
    fn trace_packet_hits(
        &self,
        packet: &mut RayPacket,
        view: u8,
        isa: Isa,
        stack: &mut PacketStack,
    ) -> [Option<Hit>; PACKET] {
        self.accel.closest_packet(packet, view, isa, stack);
        let mut moving_hits = [None; PACKET];
        if let Some(m) = &self.moving {
            // From the static hit on (as trace_with), keeping the static answers apart.
            let mut rest = *packet;
            rest.prim = [crate::render::bvh::NO_PRIM; PACKET];
            m.accel.closest_packet(&mut rest, view, isa, stack);
            moving_hits = std::array::from_fn(|lane| rest.hit(lane));
        }
        moving_hits
    }

    /// [`RenderContext::trace_with`] for lane `lane` (direction `dir`) of a packet that
    /// [`RenderContext::trace_packet_hits`] traced, given the moving layer's hits it
    /// returned: the surface the lane's ray meets.
    #[inline(always)]
    fn lane_surface(
        &self,
        packet: &RayPacket,
        moving_hits: &[Option<Hit>; PACKET],
        lane: usize,
        dir: Vec3,
    ) -> Option<SurfaceHit> {
        if packet.active >> lane & 1 == 0 {
            return None;
        }
        let origin = Vec3::from(packet.ray(lane).origin);
        let hit = packet.hit(lane);
        match (&self.moving, moving_hits[lane]) {
            (Some(m), Some(h)) if hit.is_none_or(|s| h.t < s.t) => {
                let mut s = m.world.surface(h.prim, origin, dir, h.t);
                s.material += self.world.materials.len() as u32;
                Some(s)
            }
            _ => hit.map(|h| self.world.surface(h.prim, origin, dir, h.t)),
        }
    }

    /// Which rays of `packet` a shadow-casting primitive visible in `view` blocks (bit i for
    /// lane i), as [`Accel::occluded_with`] and the moving layer's per ray.
    fn occluded_packet(
        &self,
        packet: &RayPacket,
        view: u8,
        isa: Isa,
        stack: &mut PacketStack,
    ) -> u32 {
        if packet.active == 0 {
            return 0;
        }
        let mut blocked = self.accel.occluded_packet(packet, view, isa, stack);
        if let Some(m) = &self.moving {
            let mut rest = *packet;
            rest.active &= !blocked;
            if rest.active != 0 {
                blocked |= m.accel.occluded_packet(&rest, view, isa, stack);
            }
        }
        blocked
    }

    /// What the display shows at a world point on its face: a display pixel, or — for the
    /// ideal display — what the frontal camera's ray through the exact crop point meets.
    fn display_content(
        &self,
        display: &dyn Screen,
        face: &SurfaceHit,
        view: u8,
        stack: &mut Stack,
        shadows: &mut u64,
    ) -> Pixel {
        let mut pixel = match display.shown_at(face.position) {
            Shown::Pixel(p) => p,
            Shown::FrontalRay(origin, dir) => {
                match self.trace_with(origin, dir, view_bit::FRONTAL, stack) {
                    Some(s) => Pixel {
                        color: self.shade(&s, dir, view_bit::FRONTAL, stack, shadows, true),
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
        };
        if let Some(light) = &self.scene.obstacle.display_light {
            pixel.color = self.display_light(light, pixel.color, face, view, stack, shadows);
        }
        pixel
    }

    /// What a display of light `light` gives off where it shows `shown` (the frontal
    /// image's radiance) at `face`: its emission ([`DisplayLight`]) and the light its face
    /// reflects (the sky's, the ground's, the lamps' and the sun's), in the scene's units.
    fn display_light(
        &self,
        light: &DisplayLight,
        shown: Vec3,
        face: &SurfaceHit,
        view: u8,
        stack: &mut Stack,
        shadows: &mut u64,
    ) -> Vec3 {
        let white = self
            .scene
            .photometry
            .as_ref()
            .map_or(1.0, |p| p.white_cd_m2);
        let black = (light.black_cd_m2 / white) as f32;
        let range = ((light.peak_cd_m2 - light.black_cd_m2) / white) as f32;
        // `shown` is the display's code: a coded camera's (system/display.rs), or linear light.
        let share = |code: f32| light.transfer.light(code);
        let emitted =
            Vec3::splat(black) + Vec3::new(share(shown.x), share(shown.y), share(shown.z)) * range;
        if light.reflectance == 0.0 {
            return emitted;
        }
        let cos = self.sun_cos(face);
        let mut received =
            self.sky.ambient(face.normal) + self.lamps_at(face, None, view, stack, shadows);
        if cos > 0.0 {
            *shadows += 1;
            let ray = shadow_ray(face.position, face.normal, self.sky.sun_direction);
            if !self.occluded(&ray, view, stack) {
                received += self.sky.sun_irradiance * cos;
            }
        }
        emitted + received * light.reflectance as f32
    }

    /// [`RenderContext::trace`] of the rays from `origin` along each direction of `dirs` (at
    /// most [`PACKET`]; unit; `None`: no ray), lane by lane: the same surfaces bit for bit,
    /// traced as one packet on the CPU's widest kernels; `None` in the lanes beyond. For
    /// coherent rays of one origin: a fan across the obstacle, the display's pixels seen
    /// from the eye.
    pub fn trace_fan(
        &self,
        origin: Vec3,
        dirs: &[Option<Vec3>],
        view: u8,
        stack: &mut PacketStack,
    ) -> [Option<SurfaceHit>; PACKET] {
        assert!(dirs.len() <= PACKET, "{} rays in a packet", dirs.len());
        let mut packet = RayPacket::new();
        let mut lane_dirs = [Vec3::X; PACKET];
        for (lane, dir) in dirs.iter().enumerate() {
            if let &Some(dir) = dir {
                lane_dirs[lane] = dir;
                packet.set(lane, &make_ray(origin, dir, 0.0, f32::INFINITY));
            }
        }
        let moving_hits = self.trace_packet_hits(&mut packet, view, Isa::best(), stack);
        std::array::from_fn(|lane| self.lane_surface(&packet, &moving_hits, lane, lane_dirs[lane]))
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

    /// The radiance toward a ray of direction `dir` from the surface `s` it meets: Lambert
    /// shading, albedo × (sun × cos × visibility + sky ambient + lamps), and the highlights
    /// of a glossy material's lobe, with its reflection ray where `reflect` (not for the
    /// surface a reflection ray meets: one bounce).
    fn shade(
        &self,
        s: &SurfaceHit,
        dir: Vec3,
        view: u8,
        stack: &mut Stack,
        shadows: &mut u64,
        reflect: bool,
    ) -> Vec3 {
        let mut sh = self.shade_begin(s, dir);
        sh.lamps = self.lamps_at(s, sh.lobe.as_mut(), view, stack, shadows);
        if let (Some(lobe), true) = (sh.lobe.as_mut(), reflect) {
            self.reflection_at(s, lobe, view, stack, shadows);
        }
        let mut lit = false;
        if sh.cos > 0.0 {
            *shadows += 1;
            let ray = shadow_ray(s.position, s.normal, self.sky.sun_direction);
            lit = !self.occluded(&ray, view, stack);
        }
        self.shade_end(sh, lit)
    }

    /// The cosine of the sun to the normal at `s`, where the sun gets a shadow ray of its
    /// own; 0 where it is drawn with the lamps ([`LampSampling::One`]).
    #[inline]
    fn sun_cos(&self, s: &SurfaceHit) -> f32 {
        match self.lamp_sampling {
            LampSampling::Every => s.normal.dot(self.sky.sun_direction),
            LampSampling::One => 0.0,
        }
    }

    /// The albedo, the ambient light, the sun's cosine and the glossy lobe at `s`, seen along
    /// `dir`.
    #[inline]
    fn shade_begin(&self, s: &SurfaceHit, dir: Vec3) -> Shading {
        let (material, textures) = self.material(s.material);
        let mut albedo = material.albedo;
        if let Some(t) = material.texture {
            albedo *= textures[t].sample(s.uv * material.uv_repeat);
        }
        let cos = self.sun_cos(s);
        let lobe = (material.specular > 0.0).then(|| {
            albedo *= 1.0 - material.specular;
            let mut lobe = Lobe {
                f0: material.specular,
                alpha: material.roughness,
                normal: s.normal,
                to_eye: -dir,
                lamps: Vec3::ZERO,
                sun: 0.0,
                reflected: Vec3::ZERO,
            };
            if cos > 0.0 {
                lobe.sun = lobe.pi_brdf(self.sky.sun_direction);
            }
            lobe
        });
        Shading {
            albedo,
            light: self.sky.ambient(s.normal),
            cos,
            lamps: Vec3::ZERO,
            lobe,
        }
    }

    /// The light of the scene's lamps on the surface `s` (irradiance over π, in units of the
    /// white; zero without lamps): each lamp's intensity towards `s` (a spot's profile) times
    /// the cosine over the squared distance, where its shadow ray reaches it; and, into the
    /// surface's glossy `lobe`, their highlights. The shadow rays go to every lamp, or to one
    /// light drawn among the sun and the lamps ([`LampSampling`]); the same rays on the
    /// per-ray and the packet paths.
    fn lamps_at(
        &self,
        s: &SurfaceHit,
        mut lobe: Option<&mut Lobe>,
        view: u8,
        stack: &mut Stack,
        shadows: &mut u64,
    ) -> Vec3 {
        let (mut sum, drawn) = self.lamps_but_drawn(s, lobe.as_deref_mut(), view, stack, shadows);
        if let Some(lamp) = drawn {
            *shadows += 1;
            if !self.occluded(&lamp.shadow_ray(s), view, stack) {
                lamp.add_to(&mut sum, lobe);
            }
        }
        sum
    }

    /// [`Self::lamps_at`] but for the lamp drawn under [`LampSampling::One`], returned with its
    /// shadow ray still to trace (the packet path traces those of a tile together).
    fn lamps_but_drawn(
        &self,
        s: &SurfaceHit,
        mut lobe: Option<&mut Lobe>,
        view: u8,
        stack: &mut Stack,
        shadows: &mut u64,
    ) -> (Vec3, Option<DrawnLamp>) {
        let mut sum = Vec3::ZERO;
        // One loop per way: a loop that could do either spills more registers (3 % of
        // das_night's frame).
        if self.lamp_sampling == LampSampling::Every {
            for lamp in self.lamps.iter() {
                let Some(lamp_light) = lamp.light_at(s) else {
                    continue;
                };
                if lamp.casts_shadow {
                    *shadows += 1;
                    if self.occluded(&lamp_light.shadow_ray(s), view, stack) {
                        continue;
                    }
                }
                lamp_light.add_to(&mut sum, lobe.as_deref_mut());
            }
            return (sum, None);
        }
        // "one": a single reservoir over the sun and the shadow-casting lamps.
        let mut reservoir = Reservoir::new(s);
        let cos = s.normal.dot(self.sky.sun_direction);
        if cos > 0.0 {
            reservoir.offer(DrawnLamp {
                light: self.sky.sun_irradiance * cos,
                dir: self.sky.sun_direction,
                d: f32::INFINITY,
            });
        }
        for lamp in self.lamps.iter() {
            let Some(lamp_light) = lamp.light_at(s) else {
                continue;
            };
            if lamp.casts_shadow {
                reservoir.offer(lamp_light);
            } else {
                lamp_light.add_to(&mut sum, lobe.as_deref_mut());
            }
        }
        (sum, reservoir.drawn())
    }

    /// Whether `ray` meets anything, in the static world or the moving layer.
    fn occluded(&self, ray: &TraceRay, view: u8, stack: &mut Stack) -> bool {
        self.accel.occluded_with(ray, view, stack)
            || (self.moving.as_ref()).is_some_and(|m| m.accel.occluded_with(ray, view, stack))
    }

    /// Traces the reflection ray of `lobe` at `s` ([`specular::sample_reflection`], its two
    /// numbers hashed from the point, so the per-ray and the packet paths draw the same) and
    /// keeps what it gathers: the sky without the sun's disc, or the surface it meets, shaded
    /// by the sun, the sky and the lamps (no second reflection).
    fn reflection_at(
        &self,
        s: &SurfaceHit,
        lobe: &mut Lobe,
        view: u8,
        stack: &mut Stack,
        shadows: &mut u64,
    ) {
        let h = hash_words(&s.position.to_array().map(f32::to_bits));
        let (u, v) = (unit_float(h), unit_float(hash_u32(h)));
        let Some((dir, weight)) =
            specular::sample_reflection(lobe.f0, lobe.alpha, lobe.normal, lobe.to_eye, u, v)
        else {
            return;
        };
        let radiance = match self.trace_with(off_surface(s.position, s.normal), dir, view, stack) {
            Some(hit) => self.shade(&hit, dir, view, stack, shadows, false),
            None => self.sky.radiance_without_sun(dir),
        };
        lobe.reflected = radiance * weight;
    }

    /// The shaded colour, with the sun where `lit` (its cosine positive, its ray unblocked).
    #[inline]
    fn shade_end(&self, sh: Shading, lit: bool) -> Vec3 {
        let mut light = sh.light;
        if !self.lamps.is_empty() {
            light += sh.lamps;
        }
        if lit {
            light += self.sky.sun_irradiance * sh.cos;
        }
        let mut colour = sh.albedo * light;
        if let Some(lobe) = sh.lobe {
            colour += lobe.lamps + lobe.reflected;
            if lit {
                colour += self.sky.sun_irradiance * (sh.cos * lobe.sun);
            }
        }
        colour
    }
}

/// The pixels of one packet: a band's `rows` (counted from the band's first row, frame row
/// `y`) × `columns`.
pub(super) struct Tile {
    pub(super) isa: Isa,
    pub(super) y: u32,
    pub(super) rows: std::ops::Range<u32>,
    pub(super) columns: std::ops::Range<u32>,
}

/// The AOVs of a pixel's centre sample (its colour is set after): the surface `hit` along
/// the ray from `origin` in `dir`, or what the display shows there (`shown`), or the sky.
fn sample_aovs(
    camera: &CameraAt,
    origin: Vec3,
    dir: Vec3,
    hit: Option<SurfaceHit>,
    shown: Option<Pixel>,
) -> Pixel {
    match (hit, shown) {
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
                    axial_depth(&camera.camera_from_world, d.position)
                } else {
                    f32::INFINITY
                },
                ..d
            }
        }
        (Some(s), None) => Pixel {
            color: Vec3::ZERO,
            depth: s.t,
            camera_z: axial_depth(&camera.camera_from_world, s.position),
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

/// A ray leaving a surface point `position` (unit normal `normal`) in direction `dir`, from
/// [`off_surface`].
pub fn shadow_ray(position: Vec3, normal: Vec3, dir: Vec3) -> TraceRay {
    make_ray(off_surface(position, normal), dir, 0.0, f32::INFINITY)
}

/// Where a ray leaving the surface at `position` (unit `normal`) starts: lifted along the
/// normal by a distance that grows with the coordinates' magnitude, to stay above the f32
/// rounding of the hit point.
fn off_surface(position: Vec3, normal: Vec3) -> Vec3 {
    let eps = 2e-4 * (1.0 + position.abs().max_element());
    position + normal * eps
}
