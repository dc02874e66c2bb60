//! Twin of `shaders/sampler.wgsl`: independent and Owen-scrambled Sobol' samples, bit-identical
//! to the kernel's.

use super::rng::{pcg_hash, rng_init, rng_next};
use glam::Vec2;

pub const SAMPLER_INDEPENDENT: u32 = crate::SamplerKind::Independent as u32;
pub const SAMPLER_SOBOL: u32 = crate::SamplerKind::Sobol as u32;

/// Mixed into the seed before the Sobol' sampler's per-pixel hash (`sampler_init`).
pub const SOBOL_SEED_SALT: u32 = 0x5bd1e995;

#[derive(Clone, Copy, Debug)]
pub struct Sampler {
    kind: u32,
    pixel_seed: u32,
    index: u32,
    dim: u32,
    state: u32,
}

#[inline]
pub fn sampler_init(kind: u32, pixel: u32, sample_index: u32, seed: u32) -> Sampler {
    if kind == SAMPLER_INDEPENDENT {
        return Sampler {
            kind,
            pixel_seed: 0,
            index: sample_index,
            dim: 0,
            state: rng_init(pixel, sample_index, seed),
        };
    }
    Sampler {
        kind,
        pixel_seed: pcg_hash(pixel ^ pcg_hash(seed ^ SOBOL_SEED_SALT)),
        index: sample_index,
        dim: 0,
        state: 0,
    }
}

/// The sampler's words (kind, pixel seed, sample index, dimension, PCG state), for samplers
/// kept in lanes (`cpu::lanes::sampler`).
pub fn sampler_parts(s: &Sampler) -> (u32, u32, u32, u32, u32) {
    (s.kind, s.pixel_seed, s.index, s.dim, s.state)
}

/// The sampler of `sampler_parts`' words.
pub fn sampler_from_parts(kind: u32, pixel_seed: u32, index: u32, dim: u32, state: u32) -> Sampler {
    Sampler { kind, pixel_seed, index, dim, state }
}

#[inline]
pub fn laine_karras(v: u32, seed: u32) -> u32 {
    let mut x = v;
    x ^= x.wrapping_mul(0x3d20adea);
    x = x.wrapping_add(seed);
    x = x.wrapping_mul((seed >> 16) | 1);
    x ^= x.wrapping_mul(0x05526c56);
    x ^= x.wrapping_mul(0x53a22864);
    x
}

#[inline]
pub fn owen_scramble(v: u32, seed: u32) -> u32 {
    laine_karras(v.reverse_bits(), seed).reverse_bits()
}

#[inline]
pub fn sobol_1_reversed(index: u32) -> u32 {
    let mut y = index;
    y ^= (y >> 1) & 0x5555_5555;
    y ^= (y >> 2) & 0x3333_3333;
    y ^= (y >> 4) & 0x0f0f_0f0f;
    y ^= (y >> 8) & 0x00ff_00ff;
    y ^= (y >> 16) & 0x0000_ffff;
    y
}

#[inline]
fn unit_float(bits: u32) -> f32 {
    (bits >> 8) as f32 * (1.0 / 16777216.0)
}

#[inline]
fn next_dimension_seed(s: &mut Sampler) -> u32 {
    let d = pcg_hash(s.pixel_seed ^ pcg_hash(s.dim));
    s.dim += 1;
    d
}

#[inline]
pub fn sample_1d(s: &mut Sampler) -> f32 {
    if s.kind == SAMPLER_INDEPENDENT {
        return rng_next(&mut s.state);
    }
    let d = next_dimension_seed(s);
    let i = owen_scramble(s.index, d);
    unit_float(laine_karras(i, pcg_hash(d ^ 1)).reverse_bits())
}

#[inline]
pub fn sample_2d(s: &mut Sampler) -> Vec2 {
    if s.kind == SAMPLER_INDEPENDENT {
        let a = rng_next(&mut s.state);
        let b = rng_next(&mut s.state);
        return Vec2::new(a, b);
    }
    let d = next_dimension_seed(s);
    let i = owen_scramble(s.index, d);
    let x = laine_karras(i, pcg_hash(d ^ 1)).reverse_bits();
    let y = laine_karras(sobol_1_reversed(i), pcg_hash(d ^ 2)).reverse_bits();
    Vec2::new(unit_float(x), unit_float(y))
}
