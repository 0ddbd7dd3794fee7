//! Cameras in time (geometry/shutter.rs, render/shutter_rays.rs, render/in_time.rs) against
//! analytic answers and brute-force twins: a rolling shutter slants a vertical pole by the
//! camera's yaw over the readout, an exposure blurs a point over the yaw during it, and a
//! frame in time is the mean of instantaneous renders at the same instants, bit for bit.

mod common;

use glam::{DAffine3, Vec3};
use seethru::geometry::camera::Camera;
use seethru::geometry::shutter::Shutter;
use seethru::render::footprint::PixelRect;
use seethru::render::frame::Frame;
use seethru::render::in_time::render_by_instant;
use seethru::render::integrator::RenderContext;
use seethru::render::render_job::RenderJob;
use seethru::render::settings::RenderSettings;
use seethru::scene::world::view_bit::FRONTAL;

/// A dark wall 10 m ahead of the frontal camera (640×480, 45° half angle: f = 320 px), the
/// objects `objects` (TOML) in front of it, the frontal camera's shutter keys `shutter`.
fn scene_text(shutter: &str, objects: &str) -> String {
    format!(
        r#"
[sun]
intensity = 0.0

[sky]
ambient = 1.0

[obstacle]
center = [0.0, 0.0, 0.0]

[camera.driver]
position = [0.0, 0.0, 0.7]
look_at = [0.0, 0.0, -6.0]

[camera.frontal]
resolution = [640, 480]
half_angle_deg = 45.0
{shutter}

[camera.back]
resolution = [32, 24]

[[material]]
name = "dark"
color = [0.05, 0.05, 0.05]

[[material]]
name = "bright"
color = [0.9, 0.9, 0.9]

[[object]]
name = "wall"
kind = "quad"
material = "dark"
size = [80.0, 60.0]
translate = [0.0, 0.0, -10.0]
{objects}
"#
    )
}

const POLE: &str = r#"
[[object]]
name = "pole"
kind = "box"
material = "bright"
size = [0.1, 20.0, 0.1]
translate = [0.0, 0.0, -5.0]
"#;

const POINT: &str = r#"
[[object]]
name = "point"
kind = "sphere"
material = "bright"
radius = 0.05
translate = [0.0, 0.0, -5.0]
"#;

fn context(shutter: &str, objects: &str) -> RenderContext {
    RenderContext::new(common::parse(&scene_text(shutter, objects)).unwrap()).unwrap()
}

/// The camera yawing to its left (about its own vertical axis) at `omega` rad/s: its pose
/// `dt` seconds on.
fn yawing(camera: Camera, omega: f64) -> impl Fn(f64) -> DAffine3 + Sync {
    let c = camera.position();
    move |dt| {
        DAffine3::from_translation(c)
            * DAffine3::from_rotation_y(omega * dt)
            * DAffine3::from_translation(-c)
            * camera.world_from_camera
    }
}

fn settings(spp: u32) -> RenderSettings {
    RenderSettings {
        spp,
        progress: false,
    }
}

/// Least-squares slope of `y` over `x`.
fn slope(points: &[(f64, f64)]) -> f64 {
    let n = points.len() as f64;
    let (mx, my) = points
        .iter()
        .fold((0.0, 0.0), |(a, b), (x, y)| (a + x / n, b + y / n));
    let sxy: f64 = points.iter().map(|(x, y)| (x - mx) * (y - my)).sum();
    let sxx: f64 = points.iter().map(|(x, _)| (x - mx) * (x - mx)).sum();
    sxy / sxx
}

/// The pole's centre column in each row (its object id's pixels), as (row, column).
fn pole_centres(frame: &Frame, pole_id: u32) -> Vec<(f64, f64)> {
    (0..frame.height)
        .filter_map(|y| {
            let xs: Vec<u32> = (0..frame.width)
                .filter(|&x| frame.pixel(x, y).object_id == pole_id)
                .collect();
            let mean = xs.iter().map(|&x| f64::from(x) + 0.5).sum::<f64>() / xs.len() as f64;
            (!xs.is_empty()).then_some((f64::from(y), mean))
        })
        .collect()
}

