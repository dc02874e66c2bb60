//! The network on a wgpu device: `shaders/denoise.wgsl` run layer by layer, the twin of
//! `cpu.rs`. The input and output transforms and the exposure run on the host (they are a
//! few operations a pixel; the images are there anyway), the 16 convolutions on the device.
//!
//! Tiles are sized from the device's limits: the largest tensor must fit one storage binding
//! (128 MiB on lavapipe, GiBs on discrete GPUs) and all of a tile's tensors a memory budget.
//! Long layers are cut into bands of rows so that no dispatch does more than
//! `DISPATCH_MACS` multiply-adds (a real GPU's watchdog resets the device after ~2 s).

use super::network::{Network, Source, UNET_STEPS, levels};
use super::transfer::{Images, output_value};
use super::{Options, plan_tiles};
use crate::Error;
use crate::gpu::GpuContext;
use wgpu::util::DeviceExt;

/// Output channel blocks one invocation computes (`DENOISE_BLOCKS` in the shader).
pub const DENOISE_BLOCKS: u32 = 2;
/// Quads per workgroup side (`@workgroup_size(8, 8)`).
const GROUP: u32 = 8;
/// The most multiply-adds one dispatch does: ~1 ms on a discrete GPU, ~1 s on lavapipe.
pub const DISPATCH_MACS: f64 = 1.5e9;
/// Device memory one tile's tensors may take.
pub const MEMORY_BUDGET: u64 = 1 << 30;

/// `ConvParams` of the shader.
#[repr(C)]
#[derive(Clone, Copy, Debug, bytemuck::Pod, bytemuck::Zeroable)]
pub struct ConvParams {
    pub width: u32,
    pub height: u32,
    pub a_blocks: u32,
    pub b_blocks: u32,
    pub out_blocks: u32,
    pub a_half: u32,
    pub pool: u32,
    pub quad_row_offset: u32,
}

fn binding_entry(binding: u32, buffer: &wgpu::Buffer) -> wgpu::BindGroupEntry<'_> {
    wgpu::BindGroupEntry { binding, resource: buffer.as_entire_binding() }
}

fn blocks(channels: usize) -> usize {
    channels.div_ceil(4)
}

/// A layer's weights as the shader reads them: `[output block][tap][input block]` 4×4
/// matrices whose column i is input channel i of the block; input blocks run over the
/// source's channels, then the skip's (each padded to whole blocks).
pub fn pack_weights(weight: &[f32], inputs: usize, outputs: usize, split: usize) -> Vec<f32> {
    let (a, b) = (blocks(split), blocks(inputs - split));
    let mut out = vec![0.0; blocks(outputs) * 9 * (a + b) * 16];
    for ob in 0..blocks(outputs) {
        for tap in 0..9 {
            for ib in 0..a + b {
                let base = ((ob * 9 + tap) * (a + b) + ib) * 16;
                for i in 0..4 {
                    let c = if ib < a { ib * 4 + i } else { split + (ib - a) * 4 + i };
                    let valid = if ib < a { ib * 4 + i < split } else { c < inputs };
                    for o in 0..4 {
                        let oc = ob * 4 + o;
                        if valid && oc < outputs {
                            out[base + i * 4 + o] = weight[(oc * inputs + c) * 9 + tap];
                        }
                    }
                }
            }
        }
    }
    out
}

/// How the device stores tensors and weights (arithmetic is f32 either way).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Precision {
    F32,
    /// Half the bytes read; OIDN's weights are f16 already, so only the activations round.
    F16,
}

impl Precision {
    /// Bytes of one vec4 of a tensor.
    fn vec4_bytes(self) -> usize {
        match self {
            Precision::F32 => 16,
            Precision::F16 => 8,
        }
    }

    /// `values` as this precision's bytes.
    fn bytes(self, values: &[f32]) -> Vec<u8> {
        match self {
            Precision::F32 => bytemuck::cast_slice(values).to_vec(),
            Precision::F16 => values.iter().flat_map(|v| half::f16::from_f32(*v).to_le_bytes()).collect(),
        }
    }

    /// Bytes of this precision as f32 values.
    fn values(self, bytes: &[u8]) -> Vec<f32> {
        match self {
            Precision::F32 => bytemuck::cast_slice(bytes).to_vec(),
            Precision::F16 => bytes.chunks_exact(2).map(|b| half::f16::from_le_bytes([b[0], b[1]]).to_f32()).collect(),
        }
    }
}

