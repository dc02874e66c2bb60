//! Helpers shared by the integration tests.
#![allow(dead_code)]

pub mod build;
pub mod chi2;
pub mod cli;
pub mod probe;
pub mod rng;
pub mod scenes;

use glam::Vec3;
use std::path::{Path, PathBuf};
use veach::film::Film;
use veach::gpu::GpuContext;
use veach::{Backend, Error, Renderer, Settings};

pub fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

pub fn asset(name: &str) -> PathBuf {
    root().join("assets").join(name)
}

/// The third-party models of ../shared/models, or None (after saying so) where the folder is
/// absent; with VEACH_REQUIRE_MODELS=1 (CI) its absence fails the test instead.
pub fn shared_models() -> Option<PathBuf> {
    let d = root().join("../shared/models");
    if d.is_dir() {
        Some(d)
    } else {
        if std::env::var("VEACH_REQUIRE_MODELS").as_deref() == Ok("1") {
            panic!("VEACH_REQUIRE_MODELS=1 but {} is absent", d.display());
        }
        eprintln!("SKIPPED: {} is absent (third-party models are not in the repository)", d.display());
        None
    }
}

/// A GPU context, or None (after saying why) when this machine has no Vulkan adapter.
/// With VEACH_REQUIRE_GPU=1 (CI) a missing adapter fails the test instead.
pub fn gpu(test: &str) -> Option<GpuContext> {
    match GpuContext::new() {
        Ok(ctx) => Some(ctx),
        Err(e) => {
            if std::env::var("VEACH_REQUIRE_GPU").as_deref() == Ok("1") {
                panic!("{test}: VEACH_REQUIRE_GPU=1 but the GPU is unavailable: {e}");
            }
            // The build found a Vulkan driver: an adapter that does not open is a failure,
            // never a quiet skip (without a driver the GPU tests are reported as ignored).
            if cfg!(not(veach_no_gpu)) {
                panic!("{test}: this machine has a Vulkan driver but no adapter opens: {e}");
            }
            eprintln!("SKIPPED the GPU part of {test}: {e}");
            None
        }
    }
}

/// Test settings. The z-tests take a pixel's sample variance / n as the variance of its mean,
/// which holds for independent samples only (for Sobol' it is merely an upper bound in smooth
/// regions and can fall short in heavy-tailed ones), so they use the independent sampler; the
/// default sampler, Sobol', is checked against the references by replicates (tests/sampler.rs).
pub fn settings(size: u32, max_depth: u32, seed: u32) -> Settings {
    Settings {
        width: size,
        height: size,
        max_depth,
        seed,
        sampler: veach::SamplerKind::Independent,
        ..Settings::default()
    }
}

/// Renders `spp` samples of a scene file on a backend (a GPU context selects the GPU).
pub fn render(scene: &Path, settings: &Settings, spp: u32, ctx: Option<GpuContext>) -> Film {
    try_render(scene, settings, spp, ctx).unwrap_or_else(|e| panic!("render {}: {e}", scene.display()))
}

pub fn try_render(scene: &Path, settings: &Settings, spp: u32, ctx: Option<GpuContext>) -> Result<Film, Error> {
    let (s, camera) = load_pair(scene, settings.camera.as_deref())?;
    let packed = veach::packed::PackedScene::new(&s);
    let mut r = renderer(packed, &camera, settings, ctx)?;
    r.render_samples(0, spp)?;
    r.film()
}

/// Loads a scene file and its first (or named) camera.
pub fn load_pair(path: &Path, camera: Option<&str>) -> Result<(veach::Scene, veach::Camera), Error> {
    let loaded = veach::load(path, camera)?;
    Ok((loaded.scene, loaded.camera))
}

/// A renderer on the GPU when given a context, else on the CPU reference.
pub fn renderer(
    scene: veach::PackedScene,
    camera: &veach::Camera,
    settings: &Settings,
    ctx: Option<GpuContext>,
) -> Result<Renderer, Error> {
    match ctx {
        Some(ctx) => Renderer::with_context(scene, camera, settings, ctx),
        None => Renderer::new(scene, camera, settings, Backend::Cpu),
    }
}

