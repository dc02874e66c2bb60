//! veach: a physically based path tracer built around multiple importance sampling.
//!
//! Data flows one way: glTF → [`scene::Scene`] → [`packed::PackedScene`] (the buffers) →
//! a backend ([`gpu`] or the [`cpu`] reference) → [`film::Film`] → PNG/EXR.
//! The CLI, the tests and (later) the viewer all drive [`Renderer`].

pub mod accel;
pub mod bench;
pub mod cpu;
pub mod film;
pub mod gpu;
pub mod label;
pub mod output;
pub mod packed;
pub mod params;
pub mod plot;
pub mod scene;
pub mod tonemap;
pub mod viewer;

use film::Film;
use glam::Vec3;
use packed::PackedScene;
use params::Params;
use rayon::prelude::*;
use std::fmt;

/// Every error veach reports to a user: one line, naming the file or limit at fault.
#[derive(Debug, Clone, PartialEq)]
pub enum Error {
    /// Bad input: a file, a flag, an output path.
    Input(String),
    /// No usable Vulkan adapter.
    NoAdapter(String),
    /// A device limit would be exceeded.
    Limit(String),
    /// The GPU reported an error.
    Gpu(String),
}

impl fmt::Display for Error {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Error::Input(m) | Error::NoAdapter(m) | Error::Limit(m) => write!(f, "{m}"),
            Error::Gpu(m) => write!(f, "GPU error: {m}"),
        }
    }
}

impl std::error::Error for Error {}

/// The four direct-lighting estimators of the seed.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "kebab-case")]
#[repr(u32)]
pub enum Strategy {
    /// BSDF sampling only: emission counts when a BSDF-sampled ray hits an emitter.
    Bsdf = 0,
    /// Light sampling only: BSDF rays continue the path but their emitter hits count nothing.
    Light = 1,
    /// One light and one BSDF sample, weighted by the balance heuristic.
    MisBalance = 2,
    /// One light and one BSDF sample, weighted by the power heuristic.
    MisPower = 3,
}

impl Strategy {
    pub fn from_u32(v: u32) -> Strategy {
        match v {
            0 => Strategy::Bsdf,
            1 => Strategy::Light,
            2 => Strategy::MisBalance,
            _ => Strategy::MisPower,
        }
    }
}

/// How the numbers of a path's decisions are generated (`shaders/sampler.wgsl`).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, clap::ValueEnum, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "kebab-case")]
#[repr(u32)]
pub enum SamplerKind {
    /// Independent uniform numbers (PCG); the default of renders saved before samplers existed.
    #[default]
    Independent = 0,
    /// Owen-scrambled Sobol', padded per 2D pair: lower error at equal spp.
    Sobol = 1,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum Backend {
    Gpu,
    Cpu,
}

/// A crop window of the image (the whole image by default).
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
pub struct Tile {
    pub x: u32,
    pub y: u32,
    pub width: u32,
    pub height: u32,
}

#[derive(Clone, Debug)]
pub struct Settings {
    pub width: u32,
    pub height: u32,
    pub max_depth: u32,
    pub seed: u32,
    pub strategy: Strategy,
    pub sampler: SamplerKind,
    pub camera: Option<String>,
    /// Overrides the scene's environment radiance.
    pub environment: Option<Vec3>,
    pub tile: Option<Tile>,
    /// Thin-lens radius in scene units (0: a pinhole camera).
    pub aperture: f32,
    /// Distance in focus; None with an aperture: what the image centre sees.
    pub focus_distance: Option<f32>,
}

impl Default for Settings {
    fn default() -> Self {
        Settings {
            width: 512,
            height: 512,
            max_depth: 8,
            seed: 0,
            strategy: Strategy::MisPower,
            sampler: SamplerKind::Sobol,
            camera: None,
            environment: None,
            tile: None,
            aperture: 0.0,
            focus_distance: None,
        }
    }
}

/// The render parameters of `settings` for `camera`, with the lens set up.
fn make_params(scene: &PackedScene, camera: &scene::Camera, settings: &Settings, tile: Tile) -> Params {
    let env = settings.environment.unwrap_or(scene.environment);
    let (w, h) = (settings.width, settings.height);
    let mut params =
        Params::new(camera, (w, h), tile, settings.seed, settings.max_depth, settings.strategy, env, scene);
    if settings.aperture > 0.0 && settings.aperture.is_finite() {
        params.aperture = settings.aperture;
        params.focus_distance = match settings.focus_distance {
            Some(d) if d.is_finite() && d > 0.0 => d,
            _ => cpu::camera::autofocus(scene, &params),
        };
    }
    params.sampler = settings.sampler as u32;
    params
}

/// Everything that defines a render, saved in every EXR veach writes so that a render can be
/// resumed and its parts merged.
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Job {
    pub scene: std::path::PathBuf,
    pub camera: Option<String>,
    pub width: u32,
    pub height: u32,
    pub max_depth: u32,
    pub seed: u32,
    pub strategy: Strategy,
    pub env_map: Option<std::path::PathBuf>,
    pub env_color: Option<[f32; 3]>,
    pub env_strength: f32,
    /// The crop window rendered (None: the whole image).
    pub tile: Option<Tile>,
    /// Sample indices `sample_start .. sample_end` make up this render.
    pub sample_start: u32,
    pub sample_end: u32,
    #[serde(default)]
    pub aperture: f32,
    #[serde(default)]
    pub focus_distance: Option<f32>,
    /// Renders saved before samplers existed used independent numbers.
    #[serde(default)]
    pub sampler: SamplerKind,
}

impl Job {
    pub fn settings(&self) -> Settings {
        Settings {
            width: self.width,
            height: self.height,
            max_depth: self.max_depth,
            seed: self.seed,
            strategy: self.strategy,
            sampler: self.sampler,
            camera: self.camera.clone(),
            environment: None,
            tile: self.tile,
            aperture: self.aperture,
            focus_distance: self.focus_distance,
        }
    }

