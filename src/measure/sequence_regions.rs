//! The driver-view pixels a measured sequence renders at each frame, and no more: the window
//! around the obstacle over the whole sequence, the truth and occluded views rendered where
//! they can change and copied from the last frame elsewhere, and the rectangles' arithmetic.
//! Apart from the stepping (measure/sequence.rs), which only says when each is rendered.

use glam::DVec3;
use obvhs::aabb::Aabb;

use crate::render::footprint::{PixelRect, footprint};
use crate::render::frame::Frame;
use crate::render::integrator::RenderContext;
use crate::render::render_job::RenderJob;
use crate::render::settings::RenderSettings;
use crate::scene::Obstacle;
use crate::scene::world::view_bit;
use crate::system::sequence::system_loop::SystemLoop;

/// The world box of the obstacle's body.
fn obstacle_box(o: &Obstacle) -> Aabb {
    let (lo, hi) = o.body_bounds();
    let mut b = Aabb::empty();
    for k in 0..8 {
        let pick = |bit: usize, l: f64, h: f64| if k & bit == 0 { l } else { h };
        let p = DVec3::new(
            pick(1, lo.x, hi.x),
            pick(2, lo.y, hi.y),
            pick(4, lo.z, hi.z),
        );
        b.extend(o.world_from_obstacle.transform_point3(p).as_vec3().into());
    }
    b
}

/// The union over the sequence of the driver-view pixels that can see the obstacle, grown by
/// a fifth of its size on each side.
pub(crate) fn window(system: &SystemLoop) -> PixelRect {
    let tl = system.options.timeline;
    let mut r: Option<PixelRect> = None;
    for k in 0..tl.frames() {
        let s = system.rig.scene_at(tl.times(k).display);
        let f = footprint(&s.driver, &obstacle_box(&s.obstacle));
        r = Some(r.map_or(f, |r| PixelRect {
            x0: r.x0.min(f.x0),
            y0: r.y0.min(f.y0),
            x1: r.x1.max(f.x1),
            y1: r.y1.max(f.y1),
        }));
    }
    let camera = system.rig.base.driver;
    r.unwrap_or(PixelRect::full(&camera)).grown(5, 2, &camera)
}

/// Renders the driver's truth view into `truth` within `region`, and the occluded view into
/// `occluded`: the truth with the pixels the obstacle and display change rendered again. The
/// measured sequence and the Python package's stepped sequence both make their frames so.
/// `occluded` holds the last frame's occluded view, and `last` is what this function
/// returned then (its re-rendered pixels): only `region` and `last` are copied from the
/// truth, since elsewhere neither view changed. Returns the pixels re-rendered this time.
pub fn render_truth_and_occluded(
    ctx: &RenderContext,
    settings: RenderSettings,
    region: PixelRect,
    truth: &mut Frame,
    occluded: &mut Frame,
    last: PixelRect,
) -> PixelRect {
    let driver = ctx.scene.driver;
    ctx.render_into(
        RenderJob::new(&driver, view_bit::TRUTH)
            .settings(settings)
            .region(region)
            .label("truth"),
        truth,
    );
    copy_rect(truth, occluded, union(region, last));
    let around = ctx.difference_region(&driver, view_bit::TRUTH, view_bit::OCCLUDED);
    ctx.render_into(
        RenderJob::new(&driver, view_bit::OCCLUDED)
            .settings(settings)
            .region(around)
            .label("occluded"),
        occluded,
    );
    around
}

/// No pixel.
pub(crate) const NOTHING: PixelRect = PixelRect {
    x0: 0,
    y0: 0,
    x1: 0,
    y1: 0,
};

/// The smallest rectangle holding `a` and `b` (an empty one holds nothing).
pub(crate) fn union(a: PixelRect, b: PixelRect) -> PixelRect {
    match (a.is_empty(), b.is_empty()) {
        (true, _) => b,
        (_, true) => a,
        _ => PixelRect {
            x0: a.x0.min(b.x0),
            y0: a.y0.min(b.y0),
            x1: a.x1.max(b.x1),
            y1: a.y1.max(b.y1),
        },
    }
}

/// Every AOV of the pixels of `rect` from `from` into `to` (frames of one size).
pub(crate) fn copy_rect(from: &Frame, to: &mut Frame, rect: PixelRect) {
    assert_eq!((from.width, from.height), (to.width, to.height));
    let (w, rect) = (from.width as usize, clip(rect, from));
    if rect.is_empty() {
        return;
    }
    for y in rect.y0 as usize..rect.y1 as usize {
        let at = y * w + rect.x0 as usize;
        to.copy_pixels(at, from, at, (rect.x1 - rect.x0) as usize);
    }
}

