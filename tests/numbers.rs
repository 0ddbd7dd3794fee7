//! Tests that catch a wrong number (issue 28): each measured or tabulated number against an
//! independent computation — SSIM against Wang et al.'s formula written out here, the d2 → ∞
//! closed form and the error budget against rendered misregistration, the binocular map
//! against exact vergence for an off-axis eye, the tracking latency and the head jitter
//! against what their flags ask, the border bands side by side, the ratio's uncertainty
//! against pixel pitches computed here. Tolerances are relative, or the stated quantum.

mod common;

use glam::{DQuat, DVec2, DVec3};
use seethru::analysis::dynamic::{Motion, dynamic_misregistration, error_budget};
use seethru::analysis::examples::das_geometry;
use seethru::analysis::physical::{self, ARCMIN_PER_RAD};
use seethru::measure::binocular::binocular_map;
use seethru::measure::image_diff::{STANDARD_PPD, diff_layer};
use seethru::measure::image_metrics::Flip;
use seethru::measure::image_metrics::masked_ssim_map;
use seethru::measure::metrics::measure;
use seethru::measure::picture_layers::{Layer, LayerKind};
use seethru::measure::ratio::measure_ratio;
use seethru::measure::ratio_setup::{Compensation, Setup, build_scene};
use seethru::measure::sequence::{Measuring, run_sequence};
use seethru::render::frame::Frame;
use seethru::render::frame_over::FrameView;
use seethru::render::integrator::RenderContext;
use seethru::system::display::DisplayModel;
use seethru::system::eyes::{Eye, Eyes};
use seethru::system::options::{RunOptions, WorkingDistance};
use seethru::system::pipeline::{RunResult, eye_for_compensation, run};
use seethru::util::color::encode_srgb8;

/// f32's relative rounding (half an ulp): frames store positions, the maps angles, in f32.
const F32_ROUNDING: f64 = 1.0 / (1u64 << 24) as f64;

// ---------------------------------------------------------------------------------------------
// SSIM

/// SSIM at pixel `i` as Wang et al. (2004) define it, written independently of the metrics:
/// the product of the luminance, contrast and structure terms (their eq. 6) with C3 = C2/2,
/// K1 = 0.01, K2 = 0.03, L = 255, over the 7×7 window's pixels inside `mask` (uniform
/// weights, the project's documented window), with two-pass centred moments.
fn wang_ssim(a: &[f64], b: &[f64], mask: &[bool], w: usize, h: usize, i: usize) -> f64 {
    let (x, y) = (i % w, i / w);
    let window: Vec<usize> = (y.saturating_sub(3)..(y + 4).min(h))
        .flat_map(|yy| (x.saturating_sub(3)..(x + 4).min(w)).map(move |xx| yy * w + xx))
        .filter(|&j| mask[j])
        .collect();
    let n = window.len() as f64;
    let mean = |v: &[f64]| window.iter().map(|&j| v[j]).sum::<f64>() / n;
    let (ma, mb) = (mean(a), mean(b));
    let moment = |u: &[f64], mu: f64, v: &[f64], mv: f64| {
        window
            .iter()
            .map(|&j| (u[j] - mu) * (v[j] - mv))
            .sum::<f64>()
            / n
    };
    let (va, vb, cov) = (
        moment(a, ma, a, ma),
        moment(b, mb, b, mb),
        moment(a, ma, b, mb),
    );
    let (sa, sb) = (va.sqrt(), vb.sqrt());
    let (c1, c2) = ((0.01f64 * 255.0).powi(2), (0.03f64 * 255.0).powi(2));
    let c3 = c2 / 2.0;
    let luminance = (2.0 * ma * mb + c1) / (ma * ma + mb * mb + c1);
    let contrast = (2.0 * sa * sb + c2) / (va + vb + c2);
    let structure = (cov + c3) / (sa * sb + c3);
    luminance * contrast * structure
}

/// A textured luminance image, 8-bit range: two gratings and a hash speckle, sampled at
/// (x + dx, y + dy) so that shifted copies are the same texture moved.
fn texture(w: usize, h: usize, dx: i64, dy: i64, gain: f64, offset: f64) -> Vec<f64> {
    (0..w * h)
        .map(|i| {
            let (x, y) = ((i % w) as i64 + dx, (i / w) as i64 + dy);
            let (fx, fy) = (x as f64, y as f64);
            let speckle = ((x.wrapping_mul(73_856_093) ^ y.wrapping_mul(19_349_663)).rem_euclid(41))
                as f64
                - 20.0;
            let v = 120.0
                + 55.0 * (0.7 * fx + 0.3 * fy).sin()
                + 35.0 * (0.45 * fy - 0.2 * fx).cos()
                + speckle;
            (gain * v + offset).clamp(0.0, 255.0).round()
        })
        .collect()
}

