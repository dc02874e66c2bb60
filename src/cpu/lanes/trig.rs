//! `cpu::trig` in lanes: every operation the scalar one, lane by lane in its order, with
//! selects where the scalar code branches, so each lane holds the scalar function's bits.

use super::lane::F8;
use crate::cpu::trig::{ATAN_COEFFICIENTS, SIN_COEFFICIENTS, TAN_PI_8};
use std::f32::consts::{FRAC_PI_2, FRAC_PI_4, PI};

#[inline(always)]
pub fn bounded_sin(x: F8) -> F8 {
    let y = F8::select(x.gt(F8::splat(FRAC_PI_2)), PI - x, F8::select(x.lt(F8::splat(-FRAC_PI_2)), -PI - x, x));
    let y2 = y * y;
    let [c13, c11, c9, c7, c5, c3] = SIN_COEFFICIENTS;
    let p = F8::splat(c13);
    let p = c11 + y2 * p;
    let p = c9 + y2 * p;
    let p = c7 + y2 * p;
    let p = c5 + y2 * p;
    let p = c3 + y2 * p;
    y * (1.0 + y2 * p)
}

#[inline(always)]
pub fn bounded_cos(x: F8) -> F8 {
    let y = x + FRAC_PI_2;
    bounded_sin(F8::select(y.gt(F8::splat(PI)), y - 2.0 * PI, y))
}

/// (cos φ, sin φ) of φ = 2π u.
#[inline(always)]
pub fn turn(u: F8) -> (F8, F8) {
    let x = 2.0 * PI * u - PI;
    (-bounded_cos(x), -bounded_sin(x))
}

#[inline(always)]
pub fn atan2(y: F8, x: F8) -> F8 {
    let zero = F8::splat(0.0);
    let (ax, ay) = (x.abs(), y.abs());
    let swap = ay.gt(ax);
    let (num, den) = (F8::select(swap, ax, ay), F8::select(swap, ay, ax));
    let a = F8::select(den.eq(zero), zero, num / den);
    let reduce = a.gt(F8::splat(TAN_PI_8));
    let r = F8::select(reduce, (a - 1.0) / (a + 1.0), a);
    let z = r * r;
    let [c0, c1, c2, c3] = ATAN_COEFFICIENTS;
    let p = c0 * z - c1;
    let p = p * z + c2;
    let p = p * z - c3;
    let t = p * z * r + r;
    let t = F8::select(reduce, FRAC_PI_4 + t, t);
    let t = F8::select(swap, FRAC_PI_2 - t, t);
    let t = F8::select(x.lt(zero), PI - t, t);
    F8::select(y.lt(zero), -t, t)
}
