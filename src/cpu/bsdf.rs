//! Twin of `shaders/bsdf.wgsl`: glTF metallic-roughness (GGX specular over Lambert and GGX
//! transmission, with KHR_materials_diffuse_transmission's Lambertian lobe through the surface),
//! under KHR_materials_sheen's sheen and KHR_materials_clearcoat's coat.

use super::clearcoat::{coat_alpha, coat_eval, coat_pdf, coat_sample, coat_weight};
use super::common::luminance;
use super::iridescence::iridescence_fresnel;
use super::microfacet::{
    ggx_d, ggx_d_aniso, ggx_g1, ggx_g2, ggx_g2_aniso, ggx_reflection_pdf, ggx_reflection_pdf_aniso, ggx_sample_vndf,
    ggx_sample_vndf_aniso,
};
use super::sampling::{
    UNIFORM_HEMISPHERE_PDF, cosine_hemisphere_pdf, sample_cosine_hemisphere, sample_uniform_hemisphere,
};
use crate::packed::{MAT_THIN_WALLED, Material};
use crate::sheen::{sheen_albedo, sheen_albedo_scaling, sheen_brdf};
use glam::{Vec2, Vec3, Vec4};
use std::f32::consts::FRAC_1_PI;

pub use super::microfacet::DELTA_ALPHA;

#[derive(Clone, Copy, Debug)]
pub struct BsdfSample {
    pub wi: Vec3,
    pub weight: Vec3,
    pub pdf: f32,
    pub delta: bool,
}

#[inline]
pub fn fresnel_schlick(f0: Vec3, f90: Vec3, cos_theta: f32) -> Vec3 {
    let m = (1.0 - cos_theta).clamp(0.0, 1.0);
    let m2 = m * m;
    f0 + (f90 - f0) * (m2 * m2 * m)
}

#[inline]
pub fn fresnel_dielectric(cos_i: f32, eta: f32) -> f32 {
    let c = cos_i.clamp(0.0, 1.0);
    let sin2_t = (1.0 - c * c) / (eta * eta);
    if sin2_t >= 1.0 {
        return 1.0;
    }
    let cos_t = (1.0 - sin2_t).sqrt();
    let r_parl = (eta * c - cos_t) / (eta * c + cos_t);
    let r_perp = (c - eta * cos_t) / (c + eta * cos_t);
    0.5 * (r_parl * r_parl + r_perp * r_perp)
}

#[inline]
pub fn dielectric_fresnel(m: &Material, cos_theta: f32, eta: f32) -> Vec3 {
    let f = if m.transmission > 0.0 {
        Vec3::splat(fresnel_dielectric(cos_theta, eta))
    } else {
        fresnel_schlick(m.dielectric_f0.into(), Vec3::splat(m.dielectric_f90), cos_theta)
    };
    if m.iridescence <= 0.0 {
        return f;
    }
    f.lerp(thin_film(m, cos_theta, m.dielectric_f0.into()), m.iridescence)
}

/// KHR_materials_iridescence's film over a base of normal reflectance `base_f0`.
#[inline]
pub fn thin_film(m: &Material, cos_theta: f32, base_f0: Vec3) -> Vec3 {
    iridescence_fresnel(1.0, m.iridescence_ior, cos_theta, m.iridescence_thickness_max, base_f0)
}

#[inline]
pub fn bsdf_fresnel(m: &Material, cos_theta: f32, eta: f32) -> Vec3 {
    let mut metal = fresnel_schlick(m.base_color.into(), Vec3::ONE, cos_theta);
    if m.iridescence > 0.0 && m.metallic > 0.0 {
        metal = metal.lerp(thin_film(m, cos_theta, m.base_color.into()), m.iridescence);
    }
    dielectric_fresnel(m, cos_theta, eta).lerp(metal, m.metallic)
}

