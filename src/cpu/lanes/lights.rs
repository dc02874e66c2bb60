//! `sample_light_chosen` in lanes for the common case: an emissive triangle without an
//! emission texture, chosen by the light tree (walks already taken) or the power sampler,
//! then sampled in the solid angle it subtends (`spherical_triangle.rs`, with the receiver
//! cosine warp) or by area — every operation the scalar one lane by lane, the arc tangent,
//! sine and cosine the polynomials of `cpu::trig` in lanes. Lanes that pick the environment or a
//! punctual light, or whose selection has no probability, take the scalar function.

use super::lane::{F8, M8, V3};
use super::trig::{atan2, bounded_cos, bounded_sin};
use super::{LANES, lanes_of};
use crate::cpu::common::{INF, ONE_MINUS_EPSILON};
use crate::cpu::light_tree::LightContext;
use crate::cpu::lights::{LightSample, light_entry, sample_light_chosen};
use crate::cpu::spherical_triangle::{SOLID_ANGLE_MAX, SOLID_ANGLE_MIN};
use crate::packed::{NO_TEXTURE, PackedScene};
use crate::params::{LIGHT_SAMPLER_TREE, Params};
use glam::Vec3;

/// Light samples in lanes (`LightSample`'s fields).
#[derive(Clone, Copy, Debug)]
pub struct LightSampleLanes {
    pub wi: V3,
    pub dist: F8,
    pub point: V3,
    pub normal: V3,
    pub radiance: V3,
    pub pdf: F8,
    pub delta: M8,
}

impl LightSampleLanes {
    #[inline(always)]
    pub fn lane(&self, i: usize) -> LightSample {
        LightSample {
            wi: self.wi.lane(i),
            dist: self.dist.0[i],
            point: self.point.lane(i),
            normal: self.normal.lane(i),
            radiance: self.radiance.lane(i),
            pdf: self.pdf.0[i],
            delta: self.delta.lane(i),
        }
    }

    /// No sample in any lane.
    #[inline(always)]
    pub fn zero() -> LightSampleLanes {
        let (zero, none) = (F8::splat(0.0), V3::splat(Vec3::ZERO));
        LightSampleLanes {
            wi: none,
            dist: zero,
            point: none,
            normal: none,
            radiance: none,
            pdf: zero,
            delta: M8::splat(false),
        }
    }

    /// `a` in the lanes of `m`, else `b`.
    #[inline(always)]
    pub fn select(m: M8, a: &LightSampleLanes, b: &LightSampleLanes) -> LightSampleLanes {
        LightSampleLanes {
            wi: V3::select(m, a.wi, b.wi),
            dist: F8::select(m, a.dist, b.dist),
            point: V3::select(m, a.point, b.point),
            normal: V3::select(m, a.normal, b.normal),
            radiance: V3::select(m, a.radiance, b.radiance),
            pdf: F8::select(m, a.pdf, b.pdf),
            delta: (m & a.delta) | (!m & b.delta),
        }
    }

    #[inline(always)]
    fn set_lane(&mut self, i: usize, s: &LightSample) {
        self.wi.set_lane(i, s.wi);
        self.dist.0[i] = s.dist;
        self.point.set_lane(i, s.point);
        self.normal.set_lane(i, s.normal);
        self.radiance.set_lane(i, s.radiance);
        self.pdf.0[i] = s.pdf;
        self.delta.set_lane(i, s.delta);
    }
}

/// `receiver_cosine_weights`' cosine at triangle vertex `v` seen from `ref_point` with normal
/// `n`. A function, not a closure: a closure the compiler leaves out of line is compiled
/// without AVX, and its lane operations become calls (BENCHMARKS.md session 35).
#[inline(always)]
fn receiver_cosine(n: V3, ref_point: V3, v: V3) -> F8 {
    n.dot(normalize_or_zero(v - ref_point)).abs().max_num(F8::splat(0.01))
}

/// glam's `normalize_or_zero`: v / |v| when 1 / |v| is finite and positive, else 0.
#[inline(always)]
fn normalize_or_zero(v: V3) -> V3 {
    let rcp = 1.0 / v.dot(v).sqrt();
    // Finite and positive (NaN fails both).
    let ok = rcp.gt(F8::splat(0.0)) & rcp.lt(F8::splat(f32::INFINITY));
    V3::select(ok, v * rcp, V3::splat(Vec3::ZERO))
}

