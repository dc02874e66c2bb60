//! The `veach` command line: a thin shell over `veach::Renderer`.

use clap::{Parser, Subcommand};
use glam::Vec3;
use std::path::{Path, PathBuf};
use std::process::ExitCode;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::Instant;
use veach::film::Film;
use veach::tonemap::Tonemap;
use veach::{Backend, Error, Job, Renderer, SamplerKind, Settings, Strategy, Tile};

#[derive(Parser)]
#[command(
    name = "veach",
    version,
    about = "A physically based GPU path tracer built around multiple importance sampling"
)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Render a glTF 2.0 scene (.gltf/.glb) to a PNG (tone-mapped) or EXR (linear).
    Render(RenderArgs),
    /// Open the interactive preview window (egui), refining progressively on the GPU.
    View(ViewArgs),
    /// Merge renders of disjoint sample ranges or tiles (EXRs written by veach) into one image.
    Merge(MergeArgs),
    /// Render the seed's four direct-lighting estimators at equal spp, side by side with labels.
    Strategies(StrategiesArgs),
    /// Plot RMSE against render time (log-log) for renders made with --reference and
    /// --stats-json: compare samplers, estimators and backends at equal time.
    PlotConvergence(PlotArgs),
    /// Benchmark: the Cornell box, the Veach scene and a generated ~260k-triangle scene on
    /// each backend (samples/s), with load and BVH-build times, geometry bytes per triangle
    /// and BVH traversal throughput. See BENCHMARKS.md and bench/compare-mitsuba.sh.
    Bench(BenchArgs),
    /// List the Vulkan adapters and their limits, or describe a scene.
    Info {
        /// A .gltf/.glb file: print its triangles, meshes, instances, materials, textures,
        /// lights, extensions and bounds.
        scene: Option<PathBuf>,
    },
}

#[derive(clap::Args)]
struct ViewArgs {
    /// The scene, a .gltf or .glb file (or open one from the window).
    scene: Option<PathBuf>,
    /// Render --frames frames, save a screenshot of the whole window here (.png), and exit.
    #[arg(long)]
    screenshot: Option<PathBuf>,
    #[arg(long, default_value_t = 30)]
    frames: u32,
    #[arg(long, default_value_t = 8)]
    max_depth: u32,
    #[arg(long)]
    env: Option<PathBuf>,
    #[arg(long, value_parser = parse_rgb)]
    env_color: Option<Vec3>,
    /// Window size WxH in points.
    #[arg(long, value_parser = parse_size, default_value = "1100x720")]
    window: (u32, u32),
    /// Fraction of the image area's resolution rendered when the camera is still.
    #[arg(long, default_value_t = 1.0)]
    render_scale: f32,
}

fn parse_size(s: &str) -> Result<(u32, u32), String> {
    let (w, h) = s.split_once('x').ok_or("expected WxH, e.g. 1100x720")?;
    let w: u32 = w.parse().map_err(|e| format!("'{w}': {e}"))?;
    let h: u32 = h.parse().map_err(|e| format!("'{h}': {e}"))?;
    if !(64..=16384).contains(&w) || !(64..=16384).contains(&h) {
        return Err("window sides must be 64..=16384".into());
    }
    Ok((w, h))
}

#[derive(clap::Args)]
struct MergeArgs {
    /// The parts: EXR files written by `veach render` (with --sample-range or --tile).
    #[arg(required = true)]
    parts: Vec<PathBuf>,
    /// The merged image (.exr keeps the film, .png is tone-mapped).
    #[arg(short, long)]
    output: PathBuf,
    #[arg(long, default_value_t = 0.0, allow_negative_numbers = true)]
    exposure: f32,
}

#[derive(clap::Args)]
struct PlotArgs {
    /// Statistics files written by `veach render --reference REF.exr --stats-json FILE`.
    #[arg(required = true)]
    stats: Vec<PathBuf>,
    /// The plot (.png).
    #[arg(short, long)]
    output: PathBuf,
    /// Horizontal axis: render seconds (equal-time comparison) or samples per pixel.
    #[arg(long, value_enum, default_value_t = PlotX::Seconds)]
    x: PlotX,
}

#[derive(Clone, Copy, clap::ValueEnum)]
enum PlotX {
    Seconds,
    Spp,
}

