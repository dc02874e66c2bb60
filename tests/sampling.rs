//! Light sampling, environment-map sampling, the triangle warp and the thin lens draw what
//! their pdfs claim: the shared chi-square harness (tests/common/chi2.rs), as for the BSDFs.

mod common;

use common::rng::Lcg;

use common::build::{GltfBuilder, MeshData};
use common::chi2::{self, SphereBins};
use glam::{Vec2, Vec3};
use serde_json::json;
use veach::cpu::bvh::{NO_HIT, Ray, intersect_closest};
use veach::cpu::environment::{environment_pdf, sample_environment};
use veach::cpu::light_tree::LightContext;
use veach::cpu::lights::{light_pdf, sample_light};
use veach::cpu::sampling::{bilinear_pdf, sample_bilinear, sample_uniform_disk, sample_uniform_triangle};
use veach::params::Params;
use veach::{Environment, EnvironmentMap, LightSampler, PackedScene, Settings};

/// A sky brighter towards +Y and in one hot spot: far from uniform in every direction.
fn sky() -> EnvironmentMap {
    let (w, h) = (32u32, 16u32);
    let texels = (0..w * h)
        .map(|i| {
            let (x, y) = (i % w, i / w);
            let up = 1.0 + 4.0 * (1.0 - y as f32 / h as f32);
            let spot = if (10..13).contains(&x) && (4..6).contains(&y) { 40.0 } else { 0.0 };
            Vec3::new(up + spot, up, 0.5 * up + spot)
        })
        .collect();
    EnvironmentMap { width: w, height: h, texels }
}

/// Three lamps of different size, power and orientation around the origin, disjoint in
/// direction as seen from it (so the density of a direction is one lamp's), and a sky.
fn lamps(with_sky: bool, light_sampler: LightSampler) -> (PackedScene, Params) {
    const H: f32 = std::f32::consts::FRAC_1_SQRT_2;
    let dir = tempfile::tempdir().unwrap();
    let mut b = GltfBuilder::new(dir.path(), "lamps");
    for (k, (emission, half, translation, rotation)) in [
        ([8.0, 8.0, 8.0], 0.5, [0.0, 2.0, 0.0], [H, 0.0, 0.0, H]),
        ([2.0, 1.0, 0.5], 1.5, [3.0, 0.0, 0.0], [0.0, -H, 0.0, H]),
        ([20.0, 20.0, 20.0], 0.2, [0.0, -0.5, -1.0], [0.0, 0.0, 0.0, 1.0]),
    ]
    .into_iter()
    .enumerate()
    {
        let m = b.material(json!({"emissiveFactor": emission, "name": format!("lamp{k}")}));
        let mesh = b.mesh(&MeshData::quad(-half, -half, half, half, 0.0, MeshData::UPRIGHT), m);
        b.node(json!({"mesh": mesh, "translation": translation, "rotation": rotation}));
    }
    b.camera(0.8, 1.0, [0.0, 0.0, 5.0]);
    let (scene, camera) = common::load_pair(&b.write(), None).unwrap();
    let mut packed = PackedScene::new(&scene);
    let env = if with_sky { Environment::map(sky(), Vec3::ONE) } else { Environment::constant(Vec3::ZERO) };
    packed.set_environment(&env);
    let settings = Settings { light_sampler, ..Settings::default() };
    let params = Params::new(&camera, &settings, settings.window(), &packed);
    assert_eq!(params.light_sampler, light_sampler as u32);
    (packed, params)
}