/// `angle_between` of unit vectors.
#[inline(always)]
fn angle_between(a: V3, b: V3) -> F8 {
    2.0 * atan2((a - b).dot(a - b).sqrt(), (a + b).dot(a + b).sqrt())
}

#[inline(always)]
fn orthonormal_part(v: V3, w: V3) -> V3 {
    normalize_or_zero(v - w * v.dot(w))
}

/// `unit_triangle_area`.
#[inline(always)]
fn unit_triangle_area(a: V3, b: V3, c: V3) -> F8 {
    (2.0 * atan2(a.dot(b.cross(c)), 1.0 + a.dot(b) + a.dot(c) + b.dot(c))).abs()
}

/// `triangle_solid_angle` of the triangles (p0, e1, e2) from `p` in the lanes of `mask` (0
/// in the others).
#[inline(always)]
fn triangle_solid_angle(p: V3, p0: V3, e1: V3, e2: V3, mask: u32) -> F8 {
    let zero = F8::splat(0.0);
    // surely_below_solid_angle_min
    let c = p0 + (e1 + e2) * F8::splat(1.0 / 3.0);
    let l2 = |v: V3| v.dot(v);
    let r2 = l2(p0 - c).max_num(l2(p0 + e1 - c)).max_num(l2(p0 + e2 - c));
    let d2 = l2(p - c);
    let gap = d2.sqrt() - r2.sqrt();
    let side = e1.cross(e2).dot(p - p0);
    let surely_below = (6.35 * r2).lt(SOLID_ANGLE_MIN * d2)
        | (gap.gt(zero) & (0.55 * side.abs()).lt(SOLID_ANGLE_MIN * (gap * gap * gap)));
    let behind = side.le(zero);
    let skip = behind | surely_below | !M8::from_bits(mask);
    if skip.bits() == M8::splat(true).bits() {
        // Every lane takes the scalar's early return (the common case far from a lamp).
        return zero;
    }
    let (a, b, cc) = (normalize_or_zero(p0 - p), normalize_or_zero(p0 + e1 - p), normalize_or_zero(p0 + e2 - p));
    let omega = unit_triangle_area(a, b, cc);
    let inside = omega.ge(F8::splat(SOLID_ANGLE_MIN)) & omega.le(F8::splat(SOLID_ANGLE_MAX));
    F8::select(skip | !inside, zero, omega)
}

/// `sample_linear`.
#[inline(always)]
fn sample_linear(u: F8, a: F8, b: F8) -> F8 {
    let zero = F8::splat(0.0);
    let x = u * (a + b) / (a + ((1.0 - u) * a * a + u * b * b).sqrt());
    F8::select(u.eq(zero) & a.eq(zero), zero, x.min_num(F8::splat(ONE_MINUS_EPSILON)))
}

/// `bilinear_pdf`.
#[inline(always)]
fn bilinear_pdf(x: F8, y: F8, w: &[F8; 4]) -> F8 {
    let zero = F8::splat(0.0);
    let outside = x.lt(zero) | x.gt(F8::splat(1.0)) | y.lt(zero) | y.gt(F8::splat(1.0));
    let sum = w[0] + w[1] + w[2] + w[3];
    let pdf = 4.0 * ((1.0 - x) * (1.0 - y) * w[0] + x * (1.0 - y) * w[1] + (1.0 - x) * y * w[2] + x * y * w[3]) / sum;
    F8::select(outside, zero, F8::select(sum.eq(zero), F8::splat(1.0), pdf))
}

