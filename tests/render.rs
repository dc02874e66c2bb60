//! Renders checked against independent references, analytic values, the other backend,
//! and themselves (determinism).

mod common;

use common::*;
use glam::Vec3;

/// 64×64 at 256 spp. Per pixel, z = (ours − reference) / √(our variance of the mean +
/// reference stderr²). With 256 samples the sample variance of a pixel near the light is
/// itself noisy (heavy-tailed paths), so |z| > 4 happens more often than a Gaussian's 6e-5:
/// we allow 0.5 % of pixel channels. A real bias shows in the image mean first: each channel's
/// mean must be within 2 % and within 5 standard errors of the reference. `detects_bias`
/// below proves these tolerances reject a 3 % error.
const SPP: u32 = 256;
const MAX_OUTLIERS: f64 = 0.005;

fn assert_agrees(what: &str, a: &Agreement) {
    eprintln!("{what}: {a:?}");
    assert!(a.mean_rel.abs().max_element() < 0.02, "{what}: image mean off by {:?}", a.mean_rel);
    assert!(a.mean_z.abs().max_element() < 5.0, "{what}: image mean {:?} standard errors away", a.mean_z);
    assert!(a.outliers < MAX_OUTLIERS, "{what}: {:.3}% of pixels have |z| > 4", 100.0 * a.outliers);
}

fn cornell_box_against_reference(ctx: Option<veach::gpu::GpuContext>, what: &str) {
    let film = render(&asset("cornell-box.gltf"), &settings(64, 8, 1), SPP, ctx);
    let (mean, var) = film_stats(&film);
    let (reference, stderr) = reference("cbox_d8");
    assert_agrees(what, &agreement(&mean, &var, &reference, &squares(&stderr)));
}

#[test]
fn cornell_box_matches_reference_cpu() {
    cornell_box_against_reference(None, "cbox cpu");
}

#[test]
#[cfg_attr(veach_no_gpu, ignore = "needs a GPU adapter (no Vulkan driver on this machine)")]
fn cornell_box_matches_reference_gpu() {
    if let Some(ctx) = gpu("cornell_box_matches_reference_gpu") {
        cornell_box_against_reference(Some(ctx), "cbox gpu");
    }
}

/// The glass-sphere Cornell box against Mitsuba 3's dielectric (tests/data/cbox_glass_64*).
/// Caustics found only by BSDF sampling make per-pixel variance heavy-tailed (fireflies): at
/// 4×4 blocks 8 % of blocks fail a z-test with no spatial pattern, so the test pools 16×16
/// blocks (16 regions, each within 4 standard errors) and requires the image mean within 2 %
/// and 5 standard errors (measured: within 0.2 %).
fn glass_against_reference(ctx: Option<veach::gpu::GpuContext>, what: &str) {
    let film = render(&asset("cornell-glass.gltf"), &settings(64, 8, 3), 512, ctx);
    let (mean, var) = film_stats(&film);
    let (reference, stderr) = reference("cbox_glass");
    let (m, v) = pool(&mean, &var, 64, 16);
    let (r, rv) = pool(&reference, &squares(&stderr), 64, 16);
    assert_agrees(what, &agreement(&m, &v, &r, &rv));
}

#[test]
fn glass_cornell_box_matches_reference() {
    glass_against_reference(None, "glass cbox cpu");
}

#[test]
#[cfg_attr(veach_no_gpu, ignore = "needs a GPU adapter (no Vulkan driver on this machine)")]
fn glass_cornell_box_matches_reference_on_the_gpu() {
    if let Some(ctx) = gpu("glass_cornell_box_matches_reference_on_the_gpu") {
        glass_against_reference(Some(ctx), "glass cbox gpu");
    }
}

#[test]
fn detects_bias() {
    // The same comparison must reject an image 3 % too bright or too dark.
    let film = render(&asset("cornell-box.gltf"), &settings(64, 8, 2), SPP, None);
    let (mean, var) = film_stats(&film);
    let (reference, stderr) = reference("cbox_d8");
    for scale in [0.97, 1.03] {
        let biased: Vec<Vec3> = mean.iter().map(|m| *m * scale).collect();
        let a = agreement(&biased, &var, &reference, &squares(&stderr));
        let passes =
            a.mean_rel.abs().max_element() < 0.02 && a.mean_z.abs().max_element() < 5.0 && a.outliers < MAX_OUTLIERS;
        assert!(!passes, "a {scale}× image passed: {a:?}");
    }
}

#[test]
#[cfg_attr(veach_no_gpu, ignore = "needs a GPU adapter (no Vulkan driver on this machine)")]
fn gpu_and_cpu_agree_in_distribution() {
    // Different seeds: two independent estimates of the same image.
    let Some(ctx) = gpu("gpu_and_cpu_agree_in_distribution") else { return };
    let g = render(&asset("cornell-box.gltf"), &settings(64, 8, 3), SPP, Some(ctx));
    let c = render(&asset("cornell-box.gltf"), &settings(64, 8, 33), SPP, None);
    let (gm, gv) = film_stats(&g);
    let (cm, cv) = film_stats(&c);
    assert_agrees("cbox gpu vs cpu", &agreement(&gm, &gv, &cm, &cv));
}