#[test]
fn ssim_equals_wang_et_al_on_textured_shifted_pairs() {
    let (w, h) = (48usize, 36usize);
    let a = texture(w, h, 0, 0, 1.0, 0.0);
    let everywhere = vec![true; w * h];
    // An irregular mask: a disc with a notch, so windows are cut at its edge.
    let disc: Vec<bool> = (0..w * h)
        .map(|i| {
            let (x, y) = ((i % w) as f64 - 20.0, (i / w) as f64 - 17.0);
            x * x + y * y < 15.0f64.powi(2) && !(x > 4.0 && y.abs() < 3.0)
        })
        .collect();
    let c2 = (0.03f64 * 255.0).powi(2);
    for (dx, dy, gain, offset) in [(1, 0, 1.0, 0.0), (2, 1, 0.8, 20.0), (0, 3, 1.1, -15.0)] {
        let b = texture(w, h, dx, dy, gain, offset);
        for mask in [&everywhere, &disc] {
            let map = masked_ssim_map(&a, &b, mask, w, h);
            let (mut sum, mut halved, mut n) = (0.0, 0.0, 0.0);
            for i in 0..w * h {
                if !mask[i] {
                    assert!(map[i].is_nan(), "pixel {i} outside the mask has a score");
                    continue;
                }
                let expected = wang_ssim(&a, &b, mask, w, h, i);
                // The one-pass moments of the metrics lose at most a few ulps of 255² per
                // window against these centred ones; over (σ² + C2) ≥ C2 that is < 1e-12.
                assert!(
                    (map[i] - expected).abs() < 1e-9,
                    "shift ({dx}, {dy}), pixel {i}: {} vs {expected}",
                    map[i]
                );
                sum += expected;
                n += 1.0;
                // What halving 2·cov in the structure term would give here: the window's
                // covariance from the score itself (SSIM is linear in 2 cov + C2).
                let factor = |cov: f64| (cov + c2) / (2.0 * cov + c2);
                let cov = covariance_at(&a, &b, mask, w, h, i);
                halved += expected * factor(cov);
            }
            // Textured and shifted: well away from 1, and the structure term weighs: halving
            // it moves the mean a million times the tolerance above.
            let (mean, mean_halved) = (sum / n, halved / n);
            assert!(mean > 0.05 && mean < 0.9, "shift ({dx}, {dy}): SSIM {mean}");
            assert!(
                (mean - mean_halved).abs() > 1e6 * 1e-9,
                "halving the structure term moves SSIM by only {}",
                mean - mean_halved
            );
        }
        // `seethru diff`'s SSIM: the mean of the same map over the whole 8-bit image.
        let layer = |v: &[f64]| Layer {
            name: "colour".into(),
            kind: LayerKind::Srgb8,
            channels: ["R", "G", "B"].map(String::from).to_vec(),
            values: vec![v.to_vec(), v.to_vec(), v.to_vec()],
        };
        let d = diff_layer(
            &layer(&a),
            &layer(&b),
            w as u32,
            h as u32,
            (STANDARD_PPD, "test".into()),
        )
        .unwrap();
        let expected = (0..w * h)
            .map(|i| wang_ssim(&a, &b, &everywhere, w, h, i))
            .sum::<f64>()
            / (w * h) as f64;
        let got = d.metric("ssim").unwrap();
        assert!((got - expected).abs() < 1e-9, "diff: {got} vs {expected}");
    }
}

/// The covariance of the 7×7 window at `i` inside `mask`.
fn covariance_at(a: &[f64], b: &[f64], mask: &[bool], w: usize, h: usize, i: usize) -> f64 {
    let (x, y) = (i % w, i / w);
    let window: Vec<usize> = (y.saturating_sub(3)..(y + 4).min(h))
        .flat_map(|yy| (x.saturating_sub(3)..(x + 4).min(w)).map(move |xx| yy * w + xx))
        .filter(|&j| mask[j])
        .collect();
    let n = window.len() as f64;
    let ma = window.iter().map(|&j| a[j]).sum::<f64>() / n;
    let mb = window.iter().map(|&j| b[j]).sum::<f64>() / n;
    window
        .iter()
        .map(|&j| (a[j] - ma) * (b[j] - mb))
        .sum::<f64>()
        / n
}

/// The metrics of a run's own frames, as `run` computes them (border band 5 display pixels).
fn measured(
    ctx: &RenderContext,
    r: &RunResult,
) -> (seethru::measure::metrics::MetricMaps, serde_json::Value) {
    let (maps, metrics) = measure(ctx, &ctx.scene, ctx.scene.eye(), r.measured_views(), 5);
    (maps, metrics.to_json())
}

/// A run of the textured wall at 12 m, the driver's camera at 120×90 looking as `look_at`
/// (a line of the scene file) and the model plane at 6 m: seethru is the truth shifted, by an
/// amount that grows across the display.
fn wall_run_with_the_model_plane_short(look_at: &str) -> (RenderContext, RunResult) {
    let text = common::WallScene {
        wall: 12.0,
        eye: [0.0, 0.0, 0.7],
        driver_resolution: [120, 90],
        ..common::WallScene::default()
    }
    .text()
    .replace("look_at = [0.0, 0.0, -6.0]", look_at);
    let scene = common::parse_in(&common::repo_path("scenes"), "wall.toml", &text).unwrap();
    let ctx = RenderContext::new(scene).unwrap();
    let options = RunOptions {
        d2: WorkingDistance::Metres(6.0),
        spp: 1,
        ..RunOptions::default()
    };
    let r = run(&ctx, &options).unwrap();
    (ctx, r)
}

#[test]
fn the_display_ssim_of_a_run_equals_wang_et_al_over_the_display() {
    // The textured wall at 12 m with the model plane at 6 m: seethru is the truth shifted,
    // by an amount that grows across the display.
    let (ctx, r) = wall_run_with_the_model_plane_short("look_at = [0.0, 0.0, -6.0]");
    let (maps, json) = measured(&ctx, &r);
    let (w, h) = (maps.width as usize, maps.height as usize);
    let lum = |f: &Frame| -> Vec<f64> {
        f.color
            .iter()
            .map(|&c| {
                let [r, g, b] = encode_srgb8(c).map(f64::from);
                0.2126 * r + 0.7152 * g + 0.0722 * b
            })
            .collect()
    };
    let (t, s) = (lum(&r.truth), lum(&r.seethru));
    let display: Vec<usize> = (0..w * h).filter(|&i| maps.display[i]).collect();
    let expected = display
        .iter()
        .map(|&i| wang_ssim(&t, &s, &maps.display, w, h, i))
        .sum::<f64>()
        / display.len() as f64;
    let got = json["display"]["ssim"].as_f64().unwrap();
    assert!((got - expected).abs() < 1e-9, "{got} vs {expected}");
    assert!(
        expected < 0.9,
        "the shifted wall should not look alike: {expected}"
    );
}

