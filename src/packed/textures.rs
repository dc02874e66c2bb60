//! The texture array: every image resampled to one square layer.

use crate::scene::Texture;

/// Largest side of a texture-array layer, and the budget of the whole array.
pub const MAX_TEXTURE_LAYER_SIDE: u32 = 2048;
pub const TEXTURE_BUDGET_BYTES: u64 = 256 << 20;

/// The layer side for `textures`: the largest image side rounded up to a power of two, at
/// most MAX_TEXTURE_LAYER_SIDE, halved until the array fits TEXTURE_BUDGET_BYTES.
pub fn texture_layer_side(textures: &[Texture]) -> u32 {
    let largest = textures.iter().map(|t| t.width.max(t.height)).max().unwrap_or(1);
    let mut side = largest.next_power_of_two().min(MAX_TEXTURE_LAYER_SIDE);
    while side > 64 && textures.len() as u64 * (side as u64).pow(2) * 4 > TEXTURE_BUDGET_BYTES {
        side /= 2;
    }
    side
}

/// Every texture resampled (bilinear/triangle filter) to one square layer of a texture array:
/// lavapipe has no binding arrays, and UVs are relative, so a layer can hold any image.
pub fn pack_textures(textures: &[Texture]) -> (Vec<u32>, u32, u32) {
    if textures.is_empty() {
        return (vec![u32::MAX], 1, 1);
    }
    let side = texture_layer_side(textures);
    use rayon::prelude::*;
    let layers: Vec<Vec<u32>> = textures
        .par_iter()
        .map(|t| {
            let image = image::RgbaImage::from_raw(t.width, t.height, t.rgba.clone())
                .unwrap_or_else(|| image::RgbaImage::new(t.width.max(1), t.height.max(1)));
            let image = if image.dimensions() == (side, side) {
                image
            } else {
                image::imageops::resize(&image, side, side, image::imageops::FilterType::Triangle)
            };
            image.pixels().map(|p| u32::from_le_bytes(p.0)).collect()
        })
        .collect();
    (layers.concat(), side, textures.len() as u32)
}
