//! One chi-square harness for every sampling routine (as Mitsuba tests its BSDFs and
//! emitters): draw samples, histogram them, integrate the claimed pdf over the same bins with a
//! midpoint rule, pool sparse bins, and compute Pearson's statistic and its p-value. Samples a
//! routine fails to produce (`None`) form their own bin, expected to hold 1 − ∫pdf.

use glam::{Vec2, Vec3};

/// Upper tail of the chi-square distribution (Wilson–Hilferty normal approximation).
pub fn p_value(chi2: f64, dof: f64) -> f64 {
    let z = ((chi2 / dof).powf(1.0 / 3.0) - (1.0 - 2.0 / (9.0 * dof))) / (2.0 / (9.0 * dof)).sqrt();
    0.5 * erfc(z / std::f64::consts::SQRT_2)
}

fn erfc(x: f64) -> f64 {
    // Numerical Recipes' erfc, relative error < 1.2e-7.
    let z = x.abs();
    let t = 1.0 / (1.0 + 0.5 * z);
    // Horner's rule from the highest coefficient: the nested form's operations in its order
    // (written nested, the expression took rustfmt 8 s on every test file that uses it).
    const C: [f64; 9] =
        [1.00002368, 0.37409196, 0.09678418, -0.18628806, 0.27886807, -1.13520398, 1.48851587, -0.82215223, 0.17087277];
    let mut p = C[8];
    for c in C[..8].iter().rev() {
        p = c + t * p;
    }
    let r = t * (-z * z - 1.26551223 + t * p).exp();
    if x >= 0.0 { r } else { 2.0 - r }
}

/// The outcome of one chi-square test.
#[derive(Debug)]
pub struct Chi2 {
    pub chi2: f64,
    pub dof: f64,
    pub p: f64,
    /// ∫ pdf over the domain (≤ 1; the rest is the failure bin).
    pub total: f64,
}

impl Chi2 {
    /// Fails unless p exceeds the per-test level that gives `alpha` over `tests` tests (Šidák).
    pub fn assert_passes(&self, what: &str, alpha: f64, tests: usize) {
        let level = 1.0 - (1.0 - alpha).powf(1.0 / tests as f64);
        assert!(
            self.p > level,
            "{what}: chi² = {:.1}, dof {}, p = {:.2e} (≤ {level:.1e})",
            self.chi2,
            self.dof,
            self.p
        );
    }
}

/// Pearson's statistic over `observed` against `expected` (counts), pooling bins expecting
/// fewer than 5; panics when samples land where the pdf says almost none should.
pub fn pearson(what: &str, observed: &[f64], expected: &[f64], total: f64) -> Chi2 {
    let (mut chi2, mut dof, mut pool_o, mut pool_e) = (0.0, 0.0, 0.0, 0.0);
    for (o, e) in observed.iter().zip(expected) {
        if *e < 5.0 {
            pool_o += o;
            pool_e += e;
        } else {
            chi2 += (o - e) * (o - e) / e;
            dof += 1.0;
        }
    }
    if pool_e >= 5.0 {
        chi2 += (pool_o - pool_e) * (pool_o - pool_e) / pool_e;
        dof += 1.0;
    } else {
        assert!(pool_o <= 10.0 + pool_e * 5.0, "{what}: {pool_o} samples where the pdf says {pool_e:.2}");
    }
    dof -= 1.0;
    Chi2 { chi2, dof, p: p_value(chi2, dof), total }
}

/// Bins over the sphere in (cos θ, φ): `theta`×`phi` bins, `sub`² midpoint cells per bin for
/// the expected counts, `pole_sub` cells per side in the rows at the poles (narrow lobes).
#[derive(Clone, Copy)]
pub struct SphereBins {
    pub theta: usize,
    pub phi: usize,
    pub sub: usize,
    pub pole_sub: usize,
}

