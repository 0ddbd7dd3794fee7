//! Every accelerated query against its brute-force twin: random rays over the das scene,
//! rays along the axes and grazing the ground (zero direction components, flat boxes), the
//! cameras' own rays, and finite `tmax`; and the packet traversal on every instruction set
//! the CPU has, ray for ray against the same brute force.

mod common;

use glam::{DAffine3, DVec3, Vec3};
use seethru::geometry::camera::Camera;
use seethru::render::accel::{
    Accel, BuildChoice, Hit, closest_brute_force, make_ray, occluded_brute_force,
};
use seethru::render::bvh_build::Builder;
use seethru::render::bvh_packet::{PACKET, PacketStack, RayPacket};
use seethru::render::camera_rays::CameraRays;
use seethru::render::moving::MovingParts;
use seethru::render::ray::TraceRay;
use seethru::render::render_job::RenderJob;
use seethru::render::simd::Isa;
use seethru::render::views::View;
use seethru::scene::Scene;
use seethru::scene::world::{World, view_bit};
use seethru::util::sampling::{hash_words, unit_float};

fn random_unit(seed: u32) -> Vec3 {
    // Uniform on the sphere from two hashed uniforms.
    let z = 2.0 * unit_float(hash_words(&[seed, 1])) - 1.0;
    let a = std::f32::consts::TAU * unit_float(hash_words(&[seed, 2]));
    let r = (1.0 - z * z).sqrt();
    Vec3::new(r * a.cos(), z, r * a.sin())
}

