//! The display: the frontal frame resampled through the compensation into the display's own
//! pixels, and the lookup that the `seethru` view does where a ray meets the display.

use glam::{DAffine3, DVec2, Vec3};

use crate::geometry::camera::Camera;
use crate::geometry::shutter::RowShows;
use crate::render::frame::{Frame, Pixel};
use crate::render::screen::{Screen, Shown};
use crate::scene::Obstacle;
use crate::system::compensation::Crop;
use crate::system::frontal_map::FrontalMap;
use crate::system::point_model::PointModel;

/// Object id of display pixels that show nothing because the frontal camera does not see
/// their model point (outside its view). They are black.
pub const MISSING_ID: u32 = u32::MAX;

/// How colour is resampled from the frontal image (geometric AOVs are always nearest).
#[derive(
    Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum, serde::Serialize, serde::Deserialize,
)]
#[serde(rename_all = "lowercase")]
pub enum Filter {
    /// Bilinear interpolation of the four nearest frontal pixels.
    Bilinear,
    /// Catmull–Rom bicubic over 4×4 pixels: sharper, may overshoot slightly at edges.
    Bicubic,
}

/// The frontal frame resampled into display pixels through `crop`: for each display pixel
/// centre, the frontal point the crop maps it to. Colour by `filter`; depth, position,
/// normal and ids from the nearest frontal pixel, so that every pixel carries the world
/// point it shows. Pixels mapping outside the frontal image get [`MISSING_ID`].
pub fn resample(frontal: &Frame, crop: &Crop, display_size: [u32; 2], filter: Filter) -> Frame {
    resample_with(frontal, display_size, filter, |p| crop.frontal_point(p))
}

/// [`resample`] through a [`FrontalMap`]: the crop, then the believed lens's distortion.
pub fn resample_through(frontal: &Frame, map: &FrontalMap, filter: Filter) -> Frame {
    resample_with(frontal, map.display_size, filter, |p| map.frontal_point(p))
}

/// The frontal frame resampled at `frontal_point(display pixel centre)` for every pixel.
fn resample_with(
    frontal: &Frame,
    display_size: [u32; 2],
    filter: Filter,
    frontal_point: impl Fn(DVec2) -> DVec2 + Sync,
) -> Frame {
    use rayon::prelude::*;
    let [w, h] = display_size;
    // Bands of rows in parallel, each pixel on its own: the same image for any number of
    // threads, written in place.
    let mut frame = Frame::new(w, h);
    frame.white_cd_m2 = frontal.white_cd_m2;
    frame.exposure = frontal.exposure;
    frame.bands_mut(8).into_par_iter().for_each(|mut band| {
        for row in 0..band.len() {
            let y = band.y + row;
            for x in 0..w {
                let p = frontal_point(DVec2::new(x as f64 + 0.5, y as f64 + 0.5));
                band.set(x, row, sample(frontal, p, filter));
            }
        }
    });
    frame
}

/// One display pixel's content: the frontal frame at frontal point `p` (colour by `filter`,
/// the other AOVs from the nearest pixel); [`MISSING_ID`] outside the image.
pub fn sample(frame: &Frame, p: DVec2, filter: Filter) -> Pixel {
    let (w, h) = (frame.width as f64, frame.height as f64);
    if !(p.x >= 0.0 && p.y >= 0.0 && p.x < w && p.y < h) {
        return Pixel {
            object_id: MISSING_ID,
            ..Pixel::SKY
        };
    }
    let mut pixel = frame.pixel(p.x as u32, p.y as u32);
    pixel.color = match filter {
        Filter::Bilinear => bilinear(frame, p),
        Filter::Bicubic => bicubic(frame, p),
    };
    pixel
}

fn texel(frame: &Frame, x: i64, y: i64) -> Vec3 {
    let x = x.clamp(0, frame.width as i64 - 1) as u32;
    let y = y.clamp(0, frame.height as i64 - 1) as u32;
    frame.color[frame.index(x, y)]
}

fn bilinear(frame: &Frame, p: DVec2) -> Vec3 {
    let (x, y) = (p.x - 0.5, p.y - 0.5);
    let (x0, y0) = (x.floor(), y.floor());
    let (fx, fy) = ((x - x0) as f32, (y - y0) as f32);
    let (x0, y0) = (x0 as i64, y0 as i64);
    let top = texel(frame, x0, y0).lerp(texel(frame, x0 + 1, y0), fx);
    let bottom = texel(frame, x0, y0 + 1).lerp(texel(frame, x0 + 1, y0 + 1), fx);
    top.lerp(bottom, fy)
}

