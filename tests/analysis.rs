//! The paper's closed forms against finite differences and against independent geometry:
//! ray–plane intersections of each setup, and the 3-D compensation code.

use glam::{DAffine3, DVec2, DVec3};
use seethru::analysis::paper::{
    CropParams, ForeshorteningParams, OcclusionParams, Side, head_distance, head_offset, k_px,
};
use seethru::analysis::perceived::PerceivedGeometry;
use seethru::analysis::physical;
use seethru::geometry::camera::Camera;
use seethru::scene::Obstacle;
use seethru::system::compensation::{Crop, ModelPlane, compute_crop};

const SIDES: [Side; 2] = [Side::Left, Side::Right];

fn crop_params() -> Vec<CropParams> {
    let mut out = Vec::new();
    for &(d1, d2, b_h, width, theta_deg) in &[
        (1.0, 5.0, 0.125, 0.5, 40.0f64),
        (0.8, 2.0, -0.05, 0.3, 63.5),
        (2.5, 30.0, 0.3, 1.0, 30.0),
        (0.6, 0.9, 0.0, 0.25, 80.0),
    ] {
        out.push(CropParams {
            d1,
            d2,
            b_h,
            width,
            theta_f: theta_deg.to_radians(),
        });
    }
    out
}

/// Central difference of `f` at `x`, step relative to `x`.
fn central(f: impl Fn(f64) -> f64, x: f64) -> f64 {
    let h = 1e-5 * x.abs().max(1.0);
    (f(x + h) - f(x - h)) / (2.0 * h)
}

fn close(a: f64, b: f64, tol: f64) -> bool {
    (a - b).abs() <= tol * (1.0 + b.abs())
}

#[test]
fn discarded_widths_equal_ray_casting() {
    // Eq. paralax2 against the top view: K1 runs from the frontal view's left edge on the plane
    // (x = −d2 tan θ_F) to where the eye's ray past the display's left edge meets the plane; K2
    // from that ray past the right edge to the view's right edge. The eye is at −b_h.
    for p in crop_params() {
        let eye = DVec2::new(-p.b_h, -p.d1);
        let left = hit_plane(eye, DVec2::new(-p.width / 2.0, 0.0), p.d2);
        let right = hit_plane(eye, DVec2::new(p.width / 2.0, 0.0), p.d2);
        let half_view = p.d2 * p.theta_f.tan();
        let (k1, k2) = (left + half_view, half_view - right);
        assert!(close(p.discarded_width(Side::Left), k1, 1e-12), "{p:?}");
        assert!(close(p.discarded_width(Side::Right), k2, 1e-12), "{p:?}");
        // The cutting ratios are those widths over the frontal view's width at the plane.
        let view = 2.0 * half_view;
        assert!(close(p.cutting_ratio(Side::Left), k1 / view, 1e-12));
        assert!(close(p.cutting_ratio(Side::Right), k2 / view, 1e-12));
    }
}

#[test]
fn sensitivities_equal_finite_differences() {
    for p in crop_params() {
        for side in SIDES {
            let fd_d1 = central(|d1| CropParams { d1, ..p }.cutting_ratio(side), p.d1);
            let fd_bh = central(|b_h| CropParams { b_h, ..p }.cutting_ratio(side), p.b_h);
            let fd_d2 = central(|d2| CropParams { d2, ..p }.cutting_ratio(side), p.d2);
            let fd_dphi = central(|d2| CropParams { d2, ..p }.phi_d2(), p.d2);
            assert!(
                close(p.phi_d1(side), fd_d1, 1e-7),
                "{p:?} {side:?}: {} vs {fd_d1}",
                p.phi_d1(side)
            );
            assert!(close(p.phi_bh(side), fd_bh, 1e-7), "{p:?} {side:?}");
            assert!(close(p.phi_d2(), fd_d2, 1e-7), "{p:?} {side:?}");
            assert!(close(p.dphi_d2_dd2(), fd_dphi, 1e-6), "{p:?}");
            // Erratum 1: eq. ANALYSIS_D2 as printed, −0.5 D / (2 d2² tan θ_F), has the opposite
            // sign of the derivative.
            let printed = -0.5 * p.width / (2.0 * p.d2 * p.d2 * p.theta_f.tan());
            assert!(close(p.phi_d2_as_printed(), printed, 1e-12));
            assert!(fd_d2 > 0.0 && printed < 0.0);
        }
    }
}