#[test]
fn a_rolling_shutter_slants_a_vertical_pole_by_the_yaw_over_the_readout() {
    let (omega, readout) = (3.0, 0.05);
    let ctx = context("shutter = \"rolling\"\nreadout_ms = 50.0", POLE);
    let camera = ctx.scene.frontal;
    assert_eq!(camera.shutter.readout_s, readout);
    let pole = ctx
        .scene
        .objects
        .iter()
        .position(|o| o.name == "pole")
        .unwrap() as u32
        + 1;
    let pose_at = yawing(camera, omega);
    // The pole's centre per row, seen by a context's frontal camera on that turn.
    let centres = |ctx: &RenderContext| {
        let camera = ctx.scene.frontal;
        let job = RenderJob::new(&camera, FRONTAL)
            .settings(settings(1))
            .moving(&pose_at);
        pole_centres(&ctx.render(job).0, pole)
    };
    let measured = centres(&ctx);
    assert_eq!(measured.len(), 480, "the pole spans every row");
    // The analytic answer: row r is read T (H − 1 − r) / (H − 1) before the last (at the
    // frame's instant), when the camera had turned ω t to the left (t < 0); a vertical line
    // straight ahead is then f tan(ω t) right of the centre. Its slant over the image: the
    // fitted slope times H − 1 (the same fit as the measurement, so the small curvature of tan
    // cancels).
    let f = 320.0;
    let analytic: Vec<(f64, f64)> = (0..480)
        .map(|r| {
            let t = -readout * f64::from(479 - r) / 479.0;
            (f64::from(r), 320.0 + f * (omega * t).tan())
        })
        .collect();
    let (got, want) = (slope(&measured) * 479.0, slope(&analytic) * 479.0);
    assert!(want > 45.0, "ω T = 0.15 rad: about 48 px, got {want}");
    assert!(
        (got / want - 1.0).abs() < 0.02,
        "slant {got:.2} px, ω·T gives {want:.2} px"
    );
    // Read from the bottom up, the slant turns over.
    let flipped = context(
        "shutter = \"rolling\"\nreadout_ms = 50.0\nrow_order = \"bottom_to_top\"",
        POLE,
    );
    let up = slope(&centres(&flipped)) * 479.0;
    assert!((up / -want - 1.0).abs() < 0.02, "bottom to top: {up:.2} px");
    // A global shutter: every row at once, no slant.
    let still = slope(&centres(&context("", POLE))) * 479.0;
    assert!(still.abs() < 0.5, "global shutter: {still:.3} px");
}

/// The luminance-weighted mean and variance (px²) of columns of `a − b` over `region`.
fn column_moments(a: &Frame, b: &Frame, region: PixelRect) -> (f64, f64) {
    let mut w = Vec::new();
    for y in region.y0..region.y1 {
        for x in region.x0..region.x1 {
            let i = a.index(x, y);
            let d = (a.color[i] - b.color[i]).dot(Vec3::splat(1.0 / 3.0)) as f64;
            w.push((f64::from(x) + 0.5, d));
        }
    }
    let total: f64 = w.iter().map(|(_, d)| d).sum();
    let mean = w.iter().map(|(x, d)| x * d).sum::<f64>() / total;
    let var = w.iter().map(|(x, d)| (x - mean).powi(2) * d).sum::<f64>() / total;
    (mean, var)
}

#[test]
fn an_exposure_blurs_a_point_by_the_yaw_during_it() {
    let (omega, exposure, spp) = (2.0, 0.03, 64);
    // Around the image's centre, where the point is.
    let region = PixelRect {
        x0: 280,
        y0: 228,
        x1: 360,
        y1: 252,
    };
    // The point's image with the exposure and without, each over the wall alone.
    let moments = |shutter: &str| {
        let with = context(shutter, POINT);
        let without = context(shutter, "");
        let camera = with.scene.frontal;
        let pose_at = yawing(camera, omega);
        let job = RenderJob::new(&camera, FRONTAL)
            .settings(settings(spp))
            .region(region)
            .moving(&pose_at);
        let (a, _) = with.render(job);
        let (b, _) = without.render(job);
        column_moments(&a, &b, region)
    };
    let (_, still) = moments("");
    let (mean, blurred) = moments("exposure_ms = 30.0");
    // A box of length L adds L²/12 to the variance: over the exposure the camera turns ω E,
    // and a point straight ahead sweeps f (tan(ω E / 2) + tan(ω E / 2)); the 64 slices
    // sample that box at their midpoints, whose variance is L² (1 − 1/64²) / 12.
    let f = 320.0;
    let want = 2.0 * f * (omega * exposure / 2.0).tan() * (1.0 - 1.0 / 64f64.powi(2)).sqrt();
    let got = (12.0 * (blurred - still)).sqrt();
    assert!(
        (got / want - 1.0).abs() < 0.05,
        "blur {got:.2} px, ω·E gives {want:.2} px (static variance {still:.2} px²)"
    );
    // Centred on the exposure's middle, E / 2 before the frame's instant: the camera had
    // turned ω E / 2 less to the left, so the point sits f tan(ω E / 2) left of the centre.
    let middle = 320.0 - f * (omega * exposure / 2.0).tan();
    assert!(
        (mean - middle).abs() < 0.3,
        "blur centred at {mean:.2}, the exposure's middle at {middle:.2}"
    );
}

