//! The command line's schema: subcommands and their flags, and the flag parsers.
#![cfg_attr(not(all(feature = "viewer", feature = "bench")), allow(dead_code))]

use clap::{Parser, Subcommand};
use glam::Vec3;
use std::path::PathBuf;
use veach::tonemap::Tonemap;
use veach::{Backend, LightSampler, SamplerKind, Strategy, Tile};

#[derive(Parser)]
#[command(
    name = "veach",
    version,
    about = "A physically based GPU path tracer built around multiple importance sampling"
)]
pub struct Cli {
    #[command(subcommand)]
    pub command: Command,
}

#[derive(Subcommand)]
pub enum Command {
    /// Render a glTF 2.0 scene (.gltf/.glb) to a PNG (tone-mapped) or EXR (linear).
    Render(Box<RenderArgs>),
    /// Open the interactive preview window (egui), refining progressively on the GPU.
    #[cfg(feature = "viewer")]
    View(ViewArgs),
    /// Merge renders of disjoint sample ranges or tiles (EXRs written by veach) into one image.
    Merge(MergeArgs),
    /// Denoise an EXR (R, G, B and, when present, its albedo and normal layers, as
    /// `veach render --aov albedo,normal` writes them) with Open Image Denoise's network.
    Denoise(DenoiseArgs),
    /// Render the seed's four direct-lighting estimators at equal spp, side by side with labels.
    Strategies(StrategiesArgs),
    /// Plot RMSE against render time (log-log) for renders made with --reference and
    /// --stats-json: compare samplers, estimators and backends at equal time.
    PlotConvergence(PlotArgs),
    #[cfg(feature = "bench")]
    /// Benchmark: the Cornell box, the Veach scene and a generated ~260k-triangle scene on
    /// each backend (samples/s), with load and BVH-build times, geometry bytes per triangle
    /// and BVH traversal throughput. See BENCHMARKS.md and bench/compare-mitsuba.sh.
    Bench(BenchArgs),
    /// List the GPU adapters (Vulkan, Metal, DX12) and their limits, or describe a scene.
    Info(InfoArgs),
}

#[derive(clap::Args)]
pub struct InfoArgs {
    /// A .gltf/.glb file: print what `veach render` would render of it with the same
    /// --scene, --variant and --camera (triangles, meshes, instances, lights, bounds), and
    /// its materials, textures and extensions.
    pub scene: Option<PathBuf>,
    /// Camera node name (default: the first camera, else a view framing the scene).
    #[arg(long, requires = "scene")]
    pub camera: Option<String>,
    /// The glTF scene, by index (default: the file's default scene).
    #[arg(long = "scene", id = "scene_index", value_name = "N", requires = "scene")]
    pub scene_index: Option<usize>,
    /// The KHR_materials_variants variant, by name (default: the default materials).
    #[arg(long, value_name = "NAME", requires = "scene")]
    pub variant: Option<String>,
}

#[derive(clap::Args)]
pub struct ViewArgs {
    /// The scene, a .gltf or .glb file (or open one from the window).
    pub scene: Option<PathBuf>,
    /// Render --frames frames, save a screenshot of the whole window here (.png), and exit.
    #[arg(long)]
    pub screenshot: Option<PathBuf>,
    #[arg(long, default_value_t = 30)]
    pub frames: u32,
    #[arg(long, default_value_t = 8)]
    pub max_depth: u32,
    #[arg(long)]
    pub env: Option<PathBuf>,
    #[arg(long, value_parser = parse_rgb)]
    pub env_color: Option<Vec3>,
    /// Window size WxH in points.
    #[arg(long, value_parser = parse_size, default_value = "1100x720")]
    pub window: (u32, u32),
    /// Fraction of the image area's resolution rendered when the camera is still.
    #[arg(long, default_value_t = 1.0)]
    pub render_scale: f32,
    /// auto (the window's GPU when it is a hardware adapter, else the CPU engine, its film
    /// shown in the window), gpu or cpu.
    #[arg(long, value_enum, default_value_t = Backend::Auto)]
    pub backend: Backend,
    /// Adaptive sampling's noise threshold (see `veach render --help`); 0 turns it off.
    #[arg(long, value_name = "T", default_value_t = veach::viewer::NOISE_THRESHOLD, value_parser = parse_non_negative)]
    pub noise_threshold: f32,
    /// Start showing the samples each pixel took (a heat map) instead of the image.
    #[arg(long)]
    pub heat_map: bool,
    /// Start with the denoiser on (a panel toggle): the image is denoised whenever it is
    /// still, on a worker thread.
    #[arg(long)]
    pub denoise: bool,
}

