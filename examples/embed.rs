//! Embedding veach: load a scene, render it for a sample or time budget with progress and
//! cancellation, read the film, swap the sky without rebuilding the BVH, checkpoint, resume
//! and merge through the library. Run: `cargo run --release --example embed`.

use std::sync::atomic::AtomicBool;
use std::time::Duration;
use veach::{Backend, Budget, Control, Environment, Job, Part, Renderer, Settings};

fn main() -> Result<(), veach::Error> {
    let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR"));
    let out = std::env::temp_dir().join(format!("veach-embed-{}", std::process::id()));
    std::fs::create_dir_all(&out).map_err(|e| veach::Error::Input(format!("{}: {e}", out.display())))?;

    // From bytes with a base directory (a path works the same way: `veach::load`).
    let bytes = std::fs::read(root.join("assets/cornell-box.gltf"))
        .map_err(|e| veach::Error::Input(format!("cornell-box.gltf: {e}")))?;
    let loaded = veach::load_bytes(&bytes, Some(&root.join("assets")), None)?;
    for w in &loaded.warnings {
        println!("warning: {w}");
    }
    let settings = Settings { width: 64, height: 64, max_depth: 6, ..Settings::default() };
    let scene = veach::PackedScene::new(&loaded.scene);
    // The CPU engine needs no driver; `Backend::Gpu` runs the WGSL kernel.
    let mut renderer = Renderer::new(scene, &loaded.camera, &settings, Backend::Cpu)?;

    // 16 samples, or 10 s, whichever comes first; a cancel flag another thread could set.
    let cancel = AtomicBool::new(false);
    let budget = Budget { time: Some(Duration::from_secs(10)), cancel: Some(&cancel), ..Budget::default() };
    let progress = veach::render_progressive(&mut renderer, 0, 0, 16, budget, &mut |_, p| {
        println!("{}/{} spp after {:.2} s", p.done, p.total, p.seconds);
        Ok(Control::Continue)
    })?;

    // The film: linear RGB, variance of each pixel's mean and per-pixel sample counts.
    let film = renderer.film()?;
    let rgb = film.to_rgb32f();
    let variance = film.variance();
    let counts = film.counts();
    let centre = (32 * 64 + 32) as usize;
    println!(
        "centre pixel {:?} ± {:?} from {} samples",
        &rgb[3 * centre..3 * centre + 3],
        variance[3 * centre..3 * centre + 3].iter().map(|v| v.sqrt()).collect::<Vec<_>>(),
        counts[centre]
    );
    veach::output::write(&film, &out.join("cornell.png"), 0.0, None)?;

    // A checkpoint (an EXR carrying the film and its job), resumed to 32 spp.
    let job = Job {
        scene: root.join("assets/cornell-box.gltf"),
        settings: settings.clone(),
        sample_start: 0,
        sample_end: 32,
    };
    let checkpoint = out.join("checkpoint.exr");
    veach::output::write(&film, &checkpoint, 0.0, Some(&job))?;
    let (saved, saved_job) = veach::output::read_film(&checkpoint)?;
    renderer.set_film(&saved)?;
    veach::render_progressive(
        &mut renderer,
        saved_job.sample_start,
        progress.done,
        saved_job.spp(),
        Budget::default(),
        &mut |_, _| Ok(Control::Continue),
    )?;
    let resumed = renderer.film()?;

    // Farm parts: samples 32..48 rendered separately merge exactly with the first 32.
    let part_job = Job { sample_start: 32, sample_end: 48, ..job.clone() };
    let mut part = Renderer::new(veach::PackedScene::new(&loaded.scene), &loaded.camera, &settings, Backend::Cpu)?;
    part.render_samples(32, 16)?;
    job.compatible_with(&part_job).map_err(veach::Error::Input)?;
    let parts = [
        Part { film: resumed, job: Job { sample_end: 32, ..job.clone() }, path: checkpoint.clone() },
        Part { film: part.film()?, job: part_job, path: out.join("part.exr") },
    ];
    let (merged, merged_job) = veach::merge(&parts)?;
    println!("merged {} spp (samples {}..{})", merged.samples(), merged_job.sample_start, merged_job.sample_end);

    // A new sky: the light data is rebuilt, the BVH is not.
    renderer.set_environment(&loaded.camera, &Environment::constant(glam::Vec3::new(0.2, 0.3, 0.5)))?;
    renderer.render_samples(0, 4)?;
    veach::output::write(&renderer.film()?, &out.join("cornell-sky.png"), 0.0, None)?;
    println!("wrote {}", out.display());
    Ok(())
}