/// The densities of direction `wi` from `origin` under `sample_light`'s two techniques: the
/// environment's, and the lamp's the ray meets (front faces only), as the integrator's MIS
/// weights use them. The environment's radiance is blocked where a lamp is, so a sample
/// reports the density of the technique that drew it; the directions are drawn from the sum.
fn light_densities(scene: &PackedScene, params: &Params, ctx: &LightContext, wi: Vec3) -> (f64, f64) {
    let origin = ctx.point;
    let env = if params.env_select > 0.0 { environment_pdf(scene, params, wi) as f64 } else { 0.0 };
    let hit = intersect_closest(scene, &Ray { origin, dir: wi });
    let mut lamp = 0.0;
    if hit.tri != NO_HIT {
        let tri = &scene.triangles[hit.tri as usize];
        let n = Vec3::from(tri.e1).cross(Vec3::from(tri.e2)).normalize();
        let cos = -wi.dot(n);
        if tri.light_pdf_area > 0.0 && cos > 0.0 {
            lamp = light_pdf(scene, params, ctx, tri, wi, hit.t * hit.t, cos) as f64;
        }
    }
    (env, lamp)
}

/// Both light samplers, from points in the open and (tree) at a reflecting surface whose
/// tangent plane hides the lowest lamp: the tree must give that lamp probability 0, and its
/// density (tree walk × triangle pdf) must be what MIS evaluates on a hit.
#[test]
fn light_sampling_matches_its_pdf() {
    let free = |p: Vec3| LightContext { point: p, normal: Vec3::Z, reflect_only: false };
    let mut cases = Vec::new();
    // (Resampling draws its candidates with the tree's `sample_light`; what it keeps has no
    // density to test against: tests/light_resampling.rs checks it is unbiased.)
    for sampler in [LightSampler::Power, LightSampler::Tree] {
        cases.push((sampler, false, free(Vec3::ZERO)));
        cases.push((sampler, true, free(Vec3::ZERO)));
        cases.push((sampler, true, free(Vec3::new(0.3, 0.4, -0.2))));
    }
    let floor = LightContext { point: Vec3::new(0.0, -0.25, 0.0), normal: Vec3::Y, reflect_only: true };
    cases.push((LightSampler::Tree, false, floor));
    for &(sampler, with_sky, ctx) in &cases {
        let (scene, params) = lamps(with_sky, sampler);
        assert_eq!(params.light_count, 6, "three quads, two triangles each");
        let mut rng = Lcg(3);
        let edge = std::cell::Cell::new(0usize);
        let what = format!(
            "sample_light ({} sampler, sky {with_sky}, from {}, normal {})",
            sampler.label(),
            ctx.point,
            ctx.normal
        );
        let sample = || {
            let ls = sample_light(&scene, &params, &ctx, Vec3::new(rng.f(), rng.f(), rng.f()));
            if ls.pdf <= 0.0 {
                return None;
            }
            // The pdf a sample reports is its technique's density of its direction.
            let (env, lamp) = light_densities(&scene, &params, &ctx, ls.wi);
            let close = |d: f64| (d - ls.pdf as f64).abs() <= 2e-3 * d + 1e-6;
            if !(close(env) || close(lamp)) && sampler == LightSampler::Tree {
                // Solid-angle samples can land on a lamp's edge (barycentrics clamped after
                // rounding), where the checking ray slips past or into the neighbouring
                // triangle: rare, counted below.
                edge.set(edge.get() + 1);
                return Some(ls.wi);
            }
            assert!(close(env) || close(lamp), "{what}: pdf {} vs densities {env}, {lamp}", ls.pdf);
            if ctx.reflect_only {
                // The lamp in the plane z = −1 lies wholly below the tangent plane.
                let low_lamp = (ls.point.z + 1.0).abs() < 1e-3 && ls.point.x.abs() < 0.5;
                assert!(!low_lamp, "{what}: a lamp below the tangent plane was chosen");
            }
            Some(ls.wi)
        };
        // The lamps' silhouettes cut bins: 64² midpoint cells a bin resolve the slivers.
        let bins = SphereBins { theta: 24, phi: 48, sub: 64, pole_sub: 64 };
        let density = |wi| {
            let (env, lamp) = light_densities(&scene, &params, &ctx, wi);
            env + lamp
        };
        let r = chi2::sphere(&what, bins, 300_000, sample, density);
        // Arvo in f32 puts about 2e-4 of samples a hair outside an edge (then clamped onto it).
        assert!(edge.get() <= 300, "{what}: {} of 300000 samples off their triangle", edge.get());
        // The lamps the tree keeps share all of the probability.
        assert!(r.total > 0.99 && r.total < 1.01, "{what}: the density integrates to {}", r.total);
        r.assert_passes(&what, 0.01, cases.len());
    }
}