#[test]
#[cfg_attr(veach_no_gpu, ignore = "needs a GPU adapter (no Vulkan driver on this machine)")]
fn gpu_and_cpu_trace_the_same_paths() {
    // Same seed: both backends draw the same random numbers, so apart from float rounding
    // (which can flip a rare path) they compute the same pixels. The light tree samples the
    // Cornell box's lamp by solid angle, whose asin and atan2 differ between the GPU and libm
    // by ~1e-4: pixel means then differ by ~3e-4 (median), so the tolerance is 1 %.
    // Both sample generators (shaders/sampler.wgsl and its twin) are checked.
    for sampler in [veach::SamplerKind::Independent, veach::SamplerKind::Sobol] {
        let Some(ctx) = gpu("gpu_and_cpu_trace_the_same_paths") else { return };
        let s = veach::Settings { sampler, ..settings(32, 8, 9) };
        let g = render(&asset("cornell-box.gltf"), &s, 16, Some(ctx));
        let c = render(&asset("cornell-box.gltf"), &s, 16, None);
        let close = (0..g.pixel_count())
            .filter(|&i| (g.mean(i) - c.mean(i)).abs().max_element() <= 1e-2 * c.mean(i).max_element().max(1e-3))
            .count();
        let mut rel: Vec<f32> = (0..g.pixel_count())
            .map(|i| (g.mean(i) - c.mean(i)).abs().max_element() / c.mean(i).max_element().max(1e-3))
            .collect();
        rel.sort_by(|a, b| a.total_cmp(b));
        let q = |f: f64| rel[((rel.len() - 1) as f64 * f) as usize];
        eprintln!("{sampler:?}: relative pixel differences: median {}, 90 % {}, 99 % {}", q(0.5), q(0.9), q(0.99));
        assert!(
            close as f64 >= 0.98 * g.pixel_count() as f64,
            "{sampler:?}: only {close}/{} pixels match",
            g.pixel_count()
        );
    }
}

fn furnace(ctx: Option<veach::gpu::GpuContext>, what: &str) {
    // Albedo 1 in a constant environment of radiance 1 (sampled as a light and combined with
    // BSDF samples by MIS): every pixel is 1 in expectation; the image mean within 0.5 %.
    let film = render(&asset("furnace-a100.gltf"), &settings(64, 8, 4), 64, ctx);
    let (mean, var) = film_stats(&film);
    let ones = vec![Vec3::ONE; mean.len()];
    let a = agreement(&mean, &var, &ones, &vec![Vec3::ZERO; mean.len()]);
    assert_agrees(what, &a);
    assert!(a.mean_rel.abs().max_element() < 0.005, "{what}: {a:?}");
}

#[test]
fn white_furnace_cpu() {
    furnace(None, "white furnace cpu");
}

#[test]
#[cfg_attr(veach_no_gpu, ignore = "needs a GPU adapter (no Vulkan driver on this machine)")]
fn white_furnace_gpu() {
    if let Some(ctx) = gpu("white_furnace_gpu") {
        furnace(Some(ctx), "white furnace gpu");
    }
}

#[test]
fn grey_furnace_matches_reference() {
    // Albedo 0.8: the sphere is convex, so it sees only the environment and its pixels read
    // 0.8 whatever the depth (≥ 2); the background reads 1; edge pixels mix the two.
    let film = render(&asset("furnace-a080.gltf"), &settings(64, 8, 5), 64, None);
    let (mean, var) = film_stats(&film);
    let (reference, stderr) = reference("furnace_a080");
    assert_agrees("furnace 0.8", &agreement(&mean, &var, &reference, &squares(&stderr)));
    let inside: Vec<usize> = (0..mean.len()).filter(|&i| (reference[i].x - 0.8).abs() < 1e-3).collect();
    assert!(inside.len() > 500, "the sphere covers many pixels");
    let avg = inside.iter().map(|&i| mean[i].x as f64).sum::<f64>() / inside.len() as f64;
    assert!((avg - 0.8).abs() < 0.004, "sphere pixels average {avg}, expected 0.8");
}

fn film_bytes(ctx: Option<veach::gpu::GpuContext>, seed: u32) -> (Vec<u8>, Vec<u8>) {
    let film = render(&asset("cornell-box.gltf"), &settings(32, 8, seed), 8, ctx);
    let dir =
        std::env::temp_dir().join(format!("veach-det-{}-{seed}-{:?}", std::process::id(), std::thread::current().id()));
    std::fs::create_dir_all(&dir).expect("temp dir");
    let (png, exr) = (dir.join("a.png"), dir.join("a.exr"));
    veach::output::write(&film, &png, 0.0, None).expect("png");
    veach::output::write(&film, &exr, 0.0, None).expect("exr");
    let out = (std::fs::read(&png).expect("png"), std::fs::read(&exr).expect("exr"));
    let _ = std::fs::remove_dir_all(&dir);
    out
}