#[inline]
pub fn diffuse_albedo(m: &Material, cos_o: f32, eta: f32) -> Vec3 {
    let f = dielectric_fresnel(m, cos_o, eta);
    (1.0 - m.metallic)
        * (1.0 - m.transmission)
        * (1.0 - m.diffuse_transmission)
        * Vec3::from(m.base_color)
        * (Vec3::ONE - f)
}

/// KHR_materials_diffuse_transmission's share of the Lambertian lobe: the same lobe mirrored
/// to the other side, in its own colour.
#[inline]
pub fn diffuse_transmission_albedo(m: &Material, cos_o: f32, eta: f32) -> Vec3 {
    if m.diffuse_transmission <= 0.0 {
        return Vec3::ZERO;
    }
    let f = dielectric_fresnel(m, cos_o, eta);
    (1.0 - m.metallic)
        * (1.0 - m.transmission)
        * m.diffuse_transmission
        * Vec3::from(m.diffuse_transmission_color)
        * (Vec3::ONE - f)
}

#[inline]
pub fn transmission_albedo(m: &Material, cos_o: f32, eta: f32) -> Vec3 {
    let f = dielectric_fresnel(m, cos_o, eta);
    (1.0 - m.metallic) * m.transmission * Vec3::from(m.base_color) * (Vec3::ONE - f)
}

/// Weights of the specular, diffuse, transmission and diffuse-transmission lobes.
#[inline]
pub fn lobe_weights(m: &Material, cos_o: f32, eta: f32) -> Vec4 {
    let mut wt = luminance(transmission_albedo(m, cos_o, eta));
    if transmission_is_rough(m, m.roughness * m.roughness, eta) {
        wt = wt.max(0.1 * (1.0 - m.metallic) * m.transmission * luminance(m.base_color.into()));
    }
    Vec4::new(
        luminance(bsdf_fresnel(m, cos_o, eta)),
        luminance(diffuse_albedo(m, cos_o, eta)),
        wt,
        luminance(diffuse_transmission_albedo(m, cos_o, eta)),
    )
}

#[inline]
pub fn lobe_probabilities(m: &Material, cos_o: f32, eta: f32) -> Vec4 {
    let w = lobe_weights(m, cos_o, eta);
    let total = w.x + w.y + w.z + w.w;
    if total <= 0.0 {
        return Vec4::ZERO;
    }
    w / total
}

/// Is the transmission lobe a GGX lobe (else a Dirac one)? A refracting microfacet tilted by θm
/// turns the ray by about |1 − 1/η|·θm, so the lobe is α·|1 − 1/η| wide: at η = 1 light passes
/// straight through whatever the roughness (and ωo + η ωi, the half vector, vanishes), and near
/// it the lobe is narrower than a mirror's and the half vector ill-conditioned. Thin walls
/// transmit a reflection, whose width is α's.
#[inline]
pub fn transmission_is_rough(m: &Material, alpha: f32, eta: f32) -> bool {
    if m.flags & MAT_THIN_WALLED != 0 {
        return alpha >= DELTA_ALPHA;
    }
    alpha * (1.0 - 1.0 / eta).abs() >= DELTA_ALPHA
}

pub fn refraction_half_vector(wo: Vec3, wi: Vec3, eta: f32) -> Vec4 {
    let h = wi * eta + wo;
    let len2 = h.dot(h);
    if len2 <= 0.0 {
        return Vec4::ZERO;
    }
    let mut h = h / len2.sqrt();
    if h.z < 0.0 {
        h = -h;
    }
    if h.dot(wo) <= 0.0 || h.dot(wi) >= 0.0 {
        return Vec4::ZERO;
    }
    let d = wi.dot(h) + wo.dot(h) / eta;
    h.extend(d * d)
}

/// KHR_materials_anisotropy's roughness along and across its direction: the extension's
/// α_t = mix(α, 1, strength²), α_b = α (at least DELTA_ALPHA: a mirror stretched along the
/// tangent is rough along it and nearly smooth across).
#[inline]
pub fn anisotropy_alphas(m: &Material, alpha: f32) -> Vec2 {
    Vec2::new(alpha + (1.0 - alpha) * m.anisotropy * m.anisotropy, alpha.max(DELTA_ALPHA))
}