    pub fn window(&self) -> Tile {
        self.tile.unwrap_or(Tile { x: 0, y: 0, width: self.width, height: self.height })
    }
}

/// Largest film held in memory (CPU) before asking for tiles.
pub const MAX_FILM_BYTES: u64 = 2 << 30;

/// Largest image side we accept (a GPU texture/dispatch-friendly bound).
pub const MAX_IMAGE_SIDE: u32 = 16384;

enum Engine {
    Gpu(Box<gpu::GpuRenderer>),
    Cpu(Film),
}

/// A scene ready to render with one backend, accumulating samples progressively.
pub struct Renderer {
    scene: PackedScene,
    params: Params,
    engine: Engine,
}

impl Renderer {
    /// Prepares `scene` for rendering on `backend`.
    pub fn new(
        scene: PackedScene,
        camera: &scene::Camera,
        settings: &Settings,
        backend: Backend,
    ) -> Result<Renderer, Error> {
        Self::with_gpu(scene, camera, settings, backend, None)
    }

    /// As `new`, reusing an open GPU context when given.
    pub fn with_gpu(
        scene: PackedScene,
        camera: &scene::Camera,
        settings: &Settings,
        backend: Backend,
        ctx: Option<gpu::GpuContext>,
    ) -> Result<Renderer, Error> {
        let (w, h) = (settings.width, settings.height);
        if w == 0 || h == 0 || w > MAX_IMAGE_SIDE || h > MAX_IMAGE_SIDE {
            return Err(Error::Limit(format!("image size {w}x{h} is outside 1..={MAX_IMAGE_SIDE} per side")));
        }
        if scene.bvh_depth > accel::MAX_DEPTH {
            return Err(Error::Limit(format!(
                "the scene's BVH is {} levels deep; traversal walks at most {}",
                scene.bvh_depth,
                accel::MAX_DEPTH
            )));
        }
        let tile = settings.tile.unwrap_or(Tile { x: 0, y: 0, width: w, height: h });
        if tile.width == 0 || tile.height == 0 || tile.x + tile.width > w || tile.y + tile.height > h {
            return Err(Error::Input(format!(
                "tile {},{},{},{} does not fit in the {w}x{h} image",
                tile.x, tile.y, tile.width, tile.height
            )));
        }
        let params = make_params(&scene, camera, settings, tile);
        // The film must fit in memory (and, on the GPU, in one storage binding; checked there).
        let film_bytes = tile.width as u64 * tile.height as u64 * (film::WORDS_PER_PIXEL * 4) as u64;
        if film_bytes > MAX_FILM_BYTES {
            return Err(Error::Limit(format!(
                "a {}x{} film needs {film_bytes} bytes, above veach's limit of {MAX_FILM_BYTES} bytes; render tiles (--tile)",
                tile.width, tile.height
            )));
        }
        let engine = match backend {
            Backend::Cpu => Engine::Cpu(Film::new(tile.width, tile.height)),
            Backend::Gpu => {
                let ctx = match ctx {
                    Some(c) => c,
                    None => gpu::GpuContext::new()?,
                };
                Engine::Gpu(Box::new(gpu::GpuRenderer::new(ctx, &scene, params)?))
            }
        };
        Ok(Renderer { scene, params, engine })
    }

    pub fn backend(&self) -> Backend {
        match self.engine {
            Engine::Gpu(_) => Backend::Gpu,
            Engine::Cpu(_) => Backend::Cpu,
        }
    }

