//! The flattened BVH finds exactly what brute force over all triangles finds.

use glam::Vec3;
use veach::cpu::bvh::{INF, NO_HIT, Ray, intersect_closest, intersect_triangle, occluded};
use veach::packed::PackedScene;
use veach::scene::{Material, Scene, Triangle};

mod common;

use common::rng::Lcg;

fn soup(count: usize, rng: &mut Lcg) -> Scene {
    let triangles = (0..count)
        .map(|_| {
            let c = rng.v() * 10.0;
            let p = [c + rng.v() - 0.5, c + rng.v() - 0.5, c + rng.v() - 0.5];
            let n = (p[1] - p[0]).cross(p[2] - p[0]).normalize_or_zero();
            Triangle { positions: p, normals: [n; 3], material: 0, ..Default::default() }
        })
        .collect();
    Scene { triangles, materials: vec![Material::default()], ..Default::default() }
}

/// A soup whose triangles take turns between an opaque material, a BLEND one (alpha 0.5: hit
/// by a hash of the ray) and a MASK one under its cutoff (never hit), so that the leaf test's
/// alpha path is walked.
fn alpha_soup(count: usize, rng: &mut Lcg) -> Scene {
    let mut scene = soup(count, rng);
    for (i, t) in scene.triangles.iter_mut().enumerate() {
        t.material = (i % 3) as u32;
    }
    let blend = Material { alpha: 0.5, alpha_mode: veach::scene::AlphaMode::Blend, ..Default::default() };
    let mask = Material { alpha: 0.3, alpha_mode: veach::scene::AlphaMode::Mask(0.5), ..Default::default() };
    scene.materials = vec![Material::default(), blend, mask];
    scene
}

/// Forty placements of one soup mesh (some mirrored, scaled, turned) beside a world mesh:
/// the walk through the top level and into each instance's mesh.
fn instanced_soup(rng: &mut Lcg) -> Scene {
    let mut scene = soup(200, rng);
    let mesh = soup(500, rng).triangles;
    scene.meshes.push(veach::scene::Mesh { name: "soup".into(), triangles: mesh });
    for k in 0..40 {
        let offset = rng.v() * 20.0 - 5.0;
        let scale = Vec3::new(if k % 5 == 0 { -1.0 } else { 1.0 }, 0.5 + rng.f(), 1.0);
        let rotation = glam::Quat::from_axis_angle((rng.v() - 0.5).normalize_or(Vec3::Y), rng.f() * 6.0);
        let transform = glam::Mat4::from_scale_rotation_translation(scale, rotation, offset);
        scene.instances.push(veach::scene::Instance { mesh: 0, transform });
    }
    scene
}

fn check(scene: &Scene, rays: usize, rng: &mut Lcg) {
    check_with(scene, rays, rng, |rng| (rng.v() * 2.0 - 1.0).normalize());
}

fn check_with(scene: &Scene, rays: usize, rng: &mut Lcg, mut direction: impl FnMut(&mut Lcg) -> Vec3) {
    let packed = PackedScene::new(scene);
    let b = scene.bounds();
    let (lo, size) = (b.min - 0.2 * b.diagonal(), 1.4 * b.diagonal());
    let mut hits = 0;
    for _ in 0..rays {
        let origin = lo + rng.v() * size;
        let dir = direction(rng);
        let ray = Ray { origin, dir };
        let bvh = intersect_closest(&packed, &ray);
        let mut brute = (INF, NO_HIT);
        for (i, t) in packed.triangles.iter().enumerate() {
            let r = intersect_triangle(&ray, t);
            if r.x < brute.0 {
                brute = (r.x, i as u32);
            }
        }
        // Same triangle code on both sides: the distances agree exactly (ties on shared
        // edges may name either triangle).
        assert_eq!(bvh.t.to_bits(), brute.0.to_bits(), "ray {origin} {dir}: bvh {bvh:?} vs brute {brute:?}");
        if brute.1 != NO_HIT {
            hits += 1;
            let tri = &packed.triangles[bvh.tri as usize];
            assert_eq!(intersect_triangle(&ray, tri).x, bvh.t);
            // Any-hit agrees: blocked just beyond the hit, free just before it.
            assert!(occluded(&packed, &ray, bvh.t * 1.0001));
        } else {
            assert!(!occluded(&packed, &ray, INF));
        }
    }
    assert!(hits > rays / 20, "the test rays should hit something ({hits}/{rays})");
}

#[test]
fn bvh_closest_hit_equals_brute_force() {
    let mut rng = Lcg(7);
    check(&soup(3000, &mut rng), 10_000, &mut rng);
    for name in ["cornell-box.gltf", "furnace-a080.gltf", "veach-mis.gltf"] {
        let (scene, _) = common::load_pair(&common::asset(name), None).expect("asset loads");
        check(&scene, 10_000, &mut rng);
    }
}