/// The smallest window side the viewer lays out its panel in.
const MIN_WINDOW_SIDE: u32 = 64;

pub fn parse_size(s: &str) -> Result<(u32, u32), String> {
    let (w, h) = s.split_once('x').ok_or("expected WxH, e.g. 1100x720")?;
    let w: u32 = w.parse().map_err(|e| format!("'{w}': {e}"))?;
    let h: u32 = h.parse().map_err(|e| format!("'{h}': {e}"))?;
    let sides = MIN_WINDOW_SIDE..=veach::MAX_IMAGE_SIDE;
    if !sides.contains(&w) || !sides.contains(&h) {
        return Err(format!("window sides must be {MIN_WINDOW_SIDE}..={}", veach::MAX_IMAGE_SIDE));
    }
    Ok((w, h))
}

#[derive(clap::Args)]
pub struct MergeArgs {
    /// The parts: EXR files written by `veach render` (with --sample-range or --tile).
    #[arg(required = true)]
    pub parts: Vec<PathBuf>,
    /// The merged image (.exr keeps the film, .png is tone-mapped).
    #[arg(short, long)]
    pub output: PathBuf,
    #[arg(long, default_value_t = 0.0, allow_negative_numbers = true, value_parser = parse_finite)]
    pub exposure: f32,
}

#[derive(clap::Args)]
pub struct DenoiseArgs {
    /// The noisy image: an EXR with R, G, B and optionally albedo.R/G/B and normal.X/Y/Z.
    pub input: PathBuf,
    /// The result: .png (the denoised image, tone-mapped) or .exr (the input's channels with
    /// a `denoised` layer added: R, G, B stay the noisy image, and a veach render stays
    /// resumable and mergeable).
    #[arg(short, long)]
    pub output: PathBuf,
    /// fast (the small network, half the work) or balanced (the base network).
    #[arg(long, value_name = "Q", default_value = "balanced", value_parser = parse_quality)]
    pub denoise_quality: veach::denoise::Quality,
    /// Where the network runs: auto (the GPU on a hardware adapter, else the CPU), gpu or cpu.
    #[arg(long, value_enum, default_value_t = Backend::Auto)]
    pub backend: Backend,
    /// The scale that brings the colour to the network's units (1 = 100 cd/m²; default:
    /// measured from the image, as Open Image Denoise does).
    #[arg(long, value_parser = parse_positive, allow_negative_numbers = true)]
    pub input_scale: Option<f32>,
    #[arg(long, default_value_t = 0.0, allow_negative_numbers = true, value_parser = parse_finite)]
    pub exposure: f32,
    #[arg(long, value_enum, default_value_t = Tonemap::Clamp)]
    pub tonemap: Tonemap,
    /// Write denoise statistics (time, engine, network) as JSON.
    #[arg(long)]
    pub stats_json: Option<PathBuf>,
}

pub fn parse_quality(s: &str) -> Result<veach::denoise::Quality, String> {
    s.parse()
}

#[derive(clap::Args)]
pub struct PlotArgs {
    /// Statistics files written by `veach render --reference REF.exr --stats-json FILE`.
    #[arg(required = true)]
    pub stats: Vec<PathBuf>,
    /// The plot (.png).
    #[arg(short, long)]
    pub output: PathBuf,
    /// Horizontal axis: render seconds (equal-time comparison) or samples per pixel.
    #[arg(long, value_enum, default_value_t = PlotX::Seconds)]
    pub x: PlotX,
}

#[derive(Clone, Copy, clap::ValueEnum)]
pub enum PlotX {
    Seconds,
    Spp,
}

