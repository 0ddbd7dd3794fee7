//! A render job: what one render asks of a [`RenderContext`] (camera, view, display, settings,
//! region, tracer), and how the context runs it.
//!
//! A job is rendered in bands of rows on the rayon pool, each band written straight into the
//! frame's buffers; every pixel depends only on its own coordinates, so images are the same
//! for any number of threads. Views of one camera that differ only by a few primitives
//! (`truth`, `occluded`, `seethru`) are rendered once and re-rendered only where those
//! primitives can be seen ([`RenderContext::render_over`]).

use std::sync::Arc;
use std::time::Instant;

use rayon::prelude::*;

use crate::geometry::camera::Camera;
use crate::geometry::sensor::Metering;
use crate::render::accel::Difference;
use crate::render::bvh::Stack;
use crate::render::bvh_packet::{PACKET, PacketStack};
use crate::render::exposure::{
    Metered, Zones, metering_camera, settled, with_exposure, zone_weight,
};
use crate::render::footprint::{PixelRect, footprint};
use crate::render::frame::{Frame, Rows};
use crate::render::frame_over::FrameOver;
use crate::render::integrator::{PixelJob, RenderContext, Tile};
use crate::render::screen::Screen;
use crate::render::settings::RenderSettings;
use crate::render::shutter_rays::PoseAt;
use crate::render::simd::Isa;
use crate::scene::world::view_bit;
use crate::util::progress::Progress;

/// Rows per rayon task: small enough to balance many threads, large enough to amortise; a
/// band is one row of tiles.
pub(super) const BAND_ROWS: u32 = 4;
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

#[derive(Clone, Copy, Debug, Default)]
pub struct RenderStats {
    pub primary_rays: u64,
    pub shadow_rays: u64,
    pub seconds: f64,
}

/// One render of `camera`'s view: made by [`RenderJob::new`] or [`RenderJob::seethru`],
/// narrowed by the other methods, run by [`RenderContext::render`],
/// [`RenderContext::render_into`] or [`RenderContext::render_over`].
#[derive(Clone, Copy)]
pub struct RenderJob<'a> {
    pub(super) camera: &'a Camera,
    /// A [`view_bit`]: the primitives the render shows.
    pub(super) view: u8,
    /// What the display shows, for the `seethru` view.
    display: Option<&'a dyn Screen>,
    pub(super) settings: RenderSettings,
    /// `None`: every pixel of the camera.
    pub(super) region: Option<PixelRect>,
    /// The name on the progress line.
    label: &'a str,
    tracer: Tracer,
    /// The camera's pose over its shutter's instants (`None`: still).
    pub(super) pose_at: Option<PoseAt<'a>>,
    /// Only this sample of each pixel's `spp` (`None`: all of them).
    pub(super) sample: Option<u32>,
}

impl<'a> RenderJob<'a> {
    /// The frame `camera` sees of the primitives visible in `view` (a [`view_bit`]): every
    /// pixel, with the default settings, traced by [`Tracer::best`].
    pub fn new(camera: &'a Camera, view: u8) -> RenderJob<'a> {
        RenderJob {
            camera,
            view,
            display: None,
            settings: RenderSettings::default(),
            region: None,
            label: "",
            tracer: Tracer::best(),
            pose_at: None,
            sample: None,
        }
    }

    /// The `seethru` view: the driver's eye with the obstacle present and its display showing
    /// `display`. Where a ray meets the display face, the pixel takes the display pixel there
    /// — colour and every AOV, so the frame holds the world point and id the display shows.
    pub fn seethru(camera: &'a Camera, display: &'a dyn Screen) -> RenderJob<'a> {
        RenderJob {
            display: Some(display),
            label: "seethru",
            ..RenderJob::new(camera, view_bit::SEETHRU)
        }
    }