/// The mean of `spp` instantaneous renders, render `s` at its sample's instant with sample `s`
/// alone, summed in order as a pixel's samples are; the AOVs are sample 0's.
fn mean_of_instants(
    ctx: &RenderContext,
    camera: Camera,
    pose_at: &dyn Fn(f64) -> DAffine3,
    spp: u32,
) -> Frame {
    let shutter = camera.shutter;
    let mut mean = Frame::new(camera.width, camera.height);
    let mut sums = vec![Vec3::ZERO; mean.color.len()];
    for row in 0..camera.height {
        for s in 0..spp {
            let dt = shutter.instant(row, camera.height, s, spp);
            let at = Camera {
                world_from_camera: pose_at(dt),
                shutter: Shutter::INSTANT,
                ..camera
            };
            let (frame, _) = ctx.render(
                RenderJob::new(&at, FRONTAL)
                    .settings(settings(spp))
                    .sample(s),
            );
            let i = frame.index(0, row);
            let n = camera.width as usize;
            if s == 0 {
                mean.copy_pixels(i, &frame, i, n);
            }
            for (sum, c) in sums[i..i + n].iter_mut().zip(&frame.color[i..i + n]) {
                *sum += *c;
            }
        }
    }
    for (c, sum) in mean.color.iter_mut().zip(&sums) {
        *c = *sum / spp as f32;
    }
    mean
}

#[test]
fn a_frame_in_time_is_the_mean_of_instantaneous_renders_at_its_instants() {
    let spp = 3;
    for shutter in [
        "exposure_ms = 20.0",
        "shutter = \"rolling\"\nreadout_ms = 30.0",
        "shutter = \"rolling\"\nreadout_ms = 30.0\nexposure_ms = 10.0\nrow_order = \"bottom_to_top\"",
    ] {
        let text = scene_text(shutter, &format!("{POLE}{POINT}"))
            .replace("resolution = [640, 480]", "resolution = [48, 36]");
        let ctx = RenderContext::new(common::parse(&text).unwrap()).unwrap();
        let camera = ctx.scene.frontal;
        let pose_at = yawing(camera, 4.0);
        let job = RenderJob::new(&camera, FRONTAL)
            .settings(settings(spp))
            .moving(&pose_at);
        let (one_pass, stats) = ctx.render(job);
        assert_eq!(stats.primary_rays, 48 * 36 * u64::from(spp));
        let twin = mean_of_instants(&ctx, camera, &pose_at, spp);
        assert!(
            one_pass.bit_identical(&twin),
            "{shutter}: one pass vs the mean"
        );
        // The packets' twin, one ray at a time, each from its own instant's camera.
        let (per_ray, _) = ctx.render(job.tracer(seethru::render::render_job::Tracer::PerRay));
        assert!(
            per_ray.bit_identical(&one_pass),
            "{shutter}: per ray vs packets"
        );
        // The instant-by-instant path (a context per instant) is the same frame.
        let mut by_instant = Frame::new(48, 36);
        let mut context_at = |_t: f64| ctx.with_scene(ctx.scene.clone());
        render_by_instant(&mut context_at, 0.0, job, &mut by_instant).unwrap();
        assert!(
            by_instant.bit_identical(&one_pass),
            "{shutter}: instant by instant vs one pass"
        );
        // And the camera did move: a still render differs.
        let (still, _) = ctx.render(RenderJob::new(&camera, FRONTAL).settings(settings(spp)));
        assert!(!still.bit_identical(&one_pass), "{shutter}");
    }
}

#[test]
fn an_instant_shutter_on_a_moving_camera_is_todays_image() {
    let ctx = context("", POLE);
    let camera = ctx.scene.frontal;
    assert!(camera.shutter.is_instant());
    let pose_at = yawing(camera, 3.0);
    let job = RenderJob::new(&camera, FRONTAL).settings(settings(2));
    let (still, _) = ctx.render(job);
    let (moving, _) = ctx.render(job.moving(&pose_at));
    assert!(still.bit_identical(&moving));
}

/// `run` at one moving instant: the wall 6 m ahead, the vehicle yawing at 20°/s, a rolling
/// frontal camera: the display's rows show frontal rows read before the frame's instant (the
/// truth's), so the mean misregistration is ω times their mean age; a global shutter with an
/// instant exposure refuses the motion (it would change nothing).
#[test]
fn a_run_on_a_turning_vehicle_sees_its_rolling_rows_as_old_as_they_are() {
    use seethru::analysis::physical::ARCMIN_PER_RAD;
    use seethru::measure::image_metrics::Flip;
    use seethru::measure::metrics::measure_with;
    use seethru::render::integrator::RenderContext;
    use seethru::system::options::{RunOptions, WorkingDistance};
    use seethru::system::pipeline::run;
    let text = common::WallScene::default().text().replace(
        "[camera.frontal]",
        "[camera.frontal]\nshutter = \"rolling\"\nreadout_ms = 60.0",
    );
    let scene = common::parse_in(&common::repo_path("scenes"), "wall.toml", &text).unwrap();
    let ctx = RenderContext::new(scene.clone()).unwrap();
    let options = RunOptions {
        d2: WorkingDistance::Metres(6.0),
        spp: 1,
        yaw_rate_deg_s: 20.0,
        ..RunOptions::default()
    };
    let mean_of = |options: &RunOptions| {
        let r = run(&ctx, options).unwrap();
        let eye = ctx.scene.eye();
        let views = r.measured_views();
        measure_with(&ctx, &ctx.scene, eye, views, 5, Flip::Skipped)
            .1
            .display
            .misregistration_arcmin
            .mean
    };
    let mean = mean_of(&options);
    let predicted = 20f64.to_radians() * common::readout_age(&scene, 0.06, 6.0) * ARCMIN_PER_RAD;
    assert!(
        (mean / predicted - 1.0).abs() < 0.03,
        "measured {mean:.2}′, ω × mean readout age {predicted:.2}′"
    );
    // Still, the same scene: the static error alone (the resampling quantum), a fifth of it.
    let still = mean_of(&RunOptions {
        yaw_rate_deg_s: 0.0,
        ..options.clone()
    });
    assert!(still < 0.2 * predicted, "still: {still:.2}′");
    // A global instant shutter: the motion would change nothing.
    let global = common::WallScene::default().context();
    let error = run(&global, &options).err().unwrap().to_string();
    assert!(
        error.contains("option `yaw_rate`") && error.contains("shutter"),
        "{error}"
    );
}