#[derive(clap::Args)]
pub struct BenchArgs {
    #[arg(long, default_value_t = 256)]
    pub width: u32,
    #[arg(long, default_value_t = 256)]
    pub height: u32,
    #[arg(long, default_value_t = 64)]
    pub spp: u32,
    /// Path segments, as Mitsuba's max_depth (8: up to 7 bounces).
    #[arg(long, default_value_t = 8)]
    pub max_depth: u32,
    /// Backends to run (repeat the flag for several; auto: the one `render` would pick); default: gpu and cpu.
    #[arg(long, value_enum)]
    pub backend: Vec<Backend>,
    /// Spheres per side in the generated large scene (~16k triangles each; 4 = ~262k).
    #[arg(long, default_value_t = 4)]
    pub large_grid: u32,
    /// Emitters of the generated light-tree build (no rendering; 1 M by default).
    #[arg(long, default_value_t = 1_000_000)]
    pub tree_emitters: usize,
    /// Also write the results as JSON to this file.
    #[arg(long)]
    pub json: Option<PathBuf>,
    /// Write the generated scenes (spheres-large.glb, many-lights.gltf, glossy-hall.gltf) into this directory
    /// and exit, to render them with `veach render`.
    #[arg(long)]
    pub write_scenes: Option<PathBuf>,
}

#[derive(clap::Args)]
pub struct StrategiesArgs {
    /// The scene, a .gltf or .glb file.
    pub scene: PathBuf,
    /// Output contact sheet (.png).
    #[arg(short, long)]
    pub output: PathBuf,
    /// Samples per pixel of each estimator.
    #[arg(long, default_value_t = 16)]
    pub spp: u32,
    /// Width of each panel.
    #[arg(long, default_value_t = 256)]
    pub width: u32,
    /// Height of each panel.
    #[arg(long, default_value_t = 256)]
    pub height: u32,
    /// Path depth in segments (2 = direct lighting only, the seed's setting).
    #[arg(long, default_value_t = 2)]
    pub max_depth: u32,
    #[arg(long, default_value_t = 0)]
    pub seed: u32,
    #[arg(long, default_value_t = 0.0, allow_negative_numbers = true, value_parser = parse_finite)]
    pub exposure: f32,
    #[arg(long, value_enum, default_value_t = Tonemap::Clamp)]
    pub tonemap: Tonemap,
    /// auto (the faster engine here: the GPU on a hardware adapter, else the CPU), gpu or cpu.
    #[arg(long, value_enum, default_value_t = Backend::Auto)]
    pub backend: Backend,
    #[command(flatten)]
    pub look: LookArgs,
}

/// What the camera sees: which camera, and the environment.
#[derive(clap::Args)]
pub struct LookArgs {
    /// Camera node name (default: the first camera, else a view framing the scene).
    #[arg(long)]
    pub camera: Option<String>,
    /// The glTF scene to render, by index (default: the file's default scene). Its id differs
    /// from the positional scene file's, which shares the word.
    #[arg(long = "scene", id = "scene_index", value_name = "N")]
    pub scene_index: Option<usize>,
    /// The KHR_materials_variants variant to render, by name (default: the default materials).
    #[arg(long, value_name = "NAME")]
    pub variant: Option<String>,
    /// Constant environment radiance R,G,B (default: the scene's extras.environment, else black).
    #[arg(long, value_parser = parse_rgb)]
    pub env_color: Option<Vec3>,
    /// Equirectangular environment map (.hdr or .exr), importance-sampled; --env-color tints it.
    #[arg(long)]
    pub env: Option<PathBuf>,
    /// Scales the environment (map or color) [default: 1].
    #[arg(long, value_parser = parse_non_negative, allow_negative_numbers = true)]
    pub env_strength: Option<f32>,
    /// Thin-lens radius in scene units for depth of field (default: 0, a pinhole).
    #[arg(long, value_parser = parse_non_negative, allow_negative_numbers = true)]
    pub aperture: Option<f32>,
    /// Distance in focus (default with --aperture: what the image centre sees).
    #[arg(long, value_parser = parse_positive, allow_negative_numbers = true)]
    pub focus_distance: Option<f32>,
    /// How next-event estimation picks a light: ris (the default: at glossy surfaces four
    /// candidates from the light tree, one kept by its unshadowed contribution), tree (the light
    /// BVH alone: by importance to the shading point) or power (by power alone, for comparison).
    #[arg(long, value_enum)]
    pub light_sampler: Option<LightSampler>,
}