    pub fn settings(self, settings: RenderSettings) -> RenderJob<'a> {
        RenderJob { settings, ..self }
    }

    /// Only the pixels of `region` (each as the whole frame's render gives it); rendered into
    /// a frame, the others keep what they held.
    pub fn region(self, region: PixelRect) -> RenderJob<'a> {
        RenderJob {
            region: Some(region),
            ..self
        }
    }

    pub fn label(self, label: &'a str) -> RenderJob<'a> {
        RenderJob { label, ..self }
    }

    /// The camera moving along `pose_at` (its world_from_camera `dt` seconds after the
    /// frame's instant): each sample is traced from where the camera is at its instant of
    /// the camera's shutter ([`crate::geometry::shutter::Shutter`]). The world is the
    /// context's, of the frame's instant (render/in_time.rs renders a world that moves
    /// too).
    pub fn moving(self, pose_at: PoseAt<'a>) -> RenderJob<'a> {
        RenderJob {
            pose_at: Some(pose_at),
            ..self
        }
    }

    /// Only sample `sample` of each pixel's `spp` (its colour that sample's, its AOVs too).
    pub fn sample(self, sample: u32) -> RenderJob<'a> {
        RenderJob {
            sample: Some(sample),
            ..self
        }
    }

    /// The job's camera.
    pub fn camera(&self) -> &'a Camera {
        self.camera
    }

    /// The [`view_bit`] of the primitives the job shows.
    pub fn view(&self) -> u8 {
        self.view
    }

    /// The same job of `camera` (the job's camera exposed, say).
    pub fn of_camera(self, camera: &'a Camera) -> RenderJob<'a> {
        RenderJob { camera, ..self }
    }

    /// The same job of `camera` (another size of the job's camera: its metering image, say),
    /// every pixel and every sample.
    pub fn whole_frame_of(self, camera: &'a Camera) -> RenderJob<'a> {
        RenderJob {
            region: None,
            sample: None,
            label: "",
            ..self.of_camera(camera)
        }
    }

    /// What every pixel of the job shares: its camera at each instant of its shutter.
    pub(super) fn pixels(&self) -> PixelJob<'a> {
        let spp = self.settings.spp;
        let samples = self.sample.map_or(0..spp, |s| s..s + 1);
        PixelJob::new(
            self.camera,
            self.pose_at,
            self.view,
            self.display,
            spp,
            samples,
        )
    }

    /// Traced by `tracer`: every tracer gives the same frame.
    pub fn tracer(self, tracer: Tracer) -> RenderJob<'a> {
        RenderJob { tracer, ..self }
    }
}

impl RenderContext {
    /// Renders `job` into a new frame of its camera's size.
    pub fn render(&self, job: RenderJob) -> (Frame, RenderStats) {
        let mut frame = Frame::new(job.camera.width, job.camera.height);
        let stats = self.render_into(job, &mut frame);
        (frame, stats)
    }

    /// The metering image of `job`'s camera (render/exposure.rs), as `job` renders it (its
    /// view, pose and motion) at one sample per zone.
    pub fn meter(&self, job: &RenderJob, metering: Metering) -> Zones {
        let camera = metering_camera(job.camera);
        let settings = RenderSettings {
            spp: 1,
            progress: false,
        };
        let (frame, _) = self.render(job.whole_frame_of(&camera).settings(settings));
        let (w, h) = (camera.width, camera.height);
        let weight = (0..h)
            .flat_map(|y| (0..w).map(move |x| (x, y)))
            .map(|(x, y)| zone_weight(metering, x, y, w, h))
            .collect();
        Zones {
            weight,
            colour: frame.color,
        }
    }

    /// `job`'s camera with its exposure set: an automatic exposure that has none yet meters
    /// `job`'s view over this context and settles (with what it metered); any other camera as
    /// it is.
    pub fn exposed(&self, job: &RenderJob) -> (Camera, Option<Metered>) {
        let camera = *job.camera;
        let Some(sensor) = camera.sensor else {
            return (camera, None);
        };
        let Some(auto) = sensor
            .auto_exposure
            .filter(|_| sensor.exposure_gain.is_none())
        else {
            return (camera, None);
        };
        let metered = settled(&sensor, &auto, &self.meter(job, auto.metering));
        (with_exposure(&camera, &metered), Some(metered))
    }

