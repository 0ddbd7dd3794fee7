//! A material's glossy lobe: the GGX (Trowbridge–Reitz) microfacet reflection of a dielectric
//! coat, with Schlick's approximation of the Fresnel term and the height-correlated Smith
//! masking–shadowing term (Heitz 2014, "Understanding the masking-shadowing function in
//! microfacet-based BRDFs"), as glTF's reference BRDF has them (pbrt-v4 and Mitsuba 3 use
//! GGX too, with the exact Fresnel term; Mitsuba with separable Smith masking).
//!
//! The lobe reflects the sun and the lamps (delta lights) by evaluating it toward them, and
//! the sky and the other objects by one reflection ray per sample, drawn from the
//! distribution of the facets the eye sees ([`sample_reflection`]). Under it the diffuse
//! albedo is scaled by (1 − F0), the light the coat reflects at normal incidence.

use glam::Vec3;

/// π × the lobe's BRDF for light arriving from `to_light` and leaving toward `to_eye` (unit
/// vectors from the surface point) at a surface of unit `normal`: times the irradiance over π
/// (the unit in which the integrator carries light), the reflected radiance. `f0`: the
/// reflectance at normal incidence, [0, 1]; `alpha`: the GGX roughness, (0, 1]. Zero where
/// either direction lies below the surface.
#[inline]
pub fn pi_brdf(f0: f32, alpha: f32, normal: Vec3, to_light: Vec3, to_eye: Vec3) -> f32 {
    let cos_in = normal.dot(to_light);
    let cos_out = normal.dot(to_eye);
    if cos_in <= 0.0 || cos_out <= 0.0 {
        return 0.0;
    }
    let half = (to_light + to_eye).normalize();
    let cos_half = normal.dot(half).max(0.0);
    let a2 = alpha * alpha;
    // D × π: α² / (cos²θh (α² − 1) + 1)².
    let denominator = cos_half * cos_half * (a2 - 1.0) + 1.0;
    let d_pi = a2 / (denominator * denominator);
    let fresnel = schlick(f0, to_eye.dot(half).max(0.0));
    let masking = 1.0 / (1.0 + smith_lambda(a2, cos_in) + smith_lambda(a2, cos_out));
    d_pi * fresnel * masking / (4.0 * cos_in * cos_out)
}

/// A direction to gather light from for the lobe seen from `to_eye` (unit, from the
/// surface) at a surface of unit `normal`, and the weight of the light found there: with
/// `u`, `v` uniform in [0, 1), the weight × the radiance arriving from the direction has the
/// expectation of the radiance the lobe reflects toward the eye, ∫ f L cos θi dωi. The
/// microfacet normal is drawn from GGX's distribution of visible normals (Heitz 2018,
/// "Sampling the GGX distribution of visible normals"), so the weight is F × G2 / G1, at most
/// 1 (no fireflies). `None` where the eye or the reflected direction lies below the surface
/// (that sample gathers nothing).
#[inline]
pub fn sample_reflection(
    f0: f32,
    alpha: f32,
    normal: Vec3,
    to_eye: Vec3,
    u: f32,
    v: f32,
) -> Option<(Vec3, f32)> {
    let cos_out = normal.dot(to_eye);
    if cos_out <= 0.0 {
        return None;
    }
    // The tangent frame: z along the normal.
    let (tx, ty) = normal.any_orthonormal_pair();
    let eye = Vec3::new(to_eye.dot(tx), to_eye.dot(ty), cos_out);
    // The eye in the hemisphere of the stretched (α = 1) facets.
    let stretched = Vec3::new(alpha * eye.x, alpha * eye.y, eye.z).normalize();
    let length2 = stretched.x * stretched.x + stretched.y * stretched.y;
    let t1 = if length2 > 0.0 {
        Vec3::new(-stretched.y, stretched.x, 0.0) / length2.sqrt()
    } else {
        Vec3::X
    };
    let t2 = stretched.cross(t1);
    // A point of the disc, squeezed onto the part of it the eye sees.
    let r = u.sqrt();
    let phi = std::f32::consts::TAU * v;
    let p1 = r * phi.cos();
    let s = 0.5 * (1.0 + stretched.z);
    let p2 = (1.0 - s) * (1.0 - p1 * p1).max(0.0).sqrt() + s * r * phi.sin();
    let lift = (1.0 - p1 * p1 - p2 * p2).max(0.0).sqrt();
    let facet = p1 * t1 + p2 * t2 + lift * stretched;
    let facet = Vec3::new(alpha * facet.x, alpha * facet.y, facet.z.max(0.0)).normalize();
    let half = facet.x * tx + facet.y * ty + facet.z * normal;
    let cos_half = to_eye.dot(half);
    let to_light = 2.0 * cos_half * half - to_eye;
    let cos_in = normal.dot(to_light);
    if cos_in <= 0.0 {
        return None;
    }
    let a2 = alpha * alpha;
    let (lambda_out, lambda_in) = (smith_lambda(a2, cos_out), smith_lambda(a2, cos_in));
    let weight =
        schlick(f0, cos_half.max(0.0)) * (1.0 + lambda_out) / (1.0 + lambda_out + lambda_in);
    Some((to_light, weight))
}

