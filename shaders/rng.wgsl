// Counter-based random numbers: the stream of a (pixel, sample index, seed) triple is fixed,
// whatever the dispatch order, so sample ranges can be rendered anywhere and merged.
// Twin: src/cpu/rng.rs.

fn pcg_hash(v: u32) -> u32 {
    let state = v * 747796405u + 2891336453u;
    let word = ((state >> ((state >> 28u) + 4u)) ^ state) * 277803737u;
    return (word >> 22u) ^ word;
}

fn rng_init(pixel: u32, sample_index: u32, seed: u32) -> u32 {
    return pcg_hash(pixel ^ pcg_hash(sample_index ^ pcg_hash(seed)));
}

// One PCG step (LCG state, RXS-M-XS output); a uniform float in [0, 1) with 24 bits.
fn rng_next(state: ptr<function, u32>) -> f32 {
    let s = *state * 747796405u + 2891336453u;
    *state = s;
    var w = ((s >> ((s >> 28u) + 4u)) ^ s) * 277803737u;
    w = (w >> 22u) ^ w;
    return f32(w >> 8u) * (1.0 / 16777216.0);
}

fn rng_next2(state: ptr<function, u32>) -> vec2<f32> {
    let a = rng_next(state);
    let b = rng_next(state);
    return vec2<f32>(a, b);
}