#[test]
fn d2_min_is_where_the_ratio_reaches_the_bound() {
    for p in crop_params() {
        for side in SIDES {
            let Some(d2) = p.d2_min(side, 0.05) else {
                continue;
            };
            let at = CropParams { d2, ..p };
            assert!(close(
                at.cutting_ratio(side),
                0.95 * p.cutting_ratio_at_infinity(side),
                1e-12
            ));
            assert!(
                CropParams { d2: d2 * 1.01, ..p }.cutting_ratio(side)
                    > 0.95 * p.cutting_ratio_at_infinity(side)
            );
        }
    }
    // The paper's claim for Fig. 3: θ_F = 80°, d1 = 1, b_h = 0.125, D = 0.5 → d2 > 0.9.
    let paper = CropParams {
        d1: 1.0,
        d2: 1.0,
        b_h: 0.125,
        width: 0.5,
        theta_f: 80f64.to_radians(),
    };
    let d2 = paper.d2_min(Side::Left, 0.05).unwrap();
    assert!((d2 - 0.9016).abs() < 1e-3, "{d2}");
    // No bound where R(∞) ≤ 0 (the display's view exceeds the frontal camera's) or for a
    // tolerance ≤ 0. R(∞) = 1/2 − D/(4 d1 tan θ_F) is exactly 0 for D = 2 d1 tan θ_F, b_h = 0.
    let t = paper.theta_f.tan();
    let edge = CropParams {
        b_h: 0.0,
        width: 2.0 * t,
        ..paper
    };
    assert_eq!(edge.cutting_ratio_at_infinity(Side::Left), 0.0);
    assert_eq!(edge.d2_min(Side::Left, 0.05), None);
    let beyond = CropParams {
        width: 3.0 * t,
        ..edge
    };
    assert_eq!(beyond.d2_min(Side::Right, 0.05), None);
    assert_eq!(paper.d2_min(Side::Left, 0.0), None);
    assert_eq!(paper.d2_min(Side::Left, -0.05), None);
}

/// An obstacle at the origin facing +z, `width` × `height`, and a frontal camera at its centre
/// looking down −z.
fn paper_rig(width: f64, height: f64, theta_f: f64, res: [u32; 2]) -> (Obstacle, Camera) {
    let obstacle = Obstacle {
        world_from_obstacle: DAffine3::IDENTITY,
        width,
        height,
        thickness: 0.05,
        display_resolution: [200, 300],
        display_off_color: [0.0; 3],
        body_color: [0.0; 3],
        display_shape: seethru::scene::display_surface::DisplayShape::Flat,
        scanout: seethru::geometry::shutter::Scanout::default(),
        display_light: None,
    };
    let camera = Camera::new(DAffine3::IDENTITY, theta_f, res[0], res[1]).unwrap();
    (obstacle, camera)
}

#[test]
fn the_3d_crop_equals_ratio1_in_the_papers_configuration() {
    for p in crop_params() {
        let height = 0.7 * p.width;
        let (obstacle, frontal) = paper_rig(p.width, height, p.theta_f, [1280, 720]);
        let b_v = 0.4 * p.b_h + 0.02;
        // Paper convention: b_h > 0 puts the eye at −b_h; the vertical offset b_v > 0 is up.
        let eye = DVec3::new(-p.b_h, b_v, p.d1);
        for (plane, params) in [
            (ModelPlane::At(p.d2), p),
            (
                ModelPlane::Infinity,
                CropParams {
                    d2: f64::INFINITY,
                    ..p
                },
            ),
        ] {
            let crop = compute_crop(eye, &obstacle, &frontal, plane, [200, 300]).unwrap();
            assert!(crop.is_axis_aligned(1e-9));
            let r = crop.ratios();
            assert!(
                close(r.left, params.cutting_ratio(Side::Left), 1e-12),
                "{p:?} {plane:?}: {} vs {}",
                r.left,
                params.cutting_ratio(Side::Left)
            );
            assert!(
                close(r.right, params.cutting_ratio(Side::Right), 1e-12),
                "{p:?} {plane:?}"
            );
            // Vertically the same formula with H, b_v and the vertical half angle; the top
            // border plays the left's role (the eye above the axis crops more at the top).
            let vertical = CropParams {
                b_h: b_v,
                width: height,
                theta_f: frontal.tan_half_y().atan(),
                ..params
            };
            assert!(
                close(r.top, vertical.cutting_ratio(Side::Left), 1e-12),
                "{p:?} {plane:?}"
            );
            assert!(
                close(r.bottom, vertical.cutting_ratio(Side::Right), 1e-12),
                "{p:?} {plane:?}"
            );
            assert_eq!(
                k_px(r.left, 1280),
                (params.cutting_ratio(Side::Left) * 1280.0).round() as i64
            );
        }
    }
}

#[test]
fn the_crop_maps_every_display_point_to_its_model_plane_point() {
    // A tilted, offset frontal camera: the crop is a homography, exact for points on the plane.
    let (obstacle, _) = paper_rig(0.4, 0.3, 0.7, [640, 480]);
    let pose = DAffine3::from_translation(DVec3::new(0.03, -0.02, -0.05))
        * DAffine3::from_rotation_y(0.15)
        * DAffine3::from_rotation_x(-0.08);
    let frontal = Camera::new(pose, 0.7, 640, 480).unwrap();
    let eye = DVec3::new(0.12, 0.05, 0.7);
    for plane in [ModelPlane::At(4.0), ModelPlane::Infinity] {
        let crop = compute_crop(eye, &obstacle, &frontal, plane, [200, 150]).unwrap();
        assert!(!crop.is_axis_aligned(0.5));
        for &(u, v) in &[(0.0, 0.0), (100.0, 75.0), (13.5, 140.25), (199.0, 3.0)] {
            // The display point in the world (display x right, y down from the top-left).
            let x = DVec3::new(-0.2 + 0.4 * u / 200.0, 0.15 - 0.3 * v / 150.0, 0.0);
            let expected = match plane {
                ModelPlane::At(d2) => frontal.project_point(eye + (x - eye) * (eye.z + d2) / eye.z),
                ModelPlane::Infinity => frontal.project_direction(x - eye),
            }
            .unwrap();
            let got = crop.frontal_point(DVec2::new(u, v));
            assert!(
                (got - expected).length() < 1e-8,
                "{plane:?} ({u},{v}): {got} vs {expected}"
            );
        }
    }
}

