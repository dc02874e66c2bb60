//! The film on screen without a readback: a compute pass (`shaders/display.wgsl`) exposes,
//! tone-maps and sRGB-encodes a GPU film into an RGBA8 storage texture that a window can
//! draw. The twin of `output::tonemap` on the host.

use super::{GpuContext, WORKGROUP_SIDE, shaders};
use crate::Error;
use crate::tonemap::Tonemap;

/// How the film is shown.
#[derive(Clone, Copy, Debug)]
pub struct Look {
    pub exposure: f32,
    pub tonemap: Tonemap,
    /// > 0: the samples each pixel took, as a heat map up to this count, instead of the image.
    pub heat_max: u32,
}

pub struct Display {
    pipeline: wgpu::ComputePipeline,
    layout: wgpu::BindGroupLayout,
    params: wgpu::Buffer,
    target: Option<(wgpu::Texture, wgpu::TextureView, u32, u32)>,
}

impl Display {
    pub fn new(ctx: &GpuContext) -> Result<Display, Error> {
        let device = &ctx.device;
        let module = shaders::module(ctx, shaders::DISPLAY, shaders::Geometry::Buffers)?;
        let buffer = |binding| wgpu::BindGroupLayoutEntry {
            binding,
            visibility: wgpu::ShaderStages::COMPUTE,
            ty: wgpu::BindingType::Buffer {
                ty: wgpu::BufferBindingType::Storage { read_only: true },
                has_dynamic_offset: false,
                min_binding_size: None,
            },
            count: None,
        };
        let layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("display"),
            entries: &[
                buffer(0),
                buffer(1),
                wgpu::BindGroupLayoutEntry {
                    binding: 2,
                    visibility: wgpu::ShaderStages::COMPUTE,
                    ty: wgpu::BindingType::StorageTexture {
                        access: wgpu::StorageTextureAccess::WriteOnly,
                        format: wgpu::TextureFormat::Rgba8Unorm,
                        view_dimension: wgpu::TextureViewDimension::D2,
                    },
                    count: None,
                },
            ],
        });
        let pipeline_layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("display"),
            bind_group_layouts: &[Some(&layout)],
            immediate_size: 0,
        });
        let pipeline = device.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
            label: Some("display"),
            layout: Some(&pipeline_layout),
            module: &module,
            entry_point: Some("resolve"),
            compilation_options: Default::default(),
            cache: None,
        });
        let params = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("display params"),
            size: 32,
            usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        ctx.check()?;
        Ok(Display { pipeline, layout, params, target: None })
    }

    /// Resolves the `w`×`h` film in `film` into the display texture; returns its view and
    /// whether the texture is new (its size changed), so a window re-registers it. With
    /// `heat_max` > 0 it shows the samples each pixel took, as a heat map up to that count.
    pub fn resolve(
        &mut self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        film: &wgpu::Buffer,
        (w, h): (u32, u32),
        look: Look,
    ) -> (&wgpu::TextureView, bool) {
        let Look { exposure, tonemap, heat_max } = look;
        let stale = self.target.as_ref().is_none_or(|t| (t.2, t.3) != (w, h));
        if stale {
            self.target = None;
        }
        let (_, view, _, _) = self.target.get_or_insert_with(|| {
            let texture = device.create_texture(&wgpu::TextureDescriptor {
                label: Some("display"),
                size: wgpu::Extent3d { width: w, height: h, depth_or_array_layers: 1 },
                mip_level_count: 1,
                sample_count: 1,
                dimension: wgpu::TextureDimension::D2,
                format: wgpu::TextureFormat::Rgba8Unorm,
                usage: wgpu::TextureUsages::STORAGE_BINDING | wgpu::TextureUsages::TEXTURE_BINDING,
                view_formats: &[],
            });
            let view = texture.create_view(&Default::default());
            (texture, view, w, h)
        });
        let view = &*view;
        // The film buffer may have been replaced by a reset: bind it anew each time.
        let bind_group = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("display"),
            layout: &self.layout,
            entries: &[
                wgpu::BindGroupEntry { binding: 0, resource: self.params.as_entire_binding() },
                wgpu::BindGroupEntry { binding: 1, resource: film.as_entire_binding() },
                wgpu::BindGroupEntry { binding: 2, resource: wgpu::BindingResource::TextureView(view) },
            ],
        });
        let p = [w, h, tonemap as u32, exposure.exp2().to_bits(), heat_max, 0, 0, 0];
        queue.write_buffer(&self.params, 0, bytemuck::cast_slice(&p));
        let mut encoder = device.create_command_encoder(&Default::default());
        {
            let mut pass = encoder.begin_compute_pass(&Default::default());
            pass.set_pipeline(&self.pipeline);
            pass.set_bind_group(0, &bind_group, &[]);
            pass.dispatch_workgroups(w.div_ceil(WORKGROUP_SIDE), h.div_ceil(WORKGROUP_SIDE), 1);
        }
        queue.submit([encoder.finish()]);
        (view, stale)
    }
}
