//! Lanes of numbers for the packet's arithmetic: `F8` (f32), `U8` (u32), `M8` (a mask) and
//! `V3` (three `F8`, a vector per lane). Every operation is the scalar one, lane by lane, in
//! the same order — no fused multiply-add; `max_num`/`min_num`/`clamp` with Rust's scalar
//! semantics; `dot`, `cross` and `normalize` as glam's `Vec3` computes them — so each lane
//! holds the bits the scalar reference computes. On x86-64 the arithmetic, comparisons, selects
//! and mask operations are AVX instructions written out (`avx`): left to LLVM's vectoriser, the
//! loops over arrays became 128-bit halves or single lanes in much of the kernel (BENCHMARKS.md
//! session 35), so on x86-64 the lanes run only where the CPU has AVX2 (`super::available`).
//! Elsewhere they are loops over fixed arrays, which LLVM makes NEON pairs.

use glam::Vec3;
use std::ops::{Add, BitAnd, BitOr, Div, Mul, Neg, Not, Sub};

/// Lanes of a packet.
pub const W: usize = super::LANES;

/// The lane operations as AVX instructions. Every one is IEEE's operation per lane, as the
/// scalar one: `+ − × ÷ √` round the same, the comparisons are the ordered ones Rust's `<`,
/// `<=`, `>`, `>=`, `==` are (false with a NaN), and a mask's lanes are all ones or all zeros
/// (every `M8` is made so), so a blend by the sign bit is the select by "≠ 0".
#[cfg(target_arch = "x86_64")]
mod avx {
    use super::{F8, M8, U8};
    use std::arch::x86_64::*;
    use std::mem::transmute;