/// The network's weights and the pipeline on one device.
pub struct GpuDenoiser {
    ctx: GpuContext,
    pipeline: wgpu::ComputePipeline,
    layout: wgpu::BindGroupLayout,
    weights: Vec<(wgpu::Buffer, wgpu::Buffer)>,
    net: Network,
    precision: Precision,
    /// The most multiply-adds of one dispatch (`DISPATCH_MACS`; tests lower it to cut every
    /// layer into bands).
    pub dispatch_macs: f64,
}

impl GpuDenoiser {
    /// The network on `ctx`'s device: tensors in f16 where the device has shader-f16.
    pub fn new(ctx: &GpuContext, net: &Network) -> Result<GpuDenoiser, Error> {
        let f16 = ctx.device.features().contains(wgpu::Features::SHADER_F16);
        Self::with_precision(ctx, net, if f16 { Precision::F16 } else { Precision::F32 })
    }

    pub fn with_precision(ctx: &GpuContext, net: &Network, precision: Precision) -> Result<GpuDenoiser, Error> {
        let device = &ctx.device;
        if precision == Precision::F16 && !device.features().contains(wgpu::Features::SHADER_F16) {
            return Err(Error::Gpu(format!("{} has no shader-f16 for f16 tensors", ctx.info.name)));
        }
        let source = crate::gpu::shaders::denoise_source(precision == Precision::F16).map_err(Error::Gpu)?;
        let module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
            label: Some("denoise"),
            source: wgpu::ShaderSource::Wgsl(source.into()),
        });
        ctx.check()?;
        let storage = |binding: u32, read_only: bool, dynamic: bool| wgpu::BindGroupLayoutEntry {
            binding,
            visibility: wgpu::ShaderStages::COMPUTE,
            ty: wgpu::BindingType::Buffer {
                ty: wgpu::BufferBindingType::Storage { read_only },
                has_dynamic_offset: dynamic,
                min_binding_size: None,
            },
            count: None,
        };
        let layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("denoise"),
            entries: &[
                storage(0, true, true),
                storage(1, true, false),
                storage(2, true, false),
                storage(3, true, false),
                storage(4, true, false),
                storage(5, false, false),
            ],
        });
        let pipeline_layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("denoise"),
            bind_group_layouts: &[Some(&layout)],
            immediate_size: 0,
        });
        let pipeline = device.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
            label: Some("conv3x3"),
            layout: Some(&pipeline_layout),
            module: &module,
            entry_point: Some("conv3x3"),
            compilation_options: Default::default(),
            cache: None,
        });
        let mut weights = Vec::new();
        for (s, c) in UNET_STEPS.iter().zip(&net.convs) {
            let split = if s.skip.is_some() { net.channels(s.input) } else { c.inputs };
            let w = pack_weights(&c.weight, c.inputs, c.outputs, split);
            let mut b = c.bias.clone();
            b.resize(blocks(c.outputs) * 4, 0.0);
            weights.push((
                crate::gpu::storage_buffer(device, "denoise weights", &precision.bytes(&w))?,
                crate::gpu::storage_buffer(device, "denoise bias", bytemuck::cast_slice(&b))?,
            ));
        }
        ctx.check()?;
        Ok(GpuDenoiser {
            ctx: ctx.clone(),
            pipeline,
            layout,
            weights,
            net: net.clone(),
            precision,
            dispatch_macs: DISPATCH_MACS,
        })
    }

    pub fn precision(&self) -> Precision {
        self.precision
    }

    /// Bytes of the tensors of a `width`×`height` tile (sides multiples of 16): the input,
    /// and every step's output at its resolution.
    fn tile_bytes(&self, width: usize, height: usize) -> (u64, u64) {
        let lv = levels();
        let vec4 = self.precision.vec4_bytes();
        let mut total = (width * height * blocks(self.net.input_channels) * vec4) as u64;
        let mut largest = total;
        for (k, c) in self.net.convs.iter().enumerate() {
            let pixels = (width >> lv[k]) * (height >> lv[k]);
            let bytes = (pixels * blocks(c.outputs) * vec4) as u64;
            total += bytes;
            largest = largest.max(bytes);
        }
        (total, largest)
    }

    /// The most pixels a tile may have on this device.
    pub fn max_tile_pixels(&self) -> usize {
        let limits = self.ctx.device.limits();
        let binding = limits.max_storage_buffer_binding_size.min(limits.max_buffer_size);
        let (total, largest) = self.tile_bytes(16, 16);
        let per_pixel = |b: u64| b as f64 / 256.0;
        ((binding as f64 / per_pixel(largest)).min(MEMORY_BUDGET as f64 / per_pixel(total)) as usize).max(256)
    }

    /// Denoises `images` (whose channel count matches the network's) on the device.
    pub fn denoise(&self, images: &Images, options: &Options) -> Result<Vec<f32>, Error> {
        images.validate().map_err(Error::Input)?;
        if images.channels() != self.net.input_channels {
            return Err(Error::Input(format!(
                "the network reads {} channels, the images have {}",
                self.net.input_channels,
                images.channels()
            )));
        }
        let scale = options
            .input_scale
            .unwrap_or_else(|| super::transfer::autoexposure(images.color, images.width, images.height));
        let max = options.max_tile_pixels.unwrap_or(usize::MAX).min(self.max_tile_pixels());
        let mut out = vec![0.0; images.width * images.height * 3];
        for tile in plan_tiles(images.width, images.height, max) {
            let input = super::cpu::input_tensor(images, tile.x, tile.y, tile.width, tile.height, scale);
            let result = self.run(&input)?;
            let (ix, iy, iw, ih) = tile.interior;
            for y in iy..iy + ih {
                for x in ix..ix + iw {
                    let at = ((y - tile.y) * tile.width + (x - tile.x)) * 4;
                    for c in 0..3 {
                        out[(y * images.width + x) * 3 + c] = output_value(result[at + c], scale);
                    }
                }
            }
        }
        Ok(out)
    }

    /// Runs the network on one tile's input tensor (padded activation of the CPU twin);
    /// returns the last layer's output, one vec4 a pixel.
    pub fn run(&self, input: &super::cpu::Activation) -> Result<Vec<f32>, Error> {
        let device = &self.ctx.device;
        let (w, h) = (input.width, input.height);
        let (total, largest) = self.tile_bytes(w, h);
        let limits = device.limits();
        crate::gpu::check_limit(
            "denoise tensor",
            largest,
            limits.max_storage_buffer_binding_size,
            "max_storage_buffer_binding_size",
        )?;
        crate::gpu::check_limit("denoise tile", total, MEMORY_BUDGET.max(largest), "veach's denoise budget")?;
        // The input in channel blocks, without the CPU twin's border.
        let ib = blocks(self.net.input_channels);
        let mut blocked = vec![0.0f32; w * h * ib * 4];
        for y in 0..h {
            for x in 0..w {
                for c in 0..input.channels {
                    blocked[((y * w + x) * ib) * 4 + c] = input.at(x, y, c);
                }
            }
        }
        let input_buf = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some("denoise input"),
            contents: &self.precision.bytes(&blocked),
            usage: wgpu::BufferUsages::STORAGE,
        });
        let vec4 = self.precision.vec4_bytes();
        let lv = levels();
        let outputs: Vec<wgpu::Buffer> = self
            .net
            .convs
            .iter()
            .enumerate()
            .map(|(k, c)| {
                let bytes = ((w >> lv[k]) * (h >> lv[k]) * blocks(c.outputs) * vec4).max(16) as u64;
                device.create_buffer(&wgpu::BufferDescriptor {
                    label: Some(c.name),
                    size: bytes,
                    usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_SRC,
                    mapped_at_creation: false,
                })
            })
            .collect();
        // Every dispatch's parameters, at aligned offsets of one buffer.
        let align = limits.min_storage_buffer_offset_alignment as u64;
        let stride = (std::mem::size_of::<ConvParams>() as u64).next_multiple_of(align);
        let mut params: Vec<u8> = Vec::new();
        // (step, offset, groups)
        let mut dispatches: Vec<(usize, u32, [u32; 3])> = Vec::new();
        let mut level = 0u32;
        for (k, (s, c)) in UNET_STEPS.iter().zip(&self.net.convs).enumerate() {
            if s.upsample {
                level -= 1;
            }
            let (lw, lh) = ((w >> level) as u32, (h >> level) as u32);
            let a_channels = self.net.channels(s.input);
            let b_channels = s.skip.map_or(0, |src| self.net.channels(src));
            let base = ConvParams {
                width: lw,
                height: lh,
                a_blocks: blocks(a_channels) as u32,
                b_blocks: blocks(b_channels) as u32,
                out_blocks: blocks(c.outputs) as u32,
                a_half: s.upsample as u32,
                pool: s.pool as u32,
                quad_row_offset: 0,
            };
            let quad_rows = lh.div_ceil(2);
            let row_macs = (lw as f64) * 2.0 * (c.inputs * c.outputs * 9) as f64;
            let band = ((self.dispatch_macs / row_macs.max(1.0)) as u32).clamp(1, quad_rows).next_multiple_of(GROUP);
            let mut row = 0;
            while row < quad_rows {
                let rows = band.min(quad_rows - row);
                let p = ConvParams { quad_row_offset: row, ..base };
                let offset = params.len() as u32;
                params.extend_from_slice(bytemuck::bytes_of(&p));
                params.resize(params.len().next_multiple_of(stride as usize), 0);
                let groups =
                    [lw.div_ceil(2).div_ceil(GROUP), rows.div_ceil(GROUP), base.out_blocks.div_ceil(DENOISE_BLOCKS)];
                dispatches.push((k, offset, groups));
                row += rows;
            }
            if s.pool {
                level += 1;
            }
        }
        let params_buf = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some("denoise params"),
            contents: &params,
            usage: wgpu::BufferUsages::STORAGE,
        });
        let source = |src: Source| match src {
            Source::Input => &input_buf,
            Source::Step(j) => &outputs[j],
        };
        let bind_groups: Vec<wgpu::BindGroup> = UNET_STEPS
            .iter()
            .enumerate()
            .map(|(k, s)| {
                let a = source(s.input);
                // A layer without a skip source binds its own input again (never read).
                let b = s.skip.map_or(a, source);
                device.create_bind_group(&wgpu::BindGroupDescriptor {
                    label: Some("denoise layer"),
                    layout: &self.layout,
                    entries: &[
                        wgpu::BindGroupEntry {
                            binding: 0,
                            resource: wgpu::BindingResource::Buffer(wgpu::BufferBinding {
                                buffer: &params_buf,
                                offset: 0,
                                size: std::num::NonZeroU64::new(std::mem::size_of::<ConvParams>() as u64),
                            }),
                        },
                        binding_entry(1, a),
                        binding_entry(2, b),
                        binding_entry(3, &self.weights[k].0),
                        binding_entry(4, &self.weights[k].1),
                        binding_entry(5, &outputs[k]),
                    ],
                })
            })
            .collect();
        let last = outputs.last().expect("the network has layers");
        let readback = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("denoise readback"),
            size: last.size(),
            usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        // One submission per dispatch keeps each short for the device's watchdog and lets
        // a caller's other work (a window) interleave.
        for (k, offset, groups) in &dispatches {
            let mut encoder = device.create_command_encoder(&Default::default());
            {
                let mut pass = encoder.begin_compute_pass(&Default::default());
                pass.set_pipeline(&self.pipeline);
                pass.set_bind_group(0, &bind_groups[*k], &[*offset]);
                pass.dispatch_workgroups(groups[0], groups[1], groups[2]);
            }
            let index = self.ctx.queue.submit([encoder.finish()]);
            self.ctx.wait(index)?;
        }
        let mut encoder = device.create_command_encoder(&Default::default());
        encoder.copy_buffer_to_buffer(last, 0, &readback, 0, last.size());
        let index = self.ctx.queue.submit([encoder.finish()]);
        let (tx, rx) = std::sync::mpsc::channel();
        readback.slice(..).map_async(wgpu::MapMode::Read, move |r| {
            let _ = tx.send(r);
        });
        self.ctx.wait(index)?;
        rx.recv()
            .map_err(|_| Error::Gpu("denoise readback was dropped".into()))?
            .map_err(|e| Error::Gpu(format!("denoise readback: {e}")))?;
        let values = {
            let view = readback.slice(..).get_mapped_range().map_err(|e| Error::Gpu(e.to_string()))?;
            self.precision.values(&view)
        };
        readback.unmap();
        Ok(values)
    }
}
