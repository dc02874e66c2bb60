// One layer of Open Image Denoise's U-Net: a 3×3 convolution (zero padding) with bias and
// ReLU, reading a source tensor (optionally at half resolution: nearest 2× upsampling fused
// into the reads) and a skip tensor concatenated after it, and writing either every pixel or,
// with `pool`, the 2×2 maximum at half resolution. Twin: src/denoise/cpu.rs (`conv3x3`,
// `upsample`, `pool`), which the tests hold this kernel to.
//
// Tensors are row-major pixels of channel blocks, one vec4 per 4 channels (zero-padded), so a
// pixel of C channels is ceil(C / 4) vec4 at (y · width + x) · blocks. Weights are one 4×4
// matrix per (output block, tap, input block), columns indexed by input channel, so that
// matrix × input vec4 adds the block's contribution to 4 output channels.
//
// An invocation computes a 2×2 quad of pixels for DENOISE_BLOCKS output blocks: each weight
// matrix it loads serves four pixels (loads are what costs on lavapipe, and what the
// workgroup shares on real GPUs).
//
// Tensors and weights are stored as `tensor4`: vec4<f32>, or vec4<f16> where the device has
// shader-f16 (the host then composes this file with `enable f16;` and the alias below
// rewritten, halving the bytes read); arithmetic is f32 either way.

const DENOISE_BLOCKS: u32 = 2u;

alias tensor4 = vec4<f32>;

struct ConvParams {
    // Output size before pooling; the input sources have it too (the upsampled one half).
    width: u32,
    height: u32,
    a_blocks: u32,
    b_blocks: u32,
    out_blocks: u32,
    // 1: source A is at half resolution (its size is ceil(width / 2) × ceil(height / 2)).
    a_half: u32,
    // 1: write the 2×2 maximum at half resolution (width and height are even).
    pool: u32,
    // First quad row of this dispatch (long layers run in bands of rows).
    quad_row_offset: u32,
}

@group(0) @binding(0) var<storage, read> p: ConvParams;
@group(0) @binding(1) var<storage, read> src_a: array<tensor4>;
@group(0) @binding(2) var<storage, read> src_b: array<tensor4>;
@group(0) @binding(3) var<storage, read> weights: array<tensor4>;
@group(0) @binding(4) var<storage, read> bias: array<vec4<f32>>;
@group(0) @binding(5) var<storage, read_write> dst: array<tensor4>;

fn weight_matrix(ob: u32, tap: u32, ib: u32) -> mat4x4<f32> {
    let at = ((ob * 9u + tap) * (p.a_blocks + p.b_blocks) + ib) * 4u;
    return mat4x4<f32>(
        vec4<f32>(weights[at]),
        vec4<f32>(weights[at + 1u]),
        vec4<f32>(weights[at + 2u]),
        vec4<f32>(weights[at + 3u]),
    );
}

@compute @workgroup_size(8, 8, 1)
fn conv3x3(@builtin(global_invocation_id) gid: vec3<u32>) {
    let x0 = 2u * gid.x;
    let y0 = 2u * (gid.y + p.quad_row_offset);
    let ob0 = gid.z * DENOISE_BLOCKS;
    if (x0 >= p.width || y0 >= p.height || ob0 >= p.out_blocks) {
        return;
    }
    var acc: array<vec4<f32>, 8>;
    for (var k = 0u; k < DENOISE_BLOCKS; k++) {
        let b = bias[min(ob0 + k, p.out_blocks - 1u)];
        for (var q = 0u; q < 4u; q++) {
            acc[q * DENOISE_BLOCKS + k] = b;
        }
    }
    let blocks = p.a_blocks + p.b_blocks;
    let a_width = select(p.width, (p.width + 1u) / 2u, p.a_half == 1u);
    for (var tap = 0u; tap < 9u; tap++) {
        // Input pixel of each of the quad's four pixels for this tap, or none (zero padding).
        var src: array<u32, 4>;
        var inside: array<bool, 4>;
        for (var q = 0u; q < 4u; q++) {
            let sx = i32(x0 + (q & 1u) + tap % 3u) - 1;
            let sy = i32(y0 + (q >> 1u) + tap / 3u) - 1;
            inside[q] = sx >= 0 && sy >= 0 && u32(sx) < p.width && u32(sy) < p.height;
            src[q] = select(0u, u32(sy) * p.width + u32(sx), inside[q]);
            if (p.a_half == 1u) {
                src[q] = select(0u, (u32(sy) >> 1u) * a_width + (u32(sx) >> 1u), inside[q]);
            }
        }
        for (var ib = 0u; ib < blocks; ib++) {
            var v: array<vec4<f32>, 4>;
            for (var q = 0u; q < 4u; q++) {
                var x = vec4<f32>(0.0);
                if (inside[q]) {
                    if (ib < p.a_blocks) {
                        x = vec4<f32>(src_a[src[q] * p.a_blocks + ib]);
                    } else {
                        // The skip source is at full resolution.
                        let sx = x0 + (q & 1u) + tap % 3u - 1u;
                        let sy = y0 + (q >> 1u) + tap / 3u - 1u;
                        x = vec4<f32>(src_b[(sy * p.width + sx) * p.b_blocks + ib - p.a_blocks]);
                    }
                }
                v[q] = x;
            }
            for (var k = 0u; k < DENOISE_BLOCKS; k++) {
                let ob = min(ob0 + k, p.out_blocks - 1u);
                let m = weight_matrix(ob, tap, ib);
                for (var q = 0u; q < 4u; q++) {
                    acc[q * DENOISE_BLOCKS + k] += m * v[q];
                }
            }
        }
    }
    for (var k = 0u; k < DENOISE_BLOCKS; k++) {
        let ob = ob0 + k;
        if (ob >= p.out_blocks) {
            break;
        }
        if (p.pool == 1u) {
            let top = max(acc[k], acc[DENOISE_BLOCKS + k]);
            let bottom = max(acc[2u * DENOISE_BLOCKS + k], acc[3u * DENOISE_BLOCKS + k]);
            let at = ((y0 / 2u) * (p.width / 2u) + x0 / 2u) * p.out_blocks + ob;
            dst[at] = tensor4(max(max(top, bottom), vec4<f32>(0.0)));
        } else {
            for (var q = 0u; q < 4u; q++) {
                let x = x0 + (q & 1u);
                let y = y0 + (q >> 1u);
                if (x < p.width && y < p.height) {
                    let v = max(acc[q * DENOISE_BLOCKS + k], vec4<f32>(0.0));
                    dst[(y * p.width + x) * p.out_blocks + ob] = tensor4(v);
                }
            }
        }
    }
}
