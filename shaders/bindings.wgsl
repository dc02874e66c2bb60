// The scene and film bindings, shared by every kernel.
#include "common.wgsl"

// One Params slot per dispatch of a batch, bound at a dynamic offset. A storage buffer, not a
// uniform: lavapipe (Mesa 22.3) inlines uniform values into the shader and compiled, and
// kept, a new variant on every dispatch: 12 ms and 1.3 MB each (BENCHMARKS.md).
@group(0) @binding(0) var<storage, read> params: Params;
// Bindings 1–3 (BVH nodes, triangles, vertex attributes) and their load_* functions: storage
// buffers, or for scenes beyond a storage binding's limit, textures (see geometry.wgsl).
#include "geometry.wgsl"
@group(0) @binding(4) var<storage, read> materials: array<Material>;
// The alias table (LightEntry bits, one row each), then from params.tree_base the light
// tree (LIGHT_NODE_ROWS rows per node) and from params.trail_base its trails, four per row.
@group(0) @binding(5) var<storage, read> lights: array<vec4<u32>>;
// Three rows per pixel (see film.wgsl): (Σ L high words, count), (Σ L low words, dropped
// non-finite samples), (Σ L² as f32 bits, 0).
@group(0) @binding(6) var<storage, read_write> film: array<vec4<u32>>;
// Light data: environment map texels (rgb, row CDF), the marginal CDF of the rows (x), then
// the punctual lights (four rows each, from params.punctual_base). One buffer for both keeps
// the kernel within WebGPU's default of 8 storage buffers.
@group(0) @binding(7) var<storage, read> light_data: array<vec4<f32>>;
// Every image of the scene, one square RGBA8 layer each (no binding arrays on lavapipe).
@group(0) @binding(8) var textures: texture_2d_array<f32>;
