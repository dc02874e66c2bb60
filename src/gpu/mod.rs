//! The GPU backend: device selection, the packed scene in buffers, and the progressive
//! one-sample-per-dispatch kernel.

pub mod shaders;

use crate::Error;
use crate::film::{Film, WORDS_PER_PIXEL};
use crate::packed::PackedScene;
use crate::params::Params;
use std::sync::{Arc, Mutex};
use wgpu::util::DeviceExt;

pub const NO_ADAPTER_HINT: &str = "no GPU adapter found (Vulkan, Metal or DX12); for the GPU path install a Vulkan driver (Debian/Ubuntu: apt-get install mesa-vulkan-drivers)";

/// The native backends that run compute shaders; WGPU_BACKEND narrows them.
const BACKENDS: wgpu::Backends = wgpu::Backends::VULKAN.union(wgpu::Backends::METAL).union(wgpu::Backends::DX12);

fn instance() -> wgpu::Instance {
    wgpu::Instance::new(wgpu::InstanceDescriptor {
        backends: BACKENDS.with_env(),
        flags: wgpu::InstanceFlags::empty().with_env(),
        ..wgpu::InstanceDescriptor::new_without_display_handle()
    })
}

/// Every adapter found on the compute backends, with its limits.
pub fn adapters() -> Vec<(wgpu::AdapterInfo, wgpu::Limits)> {
    let inst = instance();
    pollster::block_on(inst.enumerate_adapters(BACKENDS.with_env()))
        .iter()
        .map(|a| (a.get_info(), a.limits()))
        .collect()
}

/// A device and queue, with wgpu errors captured instead of panicking.
#[derive(Clone)]
pub struct GpuContext {
    pub device: wgpu::Device,
    pub queue: wgpu::Queue,
    pub info: wgpu::AdapterInfo,
    errors: Arc<Mutex<Option<String>>>,
}

impl GpuContext {
    /// Wraps a device opened elsewhere (the viewer's window), capturing its errors.
    pub fn from_device(device: wgpu::Device, queue: wgpu::Queue, info: wgpu::AdapterInfo) -> GpuContext {
        let errors = Arc::new(Mutex::new(None));
        let sink = errors.clone();
        device.on_uncaptured_error(Arc::new(move |e: wgpu::Error| {
            if let Ok(mut slot) = sink.lock() {
                slot.get_or_insert_with(|| e.to_string());
            }
        }));
        GpuContext { device, queue, info, errors }
    }

    /// The adapter's driver, as `veach info` prints it.
    pub fn driver(&self) -> String {
        format!("{} {}", self.info.driver, self.info.driver_info)
    }

    pub fn new() -> Result<GpuContext, Error> {
        let inst = instance();
        // WGPU_ADAPTER_NAME picks an adapter by name; an unmatched name is our error, not a panic.
        let wanted = std::env::var("WGPU_ADAPTER_NAME").ok().map(|s| s.to_lowercase());
        let adapter = match wanted {
            Some(name) => pollster::block_on(inst.enumerate_adapters(BACKENDS.with_env()))
                .into_iter()
                .find(|a| a.get_info().name.to_lowercase().contains(&name))
                .ok_or_else(|| Error::NoAdapter(format!("no GPU adapter matches WGPU_ADAPTER_NAME={name}")))?,
            None => pollster::block_on(inst.request_adapter(&wgpu::RequestAdapterOptions {
                power_preference: wgpu::PowerPreference::HighPerformance,
                ..Default::default()
            }))
            .map_err(|_| Error::NoAdapter(NO_ADAPTER_HINT.to_string()))?,
        };
        let info = adapter.get_info();
        let limits = adapter.limits();
        let (device, queue) = pollster::block_on(adapter.request_device(&wgpu::DeviceDescriptor {
            label: Some("veach"),
            required_limits: limits,
            ..Default::default()
        }))
        .map_err(|e| Error::Gpu(format!("cannot open {}: {e}", info.name)))?;
        let ctx = GpuContext::from_device(device, queue, info);
        let lost = ctx.errors.clone();
        ctx.device.set_device_lost_callback(move |_reason, msg| {
            if let Ok(mut slot) = lost.lock() {
                slot.get_or_insert_with(|| format!("device lost: {msg}"));
            }
        });
        Ok(ctx)
    }