/// Is the specular lobe a GGX lobe (else a mirror)? An anisotropic one is as soon as its
/// long axis is rough.
#[inline]
pub fn specular_is_rough(m: &Material, alpha: f32) -> bool {
    alpha >= DELTA_ALPHA || (m.anisotropy > 0.0 && anisotropy_alphas(m, alpha).x >= DELTA_ALPHA)
}

/// Local frame → the frame whose x is the anisotropy direction (a turn about the normal).
#[inline]
pub fn to_anisotropy(m: &Material, w: Vec3) -> Vec3 {
    let t = Vec2::from(m.anisotropy_tangent);
    Vec3::new(t.x * w.x + t.y * w.y, -t.y * w.x + t.x * w.y, w.z)
}

#[inline]
pub fn from_anisotropy(m: &Material, w: Vec3) -> Vec3 {
    let t = Vec2::from(m.anisotropy_tangent);
    Vec3::new(t.x * w.x - t.y * w.y, t.y * w.x + t.x * w.y, w.z)
}

/// The specular lobe's D·G2/(4 cos θo cos θi), isotropic or anisotropic.
#[inline]
pub fn specular_brdf(m: &Material, wo: Vec3, wi: Vec3, h: Vec3, alpha: f32) -> f32 {
    if m.anisotropy <= 0.0 {
        return ggx_d(h, alpha) * ggx_g2(wo, wi, alpha) / (4.0 * wo.z * wi.z);
    }
    let a = anisotropy_alphas(m, alpha);
    let (o, i, h) = (to_anisotropy(m, wo), to_anisotropy(m, wi), to_anisotropy(m, h));
    ggx_d_aniso(h, a.x, a.y) * ggx_g2_aniso(o, i, a.x, a.y) / (4.0 * wo.z * wi.z)
}

#[inline]
pub fn specular_pdf(m: &Material, wo: Vec3, h: Vec3, alpha: f32) -> f32 {
    if m.anisotropy <= 0.0 {
        return ggx_reflection_pdf(wo, h, alpha);
    }
    let a = anisotropy_alphas(m, alpha);
    ggx_reflection_pdf_aniso(to_anisotropy(m, wo), to_anisotropy(m, h), a.x, a.y)
}

#[inline]
pub fn sample_specular_normal(m: &Material, wo: Vec3, alpha: f32, u: Vec2) -> Vec3 {
    if m.anisotropy <= 0.0 {
        return ggx_sample_vndf(wo, alpha, u);
    }
    let a = anisotropy_alphas(m, alpha);
    from_anisotropy(m, ggx_sample_vndf_aniso(to_anisotropy(m, wo), a.x, a.y, u))
}

/// Thin-walled transmission continues a microfacet reflection through the sheet: the
/// reflected direction mirrored in the tangent plane (and back).
#[inline]
pub fn thin_reflection(w: Vec3) -> Vec3 {
    Vec3::new(w.x, w.y, -w.z)
}

pub fn refract_dir(wo: Vec3, n: Vec3, eta: f32) -> Vec4 {
    let cos_i = n.dot(wo);
    let sin2_t = (1.0 - cos_i * cos_i).max(0.0) / (eta * eta);
    if sin2_t >= 1.0 {
        return Vec4::ZERO;
    }
    let cos_t = (1.0 - sin2_t).sqrt();
    (-wo / eta + (cos_i / eta - cos_t) * n).extend(1.0)
}