#[test]
fn an_eye_behind_the_display_is_rejected() {
    let (obstacle, frontal) = paper_rig(0.3, 0.3, 0.7, [64, 48]);
    let err = compute_crop(
        DVec3::new(0.0, 0.0, -0.1),
        &obstacle,
        &frontal,
        ModelPlane::Infinity,
        [10, 10],
    )
    .unwrap_err();
    assert!(err.to_string().contains("d1 > 0"));
}

/// Where the ray from `from` through `through` meets the plane z = `z` (2-D: x across, z depth).
fn hit_plane(from: DVec2, through: DVec2, z: f64) -> f64 {
    let t = (z - from.y) / (through.y - from.y);
    from.x + t * (through.x - from.x)
}

/// Signed occluded width by visibility: for the box [b1 − 10, b1] × [d2 − L, d2] on the plane
/// z = d2, the width of background hidden just beyond b1 (positive), or of the box's side
/// face visible there (negative), found by bisection on what the viewer's rays hit.
fn occluded_width_by_visibility(viewer: DVec2, b1: f64, l: f64, d2: f64) -> f64 {
    // What the ray from the viewer to the background point (x, d2) meets first.
    #[derive(PartialEq, Clone, Copy, Debug)]
    enum Seen {
        Background,
        Front,
        Side,
    }
    let seen = |x: f64| {
        let target = DVec2::new(x, d2);
        let at_front = hit_plane(viewer, target, d2 - l);
        if at_front <= b1 && at_front >= b1 - 10.0 {
            return Seen::Front;
        }
        // The side face x = b1, z in [d2 − L, d2], crossed between the front plane and the target.
        let t = (b1 - viewer.x) / (x - viewer.x);
        let z = viewer.y + t * (d2 - viewer.y);
        if t > 0.0 && t < 1.0 && z > d2 - l && z < d2 {
            Seen::Side
        } else {
            Seen::Background
        }
    };
    // The boundary between `a` (seen at x = b1 + tiny) and background, searched outwards.
    let boundary = |lo: f64, hi: f64, inside: Seen| {
        let (mut lo, mut hi) = (lo, hi);
        for _ in 0..200 {
            let mid = 0.5 * (lo + hi);
            if seen(mid) == inside {
                lo = mid
            } else {
                hi = mid
            }
        }
        0.5 * (lo + hi)
    };
    let just_beyond = seen(b1 + 1e-9);
    match just_beyond {
        Seen::Front => boundary(b1 + 1e-9, b1 + 100.0, Seen::Front) - b1,
        Seen::Side => -(b1 - boundary(b1 + 1e-9, b1 + 100.0, Seen::Side)).abs(),
        Seen::Background => {
            // The side face shows to the left of b1 (inside the box's x range is the front).
            let left = boundary(b1 - 1e-9, b1 - 100.0, Seen::Side);
            if seen(b1 - 1e-9) == Seen::Side {
                left - b1
            } else {
                0.0
            }
        }
    }
}

fn occlusion_cases() -> Vec<OcclusionParams> {
    vec![
        OcclusionParams {
            l: 5.0,
            b1: -0.35,
            d2: 6.3,
            d1: 2.5,
            b_h: 1.75,
        }, // the paper's
        OcclusionParams {
            l: 1.0,
            b1: 0.5,
            d2: 4.0,
            d1: 1.0,
            b_h: 0.25,
        },
        OcclusionParams {
            l: 2.0,
            b1: 1.5,
            d2: 10.0,
            d1: 0.8,
            b_h: -0.3,
        },
        OcclusionParams {
            l: 0.5,
            b1: -1.2,
            d2: 3.0,
            d1: 1.2,
            b_h: 0.4,
        },
    ]
}

#[test]
fn occlusion_widths_equal_ray_casting() {
    for p in occlusion_cases() {
        let camera = DVec2::new(0.0, 0.0);
        let eye = DVec2::new(-p.b_h, -p.d1);
        let cam = occluded_width_by_visibility(camera, p.b1, p.l, p.d2);
        let user = occluded_width_by_visibility(eye, p.b1, p.l, p.d2);
        assert!(
            close(cam, p.p_cam(), 1e-9),
            "{p:?}: camera {cam} vs {}",
            p.p_cam()
        );
        assert!(
            close(user, p.p_user(), 1e-9),
            "{p:?}: user {user} vs {}",
            p.p_user()
        );
        assert!(close(p.ratio(), cam / user, 1e-9));
    }
    let paper = occlusion_cases()[0];
    assert!((paper.ratio() - (-0.73)).abs() < 0.005, "{}", paper.ratio());
}

