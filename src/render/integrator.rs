//! The integrator: primary rays per pixel, Lambert shading with the sun (hard shadow ray)
//! and sky ambient, textures, and the AOVs of the pixel-centre ray.
//!
//! Frames are rendered in bands of rows on the rayon pool, each band written straight into
//! the frame's buffers; every pixel depends only on its own coordinates, so images are the
//! same for any number of threads. Views of one camera that differ only by a few primitives
//! (`truth`, `occluded`, `seethru`) are rendered once and re-rendered only where those
//! primitives can be seen ([`RenderContext::render_over`]).
//!
//! Within a band, pixels are traced in 4×4 tiles ([`Tracer::Packets`]): the tile's camera rays
//! as one packet ([`crate::render::bvh_packet`]), then the shadow rays toward the sun from its
//! lit hits as another. The per-ray path ([`Tracer::PerRay`]) gives the same image bit for bit
//! and is the packets' twin in tests.

use std::sync::Arc;
use std::time::Instant;

use anyhow::Result;
use glam::{DAffine3, Vec3};
use rayon::prelude::*;

use crate::geometry::camera::Camera;
use crate::render::accel::{Accel, Difference, make_ray};
use crate::render::bvh::Stack;
use crate::render::bvh_packet::{PACKET, PacketStack, RayPacket};
use crate::render::camera_rays::CameraRays;
use crate::render::footprint::{PixelRect, footprint};
use crate::render::frame::{Frame, Pixel, Rows};
use crate::render::frame_over::FrameOver;
use crate::render::moving::MovingLayer;
use crate::render::ray::{Hit, TraceRay};
use crate::render::screen::{Screen, Shown};
use crate::render::settings::RenderSettings;
use crate::render::simd::Isa;
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

/// Rows per rayon task: small enough to balance many threads, large enough to amortise; a
/// band is one row of tiles.
const BAND_ROWS: u32 = 4;
/// Columns of a tile: a band's rows × these make one packet.
const TILE_COLUMNS: u32 = PACKET as u32 / BAND_ROWS;

/// How a render traces its camera rays and the sun's shadow rays.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Tracer {
    /// One ray at a time: the packets' twin.
    PerRay,
    /// 4×4 tiles of pixels as packets of 16 rays, on the given instruction set's kernels.
    Packets(Isa),
}

impl Tracer {
    /// Packets on the CPU's widest instruction set: what every render uses.
    pub fn best() -> Tracer {
        Tracer::Packets(Isa::best())
    }
}