/// The rough transmission lobe's f (wi.z < 0; thin walls pass a reflection through the sheet).
pub fn specular_transmission_eval(m: &Material, wo: Vec3, wi: Vec3, eta: f32, alpha: f32) -> Vec3 {
    if m.flags & MAT_THIN_WALLED != 0 {
        let r = thin_reflection(wi);
        let h = (wo + r).normalize();
        let f = fresnel_dielectric(wo.dot(h), eta);
        let ft = ggx_d(h, alpha) * ggx_g2(wo, r, alpha) * (1.0 - f) / (4.0 * wo.z * r.z);
        return (1.0 - m.metallic) * m.transmission * Vec3::from(m.base_color) * ft;
    }
    let hd = refraction_half_vector(wo, wi, eta);
    if hd.w <= 0.0 {
        return Vec3::ZERO;
    }
    let h = hd.truncate();
    let f = fresnel_dielectric(wo.dot(h), eta);
    let ft = ggx_d(h, alpha) * ggx_g2(wo, wi, alpha) * (1.0 - f) * (wi.dot(h) * wo.dot(h) / (wi.z * wo.z * hd.w)).abs()
        / (eta * eta);
    (1.0 - m.metallic) * m.transmission * Vec3::from(m.base_color) * ft
}

pub fn base_eval(m: &Material, wo: Vec3, wi: Vec3, eta: f32) -> Vec3 {
    let alpha = m.roughness * m.roughness;
    if wo.z <= 0.0 || wi.z == 0.0 {
        return Vec3::ZERO;
    }
    if wi.z < 0.0 {
        let mut f = diffuse_transmission_albedo(m, wo.z, eta) * FRAC_1_PI;
        if m.transmission > 0.0 && transmission_is_rough(m, alpha, eta) {
            f += specular_transmission_eval(m, wo, wi, eta, alpha);
        }
        return f;
    }
    let mut f = diffuse_albedo(m, wo.z, eta) * FRAC_1_PI;
    if specular_is_rough(m, alpha) {
        let h = (wo + wi).normalize();
        let spec = specular_brdf(m, wo, wi, h, alpha);
        f += bsdf_fresnel(m, wo.dot(h), eta) * spec;
    }
    f
}

/// The rough transmission lobe's density of wi (wi.z < 0) times `p_lobe`, the probability
/// of choosing the lobe (multiplied first, as the films recorded before the lobe had a function
/// of its own were computed).
/// Did the BSDF sample `wi` (local) cross a dielectric interface, its weight scaled by 1/η²
/// (`specular_transmission_eval` and the smooth refraction in `base_sample`)? A thin wall's
/// transmission and diffuse transmission are not. Russian roulette divides the factor out.
#[inline(always)]
pub fn refracted(m: &Material, wi: Vec3) -> bool {
    wi.z < 0.0 && m.transmission > 0.0 && m.flags & MAT_THIN_WALLED == 0
}

pub fn specular_transmission_pdf(m: &Material, wo: Vec3, wi: Vec3, eta: f32, alpha: f32, p_lobe: f32) -> f32 {
    if m.flags & MAT_THIN_WALLED != 0 {
        let r = thin_reflection(wi);
        return p_lobe * ggx_reflection_pdf(wo, (wo + r).normalize(), alpha);
    }
    let hd = refraction_half_vector(wo, wi, eta);
    if hd.w <= 0.0 {
        return 0.0;
    }
    let h = hd.truncate();
    let d_wo = ggx_g1(wo, alpha) * ggx_d(h, alpha) * wo.dot(h) / wo.z;
    p_lobe * d_wo * wi.dot(h).abs() / hd.w
}

pub fn base_pdf(m: &Material, wo: Vec3, wi: Vec3, eta: f32) -> f32 {
    base_pdf_chosen(m, lobe_probabilities(m, wo.z, eta), wo, wi, eta)
}

/// `base_pdf` with the lobe probabilities `p` from wo already known.
#[inline]
pub fn base_pdf_chosen(m: &Material, p: Vec4, wo: Vec3, wi: Vec3, eta: f32) -> f32 {
    if wo.z <= 0.0 || wi.z == 0.0 {
        return 0.0;
    }
    let alpha = m.roughness * m.roughness;
    if wi.z < 0.0 {
        let mut pdf = p.w * cosine_hemisphere_pdf(-wi.z);
        if p.z > 0.0 && transmission_is_rough(m, alpha, eta) {
            pdf += specular_transmission_pdf(m, wo, wi, eta, alpha, p.z);
        }
        return pdf;
    }
    let mut pdf = p.y * cosine_hemisphere_pdf(wi.z);
    if specular_is_rough(m, alpha) && p.x > 0.0 {
        pdf += p.x * specular_pdf(m, wo, (wo + wi).normalize(), alpha);
    }
    pdf
}