#[test]
fn occlusion_approximations_hold_in_their_regimes() {
    // OCLUSION2: d2 ≫ L, d2 ≫ d1.
    let far = OcclusionParams {
        l: 0.5,
        b1: 0.8,
        d2: 5000.0,
        d1: 1.0,
        b_h: 0.3,
    };
    assert!(close(far.ratio(), far.ratio_far(), 1e-3));
    // OCLUSION3: b_h → 0. The geometry gives 1 + d1/(d2 − L) (erratum 3: printed 1 − …).
    let small = OcclusionParams {
        l: 1.0,
        b1: 0.6,
        d2: 3.0,
        d1: 1.0,
        b_h: 1e-9,
    };
    assert!(close(small.ratio(), small.ratio_small_bh(), 1e-6));
    assert!(!close(
        small.ratio(),
        small.ratio_small_bh_as_printed(),
        0.1
    ));
    // The printed form itself, 1 − d1/(d2 − L): 1 − 1/2 here, 1 − 1.2/2.5 for another box.
    assert!(close(small.ratio_small_bh_as_printed(), 0.5, 1e-12));
    let other = OcclusionParams {
        l: 0.5,
        d2: 3.0,
        d1: 1.2,
        ..small
    };
    assert!(close(
        other.ratio_small_bh_as_printed(),
        1.0 - 1.2 / 2.5,
        1e-12
    ));
}

fn foreshortening_cases() -> Vec<ForeshorteningParams> {
    let p = |l, b1, d2, d1, b_h, g: f64| ForeshorteningParams {
        l,
        b1,
        d2,
        d1,
        b_h,
        gamma: g.to_radians(),
    };
    vec![
        p(5.0, -1.5, 1.3, 2.0, 0.7, 90.0), // the paper's
        p(1.0, 0.25, 3.0, 1.0, 0.125, 45.0),
        p(2.0, -0.5, 5.0, 1.5, -0.2, 60.0),
        p(0.8, 1.0, 2.0, 0.7, 0.3, 20.0),
    ]
}

#[test]
fn foreshortening_widths_equal_ray_plane_intersections() {
    for p in foreshortening_cases() {
        let corner = DVec2::new(p.b1, p.d2);
        let far_end = corner + p.l * DVec2::new(p.gamma.cos(), p.gamma.sin());
        let width_from = |viewer: DVec2| hit_plane(viewer, far_end, p.d2) - corner.x;
        let (cam, user) = (
            width_from(DVec2::ZERO),
            width_from(DVec2::new(-p.b_h, -p.d1)),
        );
        assert!(
            close(cam, p.p_cam(), 1e-12) && close(user, p.p_user(), 1e-12),
            "{p:?}"
        );
        assert!(close(p.ratio(), cam / user, 1e-12));
        // The limit d2 → ∞: 1, except at γ = 90° (erratum 4).
        let far = ForeshorteningParams { d2: 1e8, ..p };
        assert!(
            close(far.ratio(), p.ratio_far_limit(), 1e-6),
            "{p:?}: {} vs {}",
            far.ratio(),
            p.ratio_far_limit()
        );
    }
    let paper = foreshortening_cases()[0];
    assert!((paper.ratio() - 2.47).abs() < 0.005);
    assert!(paper.ratio_far_limit() != 1.0);
}

#[test]
fn head_equations_recover_an_eye_seen_by_a_pinhole_camera() {
    // A back camera at the origin looking down −z; two pupils A apart, their midpoint at
    // lateral b_h and distance d1, projected by the camera model: eqs. d1 and b_h must recover
    // the midpoint from the pixel measurements alone.
    let (a, half_angle, w) = (0.064, 35f64.to_radians(), 640u32);
    let camera = Camera::new(DAffine3::IDENTITY, half_angle, w, 480).unwrap();
    for &(d1, b_h) in &[(0.7, 0.05), (0.9, -0.12), (1.2, 0.0), (0.5, 0.2)] {
        let pupil = |side: f64| {
            camera
                .project_point(DVec3::new(b_h + side * a / 2.0, 0.03, -d1))
                .unwrap()
        };
        let (left, right) = (pupil(-1.0), pupil(1.0));
        let a_px = (right - left).length();
        let offset_px = (left.x + right.x) / 2.0 - w as f64 / 2.0;
        let d1_est = head_distance(a, a_px, w as f64, half_angle);
        assert!(close(d1_est, d1, 1e-12), "{d1_est} vs {d1}");
        let b_h_est = head_offset(offset_px, w as f64, d1_est, half_angle);
        assert!(close(b_h_est, b_h, 1e-12), "{b_h_est} vs {b_h}");
    }
}

