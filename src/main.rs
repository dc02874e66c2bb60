//! The `veach` command line: a thin shell over `veach::Renderer`.

use clap::{Parser, Subcommand};
use glam::Vec3;
use std::path::{Path, PathBuf};
use std::process::ExitCode;
use std::time::Instant;
use veach::{Backend, Error, Renderer, Settings, Strategy};

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
    /// Render the seed's four direct-lighting estimators at equal spp, side by side with labels.
    Strategies(StrategiesArgs),
    /// List the Vulkan adapters and their limits.
    Info,
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
    #[arg(long, value_enum)]
    backend: Option<Backend>,
    #[arg(long)]
    camera: Option<String>,
    #[arg(long, value_parser = parse_rgb)]
    env_color: Option<Vec3>,
    /// Equirectangular environment map (.hdr or .exr), importance-sampled.
    #[arg(long)]
    env: Option<PathBuf>,
    /// Scales the environment (map or color).
    #[arg(long, default_value_t = 1.0)]
    env_strength: f32,
}

#[derive(clap::Args)]
struct RenderArgs {
    /// The scene, a .gltf or .glb file.
    scene: PathBuf,
    /// Output image; the extension picks the format: .png (exposure, clamp, sRGB) or .exr (linear f32 RGB).
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
    /// Exposure in stops applied before the PNG is clamped (EXR stays linear).
    #[arg(long, default_value_t = 0.0, allow_negative_numbers = true)]
    exposure: f32,
    /// Direct-lighting estimator.
    #[arg(long, value_enum, default_value_t = Strategy::MisPower)]
    strategy: Strategy,
    /// gpu (Vulkan; falls back to cpu with a warning when no adapter exists unless given explicitly) or cpu.
    #[arg(long, value_enum)]
    backend: Option<Backend>,
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
    /// Write render statistics as JSON.
    #[arg(long)]
    stats_json: Option<PathBuf>,
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
    let cli = Cli::parse();
    let result = match cli.command {
        Command::Render(args) => render(&args),
        Command::Strategies(args) => strategies(&args),
        Command::Info => info(),
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
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

fn render(args: &RenderArgs) -> Result<(), Error> {
    let t0 = Instant::now();
    veach::output::check_output(&args.output)?;
    if let Some(stats) = &args.stats_json {
        check_writable(stats)?;
    }
    if args.spp == 0 {
        return Err(Error::Input("--spp must be at least 1".into()));
    }
    let (mut scene, camera) = veach::load(&args.scene, args.camera.as_deref())?;
    set_environment(&mut scene, args.env.as_deref(), args.env_color, args.env_strength)?;
    let triangles = scene.triangles.len();
    if scene.emissive_triangle_count() == 0 && scene.environment == Vec3::ZERO {
        eprintln!(
            "veach: warning: {}: the scene has no lights and no environment; the image will be black",
            args.scene.display()
        );
    }
    let packed = veach::packed::PackedScene::new(&scene);
    let (bvh_nodes, bvh_seconds) = (packed.nodes.len(), packed.bvh_build_seconds);
    let settings = Settings {
        width: args.width,
        height: args.height,
        max_depth: args.max_depth,
        seed: args.seed,
        strategy: args.strategy,
        camera: args.camera.clone(),
        environment: None,
        tile: None,
    };
    let mut renderer = open_renderer(packed, &camera, &settings, args.backend)?;

    let bar = indicatif::ProgressBar::new(args.spp as u64);
    bar.set_style(
        indicatif::ProgressStyle::with_template("{elapsed_precise} {wide_bar} {pos}/{len} spp  {msg}  ETA {eta}")
            .unwrap_or_else(|_| indicatif::ProgressStyle::default_bar()),
    );
    let pixels = args.width as f64 * args.height as f64;
    let t_render = Instant::now();
    let mut done = 0u32;
    let mut chunk = 1u32;
    while done < args.spp {
        let n = chunk.min(args.spp - done);
        let t = Instant::now();
        renderer.render_samples(done, n)?;
        done += n;
        // Aim for about a quarter second per chunk: responsive progress, few round trips.
        let secs = t.elapsed().as_secs_f64().max(1e-6);
        chunk = ((n as f64 * 0.25 / secs) as u32).clamp(1, veach::gpu::MAX_BATCH);
        bar.set_position(done as u64);
        let rate = done as f64 * pixels / t_render.elapsed().as_secs_f64().max(1e-9);
        bar.set_message(format!("{:.2} Msamples/s", rate / 1e6));
    }
    let film = renderer.film()?;
    let seconds_render = t_render.elapsed().as_secs_f64();
    bar.finish_and_clear();
    veach::output::write(&film, &args.output, args.exposure)?;
    let nonfinite = film.nonfinite_samples();
    if nonfinite > 0 {
        eprintln!("veach: warning: dropped {nonfinite} non-finite samples");
    }
    let samples_per_second = args.spp as f64 * pixels / seconds_render;
    eprintln!(
        "veach: wrote {} ({}x{}, {} spp, {}, {:.2} s, {:.2} Msamples/s)",
        args.output.display(),
        args.width,
        args.height,
        args.spp,
        renderer.adapter_name(),
        seconds_render,
        samples_per_second / 1e6
    );
    if let Some(path) = &args.stats_json {
        let stats = serde_json::json!({
            "scene": args.scene.display().to_string(),
            "width": args.width,
            "height": args.height,
            "spp": args.spp,
            "max_depth": args.max_depth,
            "seed": args.seed,
            "strategy": format!("{:?}", args.strategy),
            "adapter": renderer.adapter_name(),
            "backend": format!("{:?}", renderer.backend()).to_lowercase(),
            "seconds_total": t0.elapsed().as_secs_f64(),
            "seconds_render": seconds_render,
            "samples_per_second": samples_per_second,
            "triangles": triangles,
            "bvh_nodes": bvh_nodes,
            "bvh_build_seconds": bvh_seconds,
            "nonfinite_samples": nonfinite,
            "gpu_bytes": renderer.gpu_bytes(),
        });
        write_atomic(path, serde_json::to_string_pretty(&stats).unwrap_or_default().as_bytes())?;
    }
    Ok(())
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
    let (mut scene, camera) = veach::load(&args.scene, args.camera.as_deref())?;
    set_environment(&mut scene, args.env.as_deref(), args.env_color, args.env_strength)?;
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
            camera: args.camera.clone(),
            environment: None,
            tile: None,
        };
        let mut renderer = open_renderer(packed.clone(), &camera, &settings, backend)?;
        backend = Some(renderer.backend());
        let t = Instant::now();
        renderer.render_samples(0, args.spp)?;
        let film = renderer.film()?;
        eprintln!("veach: {strategy:?}: {} spp in {:.2} s", args.spp, t.elapsed().as_secs_f64());
        let panel = veach::output::tonemap(&film, args.exposure);
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
