// Sample generators: every number a path uses comes from `sample_1d` / `sample_2d`, as a pure
// function of (pixel, sample index, dimension, seed), so sample ranges render anywhere and merge.
// SAMPLER_INDEPENDENT: one PCG stream per (pixel, sample index).
// SAMPLER_SOBOL: Owen-scrambled Sobol', padded per 2D pair (Burley 2020, "Practical Hash-based
// Owen Scrambling"): every pair of dimensions takes the first two Sobol' dimensions at a shuffled
// index, so the first 2^m samples of a pixel form a (0, m, 2)-net in every pair; pairs are
// decorrelated by their own shuffle and scramble seeds. Twin: src/cpu/sampler.rs.
#include "rng.wgsl"

const SAMPLER_INDEPENDENT: u32 = 0u;
const SAMPLER_SOBOL: u32 = 1u;

struct Sampler {
    kind: u32,
    // Per-pixel seed of the scrambles (the same for every sample of the pixel).
    pixel_seed: u32,
    index: u32,
    // Next dimension (a 1D or a 2D draw uses one).
    dim: u32,
    // State of the independent stream.
    state: u32,
}

fn sampler_init(kind: u32, pixel: u32, sample_index: u32, seed: u32) -> Sampler {
    let pixel_seed = pcg_hash(pixel ^ pcg_hash(seed ^ 0x5bd1e995u));
    return Sampler(kind, pixel_seed, sample_index, 0u, rng_init(pixel, sample_index, seed));
}

// A random permutation of [0, 2^32) in which bit k of the output depends only on bits k and
// above of the input: Owen scrambling of the bit-reversed value (Laine–Karras style hash with
// Burley's constants).
fn owen_scramble(v: u32, seed: u32) -> u32 {
    var x = reverseBits(v);
    x ^= x * 0x3d20adeau;
    x += seed;
    x *= (seed >> 16u) | 1u;
    x ^= x * 0x05526c56u;
    x ^= x * 0x53a22864u;
    return reverseBits(x);
}

// Sobol' dimension 1 from dimension 0 (the bit reversal of the index): its generator matrix is
// Pascal's triangle mod 2, a Kronecker power of [[1, 1], [0, 1]], applied in five butterfly steps
// instead of a loop over the index bits (tests/sampler.rs checks it against the direction numbers).
fn sobol_1_from_0(x: u32) -> u32 {
    var y = x;
    y ^= (y << 1u) & 0xaaaaaaaau;
    y ^= (y << 2u) & 0xccccccccu;
    y ^= (y << 4u) & 0xf0f0f0f0u;
    y ^= (y << 8u) & 0xff00ff00u;
    y ^= (y << 16u) & 0xffff0000u;
    return y;
}

fn unit_float(bits: u32) -> f32 {
    return f32(bits >> 8u) * (1.0 / 16777216.0);
}

fn next_dimension_seed(s: ptr<function, Sampler>) -> u32 {
    let d = pcg_hash((*s).pixel_seed ^ pcg_hash((*s).dim));
    (*s).dim += 1u;
    return d;
}

fn sample_1d(s: ptr<function, Sampler>) -> f32 {
    if ((*s).kind == SAMPLER_INDEPENDENT) {
        // A local copy of the state: naga's SPIR-V writer rejects a pointer to a field of a
        // pointer argument.
        var state = (*s).state;
        let a = rng_next(&state);
        (*s).state = state;
        return a;
    }
    let d = next_dimension_seed(s);
    let i = owen_scramble((*s).index, d);
    return unit_float(owen_scramble(reverseBits(i), pcg_hash(d ^ 1u)));
}

fn sample_2d(s: ptr<function, Sampler>) -> vec2<f32> {
    if ((*s).kind == SAMPLER_INDEPENDENT) {
        var state = (*s).state;
        let a = rng_next(&state);
        let b = rng_next(&state);
        (*s).state = state;
        return vec2<f32>(a, b);
    }
    let d = next_dimension_seed(s);
    let i = owen_scramble((*s).index, d);
    let sobol_0 = reverseBits(i);
    let x = owen_scramble(sobol_0, pcg_hash(d ^ 1u));
    let y = owen_scramble(sobol_1_from_0(sobol_0), pcg_hash(d ^ 2u));
    return vec2<f32>(unit_float(x), unit_float(y));
}