/// `sample_spherical_triangle`: the direction, and the lanes where there is none.
#[inline(always)]
fn sample_spherical_triangle(p: V3, v0: V3, v1: V3, v2: V3, u0: F8, u1: F8) -> (V3, M8) {
    let zero = F8::splat(0.0);
    let a = normalize_or_zero(v0 - p);
    let b = normalize_or_zero(v1 - p);
    let c = normalize_or_zero(v2 - p);
    let (n_ab, n_bc, n_ca) = (a.cross(b), b.cross(c), c.cross(a));
    let degenerate = n_ab.dot(n_ab).eq(zero) | n_bc.dot(n_bc).eq(zero) | n_ca.dot(n_ca).eq(zero);
    let (n_ab, n_ca) = (n_ab.normalize(), n_ca.normalize());
    let alpha = angle_between(n_ab, -n_ca);
    let area = unit_triangle_area(a, b, c);
    let no_area = !area.gt(zero);
    let ap = u0 * area;
    let d = ap - alpha;
    let (sin_phi, cos_phi) = (-bounded_sin(d), -bounded_cos(d));
    let (sin_alpha, cos_alpha) = (bounded_sin(alpha), bounded_cos(alpha));
    let k1 = cos_phi + cos_alpha;
    let k2 = sin_phi - sin_alpha * a.dot(b);
    let cos_bp = ((k2 + (k2 * cos_phi - k1 * sin_phi) * cos_alpha) / ((k2 * sin_phi + k1 * cos_phi) * sin_alpha))
        .clamp(-1.0, 1.0);
    let nan = !cos_bp.eq(cos_bp);
    let sin_bp = (1.0 - cos_bp * cos_bp).max_num(zero).sqrt();
    let cp = cos_bp * a + sin_bp * orthonormal_part(c, a);
    let cos_theta = 1.0 - u1 * 0.5 * (cp - b).dot(cp - b);
    let sin_theta = (1.0 - cos_theta * cos_theta).max_num(zero).sqrt();
    let w = cos_theta * b + sin_theta * orthonormal_part(cp, b);
    let finite = |x: F8| x.abs().lt(F8::splat(f32::INFINITY));
    let infinite = !(finite(w.x) & finite(w.y) & finite(w.z));
    (w.normalize(), degenerate | no_area | nan | infinite)
}

/// `barycentrics`.
#[inline(always)]
fn barycentrics(v: V3, e1: V3, e2: V3) -> (F8, F8) {
    let (d00, d01, d11) = (e1.dot(e1), e1.dot(e2), e2.dot(e2));
    let (d20, d21) = (v.dot(e1), v.dot(e2));
    let denom = d00 * d11 - d01 * d01;
    let b1 = ((d11 * d20 - d01 * d21) / denom).clamp(0.0, 1.0);
    let b2 = ((d00 * d21 - d01 * d20) / denom).clamp(0.0, 1.0);
    let s = b1 + b2;
    let over = s.gt(F8::splat(1.0));
    (F8::select(over, b1 / s, b1), F8::select(over, b2 / s, b2))
}