pub fn base_sample(m: &Material, wo: Vec3, u: Vec3, eta: f32) -> BsdfSample {
    base_sample_chosen(m, lobe_probabilities(m, wo.z, eta), wo, u, eta)
}

/// `base_sample` with the lobe probabilities `p` from wo already known.
#[inline]
pub fn base_sample_chosen(m: &Material, p: Vec4, wo: Vec3, u: Vec3, eta: f32) -> BsdfSample {
    let none = BsdfSample { wi: Vec3::Z, weight: Vec3::ZERO, pdf: 0.0, delta: false };
    if wo.z <= 0.0 {
        return none;
    }
    let alpha = m.roughness * m.roughness;
    let wi = if u.x < p.x {
        if !specular_is_rough(m, alpha) {
            let mirror = Vec3::new(-wo.x, -wo.y, wo.z);
            return BsdfSample { wi: mirror, weight: bsdf_fresnel(m, wo.z, eta) / p.x, pdf: p.x, delta: true };
        }
        let h = sample_specular_normal(m, wo, alpha, Vec2::new(u.y, u.z));
        let wi = 2.0 * wo.dot(h) * h - wo;
        if wi.z <= 0.0 {
            return none;
        }
        wi
    } else if u.x < p.x + p.y {
        sample_cosine_hemisphere(Vec2::new(u.y, u.z))
    } else if u.x < p.x + p.y + p.w {
        let w = sample_cosine_hemisphere(Vec2::new(u.y, u.z));
        Vec3::new(w.x, w.y, -w.z)
    } else {
        if p.z <= 0.0 {
            return none;
        }
        if m.flags & MAT_THIN_WALLED != 0 {
            if alpha < DELTA_ALPHA {
                let t = transmission_albedo(m, wo.z, eta);
                return BsdfSample { wi: -wo, weight: t / p.z, pdf: p.z, delta: true };
            }
            let h = ggx_sample_vndf(wo, alpha, Vec2::new(u.y, u.z));
            let r = 2.0 * wo.dot(h) * h - wo;
            if r.z <= 0.0 {
                return none;
            }
            thin_reflection(r)
        } else {
            let rough = transmission_is_rough(m, alpha, eta);
            let h = if rough { ggx_sample_vndf(wo, alpha, Vec2::new(u.y, u.z)) } else { Vec3::Z };
            let r = refract_dir(wo, h, eta);
            if r.w == 0.0 {
                return none;
            }
            if !rough {
                let t = transmission_albedo(m, wo.z, eta) / (eta * eta);
                return BsdfSample { wi: r.truncate(), weight: t / p.z, pdf: p.z, delta: true };
            }
            let wi = r.truncate();
            if wi.z >= 0.0 {
                return none;
            }
            wi
        }
    };
    let pdf = base_pdf_chosen(m, p, wo, wi, eta);
    if wi.z == 0.0 || pdf <= 0.0 {
        return none;
    }
    BsdfSample { wi, weight: base_eval(m, wo, wi, eta) * (wi.z.abs() / pdf), pdf, delta: false }
}

/// Has the material a coat or a sheen over its base? Without, the BSDF is the base's alone.
#[inline]
pub fn has_layers(m: &Material) -> bool {
    m.clearcoat > 0.0 || Vec3::from(m.sheen_color).max_element() > 0.0
}

