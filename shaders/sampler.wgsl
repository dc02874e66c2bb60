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
    if (kind == SAMPLER_INDEPENDENT) {
        return Sampler(kind, 0u, sample_index, 0u, rng_init(pixel, sample_index, seed));
    }
    return Sampler(kind, pcg_hash(pixel ^ pcg_hash(seed ^ 0x5bd1e995u)), sample_index, 0u, 0u);
}

// A random permutation of [0, 2^32) in which bit k of the output depends only on bits k and
// below of the input (a Laine–Karras style hash with Burley's constants). Between two bit
// reversals it is an Owen scramble: bit k then depends on bits k and above.
fn laine_karras(v: u32, seed: u32) -> u32 {
    var x = v;
    x ^= x * 0x3d20adeau;
    x += seed;
    x *= (seed >> 16u) | 1u;
    x ^= x * 0x05526c56u;
    x ^= x * 0x53a22864u;
    return x;
}

fn owen_scramble(v: u32, seed: u32) -> u32 {
    return reverseBits(laine_karras(reverseBits(v), seed));
}

// Sobol' dimension 1 of `index`, bit-reversed (dimension 0 is the bit reversal itself, so in
// this domain the index is dimension 0). Its generator matrix is Pascal's triangle mod 2, a
// Kronecker power of [[1, 1], [0, 1]], applied in five butterfly steps instead of a loop over
// the index bits (tests/sampler.rs checks it against the direction numbers).
fn sobol_1_reversed(index: u32) -> u32 {
    var y = index;
    y ^= (y >> 1u) & 0x55555555u;
    y ^= (y >> 2u) & 0x33333333u;
    y ^= (y >> 4u) & 0x0f0f0f0fu;
    y ^= (y >> 8u) & 0x00ff00ffu;
    y ^= (y >> 16u) & 0x0000ffffu;
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
    // Owen-scrambled Sobol' dimension 0 at a shuffled index: owen_scramble(reverseBits(i), ..)
    // with the reversals that cancel left out.
    let d = next_dimension_seed(s);
    let i = owen_scramble((*s).index, d);
    return unit_float(reverseBits(laine_karras(i, pcg_hash(d ^ 1u))));
}

fn sample_2d(s: ptr<function, Sampler>) -> vec2<f32> {
    if ((*s).kind == SAMPLER_INDEPENDENT) {
        var state = (*s).state;
        let a = rng_next(&state);
        let b = rng_next(&state);
        (*s).state = state;
        return vec2<f32>(a, b);
    }
    // Dimensions 0 and 1 at a shuffled index, each Owen-scrambled; working on reversed values
    // saves the reversals that would cancel.
    let d = next_dimension_seed(s);
    let i = owen_scramble((*s).index, d);
    let x = reverseBits(laine_karras(i, pcg_hash(d ^ 1u)));
    let y = reverseBits(laine_karras(sobol_1_reversed(i), pcg_hash(d ^ 2u)));
    return vec2<f32>(unit_float(x), unit_float(y));
}
