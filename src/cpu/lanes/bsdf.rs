//! The base BSDF (`cpu::bsdf`: GGX specular over Lambert, Schlick's Fresnel blended by
//! metallic) in lanes, for "plain" materials: no coat, sheen, anisotropy, iridescence,
//! transmission or diffuse transmission, which covers the bundled scenes' walls, plates and
//! lamps. For those the scalar functions' other branches are provably idle (their lobes have
//! probability 0 and contribute 0), and what remains is computed here with the scalar
//! functions' operations in their order, so each lane holds the reference's bits. Paths on
//! other materials take the scalar functions (`super::trace_paths`).

use super::lane::{F8, M8, V3};
use super::trig::turn;
use crate::cpu::bsdf::has_layers;
use crate::cpu::common::INF;
use crate::cpu::microfacet::DELTA_ALPHA;
use crate::packed::Material;
use glam::Vec3;
use std::f32::consts::{FRAC_1_PI, PI};

/// Can the lanes evaluate and sample this material (see the module's comment)?
#[inline(always)]
pub fn is_plain(m: &Material) -> bool {
    !has_layers(m)
        && m.anisotropy <= 0.0
        && m.iridescence <= 0.0
        && m.transmission == 0.0
        && m.diffuse_transmission <= 0.0
}

/// A plain material per lane, and the BSDF's lobe probabilities from its wo.
#[derive(Clone, Copy, Debug)]
pub struct BaseLanes {
    pub base_color: V3,
    pub metallic: F8,
    pub roughness: F8,
    pub dielectric_f0: V3,
    pub dielectric_f90: F8,
    pub transmission: F8,
    pub diffuse_transmission: F8,
    /// `lobe_probabilities`: specular, diffuse, transmission, diffuse transmission.
    pub p: [F8; 4],
}

impl BaseLanes {
    /// Lane i from the material `m(i)` and the lobe probabilities `p(i)` (lanes without a
    /// material read zeros and are not to be used).
    #[inline(always)]
    pub fn gather<'a>(m: impl Fn(usize) -> Option<&'a Material>, p: impl Fn(usize) -> glam::Vec4) -> BaseLanes {
        let ms: [Option<&Material>; super::LANES] = super::lane::per_lane(m);
        let ps: [glam::Vec4; super::LANES] = super::lane::per_lane(p);
        let f = |get: fn(&Material) -> f32| F8::from_fn(|i| ms[i].map_or(0.0, get));
        let v = |get: fn(&Material) -> [f32; 3]| V3::from_fn(|i| ms[i].map_or(Vec3::ZERO, |m| Vec3::from(get(m))));
        BaseLanes {
            base_color: v(|m| m.base_color),
            metallic: f(|m| m.metallic),
            roughness: f(|m| m.roughness),
            dielectric_f0: v(|m| m.dielectric_f0),
            dielectric_f90: f(|m| m.dielectric_f90),
            transmission: f(|m| m.transmission),
            diffuse_transmission: f(|m| m.diffuse_transmission),
            p: [F8::from_fn(|i| ps[i].x), F8::from_fn(|i| ps[i].y), F8::from_fn(|i| ps[i].z), F8::from_fn(|i| ps[i].w)],
        }
    }
}

#[inline(always)]
pub fn fresnel_schlick(f0: V3, f90: V3, cos_theta: F8) -> V3 {
    let m = (1.0 - cos_theta).clamp(0.0, 1.0);
    let m2 = m * m;
    f0 + (f90 - f0) * (m2 * m2 * m)
}

/// `dielectric_fresnel` without transmission or iridescence: Schlick's.
#[inline(always)]
pub fn dielectric_fresnel(m: &BaseLanes, cos_theta: F8) -> V3 {
    let f90 = m.dielectric_f90;
    fresnel_schlick(m.dielectric_f0, V3::new(f90, f90, f90), cos_theta)
}