#[test]
fn same_seed_same_bytes_cpu() {
    assert_eq!(film_bytes(None, 11), film_bytes(None, 11));
    assert_ne!(film_bytes(None, 11).1, film_bytes(None, 12).1);
}

#[test]
#[cfg_attr(veach_no_gpu, ignore = "needs a GPU adapter (no Vulkan driver on this machine)")]
fn same_seed_same_bytes_gpu() {
    let Some(a) = gpu("same_seed_same_bytes_gpu") else { return };
    let first = film_bytes(Some(a), 11);
    let second = film_bytes(gpu("same_seed_same_bytes_gpu"), 11);
    let other = film_bytes(gpu("same_seed_same_bytes_gpu"), 12);
    assert_eq!(first, second);
    assert_ne!(first.1, other.1);
}

/// The glass Cornell box (caustics: fireflies) at one sample per pixel, so that each pixel
/// holds one path's estimate, with the given firefly limits.
fn clamped(
    direct: Option<f32>,
    indirect: Option<f32>,
    max_depth: u32,
    seed: u32,
    ctx: Option<veach::gpu::GpuContext>,
) -> veach::Film {
    let s = veach::Settings { clamp_direct: direct, clamp_indirect: indirect, ..settings(48, max_depth, seed) };
    render(&asset("cornell-glass.gltf"), &s, 1, ctx)
}

/// The direct and indirect limits the clamping tests set.
const CLAMP_LIMITS: (f32, f32) = (0.01, 0.004);

/// The most one sample's R+G+B may carry under the limits (see below).
fn clamp_bound(direct: f32, indirect: f32) -> f32 {
    (4.0 * direct + 18.0 * indirect) * (1.0 + 1e-4)
}

/// Firefly clamping caps every contribution by its kind and only ever removes light. A path
/// of 8 segments adds at most 4 contributions of direct light (an emitter or the sky seen by
/// the camera ray, next-event estimates at the first vertex, an emitter hit by its BSDF ray)
/// and 18 of indirect light (3 per later vertex), so one sample's R+G+B is at most
/// 4·direct + 18·indirect; the same seed traces the same paths, so no pixel gets brighter.
#[test]
fn clamping_bounds_every_contribution_and_only_removes_light() {
    let sum = |v: Vec3| v.x + v.y + v.z;
    let (direct, indirect) = CLAMP_LIMITS;
    let bound = clamp_bound(direct, indirect);
    for seed in 0..2 {
        let free = clamped(None, None, 8, seed, None);
        let n = free.pixel_count();
        let over = (0..n).filter(|&i| sum(free.mean(i)) > bound).count();
        assert!(over > n / 10, "the limits must bind: only {over} of {n} pixels exceed {bound}");
        let c = clamped(Some(direct), Some(indirect), 8, seed, None);
        for i in 0..n {
            assert!(sum(c.mean(i)) <= bound, "pixel {i}: {} above {bound}", c.mean(i));
            assert!(c.mean(i).cmple(free.mean(i) * (1.0 + 1e-5) + 1e-6).all(), "pixel {i} gained light");
        }
        // Limits above every contribution change nothing, bit for bit.
        assert_eq!(clamped(Some(1e30), Some(1e30), 8, seed, None).to_rgb32f(), free.to_rgb32f());
        // Direct light only (2 segments): the indirect limit has no effect, the direct one
        // bounds the 3 direct contributions of a path.
        let d2 = clamped(None, None, 2, seed, None);
        assert_eq!(clamped(None, Some(1e-3), 2, seed, None).to_rgb32f(), d2.to_rgb32f());
        let c2 = clamped(Some(direct), None, 2, seed, None);
        assert!((0..n).all(|i| sum(c2.mean(i)) <= 3.0 * direct * (1.0 + 1e-4)));
        assert!((0..n).any(|i| sum(d2.mean(i)) > 3.0 * direct), "the direct limit must bind");
    }
}

#[test]
#[cfg_attr(veach_no_gpu, ignore = "needs a GPU adapter (no Vulkan driver on this machine)")]
fn clamping_bounds_every_contribution_and_only_removes_light_on_the_gpu() {
    let test = "clamping_bounds_every_contribution_and_only_removes_light_on_the_gpu";
    let sum = |v: Vec3| v.x + v.y + v.z;
    let (direct, indirect) = CLAMP_LIMITS;
    let bound = clamp_bound(direct, indirect);
    if let Some(ctx) = gpu(test) {
        let c = clamped(Some(direct), Some(indirect), 8, 0, Some(ctx));
        let free = clamped(None, None, 8, 0, gpu(test));
        for i in 0..c.pixel_count() {
            assert!(sum(c.mean(i)) <= bound, "gpu pixel {i}: {} above {bound}", c.mean(i));
            assert!(c.mean(i).cmple(free.mean(i) * (1.0 + 1e-5) + 1e-6).all(), "gpu pixel {i} gained light");
        }
    }
}