    pub fn check(&self) -> Result<(), Error> {
        match self.errors.lock().ok().and_then(|mut e| e.take()) {
            Some(msg) => Err(Error::Gpu(msg)),
            None => Ok(()),
        }
    }

    pub fn adapter_name(&self) -> String {
        format!("{} ({:?}, {})", self.info.name, self.info.device_type, self.info.driver)
    }
}

/// Texels per row of the paged-geometry textures, as a power of two (PAGE_ROW_LOG2 in
/// shaders/geometry_textures.wgsl).
pub const PAGE_ROW_LOG2: u32 = 12;

/// Samples per submission: enough to amortise the submit, few enough to stay responsive.
pub const MAX_BATCH: u32 = 64;

pub struct GpuRenderer {
    ctx: GpuContext,
    pipeline: wgpu::ComputePipeline,
    layout: wgpu::BindGroupLayout,
    pipeline_layout: wgpu::PipelineLayout,
    variant: shaders::Geometry,
    constants: [(&'static str, f64); 5],
    /// `trace_rays` pipelines by TRACE_KIND, built on first use (by `veach bench` only).
    trace_pipelines: [Option<wgpu::ComputePipeline>; 3],
    scene: [wgpu::Buffer; 6],
    /// Nodes, triangles and attributes as textures (bindings 1–3) when the scene is beyond a
    /// storage binding; `scene[0..3]` are then unused placeholders.
    geometry: Option<[wgpu::TextureView; 3]>,
    textures: wgpu::TextureView,
    bind_group: wgpu::BindGroup,
    params_buf: wgpu::Buffer,
    film_buf: wgpu::Buffer,
    readback: wgpu::Buffer,
    stride: u64,
    params: Params,
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
        let paged = std::env::var("VEACH_GEOMETRY").as_deref() == Ok("textures")
            || geometry_bytes.iter().any(|b| b.len() as u64 > limits.max_storage_buffer_binding_size);
        let geometry = if paged { Some(Self::geometry_textures(&ctx, geometry_bytes)?) } else { None };
        let placeholder: [&[u8]; 3] = [&[], &[], &[]];
        let geometry_buffers = if paged { placeholder } else { geometry_bytes };
        let scene_buffers = [
            storage("bvh nodes", geometry_buffers[0])?,
            storage("triangles", geometry_buffers[1])?,
            storage("vertex attributes", geometry_buffers[2])?,
            storage("materials", bytemuck::cast_slice(&scene.materials))?,
            storage("lights", bytemuck::cast_slice(&scene.lights))?,
            storage("light data", bytemuck::cast_slice(&scene.light_data))?,
        ];
        let (textures, texture_bytes) = Self::texture_array(&ctx, scene)?;
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
        let source = shaders::compose_with(shaders::INTEGRATOR, variant).map_err(Error::Gpu)?;
        let descriptor =
            wgpu::ShaderModuleDescriptor { label: Some("integrator"), source: wgpu::ShaderSource::Wgsl(source.into()) };
        let module = device.create_shader_module(descriptor);
        if let Err(e) = ctx.check() {
            // Name the shader file and line rather than the composed source.
            return Err(shaders::check(shaders::INTEGRATOR, variant).err().map_or(e, Error::Gpu));
        }
        let storage_entry = |binding: u32, read_only: bool| wgpu::BindGroupLayoutEntry {
            binding,
            visibility: wgpu::ShaderStages::COMPUTE,
            ty: wgpu::BindingType::Buffer {
                ty: wgpu::BufferBindingType::Storage { read_only },
                has_dynamic_offset: false,
                min_binding_size: None,
            },
            count: None,
        };
        let layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("scene"),
            entries: &[
                wgpu::BindGroupLayoutEntry {
                    binding: 0,
                    visibility: wgpu::ShaderStages::COMPUTE,
                    ty: wgpu::BindingType::Buffer {
                        ty: wgpu::BufferBindingType::Storage { read_only: true },
                        has_dynamic_offset: true,
                        min_binding_size: wgpu::BufferSize::new(params_size),
                    },
                    count: None,
                },
                geometry_entry(1, paged),
                geometry_entry(2, paged),
                geometry_entry(3, paged),
                storage_entry(4, true),
                storage_entry(5, true),
                storage_entry(6, false),
                storage_entry(7, true),
                wgpu::BindGroupLayoutEntry {
                    binding: 8,
                    visibility: wgpu::ShaderStages::COMPUTE,
                    ty: wgpu::BindingType::Texture {
                        sample_type: wgpu::TextureSampleType::Float { filterable: false },
                        view_dimension: wgpu::TextureViewDimension::D2Array,
                        multisampled: false,
                    },
                    count: None,
                },
            ],
        });
        let pipeline_layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("integrator"),
            bind_group_layouts: &[Some(&layout)],
            immediate_size: 0,
        });
        let constants = scene.features().constants();
        let pipeline = device.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
            label: Some("integrator"),
            layout: Some(&pipeline_layout),
            module: &module,
            entry_point: Some("render_sample"),
            compilation_options: wgpu::PipelineCompilationOptions { constants: &constants, ..Default::default() },
            cache: None,
        });
        let (film_buf, readback, bind_group) =
            Self::film(&ctx, &layout, &scene_buffers, geometry.as_ref(), &textures, &params_buf, params)?;
        let paged_bytes = if paged { geometry_bytes.iter().map(|b| b.len() as u64).sum() } else { 0 };
        let gpu_bytes = scene_buffers.iter().chain([&film_buf, &params_buf]).map(|b| b.size()).sum::<u64>()
            + texture_bytes
            + paged_bytes;
        ctx.check()?;
        Ok(GpuRenderer {
            ctx,
            pipeline,
            layout,
            pipeline_layout,
            variant,
            constants,
            trace_pipelines: [None, None, None],
            scene: scene_buffers,
            geometry,
            textures,
            bind_group,
            params_buf,
            film_buf,
            readback,
            stride,
            params,
            gpu_bytes,
        })
    }

    /// Geometry records paged into rgba32uint textures, 4096 texels a row
    /// (shaders/geometry_textures.wgsl).
    fn geometry_textures(ctx: &GpuContext, data: [&[u8]; 3]) -> Result<[wgpu::TextureView; 3], Error> {
        const ROW: usize = 1 << PAGE_ROW_LOG2;
        let limits = ctx.device.limits();
        let names = ["BVH nodes", "triangles", "vertex attributes"];
        let mut views = Vec::new();
        for (bytes, name) in data.iter().zip(names) {
            let texels = bytes.len().div_ceil(16).max(1);
            let rows = texels.div_ceil(ROW);
            if rows as u64 > limits.max_texture_dimension_2d as u64 {
                return Err(Error::Limit(format!(
                    "the scene's {name} need {rows} texture rows of {ROW} texels, above the device's \
                     max_texture_dimension_2d = {}",
                    limits.max_texture_dimension_2d
                )));
            }
            let mut padded = bytes.to_vec();
            padded.resize(rows * ROW * 16, 0);
            let texture = ctx.device.create_texture_with_data(
                &ctx.queue,
                &wgpu::TextureDescriptor {
                    label: Some(name),
                    size: wgpu::Extent3d { width: ROW as u32, height: rows as u32, depth_or_array_layers: 1 },
                    mip_level_count: 1,
                    sample_count: 1,
                    dimension: wgpu::TextureDimension::D2,
                    format: wgpu::TextureFormat::Rgba32Uint,
                    usage: wgpu::TextureUsages::TEXTURE_BINDING,
                    view_formats: &[],
                },
                wgpu::util::TextureDataOrder::LayerMajor,
                &padded,
            );
            views.push(texture.create_view(&Default::default()));
        }
        let [a, b, c]: [wgpu::TextureView; 3] = views.try_into().map_err(|_| Error::Gpu("geometry views".into()))?;
        Ok([a, b, c])
    }

    /// The scene's images as one texture array (RGBA8, one square layer per image).
    fn texture_array(ctx: &GpuContext, scene: &PackedScene) -> Result<(wgpu::TextureView, u64), Error> {
        let limits = ctx.device.limits();
        let (side, layers) = (scene.texture_size, scene.texture_layers);
        if side > limits.max_texture_dimension_2d || layers > limits.max_texture_array_layers {
            return Err(Error::Limit(format!(
                "{layers} textures of {side}² texels exceed the device's texture arrays \
                 (max_texture_dimension_2d = {}, max_texture_array_layers = {})",
                limits.max_texture_dimension_2d, limits.max_texture_array_layers
            )));
        }
        let texture = ctx.device.create_texture_with_data(
            &ctx.queue,
            &wgpu::TextureDescriptor {
                label: Some("textures"),
                size: wgpu::Extent3d { width: side, height: side, depth_or_array_layers: layers },
                mip_level_count: 1,
                sample_count: 1,
                dimension: wgpu::TextureDimension::D2,
                format: wgpu::TextureFormat::Rgba8Unorm,
                usage: wgpu::TextureUsages::TEXTURE_BINDING,
                view_formats: &[],
            },
            wgpu::util::TextureDataOrder::LayerMajor,
            bytemuck::cast_slice(&scene.texels),
        );
        let view = texture.create_view(&wgpu::TextureViewDescriptor {
            dimension: Some(wgpu::TextureViewDimension::D2Array),
            ..Default::default()
        });
        Ok((view, scene.texels.len() as u64 * 4))
    }

    /// A zeroed film for `params`' window, its readback buffer and the bind group using it.
    fn film(
        ctx: &GpuContext,
        layout: &wgpu::BindGroupLayout,
        scene: &[wgpu::Buffer; 6],
        geometry: Option<&[wgpu::TextureView; 3]>,
        textures: &wgpu::TextureView,
        params_buf: &wgpu::Buffer,
        params: Params,
    ) -> Result<(wgpu::Buffer, wgpu::Buffer, wgpu::BindGroup), Error> {
        let device = &ctx.device;
        let limits = device.limits();
        let pixels = params.film_width as u64 * params.film_height as u64;
        let film_bytes = pixels * (WORDS_PER_PIXEL * 4) as u64;
        check_limit("film", film_bytes, limits.max_storage_buffer_binding_size, "max_storage_buffer_binding_size")?;
        let film_buf = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("film"),
            size: film_bytes,
            usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_SRC | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        let readback = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("film readback"),
            size: film_bytes,
            usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        let params_size = std::mem::size_of::<Params>() as u64;
        let bind_group = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("scene"),
            layout,
            entries: &[
                wgpu::BindGroupEntry {
                    binding: 0,
                    resource: wgpu::BindingResource::Buffer(wgpu::BufferBinding {
                        buffer: params_buf,
                        offset: 0,
                        size: wgpu::BufferSize::new(params_size),
                    }),
                },
                geometry_binding(1, &scene[0], geometry.map(|g| &g[0])),
                geometry_binding(2, &scene[1], geometry.map(|g| &g[1])),
                geometry_binding(3, &scene[2], geometry.map(|g| &g[2])),
                entry(4, &scene[3]),
                entry(5, &scene[4]),
                entry(6, &film_buf),
                entry(7, &scene[5]),
                wgpu::BindGroupEntry { binding: 8, resource: wgpu::BindingResource::TextureView(textures) },
            ],
        });
        Ok((film_buf, readback, bind_group))
    }

    /// A new environment: the light-data buffer is replaced (geometry stays on the device)
    /// and accumulation restarts with `params`.
    pub fn set_environment(&mut self, scene: &PackedScene, params: Params) -> Result<(), Error> {
        self.scene[5] = storage_buffer(&self.ctx.device, "light data", bytemuck::cast_slice(&scene.light_data))?;
        let (film, readback, bind_group) = Self::film(
            &self.ctx,
            &self.layout,
            &self.scene,
            self.geometry.as_ref(),
            &self.textures,
            &self.params_buf,
            params,
        )?;
        (self.film_buf, self.readback, self.bind_group) = (film, readback, bind_group);
        self.params = params;
        self.ctx.check()
    }

    /// New parameters (camera, settings, window) and an empty film: the viewer's restart.
    pub fn reset(&mut self, params: Params) -> Result<(), Error> {
        if (params.film_width, params.film_height) != (self.params.film_width, self.params.film_height) {
            let (film, readback, bind_group) = Self::film(
                &self.ctx,
                &self.layout,
                &self.scene,
                self.geometry.as_ref(),
                &self.textures,
                &self.params_buf,
                params,
            )?;
            (self.film_buf, self.readback, self.bind_group) = (film, readback, bind_group);
        } else {
            let mut encoder = self.ctx.device.create_command_encoder(&Default::default());
            encoder.clear_buffer(&self.film_buf, 0, None);
            self.ctx.queue.submit([encoder.finish()]);
        }
        self.params = params;
        self.ctx.check()
    }

    pub fn film_buffer(&self) -> &wgpu::Buffer {
        &self.film_buf
    }

    pub fn context(&self) -> &GpuContext {
        &self.ctx
    }

    pub fn adapter_name(&self) -> String {
        self.ctx.adapter_name()
    }

    /// Renders sample indices `start .. start + count` (one dispatch each) and waits.
    pub fn render_samples(&mut self, start: u32, count: u32) -> Result<(), Error> {
        self.dispatch_samples(None, start, count)
    }

    /// Traversal throughput (`shaders/trace.wgsl`): `passes` dispatches of the ray kernel of
    /// kind `kind` (0 primary, 1 primary + shadow, 2 primary + diffuse bounce) into a cleared
    /// film; returns the seconds they took (the pipeline is compiled before timing starts).
    pub fn trace_rays(&mut self, kind: u32, passes: u32) -> Result<f64, Error> {
        let k = kind.min(2) as usize;
        if self.trace_pipelines[k].is_none() {
            let source = shaders::compose_with(shaders::TRACE, self.variant).map_err(Error::Gpu)?;
            let module = self.ctx.device.create_shader_module(wgpu::ShaderModuleDescriptor {
                label: Some("trace"),
                source: wgpu::ShaderSource::Wgsl(source.into()),
            });
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
            self.trace_pipelines[k] = Some(pipeline);
            // Lavapipe compiles at first dispatch: one untimed pass.
            self.dispatch_samples(Some(k), 0, 1)?;
            self.ctx.check()?;
        }
        self.reset(self.params)?;
        let t = std::time::Instant::now();
        self.dispatch_samples(Some(k), 0, passes)?;
        Ok(t.elapsed().as_secs_f64())
    }

    /// `count` dispatches from sample index `start`, of the integrator or of a trace kernel.
    fn dispatch_samples(&self, trace: Option<usize>, start: u32, count: u32) -> Result<(), Error> {
        let pipeline = match trace {
            Some(k) => self.trace_pipelines[k].as_ref().ok_or_else(|| Error::Gpu("no trace pipeline".into()))?,
            None => &self.pipeline,
        };
        let mut done = 0;
        while done < count {
            let batch = (count - done).min(MAX_BATCH);
            let mut data = vec![0u8; (self.stride * batch as u64) as usize];
            for k in 0..batch {
                let p = Params { sample_index: start + done + k, ..self.params };
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
                    pass.dispatch_workgroups(
                        self.params.film_width.div_ceil(8),
                        self.params.film_height.div_ceil(8),
                        1,
                    );
                }
            }
            let index = self.ctx.queue.submit([encoder.finish()]);
            self.wait(index)?;
            done += batch;
        }
        Ok(())
    }

    /// Renders sample `sample` of film rows `y0 .. y0 + rows` only (`y0` and `rows` multiples
    /// of 8, the workgroup height, so that bands never overlap).
    pub fn render_rows(&mut self, sample: u32, y0: u32, rows: u32) -> Result<(), Error> {
        let p = Params { sample_index: sample, row_offset: y0, ..self.params };
        self.ctx.queue.write_buffer(&self.params_buf, 0, bytemuck::bytes_of(&p));
        let mut encoder = self.ctx.device.create_command_encoder(&Default::default());
        {
            let mut pass = encoder.begin_compute_pass(&Default::default());
            pass.set_pipeline(&self.pipeline);
            pass.set_bind_group(0, &self.bind_group, &[0]);
            pass.dispatch_workgroups(self.params.film_width.div_ceil(8), rows.div_ceil(8), 1);
        }
        let index = self.ctx.queue.submit([encoder.finish()]);
        self.wait(index)
    }

    fn wait(&self, index: wgpu::SubmissionIndex) -> Result<(), Error> {
        self.ctx
            .device
            .poll(wgpu::PollType::Wait { submission_index: Some(index), timeout: None })
            .map_err(|e| Error::Gpu(format!("waiting for the GPU: {e}")))?;
        self.ctx.check()
    }

    /// Replaces the film on the device (resume, or a fresh start).
    pub fn upload_film(&mut self, film: &Film) {
        self.ctx.queue.write_buffer(&self.film_buf, 0, bytemuck::cast_slice(&film.data));
    }

    pub fn read_film(&self) -> Result<Film, Error> {
        let mut encoder = self.ctx.device.create_command_encoder(&Default::default());
        encoder.copy_buffer_to_buffer(&self.film_buf, 0, &self.readback, 0, self.film_buf.size());
        let index = self.ctx.queue.submit([encoder.finish()]);
        let (tx, rx) = std::sync::mpsc::channel();
        self.readback.slice(..).map_async(wgpu::MapMode::Read, move |r| {
            let _ = tx.send(r);
        });
        self.wait(index)?;
        rx.recv()
            .map_err(|_| Error::Gpu("film readback was dropped".into()))?
            .map_err(|e| Error::Gpu(format!("film readback: {e}")))?;
        let mut film = Film::new(self.params.film_width, self.params.film_height);
        {
            let view = self.readback.slice(..).get_mapped_range().map_err(|e| Error::Gpu(e.to_string()))?;
            film.data.copy_from_slice(bytemuck::cast_slice(&view));
        }
        self.readback.unmap();
        Ok(film)
    }
}