#[derive(clap::Args)]
struct BenchArgs {
    #[arg(long, default_value_t = 256)]
    width: u32,
    #[arg(long, default_value_t = 256)]
    height: u32,
    #[arg(long, default_value_t = 64)]
    spp: u32,
    /// Path segments, as Mitsuba's max_depth (8: up to 7 bounces).
    #[arg(long, default_value_t = 8)]
    max_depth: u32,
    /// Backends to run (repeat the flag for several); default: gpu and cpu.
    #[arg(long, value_enum)]
    backend: Vec<Backend>,
    /// Spheres per side in the generated large scene (~16k triangles each; 4 = ~262k).
    #[arg(long, default_value_t = 4)]
    large_grid: u32,
    /// Also write the results as JSON to this file.
    #[arg(long)]
    json: Option<PathBuf>,
}

#[derive(clap::Args)]
struct StrategiesArgs {
    /// The scene, a .gltf or .glb file.
    scene: PathBuf,
    /// Output contact sheet (.png).
    #[arg(short, long)]
    output: PathBuf,
    /// Samples per pixel of each estimator.
    #[arg(long, default_value_t = 16)]
    spp: u32,
    /// Width of each panel.
    #[arg(long, default_value_t = 256)]
    width: u32,
    /// Height of each panel.
    #[arg(long, default_value_t = 256)]
    height: u32,
    /// Path depth in segments (2 = direct lighting only, the seed's setting).
    #[arg(long, default_value_t = 2)]
    max_depth: u32,
    #[arg(long, default_value_t = 0)]
    seed: u32,
    #[arg(long, default_value_t = 0.0, allow_negative_numbers = true)]
    exposure: f32,
    #[arg(long, value_enum, default_value_t = Tonemap::Clamp)]
    tonemap: Tonemap,
    #[arg(long, value_enum)]
    backend: Option<Backend>,
    #[command(flatten)]
    look: LookArgs,
}

/// What the camera sees: which camera, and the environment.
#[derive(clap::Args)]
struct LookArgs {
    /// Camera node name (default: the first camera, else a view framing the scene).
    #[arg(long)]
    camera: Option<String>,
    /// Constant environment radiance R,G,B (default: the scene's extras.environment, else black).
    #[arg(long, value_parser = parse_rgb)]
    env_color: Option<Vec3>,
    /// Equirectangular environment map (.hdr or .exr), importance-sampled; --env-color tints it.
    #[arg(long)]
    env: Option<PathBuf>,
    /// Scales the environment (map or color).
    #[arg(long, default_value_t = 1.0)]
    env_strength: f32,
    /// Thin-lens radius in scene units for depth of field (default: a pinhole).
    #[arg(long, default_value_t = 0.0)]
    aperture: f32,
    /// Distance in focus (default with --aperture: what the image centre sees).
    #[arg(long)]
    focus_distance: Option<f32>,
}