/// Directions with exactly zero components: the quantised boxes' coordinate 0 meets an
/// infinite 1/dir there unless traversal guards it (0 · ∞ = NaN would miss the box).
#[test]
fn bvh_finds_hits_of_axis_parallel_rays() {
    let mut rng = Lcg(11);
    let axis_parallel = |rng: &mut Lcg| {
        let mut d = rng.v() * 2.0 - 1.0;
        let k = (rng.f() * 6.0) as usize;
        match k {
            0..=2 => d[k] = 0.0,
            _ => d = Vec3::AXES[k - 3] * if d.x < 0.0 { -1.0 } else { 1.0 },
        }
        d.normalize()
    };
    check_with(&soup(3000, &mut rng), 10_000, &mut rng, axis_parallel);
    let (scene, _) = common::load_pair(&common::asset("cornell-box.gltf"), None).expect("asset loads");
    check_with(&scene, 10_000, &mut rng, axis_parallel);
}

#[test]
fn bvh_of_an_empty_scene_misses() {
    let packed = PackedScene::new(&Scene::default());
    let ray = Ray { origin: Vec3::ZERO, dir: Vec3::Z };
    assert_eq!(intersect_closest(&packed, &ray).tri, NO_HIT);
}

/// The measured depth is plausible for an 8-wide tree, and a scene deeper than the traversal
/// stacks is refused with a named limit instead of rendering with missed hits.
#[test]
fn bvh_depth_is_measured_and_bounded() {
    let mut rng = Lcg(3);
    let scene = soup(3000, &mut rng);
    let mut packed = PackedScene::new(&scene);
    // 3000 triangles, at most 3 a leaf and 8 children a node: at least 4 levels.
    assert!((4..=veach::accel::MAX_DEPTH).contains(&packed.bvh_depth), "depth {}", packed.bvh_depth);
    packed.bvh_depth = veach::accel::MAX_DEPTH + 1;
    let camera = scene.camera(None).expect("camera");
    match veach::Renderer::new(packed, &camera, &common::settings(8, 1, 0), veach::Backend::Cpu) {
        Err(veach::Error::Limit(m)) => assert!(m.contains("levels deep"), "{m}"),
        Err(e) => panic!("expected a limit error, got {e}"),
        Ok(_) => panic!("a BVH deeper than the stacks was accepted"),
    }
}

/// Zero-area triangles (glTF nodes scaled to 0 at rest) stay out of the tree: 2000 of them
/// at one point among a soup made PLOC chain them ~90 levels deep, past the traversal stacks.
/// Every triangle keeps its place in the packed scene, and hits are what brute force finds.
#[test]
fn zero_area_triangles_stay_out_of_the_tree() {
    let mut rng = Lcg(5);
    let mut scene = soup(2000, &mut rng);
    let p = Vec3::splat(3.0);
    let point = Triangle { positions: [p; 3], normals: [Vec3::Z; 3], material: 0, ..Default::default() };
    scene.triangles.extend(std::iter::repeat_n(point, 2000));
    let packed = PackedScene::new(&scene);
    assert!(packed.bvh_depth <= 8, "depth {}", packed.bvh_depth);
    let mut order = packed.order.clone();
    order.sort_unstable();
    assert!(order.iter().copied().eq(0..4000u32), "every triangle is packed once");
    check(&scene, 5_000, &mut rng);
}