/// Misregistration angle at the true eye, in the plane of a top view: the display point `x`
/// shows the model-plane point of the ray from `model_eye` (model plane at `model_d2`, seen by
/// the camera at the origin), while the truth there is the plane point at the true `d2`.
fn misregistration(eye: DVec2, model_eye: DVec2, x: f64, d2: f64, model_d2: f64) -> f64 {
    let display = DVec2::new(x, 0.0);
    // Model: the point on the model plane, then the camera's ray to it continued to the scene.
    let model_point = DVec2::new(hit_plane(model_eye, display, model_d2), model_d2);
    let shown = DVec2::new(hit_plane(DVec2::ZERO, model_point, d2), d2);
    let truth = DVec2::new(hit_plane(eye, display, d2), d2);
    let (a, b) = (shown - eye, truth - eye);
    a.perp_dot(b).atan2(a.dot(b)).abs()
}

#[test]
fn physical_sensitivities_equal_the_ray_geometry() {
    for &(d1, d2, x, b_h) in &[
        (0.8, 6.0, 0.125, 0.05),
        (1.0, 2.0, -0.2, -0.1),
        (0.7, 40.0, 0.3, 0.0),
    ] {
        // Eye at (−b_h, −d1) in (x across, z depth) with the scene at +d2.
        let eye = DVec2::new(-b_h, -d1);
        let h = 1e-6;
        let lateral = misregistration(eye, eye + DVec2::new(h, 0.0), x, d2, d2) / h;
        // The formula is the small-angle limit: it holds near the line of sight.
        let obliquity = ((x + b_h) / d1).atan().cos().powi(2);
        assert!(
            close(
                lateral,
                physical::per_lateral_head_error(d1, d2) * obliquity,
                1e-4
            ),
            "{lateral}"
        );
        let depth = misregistration(eye, eye + DVec2::new(0.0, -h), x, d2, d2) / h;
        assert!(
            close(
                depth,
                physical::per_head_distance_error((x + b_h).abs(), d1, d2) * obliquity,
                1e-4
            ),
            "{depth}"
        );
        let plane = misregistration(eye, eye, x, d2, d2 + h) / h;
        assert!(
            close(
                plane,
                physical::per_d2_error(x.abs(), d1, d2) * obliquity,
                1e-4
            ),
            "{plane}"
        );
        // The d2 → ∞ model, against the exact ray geometry with a relative bracket: the shown
        // and the true points lie |x| apart at depth D = d1 + d2 from the eye; in the top view
        // each element dp of that chord, seen at β off the display normal, subtends
        // cos²β dp/D, so the whole lies between cos²β_max and cos²β_min times |x|/D (β over
        // the chord: its ends, and 0 if it crosses the axis), and |x|/D is within (x/D)²/3
        // above atan(|x|/D). The 1e-9 is the 1e12 m stand-in for infinity and f64 rounding,
        // not a tolerance on the form.
        let inf = misregistration(eye, eye, x, d2, 1e12);
        let closed = physical::infinite_plane_error(x.abs(), d1, d2);
        let depth = d1 + d2;
        let ends = [(x + b_h) * depth / d1, (x + b_h) * depth / d1 - x];
        let tan_max = ends[0].abs().max(ends[1].abs()) / depth;
        let tan_min = if ends[0] * ends[1] <= 0.0 {
            0.0
        } else {
            ends[0].abs().min(ends[1].abs()) / depth
        };
        let cos2 = |t: f64| 1.0 / (1.0 + t * t);
        let (lo, hi) = (
            closed * cos2(tan_max),
            closed * cos2(tan_min) / (1.0 - (x / depth).powi(2) / 3.0),
        );
        assert!(
            inf >= lo * (1.0 - 1e-9) && inf <= hi * (1.0 + 1e-9),
            "{inf} outside [{lo}, {hi}]"
        );
    }
}

#[test]
fn paper_sensitivities_scaled_to_the_eye_equal_the_ray_geometry() {
    // φ is a fraction of the frontal image's width (2 d2 tan θ_F at the plane); seen from the
    // eye at distance d1 + d2 it is an angle. That angle must be the misregistration the ray
    // geometry gives for a small error, where the line of sight meets the display squarely
    // (φ_bh, at the eye's foot) or at the display edge (φ_d2, times the obliquity there).
    for p in crop_params() {
        let eye = DVec2::new(-p.b_h, -p.d1);
        let scale = 2.0 * p.d2 * p.theta_f.tan() / (p.d1 + p.d2);
        let h = 1e-6;
        let lateral = misregistration(eye, eye + DVec2::new(h, 0.0), -p.b_h, p.d2, p.d2) / h;
        assert!(
            close(p.phi_bh(Side::Left).abs() * scale, lateral, 1e-5),
            "{p:?}: {} vs {lateral}",
            p.phi_bh(Side::Left).abs() * scale
        );
        let edge = p.width / 2.0;
        let obliquity = ((edge + p.b_h) / p.d1).atan().cos().powi(2);
        let plane = misregistration(eye, eye, edge, p.d2, p.d2 + h) / h;
        assert!(
            close(p.phi_d2() * scale * obliquity, plane, 1e-5),
            "{p:?}: {} vs {plane}",
            p.phi_d2() * scale * obliquity
        );
    }
}