/// `rect` within `frame`.
fn clip(rect: PixelRect, frame: &Frame) -> PixelRect {
    PixelRect {
        x0: rect.x0.min(frame.width),
        y0: rect.y0.min(frame.height),
        x1: rect.x1.min(frame.width),
        y1: rect.y1.min(frame.height),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::render::frame::Pixel;
    use crate::scene::Scene;

    /// The obstacle's body bounds are those of its triangles in the world the renderer
    /// traces (in the obstacle frame, where they are tight), for a flat display and for the
    /// cabin's curved one, whose surface bulges out of the flat box; and its world box holds
    /// every traced triangle (the cabin's pillar is turned about all three axes).
    #[test]
    fn the_obstacle_box_holds_the_traced_obstacle() {
        for name in ["das.toml", "cabin.toml"] {
            let scene = Scene::bundled(name);
            let world = crate::scene::world::World::build(&scene).unwrap();
            let (mut lo, mut hi) = (DVec3::INFINITY, DVec3::NEG_INFINITY);
            let mut traced = Aabb::empty();
            for (prim, t) in world.triangles.iter().enumerate() {
                if world.object_of(prim) != world.obstacle_id {
                    continue;
                }
                traced = traced.union(&t.aabb());
                let v0 = t.v0.as_dvec3();
                for v in [v0, v0 - t.e1.as_dvec3(), v0 + t.e2.as_dvec3()] {
                    let p = scene.obstacle.in_obstacle_frame(v);
                    (lo, hi) = (lo.min(p), hi.max(p));
                }
            }
            let (body_lo, body_hi) = scene.obstacle.body_bounds();
            let gap = (body_lo - lo).abs().max((body_hi - hi).abs());
            assert!(
                gap.max_element() < 1e-5,
                "{name}: {body_lo}..{body_hi} against {lo}..{hi}"
            );
            let b = obstacle_box(&scene.obstacle);
            let outside = (b.min - traced.min).max(traced.max - b.max);
            assert!(
                outside.max_element() < 1e-5,
                "{name}: {b:?} against {traced:?}"
            );
        }
    }

    /// The union of two rectangles, and of one with nothing.
    #[test]
    fn union_holds_both_rectangles_and_nothing_adds_nothing() {
        let a = PixelRect {
            x0: 4,
            y0: 5,
            x1: 9,
            y1: 7,
        };
        let b = PixelRect {
            x0: 2,
            y0: 6,
            x1: 6,
            y1: 11,
        };
        assert_eq!(
            union(a, b),
            PixelRect {
                x0: 2,
                y0: 5,
                x1: 9,
                y1: 11
            }
        );
        assert_eq!(union(NOTHING, a), a);
        assert_eq!(union(a, NOTHING), a);
        let empty_elsewhere = PixelRect {
            x0: 20,
            y0: 20,
            x1: 20,
            y1: 30,
        };
        assert_eq!(union(empty_elsewhere, b), b);
        assert_eq!(union(b, empty_elsewhere), b);
    }

    /// Every AOV of the rectangle's pixels is copied, and no other pixel, also when the
    /// rectangle runs past the frame.
    #[test]
    fn copy_rect_copies_the_rectangle_and_nothing_else() {
        let (w, h) = (7u32, 5u32);
        let pixels: Vec<Pixel> = (0..w * h)
            .map(|i| {
                let v = i as f32 + 1.0;
                Pixel {
                    color: glam::Vec3::splat(v),
                    depth: v,
                    camera_z: -v,
                    position: glam::Vec3::new(v, 0.0, 0.0),
                    normal: glam::Vec3::new(0.0, v, 0.0),
                    object_id: i + 1,
                    part_id: i + 2,
                }
            })
            .collect();
        let from = Frame::from_pixels(w, h, &pixels);
        for rect in [
            PixelRect {
                x0: 2,
                y0: 1,
                x1: 5,
                y1: 4,
            },
            PixelRect {
                x0: 5,
                y0: 3,
                x1: 100,
                y1: 100,
            },
        ] {
            let mut to = Frame::new(w, h);
            copy_rect(&from, &mut to, rect);
            for y in 0..h {
                for x in 0..w {
                    let inside = (rect.x0..rect.x1).contains(&x) && (rect.y0..rect.y1).contains(&y);
                    let want = if inside { from.pixel(x, y) } else { Pixel::SKY };
                    // Debug strings, since the sky's position is NaN.
                    let (got, want) = (format!("{:?}", to.pixel(x, y)), format!("{want:?}"));
                    assert_eq!(got, want, "({x}, {y}) of {rect:?}");
                }
            }
        }
    }
}