/// The parts of Lambert shading known before the shadow ray is traced.
#[derive(Clone, Copy)]
struct Shading {
    albedo: Vec3,
    /// Sky ambient.
    light: Vec3,
    /// Cosine of the sun to the normal: a shadow ray is traced where it is positive.
    cos: f32,
}

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
        // The sky's cloud table is made while the meshes are read.
        let (built, sky) = rayon::join(
            || -> Result<_> {
                let world = World::build(&scene)?;
                let accel = Accel::build(&world)?;
                Ok((world, accel))
            },
            || SkyModel::new(&scene.sky, &scene.sun),
        );
        let (world, accel) = built?;
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
    /// two views can differ are traced, the others are `base`'s, shared rather than copied.
    /// The result is bit for bit the frame [`RenderContext::render`] (or
    /// [`RenderContext::render_seethru`]) gives.
    #[allow(clippy::too_many_arguments)]
    pub fn render_over(
        &self,
        camera: &Camera,
        base: &Arc<Frame>,
        base_view: u8,
        view: u8,
        display: Option<&dyn Screen>,
        settings: RenderSettings,
        label: &str,
    ) -> (FrameOver, RenderStats) {
        assert_eq!((base.width, base.height), (camera.width, camera.height));
        let region = self.difference_region(camera, base_view, view);
        let mut patch = Frame::new(region.x1 - region.x0, region.y1 - region.y0);
        let bands = patch.bands_mut_at(BAND_ROWS, region.x0, region.y0);
        let tracer = Tracer::best();
        let stats = self.render_bands(
            camera, view, display, settings, region, bands, label, tracer,
        );
        (FrameOver::new(Arc::clone(base), region, patch), stats)
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
        let tracer = Tracer::best();
        self.render_rect_traced(
            camera, view, display, settings, region, frame, label, tracer,
        )
    }

    /// [`RenderContext::render`] traced by `tracer`: every tracer gives the same frame.
    pub fn render_traced(
        &self,
        camera: &Camera,
        view: u8,
        settings: RenderSettings,
        tracer: Tracer,
    ) -> Frame {
        let mut frame = Frame::new(camera.width, camera.height);
        let region = PixelRect::full(camera);
        self.render_rect_traced(camera, view, None, settings, region, &mut frame, "", tracer);
        frame
    }

    /// [`RenderContext::render_seethru`] traced by `tracer`.
    pub fn render_seethru_traced(
        &self,
        camera: &Camera,
        display: &dyn Screen,
        settings: RenderSettings,
        tracer: Tracer,
    ) -> Frame {
        let mut frame = Frame::new(camera.width, camera.height);
        let region = PixelRect::full(camera);
        let view = view_bit::SEETHRU;
        self.render_rect_traced(
            camera,
            view,
            Some(display),
            settings,
            region,
            &mut frame,
            "",
            tracer,
        );
        frame
    }

    /// [`RenderContext::render_rect`] traced by `tracer`.
    #[allow(clippy::too_many_arguments)]
    fn render_rect_traced(
        &self,
        camera: &Camera,
        view: u8,
        display: Option<&dyn Screen>,
        settings: RenderSettings,
        region: PixelRect,
        frame: &mut Frame,
        label: &str,
        tracer: Tracer,
    ) -> RenderStats {
        assert_eq!((frame.width, frame.height), (camera.width, camera.height));
        let bands = frame.bands_mut(BAND_ROWS);
        self.render_bands(
            camera, view, display, settings, region, bands, label, tracer,
        )
    }

    /// Renders the pixels of `region` of `view` into `bands` (of a frame of the camera's size,
    /// or of the region alone), each pixel as [`RenderContext::render`] gives it.
    #[allow(clippy::too_many_arguments)]
    fn render_bands(
        &self,
        camera: &Camera,
        view: u8,
        display: Option<&dyn Screen>,
        settings: RenderSettings,
        region: PixelRect,
        bands: Vec<Rows<'_>>,
        label: &str,
        tracer: Tracer,
    ) -> RenderStats {
        let start = Instant::now();
        let job = PixelJob {
            rays: CameraRays::new(camera),
            camera_from_world: camera.world_from_camera.inverse(),
            view,
            display,
            spp: settings.spp,
        };
        let bands: Vec<_> = bands
            .into_iter()
            .filter(|b| b.y < region.y1 && b.y + b.len() > region.y0)
            .collect();
        let progress = Progress::new(format!("rendering {label}"), bands.len(), settings.progress);
        let shadow_rays: u64 = bands
            .into_par_iter()
            .map(|mut band| {
                Stack::with_thread_stack(|stack| {
                    PacketStack::with_thread_stack(|packet_stack| {
                        let mut shadows = 0;
                        // A cancelled render (render/cancel.rs) leaves its remaining bands as they are.
                        if crate::render::cancel::requested() {
                            return shadows;
                        }
                        // The band's rows inside the region.
                        let rows = region.y0.max(band.y) - band.y
                            ..region.y1.min(band.y + band.len()) - band.y;
                        match tracer {
                            Tracer::PerRay => {
                                for row in rows {
                                    for x in region.x0..region.x1 {
                                        let pixel = self.render_pixel(
                                            &job,
                                            x,
                                            band.y + row,
                                            stack,
                                            &mut shadows,
                                        );
                                        band.set(x, row, pixel);
                                    }
                                }
                            }
                            Tracer::Packets(isa) => {
                                for x0 in (region.x0..region.x1).step_by(TILE_COLUMNS as usize) {
                                    let tile = Tile {
                                        isa,
                                        y: band.y,
                                        rows: rows.clone(),
                                        columns: x0..(x0 + TILE_COLUMNS).min(region.x1),
                                    };
                                    self.render_tile(
                                        &job,
                                        &tile,
                                        &mut band,
                                        stack,
                                        packet_stack,
                                        &mut shadows,
                                    );
                                }
                            }
                        }
                        progress.advance(1);
                        shadows
                    })
                })
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
            if sample == 0 {
                pixel = sample_aovs(job, origin, dir, hit, shown);
            }
        }
        pixel.color = sum / job.spp as f32;
        pixel
    }

    /// The pixels of `tile` of `band`, as [`RenderContext::render_pixel`] gives each: its
    /// camera rays traced as one packet, then the sun's shadow rays from its lit hits as
    /// another, sample by sample.
    fn render_tile(
        &self,
        job: &PixelJob,
        tile: &Tile,
        band: &mut crate::render::frame::Rows,
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
        let origin = job.rays.origin;
        let mut pixels = [Pixel::SKY; PACKET];
        let mut sums = [Vec3::ZERO; PACKET];
        let mut dirs = [Vec3::ZERO; PACKET];
        let mut camera = RayPacket::new();
        let mut shadow = RayPacket::new();
        for sample in 0..job.spp {
            for (lane, &(x, row)) in at[..n].iter().enumerate() {
                let y = tile.y + row;
                let (dx, dy) = pixel_offset(x, y, sample);
                dirs[lane] = job.rays.direction(x as f32 + dx, y as f32 + dy);
            }
            camera.set_from_zero(n, |lane| (origin, dirs[lane]));
            let moving_hits = self.trace_packet_hits(&mut camera, job.view, tile.isa, packet_stack);
            let mut shown = [None; PACKET];
            let mut shading = [None; PACKET];
            shadow.clear();
            // Each lane's surface is shaded as soon as it is known: an array of sixteen
            // surfaces, written then read back, cost about 3 % of a run's CPU.
            for lane in 0..n {
                let hit = self.lane_surface(&camera, &moving_hits, lane, dirs[lane]);
                match (&hit, job.display) {
                    (Some(s), Some(d)) if self.world.is_display(s.object, s.part) => {
                        shown[lane] = Some(self.display_content(d, s.position, stack, shadows));
                    }
                    (Some(s), _) => {
                        let sh = self.shade_begin(s);
                        if sh.cos > 0.0 {
                            *shadows += 1;
                            let ray = shadow_ray(s.position, s.normal, self.sky.sun_direction);
                            shadow.set(lane, &ray);
                        }
                        shading[lane] = Some(sh);
                    }
                    (None, _) => {}
                }
                if sample == 0 {
                    pixels[lane] = sample_aovs(job, origin, dirs[lane], hit, shown[lane]);
                }
            }
            let blocked = self.occluded_packet(&shadow, job.view, tile.isa, packet_stack);
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
            pixel.color = sums[lane] / job.spp as f32;
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

    /// Lambert shading: albedo × (sun × cos × visibility + sky ambient).
    fn shade(&self, s: &SurfaceHit, view: u8, stack: &mut Stack, shadows: &mut u64) -> Vec3 {
        let sh = self.shade_begin(s);
        let mut lit = false;
        if sh.cos > 0.0 {
            *shadows += 1;
            let ray = shadow_ray(s.position, s.normal, self.sky.sun_direction);
            let blocked = self.accel.occluded_with(&ray, view, stack)
                || self
                    .moving
                    .as_ref()
                    .is_some_and(|m| m.accel.occluded_with(&ray, view, stack));
            lit = !blocked;
        }
        self.shade_end(sh, lit)
    }

    /// The albedo, the ambient light and the sun's cosine at `s`.
    #[inline]
    fn shade_begin(&self, s: &SurfaceHit) -> Shading {
        let (material, textures) = self.material(s.material);
        let mut albedo = material.albedo;
        if let Some(t) = material.texture {
            albedo *= textures[t].sample(s.uv * material.uv_repeat);
        }
        Shading {
            albedo,
            light: self.sky.ambient(s.normal),
            cos: s.normal.dot(self.sky.sun_direction),
        }
    }

    /// The shaded colour, with the sun where `lit` (its cosine positive, its ray unblocked).
    #[inline]
    fn shade_end(&self, sh: Shading, lit: bool) -> Vec3 {
        let mut light = sh.light;
        if lit {
            light += self.sky.sun_irradiance * sh.cos;
        }
        sh.albedo * light
    }
}

/// The pixels of one packet: a band's `rows` (counted from the band's first row, frame row
/// `y`) × `columns`.
struct Tile {
    isa: Isa,
    y: u32,
    rows: std::ops::Range<u32>,
    columns: std::ops::Range<u32>,
}

/// The AOVs of a pixel's centre sample (its colour is set after): the surface `hit` along
/// the ray from `origin` in `dir`, or what the display shows there (`shown`), or the sky.
fn sample_aovs(
    job: &PixelJob,
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
