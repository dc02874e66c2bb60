//! `veach render`: a scene (or a resumed checkpoint) to PNG/EXR, with checkpoints,
//! statistics and convergence measurements, over `veach::render_progressive`.

use crate::Outcome;
use crate::args::RenderArgs;
use glam::Vec3;
use std::path::Path;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::{Duration, Instant};
use veach::{Budget, Control, Error, Job, Settings, Tile};

/// Set by SIGINT/SIGTERM: finish the chunk in flight, save, exit 130.
static INTERRUPTED: AtomicBool = AtomicBool::new(false);

/// The job: from a checkpoint, or from the command line.
fn job_of(args: &RenderArgs) -> Result<(Job, Option<veach::Film>), Error> {
    if let Some(path) = &args.resume {
        if args.look.any() {
            return Err(Error::Input(
                "--resume continues the saved render: camera, environment, lens and light-sampler flags cannot change it"
                    .into(),
            ));
        }
        let (film, job) = veach::output::read_film(path)?;
        return Ok((job, Some(film)));
    }
    let scene = args.scene.clone().ok_or_else(|| Error::Input("a SCENE is required".into()))?;
    let (sample_start, sample_end) = args.sample_range.unwrap_or((0, args.spp));
    if sample_end <= sample_start {
        return Err(Error::Input("--spp must be at least 1".into()));
    }
    let mut settings = Settings {
        width: args.width,
        height: args.height,
        max_depth: args.max_depth,
        seed: args.seed,
        strategy: args.strategy,
        sampler: args.sampler,
        tile: args.tile,
        clamp_direct: args.clamp_direct,
        clamp_indirect: args.clamp_indirect,
        noise_threshold: args.noise_threshold,
        min_samples: args.min_samples,
        aovs: args.aov.clone(),
        ..Settings::default()
    };
    // The denoiser reads the albedo and the normal.
    if args.denoise {
        settings.aovs.extend([veach::aov::Aov::Albedo, veach::aov::Aov::Normal]);
    }
    settings.aovs.sort();
    settings.aovs.dedup();
    args.look.apply(&mut settings);
    settings.validate()?;
    let scene = std::fs::canonicalize(&scene).unwrap_or(scene);
    Ok((Job { scene, settings, sample_start, sample_end }, None))
}

