//! Scene geometry on the device: BVH nodes, triangles and vertex attributes in storage
//! buffers, or paged into textures for scenes beyond a storage binding
//! (shaders/geometry_buffers.wgsl, shaders/geometry_textures.wgsl).

use super::{GpuContext, PAGE_ROW_LOG2};
use crate::Error;
use wgpu::util::DeviceExt;

/// Geometry records paged into rgba32uint textures, 4096 texels a row
/// (shaders/geometry_textures.wgsl).
pub fn geometry_textures(ctx: &GpuContext, data: [&[u8]; 3]) -> Result<[wgpu::TextureView; 3], Error> {
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