#[test]
fn the_display_flip_of_a_run_is_nv_flip_of_the_display_on_grey() {
    // FLIP as the metrics' notes define it, computed here: both images cut to the display's
    // bounding box, every pixel outside the display the same grey 128, NVIDIA's FLIP at the
    // driver camera's pixels per degree; each display pixel's value and the display's mean.
    // The driver camera turned off the display's axis: the display is a trapezoid whose
    // bounding box holds pixels outside it.
    let (ctx, r) = wall_run_with_the_model_plane_short("look_at = [0.6, 0.4, -6.0]");
    let (maps, json) = measured(&ctx, &r);
    let (w, h) = (maps.width as usize, maps.height as usize);
    let display: Vec<usize> = (0..w * h).filter(|&i| maps.display[i]).collect();
    let (xs, ys) = (
        display.iter().map(|&i| i % w),
        display.iter().map(|&i| i / w),
    );
    let (x0, x1) = (xs.clone().min().unwrap(), xs.max().unwrap() + 1);
    let (y0, y1) = (ys.clone().min().unwrap(), ys.max().unwrap() + 1);
    // A box away from every edge of the frame, not square, and a display that does not fill
    // it: an offset, a stride or a mask read at the wrong pixel changes what FLIP sees.
    assert!(
        x0 > 0 && y0 > 0 && x1 < w && y1 < h,
        "box {x0}..{x1} × {y0}..{y1}"
    );
    assert_ne!(x1 - x0, y1 - y0);
    assert!(display.len() < (x1 - x0) * (y1 - y0));
    let cut = |f: &Frame| -> Vec<u8> {
        let mut out = Vec::new();
        for y in y0..y1 {
            for x in x0..x1 {
                let i = y * w + x;
                out.extend(if maps.display[i] {
                    encode_srgb8(f.color[i])
                } else {
                    [128; 3]
                });
            }
        }
        out
    };
    let (bw, bh) = ((x1 - x0) as u32, (y1 - y0) as u32);
    let fov_deg = 2.0 * ctx.scene.driver.tan_half_x().atan().to_degrees();
    let flip = nv_flip::flip(
        nv_flip::FlipImageRgb8::with_data(bw, bh, &cut(&r.truth)),
        nv_flip::FlipImageRgb8::with_data(bw, bh, &cut(&r.seethru)),
        (w as f64 / fov_deg) as f32,
    )
    .to_vec();
    for y in 0..h {
        for x in 0..w {
            let i = y * w + x;
            let got = maps.flip[i];
            if maps.display[i] {
                let expected = flip[(y - y0) * (x1 - x0) + x - x0] as f64;
                assert!(
                    (got - expected).abs() <= 1e-6 * expected.max(1e-3),
                    "({x},{y}): {got} vs {expected}"
                );
            } else {
                assert!(got.is_nan(), "({x},{y}) is outside the display: {got}");
            }
        }
    }
    let mean = display
        .iter()
        .map(|&i| flip[(i / w - y0) * (x1 - x0) + i % w - x0] as f64)
        .sum::<f64>()
        / display.len() as f64;
    let got = json["display"]["flip_mean"].as_f64().unwrap();
    assert!((got - mean).abs() <= 1e-9 * mean, "{got} vs {mean}");
    assert!(mean > 0.01, "the shifted wall should differ: {mean}");
}

// ---------------------------------------------------------------------------------------------
// The d2 → ∞ closed form and the error budget, rendered

/// The wall scene with the budget's display (half width `half_width`), the eye on the
/// display's axis `d1` in front of it, the wall `depth` behind (or none: sky only).
fn budget_wall(d1: f64, depth: Option<f64>, half_width: f64) -> RenderContext {
    let setup = common::WallScene {
        wall: depth.unwrap_or(6.0),
        eye: [0.0, 0.0, d1],
        driver_resolution: [160, 120],
        ..common::WallScene::default()
    };
    let mut text = setup
        .text()
        .replace("width = 0.3\n", &format!("width = {}\n", 2.0 * half_width));
    if depth.is_none() {
        // The wall far below every view: each pixel sees the sky.
        text = text.replace(
            "translate = [0.0, 0.0, -6]",
            "translate = [0.0, -5000.0, -6]",
        );
        assert!(text.contains("-5000"));
    }
    let scene = common::parse_in(&common::repo_path("scenes"), "wall.toml", &text).unwrap();
    assert!((scene.obstacle.width - 2.0 * half_width).abs() < 1e-12);
    RenderContext::new(scene).unwrap()
}

/// A run on `ctx` with the ideal display (no resampling quantum).
fn ideal_run(ctx: &RenderContext, d2: WorkingDistance, head_bias_cm: [f64; 3]) -> RunResult {
    run(
        ctx,
        &RunOptions {
            d2,
            spp: 1,
            display: DisplayModel::Ideal,
            head_bias_cm,
            ..RunOptions::default()
        },
    )
    .unwrap()
}

/// The angle at the eye of a straight chord in a plane at depth D in front of it (the plane
/// parallel to the display), as factors (lo, hi) of chord/D. An element dp of the chord seen
/// at β off the normal lies D/cos β away and makes at least 90° − β with the line of sight,
/// so it subtends between cos²β dp/D and cos β dp/D ≤ dp/D; along a straight chord β is at
/// most the larger of its ends' (`ends`: eye to each end). No tolerance of its own.
fn chord_bracket(ends: [DVec3; 2]) -> (f64, f64) {
    let beta = ends
        .iter()
        .map(|v| v.truncate().length().atan2(-v.z))
        .fold(0.0, f64::max);
    (beta.cos().powi(2), 1.0)
}