/// What reaches the base through the layers: 1 − the coat's weight, times the sheen's albedo
/// scaling (from both directions; a transmitted wi by its |cos|).
#[inline]
pub fn base_scaling(m: &Material, wo: Vec3, wi: Vec3, coat: f32) -> f32 {
    (1.0 - coat) * sheen_albedo_scaling(m.sheen_color.into(), m.sheen_roughness, wo.z, wi.z.abs())
}

/// Probabilities of sampling the coat, the sheen and the base, from their albedos seen from
/// wo (the base's from its lobes' weights).
pub fn layer_probabilities(m: &Material, wo: Vec3, eta: f32) -> Vec3 {
    let coat = coat_weight(m, wo);
    let sheen = Vec3::from(m.sheen_color);
    let e = if sheen.max_element() > 0.0 { sheen_albedo(wo.z, m.sheen_roughness) } else { 0.0 };
    let b = lobe_weights(m, wo.z, eta);
    let w = Vec3::new(
        coat,
        (1.0 - coat) * luminance(sheen) * e,
        (1.0 - coat) * (1.0 - sheen.max_element() * e) * (b.x + b.y + b.z + b.w),
    );
    let total = w.x + w.y + w.z;
    if total <= 0.0 {
        return Vec3::ZERO;
    }
    w / total
}

/// f(wo, wi) without the cosine: coat + (1 − coat weight) · (sheen + base · sheen scaling).
/// Dirac lobes are not included.
pub fn bsdf_eval(m: &Material, wo: Vec3, wi: Vec3, eta: f32) -> Vec3 {
    let base = base_eval(m, wo, wi, eta);
    if !has_layers(m) {
        return base;
    }
    if wo.z <= 0.0 || wi.z == 0.0 {
        return Vec3::ZERO;
    }
    let coat = coat_weight(m, wo);
    let mut f = base * base_scaling(m, wo, wi, coat);
    if wi.z > 0.0 {
        f += (1.0 - coat) * Vec3::from(m.sheen_color) * sheen_brdf(wo, wi, m.sheen_roughness);
        f += Vec3::splat(coat * coat_eval(m, wo, wi));
    }
    f
}

/// The lobe probabilities of a material seen from wo: the base's lobes and, under a coat or a
/// sheen, the layers'. They depend on wo alone, so a path's vertex computes them once for its
/// light sample's MIS weight and its BSDF sample (`*_chosen`).
#[derive(Clone, Copy, Debug)]
pub struct LobeChoice {
    pub base: Vec4,
    pub layers: Vec3,
}

pub fn lobe_choice(m: &Material, wo: Vec3, eta: f32) -> LobeChoice {
    let layers = if has_layers(m) { layer_probabilities(m, wo, eta) } else { Vec3::ZERO };
    LobeChoice { base: lobe_probabilities(m, wo.z, eta), layers }
}

pub fn bsdf_pdf(m: &Material, wo: Vec3, wi: Vec3, eta: f32) -> f32 {
    bsdf_pdf_chosen(m, &lobe_choice(m, wo, eta), wo, wi, eta)
}

/// `bsdf_pdf` with the lobe choice from wo already known.
#[inline]
pub fn bsdf_pdf_chosen(m: &Material, c: &LobeChoice, wo: Vec3, wi: Vec3, eta: f32) -> f32 {
    if !has_layers(m) {
        return base_pdf_chosen(m, c.base, wo, wi, eta);
    }
    if wo.z <= 0.0 || wi.z == 0.0 {
        return 0.0;
    }
    let p = c.layers;
    let mut pdf = p.z * base_pdf_chosen(m, c.base, wo, wi, eta);
    if wi.z > 0.0 {
        pdf += p.x * coat_pdf(m, wo, wi) + p.y * UNIFORM_HEMISPHERE_PDF;
    }
    pdf
}

/// Picks the base, the coat or the sheen with u.x, then a direction from it (the base with
/// u.x rescaled to its share). Dirac lobes of the base keep its layers' scaling.
pub fn bsdf_sample(m: &Material, wo: Vec3, u: Vec3, eta: f32) -> BsdfSample {
    bsdf_sample_chosen(m, &lobe_choice(m, wo, eta), wo, u, eta)
}