/// A reference image and its per-pixel standard error from tests/data.
pub fn reference(name: &str) -> (Vec<Vec3>, Vec<Vec3>) {
    let read = |file: String| {
        let (_, _, v) = veach::output::read_exr(&root().join("tests/data").join(file)).expect("reference data");
        v.chunks_exact(3).map(|c| Vec3::new(c[0], c[1], c[2])).collect::<Vec<_>>()
    };
    (read(format!("{name}_64.exr")), read(format!("{name}_64_stderr.exr")))
}

/// How an estimate compares with an expected image, pixel by pixel and in the mean.
#[derive(Debug)]
pub struct Agreement {
    /// Relative difference of the image mean, per channel.
    pub mean_rel: Vec3,
    /// Difference of the image means divided by its standard error, per channel.
    pub mean_z: Vec3,
    /// Fraction of pixel channels with |z| > 4.
    pub outliers: f64,
}

/// Compares `a` (with per-pixel variance of its mean `var_a`) with `b` (variance `var_b`).
/// Both sides are f32 sums of many samples, so a relative rounding error of 1e-5 is allowed
/// on top of the statistical one (it matters only for noise-free pixels, e.g. lights seen
/// directly).
pub fn agreement(a: &[Vec3], var_a: &[Vec3], b: &[Vec3], var_b: &[Vec3]) -> Agreement {
    let n = a.len() as f64;
    let (mut sum_a, mut sum_b, mut var_sum) = ([0f64; 3], [0f64; 3], [0f64; 3]);
    let mut outliers = 0usize;
    for i in 0..a.len() {
        for c in 0..3 {
            let (x, y) = (a[i][c] as f64, b[i][c] as f64);
            let v = var_a[i][c] as f64 + var_b[i][c] as f64;
            sum_a[c] += x;
            sum_b[c] += y;
            var_sum[c] += v;
            let rounding = 1e-5 * x.abs().max(y.abs()) + 1e-7;
            let bad = (x - y).abs() > 4.0 * v.sqrt() + rounding;
            outliers += bad as usize;
        }
    }
    let rel = |c: usize| ((sum_a[c] - sum_b[c]) / sum_b[c].abs().max(1e-12)) as f32;
    let z = |c: usize| ((sum_a[c] - sum_b[c]) / var_sum[c].sqrt().max(1e-12)) as f32;
    Agreement {
        mean_rel: Vec3::new(rel(0), rel(1), rel(2)),
        mean_z: Vec3::new(z(0), z(1), z(2)),
        outliers: outliers as f64 / (3.0 * n),
    }
}

/// Pools square blocks of `block`×`block` pixels (means averaged, variances of the mean
/// combined), for estimators whose per-pixel sample variance is too heavy-tailed to trust at
/// low sample counts.
pub fn pool(values: &[Vec3], variances: &[Vec3], width: usize, block: usize) -> (Vec<Vec3>, Vec<Vec3>) {
    let height = values.len() / width;
    let (bw, bh) = (width / block, height / block);
    let mut m = vec![Vec3::ZERO; bw * bh];
    let mut v = vec![Vec3::ZERO; bw * bh];
    let k = (block * block) as f32;
    for y in 0..bh * block {
        for x in 0..bw * block {
            let b = (y / block) * bw + x / block;
            m[b] += values[y * width + x] / k;
            v[b] += variances[y * width + x] / (k * k);
        }
    }
    (m, v)
}

pub fn film_stats(film: &Film) -> (Vec<Vec3>, Vec<Vec3>) {
    let n = film.pixel_count();
    ((0..n).map(|i| film.mean(i)).collect(), (0..n).map(|i| film.variance_of_mean(i)).collect())
}

pub fn squares(v: &[Vec3]) -> Vec<Vec3> {
    v.iter().map(|s| *s * *s).collect()
}