#[test]
fn environment_sampling_matches_its_pdf() {
    let mut scene = PackedScene::new(&veach::Scene::default());
    scene.set_environment(&Environment::map(sky(), Vec3::ONE));
    let camera = veach::Camera::from_matrix("c".into(), glam::Mat4::IDENTITY, 0.8);
    let params = Params::new(&camera, &Settings::default(), Settings::default().window(), &scene);
    assert_eq!(params.env_select, 1.0);
    let mut rng = Lcg(5);
    let sample = || Some(sample_environment(&scene, &params, Vec2::new(rng.f(), rng.f())));
    // Texel edges (uniform in θ) cut the bins (uniform in cos θ): 32² cells a bin.
    let bins = SphereBins { theta: 32, phi: 64, sub: 32, pole_sub: 32 };
    let r = chi2::sphere("sample_environment", bins, 400_000, sample, |wi| environment_pdf(&scene, &params, wi) as f64);
    assert!((r.total - 1.0).abs() < 5e-3, "the environment pdf integrates to {}", r.total);
    r.assert_passes("sample_environment", 0.01, 1);
}

#[test]
fn triangle_and_lens_warps_match_their_pdfs() {
    let mut rng = Lcg(7);
    let r = chi2::plane(
        "sample_uniform_triangle",
        (Vec2::ZERO, Vec2::ONE),
        (20, 8),
        200_000,
        || Some(sample_uniform_triangle(Vec2::new(rng.f(), rng.f()))),
        // Midpoints of the cells the edge x + y = 1 cuts lie on it: half of such a cell is in.
        |b| match b.x + b.y - 1.0 {
            d if d.abs() < 1e-5 => 1.0,
            d if d < 0.0 => 2.0,
            _ => 0.0,
        },
    );
    r.assert_passes("sample_uniform_triangle", 0.01, 2);
    let r = chi2::plane(
        "sample_uniform_disk (the thin lens)",
        (Vec2::splat(-1.0), Vec2::ONE),
        // The circle cuts cells: 64² a bin.
        (20, 64),
        200_000,
        || Some(sample_uniform_disk(Vec2::new(rng.f(), rng.f()))),
        |p| if p.length_squared() <= 1.0 { std::f64::consts::FRAC_1_PI } else { 0.0 },
    );
    r.assert_passes("sample_uniform_disk (the thin lens)", 0.01, 2);
}

/// The receiver-cosine warp: `sample_bilinear` draws `bilinear_pdf`, for weights as the
/// light sampler makes them (two equal corners) and for skewed ones down to the 0.01 floor.
#[test]
fn bilinear_warp_matches_its_pdf() {
    let mut rng = Lcg(11);
    for w in [[0.8, 0.8, 0.3, 0.6], [0.01, 0.01, 1.0, 0.2], [1.0, 0.05, 0.4, 0.01], [0.5; 4]] {
        let what = format!("sample_bilinear {w:?}");
        let r = chi2::plane(
            &what,
            (Vec2::ZERO, Vec2::ONE),
            (20, 4),
            200_000,
            || Some(sample_bilinear(Vec2::new(rng.f(), rng.f()), w)),
            |p| bilinear_pdf(p, w) as f64,
        );
        assert!((r.total - 1.0).abs() < 1e-3, "{what}: the density integrates to {}", r.total);
        r.assert_passes(&what, 0.01, 4);
    }
}