/// `bsdf_sample` with the lobe choice from wo already known.
#[inline]
pub fn bsdf_sample_chosen(m: &Material, c: &LobeChoice, wo: Vec3, u: Vec3, eta: f32) -> BsdfSample {
    if !has_layers(m) {
        return base_sample_chosen(m, c.base, wo, u, eta);
    }
    let none = BsdfSample { wi: Vec3::Z, weight: Vec3::ZERO, pdf: 0.0, delta: false };
    if wo.z <= 0.0 {
        return none;
    }
    let p = c.layers;
    let wi = if u.x < p.z {
        let s = base_sample_chosen(m, c.base, wo, Vec3::new(u.x / p.z, u.y, u.z), eta);
        if s.pdf <= 0.0 {
            return none;
        }
        if s.delta {
            let scale = base_scaling(m, wo, s.wi, coat_weight(m, wo));
            return BsdfSample { wi: s.wi, weight: s.weight * (scale / p.z), pdf: s.pdf * p.z, delta: true };
        }
        s.wi
    } else if u.x < p.z + p.x {
        let wi = coat_sample(m, wo, Vec2::new(u.y, u.z));
        if wi.z <= 0.0 {
            return none;
        }
        if coat_alpha(m) < DELTA_ALPHA {
            return BsdfSample { wi, weight: Vec3::splat(coat_weight(m, wo) / p.x), pdf: p.x, delta: true };
        }
        wi
    } else {
        if p.y <= 0.0 {
            return none;
        }
        sample_uniform_hemisphere(Vec2::new(u.y, u.z))
    };
    let pdf = bsdf_pdf_chosen(m, c, wo, wi, eta);
    if wi.z == 0.0 || pdf <= 0.0 {
        return none;
    }
    BsdfSample { wi, weight: bsdf_eval(m, wo, wi, eta) * (wi.z.abs() / pdf), pdf, delta: false }
}

/// Whether every lobe the material samples from `wo` is a Dirac one (a mirror, smooth glass,
/// a smooth thin sheet, under a smooth coat at most): the AOVs look through such surfaces.
/// Twin of `bsdf_is_delta`.
pub fn bsdf_is_delta(m: &Material, wo: Vec3, eta: f32) -> bool {
    let alpha = m.roughness * m.roughness;
    let p = lobe_probabilities(m, wo.z, eta);
    let base = p.y <= 0.0
        && p.w <= 0.0
        && (p.x <= 0.0 || !specular_is_rough(m, alpha))
        && (p.z <= 0.0 || !transmission_is_rough(m, alpha, eta));
    if !has_layers(m) {
        return base;
    }
    let l = layer_probabilities(m, wo, eta);
    l.y <= 0.0 && (l.z <= 0.0 || base) && (l.x <= 0.0 || coat_alpha(m) < DELTA_ALPHA)
}

/// The albedo AOV of a surface seen from `wo`, in [0, 1]: the base's lobes' reflectances
/// (specular Fresnel, diffuse and transmitted colour, textures included) under the sheen;
/// a clear coat absorbs nothing and is left out, as Open Image Denoise advises.
/// Twin of `bsdf_albedo`.
pub fn bsdf_albedo(m: &Material, wo: Vec3, eta: f32) -> Vec3 {
    let c = wo.z.max(0.0);
    let base = bsdf_fresnel(m, c, eta)
        + diffuse_albedo(m, c, eta)
        + transmission_albedo(m, c, eta)
        + diffuse_transmission_albedo(m, c, eta);
    let sheen = Vec3::from(m.sheen_color);
    let albedo = if sheen.max_element() > 0.0 {
        let e = sheen_albedo(c, m.sheen_roughness);
        sheen * e + base * (1.0 - sheen.max_element() * e)
    } else {
        base
    };
    albedo.clamp(Vec3::ZERO, Vec3::ONE)
}