/// Every display pixel of a run: its display point and the misregistration there.
fn display_pixels(ctx: &RenderContext, r: &RunResult) -> Vec<(DVec3, f64)> {
    let (maps, json) = measured(ctx, r);
    assert_eq!(json["blank_pixels"], 0);
    let to_obstacle = ctx.scene.obstacle.world_from_obstacle.inverse();
    (0..maps.display.len())
        .filter(|&i| maps.display[i])
        .map(|i| {
            (
                to_obstacle.transform_point3(r.occluded.position[i].as_dvec3()),
                maps.misregistration[i] as f64,
            )
        })
        .collect()
}

#[test]
fn the_infinite_plane_error_and_the_budget_equal_rendered_misregistration() {
    let g = das_geometry();
    let budget = error_budget(&g);
    let (d1, depth, hw) = (g.d1, g.scene_depth, g.half_width);
    let eye = DVec3::new(0.0, 0.0, d1);
    let total = d1 + depth;
    // f32 positions: the shown and true points, ~D away, each rounded by 2^-24 of their
    // coordinates, move the angle by about 2·√3·2^-24 rad; a few times that.
    let float_arcmin = 8.0 * F32_ROUNDING * ARCMIN_PER_RAD;
    let check = |what: &str, got: f64, closed: f64, (lo, hi): (f64, f64)| {
        assert!(
            got >= closed * lo - float_arcmin && got <= closed * hi + float_arcmin,
            "{what}: rendered {got}′ outside [{}, {}]′ (closed form {closed}′)",
            closed * lo,
            closed * hi
        );
    };

    // d2 → ∞ with the wall at the budget's depth: the display point p shows the point the
    // camera (at the display centre) sees along the eye's ray, S = (p − e) depth/d1; the
    // truth is T = e + (p − e)(d1 + depth)/d1; T − S = p, a lateral chord at depth D.
    let ctx = budget_wall(d1, Some(depth), hw);
    let r = ideal_run(&ctx, WorkingDistance::Infinity, [0.0; 3]);
    let pixels = display_pixels(&ctx, &r);
    let mut edge = 0;
    for &(p, got) in &pixels {
        let x = p.truncate().length();
        let truth = p - eye; // the ray's direction; its ends at depth D scale alike
        let t_end = truth * (total / d1);
        let s_end = t_end - DVec3::new(p.x, p.y, 0.0);
        let (lo, hi) = chord_bracket([t_end, s_end]);
        // atan(x/D) lies within (x/D)²/3 below x/D.
        let atan_slack = 1.0 / (1.0 - (x / total).powi(2) / 3.0);
        let closed = physical::infinite_plane_error(x, d1, depth) * ARCMIN_PER_RAD;
        check("d2 → ∞", got, closed, (lo, hi * atan_slack));
        // The budget's number is this closed form at the display's edge: scaled to the pixel.
        if x > 0.9 * hw {
            // Linear in x but for the atan: within (hw/D)²/3 of it.
            let scaled = budget.static_planar_arcmin * x / hw;
            let edge_slack = 1.0 / (1.0 - (hw / total).powi(2) / 3.0);
            check(
                "budget: static planar error",
                got,
                scaled,
                (lo, hi * edge_slack),
            );
            edge += 1;
        }
    }
    assert!(pixels.len() > 1000 && edge > 50, "{} {edge}", pixels.len());

    // 1 m of d2 error: the model plane h beyond the wall; the shown point is off by the
    // chord p (depth − d2')/d2' at depth D, i.e. |p| h / d2' — per metre, the closed form
    // x / (depth D) times depth/d2'.
    let h = 0.5;
    let model = depth + h;
    let r = ideal_run(&ctx, WorkingDistance::Metres(model), [0.0; 3]);
    let mut checked = 0;
    for &(p, got) in &display_pixels(&ctx, &r) {
        let x = p.truncate().length();
        if x < 0.2 * hw {
            continue; // a few float roundings of a tiny angle
        }
        let t_end = (p - eye) * (total / d1);
        let s_end = t_end - DVec3::new(p.x, p.y, 0.0) * (h / model);
        let (lo, hi) = chord_bracket([t_end, s_end]);
        let closed = physical::per_d2_error(x, d1, depth) * h * depth / model * ARCMIN_PER_RAD;
        check("d2 error", got, closed, (lo, hi));
        if x > 0.9 * hw {
            let scaled = budget.arcmin_per_m_d2 * x / hw * h * depth / model;
            check("budget: d2 error", got, scaled, (lo, hi));
        }
        checked += 1;
    }
    assert!(checked > 1000, "{checked}");

    // 1 cm of lateral head error, d2 → ∞, a scene at infinity (sky): the display point
    // shows the direction p − (e + δ) where the truth has p − e — the chord δ at distance d1.
    let sky = budget_wall(d1, None, hw);
    let delta = 0.01;
    let r = ideal_run(&sky, WorkingDistance::Infinity, [100.0 * delta, 0.0, 0.0]);
    let (_, json) = measured(&sky, &r);
    assert_eq!(
        json["sky_pixels_included"]["both"], json["display_pixels"],
        "every pixel sees the sky"
    );
    for &(p, got) in &display_pixels(&sky, &r) {
        let bracket = chord_bracket([p - eye, p - eye - DVec3::X * delta]);
        let closed = physical::per_lateral_head_error(d1, f64::INFINITY) * delta * ARCMIN_PER_RAD;
        check("head error", got, closed, bracket);
        let budgeted = budget.arcmin_per_mm_head * delta * 1e3;
        check("budget: head error", got, budgeted, bracket);
    }

    // The latency rows are the dynamic formula (tests/sequence.rs renders it) at 1 ms.
    let per_ms = |speed: f64, yaw_rate: f64| {
        let motion = Motion {
            speed,
            yaw_rate,
            eye_speed: 0.0,
            latency: 1e-3,
            tracking_latency: 0.0,
        };
        dynamic_misregistration(g.scene_distance(), g.bearing, d1, f64::INFINITY, &motion).abs()
            * ARCMIN_PER_RAD
    };
    let relative = |a: f64, b: f64| (a - b).abs() <= 1e-12 * b.abs();
    assert!(relative(
        budget.arcmin_per_ms_at_50_kmh,
        per_ms(50.0 / 3.6, 0.0)
    ));
    assert!(relative(
        budget.arcmin_per_ms_at_20_deg_s,
        per_ms(0.0, 20f64.to_radians())
    ));
}

