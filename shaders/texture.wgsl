// Textures: every image is one square layer of a texture array (lavapipe has no binding
// arrays), read texel by texel and filtered bilinearly here, with the glTF sampler's wrap
// modes, so the CPU twin can do exactly the same. Twin: src/cpu/texture.rs.
#include "bindings.wgsl"

const NO_TEXTURE: u32 = 0xffffffffu;
const TEX_SRGB: u32 = 16u;
// The texture reads TEXCOORD_1.
const TEX_UV1: u32 = 32u;

// Wrap modes: 0 repeat, 1 mirrored repeat, 2 clamp to edge.
fn wrap_texel(i: i32, n: i32, mode: u32) -> i32 {
    if (mode == 2u) {
        return clamp(i, 0, n - 1);
    }
    if (mode == 1u) {
        let m = ((i % (2 * n)) + 2 * n) % (2 * n);
        return select(m, 2 * n - 1 - m, m >= n);
    }
    return ((i % n) + n) % n;
}

fn srgb_to_linear(c: f32) -> f32 {
    if (c <= 0.04045) {
        return c / 12.92;
    }
    return pow((c + 0.055) / 1.055, 2.4);
}

fn texel(t: TextureRef, x: i32, y: i32, n: i32) -> vec4<f32> {
    let texel = vec2<i32>(wrap_texel(x, n, t.mode & 3u), wrap_texel(y, n, (t.mode >> 2u) & 3u));
    let c = textureLoad(textures, texel, i32(t.layer), 0);
    if ((t.mode & TEX_SRGB) != 0u) {
        return vec4<f32>(srgb_to_linear(c.x), srgb_to_linear(c.y), srgb_to_linear(c.z), c.w);
    }
    return c;
}

// The texture at uv (TEXCOORD_0 in xy, TEXCOORD_1 in zw: the texture reads its set), before
// the texture transform; linear RGB and alpha.
fn sample_texture(t: TextureRef, uv: vec4<f32>) -> vec4<f32> {
    let n = i32(textureDimensions(textures).x);
    let uv1 = vec3<f32>(select(uv.xy, uv.zw, (t.mode & TEX_UV1) != 0u), 1.0);
    var st = vec2<f32>(dot(t.row0, uv1), dot(t.row1, uv1));
    // Far-away UVs only lose precision; non-finite ones read texel 0.
    st = select(vec2<f32>(0.0), clamp(st, vec2<f32>(-1e6), vec2<f32>(1e6)), st == st);
    let p = st * f32(n) - 0.5;
    let p0 = floor(p);
    let f = p - p0;
    let x = i32(p0.x);
    let y = i32(p0.y);
    let top = mix(texel(t, x, y, n), texel(t, x + 1, y, n), f.x);
    let bottom = mix(texel(t, x, y + 1, n), texel(t, x + 1, y + 1, n), f.x);
    return mix(top, bottom, f.y);
}