/// `run` with a camera latency L (option `latency_camera`): the frontal image is L older than
/// the instant the driver looks, so on the wall 6 m ahead (the model plane on it) the vehicle
/// yawing at ω shows a mean misregistration of ω L with a global shutter, and ω (L + the mean
/// readout age) with a rolling one: the two ages add. A latency with a still vehicle would
/// change nothing: refused.
#[test]
fn a_run_with_a_camera_latency_sees_the_world_as_old_as_the_latency() {
    use seethru::analysis::physical::ARCMIN_PER_RAD;
    use seethru::measure::image_metrics::Flip;
    use seethru::measure::metrics::measure_with;
    use seethru::system::options::{RunOptions, WorkingDistance};
    use seethru::system::pipeline::run;
    let mean_of = |ctx: &RenderContext, options: &RunOptions| {
        let r = run(ctx, options).unwrap();
        let eye = ctx.scene.eye();
        measure_with(ctx, &ctx.scene, eye, r.measured_views(), 5, Flip::Skipped)
            .1
            .display
            .misregistration_arcmin
            .mean
    };
    let (omega, latency) = (20f64.to_radians(), 0.05);
    let options = RunOptions {
        d2: WorkingDistance::Metres(6.0),
        spp: 1,
        yaw_rate_deg_s: omega.to_degrees(),
        latency_camera_ms: latency * 1e3,
        ..RunOptions::default()
    };
    let global = common::WallScene::default().context();
    let mean = mean_of(&global, &options);
    let predicted = omega * latency * ARCMIN_PER_RAD;
    assert!(
        (mean / predicted - 1.0).abs() < 0.03,
        "global shutter: measured {mean:.2}′, ω L {predicted:.2}′"
    );
    let text = common::WallScene::default().text().replace(
        "[camera.frontal]",
        "[camera.frontal]\nshutter = \"rolling\"\nreadout_ms = 60.0",
    );
    let scene = common::parse_in(&common::repo_path("scenes"), "wall.toml", &text).unwrap();
    let rolling = RenderContext::new(scene.clone()).unwrap();
    let mean = mean_of(&rolling, &options);
    let predicted = omega * (latency + common::readout_age(&scene, 0.06, 6.0)) * ARCMIN_PER_RAD;
    assert!(
        (mean / predicted - 1.0).abs() < 0.03,
        "rolling shutter: measured {mean:.2}′, ω (L + readout age) {predicted:.2}′"
    );
    let still = RunOptions {
        yaw_rate_deg_s: 0.0,
        ..options
    };
    let error = run(&global, &still).err().unwrap().to_string();
    assert!(
        error.contains("option `latency_camera`") && error.contains("still"),
        "{error}"
    );
}

