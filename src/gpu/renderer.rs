//! The GPU engine: the packed scene on the device and the progressive
//! one-sample-per-dispatch integrator kernel, the twin of `cpu::Renderer`.

use super::bindings::{self, Geometry, SceneResources};
use super::film::DeviceFilm;
use super::{GeometryPlacement, GpuContext, MAX_BATCH, shaders, storage_buffer};
use crate::Error;
use crate::adaptive::adaptive_test_due;
use crate::film::Film;
use crate::packed::PackedScene;
use crate::params::Params;

/// Pixels per workgroup side of the kernels (`@workgroup_size(8, 8)`).
pub const WORKGROUP_SIDE: u32 = 8;

pub struct GpuRenderer {
    pub(super) ctx: GpuContext,
    pipeline: wgpu::ComputePipeline,
    /// Adaptive sampling's `adaptive_settle`, dispatched after each convergence test.
    settle: wgpu::ComputePipeline,
    layout: wgpu::BindGroupLayout,
    module: wgpu::ShaderModule,
    pub(super) pipeline_layout: wgpu::PipelineLayout,
    #[cfg(feature = "bench")]
    pub(super) variant: shaders::Geometry,
    /// The override constants the pipelines were made with (the scene's features, AOVs).
    pub(super) constants: [(&'static str, f64); 13],
    /// `trace_rays` pipelines by TRACE_KIND, built on first use (by `veach bench` only).
    #[cfg(feature = "bench")]
    pub(super) trace_pipelines: [Option<wgpu::ComputePipeline>; 3],
    scene: SceneResources,
    bind_group: wgpu::BindGroup,
    params_buf: wgpu::Buffer,
    film: DeviceFilm,
    stride: u64,
    pub(super) params: Params,
    /// Samples taken by the pixels still sampling (adaptive sampling's test schedule).
    taken: u32,
    /// Bytes of device memory held (scene + film).
    pub gpu_bytes: u64,
}

impl GpuRenderer {
    pub fn new(ctx: GpuContext, scene: &PackedScene, params: Params) -> Result<GpuRenderer, Error> {
        let device = &ctx.device;
        let limits = device.limits();
        let storage = |label: &str, bytes: &[u8]| storage_buffer(device, label, bytes);
        let geometry_bytes: [&[u8]; 3] = [
            bytemuck::cast_slice(&scene.nodes),
            bytemuck::cast_slice(&scene.triangles),
            bytemuck::cast_slice(&scene.attributes),
        ];
        let paged = ctx.options.geometry == GeometryPlacement::Textures
            || geometry_bytes.iter().any(|b| b.len() as u64 > limits.max_storage_buffer_binding_size);
        let (nodes, triangles, attributes, paged_bytes) = if paged {
            let [a, b, c] = super::geometry::geometry_textures(&ctx, geometry_bytes)?;
            let bytes = geometry_bytes.iter().map(|b| b.len() as u64).sum();
            (Geometry::Texture(a), Geometry::Texture(b), Geometry::Texture(c), bytes)
        } else {
            (
                Geometry::Buffer(storage("bvh nodes", geometry_bytes[0])?),
                Geometry::Buffer(storage("triangles", geometry_bytes[1])?),
                Geometry::Buffer(storage("vertex attributes", geometry_bytes[2])?),
                0,
            )
        };
        let (textures, texture_bytes) = super::textures::texture_array(&ctx, scene)?;
        let resources = SceneResources {
            nodes,
            triangles,
            attributes,
            materials: storage("materials", bytemuck::cast_slice(&scene.materials))?,
            lights: storage("lights", bytemuck::cast_slice(&scene.light_rows))?,
            light_data: storage("light data", bytemuck::cast_slice(&scene.light_data))?,
            textures,
        };
        // One Params slot per dispatch of a batch, each at an aligned offset.
        let params_size = std::mem::size_of::<Params>() as u64;
        let stride = params_size.next_multiple_of(limits.min_storage_buffer_offset_alignment as u64);
        let params_buf = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("params"),
            size: stride * MAX_BATCH as u64,
            usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });

        let variant = if paged { shaders::Geometry::Textures } else { shaders::Geometry::Buffers };
        let module = shaders::module(&ctx, shaders::INTEGRATOR, variant)?;
        let layout = bindings::layout(device, paged);
        let pipeline_layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("integrator"),
            bind_group_layouts: &[Some(&layout)],
            immediate_size: 0,
        });
        let features = crate::packed::Features { aovs: params.aov_base > 0, ..scene.features() };
        let constants = features.constants();
        let (pipeline, settle) = Self::pipelines(device, &pipeline_layout, &module, &constants);
        let film = DeviceFilm::new(&ctx, params.film_width, params.film_height, params.film_layout())?;
        let bind_group = bindings::bind_group(device, &layout, &resources, &params_buf, &film.buffer);
        let gpu_bytes = resources.buffer_bytes() + film.buffer.size() + params_buf.size() + texture_bytes + paged_bytes;
        ctx.check()?;
        Ok(GpuRenderer {
            ctx,
            pipeline,
            settle,
            layout,
            module,
            pipeline_layout,
            #[cfg(feature = "bench")]
            variant,
            constants,
            #[cfg(feature = "bench")]
            trace_pipelines: [None, None, None],
            scene: resources,
            bind_group,
            params_buf,
            film,
            stride,
            params,
            taken: 0,
            gpu_bytes,
        })
    }

    /// The integrator's two entry points for a set of override constants.
    fn pipelines(
        device: &wgpu::Device,
        layout: &wgpu::PipelineLayout,
        module: &wgpu::ShaderModule,
        constants: &[(&str, f64)],
    ) -> (wgpu::ComputePipeline, wgpu::ComputePipeline) {
        let entry = |name: &str| {
            device.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
                label: Some(name),
                layout: Some(layout),
                module,
                entry_point: Some(name),
                compilation_options: wgpu::PipelineCompilationOptions { constants, ..Default::default() },
                cache: None,
            })
        };
        (entry("render_sample"), entry("adaptive_settle"))
    }

    /// A new film for `params`' window and the bind group over it; the pipelines again when
    /// the film gains or loses its AOVs (the kernel compiles them in or out).
    fn new_film(&mut self, params: Params) -> Result<(), Error> {
        let aovs = if params.aov_base > 0 { 1.0 } else { 0.0 };
        if let Some(c) = self.constants.iter_mut().find(|c| c.0 == "AOVS")
            && c.1 != aovs
        {
            c.1 = aovs;
            (self.pipeline, self.settle) =
                Self::pipelines(&self.ctx.device, &self.pipeline_layout, &self.module, &self.constants);
            #[cfg(feature = "bench")]
            {
                self.trace_pipelines = [None, None, None];
            }
        }
        self.film = DeviceFilm::new(&self.ctx, params.film_width, params.film_height, params.film_layout())?;
        self.bind_group =
            bindings::bind_group(&self.ctx.device, &self.layout, &self.scene, &self.params_buf, &self.film.buffer);
        Ok(())
    }

    /// A new environment: the light-data buffer is replaced (geometry stays on the device)
    /// and accumulation restarts with `params`.
    pub fn set_environment(&mut self, scene: &PackedScene, params: Params) -> Result<(), Error> {
        self.scene.light_data =
            storage_buffer(&self.ctx.device, "light data", bytemuck::cast_slice(&scene.light_data))?;
        self.new_film(params)?;
        self.params = params;
        self.taken = 0;
        self.ctx.check()
    }

    /// New parameters (camera, settings, window) and an empty film: the viewer's restart.
    pub fn reset(&mut self, params: Params) -> Result<(), Error> {
        self.taken = 0;
        if (params.film_width, params.film_height, params.film_layout())
            != (self.film.width, self.film.height, self.film.layout)
        {
            self.new_film(params)?;
        } else {
            self.film.clear(&self.ctx);
        }
        self.params = params;
        self.ctx.check()
    }

    pub fn film_buffer(&self) -> &wgpu::Buffer {
        &self.film.buffer
    }

    pub fn context(&self) -> &GpuContext {
        &self.ctx
    }

    pub fn adapter_name(&self) -> String {
        self.ctx.adapter_name()
    }

    /// Renders sample indices `start .. start + count` (one dispatch each, and a settling
    /// dispatch after each convergence test of adaptive sampling) and waits.
    pub fn render_samples(&mut self, start: u32, count: u32) -> Result<(), Error> {
        self.dispatch_samples(&self.pipeline, start, 1, count, Some(self.taken))?;
        self.taken += count;
        Ok(())
    }

    /// `count` dispatches of `pipeline` at sample indices `start`, `start + step`, ... (step 0:
    /// the same sample again), in batches of MAX_BATCH; with `taken` (the samples pixels still
    /// sampling took before), settles the tests due.
    pub(super) fn dispatch_samples(
        &self,
        pipeline: &wgpu::ComputePipeline,
        start: u32,
        step: u32,
        count: u32,
        taken: Option<u32>,
    ) -> Result<(), Error> {
        let groups =
            (self.params.film_width.div_ceil(WORKGROUP_SIDE), self.params.film_height.div_ceil(WORKGROUP_SIDE));
        let mut done = 0;
        while done < count {
            let batch = (count - done).min(MAX_BATCH);
            let mut data = vec![0u8; (self.stride * batch as u64) as usize];
            for k in 0..batch {
                let p = Params { sample_index: start + (done + k) * step, ..self.params };
                let at = (self.stride * k as u64) as usize;
                data[at..at + std::mem::size_of::<Params>()].copy_from_slice(bytemuck::bytes_of(&p));
            }
            self.ctx.queue.write_buffer(&self.params_buf, 0, &data);
            let mut encoder = self.ctx.device.create_command_encoder(&Default::default());
            {
                let mut pass = encoder.begin_compute_pass(&Default::default());
                pass.set_pipeline(pipeline);
                for k in 0..batch {
                    pass.set_bind_group(0, &self.bind_group, &[(self.stride * k as u64) as u32]);
                    pass.dispatch_workgroups(groups.0, groups.1, 1);
                    if taken.is_some_and(|t| adaptive_test_due(&self.params, t + done + k + 1)) {
                        self.settle_in(&mut pass);
                        pass.set_pipeline(pipeline);
                    }
                }
            }
            let index = self.ctx.queue.submit([encoder.finish()]);
            self.ctx.wait(index)?;
            done += batch;
        }
        Ok(())
    }

    /// Records adaptive sampling's settling pass over the whole film (the bind group set).
    fn settle_in(&self, pass: &mut wgpu::ComputePass<'_>) {
        pass.set_pipeline(&self.settle);
        pass.dispatch_workgroups(
            self.params.film_width.div_ceil(WORKGROUP_SIDE),
            self.params.film_height.div_ceil(WORKGROUP_SIDE),
            1,
        );
    }

    /// Renders sample `sample` of film rows `y0 .. y0 + rows` only (`y0` and `rows` multiples
    /// of the workgroup height, so that bands never overlap).
    pub fn render_rows(&mut self, sample: u32, y0: u32, rows: u32) -> Result<(), Error> {
        let p = Params { sample_index: sample, row_offset: y0, ..self.params };
        self.ctx.queue.write_buffer(&self.params_buf, 0, bytemuck::bytes_of(&p));
        let mut encoder = self.ctx.device.create_command_encoder(&Default::default());
        {
            let mut pass = encoder.begin_compute_pass(&Default::default());
            pass.set_pipeline(&self.pipeline);
            pass.set_bind_group(0, &self.bind_group, &[0]);
            pass.dispatch_workgroups(self.params.film_width.div_ceil(WORKGROUP_SIDE), rows.div_ceil(WORKGROUP_SIDE), 1);
            // The last band of a sample settles a convergence test when one is due.
            if y0 + rows >= self.params.film_height {
                self.taken += 1;
                if adaptive_test_due(&self.params, self.taken) {
                    self.settle_in(&mut pass);
                }
            }
        }
        let index = self.ctx.queue.submit([encoder.finish()]);
        self.ctx.wait(index)
    }

    /// Replaces the film on the device (resume); its layout matches the parameters.
    pub fn upload_film(&mut self, film: &Film) {
        self.film.upload(&self.ctx, film);
        self.taken = film.samples();
    }

    /// The fraction of pixels that converged (None: not adaptive).
    pub fn converged_fraction(&self) -> Result<Option<f64>, Error> {
        if !self.film.layout.adaptive {
            return Ok(None);
        }
        let pixels = (self.film.width as u64 * self.film.height as u64).max(1);
        Ok(Some(self.film.converged_pixels(&self.ctx)? as f64 / pixels as f64))
    }

    pub fn read_film(&self) -> Result<Film, Error> {
        self.film.read(&self.ctx)
    }
}