    // SAFETY (all of this module): the lanes run on x86-64 only on CPUs with AVX2
    // (`lanes::available`); `F8`, `M8` and `__m256` are 32 bytes, any bits valid.
    #[inline(always)]
    pub fn ps(x: F8) -> __m256 {
        unsafe { transmute(x) }
    }
    #[inline(always)]
    pub fn f8(x: __m256) -> F8 {
        unsafe { transmute(x) }
    }
    #[inline(always)]
    pub fn mask(x: M8) -> __m256 {
        unsafe { transmute(x) }
    }
    #[inline(always)]
    pub fn m8(x: __m256) -> M8 {
        unsafe { transmute(x) }
    }
    #[inline(always)]
    pub fn add(a: F8, b: F8) -> F8 {
        unsafe { f8(_mm256_add_ps(ps(a), ps(b))) }
    }
    #[inline(always)]
    pub fn sub(a: F8, b: F8) -> F8 {
        unsafe { f8(_mm256_sub_ps(ps(a), ps(b))) }
    }
    #[inline(always)]
    pub fn mul(a: F8, b: F8) -> F8 {
        unsafe { f8(_mm256_mul_ps(ps(a), ps(b))) }
    }
    #[inline(always)]
    pub fn div(a: F8, b: F8) -> F8 {
        unsafe { f8(_mm256_div_ps(ps(a), ps(b))) }
    }
    #[inline(always)]
    pub fn sqrt(a: F8) -> F8 {
        unsafe { f8(_mm256_sqrt_ps(ps(a))) }
    }
    /// The sign bit cleared (`f32::abs`) or flipped (`-x`).
    #[inline(always)]
    pub fn abs(a: F8) -> F8 {
        unsafe { f8(_mm256_andnot_ps(_mm256_set1_ps(-0.0), ps(a))) }
    }
    #[inline(always)]
    pub fn neg(a: F8) -> F8 {
        unsafe { f8(_mm256_xor_ps(_mm256_set1_ps(-0.0), ps(a))) }
    }
    #[inline(always)]
    pub fn lt(a: F8, b: F8) -> M8 {
        unsafe { m8(_mm256_cmp_ps::<_CMP_LT_OQ>(ps(a), ps(b))) }
    }
    #[inline(always)]
    pub fn le(a: F8, b: F8) -> M8 {
        unsafe { m8(_mm256_cmp_ps::<_CMP_LE_OQ>(ps(a), ps(b))) }
    }
    #[inline(always)]
    pub fn gt(a: F8, b: F8) -> M8 {
        unsafe { m8(_mm256_cmp_ps::<_CMP_GT_OQ>(ps(a), ps(b))) }
    }
    #[inline(always)]
    pub fn ge(a: F8, b: F8) -> M8 {
        unsafe { m8(_mm256_cmp_ps::<_CMP_GE_OQ>(ps(a), ps(b))) }
    }
    #[inline(always)]
    pub fn eq(a: F8, b: F8) -> M8 {
        unsafe { m8(_mm256_cmp_ps::<_CMP_EQ_OQ>(ps(a), ps(b))) }
    }
    #[inline(always)]
    pub fn select(m: M8, a: F8, b: F8) -> F8 {
        unsafe { f8(_mm256_blendv_ps(ps(b), ps(a), mask(m))) }
    }
    #[inline(always)]
    pub fn and(a: M8, b: M8) -> M8 {
        unsafe { m8(_mm256_and_ps(mask(a), mask(b))) }
    }
    #[inline(always)]
    pub fn or(a: M8, b: M8) -> M8 {
        unsafe { m8(_mm256_or_ps(mask(a), mask(b))) }
    }
    #[inline(always)]
    pub fn not(a: M8) -> M8 {
        unsafe { m8(_mm256_xor_ps(_mm256_castsi256_ps(_mm256_set1_epi32(-1)), mask(a))) }
    }
    #[inline(always)]
    pub fn bits(a: M8) -> u32 {
        unsafe { _mm256_movemask_ps(mask(a)) as u32 }
    }
    #[inline(always)]
    pub fn epi(x: U8) -> __m256i {
        unsafe { transmute(x) }
    }
    #[inline(always)]
    pub fn u8(x: __m256i) -> U8 {
        unsafe { transmute(x) }
    }
    #[inline(always)]
    pub fn eq_u(a: U8, b: U8) -> M8 {
        unsafe { m8(_mm256_castsi256_ps(_mm256_cmpeq_epi32(epi(a), epi(b)))) }
    }
    #[inline(always)]
    pub fn add_u(a: U8, b: U8) -> U8 {
        unsafe { u8(_mm256_add_epi32(epi(a), epi(b))) }
    }
    #[inline(always)]
    pub fn sub_u(a: U8, b: U8) -> U8 {
        unsafe { u8(_mm256_sub_epi32(epi(a), epi(b))) }
    }
    #[inline(always)]
    pub fn select_u(m: M8, a: U8, b: U8) -> U8 {
        unsafe {
            let (a, b) = (_mm256_castsi256_ps(epi(a)), _mm256_castsi256_ps(epi(b)));
            u8(_mm256_castps_si256(_mm256_blendv_ps(b, a, mask(m))))
        }
    }
    /// `u32::reverse_bits`: the bytes reversed in each lane, then each byte's bits through a
    /// table of reversed nibbles.
    #[inline(always)]
    pub fn reverse_bits(x: U8) -> U8 {
        unsafe {
            let bytes = _mm256_setr_epi8(
                3, 2, 1, 0, 7, 6, 5, 4, 11, 10, 9, 8, 15, 14, 13, 12, 3, 2, 1, 0, 7, 6, 5, 4, 11, 10, 9, 8, 15, 14, 13,
                12,
            );
            let nibbles = _mm256_setr_epi8(
                0x0, 0x8, 0x4, 0xc, 0x2, 0xa, 0x6, 0xe, 0x1, 0x9, 0x5, 0xd, 0x3, 0xb, 0x7, 0xf, 0x0, 0x8, 0x4, 0xc,
                0x2, 0xa, 0x6, 0xe, 0x1, 0x9, 0x5, 0xd, 0x3, 0xb, 0x7, 0xf,
            );
            let low = _mm256_set1_epi8(0x0f);
            let v = _mm256_shuffle_epi8(epi(x), bytes);
            let lo = _mm256_shuffle_epi8(nibbles, _mm256_and_si256(v, low));
            let hi = _mm256_shuffle_epi8(nibbles, _mm256_and_si256(_mm256_srli_epi16::<4>(v), low));
            u8(_mm256_or_si256(_mm256_slli_epi16::<4>(lo), hi))
        }
    }
    /// Rust's `x as i32` (as bits): the truncating conversion, which gives i32::MIN for NaN
    /// and out-of-range lanes, mended to Rust's saturation (NaN → 0, ≥ 2³¹ → i32::MAX).
    #[inline(always)]
    pub fn to_i32(x: F8) -> U8 {
        unsafe {
            let c = _mm256_castsi256_ps(_mm256_cvttps_epi32(ps(x)));
            let big = _mm256_cmp_ps::<_CMP_GE_OQ>(ps(x), _mm256_set1_ps(2147483648.0));
            let c = _mm256_blendv_ps(c, _mm256_castsi256_ps(_mm256_set1_epi32(i32::MAX)), big);
            let nan = _mm256_cmp_ps::<_CMP_UNORD_Q>(ps(x), ps(x));
            u8(_mm256_castps_si256(_mm256_andnot_ps(nan, c)))
        }
    }
}