    /// What a frame's 1.0 is in cd/m² in a scene lit in physical units ([`Frame::white_cd_m2`]).
    pub fn white_cd_m2(&self) -> Option<f32> {
        (self.scene.photometry.as_ref()).map(|p| p.white_cd_m2 as f32)
    }

    /// Renders `job` into `frame`, a frame of the camera's size, so that a sequence of renders
    /// reuses its buffers: the pixels outside the job's region keep what they held.
    pub fn render_into(&self, job: RenderJob, frame: &mut Frame) -> RenderStats {
        let (camera, metered) = self.exposed(&job);
        let job = job.of_camera(&camera);
        assert_eq!((frame.width, frame.height), (camera.width, camera.height));
        frame.white_cd_m2 = self.white_cd_m2();
        // A frame reused from a camera with a sensor: its exposure is this render's.
        frame.exposure = None;
        let region = job.region.unwrap_or_else(|| PixelRect::full(&camera));
        let stats = self.render_bands(&job, region, frame.bands_mut(BAND_ROWS));
        crate::render::sensor_image::deliver_through_sensor(&camera, frame, region, metered);
        stats
    }

    /// Renders `job` given `base`, the same camera's frame in `base_view` with the same
    /// settings: only the pixels where the two views can differ are traced, the others are
    /// `base`'s, shared rather than copied. The result is bit for bit the frame
    /// [`RenderContext::render`] gives. Those pixels are the job's region: it names none.
    pub fn render_over(
        &self,
        job: RenderJob,
        base: &Arc<Frame>,
        base_view: u8,
    ) -> (FrameOver, RenderStats) {
        let camera = job.camera;
        assert_eq!((base.width, base.height), (camera.width, camera.height));
        assert!(job.region.is_none(), "render_over chooses its own region");
        let region = self.difference_region(camera, base_view, job.view);
        let mut patch = Frame::new(region.x1 - region.x0, region.y1 - region.y0);
        patch.white_cd_m2 = self.white_cd_m2();
        let bands = patch.bands_mut_at(BAND_ROWS, region.x0, region.y0);
        let stats = self.render_bands(&job, region, bands);
        (FrameOver::new(Arc::clone(base), region, patch), stats)
    }

    /// The pixels of `camera` where views `a` and `b` can differ (see [`Accel::difference`]).
    ///
    /// [`Accel::difference`]: crate::render::accel::Accel::difference
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

    /// Renders the pixels of `region` of `job` into `bands` (of a frame of the camera's size,
    /// or of the region alone).
    pub(super) fn render_bands(
        &self,
        job: &RenderJob,
        region: PixelRect,
        bands: Vec<Rows<'_>>,
    ) -> RenderStats {
        self.render_bands_of(job, &job.pixels(), region, bands)
    }

    /// [`RenderContext::render_bands`] with the job's pixels made ([`RenderJob::pixels`]),
    /// so that renders of one job over several contexts share them.
    pub(super) fn render_bands_of(
        &self,
        job: &RenderJob,
        pixels: &PixelJob,
        region: PixelRect,
        bands: Vec<Rows<'_>>,
    ) -> RenderStats {
        let start = Instant::now();
        let traced = job.sample.map_or(u64::from(job.settings.spp), |_| 1);
        let bands: Vec<_> = bands
            .into_iter()
            .filter(|b| b.y < region.y1 && b.y + b.len() > region.y0)
            .collect();
        let label = job.label;
        let progress = Progress::new(
            format!("rendering {label}"),
            bands.len(),
            job.settings.progress,
        );
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
                        match job.tracer {
                            Tracer::PerRay => {
                                for row in rows {
                                    for x in region.x0..region.x1 {
                                        let pixel = self.render_pixel(
                                            pixels,
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
                                        pixels,
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
            primary_rays: region.pixels() * traced,
            shadow_rays,
            seconds: start.elapsed().as_secs_f64(),
        }
    }
}
