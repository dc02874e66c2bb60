//! Sine, cosine and arc tangent as polynomials of our own, for the hot path: the same
//! operations here and in the lanes (`lanes::trig`), so both hold the same bits, and no libm
//! call per lane (a call there cost its own time plus a spill of every vector register).
//! The shaders use WGSL's built-ins except `bounded_sin`/`bounded_cos`
//! (`shaders/spherical_triangle.wgsl`: WGSL bounds its own sin and cos only to 2⁻¹¹).

use std::f32::consts::{FRAC_PI_2, FRAC_PI_4, PI};

/// Taylor coefficients of sin x from x¹³ down to x³ (±1/n!), highest power first.
pub const SIN_COEFFICIENTS: [f32; 6] =
    [1.0 / 6227020800.0, -1.0 / 39916800.0, 1.0 / 362880.0, -1.0 / 5040.0, 1.0 / 120.0, -1.0 / 6.0];

/// sin x for |x| ≤ π (Taylor to x¹³ on [−π/2, π/2], error below 1e-9 before rounding).
#[inline(always)]
pub fn bounded_sin(x: f32) -> f32 {
    let y = if x > FRAC_PI_2 {
        PI - x
    } else if x < -FRAC_PI_2 {
        -PI - x
    } else {
        x
    };
    let y2 = y * y;
    let [c13, c11, c9, c7, c5, c3] = SIN_COEFFICIENTS;
    let p = c13;
    let p = c11 + y2 * p;
    let p = c9 + y2 * p;
    let p = c7 + y2 * p;
    let p = c5 + y2 * p;
    let p = c3 + y2 * p;
    y * (1.0 + y2 * p)
}

/// cos x for |x| ≤ π, as sin(x + π/2) brought back into [−π, π].
#[inline(always)]
pub fn bounded_cos(x: f32) -> f32 {
    let y = x + FRAC_PI_2;
    bounded_sin(if y > PI { y - 2.0 * PI } else { y })
}

/// (cos φ, sin φ) of φ = 2π u, u in [0, 1]: −cos and −sin of φ − π ∈ [−π, π].
#[inline(always)]
pub fn turn(u: f32) -> (f32, f32) {
    let x = 2.0 * PI * u - PI;
    (-bounded_cos(x), -bounded_sin(x))
}

/// tan(π/8): above it the arc tangent's argument is reduced by π/4.
pub const TAN_PI_8: f32 = 0.414_213_57;

/// Cephes' `atanf` polynomial, highest power first (signs alternate, applied in `atan2`).
pub const ATAN_COEFFICIENTS: [f32; 4] = [0.080_537_446, 0.138_776_85, 0.199_777_11, 0.333_329_5];

/// atan2(y, x) over all four quadrants (0 when both are 0, NaN when either is): the ratio
/// of the smaller to the larger magnitude, reduced below tan(π/8), through the odd
/// polynomial of Cephes' `atanf` (relative error about 2e-7 — libm's is 1 ulp, but the
/// light sampler's pdf reads the same function its sampling does).
#[inline(always)]
pub fn atan2(y: f32, x: f32) -> f32 {
    let (ax, ay) = (x.abs(), y.abs());
    let swap = ay > ax;
    let (num, den) = if swap { (ax, ay) } else { (ay, ax) };
    let a = if den == 0.0 { 0.0 } else { num / den };
    let reduce = a > TAN_PI_8;
    let r = if reduce { (a - 1.0) / (a + 1.0) } else { a };
    let z = r * r;
    let [c0, c1, c2, c3] = ATAN_COEFFICIENTS;
    let p = c0 * z - c1;
    let p = p * z + c2;
    let p = p * z - c3;
    let mut t = p * z * r + r;
    if reduce {
        t += FRAC_PI_4;
    }
    if swap {
        t = FRAC_PI_2 - t;
    }
    if x < 0.0 {
        t = PI - t;
    }
    if y < 0.0 { -t } else { t }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Against f64 over a grid of the whole range: atan2 within 3e-7 relative (measured
    /// 2.2e-7), sin and cos of 2πu within 5e-7 absolute (measured 3.6e-7, mostly the f32
    /// rounding of 2πu − π itself, which libm's cos of 2πu shares in part).
    #[test]
    fn polynomials_agree_with_libm() {
        let n = 2000;
        for i in 0..=n {
            let u = i as f32 / n as f32;
            let (c, s) = turn(u);
            let phi = (2.0 * std::f64::consts::PI) * u as f64;
            assert!((c as f64 - phi.cos()).abs() < 5e-7, "cos at u = {u}");
            assert!((s as f64 - phi.sin()).abs() < 5e-7, "sin at u = {u}");
            for j in 0..=n / 10 {
                let angle = (j as f64 / (n / 10) as f64 - 0.5) * 2.0 * std::f64::consts::PI;
                for scale in [1e-6f64, 1e-2, 1.0, 1e3] {
                    let (y, x) = ((angle.sin() * scale * (u as f64 + 0.1)) as f32, (angle.cos() * scale) as f32);
                    let want = (y as f64).atan2(x as f64);
                    let got = atan2(y, x) as f64;
                    assert!((got - want).abs() <= 3e-7 * want.abs() + 1e-30, "atan2({y}, {x}): {got} vs {want}");
                }
            }
        }
        assert_eq!(atan2(0.0, 0.0), 0.0);
        assert!(atan2(f32::NAN, 1.0).is_nan() && atan2(1.0, f32::NAN).is_nan());
        assert_eq!(atan2(0.0, -1.0), PI);
    }
}