/// `$avx` on x86-64 (`avx`), `$portable` elsewhere.
macro_rules! by_arch {
    ($avx:expr, $portable:expr) => {{
        #[cfg(target_arch = "x86_64")]
        let r = $avx;
        #[cfg(not(target_arch = "x86_64"))]
        let r = $portable;
        r
    }};
}

#[derive(Clone, Copy, Debug, PartialEq)]
#[repr(C, align(32))]
pub struct F8(pub [f32; W]);

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[repr(C, align(32))]
pub struct U8(pub [u32; W]);

/// A mask: a lane is true when all its bits are set.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[repr(C, align(32))]
pub struct M8(pub [u32; W]);

/// `[f(0), …, f(W − 1)]` as a plain loop over an array, the shape LLVM vectorises (the
/// iterator inside `std::array::from_fn` it does not).
#[inline(always)]
fn lanes<T: Copy + Default>(mut f: impl FnMut(usize) -> T) -> [T; W] {
    let mut out = [T::default(); W];
    for (i, o) in out.iter_mut().enumerate() {
        *o = f(i);
    }
    out
}

/// `[f(0), …, f(W − 1)]` for any lane type, inlined (`std::array::from_fn` and `map` over
/// arrays of lanes stay calls, out of the AVX2 code: measured, BENCHMARKS.md session 21).
#[inline(always)]
pub fn per_lane<T: Copy>(mut f: impl FnMut(usize) -> T) -> [T; W] {
    let mut out = [f(0); W];
    for (i, o) in out.iter_mut().enumerate().skip(1) {
        *o = f(i);
    }
    out
}

impl F8 {
    #[inline(always)]
    pub fn splat(x: f32) -> F8 {
        F8([x; W])
    }

    /// Lane `i` is `f(i)`.
    #[inline(always)]
    pub fn from_fn(f: impl FnMut(usize) -> f32) -> F8 {
        F8(lanes(f))
    }

    #[inline(always)]
    pub fn map(self, f: impl Fn(f32) -> f32) -> F8 {
        F8(lanes(|i| f(self.0[i])))
    }

    #[inline(always)]
    pub fn zip(self, o: F8, f: impl Fn(f32, f32) -> f32) -> F8 {
        F8(lanes(|i| f(self.0[i], o.0[i])))
    }

    #[inline(always)]
    #[cfg_attr(target_arch = "x86_64", allow(dead_code))]
    fn compare(self, o: F8, f: impl Fn(f32, f32) -> bool) -> M8 {
        M8(lanes(|i| if f(self.0[i], o.0[i]) { u32::MAX } else { 0 }))
    }

    #[inline(always)]
    pub fn sqrt(self) -> F8 {
        by_arch!(avx::sqrt(self), self.map(f32::sqrt))
    }

    #[inline(always)]
    pub fn abs(self) -> F8 {
        by_arch!(avx::abs(self), self.map(f32::abs))
    }