#[derive(clap::Args)]
pub struct RenderArgs {
    /// The scene, a .gltf or .glb file (not needed with --resume).
    #[arg(required_unless_present = "resume")]
    pub scene: Option<PathBuf>,
    /// Output image; the extension picks the format: .png (exposure, clamp, sRGB) or .exr
    /// (linear f32 RGB, plus the film and the job so that it can be resumed or merged).
    #[arg(short, long)]
    pub output: PathBuf,
    /// Samples per pixel (with --time: the most to render).
    #[arg(long, conflicts_with = "resume", default_value_t = 64)]
    pub spp: u32,
    /// Render for this many seconds of render time (loading and writing excluded), then
    /// write the image with the samples reached; --spp caps them. With --resume: this
    /// session's budget.
    #[arg(long, value_parser = parse_budget)]
    pub time: Option<f64>,
    #[arg(long, conflicts_with = "resume", default_value_t = 512)]
    pub width: u32,
    #[arg(long, conflicts_with = "resume", default_value_t = 512)]
    pub height: u32,
    /// Longest path, counted in segments as Mitsuba's max_depth: 1 = emitters seen directly,
    /// 2 = direct lighting only, 8 = up to 7 bounces (pbrt's maxdepth is this minus 1);
    /// 0 = no limit (Russian roulette, from 4 segments on, ends paths).
    #[arg(long, conflicts_with = "resume", default_value_t = 8)]
    pub max_depth: u32,
    /// Seed of the random sequences; the same seed renders the same image.
    #[arg(long, conflicts_with = "resume", default_value_t = 0)]
    pub seed: u32,
    /// Exposure in stops applied before the PNG is tone-mapped (EXR stays linear).
    #[arg(long, default_value_t = 0.0, allow_negative_numbers = true, value_parser = parse_finite)]
    pub exposure: f32,
    /// Tone mapper of PNG output.
    #[arg(long, value_enum, default_value_t = Tonemap::Clamp)]
    pub tonemap: Tonemap,
    /// Direct-lighting estimator.
    #[arg(long, value_enum, conflicts_with = "resume", default_value_t = Strategy::MisPower)]
    pub strategy: Strategy,
    /// Sample generator: sobol (Owen-scrambled, lower error at equal spp) or independent.
    #[arg(long, value_enum, conflicts_with = "resume", default_value_t = SamplerKind::Sobol)]
    pub sampler: SamplerKind,
    /// auto (the faster engine here: the GPU on a hardware adapter; the CPU on a software
    /// adapter such as lavapipe, or with none), gpu or cpu.
    #[arg(long, value_enum, default_value_t = Backend::Auto)]
    pub backend: Backend,
    #[command(flatten)]
    pub look: LookArgs,
    /// Firefly control (biased, off by default): scale each sample's direct-light
    /// contribution (emitters seen directly or after one bounce) so that its R+G+B is at
    /// most C, as Cycles' Clamp Direct. Recorded in the EXR's job and in --stats-json.
    #[arg(long, value_name = "C", conflicts_with = "resume", value_parser = parse_positive, allow_negative_numbers = true)]
    pub clamp_direct: Option<f32>,
    /// The same limit for indirect light (paths of two bounces or more), as Cycles' Clamp
    /// Indirect.
    #[arg(long, value_name = "C", conflicts_with = "resume", value_parser = parse_positive, allow_negative_numbers = true)]
    pub clamp_indirect: Option<f32>,
    /// Adaptive sampling (off by default): a pixel stops taking samples once its noise,
    /// estimated from two halves of its samples relative to the square root of its
    /// brightness, is below T (Cycles' Noise Threshold; 0.01 is a clean image, 0.1 a
    /// preview). --spp is the cap. Adaptive renders resume but do not merge.
    #[arg(long, value_name = "T", conflicts_with = "resume", value_parser = parse_positive, allow_negative_numbers = true)]
    pub noise_threshold: Option<f32>,
    /// Samples every pixel takes before adaptive sampling first tests it (rounded up to a
    /// multiple of 8; default 16).
    #[arg(long, value_name = "N", requires = "noise_threshold", conflicts_with = "resume")]
    pub min_samples: Option<u32>,
    /// Render only sample indices START..END (a render-farm split; overrides --spp). Random
    /// numbers are keyed by sample index, so parts merge (`veach merge`) into the full render.
    #[arg(long, conflicts_with = "resume", value_parser = parse_range)]
    pub sample_range: Option<(u32, u32)>,
    /// Render only the window X,Y,W,H of the image (an image-space split, merged by `veach merge`).
    #[arg(long, conflicts_with = "resume", value_parser = parse_tile)]
    pub tile: Option<Tile>,
    /// Save the film and the job to this EXR periodically and at exit, for --resume.
    #[arg(long)]
    pub checkpoint: Option<PathBuf>,
    /// Seconds between checkpoints (0: after every chunk of samples).
    #[arg(long, default_value_t = 60.0, value_parser = parse_seconds, allow_negative_numbers = true)]
    pub checkpoint_every: f64,
    /// Continue the render saved in this checkpoint (or any EXR veach wrote) to its target.
    #[arg(long)]
    pub resume: Option<PathBuf>,
    /// AOV layers to write with an EXR, comma-separated: albedo (albedo.R/G/B), normal
    /// (normal.X/Y/Z, world space) and depth (depth.Z) of the first visible surface, looking
    /// through mirrors and smooth glass, with the image's own samples.
    #[arg(long, value_enum, value_delimiter = ',', conflicts_with = "resume")]
    pub aov: Vec<veach::aov::Aov>,
    /// Denoise the result with Open Image Denoise's network (run by veach, no driver needed):
    /// the PNG is denoised; an EXR keeps the noisy image and its albedo and normal layers and
    /// adds a `denoised` layer. Turns on the albedo and normal AOVs.
    #[arg(long)]
    pub denoise: bool,
    /// fast (the small network) or balanced (the base network).
    #[arg(long, value_name = "Q", default_value = "balanced", value_parser = parse_quality)]
    pub denoise_quality: veach::denoise::Quality,
    /// Write render statistics as JSON.
    #[arg(long)]
    pub stats_json: Option<PathBuf>,
    /// A converged image of the same size (EXR): record the RMSE against it at 1, 2, 4, ...
    /// spp and the end, with the render time, in --stats-json ("convergence").
    #[arg(long)]
    pub reference: Option<PathBuf>,
}

