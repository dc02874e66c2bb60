//! Twin of `shaders/texture.wgsl`: bilinear texture reads with glTF wrap modes.

use crate::packed::{
    PackedScene, TEX_COORD_MASK, TEX_HEIGHT_SHIFT, TEX_PAGE_SHIFT, TEX_SIZE_MASK, TEX_SRGB, TEX_UV1, TEX_WIDTH_SHIFT,
    TEX_X_SHIFT, TextureRef,
};
use glam::{Vec2, Vec3, Vec4};

pub fn wrap_texel(i: i32, n: i32, mode: u32) -> i32 {
    if mode == 2 {
        return i.clamp(0, n - 1);
    }
    if mode == 1 {
        let m = i.rem_euclid(2 * n);
        return if m >= n { 2 * n - 1 - m } else { m };
    }
    i.rem_euclid(n)
}

pub fn srgb_to_linear(c: f32) -> f32 {
    if c <= 0.04045 { c / 12.92 } else { ((c + 0.055) / 1.055).powf(2.4) }
}

fn texel(scene: &PackedScene, t: &TextureRef, x: i32, y: i32, size: (i32, i32)) -> Vec4 {
    let corner = ((t.atlas >> TEX_X_SHIFT) & TEX_COORD_MASK, t.atlas & TEX_COORD_MASK);
    let (x, y) = (wrap_texel(x, size.0, t.mode & 3), wrap_texel(y, size.1, (t.mode >> 2) & 3));
    let (x, y) = (corner.0 as usize + x as usize, corner.1 as usize + y as usize);
    let side = scene.texture_size as usize;
    let index = ((t.atlas >> TEX_PAGE_SHIFT) as usize * side + y) * side + x;
    let c = scene.texels[index].to_le_bytes().map(|b| b as f32 / 255.0);
    if t.mode & TEX_SRGB != 0 {
        Vec4::new(srgb_to_linear(c[0]), srgb_to_linear(c[1]), srgb_to_linear(c[2]), c[3])
    } else {
        Vec4::from(c)
    }
}

/// The texture at `uv` (TEXCOORD_0 in xy, TEXCOORD_1 in zw; the texture reads its set) before
/// its transform.
pub fn sample_texture(scene: &PackedScene, t: &TextureRef, uv: Vec4) -> Vec4 {
    let size = (
        ((t.mode >> TEX_WIDTH_SHIFT) & TEX_SIZE_MASK) as i32 + 1,
        ((t.mode >> TEX_HEIGHT_SHIFT) & TEX_SIZE_MASK) as i32 + 1,
    );
    let uv = if t.mode & TEX_UV1 != 0 { Vec2::new(uv.z, uv.w) } else { Vec2::new(uv.x, uv.y) };
    let uv1 = uv.extend(1.0);
    let st = Vec2::new(Vec3::from(t.row0).dot(uv1), Vec3::from(t.row1).dot(uv1));
    let fix = |v: f32| if v.is_nan() { 0.0 } else { v.clamp(-1e5, 1e5) };
    let st = Vec2::new(fix(st.x), fix(st.y));
    let p = st * Vec2::new(size.0 as f32, size.1 as f32) - 0.5;
    let p0 = p.floor();
    let f = p - p0;
    let (x, y) = (p0.x as i32, p0.y as i32);
    let top = texel(scene, t, x, y, size).lerp(texel(scene, t, x + 1, y, size), f.x);
    let bottom = texel(scene, t, x, y + 1, size).lerp(texel(scene, t, x + 1, y + 1, size), f.x);
    top.lerp(bottom, f.y)
}