/// Schlick's approximation of the Fresnel reflectance at the cosine `cos` between the light
/// and the microfacet's normal.
#[inline]
fn schlick(f0: f32, cos: f32) -> f32 {
    let m = 1.0 - cos;
    let m2 = m * m;
    f0 + (1.0 - f0) * (m2 * m2 * m)
}

/// Smith's Λ of the GGX distribution of roughness² `a2` for a direction at cosine `cos` to
/// the normal: (√(1 + α² tan²θ) − 1) / 2.
#[inline]
fn smith_lambda(a2: f32, cos: f32) -> f32 {
    let cos2 = cos * cos;
    let tan2 = (1.0 - cos2).max(0.0) / cos2;
    ((1.0 + a2 * tan2).sqrt() - 1.0) * 0.5
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The lobe's directional albedo toward `to_eye`: ∫ f cos θi dωi over the hemisphere
    /// (its reflection of a uniform sky of radiance 1).
    fn albedo(f0: f32, alpha: f32, to_eye: Vec3, n: usize) -> f64 {
        reflected(f0, alpha, to_eye, &|_| 1.0, n)
    }

    #[test]
    fn a_perfect_coat_seen_from_above_reflects_all_but_its_masked_and_its_sunken_facets() {
        // F0 = 1, the eye on the normal: a microfacet at θh mirrors the eye's ray to 2θh, so
        // the facets beyond 45° (GGX: a share α²/(1 + α²) of the projected area) send their
        // light below the horizon; masking takes more as α grows (1.4 % at α = 0.2, 14 % at
        // 0.5, by a second quadrature over the half vectors).
        for alpha in [0.05f32, 0.2, 0.5] {
            let a2 = f64::from(alpha * alpha);
            let bound = 1.0 - a2 / (1.0 + a2);
            let a = albedo(1.0, alpha, Vec3::Y, 2000);
            assert!(
                a <= bound + 1e-3 && a > 0.85 * bound,
                "α {alpha}: {a} vs {bound}"
            );
            // The same integral over the half vectors: ∫ D G (n·h) dωh for θh < 45°, the
            // light at 2θh, G = 1/(1 + Λ(2θh)) (Λ = 0 for the eye on the normal).
            let n = 20_000;
            let step = std::f64::consts::FRAC_PI_4 / n as f64;
            let twin: f64 = (0..n)
                .map(|k| {
                    let theta = (k as f64 + 0.5) * step;
                    let c = theta.cos();
                    let d = a2 / (std::f64::consts::PI * (c * c * (a2 - 1.0) + 1.0).powi(2));
                    let tan2 = (2.0 * theta).tan().powi(2);
                    let g = 1.0 / (1.0 + ((1.0 + a2 * tan2).sqrt() - 1.0) / 2.0);
                    d * g * c * theta.sin() * step * std::f64::consts::TAU
                })
                .sum();
            assert!(
                (a - twin).abs() < 2e-3,
                "α {alpha}: {a} vs {twin} over the half vectors"
            );
        }
    }

    /// The lobe's reflection of a sky of radiance `sky` toward `to_eye`, ∫ f L cos θi dωi, by
    /// the midpoint rule in (cos θi, φ), `n` steps a side.
    fn reflected(f0: f32, alpha: f32, to_eye: Vec3, sky: &dyn Fn(Vec3) -> f64, n: usize) -> f64 {
        let mut sum = 0.0f64;
        for i in 0..n {
            let cos = (i as f64 + 0.5) / n as f64;
            let sin = (1.0 - cos * cos).sqrt();
            for j in 0..n {
                let phi = std::f64::consts::TAU * (j as f64 + 0.5) / n as f64;
                let to_light = Vec3::new(
                    (sin * phi.cos()) as f32,
                    cos as f32,
                    (sin * phi.sin()) as f32,
                );
                // f cos dω = (π f / π) cos d(cos θ) dφ.
                let f =
                    f64::from(pi_brdf(f0, alpha, Vec3::Y, to_light, to_eye)) / std::f64::consts::PI;
                sum += f * cos * sky(to_light);
            }
        }
        sum * std::f64::consts::TAU / (n * n) as f64
    }

    /// The same by [`sample_reflection`], on an n × n grid of (u, v) cell midpoints, at a
    /// surface turned by `tilt` (its normal `tilt` × +y, the eye and the sky turned with it).
    fn reflected_by_samples(
        f0: f32,
        alpha: f32,
        to_eye: Vec3,
        sky: &dyn Fn(Vec3) -> f64,
        n: usize,
        tilt: glam::Quat,
    ) -> f64 {
        let normal = tilt * Vec3::Y;
        let mut sum = 0.0f64;
        for i in 0..n {
            for j in 0..n {
                let (u, v) = ((i as f32 + 0.5) / n as f32, (j as f32 + 0.5) / n as f32);
                if let Some((to_light, weight)) =
                    sample_reflection(f0, alpha, normal, tilt * to_eye, u, v)
                {
                    assert!(
                        to_light.is_normalized() && to_light.dot(normal) > 0.0,
                        "{to_light}"
                    );
                    assert!((0.0..=1.0).contains(&weight), "{weight}");
                    sum += f64::from(weight) * sky(tilt.inverse() * to_light);
                }
            }
        }
        sum / (n * n) as f64
    }

    #[test]
    fn reflection_samples_gather_what_the_lobe_reflects() {
        // The sampled estimate of the reflected radiance equals the lobe's integral, for a
        // uniform sky (the directional albedo) and for one bright toward +x and the zenith
        // (which the directions' distribution, not only the weights' mean, must get right);
        // rough and smooth, from above, at 53° and at grazing angles, across the azimuth; on
        // an upright and a leaning surface.
        let uniform = |_: Vec3| 1.0;
        let lopsided = |d: Vec3| f64::from((1.0 + d.x) * (1.0 + d.x) + 4.0 * d.y * d.y * d.y);
        let skies: [(&str, &dyn Fn(Vec3) -> f64); 2] =
            [("uniform", &uniform), ("lopsided", &lopsided)];
        // Upright, and a surface whose normal leans to (0.3, 0.5, 0.8): the tangent frame
        // built for any normal.
        let tilts = [
            glam::Quat::IDENTITY,
            glam::Quat::from_rotation_arc(Vec3::Y, Vec3::new(0.3, 0.5, 0.8).normalize()),
        ];
        for (f0, alpha) in [(0.04f32, 0.1f32), (0.5, 0.3), (1.0, 0.7)] {
            for (cos, azimuth) in [(1.0f32, 0.0f32), (0.6, 0.0), (0.6, 2.0), (0.25, 3.5)] {
                let sin = (1.0 - cos * cos).sqrt();
                let to_eye = Vec3::new(sin * azimuth.cos(), cos, sin * azimuth.sin());
                for (name, sky) in skies {
                    let want = reflected(f0, alpha, to_eye, sky, 1500);
                    for tilt in tilts {
                        let got = reflected_by_samples(f0, alpha, to_eye, sky, 500, tilt);
                        assert!(
                            (got - want).abs() < 0.01 * want + 2e-4,
                            "F0 {f0}, α {alpha}, cos {cos}, azimuth {azimuth}, {name}, {tilt}: {got} vs {want}"
                        );
                    }
                }
            }
        }
    }

    #[test]
    fn a_waters_coat_reflects_its_fresnel_share_and_more_at_grazing_angles() {
        // A smooth lobe's albedo seen from above is the Fresnel reflectance at normal
        // incidence; at grazing angles it rises toward Schlick's value, less what masking and
        // the sunken facets take.
        let alpha = 0.1;
        let overhead = albedo(0.02, alpha, Vec3::Y, 2000);
        assert!((overhead - 0.02).abs() < 0.001, "{overhead}");
        let cos = 0.2f32;
        let grazing = Vec3::new((1.0 - cos * cos).sqrt(), cos, 0.0);
        let schlick = 0.02 + 0.98 * (1.0 - f64::from(cos)).powi(5);
        let a = albedo(0.02, alpha, grazing, 2000);
        assert!(a <= schlick && a > 0.5 * schlick, "{a} vs {schlick}");
    }

    #[test]
    fn the_peak_seen_along_the_normal_is_f0_over_four_pi_alpha_squared() {
        // Light and eye on the normal: D = 1/(πα²), F = F0, G = 1, cos θ = 1.
        for (f0, alpha) in [(0.04f32, 0.1f32), (0.5, 0.3), (1.0, 1.0)] {
            let f = pi_brdf(f0, alpha, Vec3::Y, Vec3::Y, Vec3::Y) / std::f32::consts::PI;
            let want = f0 / (4.0 * std::f32::consts::PI * alpha * alpha);
            assert!((f - want).abs() < 1e-5 * want, "{f} vs {want}");
        }
    }

    #[test]
    fn in_the_mirror_direction_at_sixty_degrees_fresnel_has_risen_by_a_thirty_second() {
        // Light and eye 60° off the normal on either side: the half vector is the normal, so
        // D = 1/(πα²); the light meets the facets at 60°, (1 − cos)⁵ = 1/32; tan² 60° = 3.
        let (f0, alpha) = (0.04f32, 0.2f32);
        let s = 60f32.to_radians().sin();
        let (to_light, to_eye) = (Vec3::new(s, 0.5, 0.0), Vec3::new(-s, 0.5, 0.0));
        let fresnel = f0 + (1.0 - f0) / 32.0;
        let lambda = ((1.0 + 3.0 * alpha * alpha).sqrt() - 1.0) / 2.0;
        let want = fresnel / (1.0 + 2.0 * lambda) / (alpha * alpha) / (4.0 * 0.25);
        let got = pi_brdf(f0, alpha, Vec3::Y, to_light, to_eye);
        assert!((got - want).abs() < 1e-5 * want, "{got} vs {want}");
    }

    #[test]
    fn light_and_eye_may_trade_places_and_nothing_comes_from_below() {
        let normal = Vec3::new(0.1, 0.9, -0.2).normalize();
        let a = Vec3::new(0.6, 0.5, 0.1).normalize();
        let b = Vec3::new(-0.3, 0.4, 0.7).normalize();
        let (ab, ba) = (
            pi_brdf(0.04, 0.25, normal, a, b),
            pi_brdf(0.04, 0.25, normal, b, a),
        );
        assert!(ab > 0.0 && (ab - ba).abs() < 1e-6 * ab, "{ab} vs {ba}");
        let below = Vec3::new(0.6, -0.1, 0.1).normalize();
        assert_eq!(pi_brdf(0.04, 0.25, normal, below, b), 0.0);
        assert_eq!(pi_brdf(0.04, 0.25, normal, a, below), 0.0);
    }

    #[test]
    fn the_highlight_is_brightest_where_the_normal_halves_light_and_eye() {
        // A light 60° off the normal in x: toward the eye directions of the xy plane within
        // 80° of the normal, a smooth lobe is largest at the mirror direction, 60° off on the
        // other side.
        let to_light = Vec3::new(60f32.to_radians().sin(), 60f32.to_radians().cos(), 0.0);
        let best = (0..=1600)
            .map(|k| (k as f32 * 0.1 - 80.0).to_radians())
            .max_by(|&a, &b| {
                let f = |t: f32| {
                    pi_brdf(
                        0.04,
                        0.05,
                        Vec3::Y,
                        to_light,
                        Vec3::new(t.sin(), t.cos(), 0.0),
                    )
                };
                f(a).total_cmp(&f(b))
            })
            .unwrap();
        assert!(
            (best.to_degrees() + 60.0).abs() < 1.0,
            "{}",
            best.to_degrees()
        );
    }
}
