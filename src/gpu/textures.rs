//! The scene's images on the device: the texture atlas's pages as one texture array (RGBA8).

use super::GpuContext;
use crate::Error;
use crate::packed::PackedScene;
use wgpu::util::DeviceExt;

/// The texture atlas as one texture array (RGBA8, one square layer per page).
pub fn texture_array(ctx: &GpuContext, scene: &PackedScene) -> Result<(wgpu::TextureView, u64), Error> {
    let limits = ctx.device.limits();
    let (side, layers) = (scene.texture_size, scene.texture_pages);
    if side > limits.max_texture_dimension_2d || layers > limits.max_texture_array_layers {
        return Err(Error::Limit(format!(
            "{layers} texture pages of {side}² texels exceed the device's texture arrays \
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