/// The AVX2 walk (eight children a node in one pass, POPCNT/LZCNT, leaf triangles eight at a
/// time), which `trace` runs on CPUs that have it, finds the baseline walk's hits bit for bit —
/// same triangle, t, u, v — and the same occlusion answers: random rays through triangle soups
/// (sparse, dense, a deep tree of 200k, alpha-masked and blended, instanced and mirrored), the
/// bundled scenes, axis-parallel and grazing rays, and rays that start on a surface. Two walks
/// in step (`trace_pair`) find, for each ray, the hit it gets alone.
#[test]
#[cfg_attr(not(target_arch = "x86_64"), ignore = "the AVX2 walk exists on x86-64 only")]
fn the_avx2_walk_finds_the_baseline_walks_hits() {
    #[cfg(target_arch = "x86_64")]
    {
        use veach::cpu::bvh::{
            Hit, intersect_closest_batch, occluded_batch, trace, trace_baseline, trace_pair, wide_walk_available,
        };
        assert!(wide_walk_available(), "this CPU has no AVX2: the wide walk cannot be tested here");
        let mut rng = Lcg(41);
        let mut scenes = vec![soup(300, &mut rng), soup(3000, &mut rng), soup(200_000, &mut rng)];
        scenes.push(alpha_soup(3000, &mut rng));
        scenes.push(instanced_soup(&mut rng));
        for name in ["cornell-box.gltf", "cornell-glass.gltf", "furnace-a080.gltf", "veach-mis.gltf"] {
            scenes.push(common::load_pair(&common::asset(name), None).expect("asset loads").0);
        }
        let (mut compared, mut hits) = (0, 0);
        let bits = |h: &Hit| (h.t.to_bits(), h.tri, h.u.to_bits(), h.v.to_bits(), h.instance);
        for scene in &scenes {
            let packed = PackedScene::new(scene);
            let b = scene.bounds();
            let (lo, size) = (b.min - 0.2 * b.diagonal(), 1.4 * b.diagonal());
            let mut traced = Vec::new();
            for k in 0..20_000 {
                let tri =
                    &packed.triangles[(rng.f() * packed.triangles.len() as f32) as usize % packed.triangles.len()];
                let (p0, e1, e2) = (Vec3::from(tri.p0), Vec3::from(tri.e1), Vec3::from(tri.e2));
                let (a, c) = (rng.f(), rng.f());
                let on_surface = p0 + e1 * a.min(1.0 - c) + e2 * c.min(1.0 - a);
                let mut dir = (rng.v() * 2.0 - 1.0).normalize();
                let origin = match k % 4 {
                    0 | 1 => lo + rng.v() * size,
                    2 => on_surface,
                    _ => {
                        // Grazing: along the triangle's plane, from just off it.
                        dir = (e1 * (rng.f() - 0.5) + e2 * (rng.f() - 0.5)).normalize();
                        on_surface - dir * size.length() * 0.5
                    }
                };
                if k % 7 == 0 {
                    let axis = (rng.f() * 3.0) as usize % 3;
                    dir[axis] = 0.0;
                    dir = dir.normalize();
                }
                if !dir.is_finite() {
                    continue;
                }
                let ray = Ray { origin, dir };
                traced.push(ray);
                let (wide, base) = (trace(&packed, &ray, INF, false), trace_baseline(&packed, &ray, INF, false));
                assert_eq!(bits(&wide), bits(&base), "ray {origin} {dir}: AVX2 {wide:?} vs baseline {base:?}");
                for t_max in [INF, base.t * 1.0001, base.t * 0.9999, 0.5] {
                    let (w, b) = (trace(&packed, &ray, t_max, true), trace_baseline(&packed, &ray, t_max, true));
                    assert_eq!(
                        w.tri != NO_HIT,
                        b.tri != NO_HIT,
                        "scene {} ray {origin} {dir} t_max {t_max}: occlusion differs {w:?} {b:?}",
                        packed.triangles.len()
                    );
                    assert_eq!(
                        bits(&w),
                        bits(&b),
                        "ray {origin} {dir} t_max {t_max}: any-hit AVX2 {w:?} vs baseline {b:?}"
                    );
                }
                compared += 1;
                hits += (base.tri != NO_HIT) as u32;
            }
            // Two walks in step (`trace_pair`; instanced scenes walk one after the other): each
            // ray's hit is the one it gets traced alone, closest and any, whatever its partner.
            for (n, pair) in traced.chunks_exact(2).enumerate() {
                let any_hit = n % 2 == 1;
                let t_max = [if n % 3 == 0 { 0.5 } else { INF }, if n % 5 == 0 { 0.25 } else { INF }];
                let both = trace_pair(&packed, [&pair[0], &pair[1]], t_max, any_hit);
                for k in 0..2 {
                    let alone = trace(&packed, &pair[k], t_max[k], any_hit);
                    assert_eq!(
                        bits(&both[k]),
                        bits(&alone),
                        "ray {:?} in a pair: {:?} alone {alone:?}",
                        pair[k],
                        both[k]
                    );
                }
            }
            // The batch API (in pairs, an odd ray alone) answers as `trace` does ray by ray.
            let odd = &traced[..traced.len() - 1 + traced.len() % 2];
            let mut batch = vec![Hit { t: 0.0, tri: 0, u: 0.0, v: 0.0, instance: 0 }; odd.len()];
            intersect_closest_batch(&packed, odd, &mut batch);
            let t_max: Vec<f32> = (0..odd.len()).map(|k| if k % 3 == 0 { 0.5 } else { INF }).collect();
            let mut blocked = vec![false; odd.len()];
            occluded_batch(&packed, odd, &t_max, &mut blocked);
            for (k, ray) in odd.iter().enumerate() {
                assert_eq!(bits(&batch[k]), bits(&trace(&packed, ray, INF, false)), "batch ray {ray:?}");
                assert_eq!(blocked[k], trace(&packed, ray, t_max[k], true).tri != NO_HIT, "batch segment {ray:?}");
            }
        }
        assert!(hits > compared / 5, "the rays should hit often ({hits} of {compared})");
    }
}