    pub fn adapter_name(&self) -> String {
        match &self.engine {
            Engine::Gpu(g) => g.adapter_name(),
            Engine::Cpu(_) => format!("cpu ({} threads)", rayon::current_num_threads()),
        }
    }

    pub fn scene(&self) -> &PackedScene {
        &self.scene
    }

    pub fn params(&self) -> &Params {
        &self.params
    }

    pub fn gpu_bytes(&self) -> u64 {
        match &self.engine {
            Engine::Gpu(g) => g.gpu_bytes,
            Engine::Cpu(_) => 0,
        }
    }

    /// Accumulates sample indices `start .. start + count` into the film.
    pub fn render_samples(&mut self, start: u32, count: u32) -> Result<(), Error> {
        match &mut self.engine {
            Engine::Gpu(g) => g.render_samples(start, count),
            Engine::Cpu(film) => {
                let (scene, base) = (&self.scene, self.params);
                let width = base.film_width as usize;
                film.data.par_chunks_mut(width * film::WORDS_PER_PIXEL).enumerate().for_each(|(y, row)| {
                    let mut row_film = Film { width: base.film_width, height: 1, data: row.to_vec() };
                    for s in start..start + count {
                        let p = Params { sample_index: s, ..base };
                        for x in 0..width {
                            let l = cpu::render_sample(scene, &p, x as u32, y as u32);
                            row_film.add_sample(x, l);
                        }
                    }
                    row.copy_from_slice(&row_film.data);
                });
                Ok(())
            }
        }
    }

    /// Accumulates sample `sample` for film rows `y0 .. y0 + rows` only: the viewer's way to
    /// keep each frame short. `y0` and `rows` must be multiples of 8.
    pub fn render_rows(&mut self, sample: u32, y0: u32, rows: u32) -> Result<(), Error> {
        if !y0.is_multiple_of(8) || !rows.is_multiple_of(8) {
            return Err(Error::Input(format!("row band {y0}+{rows} is not aligned to 8 rows")));
        }
        match &mut self.engine {
            Engine::Gpu(g) => g.render_rows(sample, y0, rows),
            Engine::Cpu(film) => {
                let p = Params { sample_index: sample, ..self.params };
                let (w, h) = (p.film_width, p.film_height);
                for y in y0..(y0 + rows).min(h) {
                    for x in 0..w {
                        film.add_sample((y * w + x) as usize, cpu::render_sample(&self.scene, &p, x, y));
                    }
                }
                Ok(())
            }
        }
    }

    /// The accumulated film (a readback on the GPU).
    pub fn film(&self) -> Result<Film, Error> {
        match &self.engine {
            Engine::Gpu(g) => g.read_film(),
            Engine::Cpu(film) => Ok(film.clone()),
        }
    }

    /// Restarts accumulation with a new camera and settings (same scene): the viewer's reset.
    pub fn reset(&mut self, camera: &scene::Camera, settings: &Settings) -> Result<(), Error> {
        let (w, h) = (settings.width, settings.height);
        if w == 0 || h == 0 || w > MAX_IMAGE_SIDE || h > MAX_IMAGE_SIDE {
            return Err(Error::Limit(format!("image size {w}x{h} is outside 1..={MAX_IMAGE_SIDE} per side")));
        }
        let tile = settings.tile.unwrap_or(Tile { x: 0, y: 0, width: w, height: h });
        self.params = make_params(&self.scene, camera, settings, tile);
        match &mut self.engine {
            Engine::Gpu(g) => g.reset(self.params),
            Engine::Cpu(f) => {
                *f = Film::new(tile.width, tile.height);
                Ok(())
            }
        }
    }

    /// The GPU engine, when rendering there (the viewer displays its film in place).
    pub fn gpu(&self) -> Option<&gpu::GpuRenderer> {
        match &self.engine {
            Engine::Gpu(g) => Some(g),
            Engine::Cpu(_) => None,
        }
    }

    /// Replaces the accumulated film (resume).
    pub fn set_film(&mut self, film: &Film) {
        match &mut self.engine {
            Engine::Gpu(g) => g.upload_film(film),
            Engine::Cpu(f) => *f = film.clone(),
        }
    }
}

/// Loads a glTF file into a packed scene and the chosen camera.
pub fn load(path: &std::path::Path, camera: Option<&str>) -> Result<(scene::Scene, scene::Camera), Error> {
    let scene = scene::gltf::load(path)?;
    for w in &scene.warnings {
        eprintln!("veach: warning: {}: {w}", path.display());
    }
    let cam = scene.camera(camera).map_err(|e| Error::Input(format!("{}: {e}", path.display())))?;
    Ok((scene, cam))
}
