//! Runs a few lines of WGSL over the functions of one shader file on the GPU, to hold a WGSL
//! function to its Rust twin directly rather than through whole renders.

use veach::gpu::GpuContext;
use wgpu::util::DeviceExt;

/// For every item i of `input` (each `ins` vec4s: `probe_in[i * ins + k]`), runs `body`,
/// WGSL that writes `outs` vec4s to `probe_out[i * outs + k]`, with the functions of the
/// shader file `file` (and its includes) in scope; returns the outputs.
pub fn run(ctx: &GpuContext, file: &str, body: &str, input: &[[f32; 4]], ins: usize, outs: usize) -> Vec<[f32; 4]> {
    assert!(ins > 0 && outs > 0 && input.len().is_multiple_of(ins), "probe: input is not whole items");
    let items = input.len() / ins;
    let functions = veach::gpu::shaders::compose(file).unwrap_or_else(|e| panic!("{e}"));
    let source = format!(
        "{functions}
@group(0) @binding(0) var<storage, read> probe_in: array<vec4<f32>>;
@group(0) @binding(1) var<storage, read_write> probe_out: array<vec4<f32>>;
const PROBE_INS: u32 = {ins}u;
const PROBE_OUTS: u32 = {outs}u;
@compute @workgroup_size(64)
fn probe(@builtin(global_invocation_id) id: vec3<u32>) {{
    let i = id.x + id.y * 65535u * 64u;
    if (i >= {items}u) {{
        return;
    }}
    {body}
}}
"
    );
    let device = &ctx.device;
    let module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
        label: Some("probe"),
        source: wgpu::ShaderSource::Wgsl(source.into()),
    });
    ctx.check().unwrap_or_else(|e| panic!("probe over {file}: {e}"));
    let pipeline = device.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
        label: Some("probe"),
        layout: None,
        module: &module,
        entry_point: Some("probe"),
        compilation_options: Default::default(),
        cache: None,
    });
    let input_buffer = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
        label: Some("probe in"),
        contents: bytemuck::cast_slice(input),
        usage: wgpu::BufferUsages::STORAGE,
    });
    let bytes = (items * outs * 16) as u64;
    let output = device.create_buffer(&wgpu::BufferDescriptor {
        label: Some("probe out"),
        size: bytes,
        usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_SRC,
        mapped_at_creation: false,
    });
    let readback = device.create_buffer(&wgpu::BufferDescriptor {
        label: Some("probe readback"),
        size: bytes,
        usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
        mapped_at_creation: false,
    });
    let bind_group = device.create_bind_group(&wgpu::BindGroupDescriptor {
        label: Some("probe"),
        layout: &pipeline.get_bind_group_layout(0),
        entries: &[
            wgpu::BindGroupEntry { binding: 0, resource: input_buffer.as_entire_binding() },
            wgpu::BindGroupEntry { binding: 1, resource: output.as_entire_binding() },
        ],
    });
    let mut encoder = device.create_command_encoder(&Default::default());
    {
        let mut pass = encoder.begin_compute_pass(&Default::default());
        pass.set_pipeline(&pipeline);
        pass.set_bind_group(0, &bind_group, &[]);
        let groups = items.div_ceil(64) as u32;
        pass.dispatch_workgroups(groups.min(65535), groups.div_ceil(65535), 1);
    }
    encoder.copy_buffer_to_buffer(&output, 0, &readback, 0, bytes);
    let index = ctx.queue.submit([encoder.finish()]);
    readback.slice(..).map_async(wgpu::MapMode::Read, |r| r.expect("probe readback"));
    ctx.wait(index).unwrap_or_else(|e| panic!("probe over {file}: {e}"));
    let view = readback.slice(..).get_mapped_range().expect("probe readback");
    bytemuck::cast_slice::<u8, [f32; 4]>(&view).to_vec()
}