/// The number in the last column of the guide's budget row starting `row`, and its
/// rounding quantum (half a unit of its last printed digit).
fn table_value(page: &str, row: &str) -> (f64, f64) {
    let line = page
        .lines()
        .find(|l| l.starts_with(&format!("| {row}")))
        .unwrap_or_else(|| panic!("no row `{row}`"));
    let cell = line
        .trim_end_matches('|')
        .rsplit('|')
        .next()
        .unwrap()
        .trim();
    let decimals = cell.split_once('.').map_or(0, |(_, d)| d.len());
    (cell.parse().unwrap(), 0.5 * 10f64.powi(-(decimals as i32)))
}

#[test]
fn the_guides_budget_table_is_the_budget() {
    let page = std::fs::read_to_string(common::repo_path("docs/guide/sequences.md")).unwrap();
    let b = error_budget(&das_geometry());
    for (row, value) in [
        ("1 mm of lateral head error", b.arcmin_per_mm_head),
        ("1 ms of latency at 50 km/h", b.arcmin_per_ms_at_50_kmh),
        ("1 ms of latency at 20 °/s", b.arcmin_per_ms_at_20_deg_s),
        ("1 m of d2 error", b.arcmin_per_m_d2),
        ("static planar error", b.static_planar_arcmin),
    ] {
        let (printed, quantum) = table_value(&page, row);
        assert!(
            (printed - value).abs() <= quantum,
            "`{row}`: the guide prints {printed}, the budget is {value}"
        );
    }
    // The break-even latencies in the text below the table.
    let after = |marker: &str| -> (f64, f64) {
        let rest = &page[page.find(marker).unwrap_or_else(|| panic!("{marker}")) + marker.len()..];
        let number: String = rest
            .chars()
            .take_while(|c| c.is_ascii_digit() || *c == '.')
            .collect();
        let decimals = number.split_once('.').map_or(0, |(_, d)| d.len());
        (
            number.parse().unwrap(),
            0.5 * 10f64.powi(-(decimals as i32)),
        )
    };
    for (marker, value) in [
        (
            "whole static planar error after **",
            b.break_even_ms_at_50_kmh,
        ),
        (
            "ms of latency at\n50 km/h** and ",
            b.break_even_ms_at_20_deg_s,
        ),
    ] {
        let (printed, quantum) = after(marker);
        assert!(
            (printed - value).abs() <= quantum,
            "after `{marker}`: {printed} vs {value}"
        );
    }
    // `seethru analyze` prints the same budget.
    let (ok, out, err) = common::seethru(&["analyze"]);
    assert!(ok, "{err}");
    for value in [
        format!(
            "| 1 mm of lateral head error | {:.2} |",
            b.arcmin_per_mm_head
        ),
        format!(
            "| static planar error (d2 → ∞, display edge) | {:.1} |",
            b.static_planar_arcmin
        ),
    ] {
        assert!(out.contains(&value), "analyze lacks `{value}`");
    }
}

// ---------------------------------------------------------------------------------------------
// The binocular map

/// Vergence at `p`: the angle between the directions to the two eyes, radians.
fn vergence_at(left: DVec3, right: DVec3, p: DVec3) -> f64 {
    let (a, b) = (left - p, right - p);
    a.cross(b).length().atan2(a.dot(b))
}

#[test]
fn the_binocular_map_is_the_exact_vergence_for_an_off_axis_eye_at_every_pixel() {
    // The cyclopean eye 10 cm right of and 5 cm above the display's axis: the display's
    // vergence differs from its left to its right and top to bottom edge, so a flipped map
    // cannot pass. The model plane on the wall: each display pixel shows its model point.
    let (d1, d2, ipd) = (0.8, 6.0, 0.064);
    let ctx = common::WallScene {
        wall: d2,
        eye: [0.1, 0.05, d1],
        display_resolution: [60, 40],
        ..Default::default()
    }
    .context();
    let eyes = Eyes {
        view: Eye::Left,
        target: Eye::Cyclopean,
        ipd,
    };
    let r = run(
        &ctx,
        &RunOptions {
            d2: WorkingDistance::Metres(d2),
            spp: 1,
            eyes,
            ..RunOptions::default()
        },
    )
    .unwrap();
    let scene = &ctx.scene;
    let (l, rr) = (
        eyes.position(&scene.driver, Eye::Left),
        eyes.position(&scene.driver, Eye::Right),
    );
    let o = &scene.obstacle;
    let cyclopean = o.in_obstacle_frame((l + rr) / 2.0);
    let map = binocular_map(&r.display, o, l, rr);
    let [dw, dh] = o.display_resolution;
    assert_eq!((map.width, map.height), (dw, dh));
    // The frame's scene point is the frontal pixel's, not the model point: off by at most
    // half a frontal pixel's diagonal on the wall (footprint d2·2tanθ_F/W, larger by
    // 1/cos² off the axis); vergence, ≈ ipd/ρ, changes by at most ipd·δ/ρ² for a shift δ.
    let frontal = &scene.frontal;
    let tan_px = 2.0 * frontal.tan_half_x() / frontal.width as f64;
    let corner_tan = (frontal.tan_half_x().powi(2) + frontal.tan_half_y().powi(2)).sqrt();
    let shift = 0.5 * std::f64::consts::SQRT_2 * tan_px * d2 * (1.0 + corner_tan.powi(2));
    let near = d1 + d2;
    let tolerance = (ipd * shift / (near * near)
        + 4.0 * F32_ROUNDING * vergence_at(l, rr, o.world_from_obstacle.translation))
        * ARCMIN_PER_RAD;
    let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
    for y in 0..dh {
        for x in 0..dw {
            let i = (y * dw + x) as usize;
            // The centre of display pixel (x, y): x to the right, y down, in the obstacle frame.
            let local = DVec3::new(
                ((x as f64 + 0.5) / dw as f64 - 0.5) * o.width,
                (0.5 - (y as f64 + 0.5) / dh as f64) * o.height,
                0.0,
            );
            let on_display = o.world_from_obstacle.transform_point3(local);
            let model = cyclopean + (local - cyclopean) * (cyclopean.z + d2) / cyclopean.z;
            let shown = o.world_from_obstacle.transform_point3(model);
            let frame_point = r.display.position[i].as_dvec3();
            assert!(
                (frame_point - shown).length() <= shift * 1.001,
                "pixel ({x}, {y}) shows {frame_point}, the model point is {shown}"
            );
            let expected =
                (vergence_at(l, rr, on_display) - vergence_at(l, rr, shown)) * ARCMIN_PER_RAD;
            let got = map.mismatch_arcmin[i] as f64;
            assert!(
                (got - expected).abs() <= tolerance,
                "pixel ({x}, {y}): {got}′ vs {expected}′ (± {tolerance}′)"
            );
            lo = lo.min(expected);
            hi = hi.max(expected);
        }
    }
    // The map varies across the display by far more than the tolerance.
    assert!(hi - lo > 100.0 * tolerance, "{lo}..{hi} ± {tolerance}");
}