    /// `f32::max`: the other operand when one is NaN.
    #[inline(always)]
    pub fn max_num(self, o: F8) -> F8 {
        self.zip(o, f32::max)
    }

    /// `f32::min`.
    #[inline(always)]
    pub fn min_num(self, o: F8) -> F8 {
        self.zip(o, f32::min)
    }

    /// `f32::clamp`: NaN stays NaN.
    #[inline(always)]
    pub fn clamp(self, lo: f32, hi: f32) -> F8 {
        self.map(|x| {
            let mut x = x;
            if x < lo {
                x = lo;
            }
            if x > hi {
                x = hi;
            }
            x
        })
    }

    #[inline(always)]
    pub fn lt(self, o: F8) -> M8 {
        by_arch!(avx::lt(self, o), self.compare(o, |a, b| a < b))
    }

    #[inline(always)]
    pub fn le(self, o: F8) -> M8 {
        by_arch!(avx::le(self, o), self.compare(o, |a, b| a <= b))
    }

    #[inline(always)]
    pub fn gt(self, o: F8) -> M8 {
        by_arch!(avx::gt(self, o), self.compare(o, |a, b| a > b))
    }

    #[inline(always)]
    pub fn ge(self, o: F8) -> M8 {
        by_arch!(avx::ge(self, o), self.compare(o, |a, b| a >= b))
    }

    #[inline(always)]
    pub fn eq(self, o: F8) -> M8 {
        by_arch!(avx::eq(self, o), self.compare(o, |a, b| a == b))
    }

    /// Each lane's bits (`f32::to_bits`).
    #[inline(always)]
    pub fn to_bits(self) -> U8 {
        // SAFETY: [f32; W] and [u32; W] have the same size, any bits valid.
        U8(unsafe { std::mem::transmute::<[f32; W], [u32; W]>(self.0) })
    }

    /// The floats with bits `b` (`f32::from_bits`).
    #[inline(always)]
    pub fn from_bits(b: U8) -> F8 {
        // SAFETY: as in `to_bits`.
        F8(unsafe { std::mem::transmute::<[u32; W], [f32; W]>(b.0) })
    }

    /// `x as i32` lane by lane (NaN → 0, out of range → the nearest end), as the i32's bits.
    #[inline(always)]
    pub fn to_i32(self) -> U8 {
        by_arch!(avx::to_i32(self), U8(lanes(|i| self.0[i] as i32 as u32)))
    }

    /// `a` where `m`, else `b`.
    #[inline(always)]
    pub fn select(m: M8, a: F8, b: F8) -> F8 {
        by_arch!(avx::select(m, a, b), F8(lanes(|i| if m.0[i] != 0 { a.0[i] } else { b.0[i] })))
    }
}

macro_rules! float_op {
    ($trait:ident, $f:ident, $op:tt) => {
        impl $trait for F8 {
            type Output = F8;
            #[inline(always)]
            fn $f(self, o: F8) -> F8 {
                by_arch!(avx::$f(self, o), F8(lanes(|i| self.0[i] $op o.0[i])))
            }
        }
        impl $trait<f32> for F8 {
            type Output = F8;
            #[inline(always)]
            fn $f(self, o: f32) -> F8 {
                self $op F8::splat(o)
            }
        }
        impl $trait<F8> for f32 {
            type Output = F8;
            #[inline(always)]
            fn $f(self, o: F8) -> F8 {
                F8::splat(self) $op o
            }
        }
    };
}
float_op!(Add, add, +);
float_op!(Sub, sub, -);
float_op!(Mul, mul, *);
float_op!(Div, div, /);

impl Neg for F8 {
    type Output = F8;
    #[inline(always)]
    fn neg(self) -> F8 {
        by_arch!(avx::neg(self), self.map(|x| -x))
    }
}

impl M8 {
    #[inline(always)]
    pub fn splat(b: bool) -> M8 {
        M8([if b { u32::MAX } else { 0 }; W])
    }