/// `bsdf_fresnel` without iridescence.
#[inline(always)]
pub fn bsdf_fresnel(m: &BaseLanes, cos_theta: F8) -> V3 {
    let one = F8::splat(1.0);
    let metal = fresnel_schlick(m.base_color, V3::new(one, one, one), cos_theta);
    let d = dielectric_fresnel(m, cos_theta);
    // glam's lerp: self · (1 − s) + rhs · s.
    d * (1.0 - m.metallic) + metal * m.metallic
}

#[inline(always)]
pub fn diffuse_albedo(m: &BaseLanes, cos_o: F8) -> V3 {
    let f = dielectric_fresnel(m, cos_o);
    let one = F8::splat(1.0);
    (1.0 - m.metallic)
        * (1.0 - m.transmission)
        * (1.0 - m.diffuse_transmission)
        * m.base_color
        * (V3::new(one, one, one) - f)
}

#[inline(always)]
pub fn ggx_d(h: V3, alpha: F8) -> F8 {
    let a2 = alpha * alpha;
    let d = a2 * h.z * h.z + (h.x * h.x + h.y * h.y);
    a2 / (PI * d * d)
}

#[inline(always)]
pub fn ggx_lambda(w: V3, alpha: F8) -> F8 {
    let c2 = w.z * w.z;
    let t2 = (1.0 - c2).max_num(F8::splat(0.0)) / c2;
    let l = 0.5 * ((1.0 + alpha * alpha * t2).sqrt() - 1.0);
    F8::select(c2.le(F8::splat(0.0)), F8::splat(INF), l)
}

#[inline(always)]
pub fn ggx_g1(w: V3, alpha: F8) -> F8 {
    1.0 / (1.0 + ggx_lambda(w, alpha))
}

#[inline(always)]
pub fn ggx_g2(wo: V3, wi: V3, alpha: F8) -> F8 {
    1.0 / (1.0 + ggx_lambda(wo, alpha) + ggx_lambda(wi, alpha))
}

#[inline(always)]
pub fn ggx_reflection_pdf(wo: V3, h: V3, alpha: F8) -> F8 {
    ggx_g1(wo, alpha) * ggx_d(h, alpha) / (4.0 * wo.z)
}

/// `ggx_sample_vndf` with cos φ and sin φ of φ = 2π u2 given (`turn`).
#[inline(always)]
pub fn ggx_sample_vndf(wo: V3, alpha: F8, u1: F8, (cos_phi, sin_phi): (F8, F8)) -> V3 {
    let zero = F8::splat(0.0);
    let vh = V3::new(alpha * wo.x, alpha * wo.y, wo.z).normalize();
    let len2 = vh.x * vh.x + vh.y * vh.y;
    let t1 = V3::select(len2.gt(zero), V3::new(-vh.y, vh.x, zero) / len2.sqrt(), V3::new(F8::splat(1.0), zero, zero));
    let t2 = vh.cross(t1);
    let r = u1.sqrt();
    let p1 = r * cos_phi;
    let s = 0.5 * (1.0 + vh.z);
    let p2 = (1.0 - s) * (1.0 - p1 * p1).max_num(zero).sqrt() + s * r * sin_phi;
    let nh = p1 * t1 + p2 * t2 + (1.0 - p1 * p1 - p2 * p2).max_num(zero).sqrt() * vh;
    V3::new(alpha * nh.x, alpha * nh.y, nh.z.max_num(F8::splat(1e-7))).normalize()
}

/// `sample_cosine_hemisphere` with cos φ and sin φ of φ = 2π u2 given (`turn`).
#[inline(always)]
pub fn sample_cosine_hemisphere(u1: F8, (cos_phi, sin_phi): (F8, F8)) -> V3 {
    let r = u1.sqrt();
    V3::new(r * cos_phi, r * sin_phi, (1.0 - u1).max_num(F8::splat(0.0)).sqrt())
}

#[inline(always)]
pub fn cosine_hemisphere_pdf(cos_theta: F8) -> F8 {
    cos_theta.max_num(F8::splat(0.0)) * FRAC_1_PI
}

