//! `Engine`: what `Renderer` asks of a render engine — accumulate samples of its packed scene
//! into its film — so that the CPU reference, the GPU kernel and any faster engine (a
//! wavefront over SIMD lanes) are interchangeable behind one `Renderer`.

use crate::film::Film;
use crate::packed::PackedScene;
use crate::params::Params;
use crate::scene::Environment;
use crate::settings::Backend;
use crate::{Error, cpu, gpu};

pub(crate) trait Engine: Send {
    /// The kind of engine, as `--backend` names it.
    fn backend(&self) -> Backend;
    /// The engine and its device, for logs and statistics.
    fn adapter_name(&self) -> String;
    /// The packed scene (the host copy on the GPU), for host ray queries and statistics.
    fn scene(&self) -> &PackedScene;
    /// Bytes of device memory held.
    fn gpu_bytes(&self) -> u64 {
        0
    }
    /// Accumulates sample indices `start .. start + count` into the film.
    fn render_samples(&mut self, start: u32, count: u32) -> Result<(), Error>;
    /// Accumulates sample `sample` for film rows `y0 .. y0 + rows` only.
    fn render_rows(&mut self, sample: u32, y0: u32, rows: u32) -> Result<(), Error>;
    /// The accumulated film (a readback on the GPU).
    fn film(&self) -> Result<Film, Error>;
    /// The fraction of pixels that stopped sampling (None: not an adaptive render).
    fn converged_fraction(&self) -> Result<Option<f64>, Error>;
    /// New parameters (camera, settings) and an empty film.
    fn reset(&mut self, params: Params) -> Result<(), Error>;
    /// A new environment, then an empty film with the parameters `params` makes for the scene
    /// that has it; returns those parameters.
    fn set_environment(
        &mut self,
        environment: &Environment,
        params: &dyn Fn(&PackedScene) -> Params,
    ) -> Result<Params, Error>;
    /// Continues from `film` (resume); its layout matches the parameters.
    fn set_film(&mut self, film: &Film);
    /// The GPU renderer, when this engine is one (the viewer displays its film in place).
    fn gpu(&self) -> Option<&gpu::GpuRenderer> {
        None
    }
    /// Chooses how the CPU engine runs the integrator (no effect on the GPU's).
    fn set_cpu_kernel(&mut self, _kernel: cpu::Kernel) {}
}

impl Engine for cpu::Renderer {
    fn backend(&self) -> Backend {
        Backend::Cpu
    }

    fn adapter_name(&self) -> String {
        match self.kernel() {
            cpu::Kernel::Lanes => format!("cpu ({} threads)", rayon::current_num_threads()),
            k => format!("cpu ({} threads, {} kernel)", rayon::current_num_threads(), k.name()),
        }
    }

    fn scene(&self) -> &PackedScene {
        cpu::Renderer::scene(self)
    }

    fn render_samples(&mut self, start: u32, count: u32) -> Result<(), Error> {
        cpu::Renderer::render_samples(self, start, count);
        Ok(())
    }

    fn render_rows(&mut self, sample: u32, y0: u32, rows: u32) -> Result<(), Error> {
        cpu::Renderer::render_rows(self, sample, y0, rows);
        Ok(())
    }

    fn film(&self) -> Result<Film, Error> {
        Ok(cpu::Renderer::film(self).clone())
    }

    fn converged_fraction(&self) -> Result<Option<f64>, Error> {
        Ok(cpu::Renderer::film(self).converged_fraction())
    }

    fn reset(&mut self, params: Params) -> Result<(), Error> {
        cpu::Renderer::reset(self, params);
        Ok(())
    }

    fn set_environment(
        &mut self,
        environment: &Environment,
        params: &dyn Fn(&PackedScene) -> Params,
    ) -> Result<Params, Error> {
        cpu::Renderer::set_environment(self, environment);
        let p = params(cpu::Renderer::scene(self));
        cpu::Renderer::reset(self, p);
        Ok(p)
    }

    fn set_film(&mut self, film: &Film) {
        cpu::Renderer::set_film(self, film);
    }

    fn set_cpu_kernel(&mut self, kernel: cpu::Kernel) {
        cpu::Renderer::set_kernel(self, kernel);
    }
}

/// The GPU kernel, and the host copy of the scene for host ray queries.
pub(crate) struct GpuEngine {
    pub renderer: gpu::GpuRenderer,
    pub scene: PackedScene,
}

impl Engine for GpuEngine {
    fn backend(&self) -> Backend {
        Backend::Gpu
    }

    fn adapter_name(&self) -> String {
        self.renderer.adapter_name()
    }

    fn scene(&self) -> &PackedScene {
        &self.scene
    }

    fn gpu_bytes(&self) -> u64 {
        self.renderer.gpu_bytes
    }

    fn render_samples(&mut self, start: u32, count: u32) -> Result<(), Error> {
        self.renderer.render_samples(start, count)
    }

    fn render_rows(&mut self, sample: u32, y0: u32, rows: u32) -> Result<(), Error> {
        self.renderer.render_rows(sample, y0, rows)
    }

    fn film(&self) -> Result<Film, Error> {
        self.renderer.read_film()
    }

    fn converged_fraction(&self) -> Result<Option<f64>, Error> {
        self.renderer.converged_fraction()
    }

    fn reset(&mut self, params: Params) -> Result<(), Error> {
        self.renderer.reset(params)
    }

    fn set_environment(
        &mut self,
        environment: &Environment,
        params: &dyn Fn(&PackedScene) -> Params,
    ) -> Result<Params, Error> {
        self.scene.set_environment(environment);
        let p = params(&self.scene);
        self.renderer.set_environment(&self.scene, p)?;
        Ok(p)
    }

    fn set_film(&mut self, film: &Film) {
        self.renderer.upload_film(film);
    }

    fn gpu(&self) -> Option<&gpu::GpuRenderer> {
        Some(&self.renderer)
    }
}