/// `invert_spherical_triangle_sample` undoes `sample_spherical_triangle` closely enough that
/// the warp's density read at the inverted sample (what a BSDF hit's MIS weight uses) is the
/// one the light sample reported, for triangles across the solid-angle range the light
/// sampler uses and receivers that see them from the front, edge-on and at a slant.
#[test]
fn spherical_triangle_inversion_recovers_the_sample() {
    use veach::cpu::spherical_triangle::{
        SOLID_ANGLE_MAX, SOLID_ANGLE_MIN, invert_spherical_triangle_sample, sample_spherical_triangle,
        spherical_triangle_area,
    };
    let mut rng = Lcg(23);
    for s in [2.0f32, 3.0, 8.0, 30.0] {
        let v = [Vec3::new(0.0, 0.0, 3.0), Vec3::new(s, 0.0, 3.0), Vec3::new(0.0, 0.8 * s, 3.0 + 0.5 * s)];
        let omega = spherical_triangle_area(Vec3::ZERO, v[0], v[1], v[2]);
        assert!((SOLID_ANGLE_MIN..=SOLID_ANGLE_MAX).contains(&omega), "size {s}: Ω = {omega}");
        for n in [Vec3::Z, Vec3::X, Vec3::new(-0.6, 0.3, 0.74).normalize()] {
            let c = |p: Vec3| n.dot(p.normalize()).abs().max(0.01);
            let weights = [c(v[1]), c(v[1]), c(v[0]), c(v[2])];
            let mut worst = 0.0f32;
            for _ in 0..20_000 {
                let u = sample_bilinear(Vec2::new(rng.f(), rng.f()), weights);
                let w = sample_spherical_triangle(Vec3::ZERO, v[0], v[1], v[2], u.x, u.y).expect("sample");
                let back = invert_spherical_triangle_sample(Vec3::ZERO, v[0], v[1], v[2], w);
                worst = worst.max((bilinear_pdf(back, weights) / bilinear_pdf(u, weights) - 1.0).abs());
            }
            assert!(worst < 0.02, "size {s} (Ω = {omega}), normal {n}: the density read back is off by {worst}");
        }
    }
}

/// Random triangles seen from log-uniform distances of 0.1 to 100 triangle sizes: (p, p0, e1, e2).
fn shortcut_cases(n: usize) -> Vec<[Vec3; 4]> {
    let mut rng = Lcg(29);
    let mut v3 = |scale: f32| Vec3::new(rng.f() - 0.5, rng.f() - 0.5, rng.f() - 0.5) * scale;
    (0..n)
        .map(|i| {
            let (p0, e1, e2) = (v3(2.0), v3(2.0), v3(2.0));
            let dist = 10f32.powf(-1.0 + 3.0 * (i as f32 / n as f32));
            let p = p0 + v3(1.0).normalize_or_zero() * dist * e1.length().max(e2.length());
            [p, p0, e1, e2]
        })
        .collect()
}

/// The cheap test that skips the exact solid angle never skips a triangle the exact formula
/// would sample by solid angle (so the shortcut changes no choice), and does skip distant
/// ones (so it is not vacuous): random triangles from random points at distances spanning
/// the threshold.
#[test]
fn the_solid_angle_shortcut_is_conservative() {
    use veach::cpu::spherical_triangle::{SOLID_ANGLE_MIN, spherical_triangle_area, surely_below_solid_angle_min};
    let (mut skipped, mut by_plane, mut kept_small) = (0, 0, 0);
    for [p, p0, e1, e2] in shortcut_cases(200_000) {
        let omega = spherical_triangle_area(p, p0, p0 + e1, p0 + e2);
        if surely_below_solid_angle_min(p, p0, e1, e2) {
            assert!(omega < SOLID_ANGLE_MIN, "skipped a triangle of Ω = {omega} ≥ {SOLID_ANGLE_MIN}");
            skipped += 1;
            by_plane += u32::from(!sphere_bound_skips(p, p0, e1, e2));
        } else if omega < SOLID_ANGLE_MIN {
            kept_small += 1;
        }
    }
    assert!(skipped > 50_000, "the shortcut skipped only {skipped} of 200000");
    // The second bound (A·h/(d − r)³) is not vacuous: it skips triangles the ball's cap keeps.
    assert!(by_plane > 5_000, "the plane bound skipped only {by_plane} the ball's did not");
    println!(
        "skipped {skipped} ({by_plane} by the plane bound), left to the exact formula below the threshold {kept_small}"
    );
}

