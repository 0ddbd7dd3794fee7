//! Every accelerated query against its brute-force twin, on the das scene, for both BVH kinds.

mod common;

use glam::Vec3;
use seethru::render::accel::{Accel, BvhKind, closest_brute_force, make_ray, occluded_brute_force};
use seethru::scene::world::{World, view_bit};
use seethru::util::sampling::{hash_words, unit_float};

fn random_unit(seed: u32) -> Vec3 {
    // Uniform on the sphere from two hashed uniforms.
    let z = 2.0 * unit_float(hash_words(&[seed, 1])) - 1.0;
    let a = std::f32::consts::TAU * unit_float(hash_words(&[seed, 2]));
    let r = (1.0 - z * z).sqrt();
    Vec3::new(r * a.cos(), z, r * a.sin())
}

/// Rays from points around the street (and from the cameras) in random directions.
fn rays(n: u32) -> Vec<(Vec3, Vec3)> {
    let scene = common::das();
    let eye = scene.eye().as_vec3();
    (0..n)
        .map(|i| {
            let origin = if i % 4 == 0 {
                eye
            } else {
                let u = |k| unit_float(hash_words(&[i, k]));
                Vec3::new(-15.0 + 30.0 * u(3), 0.05 + 6.0 * u(4), 5.0 - 80.0 * u(5))
            };
            // Bias a third of the rays towards the ground so that the big triangles are hit.
            let mut dir = random_unit(i);
            if i % 3 == 0 {
                dir.y = -dir.y.abs();
            }
            (origin, dir.normalize())
        })
        .collect()
}

#[test]
fn closest_and_occluded_equal_brute_force() {
    let world = World::build(&common::das()).unwrap();
    let rays = rays(3000);
    for kind in [BvhKind::Cwbvh, BvhKind::Bvh2] {
        let accel = Accel::build(&world, kind);
        let mut hits = 0;
        for (i, &(origin, dir)) in rays.iter().enumerate() {
            let view = [
                view_bit::TRUTH,
                view_bit::OCCLUDED,
                view_bit::FRONTAL,
                view_bit::BACK,
            ][i % 4];
            let tmax = if i % 5 == 0 { 7.5 } else { f32::INFINITY };
            let ray = make_ray(origin, dir, 0.0, tmax);
            let fast = accel.closest(&world, ray, view);
            let slow = closest_brute_force(&world, ray, view);
            match (fast, slow) {
                (None, None) => {}
                (Some(f), Some(s)) => {
                    hits += 1;
                    // The same distance, bit for bit; at an exact tie (a shared edge) either
                    // primitive is a correct answer.
                    assert_eq!(
                        f.t.to_bits(),
                        s.t.to_bits(),
                        "{kind:?} ray {i}: {f:?} vs {s:?}"
                    );
                    if f.prim != s.prim {
                        assert_eq!(world.intersect(f.prim, &ray), s.t, "{kind:?} ray {i}");
                    }
                }
                _ => panic!("{kind:?} ray {i}: accelerated {fast:?}, brute force {slow:?}"),
            }
            assert_eq!(
                accel.occluded(&world, ray, view),
                occluded_brute_force(&world, ray, view),
                "{kind:?} ray {i}"
            );
        }
        // The comparison means something only if many rays hit something and many miss.
        assert!(
            hits > rays.len() / 3 && hits < rays.len(),
            "{kind:?}: {hits} hits of {}",
            rays.len()
        );
    }
}

#[test]
fn hidden_objects_are_invisible_only_in_their_views() {
    let scene = common::das();
    let world = World::build(&scene).unwrap();
    let accel = Accel::build(&world, BvhKind::Cwbvh);
    // From the eye towards the display centre: the obstacle in `occluded`, not in `truth`.
    let eye = scene.eye().as_vec3();
    let centre = scene.obstacle.world_from_obstacle.translation.as_vec3();
    let ray = make_ray(eye, (centre - eye).normalize(), 0.0, f32::INFINITY);
    let occluded = accel.closest(&world, ray, view_bit::OCCLUDED).unwrap();
    assert_eq!(world.object_of(occluded.prim), world.obstacle_id);
    let truth = accel
        .closest(&world, ray, view_bit::TRUTH)
        .map(|h| world.object_of(h.prim));
    assert_ne!(truth, Some(world.obstacle_id));
    // From the back camera towards the eye: the head in `back`; the driver never sees it.
    let back = scene.back.position().as_vec3();
    let ray = make_ray(back, (eye - back).normalize(), 0.0, f32::INFINITY);
    let head = accel.closest(&world, ray, view_bit::BACK).unwrap();
    let head_id = scene.objects.iter().position(|o| o.name == "head").unwrap() as u32 + 1;
    assert_eq!(world.object_of(head.prim), head_id);
    let ray = make_ray(
        eye + Vec3::new(0.0, 0.0, 0.5),
        Vec3::new(0.0, 0.0, -1.0),
        0.0,
        f32::INFINITY,
    );
    let seen = accel
        .closest(&world, ray, view_bit::TRUTH)
        .map(|h| world.object_of(h.prim));
    assert_ne!(seen, Some(head_id));
}