/// The frontal image of a run (and of a capture) with a latency L is the frontal camera's
/// render where the vehicle had it L before, placed by hand (driving back v L along +z,
/// turning back ω L about the eye), bit for bit; the depth sensor's map keeps the camera where
/// it is mounted.
#[test]
fn a_latency_renders_the_frontal_camera_where_the_vehicle_had_it() {
    use seethru::system::options::RunOptions;
    use seethru::system::pipeline::run;
    let ctx = common::WallScene::default().context();
    let (speed, omega, latency) = (0.0, 15f64.to_radians(), 0.08);
    for (speed_kmh, yaw_rate) in [(36.0, 0.0), (speed, omega.to_degrees())] {
        let options = RunOptions {
            spp: 1,
            speed_kmh,
            yaw_rate_deg_s: yaw_rate,
            latency_camera_ms: latency * 1e3,
            ..RunOptions::default()
        };
        let frontal = run(&ctx, &options).unwrap().frontal;
        let camera = ctx.scene.frontal;
        let eye = ctx.scene.eye();
        // Straight on (−z) at v, or turning about the eye at ω: L earlier.
        let world_from_rig = if yaw_rate == 0.0 {
            DAffine3::from_translation(glam::DVec3::Z * (speed_kmh / 3.6) * latency)
        } else {
            DAffine3::from_translation(eye)
                * DAffine3::from_rotation_y(-omega * latency)
                * DAffine3::from_translation(-eye)
        };
        let by_hand = Camera {
            world_from_camera: world_from_rig * camera.world_from_camera,
            ..camera
        };
        let (want, _) = ctx.render(RenderJob::new(&by_hand, FRONTAL).settings(settings(1)));
        let moved = (by_hand.position() - camera.position()).length();
        assert!(moved > 0.005, "the camera moved {moved} m");
        assert!(
            frontal.bit_identical(&want),
            "speed {speed_kmh} km/h, yaw rate {yaw_rate}°/s: the frontal image is not the moved camera's"
        );
        // A capture sees the same; its depth sensor sensed from there too (the ideal sensor's
        // depths are the frontal render's), read as from the mount: the system's belief.
        let captured = seethru::system::capture::capture(&ctx, &options, true).unwrap();
        assert!(captured.frontal.bit_identical(&want));
        let depth = captured.depth.unwrap();
        assert_eq!(depth.camera.world_from_camera, camera.world_from_camera);
        let nearest = want.camera_z.iter().copied().fold(f32::INFINITY, f32::min);
        assert!((depth.max_inverse_depth() - 1.0 / nearest).abs() < 1e-6);
    }
}

/// A sequence on the textured wall 6 m ahead (the model plane on it), the vehicle yawing at
/// ω, the image `latency` s old when complete, the frontal camera's shutter `shutter`: each
/// display pixel shows a frontal row read `T (H − 1 − r) / (H − 1)` before the last, so its
/// image is that much older, and the mean misregistration is ω times the mean age over the
/// display's pixels, the rows found by casting the eye's rays through the display onto the
/// wall.
#[test]
fn a_rolling_frontal_camera_makes_each_display_row_as_old_as_its_frontal_row() {
    use seethru::analysis::physical::ARCMIN_PER_RAD;
    use seethru::measure::image_metrics::Flip;
    use seethru::measure::sequence::run_sequence;
    use seethru::system::options::{RunOptions, WorkingDistance};
    let wall = common::WallScene::default();
    let (omega, latency, readout) = (20f64.to_radians(), 0.1, 0.06);
    let mut means = Vec::new();
    for shutter in ["", "shutter = \"rolling\"\nreadout_ms = 60.0"] {
        let text = wall
            .text()
            .replace("[camera.frontal]", &format!("[camera.frontal]\n{shutter}"));
        let scene = common::parse_in(&common::repo_path("scenes"), "wall.toml", &text).unwrap();
        let run = RunOptions {
            d2: WorkingDistance::Metres(6.0),
            spp: 1,
            ..RunOptions::default()
        };
        let mut o = common::still_sequence(run, 6.0 / 30.0, 30.0, latency);
        o.run.yaw_rate_deg_s = omega.to_degrees();
        let how = common::measuring(Flip::Skipped);
        let run = run_sequence(&scene, o, how, &mut |_| Ok(())).unwrap();
        let m: Vec<f64> = run
            .records
            .iter()
            .map(|r| r.metrics.unwrap().mean_arcmin)
            .collect();
        means.push(m.iter().sum::<f64>() / m.len() as f64);
        let rolled = if shutter.is_empty() {
            0.0
        } else {
            common::readout_age(&scene, readout, 6.0)
        };
        let predicted = omega * (latency + rolled) * ARCMIN_PER_RAD;
        let mean = means[means.len() - 1];
        assert!(
            (mean / predicted - 1.0).abs() < 0.02,
            "{shutter:?}: measured {mean:.2}′, ω × mean age {predicted:.2}′"
        );
    }
    // The rolling shutter's rows, read before the last, are older: more misregistration.
    assert!(means[1] > means[0] * 1.2, "{means:?}");
}

/// das's sequence loop with a rolling (30 ms), exposed (8 ms) frontal camera `frontal_width`
/// pixels wide, driving at 10 km/h and turning at 0.3 rad/s: its ball rolls through the
/// frontal view.
fn turning_das(spp: u32, frontal_width: u32) -> seethru::system::sequence::system_loop::SystemLoop {
    use seethru::system::options::RunOptions;
    let text = std::fs::read_to_string(common::repo_path("scenes/das.toml"))
        .unwrap()
        .replace(
            "[camera.frontal]",
            "[camera.frontal]\nshutter = \"rolling\"\nreadout_ms = 30.0\nexposure_ms = 8.0",
        );
    let scene = common::parse_in(&common::repo_path("scenes"), "das.toml", &text).unwrap();
    let run = RunOptions {
        spp,
        frontal_width: Some(frontal_width),
        ..RunOptions::default()
    };
    let mut o = common::still_sequence(run, 0.2, 10.0, 0.0);
    (o.run.speed_kmh, o.run.yaw_rate_deg_s) = (10.0, 0.3f64.to_degrees());
    seethru::system::sequence::system_loop::SystemLoop::new(&scene, o).unwrap()
}