/// The ball's bound of `surely_below_solid_angle_min` alone.
fn sphere_bound_skips(p: Vec3, p0: Vec3, e1: Vec3, e2: Vec3) -> bool {
    use veach::cpu::spherical_triangle::SOLID_ANGLE_MIN;
    let c = p0 + (e1 + e2) / 3.0;
    let r2 = (p0 - c).length_squared().max((p0 + e1 - c).length_squared()).max((p0 + e2 - c).length_squared());
    6.35 * r2 < SOLID_ANGLE_MIN * (p - c).length_squared()
}

/// The WGSL twin of the shortcut decides as the Rust one does, and is as conservative: run on
/// the GPU over the same triangles, it skips the same ones (apart from ties within float
/// rounding of its two sides) and never one whose exact solid angle reaches the threshold.
#[test]
#[cfg_attr(veach_no_gpu, ignore = "needs a GPU adapter (no Vulkan driver on this machine)")]
fn the_wgsl_solid_angle_shortcut_decides_as_the_rust_one() {
    use veach::cpu::spherical_triangle::{SOLID_ANGLE_MIN, spherical_triangle_area, surely_below_solid_angle_min};
    let Some(ctx) = common::gpu("the_wgsl_solid_angle_shortcut_decides_as_the_rust_one") else { return };
    let cases = shortcut_cases(200_000);
    let input: Vec<[f32; 4]> = cases.iter().flatten().map(|v| v.extend(0.0).to_array()).collect();
    let body = "let p = probe_in[i * 4u].xyz;
    let p0 = probe_in[i * 4u + 1u].xyz;
    let e1 = probe_in[i * 4u + 2u].xyz;
    let e2 = probe_in[i * 4u + 3u].xyz;
    let skip = surely_below_solid_angle_min(p, p0, e1, e2);
    let omega = spherical_triangle_area(p, p0, p0 + e1, p0 + e2);
    probe_out[i] = vec4<f32>(select(0.0, 1.0, skip), omega, 0.0, 0.0);";
    let out = common::probe::run(&ctx, "spherical_triangle.wgsl", body, &input, 4, 1);
    let (mut skipped, mut ties) = (0, 0);
    for (&[p, p0, e1, e2], o) in cases.iter().zip(&out) {
        let gpu_skip = o[0] == 1.0;
        let exact = spherical_triangle_area(p, p0, p0 + e1, p0 + e2);
        assert!(!gpu_skip || exact < SOLID_ANGLE_MIN, "the GPU skipped a triangle of Ω = {exact} (GPU Ω {})", o[1]);
        assert!((o[1] - exact).abs() <= 1e-4 * exact.max(1e-3), "solid angle {} on the GPU, {exact} on the CPU", o[1]);
        if gpu_skip != surely_below_solid_angle_min(p, p0, e1, e2) {
            // Only a tie may decide differently: the two sides of one bound equal to float
            // rounding (the plane bound's within the square roots' rounding).
            let c = p0 + (e1 + e2) / 3.0;
            let r2 = (p0 - c).length_squared().max((p0 + e1 - c).length_squared()).max((p0 + e2 - c).length_squared());
            let (lhs, rhs) = (6.35 * r2, SOLID_ANGLE_MIN * (p - c).length_squared());
            let gap = (p - c).length() - r2.sqrt();
            let (plhs, prhs) = (0.55 * e1.cross(e2).dot(p - p0).abs(), SOLID_ANGLE_MIN * gap * gap * gap);
            assert!(
                (lhs - rhs).abs() <= 1e-5 * rhs || (plhs - prhs).abs() <= 1e-4 * prhs.abs(),
                "GPU and CPU decide differently: {lhs} vs {rhs}, {plhs} vs {prhs}"
            );
            ties += 1;
        }
        skipped += gpu_skip as u32;
    }
    assert!(skipped > 50_000, "the GPU skipped only {skipped} of 200000");
    println!("the GPU skipped {skipped}; {ties} ties decided differently");
}