pub fn parse_range(s: &str) -> Result<(u32, u32), String> {
    let (a, b) = s.split_once("..").ok_or("expected START..END, e.g. 0..32")?;
    let a: u32 = a.trim().parse().map_err(|e| format!("'{a}': {e}"))?;
    let b: u32 = b.trim().parse().map_err(|e| format!("'{b}': {e}"))?;
    if b <= a {
        return Err(format!("{a}..{b} is empty"));
    }
    Ok((a, b))
}

pub fn parse_tile(s: &str) -> Result<Tile, String> {
    let v: Vec<u32> =
        s.split(',').map(|x| x.trim().parse::<u32>().map_err(|e| format!("'{x}': {e}"))).collect::<Result<_, _>>()?;
    match v[..] {
        [x, y, width, height] if width > 0 && height > 0 => Ok(Tile { x, y, width, height }),
        _ => Err("expected X,Y,W,H with W, H > 0".into()),
    }
}

pub fn parse_rgb(s: &str) -> Result<Vec3, String> {
    let v: Vec<f32> =
        s.split(',').map(|x| x.trim().parse::<f32>().map_err(|e| format!("'{x}': {e}"))).collect::<Result<_, _>>()?;
    match v[..] {
        [r, g, b] if v.iter().all(|c| c.is_finite() && *c >= 0.0) => Ok(Vec3::new(r, g, b)),
        [c] if c.is_finite() && c >= 0.0 => Ok(Vec3::splat(c)),
        _ => Err("expected R,G,B with finite non-negative values".into()),
    }
}

fn parse_f32(s: &str) -> Result<f32, String> {
    s.trim().parse::<f32>().map_err(|e| format!("'{s}': {e}"))
}

/// A finite number (exposure).
pub fn parse_finite(s: &str) -> Result<f32, String> {
    let v = parse_f32(s)?;
    if v.is_finite() { Ok(v) } else { Err(format!("{v}: expected a finite number")) }
}

/// A finite number ≥ 0 (aperture, environment strength).
pub fn parse_non_negative(s: &str) -> Result<f32, String> {
    let v = parse_f32(s)?;
    if v.is_finite() && v >= 0.0 { Ok(v) } else { Err(format!("{v}: expected a finite number ≥ 0")) }
}

