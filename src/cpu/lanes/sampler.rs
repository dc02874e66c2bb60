//! `cpu::sampler` in lanes: each lane is one path's sampler (its pixel's seed, its own
//! dimension counter), drawing the numbers the scalar sampler draws, bit for bit.

use super::lane::{F8, M8, U8};
use crate::cpu::sampler::{SAMPLER_INDEPENDENT, Sampler, sampler_from_parts, sampler_parts};

#[inline(always)]
pub fn pcg_hash(v: U8) -> U8 {
    let state = v.map(|v| v.wrapping_mul(747796405).wrapping_add(2891336453));
    let word = state.map(|s| ((s >> ((s >> 28) + 4)) ^ s).wrapping_mul(277803737));
    word.map(|w| (w >> 22) ^ w)
}

#[inline(always)]
pub fn laine_karras(v: U8, seed: U8) -> U8 {
    v.zip(seed, |v, seed| {
        let mut x = v;
        x ^= x.wrapping_mul(0x3d20adea);
        x = x.wrapping_add(seed);
        x = x.wrapping_mul((seed >> 16) | 1);
        x ^= x.wrapping_mul(0x05526c56);
        x ^= x.wrapping_mul(0x53a22864);
        x
    })
}

#[inline(always)]
fn reverse_bits(v: U8) -> U8 {
    v.reverse_bits()
}

#[inline(always)]
pub fn sobol_1_reversed(index: U8) -> U8 {
    index.map(|index| {
        let mut y = index;
        y ^= (y >> 1) & 0x5555_5555;
        y ^= (y >> 2) & 0x3333_3333;
        y ^= (y >> 4) & 0x0f0f_0f0f;
        y ^= (y >> 8) & 0x00ff_00ff;
        y ^= (y >> 16) & 0x0000_ffff;
        y
    })
}

/// The samplers of a packet's paths. `kind` is the packet's; the rest, the sample index
/// included (a lane whose path ends takes another pixel's or sample's), is per lane.
#[derive(Clone, Copy, Debug)]
pub struct SamplerLanes {
    pub kind: u32,
    pub index: U8,
    pub pixel_seed: U8,
    pub dim: U8,
    /// The independent sampler's PCG state.
    pub state: U8,
}

impl SamplerLanes {
    /// Lane i is `samplers[i]` (all of one kind).
    pub fn from_samplers(samplers: &[Sampler; super::LANES]) -> SamplerLanes {
        let parts = samplers.map(|s| sampler_parts(&s));
        SamplerLanes {
            kind: parts[0].0,
            index: U8::from_fn(|i| parts[i].2),
            pixel_seed: U8::from_fn(|i| parts[i].1),
            dim: U8::from_fn(|i| parts[i].3),
            state: U8::from_fn(|i| parts[i].4),
        }
    }

    /// Lane i's sampler.
    #[inline(always)]
    pub fn lane(&self, i: usize) -> Sampler {
        sampler_from_parts(self.kind, self.pixel_seed.0[i], self.index.0[i], self.dim.0[i], self.state.0[i])
    }

    /// Lane i becomes `s`.
    #[inline(always)]
    pub fn set_lane(&mut self, i: usize, s: &Sampler) {
        let (_, pixel_seed, index, dim, state) = sampler_parts(s);
        self.pixel_seed.0[i] = pixel_seed;
        self.index.0[i] = index;
        self.dim.0[i] = dim;
        self.state.0[i] = state;
    }

    /// The next dimension's seed, advancing the lanes of `m`.
    #[inline(always)]
    fn next_dimension_seed(&mut self, m: M8) -> U8 {
        let d = pcg_hash(self.pixel_seed.zip(pcg_hash(self.dim), |a, b| a ^ b));
        let next = self.dim.map(|d| d + 1);
        self.dim = U8::from_fn(|i| if m.0[i] != 0 { next.0[i] } else { self.dim.0[i] });
        d
    }

    /// `rng_next` in the lanes of `m`.
    #[inline(always)]
    fn rng_next(&mut self, m: M8) -> F8 {
        let s = self.state.map(|s| s.wrapping_mul(747796405).wrapping_add(2891336453));
        self.state = U8::from_fn(|i| if m.0[i] != 0 { s.0[i] } else { self.state.0[i] });
        let w = s.map(|s| {
            let mut w = ((s >> ((s >> 28) + 4)) ^ s).wrapping_mul(277803737);
            w ^= w >> 22;
            w
        });
        w.unit_float()
    }

    /// `sample_1d` in the lanes of `m` (the others draw nothing; their value is not to be used).
    #[inline(always)]
    pub fn sample_1d(&mut self, m: M8) -> F8 {
        if self.kind == SAMPLER_INDEPENDENT {
            return self.rng_next(m);
        }
        let d = self.next_dimension_seed(m);
        let i = owen_scramble(self.index, d);
        reverse_bits(laine_karras(i, pcg_hash(d.map(|d| d ^ 1)))).unit_float()
    }

    /// `sample_2d` in the lanes of `m`.
    #[inline(always)]
    pub fn sample_2d(&mut self, m: M8) -> (F8, F8) {
        if self.kind == SAMPLER_INDEPENDENT {
            let a = self.rng_next(m);
            let b = self.rng_next(m);
            return (a, b);
        }
        let d = self.next_dimension_seed(m);
        let i = owen_scramble(self.index, d);
        let x = reverse_bits(laine_karras(i, pcg_hash(d.map(|d| d ^ 1))));
        let y = reverse_bits(laine_karras(sobol_1_reversed(i), pcg_hash(d.map(|d| d ^ 2))));
        (x.unit_float(), y.unit_float())
    }
}

#[inline(always)]
fn owen_scramble(v: U8, seed: U8) -> U8 {
    reverse_bits(laine_karras(reverse_bits(v), seed))
}