// ---------------------------------------------------------------------------------------------
// --latency-tracking and --head-jitter-cm

/// `frames.csv` of a sequence folder as rows of named values.
fn frames_csv(dir: &std::path::Path) -> Vec<std::collections::HashMap<String, f64>> {
    let mut reader = csv::Reader::from_path(dir.join("frames.csv")).unwrap();
    let header: Vec<String> = reader.headers().unwrap().iter().map(String::from).collect();
    reader
        .records()
        .map(|r| {
            let r = r.unwrap();
            header
                .iter()
                .cloned()
                .zip(r.iter().map(|v| v.parse::<f64>().unwrap_or(f64::NAN)))
                .collect()
        })
        .collect()
}

#[test]
fn the_tracking_latency_costs_what_the_dynamic_formula_says() {
    // A swaying head, the wall on the model plane, an ideal display: the only error is the
    // head's motion over the estimate's age, capture latency plus tracking latency. Each
    // frame where the sway is fast reads the formula `u (L + L_t) d2 / (d1 (d1 + d2))`, within
    // the band tests/sequence.rs justifies for camera latency (first order, paraxial).
    let dir = tempfile::tempdir().unwrap();
    let setup = common::WallScene::default();
    let scene = setup.file_in(dir.path());
    let out = dir.path().join("seq");
    let (amplitude, frequency, latency, tracking) = (0.03, 0.5, 0.02, 0.03);
    let (ok, _, err) = common::seethru(&[
        "sequence",
        scene.to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
        "--head",
        "sway",
        "--sway-cm",
        "3",
        "--sway-hz",
        "0.5",
        "--latency-camera",
        "20",
        "--latency-tracking",
        "30",
        "--display",
        "ideal",
        "--d2",
        "6",
        "--duration",
        "2",
        "--fps",
        "10",
        "--width",
        "100",
    ]);
    assert!(ok, "{err}");
    let rows = frames_csv(&out.join("latency_20ms"));
    let eye0 = DVec3::from_array(setup.eye);
    let mut checked = 0;
    for row in &rows {
        let t = row["t_s"];
        let phase = std::f64::consts::TAU * frequency * t;
        if phase.cos().abs() < 0.8 {
            continue; // near the turning points the first-order formula is not the point
        }
        // The eye's speed over the estimate's age (50 ms: the speed at display time alone
        // would be off by up to 10 % where the sway turns).
        let age = latency + tracking;
        let eye_speed = amplitude
            * ((std::f64::consts::TAU * frequency * t).sin()
                - (std::f64::consts::TAU * frequency * (t - age)).sin())
            / age;
        let motion = Motion {
            speed: 0.0,
            yaw_rate: 0.0,
            eye_speed,
            latency,
            tracking_latency: tracking,
        };
        let predicted =
            dynamic_misregistration(6.0 - eye0.z, 0.0, row["eye_true_z_m"], 6.0, &motion).abs()
                * ARCMIN_PER_RAD;
        let measured = row["misregistration_mean_arcmin"];
        assert!(
            measured < predicted * 1.02 && measured > predicted * 0.92,
            "t = {t}: measured {measured:.2}′, formula {predicted:.2}′"
        );
        checked += 1;
    }
    assert!(checked >= 6, "{checked}");
    for row in &rows {
        let t = row["t_s"];
        // The estimate is of the head at capture − L_t = t − L − L_t (oracle head, no
        // prediction, a display as fast as the frames).
        let sampled = eye0.x
            + amplitude * (std::f64::consts::TAU * frequency * (t - latency - tracking)).sin();
        assert!(
            (row["eye_used_x_m"] - sampled).abs() < 1e-9,
            "t = {t}: the compensation's eye {} is not the head of {} s ({sampled})",
            row["eye_used_x_m"],
            t - latency - tracking
        );
    }
}

/// The sample standard deviation of each of the three components of `errors`.
fn spreads(errors: &[DVec3]) -> [f64; 3] {
    let n = errors.len() as f64;
    [0, 1, 2].map(|k| {
        let v: Vec<f64> = errors.iter().map(|e| e.to_array()[k]).collect();
        let mean = v.iter().sum::<f64>() / n;
        (v.iter().map(|x| (x - mean).powi(2)).sum::<f64>() / (n - 1.0)).sqrt()
    })
}