#[test]
fn head_error_angles_equal_the_ray_geometry() {
    // The exact (not linearised) misregistration of a 1 cm head error, against this file's
    // own ray construction; a scene at infinity approximated by a very distant plane.
    for &(d1, b_h, d2) in &[
        (0.8, 0.0, 10.0),
        (0.7, 0.2, 1.0),
        (1.2, -0.1, 0.3),
        (0.8, 0.1, 1e9),
    ] {
        let eye = DVec2::new(-b_h, -d1);
        for x in [-0.25, -0.1, 0.0, 0.15, 0.3] {
            for (ex, ed) in [(0.01, 0.0), (0.0, 0.01), (-0.02, 0.03)] {
                let model_eye = eye + DVec2::new(ex, -ed);
                let expected = misregistration(eye, model_eye, x, d2, d2);
                let library_d2 = if d2 > 1e8 { f64::INFINITY } else { d2 };
                let got = physical::head_error_angle(-b_h, d1, ex, ed, x, library_d2);
                assert!(
                    (got - expected).abs() <= 1e-9 + 1e-7 * expected,
                    "d1 {d1} b_h {b_h} d2 {d2} x {x} error ({ex}, {ed}): {got} vs {expected}"
                );
            }
        }
    }
    // Per cm at d2 → ∞ the lateral error tends to 1/d1 (radians per metre) on the axis.
    let per_cm = physical::head_error_arcmin_per_cm(0.0, 0.8, 0.5, f64::INFINITY, true);
    assert!(
        close(per_cm, 0.01 / 0.8 * physical::ARCMIN_PER_RAD, 1e-3),
        "{per_cm}"
    );
    // An eye beyond the display's right edge (x = 0.3 m, the display spanning ±0.25 m):
    // the worst point is that edge, 5 cm short of the eye, where the directions through
    // it from the true eye and from the eye 1 cm further out differ by
    // atan(6 cm / d1) − atan(5 cm / d1); nowhere on the display is it larger.
    let edge = physical::head_error_arcmin_per_cm(0.3, 0.8, 0.5, f64::INFINITY, true);
    let expected = ((0.06f64 / 0.8).atan() - (0.05f64 / 0.8).atan()) * physical::ARCMIN_PER_RAD;
    assert!(
        (edge - expected).abs() <= 1e-9 * expected,
        "{edge} vs {expected} arcmin"
    );
}

/// Which display point shows the scene-plane edge, found by bisection on what the frontal
/// camera's ray towards the model point `M(x)` meets (`on_object`), and where the driver's
/// ray through that display point meets the scene plane. Top view, depths into the scene.
fn perceived_edge_by_ray_casting(
    geometry: &PerceivedGeometry,
    on_object: impl Fn(DVec2) -> bool,
) -> f64 {
    let model_eye = DVec2::new(geometry.model_eye_x, -geometry.model_eye_d1);
    // The camera's ray direction towards the model point of display point x.
    let towards = |x: f64| {
        let through = DVec2::new(x, 0.0);
        if geometry.model_d2.is_infinite() {
            through - model_eye
        } else {
            DVec2::new(
                hit_plane(model_eye, through, geometry.model_d2),
                geometry.model_d2,
            )
        }
    };
    let (mut lo, mut hi) = (-50.0, 50.0);
    let on_lo = on_object(towards(lo));
    assert_ne!(
        on_lo,
        on_object(towards(hi)),
        "no edge between the bisection bounds"
    );
    for _ in 0..200 {
        let mid = 0.5 * (lo + hi);
        if on_object(towards(mid)) == on_lo {
            lo = mid
        } else {
            hi = mid
        }
    }
    let eye = DVec2::new(geometry.eye_x, -geometry.eye_d1);
    hit_plane(eye, DVec2::new(0.5 * (lo + hi), 0.0), geometry.scene_d2)
}

/// Whether the ray from the origin along `dir` meets the segment from `a` to `b` (top view).
fn ray_meets_segment(dir: DVec2, a: DVec2, b: DVec2) -> bool {
    let e = b - a;
    let denom = dir.perp_dot(e);
    if denom.abs() < 1e-15 {
        return false;
    }
    let t = a.perp_dot(e) / denom;
    let s = a.perp_dot(dir) / denom;
    t > 0.0 && (0.0..=1.0).contains(&s)
}