#[derive(clap::Args)]
struct RenderArgs {
    /// The scene, a .gltf or .glb file (not needed with --resume).
    #[arg(required_unless_present = "resume")]
    scene: Option<PathBuf>,
    /// Output image; the extension picks the format: .png (exposure, clamp, sRGB) or .exr
    /// (linear f32 RGB, plus the film and the job so that it can be resumed or merged).
    #[arg(short, long)]
    output: PathBuf,
    /// Samples per pixel.
    #[arg(long, default_value_t = 64)]
    spp: u32,
    #[arg(long, default_value_t = 512)]
    width: u32,
    #[arg(long, default_value_t = 512)]
    height: u32,
    /// Longest path, counted in segments as Mitsuba's max_depth: 1 = emitters seen directly,
    /// 2 = direct lighting only, 8 = up to 7 bounces (pbrt's maxdepth is this minus 1);
    /// 0 = no limit (Russian roulette, from 3 segments on, ends paths).
    #[arg(long, default_value_t = 8)]
    max_depth: u32,
    /// Seed of the random sequences; the same seed renders the same image.
    #[arg(long, default_value_t = 0)]
    seed: u32,
    /// Exposure in stops applied before the PNG is tone-mapped (EXR stays linear).
    #[arg(long, default_value_t = 0.0, allow_negative_numbers = true)]
    exposure: f32,
    /// Tone mapper of PNG output.
    #[arg(long, value_enum, default_value_t = Tonemap::Clamp)]
    tonemap: Tonemap,
    /// Direct-lighting estimator.
    #[arg(long, value_enum, default_value_t = Strategy::MisPower)]
    strategy: Strategy,
    /// Sample generator: sobol (Owen-scrambled, lower error at equal spp) or independent.
    #[arg(long, value_enum, default_value_t = SamplerKind::Sobol)]
    sampler: SamplerKind,
    /// gpu (Vulkan; falls back to cpu with a warning when no adapter exists unless given explicitly) or cpu.
    #[arg(long, value_enum)]
    backend: Option<Backend>,
    #[command(flatten)]
    look: LookArgs,
    /// Render only sample indices START..END (a render-farm split; overrides --spp). Random
    /// numbers are keyed by sample index, so parts merge (`veach merge`) into the full render.
    #[arg(long, value_parser = parse_range)]
    sample_range: Option<(u32, u32)>,
    /// Render only the window X,Y,W,H of the image (an image-space split, merged by `veach merge`).
    #[arg(long, value_parser = parse_tile)]
    tile: Option<Tile>,
    /// Save the film and the job to this EXR periodically and at exit, for --resume.
    #[arg(long)]
    checkpoint: Option<PathBuf>,
    /// Seconds between checkpoints.
    #[arg(long, default_value_t = 60.0)]
    checkpoint_every: f64,
    /// Continue the render saved in this checkpoint (or any EXR veach wrote) to its target.
    #[arg(long)]
    resume: Option<PathBuf>,
    /// Write render statistics as JSON.
    #[arg(long)]
    stats_json: Option<PathBuf>,
    /// A converged image of the same size (EXR): record the RMSE against it at 1, 2, 4, ...
    /// spp and the end, with the render time, in --stats-json ("convergence").
    #[arg(long)]
    reference: Option<PathBuf>,
}

fn parse_range(s: &str) -> Result<(u32, u32), String> {
    let (a, b) = s.split_once("..").ok_or("expected START..END, e.g. 0..32")?;
    let a: u32 = a.trim().parse().map_err(|e| format!("'{a}': {e}"))?;
    let b: u32 = b.trim().parse().map_err(|e| format!("'{b}': {e}"))?;
    if b <= a {
        return Err(format!("{a}..{b} is empty"));
    }
    Ok((a, b))
}

fn parse_tile(s: &str) -> Result<Tile, String> {
    let v: Vec<u32> =
        s.split(',').map(|x| x.trim().parse::<u32>().map_err(|e| format!("'{x}': {e}"))).collect::<Result<_, _>>()?;
    match v[..] {
        [x, y, width, height] if width > 0 && height > 0 => Ok(Tile { x, y, width, height }),
        _ => Err("expected X,Y,W,H with W, H > 0".into()),
    }
}

fn parse_rgb(s: &str) -> Result<Vec3, String> {
    let v: Vec<f32> =
        s.split(',').map(|x| x.trim().parse::<f32>().map_err(|e| format!("'{x}': {e}"))).collect::<Result<_, _>>()?;
    match v[..] {
        [r, g, b] if v.iter().all(|c| c.is_finite() && *c >= 0.0) => Ok(Vec3::new(r, g, b)),
        [c] if c.is_finite() && c >= 0.0 => Ok(Vec3::splat(c)),
        _ => Err("expected R,G,B with finite non-negative values".into()),
    }
}

fn main() -> ExitCode {
    quiet_vulkan_loader();
    // A bug must still be one line on stderr, never a backtrace in a user's face.
    std::panic::set_hook(Box::new(|info| {
        let msg = info.payload().downcast_ref::<&str>().map(|s| s.to_string());
        let msg = msg.or_else(|| info.payload().downcast_ref::<String>().cloned()).unwrap_or_default();
        let at = info.location().map(|l| format!(" at {}:{}", l.file(), l.line())).unwrap_or_default();
        eprintln!("veach: internal error{at}: {msg} (please report it)");
    }));
    let cli = Cli::parse();
    let result = match cli.command {
        Command::Render(args) => render(&args),
        Command::Merge(args) => merge(&args),
        Command::View(args) => view(args).map(|_| Outcome::Done),
        Command::Strategies(args) => strategies(&args).map(|_| Outcome::Done),
        Command::Bench(args) => bench(&args).map(|_| Outcome::Done),
        Command::PlotConvergence(args) => plot_convergence(&args).map(|_| Outcome::Done),
        Command::Info { scene: Some(path) } => {
            veach::scene::gltf::describe_file(&path).map(|text| println!("{text}")).map(|_| Outcome::Done)
        }
        Command::Info { scene: None } => info().map(|_| Outcome::Done),
    };
    match result {
        Ok(Outcome::Done) => ExitCode::SUCCESS,
        Ok(Outcome::Interrupted) => ExitCode::from(EXIT_INTERRUPTED),
        Err(e) => {
            eprintln!("veach: {e}");
            ExitCode::from(2)
        }
    }
}