/// The harness rejects a sampler that does not draw its pdf (a 5 % distortion).
#[test]
fn the_harness_detects_a_wrong_pdf() {
    let mut rng = Lcg(9);
    let r = chi2::plane(
        "skewed",
        (Vec2::ZERO, Vec2::ONE),
        (20, 4),
        200_000,
        || {
            let u = Vec2::new(rng.f(), rng.f());
            Some(Vec2::new(u.x.powf(1.05), u.y))
        },
        |_| 1.0,
    );
    assert!(r.p < 1e-6, "a skewed sampler passed: {r:?}");
}

/// Spherical-triangle sampling is uniform over the triangle's solid angle, from near and far,
/// for a sliver and for a triangle covering most of a hemisphere; no sample fails. Tested in
/// the triangle's barycentric square, where slivers are as well resolved as the rest: the
/// density of the point the direction meets is (1/Ω) · cos θ_light / d² · 2 area.
#[test]
fn spherical_triangle_sampling_is_uniform_in_solid_angle() {
    use veach::cpu::spherical_triangle::{sample_spherical_triangle, spherical_triangle_area};
    let cases = [
        ("regular", [Vec3::new(-1.0, -0.5, 2.0), Vec3::new(1.0, -0.5, 2.0), Vec3::new(0.0, 1.0, 2.0)]),
        ("sliver", [Vec3::new(-1.0, 0.0, 1.0), Vec3::new(1.0, 0.02, 1.0), Vec3::new(0.3, 0.05, 1.0)]),
        ("near", [Vec3::new(-1.0, -1.0, 0.05), Vec3::new(1.5, -1.0, 0.05), Vec3::new(0.0, 1.5, 0.05)]),
        ("huge", [Vec3::new(-30.0, -20.0, 0.3), Vec3::new(30.0, -20.0, 0.3), Vec3::new(0.0, 40.0, 0.3)]),
    ];
    for (name, v) in cases {
        let omega = spherical_triangle_area(Vec3::ZERO, v[0], v[1], v[2]) as f64;
        let (e1, e2) = (v[1] - v[0], v[2] - v[0]);
        let n = e1.cross(e2);
        let two_area = n.length() as f64;
        let n = n.normalize();
        let mut rng = Lcg(17);
        let mut failures = 0;
        let what = format!("sample_spherical_triangle ({name}, Ω = {omega:.4})");
        let sample = || {
            let Some(w) = sample_spherical_triangle(Vec3::ZERO, v[0], v[1], v[2], rng.f(), rng.f()) else {
                failures += 1;
                return None;
            };
            let t = v[0].dot(n) / w.dot(n);
            Some(veach::cpu::lights::barycentrics(t * w - v[0], e1, e2))
        };
        let density = |b: Vec2| {
            let x = v[0] + b.x * e1 + b.y * e2;
            let cos = (x.normalize().dot(n) as f64).abs();
            let j = cos / x.length_squared() as f64 * two_area / omega;
            match b.x + b.y - 1.0 {
                d if d.abs() < 1e-5 => 0.5 * j,
                d if d < 0.0 => j,
                _ => 0.0,
            }
        };
        // The huge triangle peaks sharply below the point: 32² midpoint cells a bin.
        let r = chi2::plane(&what, (Vec2::ZERO, Vec2::ONE), (20, 32), 200_000, sample, density);
        assert!((r.total - 1.0).abs() < 0.01, "{what}: the density integrates to {}", r.total);
        r.assert_passes(&what, 0.01, cases.len());
        assert_eq!(failures, 0, "{what}: {failures} failed samples");
    }
}