/// The frontal camera's pose `dt` after `t`, carried by `system`'s vehicle.
fn carried(
    system: &seethru::system::sequence::system_loop::SystemLoop,
    t: f64,
) -> impl Fn(f64) -> DAffine3 + Sync + use<> {
    let vehicle = system.rig.vehicle.clone();
    let base = system.rig.base.frontal.world_from_camera;
    move |dt: f64| vehicle.world_from_rig(t + dt) * base
}

/// das's ball rolls across the frontal camera's view while the vehicle drives and turns: with
/// a rolling shutter and an exposure, the world differs from band to band of rows and slice
/// to slice, so the frame is rendered instant by instant; its brute-force twin renders the
/// whole frame (the camera moving) over the world placed at each band's and slice's instant
/// and keeps that band's rows.
#[test]
fn a_moving_world_through_a_rolling_shutter_equals_its_band_by_band_twin() {
    use seethru::render::in_time::{band_instant, needs_instants, render_in_time};
    let mut system = turning_das(2, 64);
    let t = 0.3;
    let ctx = system.context_at(t).unwrap();
    let camera = ctx.scene.frontal;
    let (w, h, spp) = (camera.width, camera.height, 2);
    let pose_at = carried(&system, t);
    let job = RenderJob::new(&camera, FRONTAL)
        .settings(settings(spp))
        .moving(&pose_at);
    assert!(
        needs_instants(&ctx, &job),
        "the ball is in the frontal view"
    );
    let mut frame = Frame::new(w, h);
    render_in_time(&ctx, &mut |at| system.context_at(at), t, job, &mut frame).unwrap();
    let mut twin = Frame::new(w, h);
    let mut sums = vec![Vec3::ZERO; twin.color.len()];
    for band in (0..h).step_by(4) {
        for s in 0..spp {
            let dt = band_instant(&camera.shutter, band, h, s, spp);
            let at = system.context_at(t + dt).unwrap();
            let (full, _) = at.render(job.sample(s));
            let i = full.index(0, band);
            let n = (w * (h - band).min(4)) as usize;
            if s == 0 {
                twin.copy_pixels(i, &full, i, n);
            }
            for (sum, c) in sums[i..i + n].iter_mut().zip(&full.color[i..i + n]) {
                *sum += *c;
            }
        }
    }
    for (c, sum) in twin.color.iter_mut().zip(&sums) {
        *c = *sum / spp as f32;
    }
    assert!(frame.bit_identical(&twin));
    // The ball is in it, and the one-pass render (the world held at t) differs where it moves.
    let ball = ctx
        .scene
        .objects
        .iter()
        .position(|o| o.name == "ball")
        .unwrap() as u32
        + 1;
    assert!(frame.object_id.contains(&ball));
    let (held, _) = ctx.render(job);
    assert!(!held.bit_identical(&frame));
}

/// Each shutter key out of its range, or where the shutter does not read it, is one error
/// naming the file's line, the key, the value or the rule, and the admissible range.
#[test]
fn bad_shutter_keys_are_one_clear_error() {
    for (keys, words) in [
        (
            "readout_ms = 20.0",
            &["readout_ms", "shutter = \\\"rolling\\\""][..],
        ),
        ("row_order = \"bottom_to_top\"", &["row_order", "rolling"]),
        ("shutter = \"slow\"", &["shutter", "global", "rolling"]),
        (
            "shutter = \"rolling\"\nreadout_ms = 0.0",
            &["readout_ms", "0.001", "1000"],
        ),
        (
            "shutter = \"rolling\"\nreadout_ms = 2000.0",
            &["readout_ms", "1000"],
        ),
        (
            "shutter = \"rolling\"\nrow_order = \"left\"",
            &["row_order", "top_to_bottom"],
        ),
        ("exposure_ms = -1.0", &["exposure_ms", "0", "1000"]),
        ("exposure_ms = nan", &["exposure_ms"]),
    ] {
        let text = scene_text(keys, "");
        let error = common::parse(&text).unwrap_err().to_string();
        assert!(!error.contains('\n'), "{keys}: {error}");
        assert!(error.contains("scene.toml:"), "{keys}: {error}");
        for w in words {
            let w = w.replace("\\\"", "\"");
            assert!(error.contains(&w), "{keys}: `{w}` missing from: {error}");
        }
    }
    // The display's keys.
    for (keys, words) in [
        ("scanout = \"fast\"", &["scanout", "global", "rolling"][..]),
        ("persistence_ms = 0.0", &["persistence_ms", "0.001", "1000"]),
        ("persistence_ms = 5000.0", &["persistence_ms", "1000"]),
    ] {
        let text = scene_text("", "").replace("[obstacle]", &format!("[obstacle]\n{keys}"));
        let error = common::parse(&text).unwrap_err().to_string();
        assert!(
            !error.contains('\n') && error.contains("scene.toml:"),
            "{error}"
        );
        for w in words {
            assert!(error.contains(w), "{keys}: `{w}` missing from: {error}");
        }
    }
    // The driver's eye has no shutter: an unknown key.
    let text =
        scene_text("", "").replace("[camera.driver]", "[camera.driver]\nshutter = \"rolling\"");
    let error = common::parse(&text).unwrap_err().to_string();
    assert!(error.contains("shutter"), "{error}");
}

