// Accumulation into the film: 64-bit fixed-point sums (two u32 words), so that films of
// sample ranges and tiles merge exactly. Twin: src/film.rs (layout and arithmetic there).
#include "bindings.wgsl"
#include "film_layout.wgsl"

// Where invocation `gid` of a dispatch writes: its film slot and its image pixel (the film
// covers the tile, from row params.row_offset on); `inside` is false past the film's edge.
struct FilmPixel {
    slot: u32,
    pixel: vec2<u32>,
    inside: bool,
}

fn film_pixel(gid: vec3<u32>) -> FilmPixel {
    let row = gid.y + params.row_offset;
    let inside = gid.x < params.film_width && row < params.film_height;
    return FilmPixel(row * params.film_width + gid.x, vec2<u32>(gid.x + params.tile_x, row + params.tile_y), inside);
}

// Σ L of the pixel whose rows start at `base`, in f32. Twin: film_sum in src/film.rs.
fn film_sum(base: u32) -> vec3<f32> {
    return vec3<f32>(film[base].xyz) + vec3<f32>(film[base + 1u].xyz) * (1.0 / 4294967296.0);
}

fn film_add_sample(pixel: u32, l: vec3<f32>) {
    let base = FILM_WORDS * pixel;
    if (!is_finite_vec3(l)) {
        film[base + 1u].w += 1u;
        return;
    }
    let c = clamp(l, vec3<f32>(0.0), vec3<f32>(MAX_SAMPLE));
    let hi = floor(c);
    let add_hi = vec3<u32>(hi);
    let add_lo = vec3<u32>((c - hi) * 4294967296.0);
    let sum_hi = film[base];
    let sum_lo = film[base + 1u];
    let lo = sum_lo.xyz + add_lo;
    let carry = select(vec3<u32>(0u), vec3<u32>(1u), lo < sum_lo.xyz);
    film[base] = vec4<u32>(sum_hi.xyz + add_hi + carry, sum_hi.w + 1u);
    film[base + 1u] = vec4<u32>(lo, sum_lo.w);
    let sq = bitcast<vec3<f32>>(film[base + 2u].xyz) + l * l;
    film[base + 2u] = vec4<u32>(bitcast<vec3<u32>>(sq), 0u);
}