/// Catmull–Rom weights for the four taps around a fraction `t` in [0, 1).
fn catmull_rom(t: f32) -> [f32; 4] {
    let (t2, t3) = (t * t, t * t * t);
    [
        0.5 * (-t3 + 2.0 * t2 - t),
        0.5 * (3.0 * t3 - 5.0 * t2 + 2.0),
        0.5 * (-3.0 * t3 + 4.0 * t2 + t),
        0.5 * (t3 - t2),
    ]
}

fn bicubic(frame: &Frame, p: DVec2) -> Vec3 {
    let (x, y) = (p.x - 0.5, p.y - 0.5);
    let (x0, y0) = (x.floor(), y.floor());
    let (wx, wy) = (catmull_rom((x - x0) as f32), catmull_rom((y - y0) as f32));
    let (x0, y0) = (x0 as i64, y0 as i64);
    let mut sum = Vec3::ZERO;
    for (j, wyj) in wy.iter().enumerate() {
        for (i, wxi) in wx.iter().enumerate() {
            sum += texel(frame, x0 - 1 + i as i64, y0 - 1 + j as i64) * (wxi * wyj);
        }
    }
    sum.max(Vec3::ZERO)
}

/// Where the display is: world points on its face to continuous display pixel coordinates.
#[derive(Clone, Debug)]
pub struct DisplayPlacement {
    obstacle_from_world: DAffine3,
    /// Display size, metres.
    width: f64,
    height: f64,
    resolution: [u32; 2],
    /// A curved display's surface (its UVs give the pixel); `None` for the flat face.
    curved: Option<std::sync::Arc<crate::scene::display_surface::CurvedSurface>>,
}

impl DisplayPlacement {
    pub fn new(obstacle: &Obstacle) -> Self {
        Self {
            obstacle_from_world: obstacle.world_from_obstacle.inverse(),
            width: obstacle.width,
            height: obstacle.height,
            resolution: obstacle.display_resolution,
            curved: match &obstacle.display_shape {
                crate::scene::display_surface::DisplayShape::Curved(s) => Some(s.clone()),
                crate::scene::display_surface::DisplayShape::Flat => None,
            },
        }
    }

    /// Continuous display pixel coordinates (x right, y down) of a world point on the display.
    pub fn pixel_coords(&self, world: Vec3) -> DVec2 {
        let p = self.obstacle_from_world.transform_point3(world.as_dvec3());
        if let Some(surface) = &self.curved {
            // NaN (no triangle near the point) clamps to pixel 0 in the lookup.
            let uv = surface.uv_at_point(p).unwrap_or(DVec2::NAN);
            return uv * DVec2::new(self.resolution[0] as f64, self.resolution[1] as f64);
        }
        DVec2::new(
            (p.x / self.width + 0.5) * self.resolution[0] as f64,
            (0.5 - p.y / self.height) * self.resolution[1] as f64,
        )
    }
}

/// How an ideal display finds the frontal point of a point on its face.
// One value per run (or refresh), borrowed by the renderer: the variants' sizes cost nothing.
#[allow(clippy::large_enum_variant)]
#[derive(Clone, Debug)]
pub enum IdealMap {
    /// A flat display: the point's continuous display coordinates through the crop's
    /// homography, then the believed frontal lens ([`FrontalMap`]; `None`: a pinhole).
    Crop {
        crop: Crop,
        lens: Option<crate::geometry::lens::Lens>,
    },
    /// A curved display: the point itself (where the display is now, in its obstacle frame)
    /// through the planar model ([`PointModel`]) — the eye's ray through it meets the model
    /// plane, projected into the believed frontal camera.
    Surface(PointModel),
}

/// What the display shows where the `seethru` view meets it.
// One value per run, borrowed by the renderer: the ideal variant's size (a camera with its
// lens, the crop) costs nothing.
#[allow(clippy::large_enum_variant)]
pub enum DisplaySurface {
    /// A physical display: the nearest of its pixels — one colour per pixel, all AOVs alike.
    Pixels {
        image: Frame,
        placement: DisplayPlacement,
        /// Which image each row shows at the instant looked at, where not all of them show
        /// `image` (a scan-out in progress, rows gone dark); `None`: every row `image`.
        scan: Option<ScannedRows>,
    },
    /// An ideal display and frontal camera of unlimited resolution: the exact point hit is
    /// mapped through the compensation (`map`) into the frontal camera, and a ray from there
    /// finds what it sees. This isolates the planar model's error from resampling.
    Ideal {
        map: IdealMap,
        frontal: Camera,
        placement: DisplayPlacement,
    },
}

/// The rows of a display at one instant of a refresh (geometry/shutter.rs's [`Scanout`]).
///
/// [`Scanout`]: crate::geometry::shutter::Scanout
pub struct ScannedRows {
    /// The image of the refresh before the latest (`None`: there was none).
    pub previous: Option<std::sync::Arc<Frame>>,
    /// What each row shows, from the top: one per row of the display image.
    pub rows: Vec<RowShows>,
}