    /// Lane i set where `f(i)` is true.
    #[inline(always)]
    pub fn from_fn(mut f: impl FnMut(usize) -> bool) -> M8 {
        M8(lanes(|i| if f(i) { u32::MAX } else { 0 }))
    }

    /// Lane i set where bit i of `bits` is.
    #[inline(always)]
    pub fn from_bits(bits: u32) -> M8 {
        M8(lanes(|i| if bits >> i & 1 != 0 { u32::MAX } else { 0 }))
    }

    /// Bit i set where lane i is.
    #[inline(always)]
    pub fn bits(self) -> u32 {
        by_arch!(avx::bits(self), {
            let mut b = 0;
            for i in 0..W {
                b |= (self.0[i] & 1) << i;
            }
            b
        })
    }

    #[inline(always)]
    pub fn lane(self, i: usize) -> bool {
        self.0[i] != 0
    }

    #[inline(always)]
    pub fn set_lane(&mut self, i: usize, b: bool) {
        self.0[i] = if b { u32::MAX } else { 0 };
    }
}

impl BitAnd for M8 {
    type Output = M8;
    #[inline(always)]
    fn bitand(self, o: M8) -> M8 {
        by_arch!(avx::and(self, o), M8(lanes(|i| self.0[i] & o.0[i])))
    }
}

impl BitOr for M8 {
    type Output = M8;
    #[inline(always)]
    fn bitor(self, o: M8) -> M8 {
        by_arch!(avx::or(self, o), M8(lanes(|i| self.0[i] | o.0[i])))
    }
}

impl Not for M8 {
    type Output = M8;
    #[inline(always)]
    fn not(self) -> M8 {
        by_arch!(avx::not(self), M8(lanes(|i| !self.0[i])))
    }
}

impl U8 {
    #[inline(always)]
    pub fn splat(x: u32) -> U8 {
        U8([x; W])
    }

    #[inline(always)]
    pub fn from_fn(f: impl FnMut(usize) -> u32) -> U8 {
        U8(lanes(f))
    }

    #[inline(always)]
    pub fn map(self, f: impl Fn(u32) -> u32) -> U8 {
        U8(lanes(|i| f(self.0[i])))
    }

    #[inline(always)]
    pub fn zip(self, o: U8, f: impl Fn(u32, u32) -> u32) -> U8 {
        U8(lanes(|i| f(self.0[i], o.0[i])))
    }

    #[inline(always)]
    pub fn eq(self, o: U8) -> M8 {
        by_arch!(avx::eq_u(self, o), M8(lanes(|i| if self.0[i] == o.0[i] { u32::MAX } else { 0 })))
    }

    #[inline(always)]
    pub fn reverse_bits(self) -> U8 {
        by_arch!(avx::reverse_bits(self), self.map(u32::reverse_bits))
    }

    #[inline(always)]
    pub fn wrapping_add(self, o: U8) -> U8 {
        by_arch!(avx::add_u(self, o), self.zip(o, u32::wrapping_add))
    }

    #[inline(always)]
    pub fn wrapping_sub(self, o: U8) -> U8 {
        by_arch!(avx::sub_u(self, o), self.zip(o, u32::wrapping_sub))
    }

    /// `a` where `m`, else `b`.
    #[inline(always)]
    pub fn select(m: M8, a: U8, b: U8) -> U8 {
        by_arch!(avx::select_u(m, a, b), U8(lanes(|i| if m.0[i] != 0 { a.0[i] } else { b.0[i] })))
    }

    #[inline(always)]
    pub fn gt(self, x: u32) -> M8 {
        M8(lanes(|i| if self.0[i] > x { u32::MAX } else { 0 }))
    }

    #[inline(always)]
    pub fn ge(self, x: u32) -> M8 {
        M8(lanes(|i| if self.0[i] >= x { u32::MAX } else { 0 }))
    }

    /// (x >> 8) / 2²⁴: a float in [0, 1) from the top 24 bits (`unit_float`), converted as a
    /// signed integer (exact below 2²⁴, one instruction on x86).
    #[inline(always)]
    pub fn unit_float(self) -> F8 {
        F8(lanes(|i| (self.0[i] >> 8) as i32 as f32 * (1.0 / 16777216.0)))
    }
}