impl Default for SphereBins {
    fn default() -> Self {
        SphereBins { theta: 20, phi: 40, sub: 32, pole_sub: 256 }
    }
}

pub fn direction(cos_theta: f32, phi: f32) -> Vec3 {
    let s = (1.0 - cos_theta * cos_theta).max(0.0).sqrt();
    Vec3::new(s * phi.cos(), s * phi.sin(), cos_theta)
}

/// Chi-square of `n` directions drawn by `sample` against `pdf` (solid angle).
pub fn sphere(
    what: &str,
    bins: SphereBins,
    n: usize,
    mut sample: impl FnMut() -> Option<Vec3>,
    pdf: impl Fn(Vec3) -> f64,
) -> Chi2 {
    use std::f32::consts::PI;
    let (t, p) = (bins.theta, bins.phi);
    let mut observed = vec![0f64; t * p + 1];
    for _ in 0..n {
        let Some(w) = sample() else {
            observed[t * p] += 1.0;
            continue;
        };
        let i = (((w.z + 1.0) * 0.5 * t as f32) as usize).min(t - 1);
        let mut phi = w.y.atan2(w.x);
        if phi < 0.0 {
            phi += 2.0 * PI;
        }
        let j = ((phi / (2.0 * PI) * p as f32) as usize).min(p - 1);
        observed[i * p + j] += 1.0;
    }
    let mut expected = vec![0f64; t * p + 1];
    let dp = 2.0 * std::f64::consts::PI / (p * bins.sub) as f64;
    let mut total = 0.0;
    for row in 0..t {
        let sub = if row == 0 || row == t - 1 { bins.pole_sub } else { bins.sub };
        let dc = 2.0 / (t * sub) as f64;
        for i in 0..sub {
            let c = -1.0 + 2.0 * row as f64 / t as f64 + (i as f64 + 0.5) * dc;
            for j in 0..p * bins.sub {
                let ph = (j as f64 + 0.5) * dp;
                let mass = pdf(direction(c as f32, ph as f32)) * dc * dp;
                expected[row * p + j / bins.sub] += mass * n as f64;
                total += mass;
            }
        }
    }
    expected[t * p] = (1.0 - total).max(0.0) * n as f64;
    pearson(what, &observed, &expected, total)
}

/// Chi-square of `n` points drawn by `sample` in the box `lo`..`hi` against `pdf` (area
/// measure), on `bins`×`bins` bins of `sub`² midpoint cells each.
pub fn plane(
    what: &str,
    (lo, hi): (Vec2, Vec2),
    (bins, sub): (usize, usize),
    n: usize,
    mut sample: impl FnMut() -> Option<Vec2>,
    pdf: impl Fn(Vec2) -> f64,
) -> Chi2 {
    let size = hi - lo;
    let mut observed = vec![0f64; bins * bins + 1];
    for _ in 0..n {
        match sample() {
            Some(q) if q.cmpge(lo).all() && q.cmplt(hi).all() => {
                let f = (q - lo) / size * bins as f32;
                let (i, j) = ((f.y as usize).min(bins - 1), (f.x as usize).min(bins - 1));
                observed[i * bins + j] += 1.0;
            }
            _ => observed[bins * bins] += 1.0,
        }
    }
    let mut expected = vec![0f64; bins * bins + 1];
    let cells = bins * sub;
    let (dx, dy) = (size.x as f64 / cells as f64, size.y as f64 / cells as f64);
    let mut total = 0.0;
    for i in 0..cells {
        for j in 0..cells {
            let q = lo + Vec2::new(((j as f64 + 0.5) * dx) as f32, ((i as f64 + 0.5) * dy) as f32);
            let mass = pdf(q) * dx * dy;
            expected[(i / sub) * bins + j / sub] += mass * n as f64;
            total += mass;
        }
    }
    expected[bins * bins] = (1.0 - total).max(0.0) * n as f64;
    pearson(what, &observed, &expected, total)
}