/// Each component's spread is σ within five standard errors of a Gaussian sample's standard
/// deviation (σ/√(2(n − 1))), and its mean zero within five of the mean's (σ/√n).
fn assert_spread(what: &str, errors: &[DVec3], sigma: f64) {
    let n = errors.len() as f64;
    let se = 1.0 / (2.0 * (n - 1.0)).sqrt();
    for (k, s) in spreads(errors).into_iter().enumerate() {
        assert!(
            (s / sigma - 1.0).abs() < 5.0 * se,
            "{what}, component {k}: spread {s} m for --head-jitter-cm {} (n = {n})",
            sigma * 100.0
        );
        let mean = errors.iter().map(|e| e.to_array()[k]).sum::<f64>() / n;
        assert!(mean.abs() < 5.0 * sigma / n.sqrt(), "{what}: mean {mean}");
    }
}

#[test]
fn the_head_jitter_has_the_spread_its_flag_states() {
    let sigma_cm = 0.8;
    let ctx = common::WallScene::default().context();
    let scene = &ctx.scene;
    let eye = scene.obstacle.in_obstacle_frame(scene.eye());
    // `run`: one draw per seed.
    let back = Frame::new(1, 1);
    let errors: Vec<DVec3> = (0..400)
        .map(|seed| {
            let options = RunOptions {
                head_jitter_cm: sigma_cm,
                seed,
                ..RunOptions::default()
            };
            let (used, _) = eye_for_compensation(scene, &back, &options).unwrap();
            scene.obstacle.in_obstacle_frame(used) - eye
        })
        .collect();
    assert_spread("run", &errors, sigma_cm / 100.0);
    // `sequence`: one draw per display refresh.
    let small = common::WallScene {
        driver_resolution: [32, 24],
        display_resolution: [30, 20],
        frontal_resolution: [64, 48],
        ..common::WallScene::default()
    };
    let scene = small.scene();
    let run = RunOptions {
        head_jitter_cm: sigma_cm,
        spp: 1,
        ..RunOptions::default()
    };
    let options = common::still_sequence(run, 1.5, 100.0, 0.0);
    let how = Measuring {
        metrics: false,
        full_frames: false,
        band: 5,
        progress: false,
        flip: Flip::Skipped,
    };
    let run = run_sequence(&scene, options, how, &mut |_| Ok(())).unwrap();
    let errors: Vec<DVec3> = run
        .records
        .iter()
        .map(|r| r.eye_estimated - r.eye_true)
        .collect();
    assert_eq!(errors.len(), 150);
    assert_spread("sequence", &errors, sigma_cm / 100.0);
}

// ---------------------------------------------------------------------------------------------
// Border bands

#[test]
fn each_border_band_reads_its_own_side() {
    // A seethru frame that shows the truth turned by 10′ on one half of the display only:
    // the band of that side reads 10′, the opposite band 0′. Swapping the sides fails.
    let ctx = common::WallScene {
        eye: [0.0, 0.0, 0.7],
        ..common::WallScene::default()
    }
    .context();
    let r = run(
        &ctx,
        &RunOptions {
            d2: WorkingDistance::Metres(6.0),
            spp: 1,
            ..RunOptions::default()
        },
    )
    .unwrap();
    let eye = ctx.scene.eye();
    let o = &ctx.scene.obstacle;
    let turn = 10.0;
    let w = r.truth.width as usize;
    for (turned_side, opposite, axis) in [("left", "right", 0), ("top", "bottom", 1)] {
        let mut shown = Frame::clone(&r.truth);
        let mut columns = Vec::new();
        for (i, p) in shown.position.iter_mut().enumerate() {
            let on_display = o.in_obstacle_frame(r.occluded.position[i].as_dvec3());
            let side = on_display.to_array()[axis];
            // Left: x < 0 on the display, seen from the driver; top: y > 0.
            let turned = if axis == 0 { side < 0.0 } else { side > 0.0 };
            if !turned || !p.is_finite() {
                continue;
            }
            let v = p.as_dvec3() - eye;
            let about = v.cross(DVec3::new(0.3, 1.0, 0.2)).normalize();
            *p = (eye + DQuat::from_axis_angle(about, (turn / 60.0f64).to_radians()) * v).as_vec3();
            columns.push(i % w);
        }
        let (maps, json) = measure(
            &ctx,
            &ctx.scene,
            eye,
            [
                FrameView::Whole(&r.truth),
                FrameView::Whole(&shown),
                FrameView::Over(&r.occluded),
            ],
            5,
        );
        assert!(maps.display.iter().filter(|&&d| d).count() > 1000);
        let json = json.to_json();
        let band = |side: &str| json["border_per_side"][side]["misregistration_arcmin"].clone();
        let (on, off) = (band(turned_side), band(opposite));
        assert!(on["count"].as_u64().unwrap() > 50, "{on}");
        assert!(
            (on["mean"].as_f64().unwrap() - turn).abs() < 0.01,
            "{turned_side}: {on}"
        );
        assert!(
            off["max"].as_f64().unwrap() < 0.01 * turn,
            "{opposite}: {off}"
        );
        if axis == 0 {
            // The driver's left is the image's left.
            assert!(
                columns.iter().all(|&c| c < w / 2),
                "left half in image columns"
            );
        }
    }
}

// ---------------------------------------------------------------------------------------------
// θ_F drops out (erratum 7), rendered