#[test]
fn perceived_widths_equal_ray_casting_under_a_wrong_model_or_eye() {
    let compensations = |d2: f64, d1: f64, b_h: f64| {
        let exact = PerceivedGeometry::exact(-b_h, d1, d2);
        vec![
            exact,
            PerceivedGeometry {
                model_d2: 0.5 * d2,
                ..exact
            },
            PerceivedGeometry {
                model_d2: 2.0 * d2,
                ..exact
            },
            PerceivedGeometry {
                model_d2: f64::INFINITY,
                ..exact
            },
            PerceivedGeometry {
                model_eye_x: -b_h + 0.05,
                ..exact
            },
            PerceivedGeometry {
                model_eye_d1: d1 - 0.1,
                model_d2: 1.5 * d2,
                ..exact
            },
        ]
    };
    for p in occlusion_cases() {
        // The camera sees the box's front face (depth d2 − L, x ≤ b1) or not.
        let front = |dir: DVec2| {
            ray_meets_segment(
                dir,
                DVec2::new(p.b1 - 1e6, p.d2 - p.l),
                DVec2::new(p.b1, p.d2 - p.l),
            )
        };
        for g in compensations(p.d2, p.d1, p.b_h) {
            let edge = perceived_edge_by_ray_casting(&g, front);
            let predicted = g.perceived_width(p.b1, p.p_cam());
            assert!(
                close(edge - p.b1, predicted, 1e-9),
                "{p:?} {g:?}: {} vs {predicted}",
                edge - p.b1
            );
        }
        // The paper's compensation perceives the paper's p_cam.
        let exact = PerceivedGeometry::exact(-p.b_h, p.d1, p.d2);
        assert!(close(
            exact.perceived_width(p.b1, p.p_cam()),
            p.p_cam(),
            1e-12
        ));
    }
    for p in foreshortening_cases() {
        let corner = DVec2::new(p.b1, p.d2);
        let far_end = corner + p.l * DVec2::new(p.gamma.cos(), p.gamma.sin());
        // The surface itself, extended a little past its corner (where it meets the plane,
        // the backdrop's edge is the far end, not the corner).
        let surface =
            |dir: DVec2| ray_meets_segment(dir, corner - 0.01 * (far_end - corner), far_end);
        for g in compensations(p.d2, p.d1, p.b_h) {
            // Only the far end's edge: search beyond the corner's perceived position.
            let edge = perceived_edge_by_ray_casting(&g, |dir| {
                surface(dir) || (dir.x / dir.y - p.b1 / p.d2) * p.p_cam().signum() < 0.0
            });
            let predicted = g.perceived_width(p.b1, p.p_cam());
            assert!(
                close(edge - p.b1, predicted, 1e-9),
                "{p:?} {g:?}: {} vs {predicted}",
                edge - p.b1
            );
        }
    }
}

#[test]
fn the_resampling_quantum_is_half_a_pixel_of_each_grid_carried_to_the_plane() {
    // Half a display pixel carried along the eye's ray to the scene plane, plus half a frontal
    // pixel: two frontal rays a pixel apart (in tangent) meet the model plane, are seen through
    // the model's eye on the display, and carried along the eye's ray to the scene plane.
    let (display_px, frontal_tan_px) = (0.002, 0.0015);
    for (d1, d2, b_h) in [(2.5, 6.3, 1.75), (2.0, 1.3, 0.7), (0.8, 10.0, -0.1)] {
        let exact = PerceivedGeometry::exact(-b_h, d1, d2);
        for g in [
            exact,
            PerceivedGeometry {
                model_d2: 0.5 * d2,
                ..exact
            },
            PerceivedGeometry {
                model_d2: 3.0 * d2,
                model_eye_x: -b_h + 0.1,
                ..exact
            },
            PerceivedGeometry {
                model_d2: f64::INFINITY,
                model_eye_d1: d1 + 0.2,
                ..exact
            },
        ] {
            let eye = DVec2::new(g.eye_x, -g.eye_d1);
            let model_eye = DVec2::new(g.model_eye_x, -g.model_eye_d1);
            let on_plane = |x: f64| hit_plane(eye, DVec2::new(x, 0.0), g.scene_d2);
            let display = (on_plane(0.1 + display_px) - on_plane(0.1)).abs();
            let seen_on_display = |tan: f64| {
                let towards = if g.model_d2.is_infinite() {
                    model_eye + DVec2::new(tan, 1.0)
                } else {
                    DVec2::new(tan * g.model_d2, g.model_d2)
                };
                hit_plane(model_eye, towards, 0.0)
            };
            let frontal = (on_plane(seen_on_display(0.3 + frontal_tan_px))
                - on_plane(seen_on_display(0.3)))
            .abs();
            let expected = 0.5 * (display + frontal);
            let got = g.resampling_quantum(display_px, frontal_tan_px);
            assert!(close(got, expected, 1e-9), "{g:?}: {got} vs {expected}");
        }
    }
}