/// The wall sequence of [`a_rolling_frontal_camera_makes_each_display_row_as_old_as_its_frontal_row`]
/// with the display's scan-out keys `obstacle` (TOML lines under `[obstacle]`), sampled 8
/// times per 30 Hz refresh, the image 50 ms old at its refresh: each frame's records.
fn scanned_sequence(obstacle: &str) -> seethru::measure::sequence::SequenceRun {
    use seethru::measure::image_metrics::Flip;
    use seethru::measure::sequence::run_sequence;
    use seethru::system::options::{RunOptions, WorkingDistance};
    let text = common::WallScene::default()
        .text()
        .replace("[obstacle]", &format!("[obstacle]\n{obstacle}"));
    let scene = common::parse_in(&common::repo_path("scenes"), "wall.toml", &text).unwrap();
    let run = RunOptions {
        d2: WorkingDistance::Metres(6.0),
        spp: 1,
        ..RunOptions::default()
    };
    let mut o = common::still_sequence(run, 3.0 / 30.0, 240.0, 0.05);
    o.timeline.display_hz = 30.0;
    o.run.yaw_rate_deg_s = 20.0;
    let how = common::measuring(Flip::Skipped);
    run_sequence(&scene, o, how, &mut |_| Ok(())).unwrap()
}

/// A rolling scan-out lights the display's 100 rows top to bottom over the 33 ms refresh:
/// at a frame `s` after the refresh began, the rows it has reached show the new image and
/// the others the previous one, a refresh period older. So the frame's mean misregistration
/// is ω times the age of the new image plus the period times the share of rows not reached;
/// with a global scan-out every row is new.
#[test]
fn a_rolling_scanout_shows_the_rows_below_the_scan_line_one_refresh_older() {
    use seethru::analysis::physical::ARCMIN_PER_RAD;
    let omega = 20f64.to_radians();
    let period = 1.0 / 30.0;
    for (keys, rolling) in [("", false), ("scanout = \"rolling\"", true)] {
        let records = scanned_sequence(keys).records;
        assert_eq!(records.len(), 24);
        for r in &records {
            let m = r.metrics.unwrap();
            let since = (r.times.display - r.times.refresh_time).max(0.0);
            let reached = ((since / period * 100.0 + 1e-9).floor() + 1.0).min(100.0);
            let waiting = if rolling { 1.0 - reached / 100.0 } else { 0.0 };
            let age = r.times.display - r.times.capture + period * waiting;
            let predicted = omega * age * ARCMIN_PER_RAD;
            assert!(
                (m.mean_arcmin / predicted - 1.0).abs() < 0.03,
                "{keys:?} frame {}: {:.2}′ measured, ω × age {predicted:.2}′",
                r.frame,
                m.mean_arcmin
            );
            assert_eq!(m.coverage, 1.0, "{keys:?} frame {}", r.frame);
        }
    }
}

/// A display whose rows stay lit 5 ms after their scan: at each frame only the rows scanned
/// in the last 5 ms shine, the others are dark and counted as missing; with a global
/// scan-out the whole display shines for 5 ms after each refresh.
#[test]
fn a_short_persistence_lights_only_the_rows_scanned_within_it() {
    let period = 1.0 / 30.0;
    for (keys, rolling) in [
        ("scanout = \"rolling\"\npersistence_ms = 5.0", true),
        ("persistence_ms = 5.0", false),
    ] {
        let records = scanned_sequence(keys).records;
        for r in &records {
            let m = r.metrics.unwrap();
            let since = (r.times.display - r.times.refresh_time).max(0.0);
            // Rows lit: scanned at period k / 100 within (since − 5 ms, since], counting the
            // previous refresh's scan (its rows at k / 100 periods − one period).
            let lit = (0..100)
                .filter(|&k| {
                    let scanned = if rolling {
                        period * f64::from(k) / 100.0
                    } else {
                        0.0
                    };
                    let ago = if since >= scanned {
                        since - scanned
                    } else {
                        since - scanned + period
                    };
                    ago < 0.005
                })
                .count() as f64
                / 100.0;
            assert!(
                (m.coverage - lit).abs() < 0.03,
                "{keys:?} frame {}: coverage {:.3}, rows lit {lit:.3}",
                r.frame,
                m.coverage
            );
        }
        // A global flash lights all or nothing; a rolling one a band of 5 / 33 of the rows,
        // the first refresh too (the display ran before the sequence).
        let coverages: Vec<f64> = records
            .iter()
            .map(|r| r.metrics.unwrap().coverage)
            .collect();
        let (least, most) = coverages
            .iter()
            .fold((1.0f64, 0.0f64), |(l, m), &c| (l.min(c), m.max(c)));
        if rolling {
            assert!(least > 0.12 && most < 0.18, "{keys:?}: {coverages:?}");
        } else {
            assert!(least < 0.05 && most > 0.95, "{keys:?}: {coverages:?}");
        }
    }
}