/// A finite number > 0 (focus distance).
pub fn parse_positive(s: &str) -> Result<f32, String> {
    let v = parse_f32(s)?;
    if v.is_finite() && v > 0.0 { Ok(v) } else { Err(format!("{v}: expected a finite number > 0")) }
}

/// Seconds: finite and ≥ 0 (0 checkpoints after every chunk).
pub fn parse_seconds(s: &str) -> Result<f64, String> {
    let v: f64 = s.trim().parse().map_err(|e| format!("'{s}': {e}"))?;
    if v.is_finite() && v >= 0.0 { Ok(v) } else { Err(format!("{v}: expected a finite number of seconds ≥ 0")) }
}

/// A time budget: finite and > 0 seconds.
pub fn parse_budget(s: &str) -> Result<f64, String> {
    let v: f64 = s.trim().parse().map_err(|e| format!("'{s}': {e}"))?;
    if v.is_finite() && v > 0.0 { Ok(v) } else { Err(format!("{v}: expected a finite number of seconds > 0")) }
}

impl LookArgs {
    /// These flags as render settings.
    pub fn apply(&self, settings: &mut veach::Settings) {
        let absolute = |p: &std::path::Path| std::fs::canonicalize(p).unwrap_or_else(|_| p.to_path_buf());
        settings.camera = self.camera.clone();
        settings.scene = self.scene_index;
        settings.variant = self.variant.clone();
        settings.env_map = self.env.as_deref().map(absolute);
        settings.env_color = self.env_color.map(Into::into);
        let defaults = veach::Settings::default();
        settings.env_strength = self.env_strength.unwrap_or(defaults.env_strength);
        settings.aperture = self.aperture.unwrap_or(defaults.aperture);
        settings.focus_distance = self.focus_distance;
        settings.light_sampler = self.light_sampler.unwrap_or(defaults.light_sampler);
    }

    /// Whether any of these flags was given, even at its default value (they conflict with
    /// --resume, which continues the saved render as it was).
    pub fn any(&self) -> bool {
        self.camera.is_some()
            || self.scene_index.is_some()
            || self.variant.is_some()
            || self.env_color.is_some()
            || self.env.is_some()
            || self.env_strength.is_some()
            || self.aperture.is_some()
            || self.light_sampler.is_some()
            || self.focus_distance.is_some()
    }
}

#[cfg(test)]
mod tests {
    use super::Cli;
    use clap::CommandFactory;
    use clap::parser::ValueSource;

    /// A value each argument accepts, by id; an argument missing here fails the test, so a new
    /// flag cannot be left out of it.
    fn sample(id: &str, arg: &clap::Arg) -> String {
        if let Some(v) = arg.get_possible_values().first() {
            return v.get_name().to_string();
        }
        let v = match id {
            "scene" => "scene.gltf",
            "parts" => "a.exr",
            "input" | "resume" | "reference" | "env" => "in.exr",
            "stats" => "stats.json",
            "output" | "screenshot" => "out.png",
            "checkpoint" => "checkpoint.exr",
            "stats_json" | "json" => "stats.json",
            "write_scenes" => "scenes",
            "width" | "height" | "spp" | "frames" | "large_grid" | "tree_emitters" => "4",
            "max_depth" | "seed" | "scene_index" => "1",
            "min_samples" => "16",
            "time" | "checkpoint_every" | "exposure" | "env_strength" | "aperture" | "focus_distance"
            | "clamp_direct" | "clamp_indirect" | "input_scale" | "render_scale" => "0.5",
            "noise_threshold" => "0.05",
            "camera" => "Camera",
            "variant" => "Winter",
            "env_color" => "1,0.5,0.25",
            "window" => "800x600",
            "sample_range" => "0..4",
            "tile" => "0,0,8,8",
            "denoise_quality" => "fast",
            _ => panic!("no sample value for argument '{id}': add one to args::tests::sample"),
        };
        v.to_string()
    }

    /// The words that give `arg` its sample value on a command line.
    fn words(arg: &clap::Arg) -> Vec<String> {
        let id = arg.get_id().as_str();
        let takes_value = arg.get_action().takes_values();
        let value = takes_value.then(|| sample(id, arg));
        match arg.get_long() {
            Some(long) => std::iter::once(format!("--{long}")).chain(value).collect(),
            None => value.into_iter().collect(),
        }
    }

