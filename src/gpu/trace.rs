//! The ray-throughput kernels of `veach bench` (`shaders/trace.wgsl`): the integrator's
//! traversal alone, for primary, shadow and bounce rays.

use super::{GpuRenderer, shaders};
use crate::Error;

impl GpuRenderer {
    /// Traversal throughput (`shaders/trace.wgsl`): `passes` dispatches of the ray kernel of
    /// kind `kind` (0 primary, 1 primary + shadow, 2 primary + diffuse bounce) into a cleared
    /// film; returns the seconds they took (the pipeline is compiled before timing starts).
    pub fn trace_rays(&mut self, kind: u32, passes: u32) -> Result<f64, Error> {
        let k = kind.min(2) as usize;
        if self.trace_pipelines[k].is_none() {
            let module = shaders::module(&self.ctx, shaders::TRACE, self.variant)?;
            let mut constants = self.constants.to_vec();
            constants.push(("TRACE_KIND", k as f64));
            let pipeline = self.ctx.device.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
                label: Some("trace"),
                layout: Some(&self.pipeline_layout),
                module: &module,
                entry_point: Some("trace_rays"),
                compilation_options: wgpu::PipelineCompilationOptions { constants: &constants, ..Default::default() },
                cache: None,
            });
            // Lavapipe compiles at first dispatch: one untimed pass.
            self.dispatch_samples(&pipeline, 0, 0, 1, None)?;
            self.ctx.check()?;
            self.trace_pipelines[k] = Some(pipeline);
        }
        // The kernels count rays into the film: start from an empty one.
        self.reset(self.params)?;
        let pipeline = self.trace_pipelines[k].as_ref().ok_or_else(|| Error::Gpu("no trace pipeline".into()))?;
        let t = std::time::Instant::now();
        // Every pass traces sample 0's rays, the rays the CPU column traces.
        self.dispatch_samples(pipeline, 0, 0, passes, None)?;
        Ok(t.elapsed().as_secs_f64())
    }
}
