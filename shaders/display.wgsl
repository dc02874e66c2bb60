// The viewer's resolve pass: film mean × 2^exposure → tone map → sRGB, into the texture
// egui shows (no readback to the CPU). The film layout is film.wgsl's.
#include "tonemap.wgsl"
#include "film_layout.wgsl"

struct DisplayParams {
    width: u32,
    height: u32,
    tonemap: u32,
    scale: f32, // 2^exposure
    // > 0: show each pixel's samples (adaptive sampling) as a heat map up to this count.
    heat_max: u32,
    pad0: u32,
    pad1: u32,
    pad2: u32,
}

// A perceptually ordered ramp: black, purple, orange, pale yellow (inferno-like stops).
fn heat_color(t: f32) -> vec3<f32> {
    let x = clamp(t, 0.0, 1.0) * 3.0;
    var stops = array<vec3<f32>, 4>(
        vec3<f32>(0.0, 0.0, 0.02),
        vec3<f32>(0.34, 0.06, 0.43),
        vec3<f32>(0.93, 0.41, 0.14),
        vec3<f32>(0.99, 1.0, 0.64),
    );
    let i = min(u32(x), 2u);
    return mix(stops[i], stops[i + 1u], x - f32(i));
}

@group(0) @binding(0) var<storage, read> display: DisplayParams;
@group(0) @binding(1) var<storage, read> film: array<vec4<u32>>;
@group(0) @binding(2) var output: texture_storage_2d<rgba8unorm, write>;

@compute @workgroup_size(8, 8, 1)
fn resolve(@builtin(global_invocation_id) gid: vec3<u32>) {
    if (gid.x >= display.width || gid.y >= display.height) {
        return;
    }
    let base = FILM_WORDS * (gid.y * display.width + gid.x);
    let hi = film[base];
    let lo = film[base + 1u];
    var mean = vec3<f32>(0.0);
    if (hi.w > 0u) {
        mean = (vec3<f32>(hi.xyz) + vec3<f32>(lo.xyz) * (1.0 / 4294967296.0)) / f32(hi.w);
    }
    var c = srgb_encode(tonemap(mean * display.scale, display.tonemap));
    if (display.heat_max > 0u) {
        c = heat_color(f32(hi.w + lo.w) / f32(display.heat_max));
    }
    textureStore(output, vec2<i32>(gid.xy), vec4<f32>(c, 1.0));
}