#[test]
fn the_claims_table_reproduces_the_papers_numbers_and_flags_its_errata() {
    let claims = seethru::paper::claims::paper_claims();
    let row = |prefix: &str| {
        claims
            .iter()
            .find(|c| c.claim.starts_with(prefix))
            .unwrap_or_else(|| panic!("no claim `{prefix}`"))
    };
    // The paper's numbers that stand, to the paper's printed precision.
    for prefix in ["§5.1 Fig. 3", "§5.2 occlusion", "§5.2 foreshortening"] {
        let c = row(prefix);
        assert!((c.seethru - c.paper).abs() < 0.005, "{c:?}");
    }
    // Erratum 6: the lateral head error costs d2/(d1(d1 + d2)) on the axis, so 1 m over 10 m
    // at d1 = 0.8 is (1/1.8)/(10/10.8) = 0.6, where the paper has a constant error (1); the
    // table's exact 1 cm geometry differs from this first-order value by about 1e-5.
    let c = row("§4.1 'sensitivities independent of d2");
    assert!((c.seethru - 0.6).abs() < 1e-4 && c.paper == 1.0, "{c:?}");
    // The depth error at the display edge (x = 0.25): x d2/(d1²(d1 + d2)) times the obliquity.
    let depth = |d2: f64| {
        let x: f64 = 0.25;
        x * d2 / (0.64 * (0.8 + d2)) * (x / 0.8).atan().cos().powi(2)
    };
    let c = row("  the same for depth");
    assert!((c.seethru - depth(1.0) / depth(10.0)).abs() < 2e-3, "{c:?}");
    // Erratum 7: no θ_F in what the driver sees, against the paper's tan 30°/tan 80°.
    let c = row("§4.1 'a larger θ_F");
    assert!(c.seethru == 1.0 && (c.paper - 0.1018).abs() < 1e-4, "{c:?}");
    // The statement on d1 holds: (10/(1.6·11.6)) / (10/(0.8·10.8)).
    let c = row("§4.1 'less impact");
    assert!(
        (c.seethru - (10.0 / (1.6 * 11.6)) / (10.0 / (0.8 * 10.8))).abs() < 1e-4,
        "{c:?}"
    );
}

#[test]
fn a_frontal_pixel_subtends_at_the_eye_what_the_camera_model_gives() {
    // The two rays through the central pixel's edges of a frontal camera at the display
    // centre meet the scene plane; the eye on the axis at d1 sees the segment between them
    // under an angle. For d2 → ∞ it is the angle between the rays.
    for (theta_deg, px, d1, d2) in [
        (40.0, 1280u32, 0.8, 10.0),
        (63.5, 640, 1.2, 2.0),
        (20.0, 1920, 0.7, f64::INFINITY),
    ] {
        let theta: f64 = f64::to_radians(theta_deg);
        let camera = Camera::new(DAffine3::IDENTITY, theta, px, px / 2).unwrap();
        let edge = |u: f64| camera.world_ray(DVec2::new(u, px as f64 / 4.0)).1;
        let (a, b) = (edge(px as f64 / 2.0), edge(px as f64 / 2.0 + 1.0));
        let angle = if d2.is_infinite() {
            a.angle_between(b)
        } else {
            let eye = DVec3::new(0.0, 0.0, d1);
            let on_plane = |d: DVec3| d * (d2 / -d.z);
            (on_plane(a) - eye).angle_between(on_plane(b) - eye)
        };
        let got = physical::frontal_pixel_angle(theta, px, d1, d2);
        assert!(close(got, angle, 1e-6), "θ_F {theta_deg}: {got} vs {angle}");
    }
    // One degree is sixty arc-minutes.
    assert!(close(
        physical::ARCMIN_PER_RAD * 1f64.to_radians(),
        60.0,
        1e-15
    ));
    // The d2 → ∞ limits of the head-error sensitivities are the finite forms far away.
    for d1 in [0.6, 0.8, 1.5] {
        let far = 1e9;
        assert!(close(
            physical::per_lateral_head_error(d1, f64::INFINITY),
            physical::per_lateral_head_error(d1, far),
            1e-8
        ));
        assert!(close(
            physical::per_head_distance_error(0.2, d1, f64::INFINITY),
            physical::per_head_distance_error(0.2, d1, far),
            1e-8
        ));
    }
}

#[test]
fn a_crop_is_axis_aligned_only_when_all_four_edges_are() {
    let crop = |corners: [DVec2; 4]| Crop {
        corners,
        frontal_from_display: glam::DMat3::IDENTITY,
        frontal_size: [100, 100],
    };
    let [tl, tr, br, bl] = [
        DVec2::new(10.0, 10.0),
        DVec2::new(90.0, 10.0),
        DVec2::new(90.0, 80.0),
        DVec2::new(10.0, 80.0),
    ];
    assert!(crop([tl, tr, br, bl]).is_axis_aligned(0.5));
    // Each edge off on its own makes the crop a general quadrilateral.
    let off = DVec2::new(0.0, 3.0);
    let sideways = DVec2::new(3.0, 0.0);
    for corners in [
        [tl + off, tr, br, bl],
        [tl, tr, br + off, bl],
        [tl + sideways, tr, br, bl],
        [tl, tr + sideways, br, bl],
    ] {
        assert!(!crop(corners).is_axis_aligned(0.5), "{corners:?}");
        assert!(crop(corners).is_axis_aligned(3.0), "{corners:?}");
    }
}
