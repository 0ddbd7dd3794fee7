//! The SAE J941 eyellipse: its centre from the seat package (hand-worked formula), and its
//! seeded samples' mean, covariance and 95 % contour against the analytic values.

use glam::{DMat3, DVec3};
use seethru::scene::eyellipse::{CHI2_3_95, Eyellipse, SeatPackage};

/// The cabin's seat package (docs/guide/cabin-pillar.md).
fn cabin_seat(clutch: bool) -> SeatPackage {
    SeatPackage {
        sgrp: DVec3::new(1.4, 0.562, -0.05),
        ball_of_foot: DVec3::new(1.4, 0.3, -0.88063),
        steering_l6: 0.45,
        seat_height_h30: 0.27,
        clutch,
    }
}

#[test]
fn centre_follows_the_j941_formula() {
    // X = L1 + 664 + 0.587·450 − 0.176·270 = L1 + 880.63 mm rearward (world +z);
    // Z = H8 + 638 mm (world +y); Y = W20 (world x).
    let e = Eyellipse::j941_95(&cabin_seat(false));
    assert!(
        (e.centre - DVec3::new(1.4, 1.2, 0.0)).length() < 1e-9,
        "{:?}",
        e.centre
    );
    // A clutch pedal moves it 12.5 mm forward (world −z).
    let c = Eyellipse::j941_95(&cabin_seat(true));
    assert!(
        (c.centre - DVec3::new(1.4, 1.2, -0.0125)).length() < 1e-9,
        "{:?}",
        c.centre
    );
}

#[test]
fn axes_are_tilted_12_degrees_front_down() {
    let e = Eyellipse::j941_95(&cabin_seat(false));
    // The fore-aft axis points rearward (+z) and rises by tan 12° rearward.
    let ex = e.world_from_ellipse.x_axis;
    assert!(
        (ex.y / ex.z - 12f64.to_radians().tan()).abs() < 1e-12,
        "{ex:?}"
    );
    // The endpoints of the full axes are 206.4, 60.3, 93.4 mm apart.
    let ends = |axis: DVec3, half: f64| 2.0 * half * axis.length();
    assert!((ends(ex, e.semi_axes.x) - 0.2064).abs() < 1e-12);
    assert!((ends(e.world_from_ellipse.y_axis, e.semi_axes.y) - 0.0603).abs() < 1e-12);
    assert!((ends(e.world_from_ellipse.z_axis, e.semi_axes.z) - 0.0934).abs() < 1e-12);
    assert!(e.world_from_ellipse.y_axis.abs_diff_eq(DVec3::X, 1e-12));
}

#[test]
fn samples_have_the_stated_mean_and_covariance() {
    let e = Eyellipse::j941_95(&cabin_seat(false));
    let n = 40_000;
    let points = e.samples(7, n);
    let nf = n as f64;
    let mean = points.iter().copied().sum::<DVec3>() / nf;
    // Expected covariance, built here from the axes and the 12° rotation (not from the code's).
    let b = 12f64.to_radians();
    let r = DMat3::from_cols(
        DVec3::new(0.0, b.sin(), b.cos()),
        DVec3::X,
        DVec3::new(0.0, b.cos(), -b.sin()),
    );
    let s = DVec3::new(0.1032, 0.03015, 0.0467) / CHI2_3_95.sqrt();
    let expected = r * DMat3::from_diagonal(s * s) * r.transpose();
    let sigma = |m: &DMat3, i: usize, j: usize| m.col(j)[i];
    for i in 0..3 {
        // Mean: within 4 standard errors.
        let se = (sigma(&expected, i, i) / nf).sqrt();
        assert!(
            (mean[i] - e.centre[i]).abs() < 4.0 * se,
            "mean[{i}] {} vs {} (se {se})",
            mean[i],
            e.centre[i]
        );
    }
    let mut cov = DMat3::ZERO;
    for p in &points {
        let d = *p - mean;
        cov += DMat3::from_cols(d * d.x, d * d.y, d * d.z);
    }
    cov /= nf - 1.0;
    for i in 0..3 {
        for j in 0..3 {
            // Var of a normal sample covariance: (Σii Σjj + Σij²) / n.
            let (ii, jj, ij) = (
                sigma(&expected, i, i),
                sigma(&expected, j, j),
                sigma(&expected, i, j),
            );
            let se = ((ii * jj + ij * ij) / nf).sqrt();
            let got = sigma(&cov, i, j);
            assert!(
                (got - ij).abs() < 4.0 * se,
                "cov[{i}][{j}] {got} vs {ij} (se {se})"
            );
        }
    }
}

#[test]
fn ninety_five_percent_of_samples_fall_inside_the_ellipse() {
    let e = Eyellipse::j941_95(&cabin_seat(false));
    let n = 40_000;
    let inside = e
        .samples(11, n)
        .iter()
        .filter(|p| e.radius_squared(**p) <= 1.0)
        .count() as f64
        / n as f64;
    // Binomial standard error sqrt(0.95·0.05/n) ≈ 0.0011; 4 of them.
    assert!((inside - 0.95).abs() < 0.0044, "share inside {inside}");
}

#[test]
fn samples_depend_on_seed_and_index_only() {
    let e = Eyellipse::j941_95(&cabin_seat(false));
    let all = e.samples(3, 100);
    assert_eq!(all[57], e.sample(3, 57));
    assert_ne!(e.samples(4, 100), all);
}

#[test]
fn the_cabin_eye_is_the_eyellipse_centre() {
    // scenes/cabin.toml writes its eye out; it must stay the centre of its seat package's ellipse.
    let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR"));
    let scene = seethru::scene::Scene::load(&root.join("scenes/cabin.toml")).unwrap();
    let centre = Eyellipse::j941_95(&cabin_seat(false)).centre;
    assert!(
        (scene.eye() - centre).length() < 1e-9,
        "{:?} vs {centre:?}",
        scene.eye()
    );
}
