//! `Renderer`: a packed scene on one engine (the GPU kernel or the CPU reference),
//! accumulating samples progressively into a film.

use crate::engine::{Engine, GpuEngine};
use crate::film::Film;
use crate::packed::PackedScene;
use crate::params::Params;
use crate::scene::{Camera, Environment};
use crate::settings::{Backend, EnvironmentSource, Settings, Tile};
use crate::{Error, accel, cpu, gpu};

/// The render parameters of `settings` for `camera`, with the lens set up.
fn make_params(scene: &PackedScene, camera: &Camera, settings: &Settings, tile: Tile) -> Params {
    let mut params = Params::new(camera, settings, tile, scene);
    if settings.aperture > 0.0 {
        params.aperture = settings.aperture;
        // Autofocus is a host-side ray query on the CPU BVH.
        params.focus_distance = settings.focus_distance.unwrap_or_else(|| cpu::camera::autofocus(scene, &params));
    }
    params
}

/// A scene ready to render with one engine, accumulating samples progressively.
pub struct Renderer {
    params: Params,
    settings: Settings,
    engine: Box<dyn Engine>,
    environment_source: EnvironmentSource,
}

impl Renderer {
    /// Prepares `scene` for rendering on `backend` (opening a GPU device for `Backend::Gpu`).
    pub fn new(scene: PackedScene, camera: &Camera, settings: &Settings, backend: Backend) -> Result<Renderer, Error> {
        match backend {
            Backend::Cpu => Self::build(scene, camera, settings, None),
            Backend::Gpu => Self::build(scene, camera, settings, Some(gpu::GpuContext::new()?)),
            Backend::Auto => Ok(Self::auto(scene, camera, settings)?.0),
        }
    }

    /// The faster engine for this machine, and why, in a phrase for logs and statistics: the
    /// GPU engine on a hardware adapter; the CPU engine when the only adapter is a software
    /// one (adapter type CPU: lavapipe, llvmpipe, SwiftShader, WARP), which runs the kernel
    /// slower than the CPU engine runs its twin (BENCHMARKS.md), or when there is none.
    pub fn auto(scene: PackedScene, camera: &Camera, settings: &Settings) -> Result<(Renderer, String), Error> {
        match gpu::adapter_info() {
            Ok(info) if info.device_type == wgpu::DeviceType::Cpu => {
                let why = format!(
                    "the only GPU adapter ({}) is a software one, slower here than the CPU backend; \
                     --backend gpu uses it anyway",
                    info.name
                );
                Ok((Self::build(scene, camera, settings, None)?, why))
            }
            Ok(info) => {
                let why = format!("hardware GPU adapter ({})", info.name);
                Ok((Self::build(scene, camera, settings, Some(gpu::GpuContext::new()?))?, why))
            }
            Err(Error::NoAdapter(_)) => Ok((Self::build(scene, camera, settings, None)?, "no GPU adapter".to_string())),
            Err(e) => Err(e),
        }
    }

    /// Prepares `scene` for the GPU engine on an open device.
    pub fn with_context(
        scene: PackedScene,
        camera: &Camera,
        settings: &Settings,
        ctx: gpu::GpuContext,
    ) -> Result<Renderer, Error> {
        Self::build(scene, camera, settings, Some(ctx))
    }

    fn build(
        mut scene: PackedScene,
        camera: &Camera,
        settings: &Settings,
        ctx: Option<gpu::GpuContext>,
    ) -> Result<Renderer, Error> {
        settings.validate()?;
        if scene.bvh_depth > accel::MAX_DEPTH {
            return Err(Error::Limit(format!(
                "the scene's BVH is {} levels deep; traversal walks at most {}",
                scene.bvh_depth,
                accel::MAX_DEPTH
            )));
        }
        let environment_source = settings.environment_source(&scene.scene_environment, scene.has_lights());
        let environment = settings.environment(&scene.scene_environment, scene.has_lights())?;
        scene.set_environment(&environment);
        let params = make_params(&scene, camera, settings, settings.window());
        let engine: Box<dyn Engine> = match ctx {
            None => Box::new(cpu::Renderer::new(scene, params)),
            Some(ctx) => Box::new(GpuEngine { renderer: gpu::GpuRenderer::new(ctx, &scene, params)?, scene }),
        };
        Ok(Renderer { params, settings: settings.clone(), engine, environment_source })
    }

    pub fn backend(&self) -> Backend {
        self.engine.backend()
    }

    /// How the CPU engine runs the integrator: `cpu::Kernel::Lanes` (the default, fast) or
    /// `Reference` (one path at a time, the GPU kernel's twin); the films are the same bits.
    /// No effect on the GPU engine.
    pub fn set_cpu_kernel(&mut self, kernel: cpu::Kernel) {
        self.engine.set_cpu_kernel(kernel);
    }

    /// The engine and its device, for logs and statistics.
    pub fn adapter_name(&self) -> String {
        self.engine.adapter_name()
    }