#[test]
fn the_claim_that_theta_f_drops_out_is_two_renders() {
    use seethru::paper::claims::{paper_claims, rendered_head_error_arcmin};
    let claims = paper_claims();
    let claim = claims
        .iter()
        .find(|c| c.claim.contains("a larger θ_F reduces errors"))
        .unwrap();
    let (wide, narrow) = (
        rendered_head_error_arcmin(80.0).unwrap(),
        rendered_head_error_arcmin(30.0).unwrap(),
    );
    assert_eq!(claim.seethru, wide / narrow);
    // Each render is the geometry: the model eye 1 cm off moves the shown wall point by the
    // chord δ d2/d1 at D = d1 + d2, so the display's mean lies between cos²β_max and 1 of
    // δ d2 / (d1 D) (chord_bracket; β_max at the display's corner, plus the chord).
    let (d1, d2, delta) = (0.8, 10.0, 0.01);
    let closed = physical::per_lateral_head_error(d1, d2) * delta * ARCMIN_PER_RAD;
    let corner = 0.25f64.hypot(0.1) / d1 + delta * d2 / d1 / (d1 + d2);
    let lo = corner.atan().cos().powi(2);
    for v in [wide, narrow] {
        assert!(
            v >= closed * lo && v <= closed * (1.0 + 8.0 * F32_ROUNDING),
            "{v}′ outside [{}, {closed}]′",
            closed * lo
        );
    }
    // And they agree to the float rounding of each pixel's angle (8·2^-24 rad, as above,
    // over the smallest angle, twice): far from the paper's tan 30°/tan 80° ≈ 0.10.
    let float = 2.0 * 8.0 * F32_ROUNDING * ARCMIN_PER_RAD / (closed * lo);
    assert!(
        (claim.seethru - 1.0).abs() <= float,
        "θ_F = 80° over 30°: {} (± {float}); the paper's scaling {}",
        claim.seethru,
        claim.paper
    );
}

// ---------------------------------------------------------------------------------------------
// The ratio's uncertainty

#[test]
fn the_ratios_uncertainty_is_bounded_by_pixel_pitches_computed_here() {
    let occlusion = |l, b1, d2, d1, b_h| {
        Setup::Occlusion(seethru::analysis::paper::OcclusionParams { l, b1, d2, d1, b_h })
    };
    let foreshortening = |l, b1, d2, d1, b_h, gamma: f64| {
        Setup::Foreshortening(seethru::analysis::paper::ForeshorteningParams {
            l,
            b1,
            d2,
            d1,
            b_h,
            gamma: gamma.to_radians(),
        })
    };
    let width = 320;
    for setup in [
        occlusion(5.0, -0.35, 6.3, 2.5, 1.75),
        occlusion(1.0, 0.5, 4.0, 1.0, 0.25),
        foreshortening(5.0, -1.5, 1.3, 2.0, 0.7, 90.0),
        foreshortening(1.0, 0.25, 3.0, 1.0, 0.125, 45.0),
    ] {
        let compensation = Compensation::default();
        let scene = build_scene(&setup, width, &compensation).unwrap();
        let (d1, d2) = match &setup {
            Setup::Occlusion(p) => (p.d1, p.d2),
            Setup::Foreshortening(p) => (p.d1, p.d2),
        };
        let eye = scene.eye();
        // The driver's lines of sight through the display, carried to the scene plane
        // z = −d2: the spacing of neighbouring pixels there bounds every edge bracket.
        let driver = &scene.driver;
        let o = &scene.obstacle;
        let mut pitch = 0.0f64;
        for y in 0..driver.height {
            let row: Vec<Option<f64>> = (0..driver.width)
                .map(|x| {
                    let (origin, dir) =
                        driver.world_ray(DVec2::new(x as f64 + 0.5, y as f64 + 0.5));
                    let at = origin + dir * (-origin.z / dir.z);
                    (at.x.abs() <= o.width / 2.0 && at.y.abs() <= o.height / 2.0)
                        .then(|| origin.x + dir.x * ((-d2 - origin.z) / dir.z))
                })
                .collect();
            for pair in row.windows(2) {
                if let [Some(a), Some(b)] = pair {
                    pitch = pitch.max((b - a).abs());
                }
            }
        }
        // Resampling, carried to the plane: half a display pixel seen from the eye, and half
        // a frontal pixel on the model plane (the scene plane: the paper's compensation).
        let display_px = o.width / o.display_resolution[0] as f64;
        let frontal_tan_px = 2.0 * scene.frontal.tan_half_x() / scene.frontal.width as f64;
        let quantum = 0.5 * (display_px * (d1 + d2) / d1 + frontal_tan_px * d2);
        assert!((eye.z - d1).abs() < 1e-12);
        let r = measure_ratio(&setup, width, &compensation).unwrap();
        let (user_bound, cam_bound) = (0.5 * pitch, 0.5 * pitch + quantum);
        let relative = |a: f64, b: f64| (a - b).abs() <= 1e-12 * b.abs();
        assert!(
            relative(r.resampling_quantum_m, quantum),
            "{r:?} vs {quantum}"
        );
        assert!(
            r.p_user.uncertainty <= user_bound * (1.0 + 1e-12),
            "{r:?}: pitch {pitch}"
        );
        assert!(
            r.p_cam.uncertainty <= cam_bound * (1.0 + 1e-12),
            "{r:?}: pitch {pitch}"
        );
        assert!(r.p_cam.uncertainty >= quantum, "{r:?}");
        // The ratio's worst corner over those bounds, computed here.
        let (c, u) = (r.p_cam.observed, r.p_user.observed);
        assert!(u.abs() > user_bound);
        let bound = [-1.0, 1.0]
            .into_iter()
            .flat_map(|a| [-1.0, 1.0].map(|b| (a, b)))
            .map(|(a, b)| ((c + a * cam_bound) / (u + b * user_bound) - c / u).abs())
            .fold(0.0, f64::max);
        assert!(
            r.ratio.uncertainty <= bound * (1.0 + 1e-12),
            "{r:?}: bound {bound}"
        );
        // And the observation is the prediction within it.
        for q in [r.p_cam, r.p_user, r.ratio] {
            assert!((q.observed - q.predicted).abs() <= q.uncertainty, "{r:?}");
        }
        assert!(
            (r.ratio.observed - r.ratio.predicted).abs() <= bound,
            "{r:?}"
        );
    }
}