/// What a dark display row shows: no light, and no world point (counted as missing).
const DARK: Pixel = Pixel {
    color: Vec3::ZERO,
    object_id: MISSING_ID,
    ..Pixel::SKY
};

impl Screen for DisplaySurface {
    fn shown_at(&self, world: Vec3) -> Shown {
        match self {
            DisplaySurface::Pixels {
                image,
                placement,
                scan,
            } => {
                let c = placement.pixel_coords(world);
                let x = (c.x.max(0.0) as u32).min(image.width - 1);
                let y = (c.y.max(0.0) as u32).min(image.height - 1);
                let shown = match scan {
                    None => image,
                    Some(scan) => match (scan.rows[y as usize], &scan.previous) {
                        (RowShows::Latest, _) => image,
                        (RowShows::Previous, Some(previous)) => &**previous,
                        (RowShows::Previous, None) | (RowShows::Dark, _) => {
                            return Shown::Pixel(DARK);
                        }
                    },
                };
                let mut pixel = shown.pixel(x, y);
                // A coded camera's image is shown by its codes (the display's light turns them
                // into light, render/integrator.rs); linear light as it is.
                if let Some(exposure) = shown.exposure.filter(|e| e.coding.is_some()) {
                    pixel.color = pixel.color.map(|c| exposure.code(c));
                }
                Shown::Pixel(pixel)
            }
            DisplaySurface::Ideal {
                map,
                frontal,
                placement,
            } => {
                let p = match map {
                    IdealMap::Crop { crop, lens } => {
                        let p = crop.frontal_point(placement.pixel_coords(world));
                        lens.as_ref().map_or(p, |l| l.distort_pixel(p))
                    }
                    IdealMap::Surface(model) => {
                        let local = placement
                            .obstacle_from_world
                            .transform_point3(world.as_dvec3());
                        // No model point (the ray misses the plane, or the point is behind
                        // the camera): shown as missing below.
                        model.frontal_point_local(local).unwrap_or(DVec2::NAN)
                    }
                };
                if !(p.x >= 0.0
                    && p.y >= 0.0
                    && p.x < frontal.width as f64
                    && p.y < frontal.height as f64)
                {
                    return Shown::Pixel(Pixel {
                        object_id: MISSING_ID,
                        ..Pixel::SKY
                    });
                }
                let (origin, dir) = frontal.world_ray(p);
                Shown::FrontalRay(origin.as_vec3(), dir.as_vec3())
            }
        }
    }
}

/// How the `seethru` view models the display.
#[derive(
    Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum, serde::Serialize, serde::Deserialize,
)]
#[serde(rename_all = "lowercase")]
pub enum DisplayModel {
    /// The physical display's pixels, resampled from the frontal image.
    Pixels,
    /// Unlimited display and frontal resolution: only the planar model's error remains (on
    /// a curved display, per point of its surface).
    Ideal,
}

#[cfg(test)]
mod tests {
    use super::*;

    fn ramp(w: u32, h: u32) -> Frame {
        let pixels: Vec<Pixel> = (0..w * h)
            .map(|i| Pixel {
                color: Vec3::new((i % w) as f32, (i / w) as f32, 1.0),
                object_id: i,
                ..Pixel::SKY
            })
            .collect();
        Frame::from_pixels(w, h, &pixels)
    }

    #[test]
    fn filters_reproduce_a_linear_ramp_exactly() {
        let f = ramp(16, 8);
        for &(x, y) in &[(5.5, 3.5), (6.25, 2.75), (10.9, 4.1)] {
            let p = DVec2::new(x, y);
            let expected = Vec3::new((x - 0.5) as f32, (y - 0.5) as f32, 1.0);
            assert!(bilinear(&f, p).abs_diff_eq(expected, 1e-5));
            assert!(
                bicubic(&f, p).abs_diff_eq(expected, 1e-4),
                "{}",
                bicubic(&f, p)
            );
        }
        // Catmull–Rom weights sum to one.
        for t in [0.0, 0.3, 0.99] {
            assert!((catmull_rom(t).iter().sum::<f32>() - 1.0).abs() < 1e-6);
        }
    }

    #[test]
    fn outside_points_are_missing_and_inside_ids_are_nearest() {
        let f = ramp(16, 8);
        assert_eq!(
            sample(&f, DVec2::new(-0.1, 2.0), Filter::Bilinear).object_id,
            MISSING_ID
        );
        assert_eq!(
            sample(&f, DVec2::new(3.0, 8.0), Filter::Bilinear).object_id,
            MISSING_ID
        );
        assert_eq!(
            sample(&f, DVec2::new(3.9, 2.1), Filter::Bicubic).object_id,
            2 * 16 + 3
        );
    }
}