pub fn run(args: &RenderArgs) -> Result<Outcome, Error> {
    let t0 = Instant::now();
    veach::output::check_output(&args.output)?;
    for path in [&args.stats_json, &args.checkpoint].into_iter().flatten() {
        veach::output::check_writable(path)?;
    }
    let (job, resumed) = job_of(args)?;
    let loaded = veach::load_with(&job.scene, &job.settings.load_options())?;
    crate::warn_all(&job.scene, &loaded.warnings);
    let triangles = loaded.scene.triangles.len();
    let packed = veach::PackedScene::new(&loaded.scene);
    crate::warn_all(&job.scene, &packed.warnings);
    let textures = serde_json::json!({
        "texture_bytes": packed.texels.len() as u64 * 4,
        "texture_pages": packed.texture_pages,
        "texture_page_side": packed.texture_size,
        "texture_occupancy": packed.texture_occupancy,
        "textures_shrunk": packed.warnings.len(),
    });
    let (bvh_nodes, bvh_depth, bvh_seconds) = (packed.bvh_nodes, packed.bvh_depth, packed.bvh_build_seconds);
    let light_tree =
        (packed.light_tree_nodes, packed.light_tree_depth, packed.light_tree_seconds, packed.light_tree_clusters);
    let (mut renderer, backend_reason) = crate::open_renderer(packed, &loaded.camera, &job.settings, args.backend)?;
    if renderer.environment_source() == veach::EnvironmentSource::Studio && job.settings.env_strength > 0.0 {
        eprintln!(
            "veach: {}: the scene has no lights: lit by the default studio environment (--env-color 0,0,0 keeps it black)",
            job.scene.display()
        );
    }
    let mut done = 0u32;
    let mut resumed_mean_spp = 0.0;
    if let Some(film) = resumed {
        done = film.samples().min(job.spp());
        resumed_mean_spp = film.mean_spp();
        renderer.set_film(&film)?;
    }
    let total = job.spp();
    let window = job.window();
    let reference = match &args.reference {
        Some(path) => Some(read_reference(path, window)?),
        None => None,
    };
    let mut convergence = Vec::new();
    // Ctrl-C and SIGTERM stop the loop between chunks; the work done is kept.
    if let Err(e) = ctrlc::set_handler(|| INTERRUPTED.store(true, Ordering::SeqCst)) {
        eprintln!("veach: warning: cannot catch Ctrl-C ({e}); an interrupted render will not be saved");
    }

    let bar = indicatif::ProgressBar::new(total as u64);
    // Under a time budget the samples' ETA says nothing: the message shows the time left.
    let template = if args.time.is_some() {
        "{elapsed_precise} {wide_bar} {pos}/{len} spp  {msg}"
    } else {
        "{elapsed_precise} {wide_bar} {pos}/{len} spp  {msg}  ETA {eta}"
    };
    bar.set_style(
        indicatif::ProgressStyle::with_template(template).unwrap_or_else(|_| indicatif::ProgressStyle::default_bar()),
    );
    bar.set_position(done as u64);
    let pixels = window.width as f64 * window.height as f64;
    let first = done;
    let mut last_checkpoint = Instant::now();
    let budget = Budget {
        time: args.time.map(Duration::from_secs_f64),
        cancel: Some(&INTERRUPTED),
        stop_at_powers_of_two: reference.is_some(),
    };
    let progress =
        veach::render_progressive(&mut renderer, job.sample_start, done, total, budget, &mut |renderer, p| {
            if let Some(r) = &reference
                && (p.done.is_power_of_two() || p.finished())
            {
                convergence.push(convergence_entry(&renderer.film()?, r, p.done, p.seconds));
            }
            bar.set_position(p.done as u64);
            let rate = (p.done - first) as f64 * pixels / p.seconds.max(1e-9);
            let rate = match p.converged {
                Some(c) => format!("{:.1} % of pixels converged", 100.0 * c),
                None => format!("{:.2} Msamples/s", rate / 1e6),
            };
            match args.time {
                Some(t) => bar.set_message(format!("{rate}  {:.0} s left", (t - p.seconds).max(0.0))),
                None => bar.set_message(rate),
            }
            if let Some(path) = &args.checkpoint
                && last_checkpoint.elapsed().as_secs_f64() >= args.checkpoint_every
                && !p.finished()
            {
                veach::output::write(&renderer.film()?, path, 0.0, Some(&job))?;
                last_checkpoint = Instant::now();
            }
            Ok(Control::Continue)
        })?;
    let done = progress.done;
    // A render stopped between powers of two (time budget, convergence, interrupt) records
    // its last state too.
    if let Some(r) = &reference
        && convergence.last().and_then(|c| c["spp"].as_u64()) != Some(done as u64)
    {
        convergence.push(convergence_entry(&renderer.film()?, r, done, progress.seconds));
    }
    // Short of the target: the budget ran out (a finished render) or a signal came (saved, exit 130).
    let interrupted = !progress.finished() && INTERRUPTED.load(Ordering::SeqCst);
    let stopped_by = progress.stopped_by(interrupted);
    let film = renderer.film()?;
    let seconds_render = progress.seconds;
    bar.finish_and_clear();
    let mut denoise_seconds = None;
    let mut denoise_engine = "";
    if args.denoise {
        let options = veach::denoise::Options { quality: args.denoise_quality, ..Default::default() };
        let start = Instant::now();
        // The network runs where the render did.
        let engine = match renderer.gpu() {
            Some(g) => veach::denoise::Engine::Gpu(g.context()),
            None => veach::denoise::Engine::Cpu,
        };
        denoise_engine = engine.name();
        let denoised = veach::denoise::denoise_film(&film, &options, engine)?;
        denoise_seconds = Some(start.elapsed().as_secs_f64());
        veach::output::write_denoised(&film, &denoised, &args.output, args.exposure, args.tonemap, Some(&job))?;
    } else {
        veach::output::write_with(&film, &args.output, args.exposure, args.tonemap, Some(&job))?;
    }
    if let Some(path) = &args.checkpoint {
        veach::output::write(&film, path, 0.0, Some(&job))?;
    }
    let nonfinite = film.nonfinite_samples();
    if nonfinite > 0 {
        eprintln!("veach: warning: dropped {nonfinite} non-finite samples");
    }
    // Samples actually taken (adaptive sampling skips converged pixels).
    let rendered = if film.is_adaptive() {
        (film.mean_spp() - resumed_mean_spp).max(0.0) * pixels
    } else {
        (done - first) as f64 * pixels
    };
    let samples_per_second = rendered / seconds_render.max(1e-9);
    if interrupted {
        eprintln!("veach: interrupted: wrote {} with {done} of {total} spp", args.output.display());
    } else {
        let spp = if film.is_adaptive() {
            format!(
                "{:.1} spp on average, at most {} of {total}, {:.1} % of pixels converged",
                film.mean_spp(),
                film.samples(),
                100.0 * film.converged_fraction().unwrap_or(0.0)
            )
        } else if done < total {
            format!("{done} spp (the time budget; cap {total})")
        } else {
            format!("{done} spp")
        };
        eprintln!(
            "veach: wrote {} ({}x{}, {spp}, {}, {:.2} s, {:.2} Msamples/s)",
            args.output.display(),
            window.width,
            window.height,
            renderer.adapter_name(),
            seconds_render,
            samples_per_second / 1e6
        );
    }
    if let Some(path) = &args.stats_json {
        let mut stats = veach::render_stats(&job, &film, &renderer, &progress, stopped_by);
        // (Several objects: serde_json's macro has a recursion limit.)
        let more = serde_json::json!({
            "interrupted": interrupted,
            "time_budget": args.time,
            "light_tree_nodes": light_tree.0,
            "light_tree_depth": light_tree.1,
            "light_tree_build_seconds": light_tree.2,
            "light_tree_clusters": light_tree.3,
            "backend_reason": backend_reason,
            "seconds_total": t0.elapsed().as_secs_f64(),
            "samples_per_second": samples_per_second,
            "triangles": triangles,
            "bvh_nodes": bvh_nodes,
            "bvh_depth": bvh_depth,
            "bvh_build_seconds": bvh_seconds,
            "reference": args.reference.as_ref().map(|p| p.display().to_string()),
            "convergence": convergence,
        });
        let denoise = serde_json::json!({
            "denoise_quality": args.denoise.then(|| args.denoise_quality.name()),
            "denoise_engine": args.denoise.then_some(denoise_engine),
            "denoise_seconds": denoise_seconds,
        });
        for m in [more, denoise, textures] {
            veach::extend_stats(&mut stats, m);
        }
        veach::output::write_atomic(path, serde_json::to_string_pretty(&stats).unwrap_or_default().as_bytes())?;
    }
    Ok(if interrupted { Outcome::Interrupted } else { Outcome::Done })
}

/// One point of `--reference`'s convergence record.
fn convergence_entry(film: &veach::Film, reference: &[Vec3], spp: u32, seconds: f64) -> serde_json::Value {
    let (rmse, clamped) = (veach::metrics::rmse(film, reference), veach::metrics::rmse_clamped(film, reference));
    serde_json::json!({"spp": spp, "mean_spp": film.mean_spp(), "seconds": seconds, "rmse": rmse, "rmse_clamped": clamped})
}

/// The reference image for --reference, as linear RGB per pixel of the render window.
fn read_reference(path: &Path, window: Tile) -> Result<Vec<Vec3>, Error> {
    let (w, h, v) = veach::output::read_exr(path)?;
    if (w, h) != (window.width, window.height) {
        return Err(Error::Input(format!(
            "{}: the reference is {w}x{h}, the render {}x{}",
            path.display(),
            window.width,
            window.height
        )));
    }
    if v.iter().any(|x| !x.is_finite()) {
        return Err(Error::Input(format!("{}: the reference has non-finite pixels", path.display())));
    }
    Ok(v.chunks_exact(3).map(|c| Vec3::new(c[0], c[1], c[2])).collect())
}
