//! Twin of `shaders/rng.wgsl`: bit-identical counter-based random numbers.

#[inline]
pub fn pcg_hash(v: u32) -> u32 {
    let state = v.wrapping_mul(747796405).wrapping_add(2891336453);
    let word = ((state >> ((state >> 28) + 4)) ^ state).wrapping_mul(277803737);
    (word >> 22) ^ word
}

#[inline]
pub fn rng_init(pixel: u32, sample_index: u32, seed: u32) -> u32 {
    pcg_hash(pixel ^ pcg_hash(sample_index ^ pcg_hash(seed)))
}

#[inline]
pub fn rng_next(state: &mut u32) -> f32 {
    let s = state.wrapping_mul(747796405).wrapping_add(2891336453);
    *state = s;
    let mut w = ((s >> ((s >> 28) + 4)) ^ s).wrapping_mul(277803737);
    w ^= w >> 22;
    (w >> 8) as f32 * (1.0 / 16777216.0)
}

pub fn rng_next2(state: &mut u32) -> glam::Vec2 {
    let a = rng_next(state);
    let b = rng_next(state);
    glam::Vec2::new(a, b)
}