/// Layout of a geometry binding: a read-only storage buffer, or a u32 texture when paged.
fn geometry_entry(binding: u32, paged: bool) -> wgpu::BindGroupLayoutEntry {
    let ty = if paged {
        wgpu::BindingType::Texture {
            sample_type: wgpu::TextureSampleType::Uint,
            view_dimension: wgpu::TextureViewDimension::D2,
            multisampled: false,
        }
    } else {
        wgpu::BindingType::Buffer {
            ty: wgpu::BufferBindingType::Storage { read_only: true },
            has_dynamic_offset: false,
            min_binding_size: None,
        }
    };
    wgpu::BindGroupLayoutEntry { binding, visibility: wgpu::ShaderStages::COMPUTE, ty, count: None }
}

fn geometry_binding<'a>(
    binding: u32,
    buffer: &'a wgpu::Buffer,
    view: Option<&'a wgpu::TextureView>,
) -> wgpu::BindGroupEntry<'a> {
    match view {
        Some(v) => wgpu::BindGroupEntry { binding, resource: wgpu::BindingResource::TextureView(v) },
        None => entry(binding, buffer),
    }
}

fn entry(binding: u32, buffer: &wgpu::Buffer) -> wgpu::BindGroupEntry<'_> {
    wgpu::BindGroupEntry { binding, resource: buffer.as_entire_binding() }
}

fn check_limit(what: &str, bytes: u64, limit: u64, name: &str) -> Result<(), Error> {
    if bytes > limit {
        // Only the film shrinks with a tile; the scene's buffers do not.
        let advice = if what == "film" { "; render tiles (--tile)" } else { "" };
        return Err(Error::Limit(format!(
            "the {what} buffer needs {bytes} bytes, above the device limit {name} = {limit}{advice}"
        )));
    }
    Ok(())
}

/// A read-only storage buffer holding `bytes`, within the device's binding limits.
fn storage_buffer(device: &wgpu::Device, label: &str, bytes: &[u8]) -> Result<wgpu::Buffer, Error> {
    let limits = device.limits();
    let len = bytes.len() as u64;
    check_limit(label, len, limits.max_storage_buffer_binding_size, "max_storage_buffer_binding_size")?;
    check_limit(label, len, limits.max_buffer_size, "max_buffer_size")?;
    // Zero-sized bindings are invalid; an empty array gets one zeroed element.
    let padded;
    let contents = if bytes.is_empty() {
        padded = vec![0u8; 16];
        &padded[..]
    } else {
        bytes
    };
    Ok(device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
        label: Some(label),
        contents,
        usage: wgpu::BufferUsages::STORAGE,
    }))
}
