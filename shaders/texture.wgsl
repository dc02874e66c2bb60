// Textures: every image keeps its own size in an atlas of square pages in one texture array
// (lavapipe has no binding arrays). Reads go texel by texel, wrapped by the glTF sampler's modes
// within the image's own rectangle (so no neighbour bleeds in) and filtered bilinearly here, so
// the CPU twin can do exactly the same. Twin: src/cpu/texture.rs.
#include "bindings.wgsl"

const NO_TEXTURE: u32 = 0xffffffffu;
const TEX_SRGB: u32 = 16u;
// The texture reads TEXCOORD_1.
const TEX_UV1: u32 = 32u;
// The atlas word: page, x, y of the image's corner; the mode word's high bits: its size − 1.
const TEX_PAGE_SHIFT: u32 = 24u;
const TEX_X_SHIFT: u32 = 12u;
const TEX_COORD_MASK: u32 = 0xfffu;
const TEX_WIDTH_SHIFT: u32 = 6u;
const TEX_HEIGHT_SHIFT: u32 = 19u;
const TEX_SIZE_MASK: u32 = 0x1fffu;

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

fn texel(t: TextureRef, x: i32, y: i32, size: vec2<i32>) -> vec4<f32> {
    let corner = vec2<u32>((t.atlas >> TEX_X_SHIFT) & TEX_COORD_MASK, t.atlas & TEX_COORD_MASK);
    let inside = vec2<i32>(wrap_texel(x, size.x, t.mode & 3u), wrap_texel(y, size.y, (t.mode >> 2u) & 3u));
    let c = textureLoad(textures, vec2<i32>(corner) + inside, i32(t.atlas >> TEX_PAGE_SHIFT), 0);
    if ((t.mode & TEX_SRGB) != 0u) {
        return vec4<f32>(srgb_to_linear(c.x), srgb_to_linear(c.y), srgb_to_linear(c.z), c.w);
    }
    return c;
}

// The texture at uv (TEXCOORD_0 in xy, TEXCOORD_1 in zw: the texture reads its set), before
// the texture transform; linear RGB and alpha.
fn sample_texture(t: TextureRef, uv: vec4<f32>) -> vec4<f32> {
    let size = vec2<i32>(
        i32((t.mode >> TEX_WIDTH_SHIFT) & TEX_SIZE_MASK) + 1,
        i32((t.mode >> TEX_HEIGHT_SHIFT) & TEX_SIZE_MASK) + 1,
    );
    let uv1 = vec3<f32>(select(uv.xy, uv.zw, (t.mode & TEX_UV1) != 0u), 1.0);
    var st = vec2<f32>(dot(t.row0, uv1), dot(t.row1, uv1));
    // Far-away UVs only lose precision; non-finite ones read texel 0.
    st = select(vec2<f32>(0.0), clamp(st, vec2<f32>(-1e5), vec2<f32>(1e5)), st == st);
    let p = st * vec2<f32>(size) - 0.5;
    let p0 = floor(p);
    let f = p - p0;
    let x = i32(p0.x);
    let y = i32(p0.y);
    let top = mix(texel(t, x, y, size), texel(t, x + 1, y, size), f.x);
    let bottom = mix(texel(t, x, y + 1, size), texel(t, x + 1, y + 1, size), f.x);
    return mix(top, bottom, f.y);
}