/// A frame whose display is dark all over (between a global 5 ms flash's refreshes) has no
/// misregistration: the summary's means leave it out and count it, and its coverage (0)
/// counts in the mean coverage.
#[test]
fn a_dark_frame_is_left_out_of_the_means_and_counted() {
    use seethru::measure::sequence_files::summary;
    let run = scanned_sequence("persistence_ms = 5.0");
    let metrics: Vec<_> = run.records.iter().map(|r| r.metrics.unwrap()).collect();
    let dark: Vec<f64> = metrics
        .iter()
        .filter(|m| m.coverage == 0.0)
        .map(|m| m.mean_arcmin)
        .collect();
    assert!(
        dark.len() > 5 && dark.iter().all(|m| m.is_nan()),
        "{dark:?}"
    );
    let lit: Vec<f64> = metrics
        .iter()
        .map(|m| m.mean_arcmin)
        .filter(|m| !m.is_nan())
        .collect();
    let timeline = seethru::system::sequence::timeline::Timeline {
        duration: 3.0 / 30.0,
        fps: 240.0,
        display_hz: 30.0,
        latency_camera: 0.05,
        latency_tracking: 0.0,
    };
    let s = summary(&run, &timeline);
    let m = &s["misregistration_arcmin"];
    assert_eq!(m["frames_left_out"], dark.len());
    let mean = m["mean_of_frame_means"].as_f64().unwrap();
    let expected = lit.iter().sum::<f64>() / lit.len() as f64;
    assert!(
        (mean - expected).abs() < 1e-9 * expected,
        "{mean} {expected}"
    );
    let coverage = s["coverage"]["mean"].as_f64().unwrap();
    let all: f64 = metrics.iter().map(|m| m.coverage).sum::<f64>() / metrics.len() as f64;
    assert!((coverage - all).abs() < 1e-12, "{coverage} {all}");
}

/// A display scan-out the sequence cannot show is refused before any frame, in one line: a
/// rolling scan-out sampled more slowly than the display refreshes (it shows two refreshes
/// at once, the one before made), and the ideal display (which has no pixels to scan).
#[test]
fn a_scanout_the_sequence_cannot_show_is_refused() {
    let dir = tempfile::tempdir().unwrap();
    let das = std::fs::read_to_string(common::repo_path("scenes/das.toml")).unwrap();
    for (keys, flags, expected) in [
        (
            "scanout = \"rolling\"",
            &["--fps", "20", "--display-hz", "30"][..],
            "--fps (20) must be at least --display-hz (30)",
        ),
        (
            "persistence_ms = 4.0",
            &["--display", "ideal"],
            "not with --display ideal",
        ),
    ] {
        let text = das
            .replace("[obstacle]", &format!("[obstacle]\n{keys}"))
            .replace("../assets", &common::repo_path("assets").to_string_lossy());
        let scene = common::scene_file_in(dir.path(), "scanned.toml", &text);
        let out = dir.path().join("out");
        let mut args = vec![
            "sequence",
            scene.to_str().unwrap(),
            "--out",
            out.to_str().unwrap(),
            "--width",
            "32",
            "--duration",
            "0.2",
        ];
        args.extend(flags);
        let (ok, _, err) = common::seethru(&args);
        assert!(!ok, "{args:?}");
        assert_eq!(err.trim_end().lines().count(), 1, "{err}");
        assert!(
            err.starts_with("error:") && err.contains(expected),
            "{args:?}: {err}"
        );
        assert!(!out.exists());
    }
}

/// A frame in time is the same for any number of threads: das's ball rolling through a
/// rolling, exposed frontal camera (the band-by-band path, contexts made in order) rendered
/// on 1, 2 and 5 threads, bit for bit.
#[test]
fn a_frame_in_time_is_the_same_on_any_number_of_threads() {
    use seethru::render::in_time::render_in_time;
    let frames: Vec<Frame> = [1, 2, 5]
        .into_iter()
        .map(|threads| {
            let pool = rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .build()
                .unwrap();
            pool.install(|| {
                let mut system = turning_das(3, 96);
                let t = 0.3;
                let ctx = system.context_at(t).unwrap();
                let camera = ctx.scene.frontal;
                let pose_at = carried(&system, t);
                let job = RenderJob::new(&camera, FRONTAL)
                    .settings(settings(3))
                    .moving(&pose_at);
                let mut frame = Frame::new(camera.width, camera.height);
                render_in_time(&ctx, &mut |at| system.context_at(at), t, job, &mut frame).unwrap();
                frame
            })
        })
        .collect();
    assert!(frames[0].bit_identical(&frames[1]) && frames[0].bit_identical(&frames[2]));
}