/// `base_eval` of a plain material.
#[inline(always)]
pub fn base_eval(m: &BaseLanes, wo: V3, wi: V3) -> V3 {
    let zero = F8::splat(0.0);
    let alpha = m.roughness * m.roughness;
    let mut f = diffuse_albedo(m, wo.z) * F8::splat(FRAC_1_PI);
    let h = (wo + wi).normalize();
    let spec = ggx_d(h, alpha) * ggx_g2(wo, wi, alpha) / (4.0 * wo.z * wi.z);
    f = V3::select(alpha.ge(F8::splat(DELTA_ALPHA)), f + bsdf_fresnel(m, wo.dot(h)) * spec, f);
    // Below the surface a plain material has no lobe (f = 0 · 1/π exactly).
    let none = wo.z.le(zero) | wi.z.eq(zero) | wi.z.lt(zero);
    V3::select(none, V3::new(zero, zero, zero), f)
}

/// `base_pdf_chosen` of a plain material (its transmission lobe has probability ≤ 0).
#[inline(always)]
pub fn base_pdf(m: &BaseLanes, wo: V3, wi: V3) -> F8 {
    let zero = F8::splat(0.0);
    let [px, py, _, pw] = m.p;
    let alpha = m.roughness * m.roughness;
    let below = pw * cosine_hemisphere_pdf(-wi.z);
    let mut above = py * cosine_hemisphere_pdf(wi.z);
    let spec = px * ggx_reflection_pdf(wo, (wo + wi).normalize(), alpha);
    above = F8::select(alpha.ge(F8::splat(DELTA_ALPHA)) & px.gt(zero), above + spec, above);
    let pdf = F8::select(wi.z.lt(zero), below, above);
    F8::select(wo.z.le(zero) | wi.z.eq(zero), zero, pdf)
}

/// `base_sample_chosen` of a plain material, in lanes: direction, weight, density, Dirac.
#[derive(Clone, Copy, Debug)]
pub struct SampleLanes {
    pub wi: V3,
    pub weight: V3,
    pub pdf: F8,
    pub delta: M8,
}

/// `base_sample_chosen` of a plain material.
#[inline(always)]
pub fn base_sample(m: &BaseLanes, wo: V3, u: V3) -> SampleLanes {
    let zero = F8::splat(0.0);
    let one = F8::splat(1.0);
    let [px, py, _, pw] = m.p;
    let alpha = m.roughness * m.roughness;
    let rough = alpha.ge(F8::splat(DELTA_ALPHA));
    // The specular lobe: a mirror, or a visible normal and its reflection.
    let turn = turn(u.z);
    let h = ggx_sample_vndf(wo, alpha, u.y, turn);
    let reflected = 2.0 * wo.dot(h) * h - wo;
    // The diffuse lobe, and (probability 0 here) its mirror image below.
    let c = sample_cosine_hemisphere(u.y, turn);
    let specular = u.x.lt(px);
    let diffuse = !specular & u.x.lt(px + py);
    let diffuse_below = !specular & !diffuse & u.x.lt(px + py + pw);
    let wi = V3::select(specular, reflected, V3::select(diffuse_below, V3::new(c.x, c.y, -c.z), c));
    let pdf = base_pdf(m, wo, wi);
    let weight = base_eval(m, wo, wi) * (wi.z.abs() / pdf);
    // The mirror's sample.
    let mirror = specular & !rough;
    let mirror_wi = V3::new(-wo.x, -wo.y, wo.z);
    let mirror_weight = bsdf_fresnel(m, wo.z) / px;
    // Nothing: wo below, a reflection below the surface, the transmission lobe (never a
    // plain material's, but where u falls past the others), no density.
    let lobe_missed = !specular & !diffuse & !diffuse_below;
    let none =
        wo.z.le(zero) | (!mirror & ((specular & reflected.z.le(zero)) | lobe_missed | wi.z.eq(zero) | pdf.le(zero)));
    let zero3 = V3::new(zero, zero, zero);
    SampleLanes {
        wi: V3::select(none, V3::new(zero, zero, one), V3::select(mirror, mirror_wi, wi)),
        weight: V3::select(none, zero3, V3::select(mirror, mirror_weight, weight)),
        pdf: F8::select(none, zero, F8::select(mirror, px, pdf)),
        delta: !none & mirror,
    }
}