/// Mesa's window-system code complains on every device creation when XDG_RUNTIME_DIR is
/// unset (headless machines, CI); give it a private directory before any thread starts.
fn quiet_vulkan_loader() {
    if std::env::var_os("XDG_RUNTIME_DIR").is_none() {
        let dir = std::env::temp_dir().join("veach-xdg-runtime");
        #[cfg(unix)]
        {
            use std::os::unix::fs::DirBuilderExt;
            let _ = std::fs::DirBuilder::new().mode(0o700).create(&dir);
        }
        if dir.is_dir() {
            // SAFETY: called first thing in main, before any other thread exists.
            unsafe { std::env::set_var("XDG_RUNTIME_DIR", &dir) };
        }
    }
}

fn info() -> Result<(), Error> {
    let adapters = veach::gpu::adapters();
    if adapters.is_empty() {
        return Err(Error::NoAdapter(veach::gpu::NO_ADAPTER_HINT.into()));
    }
    for (info, limits) in adapters {
        println!(
            "{} ({:?}, {:?}, driver {} {})",
            info.name, info.device_type, info.backend, info.driver, info.driver_info
        );
        println!("  max_storage_buffer_binding_size {}", limits.max_storage_buffer_binding_size);
        println!("  max_buffer_size {}", limits.max_buffer_size);
        println!("  max_texture_dimension_2d {}", limits.max_texture_dimension_2d);
        println!("  max_texture_array_layers {}", limits.max_texture_array_layers);
        println!("  max_compute_workgroups_per_dimension {}", limits.max_compute_workgroups_per_dimension);
        println!("  max_compute_invocations_per_workgroup {}", limits.max_compute_invocations_per_workgroup);
        println!("  max_storage_buffers_per_shader_stage {}", limits.max_storage_buffers_per_shader_stage);
        println!("  subgroup size {}..{}", info.subgroup_min_size, info.subgroup_max_size);
    }
    Ok(())
}

/// Set by SIGINT/SIGTERM: finish the dispatch in flight, save, exit 130.
static INTERRUPTED: AtomicBool = AtomicBool::new(false);

/// Exit status of an interrupted render that kept its work.
const EXIT_INTERRUPTED: u8 = 130;