/// Rays from points around the street (and from the eye) in random directions.
fn random_rays(eye: Vec3, n: u32) -> Vec<(Vec3, Vec3)> {
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

/// Rays along the six axes, and rays grazing the street and the ground (direction y of 0
/// and ±1e-7), from origins on and just above those planes and on box faces.
fn special_rays() -> Vec<(Vec3, Vec3)> {
    let origins = [
        Vec3::new(0.3, 0.0, -10.0),   // on the street plane
        Vec3::new(2.0, -0.01, -40.0), // on the ground plane
        Vec3::new(-3.5, 0.12, -20.0), // on a kerb's top face and side
        Vec3::new(1.4, 1e-4, -5.0),
        Vec3::new(-1.75, 0.6, -2.0), // in front of the car
        Vec3::new(-0.9, 0.35, -3.0), // level with the ball's centre
    ];
    let mut dirs: Vec<Vec3> = vec![Vec3::X, -Vec3::X, Vec3::Y, -Vec3::Y, Vec3::Z, -Vec3::Z];
    for y in [0.0, 1e-7, -1e-7] {
        for a in 0..8 {
            let a = a as f32 * std::f32::consts::FRAC_PI_4;
            dirs.push(Vec3::new(a.cos(), y, a.sin()).normalize());
        }
    }
    origins
        .iter()
        .flat_map(|&o| dirs.iter().map(move |&d| (o, d)))
        .collect()
}

/// Every 5th pixel's ray (columns and rows) of `camera` at 192 px wide.
fn camera_rays(camera: &Camera) -> Vec<(Vec3, Vec3)> {
    let camera = camera.with_resolution(192, (192 * camera.height / camera.width).max(1));
    let rays = CameraRays::new(&camera);
    (0..camera.height)
        .step_by(5)
        .flat_map(|y| (0..camera.width).step_by(5).map(move |x| (x, y)))
        .map(|(x, y)| (rays.origin, rays.direction(x as f32 + 0.5, y as f32 + 0.5)))
        .collect()
}

/// Checks `closest` and `occluded` against the brute force for each ray in each given view
/// (cycling), every fifth with a finite `tmax`, one ray at a time and in packets on every
/// available ISA; returns how many rays hit.
fn compare(world: &World, accel: &Accel, rays: &[(Vec3, Vec3)], views: &[u8]) -> usize {
    let mut hits = 0;
    let mut expected: Vec<(TraceRay, Option<Hit>, bool)> = Vec::new();
    for (i, &(origin, dir)) in rays.iter().enumerate() {
        let view = views[i % views.len()];
        let tmax = if i % 5 == 0 { 7.5 } else { f32::INFINITY };
        let ray = make_ray(origin, dir, 0.0, tmax);
        let fast = accel.closest(&ray, view);
        let slow = closest_brute_force(world, &ray, view);
        match (fast, slow) {
            (None, None) => {}
            (Some(f), Some(s)) => {
                hits += 1;
                // The same distance, bit for bit, and the same primitive: at an exact tie (a
                // shared edge) the first in world order, as the brute force.
                assert_eq!(f.t.to_bits(), s.t.to_bits(), "ray {i}: {f:?} vs {s:?}");
                assert_eq!(f.prim, s.prim, "ray {i}: {f:?} vs {s:?}");
            }
            _ => panic!("ray {i} ({origin}, {dir}): accelerated {fast:?}, brute force {slow:?}"),
        }
        let blocked = occluded_brute_force(world, &ray, view);
        assert_eq!(
            accel.occluded(&ray, view),
            blocked,
            "ray {i} ({origin}, {dir})"
        );
        expected.push((ray, slow, blocked));
    }
    compare_packets(accel, &expected, views);
    hits
}

/// Packets of the rays of each view (ray i is in view i mod the views), every third with
/// lane 5 left empty, on every ISA this CPU has: each lane's closest hit (primitive and
/// distance, bit for bit) and shadow answer equal the brute force's; empty lanes find nothing.
fn compare_packets(accel: &Accel, expected: &[(TraceRay, Option<Hit>, bool)], views: &[u8]) {
    let mut stack = PacketStack::new();
    let isas: Vec<Isa> = Isa::ALL.into_iter().filter(|i| i.available()).collect();
    assert!(isas.contains(&Isa::Portable));
    for isa in isas {
        for (k, &view) in views.iter().enumerate() {
            let mine: Vec<usize> = (k..expected.len()).step_by(views.len()).collect();
            for (p, chunk) in mine.chunks(PACKET).enumerate() {
                let mut packet = RayPacket::new();
                for (lane, &i) in chunk.iter().enumerate() {
                    if !(p % 3 == 1 && lane == 5) {
                        packet.set(lane, &expected[i].0);
                    }
                }
                let mut closest = packet;
                accel.closest_packet(&mut closest, view, isa, &mut stack);
                let blocked = accel.occluded_packet(&packet, view, isa, &mut stack);
                for (lane, &i) in chunk.iter().enumerate() {
                    let (want_hit, want_blocked) = if packet.active >> lane & 1 != 0 {
                        (expected[i].1, expected[i].2)
                    } else {
                        (None, false)
                    };
                    let got = closest.hit(lane);
                    let bits = |h: Option<Hit>| h.map(|h| (h.prim, h.t.to_bits()));
                    assert_eq!(bits(got), bits(want_hit), "{isa:?} ray {i} (lane {lane})");
                    assert_eq!(
                        blocked >> lane & 1 != 0,
                        want_blocked,
                        "{isa:?} ray {i} (lane {lane}) shadow"
                    );
                }
            }
        }
    }
}

#[test]
fn a_packet_filled_axis_by_axis_equals_one_set_lane_by_lane() {
    // Directions with zero, signed-zero, tiny (below and above the 1e-20 clamp) and ordinary
    // components, from several origins; every count of rays from none to a full packet.
    let mut rays = special_rays();
    rays.extend(random_rays(Vec3::new(1.4, 1.2, 0.0), 40));
    for d in [
        Vec3::new(-0.0, 0.0, -1.0),
        Vec3::new(1e-21, -1e-21, 1.0),
        Vec3::new(-1e-20, 1e-20, -1.0),
        Vec3::new(3e-20, -2e-19, 1.0),
    ] {
        rays.push((Vec3::new(-2.0, 0.5, -7.0), d));
    }
    let fields = |p: &RayPacket, lane: usize| {
        let mut v: Vec<u32> = Vec::new();
        for a in 0..3 {
            v.extend([p.origin[a][lane], p.dir[a][lane], p.inv_dir[a][lane]].map(f32::to_bits));
        }
        v.extend([p.tmin[lane].to_bits(), p.tmax[lane].to_bits(), p.prim[lane]]);
        v
    };
    for (start, n) in (0..rays.len()).step_by(7).zip((0..=PACKET).cycle()) {
        let chunk: Vec<(Vec3, Vec3)> = rays.iter().cycle().skip(start).take(n).copied().collect();
        let mut by_lane = RayPacket::new();
        for (lane, &(o, d)) in chunk.iter().enumerate() {
            by_lane.set(lane, &make_ray(o, d, 0.0, f32::INFINITY));
        }
        let mut by_axis = RayPacket::new();
        by_axis.set_from_zero(n, |lane| chunk[lane]);
        assert_eq!(by_axis.active, by_lane.active, "{n} rays from {start}");
        for lane in 0..n {
            assert_eq!(
                fields(&by_axis, lane),
                fields(&by_lane, lane),
                "lane {lane} of {n}"
            );
        }
    }
}

#[test]
fn bench_batches_traced_in_packets_equal_them_traced_ray_by_ray() {
    // `bench`'s trace-only batches: camera rays in tiles, at a size whose last packet is
    // short (61 × 37 = 2257 rays, 2257 mod 16 = 1), and the sun's shadow rays from their hits.
    use seethru::render::throughput::{
        camera_batch, shadow_batch, trace_any, trace_any_per_ray, trace_closest,
        trace_closest_per_ray,
    };
    let scene = common::das();
    let world = World::build(&scene).unwrap();
    let accel = Accel::build(&world).unwrap();
    let sun =
        seethru::render::sky::SkyModel::new(&scene.sky, &scene.sun, scene.photometry.as_ref())
            .sun_direction;
    let camera = View::Truth.camera(&scene).with_resolution(61, 37);
    let primary = camera_batch(&camera, view_bit::TRUTH);
    let mut per_ray = vec![None; primary.rays.len()];
    trace_closest_per_ray(&accel, &primary, &mut per_ray);
    for isa in Isa::ALL.into_iter().filter(|i| i.available()) {
        let mut packets = vec![None; primary.rays.len()];
        trace_closest(&accel, &primary, isa, &mut packets);
        let bits = |h: &Option<Hit>| h.map(|h| (h.prim, h.t.to_bits()));
        let first_difference = (0..per_ray.len()).find(|&i| bits(&packets[i]) != bits(&per_ray[i]));
        assert_eq!(first_difference, None, "{isa:?}");
    }
    let hits = per_ray.iter().filter(|h| h.is_some()).count();
    assert!(
        hits > primary.rays.len() / 3 && hits < primary.rays.len(),
        "{hits}"
    );
    let shadow = shadow_batch(&world, &primary, &per_ray, sun);
    let mut per_ray = vec![false; shadow.rays.len()];
    trace_any_per_ray(&accel, &shadow, &mut per_ray);
    for isa in Isa::ALL.into_iter().filter(|i| i.available()) {
        let mut packets = vec![true; shadow.rays.len()];
        trace_any(&accel, &shadow, isa, &mut packets);
        assert_eq!(packets, per_ray, "{isa:?}");
    }
    let blocked = per_ray.iter().filter(|&&b| b).count();
    assert!(
        blocked > 0 && blocked < per_ray.len(),
        "{blocked} of {}",
        per_ray.len()
    );
}

#[test]
fn a_thread_stack_in_use_further_up_gives_way_to_a_fresh_one() {
    // A query made while this thread's stack is borrowed (a trace inside a trace) gets a
    // stack of its own, and the same answer, instead of a panic.
    use seethru::render::bvh::Stack;
    let scene = common::das();
    let world = World::build(&scene).unwrap();
    let accel = Accel::build(&world).unwrap();
    let ray = make_ray(
        scene.eye().as_vec3(),
        Vec3::new(0.0, -0.3, -1.0).normalize(),
        0.0,
        f32::INFINITY,
    );
    let mut packet = RayPacket::new();
    packet.set_from_zero(1, |_| (Vec3::from(ray.origin), Vec3::from(ray.dir)));
    let trace = |stack: &mut PacketStack| {
        let mut p = packet;
        accel.closest_packet(&mut p, view_bit::TRUTH, Isa::best(), stack);
        p.hit(0).map(|h| (h.prim, h.t.to_bits()))
    };
    let (outer, inner) = PacketStack::with_thread_stack(|outer| {
        (
            trace(outer),
            PacketStack::with_thread_stack(|inner| trace(inner)),
        )
    });
    assert!(outer.is_some());
    assert_eq!(inner, outer);
    let (outer, inner) = Stack::with_thread_stack(|outer| {
        let hit = |s: &mut Stack| accel.closest_with(&ray, view_bit::TRUTH, s);
        (hit(outer), Stack::with_thread_stack(|inner| hit(inner)))
    });
    assert_eq!(inner, outer);
    assert_eq!(
        outer.map(|h| (h.prim, h.t.to_bits())),
        trace(&mut PacketStack::new())
    );
}

/// Camera rays in 4×4 tiles: packets as the integrator makes them.
fn tiled_camera_rays(camera: &Camera) -> Vec<(Vec3, Vec3)> {
    let camera = camera.with_resolution(160, (160 * camera.height / camera.width).max(1));
    let rays = CameraRays::new(&camera);
    seethru::render::throughput::tile_order(camera.width, camera.height)
        .map(|(x, y)| (rays.origin, rays.direction(x as f32 + 0.5, y as f32 + 0.5)))
        .collect()
}

const ALL_VIEWS: [u8; 4] = [
    view_bit::TRUTH,
    view_bit::OCCLUDED,
    view_bit::FRONTAL,
    view_bit::BACK,
];

#[test]
fn closest_and_occluded_equal_brute_force() {
    let scene = common::das();
    let world = World::build(&scene).unwrap();
    let [ploc, binned] = both_builders(&world);
    // Boxes too big (or everything-boxes) and poor cuts still answer right: only the summed
    // area of the boxes, the surface-area cost of a traversal, shows them. The binned tree's
    // is 0.997 of PLOC's on das (1.043 where every small range was cut after its first item).
    assert!(
        binned.area() < 1.02 * ploc.area(),
        "{} against {}",
        binned.area(),
        ploc.area()
    );
    for accel in [ploc, binned] {
        let rays = random_rays(scene.eye().as_vec3(), 3000);
        let hits = compare(&world, &accel, &rays, &ALL_VIEWS);
        // The comparison means something only if many rays hit something and many miss.
        assert!(
            hits > rays.len() / 3 && hits < rays.len(),
            "{hits} hits of {}",
            rays.len()
        );
        let rays = special_rays();
        let hits = compare(&world, &accel, &rays, &ALL_VIEWS);
        assert!(hits > rays.len() / 4, "{hits} hits of {}", rays.len());
    }
}

/// The hierarchies of `world` by the builder before (PLOC's binary tree collapsed) and by the
/// binned builder.
fn both_builders(world: &World) -> [Accel; 2] {
    [BuildChoice::Ploc, BuildChoice::Binned].map(|choice| {
        let accel = Accel::build_with(world, choice).unwrap();
        let binned = accel.builders().iter().any(|&(b, _)| b == Builder::Binned);
        assert_eq!(
            binned,
            choice == BuildChoice::Binned,
            "{:?}",
            accel.builders()
        );
        accel
    })
}

/// The hierarchy of `world` built by `choice` on a pool of `threads` threads.
fn built_on(world: &World, choice: BuildChoice, threads: usize) -> Accel {
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .unwrap();
    pool.install(|| Accel::build_with(world, choice).unwrap())
}

#[test]
fn a_big_hierarchy_collapsed_side_by_side_equals_brute_force_on_any_thread_count() {
    // das grown eightfold, by the builder before: over the boxes from which the root's
    // subtrees are collapsed into wide nodes in parallel and appended.
    let scene = seethru::scene::grow::grow(&common::das(), 8.0).unwrap();
    let world = World::build(&scene).unwrap();
    assert!(world.triangles.len() > 1 << 16, "{}", world.triangles.len());
    let (one, two) = (
        built_on(&world, BuildChoice::Ploc, 1),
        built_on(&world, BuildChoice::Ploc, 2),
    );
    assert!(two.builders().iter().all(|&(b, _)| b == Builder::Ploc));
    // The same hierarchy whatever the threads: the same size and the same summed areas.
    assert_eq!(one.bytes(), two.bytes());
    assert_eq!(one.area().to_bits(), two.area().to_bits());
    let rays = random_rays(scene.eye().as_vec3(), 1500);
    let hits = compare(&world, &two, &rays, &ALL_VIEWS);
    assert!(hits > rays.len() / 3, "{hits} hits of {}", rays.len());
}

#[test]
fn a_large_hierarchy_is_binned_the_same_on_one_two_and_three_threads_and_equals_brute_force() {
    // das grown 24-fold: binned in chunks side by side and filled by halves side by side at
    // the top, built in subtrees side by side below: the tree must not depend on how the
    // work is split.
    let scene = seethru::scene::grow::grow(&common::das(), 24.0).unwrap();
    let world = World::build(&scene).unwrap();
    let one = built_on(&world, BuildChoice::Binned, 1);
    let binned = one.builders();
    assert_eq!(binned[0].0, Builder::Binned, "{binned:?}");
    assert!(binned[0].1 > 1 << 18, "{binned:?}");
    for threads in [2, 3] {
        let other = built_on(&world, BuildChoice::Binned, threads);
        assert_eq!(one.bytes(), other.bytes());
        assert_eq!(one.area().to_bits(), other.area().to_bits());
    }
    let rays = random_rays(scene.eye().as_vec3(), 1500);
    let hits = compare(&world, &one, &rays, &ALL_VIEWS);
    assert!(hits > rays.len() / 3, "{hits} hits of {}", rays.len());
}

#[test]
fn every_hierarchy_of_das_is_binned() {
    let world = World::build(&common::das()).unwrap();
    let builders = Accel::build(&world).unwrap().builders();
    assert!(
        builders.iter().all(|&(b, _)| b == Builder::Binned),
        "{builders:?}"
    );
}

#[test]
fn camera_rays_of_every_view_equal_brute_force() {
    let scene = common::das();
    let world = World::build(&scene).unwrap();
    for accel in both_builders(&world) {
        for view in View::ALL {
            let rays = camera_rays(&view.camera(&scene));
            let hits = compare(&world, &accel, &rays, &[view.bit()]);
            assert!(hits > rays.len() / 3, "{view:?}: {hits} of {}", rays.len());
        }
    }
}

#[test]
fn coherent_packets_of_every_view_and_their_shadow_rays_equal_brute_force() {
    // Whole tiles of camera rays (the integrator's packets), then the shadow rays toward the
    // sun from their hits, as the integrator casts them.
    let scene = common::das();
    let world = World::build(&scene).unwrap();
    let sun =
        seethru::render::sky::SkyModel::new(&scene.sky, &scene.sun, scene.photometry.as_ref())
            .sun_direction;
    for (accel, view) in both_builders(&world)
        .iter()
        .flat_map(|accel| View::ALL.map(|view| (accel, view)))
    {
        let rays = tiled_camera_rays(&view.camera(&scene));
        let hits = compare(&world, accel, &rays, &[view.bit()]);
        assert!(hits > rays.len() / 3, "{view:?}: {hits} of {}", rays.len());
        let shadow: Vec<(Vec3, Vec3)> = rays
            .iter()
            .filter_map(|&(o, d)| {
                let h = accel.closest(&make_ray(o, d, 0.0, f32::INFINITY), view.bit())?;
                let s = world.surface(h.prim, o, d, h.t);
                (s.normal.dot(sun) > 0.0).then(|| {
                    let r = seethru::render::integrator::shadow_ray(s.position, s.normal, sun);
                    (Vec3::from(r.origin), sun)
                })
            })
            .collect();
        // Shadow rays' tmax is infinite in the integrator: every fifth here is finite too.
        compare(&world, accel, &shadow, &[view.bit()]);
        assert!(shadow.len() > rays.len() / 4, "{view:?}: {}", shadow.len());
    }
}

#[test]
fn hidden_objects_are_invisible_only_in_their_views() {
    let scene = common::das();
    let world = World::build(&scene).unwrap();
    let accel = Accel::build(&world).unwrap();
    // From the eye towards the display centre: the obstacle in `occluded`, not in `truth`.
    let eye = scene.eye().as_vec3();
    let centre = scene.obstacle.world_from_obstacle.translation.as_vec3();
    let ray = make_ray(eye, (centre - eye).normalize(), 0.0, f32::INFINITY);
    let occluded = accel.closest(&ray, view_bit::OCCLUDED).unwrap();
    assert_eq!(world.object_of(occluded.prim), world.obstacle_id);
    let truth = accel
        .closest(&ray, view_bit::TRUTH)
        .map(|h| world.object_of(h.prim));
    assert_ne!(truth, Some(world.obstacle_id));
    // From the back camera towards the eye: the head in `back`; the driver never sees it.
    let back = scene.back.position().as_vec3();
    let ray = make_ray(back, (eye - back).normalize(), 0.0, f32::INFINITY);
    let head = accel.closest(&ray, view_bit::BACK).unwrap();
    let head_id = scene.objects.iter().position(|o| o.name == "head").unwrap() as u32 + 1;
    assert_eq!(world.object_of(head.prim), head_id);
    let ray = make_ray(
        eye + Vec3::new(0.0, 0.0, 0.5),
        Vec3::new(0.0, 0.0, -1.0),
        0.0,
        f32::INFINITY,
    );
    let seen = accel
        .closest(&ray, view_bit::TRUTH)
        .map(|h| world.object_of(h.prim));
    assert_ne!(seen, Some(head_id));
}

/// Loads `scene` (the minimal scene plus `extra`, mesh files `files` beside it), builds its
/// hierarchy and renders a small `truth` on a thread that must finish within `limit`; returns
/// the context. A build that is quadratic, or that fails, fails here.
fn build_and_render_within(
    extra: &str,
    files: &[(&str, String)],
    limit: std::time::Duration,
) -> seethru::render::integrator::RenderContext {
    let dir = tempfile::tempdir().unwrap();
    for (name, text) in files {
        std::fs::write(dir.path().join(name), text).unwrap();
    }
    let text = format!("{}{extra}", common::MINIMAL);
    let scene = common::parse_in(dir.path(), "scene.toml", &text).unwrap();
    let (send, receive) = std::sync::mpsc::channel();
    std::thread::spawn(move || {
        let ctx = seethru::render::integrator::RenderContext::new(scene).inspect(|ctx| {
            let camera = View::Truth.camera(&ctx.scene).with_resolution(32, 18);
            let settings = seethru::render::settings::RenderSettings {
                spp: 1,
                progress: false,
            };
            let _ = ctx.render(
                RenderJob::new(&camera, view_bit::TRUTH)
                    .settings(settings)
                    .label("truth"),
            );
        });
        let _ = send.send(ctx.map_err(|e| format!("{e:#}")));
    });
    match receive.recv_timeout(limit) {
        Ok(ctx) => ctx.unwrap(),
        Err(_) => panic!("the build and render took longer than {limit:?}"),
    }
}

/// Rays from around `centre` (within `spread` metres) in random directions, a third of them
/// aimed at `centre` itself.
fn rays_around(centre: Vec3, spread: f32, n: u32) -> Vec<(Vec3, Vec3)> {
    (0..n)
        .map(|i| {
            let u = |k| 2.0 * unit_float(hash_words(&[i, k])) - 1.0;
            let origin = centre + spread * Vec3::new(u(7), u(8).abs(), u(9));
            let dir = if i % 3 == 0 {
                (centre - origin).normalize()
            } else {
                random_unit(i + 17)
            };
            (origin, dir)
        })
        .collect()
}

const LIMIT: std::time::Duration = std::time::Duration::from_secs(8);

/// The hierarchy of `world` by the builder before (PLOC, or its top-down fallback), which
/// must finish within [`LIMIT`]: these are the arrangements that made PLOC quadratic.
fn ploc_within(world: &World) -> Accel {
    let start = std::time::Instant::now();
    let accel = Accel::build_with(world, BuildChoice::Ploc).unwrap();
    assert!(start.elapsed() < LIMIT, "{:?}", start.elapsed());
    accel
}

fn mesh(path: &str) -> String {
    format!(
        "\n[[object]]\nname = \"m\"\nkind = \"mesh\"\npath = \"{path}\"\nmaterial = \"grey\"\ntranslate = [0.0, 0.0, -5.0]\n"
    )
}

#[test]
fn a_mesh_of_coincident_triangles_builds_fast_and_equals_brute_force() {
    // 50 000 copies of one triangle (a mesh exported twice, many times over): PLOC merged one
    // pair per pass (minutes), then the hierarchy was too deep.
    let mut obj = String::from("v 0 0 0\nv 1 0 0\nv 0 1 0\n");
    obj.push_str(&"f 1 2 3\n".repeat(50_000));
    let ctx = build_and_render_within(&mesh("m.obj"), &[("m.obj", obj)], LIMIT);
    let rays = rays_around(Vec3::new(0.3, 0.3, -5.0), 2.0, 300);
    for accel in [&ctx.accel, &ploc_within(&ctx.world)] {
        let hits = compare(&ctx.world, accel, &rays, &ALL_VIEWS);
        assert!(hits > rays.len() / 4, "{hits} hits of {}", rays.len());
    }
}

#[test]
fn a_mesh_of_nested_triangles_builds_fast_and_equals_brute_force() {
    // 20 000 triangles sharing a corner, each larger than the last: every PLOC pass merged
    // the two smallest (a chain as deep as the triangles are many).
    let mut obj = String::new();
    for i in 1..=20_000 {
        let s = i as f32 * 1e-4;
        obj.push_str(&format!("v 0 0 0\nv {s} 0 0\nv 0 {s} 0\n"));
    }
    for i in 0..20_000 {
        obj.push_str(&format!("f {} {} {}\n", 3 * i + 1, 3 * i + 2, 3 * i + 3));
    }
    let ctx = build_and_render_within(&mesh("m.obj"), &[("m.obj", obj)], LIMIT);
    let rays = rays_around(Vec3::new(0.3, 0.3, -5.0), 2.0, 300);
    for accel in [&ctx.accel, &ploc_within(&ctx.world)] {
        let hits = compare(&ctx.world, accel, &rays, &ALL_VIEWS);
        assert!(hits > rays.len() / 4, "{hits} hits of {}", rays.len());
    }
}

fn boxes(n: usize, place: impl Fn(usize) -> [f32; 3]) -> String {
    (0..n)
        .map(|i| {
            let [x, y, z] = place(i);
            format!(
                "\n[[object]]\nkind = \"box\"\nmaterial = \"grey\"\nsize = [0.2, 1.0, 0.2]\ntranslate = [{x:?}, {y:?}, {z:?}]\n"
            )
        })
        .collect()
}

#[test]
fn many_identical_objects_build_fast_and_equal_brute_force() {
    // 3000 boxes at one place (a script that puts every object at the origin): 6 s, then
    // "the scene's hierarchy is deeper than 128 levels".
    let ctx = build_and_render_within(&boxes(3000, |_| [0.0, 0.5, -5.0]), &[], LIMIT);
    let rays = rays_around(Vec3::new(0.0, 0.5, -5.0), 2.0, 200);
    for accel in [&ctx.accel, &ploc_within(&ctx.world)] {
        let hits = compare(&ctx.world, accel, &rays, &ALL_VIEWS);
        assert!(hits > rays.len() / 4, "{hits} hits of {}", rays.len());
    }
}

#[test]
fn a_long_row_of_evenly_spaced_objects_builds_fast_and_equals_brute_force() {
    // 30 000 posts a metre apart (17 s before): the costs of neighbouring pairs tie exactly, and PLOC
    // merged a pair or two per pass.
    let ctx = build_and_render_within(
        &boxes(30_000, |i| [i as f32 - 15_000.0, 0.5, -5.0]),
        &[],
        LIMIT,
    );
    let rays = rays_around(Vec3::new(0.0, 0.5, -5.0), 3.0, 200);
    for accel in [&ctx.accel, &ploc_within(&ctx.world)] {
        let hits = compare(&ctx.world, accel, &rays, &ALL_VIEWS);
        assert!(hits > rays.len() / 8, "{hits} hits of {}", rays.len());
    }
}

/// An OBJ of `n` × `n` small squares (two triangles each, 0.1 m) on the plane y = 0.5 about
/// x = 0, z = −5, and, when `sliver`, a 40 m long, 1 m wide diagonal strip (two triangles)
/// just below them: its boxes are hundreds of times its area.
fn grid_obj(n: usize, sliver: bool) -> String {
    let mut obj = String::new();
    let mut faces = String::new();
    let mut v = 0;
    let mut quad = |corners: [(f32, f32); 4], y: f32, obj: &mut String| {
        for (x, z) in corners {
            obj.push_str(&format!("v {x} {y} {z}\n"));
        }
        faces.push_str(&format!(
            "f {} {} {}\nf {} {} {}\n",
            v + 1,
            v + 3,
            v + 2,
            v + 1,
            v + 4,
            v + 3
        ));
        v += 4;
    };
    for i in 0..n {
        for k in 0..n {
            let (x, z) = (
                0.12 * i as f32 - 0.06 * n as f32,
                0.12 * k as f32 - 0.06 * n as f32 - 5.0,
            );
            quad(
                [(x, z), (x + 0.1, z), (x + 0.1, z + 0.1), (x, z + 0.1)],
                0.5,
                &mut obj,
            );
        }
    }
    if sliver {
        quad(
            [(-20.0, -25.0), (-19.3, -25.7), (20.7, 14.3), (20.0, 15.0)],
            0.45,
            &mut obj,
        );
    }
    obj + &faces
}

#[test]
fn a_long_sliver_among_small_triangles_is_split_into_tight_boxes_and_equals_brute_force() {
    // The pre-splits give a triangle whose box is many times the average several tighter
    // boxes, which both builders take in; each split box must refer to it (das has no such
    // triangle: none of its boxes is split).
    let ctx = build_and_render_within(&mesh("m.obj"), &[("m.obj", grid_obj(40, true))], LIMIT);
    let triangles = ctx.world.triangles.len();
    let boxes: usize = ctx.accel.builders().iter().map(|&(_, b)| b).sum();
    let ellipsoids = ctx.world.primitive_count() - ctx.world.ellipsoid_base();
    assert!(
        boxes > triangles + ellipsoids + 10,
        "{boxes} boxes, {triangles} triangles"
    );
    // Rays down onto the strip, along it and across it, beside the small squares.
    let rays: Vec<(Vec3, Vec3)> = (0..400)
        .map(|i| {
            let u = |k| 2.0 * unit_float(hash_words(&[i, k])) - 1.0;
            let (along, across) = (19.0 * u(1), 0.3 * u(2));
            // The strip's centre line is z = x − 10.7 once the mesh is placed; it is 0.99 m wide.
            let origin = Vec3::new(along + across, 3.0, along - 10.7 - across);
            (
                origin,
                Vec3::new(0.05 * u(3), -1.0, 0.05 * u(4)).normalize(),
            )
        })
        .collect();
    for accel in [&ctx.accel, &ploc_within(&ctx.world)] {
        compare(&ctx.world, accel, &rays, &ALL_VIEWS);
        let on_strip = rays
            .iter()
            .filter_map(|&(o, d)| {
                accel
                    .closest(&make_ray(o, d, 0.0, f32::INFINITY), view_bit::TRUTH)
                    .map(|h| o + h.t * d)
            })
            .filter(|p| (p.y - 0.45).abs() < 1e-3)
            .count();
        assert!(
            on_strip > rays.len() / 2,
            "{on_strip} of {} on the strip",
            rays.len()
        );
    }
}

#[test]
fn ellipsoids_among_subtrees_built_apart_equal_brute_force() {
    // 135 000 small triangles and 100 balls over them: the binned builder makes the root's
    // subtrees apart, and their ellipsoid leaves must be moved by the ellipsoids before them.
    let balls: String = (0..100)
        .map(|i| {
            let (x, z) = (3.0 * (i % 10) as f32 - 13.5, 3.0 * (i / 10) as f32 - 23.5);
            format!(
                "\n[[object]]\nkind = \"sphere\"\nmaterial = \"grey\"\nradius = 0.2\ntranslate = [{x:?}, 0.8, {z:?}]\n"
            )
        })
        .collect();
    let extra = format!("{}{balls}", mesh("m.obj"));
    let ctx = build_and_render_within(&extra, &[("m.obj", grid_obj(260, false))], LIMIT);
    let rays: Vec<(Vec3, Vec3)> = (0..600)
        .map(|i| {
            let u = |k| 2.0 * unit_float(hash_words(&[i, k])) - 1.0;
            // Every other ray straight down near a ball (0.15 m from its centre at most).
            let ball = Vec3::new(
                3.0 * (i % 10) as f32 - 13.5,
                3.0,
                3.0 * (i / 10 % 10) as f32 - 23.5,
            );
            let origin = if i % 2 == 0 {
                Vec3::new(15.0 * u(1), 3.0, -10.0 + 15.0 * u(2))
            } else {
                ball + 0.1 * Vec3::new(u(1), 0.0, u(2))
            };
            (
                origin,
                Vec3::new(0.02 * u(3), -1.0, 0.02 * u(4)).normalize(),
            )
        })
        .collect();
    let binned = &ctx.accel;
    assert!(binned.builders().iter().all(|&(b, _)| b == Builder::Binned));
    let hits = compare(&ctx.world, binned, &rays, &ALL_VIEWS);
    assert!(hits > rays.len() / 2, "{hits} hits of {}", rays.len());
    let balls_hit = rays
        .iter()
        .filter_map(|&(o, d)| binned.closest(&make_ray(o, d, 0.0, f32::INFINITY), view_bit::TRUTH))
        .filter(|h| h.prim >= ctx.world.ellipsoid_base())
        .count();
    assert!(balls_hit > rays.len() / 3, "{balls_hit} balls hit");
}

/// The id of the object named `name` in `world` (its index in the objects plus one).
fn object_id(world: &World, name: &str) -> u32 {
    let i = world.objects.iter().position(|o| o.name == name);
    i.unwrap_or_else(|| panic!("no object {name}")) as u32 + 1
}

/// The moving layer of `scenes/das_mesh_head.toml` with the head mesh, the ball (an
/// ellipsoid) and the car; the head and the ball carried by `head` and `ball` (rigid
/// world_from_world maps), the car left in place.
fn moved_layers(
    head: DAffine3,
    ball: DAffine3,
    car: DAffine3,
) -> (MovingParts, Vec3, Vec3, impl Fn(u32) -> Option<DAffine3>) {
    let scene = Scene::load(&common::repo_path("scenes/das_mesh_head.toml")).unwrap();
    let names = ["head", "ball", "car"];
    let mut parts =
        MovingParts::new(&scene, &|i| names.contains(&scene.objects[i].name.as_str())).unwrap();
    let still = parts.at(&|_| None).unwrap();
    let id = |name| object_id(&still.world, name);
    let (head_id, ball_id, car_id) = (id("head"), id("ball"), id("car"));
    // Where the rays aim: the head's centre and the ball's, after the motion.
    let mut head_box = obvhs::aabb::Aabb::empty();
    for (t, attr) in still.world.triangles.iter().zip(&still.world.tri_attrs) {
        if attr.object == head_id {
            head_box = head_box.union(&t.aabb());
        }
    }
    let ball_centre = still
        .world
        .ellipsoids
        .iter()
        .find(|e| e.object == ball_id)
        .unwrap()
        .world_from_object
        .translation;
    let head_centre = head.transform_point3(Vec3::from(head_box.center()).as_dvec3());
    let ball_centre = ball.transform_point3(Vec3::from(ball_centre).as_dvec3());
    let motion = move |o: u32| {
        (o == head_id)
            .then_some(head)
            .or((o == ball_id).then_some(ball))
            .or((o == car_id && car != DAffine3::IDENTITY).then_some(car))
    };
    (parts, head_centre.as_vec3(), ball_centre.as_vec3(), motion)
}

/// A turn of `yaw` and `pitch` radians about `pivot`, then a shift by `shift`.
fn turn_about(pivot: DVec3, yaw: f64, pitch: f64, shift: DVec3) -> DAffine3 {
    DAffine3::from_translation(pivot + shift)
        * DAffine3::from_rotation_y(yaw)
        * DAffine3::from_rotation_x(pitch)
        * DAffine3::from_translation(-pivot)
}

#[test]
fn a_refitted_moving_layer_equals_a_rebuilt_one_and_brute_force() {
    // The head turned 20° and nodded 8° about a point behind it and shifted 6 cm; the ball
    // turned about the eye and lifted: both far past their boxes at t = 0.
    let eye = Scene::load(&common::repo_path("scenes/das_mesh_head.toml"))
        .unwrap()
        .eye();
    let head = turn_about(
        eye + DVec3::new(0.0, 0.0, 0.12),
        0.35,
        0.14,
        DVec3::new(0.06, 0.02, -0.03),
    );
    let ball = turn_about(eye, 0.25, 0.0, DVec3::new(0.0, 0.4, 0.0));
    let (parts, head_centre, ball_centre, motion) = moved_layers(head, ball, DAffine3::IDENTITY);
    assert_eq!(parts.builds, 1);
    let still = parts.at_rebuilt(&|_| None).unwrap();
    let rebuilt = parts.at_rebuilt(&motion).unwrap();
    let refitted = still.accel.refit(&rebuilt.world);
    let world = &rebuilt.world;
    let mut rays = rays_around(head_centre, 0.3, 3000);
    rays.extend(rays_around(ball_centre, 1.0, 1000));
    rays.extend(special_rays());
    // Refit and build each equal the brute force over the moved world, so each other.
    let hits = compare(world, &refitted, &rays, &ALL_VIEWS);
    assert_eq!(compare(world, &rebuilt.accel, &rays, &ALL_VIEWS), hits);
    // A ray at every moved primitive (from 30 cm off each triangle's front, at its centroid;
    // at each ellipsoid's centre from the eye): refit and build give the same answer, which
    // the build gives as the brute force does (above and the tests before).
    let mut aimed: Vec<(Vec3, Vec3)> = world
        .triangles
        .iter()
        .zip(&world.tri_attrs)
        .map(|(t, attr)| {
            let v0 = Vec3::from(t.v0);
            let centroid = (3.0 * v0 - Vec3::from(t.e1) + Vec3::from(t.e2)) / 3.0;
            (centroid + 0.3 * attr.normal, -attr.normal)
        })
        .collect();
    let eye = eye.as_vec3();
    aimed.extend(world.ellipsoids.iter().map(|e| {
        let c = Vec3::from(e.world_from_object.translation);
        (eye, (c - eye).normalize())
    }));
    for (i, &(o, d)) in aimed.iter().enumerate() {
        for view in ALL_VIEWS {
            let ray = make_ray(o, d, 0.0, f32::INFINITY);
            let bits = |h: Option<Hit>| h.map(|h| (h.prim, h.t.to_bits()));
            let (a, b) = (
                refitted.closest(&ray, view),
                rebuilt.accel.closest(&ray, view),
            );
            assert_eq!(
                bits(a),
                bits(b),
                "ray {i} at primitive {i} ({o}, {d}), view {view}"
            );
            let (a, b) = (
                refitted.occluded(&ray, view),
                rebuilt.accel.occluded(&ray, view),
            );
            assert_eq!(a, b, "shadow ray {i} ({o}, {d}), view {view}");
        }
    }
    // Many rays hit the moved head's triangles and the moved ball.
    let (head_id, ball_id) = (object_id(world, "head"), object_id(world, "ball"));
    let (mut on_head, mut on_ball) = (0, 0);
    for &(o, d) in &rays {
        let ray = make_ray(o, d, 0.0, f32::INFINITY);
        if let Some(h) = closest_brute_force(world, &ray, view_bit::BACK) {
            let object = world.object_of(h.prim);
            on_head += usize::from(object == head_id);
            on_ball += usize::from(object == ball_id);
        }
    }
    assert!(
        on_head > 500 && on_ball > 100,
        "{on_head} head hits, {on_ball} ball hits"
    );
}

#[test]
fn the_moving_layer_refits_rigid_motion_and_rebuilds_where_its_boxes_grow() {
    // The head sways 6 cm and turns 10°: alone in its group, it is refitted.
    let eye = Scene::load(&common::repo_path("scenes/das_mesh_head.toml"))
        .unwrap()
        .eye();
    let head = turn_about(eye, 0.17, 0.0, DVec3::new(0.06, 0.0, 0.0));
    let (mut parts, head_centre, _, motion) =
        moved_layers(head, DAffine3::IDENTITY, DAffine3::IDENTITY);
    let layer = parts.at(&motion).unwrap();
    assert_eq!((parts.builds, parts.refits), (1, 1));
    compare(
        &layer.world,
        &layer.accel,
        &rays_around(head_centre, 0.3, 600),
        &ALL_VIEWS,
    );
    // The ball thrown 30 m up, away from the car of its group: the binned tree holds it in a
    // leaf of the root apart from the car's subtrees, so its refit is as tight as a build.
    let up = DAffine3::from_translation(DVec3::new(0.0, 30.0, 0.0));
    let (mut parts, _, ball_centre, motion) =
        moved_layers(DAffine3::IDENTITY, up, DAffine3::IDENTITY);
    let layer = parts.at(&motion).unwrap();
    assert_eq!((parts.builds, parts.refits), (1, 1));
    compare(
        &layer.world,
        &layer.accel,
        &rays_around(ball_centre, 1.0, 600),
        &ALL_VIEWS,
    );
    // The car stretched fourfold along its length: every box of its subtrees grows, past the
    // refit's bound, so the layer is built afresh (and later instants refit that build).
    let stretch = DAffine3::from_scale(DVec3::new(4.0, 1.0, 1.0));
    let (mut parts, _, _, motion) = moved_layers(DAffine3::IDENTITY, DAffine3::IDENTITY, stretch);
    let layer = parts.at(&motion).unwrap();
    assert_eq!((parts.builds, parts.refits), (2, 0));
    let car = object_id(&layer.world, "car");
    let car_box = layer
        .world
        .triangles
        .iter()
        .zip(&layer.world.tri_attrs)
        .filter(|(_, a)| a.object == car)
        .fold(obvhs::aabb::Aabb::empty(), |b, (t, _)| b.union(&t.aabb()));
    compare(
        &layer.world,
        &layer.accel,
        &rays_around(Vec3::from(car_box.center()), 2.0, 600),
        &ALL_VIEWS,
    );
    parts.at(&motion).unwrap();
    assert_eq!((parts.builds, parts.refits), (2, 1));
}