    /// Every documented argument of a subcommand (not clap's own --help/--version).
    fn documented(sub: &clap::Command) -> Vec<&clap::Arg> {
        sub.get_arguments().filter(|a| !matches!(a.get_id().as_str(), "help" | "version")).collect()
    }

    /// Parses `line` and checks that every id in `given` was read from the command line.
    fn parses(sub: &str, line: &[String], given: &[&str]) {
        let argv = ["veach".to_string(), sub.to_string()].into_iter().chain(line.iter().cloned());
        let matches =
            Cli::command().try_get_matches_from(argv).unwrap_or_else(|e| panic!("veach {sub} {}: {e}", line.join(" ")));
        let (_, m) = matches.subcommand().expect("a subcommand");
        for id in given {
            assert_eq!(
                m.value_source(id),
                Some(ValueSource::CommandLine),
                "veach {sub} {}: '{id}' did not come from the command line",
                line.join(" ")
            );
        }
    }

    /// Every flag of every subcommand parses, each alone (with what its subcommand requires)
    /// and all together (except --resume, which conflicts with the flags that would change
    /// the render), and lands in its own argument: a clash of names, such as the scene file
    /// and --scene N sharing one id, fails here, while clap's own check of it runs only in
    /// debug builds.
    #[test]
    fn every_documented_flag_parses_alone_and_together() {
        let cli = Cli::command();
        let mut checked = 0;
        for sub in cli.get_subcommands() {
            let name = sub.get_name();
            let args = documented(sub);
            let required: Vec<&clap::Arg> = args.iter().copied().filter(|a| a.is_required_set()).collect();
            // Arguments that need another one to be given with them.
            let companion = |id: &str| -> Vec<&str> {
                match (name, id) {
                    ("render", "min_samples") => vec!["noise_threshold"],
                    ("info", "camera" | "scene_index" | "variant") => vec!["scene"],
                    _ => vec![],
                }
            };
            let required_line = |skip: &str| -> Vec<String> {
                let mut line = Vec::new();
                for r in &required {
                    if r.get_id().as_str() != skip {
                        line.extend(words(r));
                    }
                }
                // render's scene file is required unless --resume is given.
                if name == "render" && skip != "scene" {
                    line.extend(["scene.gltf".to_string()]);
                }
                line
            };
            for arg in &args {
                let id = arg.get_id().as_str();
                if name == "render" && id == "scene" {
                    continue; // always in `required_line`
                }
                let mut line = required_line(id);
                let mut given = vec![id];
                for c in companion(id) {
                    let other = args.iter().find(|a| a.get_id().as_str() == c).expect("companion argument");
                    line.extend(words(other));
                    given.push(c);
                }
                line.extend(words(arg));
                parses(name, &line, &given);
                checked += 1;
            }
            let together: Vec<&clap::Arg> = args.iter().copied().filter(|a| a.get_id().as_str() != "resume").collect();
            let line: Vec<String> = together.iter().flat_map(|a| words(a)).collect();
            let ids: Vec<&str> = together.iter().map(|a| a.get_id().as_str()).collect();
            parses(name, &line, &ids);
        }
        assert!(checked > 60, "only {checked} arguments checked");
    }

    /// The case that was broken: the positional scene file beside --scene N, both spellings.
    #[test]
    fn scene_file_and_scene_index_are_separate_arguments() {
        use clap::Parser;
        for flag in [&["--scene", "1"][..], &["--scene=1"][..]] {
            let argv = ["veach", "render", "MultipleScenes.gltf"].iter().chain(flag).chain(&["-o", "a.png"]);
            let cli = Cli::try_parse_from(argv).unwrap_or_else(|e| panic!("{flag:?}: {e}"));
            let super::Command::Render(r) = cli.command else { panic!("not render") };
            assert_eq!(r.scene.as_deref(), Some(std::path::Path::new("MultipleScenes.gltf")));
            assert_eq!(r.look.scene_index, Some(1));
        }
        let cli = Cli::try_parse_from(["veach", "info", "m.gltf", "--scene", "1", "--variant", "v", "--camera", "c"])
            .unwrap_or_else(|e| panic!("info: {e}"));
        let super::Command::Info(i) = cli.command else { panic!("not info") };
        assert_eq!((i.scene_index, i.variant.as_deref(), i.camera.as_deref()), (Some(1), Some("v"), Some("c")));
    }
}