    /// The packed scene (host copy), for host ray queries and statistics.
    pub fn scene(&self) -> &PackedScene {
        self.engine.scene()
    }

    #[doc(hidden)]
    pub fn params(&self) -> &Params {
        &self.params
    }

    pub fn settings(&self) -> &Settings {
        &self.settings
    }

    /// Where the environment in use comes from (the default studio lights scenes without
    /// lights).
    pub fn environment_source(&self) -> EnvironmentSource {
        self.environment_source
    }

    /// Bytes of device memory held (0 on the CPU engine).
    pub fn gpu_bytes(&self) -> u64 {
        self.engine.gpu_bytes()
    }

    /// Accumulates sample indices `start .. start + count` into the film.
    pub fn render_samples(&mut self, start: u32, count: u32) -> Result<(), Error> {
        if start.checked_add(count).is_none() {
            return Err(Error::Input(format!("sample indices {start}+{count} overflow")));
        }
        self.engine.render_samples(start, count)
    }

    /// Accumulates sample `sample` for film rows `y0 .. y0 + rows` only: the viewer's way to
    /// keep each frame short. `y0` and `rows` must be multiples of `ROW_BAND`.
    pub fn render_rows(&mut self, sample: u32, y0: u32, rows: u32) -> Result<(), Error> {
        if !y0.is_multiple_of(ROW_BAND) || !rows.is_multiple_of(ROW_BAND) {
            return Err(Error::Input(format!("row band {y0}+{rows} is not aligned to {ROW_BAND} rows")));
        }
        self.engine.render_rows(sample, y0, rows)
    }

    /// The accumulated film (a readback on the GPU).
    pub fn film(&self) -> Result<Film, Error> {
        self.engine.film()
    }

    /// The fraction of pixels that stopped sampling (None: not an adaptive render). A
    /// readback of one word a pixel on the GPU.
    pub fn converged_fraction(&self) -> Result<Option<f64>, Error> {
        self.engine.converged_fraction()
    }

    /// Restarts accumulation with a new camera and settings (same scene and environment):
    /// the viewer's reset.
    pub fn reset(&mut self, camera: &Camera, settings: &Settings) -> Result<(), Error> {
        settings.validate()?;
        let params = make_params(self.scene(), camera, settings, settings.window());
        self.engine.reset(params)?;
        (self.params, self.settings) = (params, settings.clone());
        Ok(())
    }

    /// Replaces the environment (a new sky keeps the BVH and the device's geometry) and
    /// restarts accumulation.
    pub fn set_environment(&mut self, camera: &Camera, environment: &Environment) -> Result<(), Error> {
        let settings = &self.settings;
        let window = settings.window();
        self.params =
            self.engine.set_environment(environment, &|scene| make_params(scene, camera, settings, window))?;
        self.environment_source = EnvironmentSource::Settings;
        Ok(())
    }

    /// A host ray query: the depth along the view direction of what the centre of film pixel
    /// `pixel` sees (through a pinhole), or None when it sees the sky. The viewer's
    /// click-to-focus.
    pub fn pick_depth(&self, pixel: glam::UVec2) -> Option<f32> {
        let params = Params { aperture: 0.0, ..self.params };
        let mut sampler = cpu::sampler::sampler_init(cpu::sampler::SAMPLER_INDEPENDENT, 0, 0, 0);
        let ray = cpu::camera::generate_ray(&params, pixel, glam::Vec2::splat(0.5), &mut sampler);
        let hit = cpu::bvh::intersect_closest(self.scene(), &ray);
        (hit.tri != cpu::bvh::NO_HIT).then(|| hit.t * ray.dir.dot(glam::Vec3::from(params.cam_forward)))
    }

    /// The GPU engine, when rendering there (the viewer displays its film in place).
    pub fn gpu(&self) -> Option<&gpu::GpuRenderer> {
        self.engine.gpu()
    }

    /// Replaces the accumulated film (resume); it must match the render window.
    pub fn set_film(&mut self, film: &Film) -> Result<(), Error> {
        let w = self.settings.window();
        if (film.width, film.height) != (w.width, w.height) {
            return Err(Error::Input(format!(
                "a {}x{} film does not fit the {}x{} render window",
                film.width, film.height, w.width, w.height
            )));
        }
        let layout = self.settings.film_layout();
        if film.layout.adaptive != layout.adaptive {
            let (want, have) =
                if layout.adaptive { ("an adaptive", "a uniform") } else { ("a uniform", "an adaptive") };
            return Err(Error::Input(format!("the render is {want} one; the film is of {have} render")));
        }
        if film.layout != layout || film.data.len() != layout.words(film.pixel_count()) {
            return Err(Error::Input("the film's AOVs do not match the render's".into()));
        }
        self.engine.set_film(film);
        Ok(())
    }
}

/// Rows of one band of `Renderer::render_rows`: the kernel's workgroup height.
pub const ROW_BAND: u32 = 8;