/// Three lanes of floats: a vector per lane.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct V3 {
    pub x: F8,
    pub y: F8,
    pub z: F8,
}

impl V3 {
    #[inline(always)]
    pub fn new(x: F8, y: F8, z: F8) -> V3 {
        V3 { x, y, z }
    }

    #[inline(always)]
    pub fn splat(v: Vec3) -> V3 {
        V3::new(F8::splat(v.x), F8::splat(v.y), F8::splat(v.z))
    }

    /// Lane `i` is `f(i)`.
    #[inline(always)]
    pub fn from_fn(f: impl Fn(usize) -> Vec3) -> V3 {
        let v: [Vec3; W] = lanes(f);
        V3::new(F8(lanes(|i| v[i].x)), F8(lanes(|i| v[i].y)), F8(lanes(|i| v[i].z)))
    }

    #[inline(always)]
    pub fn lane(&self, i: usize) -> Vec3 {
        Vec3::new(self.x.0[i], self.y.0[i], self.z.0[i])
    }

    #[inline(always)]
    pub fn set_lane(&mut self, i: usize, v: Vec3) {
        (self.x.0[i], self.y.0[i], self.z.0[i]) = (v.x, v.y, v.z);
    }

    /// glam's `dot`: (x x' + y y') + z z'.
    #[inline(always)]
    pub fn dot(self, o: V3) -> F8 {
        self.x * o.x + self.y * o.y + self.z * o.z
    }

    /// glam's `cross`.
    #[inline(always)]
    pub fn cross(self, o: V3) -> V3 {
        V3::new(self.y * o.z - o.y * self.z, self.z * o.x - o.z * self.x, self.x * o.y - o.x * self.y)
    }

    /// glam's `normalize`: v · (1 / √(v · v)).
    #[inline(always)]
    pub fn normalize(self) -> V3 {
        self * (1.0 / self.dot(self).sqrt())
    }

    /// glam's `max_element`: max(x, max(y, z)) by `>`.
    #[inline(always)]
    pub fn max_element(self) -> F8 {
        let max = |a: F8, b: F8| F8::select(a.gt(b), a, b);
        max(self.x, max(self.y, self.z))
    }

    #[inline(always)]
    pub fn select(m: M8, a: V3, b: V3) -> V3 {
        V3::new(F8::select(m, a.x, b.x), F8::select(m, a.y, b.y), F8::select(m, a.z, b.z))
    }
}

impl Add for V3 {
    type Output = V3;
    #[inline(always)]
    fn add(self, o: V3) -> V3 {
        V3::new(self.x + o.x, self.y + o.y, self.z + o.z)
    }
}

impl Sub for V3 {
    type Output = V3;
    #[inline(always)]
    fn sub(self, o: V3) -> V3 {
        V3::new(self.x - o.x, self.y - o.y, self.z - o.z)
    }
}

impl Mul for V3 {
    type Output = V3;
    #[inline(always)]
    fn mul(self, o: V3) -> V3 {
        V3::new(self.x * o.x, self.y * o.y, self.z * o.z)
    }
}

impl Mul<F8> for V3 {
    type Output = V3;
    #[inline(always)]
    fn mul(self, s: F8) -> V3 {
        V3::new(self.x * s, self.y * s, self.z * s)
    }
}

impl Mul<V3> for F8 {
    type Output = V3;
    #[inline(always)]
    fn mul(self, v: V3) -> V3 {
        V3::new(self * v.x, self * v.y, self * v.z)
    }
}

impl Div<F8> for V3 {
    type Output = V3;
    #[inline(always)]
    fn div(self, s: F8) -> V3 {
        V3::new(self.x / s, self.y / s, self.z / s)
    }
}

impl Neg for V3 {
    type Output = V3;
    #[inline(always)]
    fn neg(self) -> V3 {
        V3::new(-self.x, -self.y, -self.z)
    }
}
