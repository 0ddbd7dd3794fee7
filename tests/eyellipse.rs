//! The SAE J941 eyellipse: its centre from the seat package (hand-worked formula), and its
//! seeded samples' mean, covariance and 95 % contour against the analytic values.

use glam::{DMat3, DVec3};
use seethru::scene::Scene;
use seethru::scene::eyellipse::{Eyellipse, SeatPackage};
use seethru::scene::source::SourceFile;

/// The cabin's seat package (docs/guide/cabin-pillar.md).
fn cabin_seat(clutch: bool) -> SeatPackage {
    SeatPackage {
        sgrp: DVec3::new(1.4, 0.562, -0.05),
        ball_of_foot_z: -0.88063,
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
    let r = expected_axes();
    // J941's tangent cutoff: the semi-axis is the normal's 95th percentile, 1.6449 σ.
    let s = DVec3::new(0.1032, 0.03015, 0.0467) / 1.644_853_626_951_472_2;
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

/// The cabin ellipse's rotation, built here from the 12° tilt (not from the code's).
fn expected_axes() -> DMat3 {
    let b = 12f64.to_radians();
    DMat3::from_cols(
        DVec3::new(0.0, b.sin(), b.cos()),
        DVec3::X,
        DVec3::new(0.0, b.cos(), -b.sin()),
    )
}

#[test]
fn five_percent_of_samples_lie_beyond_each_tangent_plane() {
    // J941's meaning of "95th percentile": for any tangent plane of the ellipse, 95 % of eyes
    // are on the centre's side of it. Directions: the three axes, both ways, and skew ones.
    let e = Eyellipse::j941_95(&cabin_seat(false));
    let n = 40_000;
    let points = e.samples(11, n);
    let semi = DVec3::new(0.1032, 0.03015, 0.0467);
    let r = expected_axes();
    let normals = [
        DVec3::X,
        -DVec3::X,
        DVec3::Y,
        -DVec3::Y,
        DVec3::Z,
        -DVec3::Z,
        DVec3::new(1.0, 1.0, 1.0).normalize(),
        DVec3::new(-0.3, 0.8, -0.5).normalize(),
        r.x_axis,
        -r.z_axis,
    ];
    for normal in normals {
        // Support distance of the ellipse along `normal`: √(nᵀ R diag(a²) Rᵀ n).
        let h = ((r.transpose() * normal) * semi).length();
        assert!((e.tangent_distance(normal) - h).abs() < 1e-12, "{normal:?}");
        let beyond = points
            .iter()
            .filter(|p| (**p - e.centre).dot(normal) > h)
            .count() as f64
            / n as f64;
        // Binomial standard error sqrt(0.05·0.95/n) ≈ 0.0011; 4 of them.
        assert!(
            (beyond - 0.05).abs() < 0.0044,
            "share beyond the tangent plane along {normal:?}: {beyond}"
        );
    }
    // Not the 95 % contour reading: the ellipse itself holds P(χ²₃ ≤ 1.645²) = 56.1 %.
    let inside = points
        .iter()
        .filter(|p| e.radius_squared(**p) <= 1.0)
        .count() as f64
        / n as f64;
    assert!((inside - 0.5607).abs() < 0.01, "share inside {inside}");
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
    // scenes/cabin.toml gives no eye position: its [eyellipse] table places the eye at the
    // ellipse's centre, which for this seat package is (1.4, 1.2, 0) exactly (the eye the
    // cabin had when it was written out, so its images are unchanged).
    let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR"));
    let scene = seethru::scene::Scene::load(&root.join("scenes/cabin.toml")).unwrap();
    let centre = Eyellipse::j941_95(&cabin_seat(false)).centre;
    assert_eq!(scene.eye(), DVec3::new(1.4, 1.2, 0.0));
    assert_eq!(centre, DVec3::new(1.4, 1.2, 0.0));
    assert_eq!(
        scene.eyellipse,
        Some(Eyellipse::j941_95(&cabin_seat(false)))
    );
}

/// The cabin's text with its `[eyellipse]` table's body replaced by `table` (and, when
/// `position` is given, an eye position written into `[camera.driver]`).
fn cabin_with(table: &str, position: Option<&str>) -> Result<Scene, String> {
    let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR"));
    let path = root.join("scenes/cabin.toml");
    let text = std::fs::read_to_string(&path).unwrap();
    let start = text.find("[eyellipse]\n").unwrap() + "[eyellipse]\n".len();
    let end = start + text[start..].find("\n\n").unwrap();
    let mut edited = format!("{}{table}{}", &text[..start], &text[end..]);
    if let Some(p) = position {
        edited = edited.replace(
            "[camera.driver]\n",
            &format!("[camera.driver]\nposition = {p}\n"),
        );
    }
    Scene::from_source(&SourceFile::from_text(&path, edited)).map_err(|e| e.to_string())
}

#[test]
fn eyellipse_keys_have_their_defaults_and_a_given_eye_wins() {
    // Only the required keys: L6 0.45 m, H30 0.27 m and no clutch are the defaults, so the
    // centre is the cabin's.
    let scene = cabin_with(
        "sgrp = [1.4, 0.562, -0.05]\nball_of_foot_z = -0.88063",
        None,
    )
    .unwrap();
    assert_eq!(scene.eye(), DVec3::new(1.4, 1.2, 0.0));
    // Each input moves the centre as the formula says: a clutch 12.5 mm forward, L6 + 100 mm
    // 58.7 mm rearward, H30 + 100 mm 17.6 mm forward.
    for (extra, dz) in [
        ("clutch = true", -0.0125),
        ("steering_l6 = 0.55", 0.0587),
        ("seat_height_h30 = 0.37", -0.0176),
    ] {
        let table = format!("sgrp = [1.4, 0.562, -0.05]\nball_of_foot_z = -0.88063\n{extra}");
        let eye = cabin_with(&table, None).unwrap().eye();
        assert!(
            (eye - DVec3::new(1.4, 1.2, dz)).length() < 1e-12,
            "{extra}: {eye:?}"
        );
    }
    // A written-out position is the eye; the ellipse stays for sampling.
    let scene = cabin_with(
        "sgrp = [1.4, 0.562, -0.05]\nball_of_foot_z = -0.88063",
        Some("[1.38, 1.21, 0.02]"),
    )
    .unwrap();
    assert_eq!(scene.eye(), DVec3::new(1.38, 1.21, 0.02));
    assert_eq!(scene.eyellipse.unwrap().centre, DVec3::new(1.4, 1.2, 0.0));
}

#[test]
fn bad_eyellipse_keys_are_one_error_naming_file_line_key_and_range() {
    let base = "sgrp = [1.4, 0.562, -0.05]\nball_of_foot_z = -0.88063";
    for (table, words) in [
        (
            format!("{base}\nseat_height_h30 = 0.5"),
            "key `eyellipse.seat_height_h30`: must be in [0.127, 0.405]",
        ),
        (
            format!("{base}\nsteering_l6 = -0.1"),
            "key `eyellipse.steering_l6`: must be in [0, 1.5]",
        ),
        (format!("{base}\nseat_tilt = 3"), "eyellipse.seat_tilt"),
        (format!("{base}\nclutch = 1"), "key `eyellipse.clutch`"),
        (
            "ball_of_foot_z = -0.88063".to_string(),
            "key `eyellipse.sgrp`: required key is missing",
        ),
        (
            "sgrp = [1.4, 0.562, -0.05]".to_string(),
            "key `eyellipse.ball_of_foot_z`",
        ),
        (
            "sgrp = [1.4, 0.562, -0.05]\nball_of_foot_z = 0.3".to_string(),
            "the ball of foot must be ahead of the SgRP",
        ),
    ] {
        let err = cabin_with(&table, None).unwrap_err();
        assert!(err.contains(words), "{table}: {err}");
        assert!(err.contains("cabin.toml:"), "{err}");
        assert!(!err.contains('\n'), "one line: {err}");
    }
    // The range error points at the key's own line.
    let err = cabin_with(&format!("{base}\nseat_height_h30 = 0.5"), None).unwrap_err();
    let text = std::fs::read_to_string(
        std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/cabin.toml"),
    )
    .unwrap();
    let table_line = text.lines().position(|l| l == "[eyellipse]").unwrap() + 1;
    assert!(
        err.contains(&format!("cabin.toml:{}:", table_line + 3)),
        "{err}"
    );
    // Without [eyellipse] and without a position, the driver's eye is missing.
    let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR"));
    let path = root.join("scenes/cabin.toml");
    let start = text.find("\n[eyellipse]\n").unwrap();
    let end = start + 1 + text[start + 1..].find("\n\n").unwrap();
    let edited = format!("{}{}", &text[..start], &text[end..]);
    let Err(err) = Scene::from_source(&SourceFile::from_text(&path, edited)) else {
        panic!("a cabin without [eyellipse] and without an eye position was read");
    };
    let err = err.to_string();
    assert!(err.contains("camera.driver.position"), "{err}");
}