/// `sample_light_chosen` from the contexts `ctx` with numbers `u` and the tree's `walks`, in
/// the lanes of `mask`.
#[inline(always)]
pub fn sample_lights(
    scene: &PackedScene,
    params: &Params,
    ctx: &[LightContext; LANES],
    u: (F8, F8, F8),
    walks: &[(u32, f32); LANES],
    mask: u32,
) -> LightSampleLanes {
    let zero = F8::splat(0.0);
    let env_select = params.env_select;
    let tree = params.light_sampler == LIGHT_SAMPLER_TREE;
    // The triangle each lane samples (and its selection probability), or the scalar path.
    let mut triangle = [0u32; LANES];
    let mut select_pmf = [0.0f32; LANES];
    let mut lanes = 0u32;
    for i in lanes_of(mask) {
        let ux = u.0.0[i];
        if ux < env_select {
            continue;
        }
        let t = if tree {
            let (emitter, pmf) = walks[i];
            let pmf = (1.0 - env_select) * pmf;
            if pmf <= 0.0 || emitter >= params.light_count {
                continue;
            }
            select_pmf[i] = pmf;
            light_entry(scene, emitter).triangle
        } else {
            let u_select = (ux - env_select) / (1.0 - env_select);
            let n = params.light_count;
            let scaled = u_select * n as f32;
            let slot = (scaled as u32).min(n - 1);
            let mut entry = light_entry(scene, slot);
            if scaled - slot as f32 >= entry.prob {
                entry = light_entry(scene, entry.alias_slot);
            }
            entry.triangle
        };
        let tri = &scene.triangles[t as usize];
        if scene.materials[tri.material as usize].emissive_texture.atlas != NO_TEXTURE {
            continue;
        }
        triangle[i] = t;
        lanes |= 1 << i;
    }
    let tri = |i: usize| &scene.triangles[triangle[i] as usize];
    let p0 = V3::from_fn(|i| Vec3::from(tri(i).p0));
    let e1 = V3::from_fn(|i| Vec3::from(tri(i).e1));
    let e2 = V3::from_fn(|i| Vec3::from(tri(i).e2));
    let radiance = V3::from_fn(|i| Vec3::from(scene.materials[tri(i).material as usize].emission));
    let ref_point = V3::from_fn(|i| ctx[i].point);
    let normal = e1.cross(e2).normalize();
    let omega = if tree { triangle_solid_angle(ref_point, p0, e1, e2, lanes) } else { zero };
    let spherical = lanes & omega.gt(zero).bits();
    let by_area = lanes & !spherical;
    let mut out = LightSampleLanes {
        wi: normal,
        dist: F8::splat(INF),
        point: ref_point,
        normal,
        radiance: V3::splat(Vec3::ZERO),
        pdf: zero,
        delta: M8::splat(false),
    };
    if spherical != 0 {
        // receiver_cosine_weights
        let n = V3::from_fn(|i| ctx[i].normal);
        let c0 = receiver_cosine(n, ref_point, p0);
        let c1 = receiver_cosine(n, ref_point, p0 + e1);
        let c2 = receiver_cosine(n, ref_point, p0 + e2);
        let weights = [c1, c1, c0, c2];
        // sample_bilinear
        let y = sample_linear(u.2, weights[0] + weights[1], weights[2] + weights[3]);
        let x = sample_linear(u.1, (1.0 - y) * weights[0] + y * weights[2], (1.0 - y) * weights[1] + y * weights[3]);
        let warp_pdf = bilinear_pdf(x, y, &weights);
        let (w, none) = sample_spherical_triangle(ref_point, p0, p0 + e1, p0 + e2, x, y);
        let t = (p0 - ref_point).dot(normal) / w.dot(normal);
        let (b1, b2) = barycentrics(ref_point + t * w - p0, e1, e2);
        let point = p0 + b1 * e1 + b2 * e2;
        let to_light = point - ref_point;
        let dist = to_light.dot(to_light).sqrt();
        let wi = to_light / dist;
        let pmf = F8(select_pmf);
        let pdf = F8::select(t.gt(zero) & dist.gt(zero), pmf * warp_pdf / omega, zero);
        let got = M8::from_bits(spherical) & !none;
        out.wi = V3::select(got, wi, out.wi);
        out.dist = F8::select(got, dist, out.dist);
        out.point = V3::select(got, point, out.point);
        out.radiance = V3::select(got, radiance, out.radiance);
        out.pdf = F8::select(got, pdf, out.pdf);
    }
    if by_area != 0 {
        // sample_uniform_triangle
        let su = u.1.sqrt();
        let (b1, b2) = (1.0 - su, u.2 * su);
        let point = p0 + b1 * e1 + b2 * e2;
        let to_light = point - ref_point;
        let dist2 = to_light.dot(to_light);
        let dist = dist2.sqrt();
        let wi = to_light / dist;
        let cos_light = -wi.dot(normal);
        let pdf = if tree {
            let area = 0.5 * e1.cross(e2).dot(e1.cross(e2)).sqrt();
            F8(select_pmf) * dist2 / (cos_light * area)
        } else {
            let pdf_area = F8::from_fn(|i| tri(i).light_pdf_area);
            (1.0 - env_select) * pdf_area * dist2 / cos_light
        };
        let pdf = F8::select(cos_light.le(zero) | dist2.le(zero), zero, pdf);
        let got = M8::from_bits(by_area);
        out.wi = V3::select(got, wi, out.wi);
        out.dist = F8::select(got, dist, out.dist);
        out.point = V3::select(got, point, out.point);
        out.radiance = V3::select(got, radiance, out.radiance);
        out.pdf = F8::select(got, pdf, out.pdf);
    }
    for i in lanes_of(mask & !lanes) {
        let ls = sample_light_chosen(scene, params, &ctx[i], Vec3::new(u.0.0[i], u.1.0[i], u.2.0[i]), walks[i]);
        out.set_lane(i, &ls);
    }
    out
}