fn render(args: &RenderArgs) -> Result<Outcome, Error> {
    let t0 = Instant::now();
    veach::output::check_output(&args.output)?;
    for path in [&args.stats_json, &args.checkpoint].into_iter().flatten() {
        check_writable(path)?;
    }
    // The job: from a checkpoint, or from the command line.
    let (job, resumed) = match &args.resume {
        Some(path) => {
            let (film, job) = veach::output::read_film(path)?;
            (job, Some(film))
        }
        None => {
            let scene = args.scene.clone().ok_or_else(|| Error::Input("a SCENE is required".into()))?;
            let (sample_start, sample_end) = args.sample_range.unwrap_or((0, args.spp));
            if sample_end <= sample_start {
                return Err(Error::Input("--spp must be at least 1".into()));
            }
            let absolute = |p: &Path| std::fs::canonicalize(p).unwrap_or_else(|_| p.to_path_buf());
            let job = Job {
                scene: absolute(&scene),
                camera: args.look.camera.clone(),
                width: args.width,
                height: args.height,
                max_depth: args.max_depth,
                seed: args.seed,
                strategy: args.strategy,
                env_map: args.look.env.as_deref().map(absolute),
                env_color: args.look.env_color.map(Into::into),
                env_strength: args.look.env_strength,
                tile: args.tile,
                sample_start,
                sample_end,
                aperture: args.look.aperture,
                focus_distance: args.look.focus_distance,
                sampler: args.sampler,
            };
            (job, None)
        }
    };
    let (mut scene, camera) = veach::load(&job.scene, job.camera.as_deref())?;
    set_environment(&mut scene, job.env_map.as_deref(), job.env_color.map(Vec3::from), job.env_strength)?;
    let triangles = scene.triangles.len();
    if scene.emissive_triangle_count() == 0 && scene.environment == Vec3::ZERO {
        eprintln!(
            "veach: warning: {}: the scene has no lights and no environment; the image will be black",
            job.scene.display()
        );
    }
    let packed = veach::packed::PackedScene::new(&scene);
    let (bvh_nodes, bvh_depth, bvh_seconds) = (packed.bvh_nodes, packed.bvh_depth, packed.bvh_build_seconds);
    let mut renderer = open_renderer(packed, &camera, &job.settings(), args.backend)?;
    let mut done = 0u32;
    if let Some(film) = resumed {
        let window = job.window();
        if (film.width, film.height) != (window.width, window.height) {
            return Err(Error::Input("the checkpoint's film does not match its job".into()));
        }
        done = film.samples();
        renderer.set_film(&film);
    }
    let total = job.sample_end - job.sample_start;
    let reference = match &args.reference {
        Some(path) => Some(read_reference(path, job.window())?),
        None => None,
    };
    let mut convergence = Vec::new();
    let mut measuring = std::time::Duration::ZERO;
    let mut next_measure = (done + 1).next_power_of_two();
    // Ctrl-C and SIGTERM stop the loop between dispatches; the work done is kept.
    let _ = ctrlc::set_handler(|| INTERRUPTED.store(true, Ordering::SeqCst));

    let bar = indicatif::ProgressBar::new(total as u64);
    bar.set_style(
        indicatif::ProgressStyle::with_template("{elapsed_precise} {wide_bar} {pos}/{len} spp  {msg}  ETA {eta}")
            .unwrap_or_else(|_| indicatif::ProgressStyle::default_bar()),
    );
    bar.set_position(done as u64);
    let window = job.window();
    let pixels = window.width as f64 * window.height as f64;
    let t_render = Instant::now();
    let mut last_checkpoint = Instant::now();
    let (mut chunk, first) = (1u32, done);
    while done < total && !INTERRUPTED.load(Ordering::SeqCst) {
        let mut n = chunk.min(total - done);
        if reference.is_some() {
            n = n.min(next_measure - done);
        }
        let t = Instant::now();
        renderer.render_samples(job.sample_start + done, n)?;
        done += n;
        // Aim for about a quarter second per chunk: responsive to Ctrl-C, few round trips.
        let secs = t.elapsed().as_secs_f64().max(1e-6);
        chunk = ((n as f64 * 0.25 / secs) as u32).clamp(1, veach::gpu::MAX_BATCH);
        if let Some(r) = &reference
            && (done == next_measure || done == total)
        {
            // The readback and the error are not render time.
            let t = Instant::now();
            let rmse = rmse(&renderer.film()?, r);
            measuring += t.elapsed();
            let seconds = (t_render.elapsed() - measuring).as_secs_f64();
            convergence.push(serde_json::json!({"spp": done, "seconds": seconds, "rmse": rmse}));
            next_measure = (done + 1).next_power_of_two();
        }
        bar.set_position(done as u64);
        let rate = (done - first) as f64 * pixels / t_render.elapsed().as_secs_f64().max(1e-9);
        bar.set_message(format!("{:.2} Msamples/s", rate / 1e6));
        if let Some(path) = &args.checkpoint
            && last_checkpoint.elapsed().as_secs_f64() >= args.checkpoint_every
            && done < total
        {
            veach::output::write(&renderer.film()?, path, 0.0, Some(&job))?;
            last_checkpoint = Instant::now();
        }
    }
    let interrupted = done < total;
    let film = renderer.film()?;
    let seconds_render = (t_render.elapsed() - measuring).as_secs_f64();
    bar.finish_and_clear();
    veach::output::write_with(&film, &args.output, args.exposure, args.tonemap, Some(&job))?;
    if let Some(path) = &args.checkpoint {
        veach::output::write(&film, path, 0.0, Some(&job))?;
    }
    let nonfinite = film.nonfinite_samples();
    if nonfinite > 0 {
        eprintln!("veach: warning: dropped {nonfinite} non-finite samples");
    }
    let rendered = (done - first) as f64 * pixels;
    let samples_per_second = rendered / seconds_render.max(1e-9);
    if interrupted {
        eprintln!("veach: interrupted: wrote {} with {done} of {total} spp", args.output.display());
    } else {
        eprintln!(
            "veach: wrote {} ({}x{}, {} spp, {}, {:.2} s, {:.2} Msamples/s)",
            args.output.display(),
            window.width,
            window.height,
            total,
            renderer.adapter_name(),
            seconds_render,
            samples_per_second / 1e6
        );
    }
    if let Some(path) = &args.stats_json {
        let stats = serde_json::json!({
            "scene": job.scene.display().to_string(),
            "width": job.width,
            "height": job.height,
            "tile": job.tile,
            "spp": done,
            "spp_target": total,
            "sample_start": job.sample_start,
            "interrupted": interrupted,
            "max_depth": job.max_depth,
            "seed": job.seed,
            "strategy": job.strategy,
            "sampler": job.sampler,
            "adapter": renderer.adapter_name(),
            "backend": format!("{:?}", renderer.backend()).to_lowercase(),
            "seconds_total": t0.elapsed().as_secs_f64(),
            "seconds_render": seconds_render,
            "samples_per_second": samples_per_second,
            "triangles": triangles,
            "bvh_nodes": bvh_nodes,
            "bvh_depth": bvh_depth,
            "bvh_build_seconds": bvh_seconds,
            "nonfinite_samples": nonfinite,
            "gpu_bytes": renderer.gpu_bytes(),
            "reference": args.reference.as_ref().map(|p| p.display().to_string()),
            "convergence": convergence,
        });
        write_atomic(path, serde_json::to_string_pretty(&stats).unwrap_or_default().as_bytes())?;
    }
    Ok(if interrupted { Outcome::Interrupted } else { Outcome::Done })
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

/// Root-mean-square error of the film's mean against a reference, over pixels and channels.
fn rmse(film: &Film, reference: &[Vec3]) -> f64 {
    let sum: f64 = reference
        .iter()
        .enumerate()
        .map(|(i, r)| {
            let d = (film.mean(i) - *r).as_dvec3();
            d.dot(d)
        })
        .sum();
    (sum / (3.0 * reference.len().max(1) as f64)).sqrt()
}

enum Outcome {
    Done,
    Interrupted,
}

fn plot_convergence(args: &PlotArgs) -> Result<(), Error> {
    if veach::output::check_output(&args.output)? != veach::output::Format::Png {
        return Err(Error::Input(format!("{}: the plot is a .png", args.output.display())));
    }
    let mut series = Vec::new();
    for path in &args.stats {
        let fail = |m: &str| Error::Input(format!("{}: {m}", path.display()));
        let text = std::fs::read_to_string(path).map_err(|e| fail(&format!("cannot read: {e}")))?;
        let stats: serde_json::Value = serde_json::from_str(&text).map_err(|e| fail(&format!("invalid JSON: {e}")))?;
        let points = stats["convergence"]
            .as_array()
            .ok_or_else(|| fail("no \"convergence\" series (render with --reference and --stats-json)"))?;
        let key = match args.x {
            PlotX::Seconds => "seconds",
            PlotX::Spp => "spp",
        };
        let points: Vec<(f64, f64)> =
            points.iter().filter_map(|p| Some((p[key].as_f64()?, p["rmse"].as_f64()?))).collect();
        if points.is_empty() {
            return Err(fail("the convergence series is empty"));
        }
        let stem = path.file_stem().map_or_else(String::new, |s| s.to_string_lossy().to_string());
        let what = [&stats["backend"], &stats["strategy"]]
            .iter()
            .filter_map(|v| v.as_str().map(str::to_string))
            .collect::<Vec<_>>()
            .join(" ");
        series.push(veach::plot::Series { label: format!("{stem} ({what})"), points });
    }
    let x_label = match args.x {
        PlotX::Seconds => "RENDER TIME (S)",
        PlotX::Spp => "SAMPLES PER PIXEL",
    };
    let img = veach::plot::plot_loglog(&series, x_label, "RMSE");
    veach::output::write_png(&img, &args.output)?;
    eprintln!("veach: wrote {}", args.output.display());
    Ok(())
}

fn bench(args: &BenchArgs) -> Result<(), Error> {
    if args.width == 0 || args.height == 0 || args.spp == 0 || args.large_grid == 0 || args.large_grid > 32 {
        return Err(Error::Input("bench: sizes and spp must be positive, --large-grid in 1..=32".into()));
    }
    let backends = if args.backend.is_empty() { vec![Backend::Gpu, Backend::Cpu] } else { args.backend.clone() };
    let opts = veach::bench::BenchOptions {
        width: args.width,
        height: args.height,
        spp: args.spp,
        max_depth: args.max_depth,
        large_grid: args.large_grid,
    };
    let report = veach::bench::run(&opts, &backends, &mut |line| eprintln!("veach bench: {line}"))?;
    print!("{}", veach::bench::format_report(&report));
    if let Some(path) = &args.json {
        write_atomic(path, serde_json::to_string_pretty(&report).unwrap_or_default().as_bytes())?;
    }
    Ok(())
}

fn view(args: ViewArgs) -> Result<(), Error> {
    if let Some(shot) = &args.screenshot
        && veach::output::check_output(shot)? != veach::output::Format::Png
    {
        return Err(Error::Input(format!("{}: screenshots are .png", shot.display())));
    }
    veach::viewer::run(veach::viewer::ViewOptions {
        scene: args.scene,
        screenshot: args.screenshot,
        frames: args.frames,
        max_depth: args.max_depth,
        env: args.env,
        env_color: args.env_color,
        window: args.window,
        render_scale: args.render_scale,
    })
}

/// What parts of one render must share to be merged.
fn settings_key(j: &Job) -> (u32, u32, u32, u32, Strategy, SamplerKind, &Path, Option<&str>) {
    (j.width, j.height, j.seed, j.max_depth, j.strategy, j.sampler, &j.scene, j.camera.as_deref())
}

fn merge(args: &MergeArgs) -> Result<Outcome, Error> {
    veach::output::check_output(&args.output)?;
    let mut parts = Vec::new();
    for path in &args.parts {
        parts.push(veach::output::read_film(path)?);
    }
    let Some((_, first)) = parts.first() else {
        return Err(Error::Input("nothing to merge".into()));
    };
    let mut job = first.clone();
    let mut merged = Film::new(job.width, job.height);
    let mut seen: Vec<(Tile, u32, u32, &Path)> = Vec::new();
    for ((film, part), path) in parts.iter().zip(&args.parts) {
        let same = settings_key(part) == settings_key(&job);
        if !same {
            return Err(Error::Input(format!(
                "{}: rendered with other settings than {} (scene, size, seed, depth, strategy, sampler and camera must match)",
                path.display(),
                args.parts[0].display()
            )));
        }
        let w = part.window();
        let (start, end) = (part.sample_start, part.sample_start + film.samples());
        for (t, s, e, other) in &seen {
            let overlap_px = t.x < w.x + w.width && w.x < t.x + t.width && t.y < w.y + w.height && w.y < t.y + t.height;
            if overlap_px && *s < end && start < *e {
                return Err(Error::Input(format!(
                    "{}: its samples {start}..{end} overlap those of {} in the same pixels",
                    path.display(),
                    other.display()
                )));
            }
        }
        seen.push((w, start, end, path));
        merged.merge_at(film, w.x, w.y);
        job.sample_start = job.sample_start.min(start);
        job.sample_end = job.sample_end.max(end);
    }
    // The merged film covers the whole image (pixels no part rendered stay black).
    job.tile = None;
    veach::output::write(&merged, &args.output, args.exposure, Some(&job))?;
    eprintln!("veach: merged {} parts into {}", parts.len(), args.output.display());
    Ok(Outcome::Done)
}

/// The environment from the command line: a map (tinted by the color), a color, or the
/// scene's own, each scaled by the strength.
fn set_environment(
    scene: &mut veach::scene::Scene,
    map: Option<&Path>,
    color: Option<Vec3>,
    strength: f32,
) -> Result<(), Error> {
    if !strength.is_finite() || strength < 0.0 {
        return Err(Error::Input(format!("--env-strength {strength}: expected a finite value ≥ 0")));
    }
    if let Some(path) = map {
        scene.environment_map = Some(veach::scene::EnvironmentMap::load(path)?);
        scene.environment = color.unwrap_or(Vec3::ONE);
    } else if let Some(c) = color {
        scene.environment = c;
    }
    scene.environment *= strength;
    Ok(())
}

/// A renderer on the requested backend; with none requested, the GPU, or the CPU with a
/// one-line warning when there is no Vulkan adapter.
fn open_renderer(
    packed: veach::packed::PackedScene,
    camera: &veach::scene::Camera,
    settings: &Settings,
    backend: Option<Backend>,
) -> Result<Renderer, Error> {
    match backend {
        Some(b) => Renderer::new(packed, camera, settings, b),
        None => match veach::gpu::GpuContext::new() {
            Ok(ctx) => Renderer::with_gpu(packed, camera, settings, Backend::Gpu, Some(ctx)),
            Err(Error::NoAdapter(msg)) => {
                eprintln!("veach: warning: {msg}; rendering on the CPU backend");
                Renderer::new(packed, camera, settings, Backend::Cpu)
            }
            Err(e) => Err(e),
        },
    }
}

fn strategies(args: &StrategiesArgs) -> Result<(), Error> {
    if veach::output::check_output(&args.output)? != veach::output::Format::Png {
        return Err(Error::Input(format!("{}: the contact sheet is a .png", args.output.display())));
    }
    if args.spp == 0 {
        return Err(Error::Input("--spp must be at least 1".into()));
    }
    let (mut scene, camera) = veach::load(&args.scene, args.look.camera.as_deref())?;
    set_environment(&mut scene, args.look.env.as_deref(), args.look.env_color, args.look.env_strength)?;
    let packed = veach::packed::PackedScene::new(&scene);
    let (w, h) = (args.width, args.height);
    let bar = 14 * 3;
    let mut sheet = image::RgbImage::new(4 * w, h + bar);
    let mut backend = args.backend;
    for (k, strategy) in
        [Strategy::Bsdf, Strategy::Light, Strategy::MisBalance, Strategy::MisPower].into_iter().enumerate()
    {
        let settings = Settings {
            width: w,
            height: h,
            max_depth: args.max_depth,
            seed: args.seed,
            strategy,
            sampler: SamplerKind::Sobol,
            camera: args.look.camera.clone(),
            environment: None,
            tile: None,
            aperture: args.look.aperture,
            focus_distance: args.look.focus_distance,
        };
        let mut renderer = open_renderer(packed.clone(), &camera, &settings, backend)?;
        backend = Some(renderer.backend());
        let t = Instant::now();
        renderer.render_samples(0, args.spp)?;
        let film = renderer.film()?;
        eprintln!("veach: {strategy:?}: {} spp in {:.2} s", args.spp, t.elapsed().as_secs_f64());
        let panel = veach::output::tonemap(&film, args.exposure, args.tonemap);
        image::imageops::replace(&mut sheet, &panel, (k as u32 * w) as i64, bar as i64);
        let name = match strategy {
            Strategy::Bsdf => "BSDF",
            Strategy::Light => "LIGHT",
            Strategy::MisBalance => "MIS BALANCE",
            Strategy::MisPower => "MIS POWER",
        };
        let scale = if veach::label::text_width(name, 2) + 8 <= w { 2 } else { 1 };
        veach::label::draw_text(&mut sheet, k as u32 * w + 6, 6, name, scale, [255, 255, 255]);
        let sub = format!("{} SPP", args.spp);
        veach::label::draw_text(&mut sheet, k as u32 * w + 6, 6 + 8 * scale + 4, &sub, 1, [180, 180, 180]);
    }
    veach::output::write_png(&sheet, &args.output)?;
    eprintln!("veach: wrote {}", args.output.display());
    Ok(())
}

/// Fails early when `path` cannot be written, leaving nothing behind.
fn check_writable(path: &Path) -> Result<(), Error> {
    let name = path.file_name().map(|n| n.to_string_lossy().into_owned()).unwrap_or_default();
    let probe = path.with_file_name(format!(".{name}.{}.probe", std::process::id()));
    std::fs::write(&probe, b"").map_err(|e| Error::Input(format!("{}: cannot write: {e}", path.display())))?;
    let _ = std::fs::remove_file(&probe);
    Ok(())
}

fn write_atomic(path: &Path, bytes: &[u8]) -> Result<(), Error> {
    let name = path.file_name().map(|n| n.to_string_lossy().into_owned()).unwrap_or_default();
    let tmp = path.with_file_name(format!(".{name}.{}.tmp", std::process::id()));
    let fail = |e: std::io::Error| Error::Input(format!("{}: cannot write: {e}", path.display()));
    std::fs::write(&tmp, bytes).map_err(fail)?;
    std::fs::rename(&tmp, path).map_err(|e| {
        let _ = std::fs::remove_file(&tmp);
        fail(e)
    })
}
