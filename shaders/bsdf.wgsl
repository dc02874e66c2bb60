// glTF's metallic-roughness material as a path tracer reads it: a GGX specular lobe
// (α = roughness²) whose Fresnel term blends the dielectric's and the base color by
// metallic; under it, the non-metal part splits by KHR_materials_transmission into a
// Lambertian lobe and a GGX transmission lobe (Walter et al. 2007), both weighted by 1 − F so
// energy is conserved; KHR_materials_diffuse_transmission passes a share of the Lambertian
// lobe, in its own colour, to the other side. α below DELTA_ALPHA makes the specular and transmission lobes Dirac
// lobes (mirror, smooth glass).
// Everything in the local shading frame (normal = +z, wo.z > 0). `eta` is the relative index
// of refraction across the surface seen from wo (ior entering, 1/ior leaving); transmitted
// directions have wi.z < 0. eval, pdf and sample agree. Twin: src/cpu/bsdf.rs.
#include "common.wgsl"
#include "sampling.wgsl"
#include "microfacet.wgsl"
#include "clearcoat.wgsl"
#include "iridescence.wgsl"
#include "sheen.wgsl"

struct BsdfSample {
    wi: vec3<f32>,
    // f · |cos θi| / pdf
    weight: vec3<f32>,
    pdf: f32,
    // Drawn from a Dirac lobe: light sampling cannot find it, so no MIS.
    delta: bool,
}

fn fresnel_schlick(f0: vec3<f32>, f90: vec3<f32>, cos_theta: f32) -> vec3<f32> {
    let m = clamp(1.0 - cos_theta, 0.0, 1.0);
    let m2 = m * m;
    return f0 + (f90 - f0) * (m2 * m2 * m);
}

// Unpolarised Fresnel reflectance of a dielectric interface; 1 under total internal reflection.
fn fresnel_dielectric(cos_i: f32, eta: f32) -> f32 {
    let c = clamp(cos_i, 0.0, 1.0);
    let sin2_t = (1.0 - c * c) / (eta * eta);
    if (sin2_t >= 1.0) {
        return 1.0;
    }
    let cos_t = sqrt(1.0 - sin2_t);
    let r_parl = (eta * c - cos_t) / (eta * c + cos_t);
    let r_perp = (c - eta * cos_t) / (c + eta * cos_t);
    return 0.5 * (r_parl * r_parl + r_perp * r_perp);
}

// The non-metal Fresnel: exact for transmissive materials (refraction needs the same F on
// both sides, with total internal reflection), else Schlick with KHR_materials_specular.
fn dielectric_fresnel(m: Material, cos_theta: f32, eta: f32) -> vec3<f32> {
    var f: vec3<f32>;
    if (TRANSMISSION && m.transmission > 0.0) {
        f = vec3<f32>(fresnel_dielectric(cos_theta, eta));
    } else {
        f = fresnel_schlick(m.dielectric_f0, vec3<f32>(m.dielectric_f90), cos_theta);
    }
    if (!IRIDESCENCE || m.iridescence <= 0.0) {
        return f;
    }
    return mix(f, thin_film(m, cos_theta, m.dielectric_f0), m.iridescence);
}

// KHR_materials_iridescence's film over a base of normal reflectance base_f0.
fn thin_film(m: Material, cos_theta: f32, base_f0: vec3<f32>) -> vec3<f32> {
    return iridescence_fresnel(1.0, m.iridescence_ior, cos_theta, m.iridescence_thickness_max, base_f0);
}

fn bsdf_fresnel(m: Material, cos_theta: f32, eta: f32) -> vec3<f32> {
    var metal = fresnel_schlick(m.base_color, vec3<f32>(1.0), cos_theta);
    if (IRIDESCENCE && m.iridescence > 0.0 && m.metallic > 0.0) {
        metal = mix(metal, thin_film(m, cos_theta, m.base_color), m.iridescence);
    }
    return mix(dielectric_fresnel(m, cos_theta, eta), metal, m.metallic);
}

// Albedo of the Lambertian lobe seen from wo.
fn diffuse_albedo(m: Material, cos_o: f32, eta: f32) -> vec3<f32> {
    let f = dielectric_fresnel(m, cos_o, eta);
    return (1.0 - m.metallic) * (1.0 - m.transmission) * (1.0 - m.diffuse_transmission) * m.base_color
        * (vec3<f32>(1.0) - f);
}

// KHR_materials_diffuse_transmission's share of the Lambertian lobe: the same lobe mirrored to
// the other side, in its own colour.
fn diffuse_transmission_albedo(m: Material, cos_o: f32, eta: f32) -> vec3<f32> {
    if (!DIFFUSE_TRANSMISSION || m.diffuse_transmission <= 0.0) {
        return vec3<f32>(0.0);
    }
    let f = dielectric_fresnel(m, cos_o, eta);
    return (1.0 - m.metallic) * (1.0 - m.transmission) * m.diffuse_transmission * m.diffuse_transmission_color
        * (vec3<f32>(1.0) - f);
}

// Estimated albedo of the transmission lobe seen from wo.
fn transmission_albedo(m: Material, cos_o: f32, eta: f32) -> vec3<f32> {
    if (!TRANSMISSION) {
        return vec3<f32>(0.0);
    }
    let f = dielectric_fresnel(m, cos_o, eta);
    return (1.0 - m.metallic) * m.transmission * m.base_color * (vec3<f32>(1.0) - f);
}

// Is the transmission lobe a GGX lobe (else a Dirac one)? A refracting microfacet tilted by θm
// turns the ray by about |1 − 1/η|·θm, so the lobe is α·|1 − 1/η| wide: at η = 1 light passes
// straight through whatever the roughness, and near it the half vector is ill-conditioned.
// Thin walls transmit a reflection, whose width is α's.
fn transmission_is_rough(m: Material, alpha: f32, eta: f32) -> bool {
    if ((m.flags & MAT_THIN_WALLED) != 0u) {
        return alpha >= DELTA_ALPHA;
    }
    return alpha * abs(1.0 - 1.0 / eta) >= DELTA_ALPHA;
}

// Probabilities of sampling the specular, diffuse, transmission and diffuse-transmission
// lobes, from their albedos. A rough interface transmits through some microfacets even beyond
// the critical angle of the macro surface, so its transmission lobe keeps at least a tenth of
// its weight.
fn lobe_weights(m: Material, cos_o: f32, eta: f32) -> vec4<f32> {
    var wt = luminance(transmission_albedo(m, cos_o, eta));
    if (TRANSMISSION && transmission_is_rough(m, m.roughness * m.roughness, eta)) {
        wt = max(wt, 0.1 * (1.0 - m.metallic) * m.transmission * luminance(m.base_color));
    }
    return vec4<f32>(
        luminance(bsdf_fresnel(m, cos_o, eta)),
        luminance(diffuse_albedo(m, cos_o, eta)),
        wt,
        luminance(diffuse_transmission_albedo(m, cos_o, eta)),
    );
}

fn lobe_probabilities(m: Material, cos_o: f32, eta: f32) -> vec4<f32> {
    let w = lobe_weights(m, cos_o, eta);
    let total = w.x + w.y + w.z + w.w;
    if (total <= 0.0) {
        return vec4<f32>(0.0);
    }
    return w / total;
}

// The generalised half vector of a refraction (Walter et al. 2007), facing +z, and the
// Jacobian denominator (wi·h + wo·h/eta)²; w = 0 when wo, wi do not form a refraction.
fn refraction_half_vector(wo: vec3<f32>, wi: vec3<f32>, eta: f32) -> vec4<f32> {
    var h = wi * eta + wo;
    let len2 = dot(h, h);
    if (len2 <= 0.0) {
        return vec4<f32>(0.0);
    }
    h = h * inverseSqrt(len2);
    h = select(h, -h, h.z < 0.0);
    if (dot(h, wo) <= 0.0 || dot(h, wi) >= 0.0) {
        return vec4<f32>(0.0);
    }
    let d = dot(wi, h) + dot(wo, h) / eta;
    return vec4<f32>(h, d * d);
}

// KHR_materials_anisotropy's roughness along and across its direction: the extension's
// α_t = mix(α, 1, strength²), α_b = α (at least DELTA_ALPHA: a mirror stretched along the
// tangent is rough along it and nearly smooth across).
fn anisotropy_alphas(m: Material, alpha: f32) -> vec2<f32> {
    return vec2<f32>(alpha + (1.0 - alpha) * m.anisotropy * m.anisotropy, max(alpha, DELTA_ALPHA));
}

// Is the specular lobe a GGX lobe (else a mirror)? An anisotropic one is as soon as its long
// axis is rough.
fn specular_is_rough(m: Material, alpha: f32) -> bool {
    return alpha >= DELTA_ALPHA || (ANISOTROPY && m.anisotropy > 0.0 && anisotropy_alphas(m, alpha).x >= DELTA_ALPHA);
}

// Local frame → the frame whose x is the anisotropy direction (a turn about the normal).
fn to_anisotropy(m: Material, w: vec3<f32>) -> vec3<f32> {
    let t = m.anisotropy_tangent;
    return vec3<f32>(t.x * w.x + t.y * w.y, -t.y * w.x + t.x * w.y, w.z);
}

fn from_anisotropy(m: Material, w: vec3<f32>) -> vec3<f32> {
    let t = m.anisotropy_tangent;
    return vec3<f32>(t.x * w.x - t.y * w.y, t.y * w.x + t.x * w.y, w.z);
}

// The specular lobe's D·G2/(4 cos θo cos θi), isotropic or anisotropic.
fn specular_brdf(m: Material, wo: vec3<f32>, wi: vec3<f32>, h: vec3<f32>, alpha: f32) -> f32 {
    if (!ANISOTROPY || m.anisotropy <= 0.0) {
        return ggx_d(h, alpha) * ggx_g2(wo, wi, alpha) / (4.0 * wo.z * wi.z);
    }
    let a = anisotropy_alphas(m, alpha);
    let o = to_anisotropy(m, wo);
    let i = to_anisotropy(m, wi);
    return ggx_d_aniso(to_anisotropy(m, h), a.x, a.y) * ggx_g2_aniso(o, i, a.x, a.y) / (4.0 * wo.z * wi.z);
}

fn specular_pdf(m: Material, wo: vec3<f32>, h: vec3<f32>, alpha: f32) -> f32 {
    if (!ANISOTROPY || m.anisotropy <= 0.0) {
        return ggx_reflection_pdf(wo, h, alpha);
    }
    let a = anisotropy_alphas(m, alpha);
    return ggx_reflection_pdf_aniso(to_anisotropy(m, wo), to_anisotropy(m, h), a.x, a.y);
}

fn sample_specular_normal(m: Material, wo: vec3<f32>, alpha: f32, u: vec2<f32>) -> vec3<f32> {
    if (!ANISOTROPY || m.anisotropy <= 0.0) {
        return ggx_sample_vndf(wo, alpha, u);
    }
    let a = anisotropy_alphas(m, alpha);
    return from_anisotropy(m, ggx_sample_vndf_aniso(to_anisotropy(m, wo), a.x, a.y, u));
}

// Thin-walled transmission continues a microfacet reflection through the sheet: the reflected
// direction mirrored in the tangent plane (and back).
fn thin_reflection(w: vec3<f32>) -> vec3<f32> {
    return vec3<f32>(w.x, w.y, -w.z);
}

// Refraction of wo through a surface with normal n (same side as wo); w = 0 under total
// internal reflection.
fn refract_dir(wo: vec3<f32>, n: vec3<f32>, eta: f32) -> vec4<f32> {
    let cos_i = dot(n, wo);
    let sin2_t = max(0.0, 1.0 - cos_i * cos_i) / (eta * eta);
    if (sin2_t >= 1.0) {
        return vec4<f32>(0.0);
    }
    let cos_t = sqrt(1.0 - sin2_t);
    return vec4<f32>(-wo / eta + (cos_i / eta - cos_t) * n, 1.0);
}

// The rough transmission lobe's f (wi.z < 0; thin walls pass a reflection through the sheet).
fn specular_transmission_eval(m: Material, wo: vec3<f32>, wi: vec3<f32>, eta: f32, alpha: f32) -> vec3<f32> {
    if ((m.flags & MAT_THIN_WALLED) != 0u) {
        let r = thin_reflection(wi);
        let h = normalize(wo + r);
        let f = fresnel_dielectric(dot(wo, h), eta);
        let ft = ggx_d(h, alpha) * ggx_g2(wo, r, alpha) * (1.0 - f) / (4.0 * wo.z * r.z);
        return (1.0 - m.metallic) * m.transmission * m.base_color * ft;
    }
    let hd = refraction_half_vector(wo, wi, eta);
    if (hd.w <= 0.0) {
        return vec3<f32>(0.0);
    }
    let h = hd.xyz;
    let f = fresnel_dielectric(dot(wo, h), eta);
    let ft = ggx_d(h, alpha) * ggx_g2(wo, wi, alpha) * (1.0 - f)
        * abs(dot(wi, h) * dot(wo, h) / (wi.z * wo.z * hd.w)) / (eta * eta);
    return (1.0 - m.metallic) * m.transmission * m.base_color * ft;
}

// The rough transmission lobe's density of wi (wi.z < 0) times p_lobe, the probability of
// choosing the lobe (multiplied first, as the films recorded before the lobe had a function of
// its own were computed).
// Did the BSDF sample `wi` (local) cross a dielectric interface, its weight scaled by 1/η²
// (specular_transmission_eval and the smooth refraction in base_sample)? A thin wall's
// transmission and diffuse transmission are not. Russian roulette divides the factor out.
fn refracted(m: Material, wi: vec3<f32>) -> bool {
    return TRANSMISSION && wi.z < 0.0 && m.transmission > 0.0 && (m.flags & MAT_THIN_WALLED) == 0u;
}

fn specular_transmission_pdf(m: Material, wo: vec3<f32>, wi: vec3<f32>, eta: f32, alpha: f32, p_lobe: f32) -> f32 {
    if ((m.flags & MAT_THIN_WALLED) != 0u) {
        let r = thin_reflection(wi);
        return p_lobe * ggx_reflection_pdf(wo, normalize(wo + r), alpha);
    }
    let hd = refraction_half_vector(wo, wi, eta);
    if (hd.w <= 0.0) {
        return 0.0;
    }
    let h = hd.xyz;
    let d_wo = ggx_g1(wo, alpha) * ggx_d(h, alpha) * dot(wo, h) / wo.z;
    return p_lobe * d_wo * abs(dot(wi, h)) / hd.w;
}

// f(wo, wi) without the cosine; Dirac lobes are not included.
fn base_eval(m: Material, wo: vec3<f32>, wi: vec3<f32>, eta: f32) -> vec3<f32> {
    let alpha = m.roughness * m.roughness;
    if (wo.z <= 0.0 || wi.z == 0.0) {
        return vec3<f32>(0.0);
    }
    if (wi.z < 0.0) {
        var f = diffuse_transmission_albedo(m, wo.z, eta) * INV_PI;
        if (TRANSMISSION && m.transmission > 0.0 && transmission_is_rough(m, alpha, eta)) {
            f += specular_transmission_eval(m, wo, wi, eta, alpha);
        }
        return f;
    }
    var f = diffuse_albedo(m, wo.z, eta) * INV_PI;
    if (specular_is_rough(m, alpha)) {
        let h = normalize(wo + wi);
        let spec = specular_brdf(m, wo, wi, h, alpha);
        f += bsdf_fresnel(m, dot(wo, h), eta) * spec;
    }
    return f;
}

fn base_pdf(m: Material, wo: vec3<f32>, wi: vec3<f32>, eta: f32) -> f32 {
    if (wo.z <= 0.0 || wi.z == 0.0) {
        return 0.0;
    }
    let p = lobe_probabilities(m, wo.z, eta);
    let alpha = m.roughness * m.roughness;
    if (wi.z < 0.0) {
        var pdf = p.w * cosine_hemisphere_pdf(-wi.z);
        if (TRANSMISSION && p.z > 0.0 && transmission_is_rough(m, alpha, eta)) {
            pdf += specular_transmission_pdf(m, wo, wi, eta, alpha, p.z);
        }
        return pdf;
    }
    var pdf = p.y * cosine_hemisphere_pdf(wi.z);
    if (specular_is_rough(m, alpha) && p.x > 0.0) {
        pdf += p.x * specular_pdf(m, wo, normalize(wo + wi), alpha);
    }
    return pdf;
}

fn base_sample(m: Material, wo: vec3<f32>, u: vec3<f32>, eta: f32) -> BsdfSample {
    let none = BsdfSample(vec3<f32>(0.0, 0.0, 1.0), vec3<f32>(0.0), 0.0, false);
    if (wo.z <= 0.0) {
        return none;
    }
    let p = lobe_probabilities(m, wo.z, eta);
    let alpha = m.roughness * m.roughness;
    var wi: vec3<f32>;
    if (u.x < p.x) {
        if (!specular_is_rough(m, alpha)) {
            let mirror = vec3<f32>(-wo.x, -wo.y, wo.z);
            return BsdfSample(mirror, bsdf_fresnel(m, wo.z, eta) / p.x, p.x, true);
        }
        let h = sample_specular_normal(m, wo, alpha, u.yz);
        wi = 2.0 * dot(wo, h) * h - wo;
        // A reflection below the horizon is a lost sample (pdf below counts transmission only).
        if (wi.z <= 0.0) {
            return none;
        }
    } else if (u.x < p.x + p.y) {
        wi = sample_cosine_hemisphere(u.yz);
    } else if (u.x < p.x + p.y + p.w) {
        let w = sample_cosine_hemisphere(u.yz);
        wi = vec3<f32>(w.x, w.y, -w.z);
    } else {
        if (!TRANSMISSION || p.z <= 0.0) {
            return none;
        }
        if ((m.flags & MAT_THIN_WALLED) != 0u) {
            if (alpha < DELTA_ALPHA) {
                return BsdfSample(-wo, transmission_albedo(m, wo.z, eta) / p.z, p.z, true);
            }
            let hm = ggx_sample_vndf(wo, alpha, u.yz);
            let r = 2.0 * dot(wo, hm) * hm - wo;
            if (r.z <= 0.0) {
                return none;
            }
            wi = thin_reflection(r);
        } else {
        let rough = transmission_is_rough(m, alpha, eta);
        var h = vec3<f32>(0.0, 0.0, 1.0);
        if (rough) {
            h = ggx_sample_vndf(wo, alpha, u.yz);
        }
        let r = refract_dir(wo, h, eta);
        if (r.w == 0.0) {
            return none;
        }
        if (!rough) {
            let t = transmission_albedo(m, wo.z, eta) / (eta * eta);
            return BsdfSample(r.xyz, t / p.z, p.z, true);
        }
        wi = r.xyz;
        if (wi.z >= 0.0) {
            return none;
        }
        }
    }
    let pdf = base_pdf(m, wo, wi, eta);
    if (wi.z == 0.0 || pdf <= 0.0) {
        return none;
    }
    return BsdfSample(wi, base_eval(m, wo, wi, eta) * (abs(wi.z) / pdf), pdf, false);
}

// The layers over the base: KHR_materials_clearcoat's coat over KHR_materials_sheen's sheen.
fn has_layers(m: Material) -> bool {
    return (CLEARCOAT && m.clearcoat > 0.0) || (SHEEN && max_component(m.sheen_color) > 0.0);
}

// What reaches the base through the layers: 1 − the coat's weight, times the sheen's albedo
// scaling (from both directions; a transmitted wi by its |cos|).
fn base_scaling(m: Material, wo: vec3<f32>, wi: vec3<f32>, coat: f32) -> f32 {
    if (!SHEEN) {
        return 1.0 - coat;
    }
    return (1.0 - coat) * sheen_albedo_scaling(m.sheen_color, m.sheen_roughness, wo.z, abs(wi.z));
}

// Probabilities of sampling the coat, the sheen and the base, from their albedos seen from wo.
fn layer_probabilities(m: Material, wo: vec3<f32>, eta: f32) -> vec3<f32> {
    let coat = coat_weight(m, wo);
    var e = 0.0;
    if (SHEEN && max_component(m.sheen_color) > 0.0) {
        e = sheen_albedo(wo.z, m.sheen_roughness);
    }
    let b = lobe_weights(m, wo.z, eta);
    let w = vec3<f32>(
        coat,
        (1.0 - coat) * luminance(m.sheen_color) * e,
        (1.0 - coat) * (1.0 - max_component(m.sheen_color) * e) * (b.x + b.y + b.z + b.w),
    );
    let total = w.x + w.y + w.z;
    if (total <= 0.0) {
        return vec3<f32>(0.0);
    }
    return w / total;
}

// f(wo, wi) without the cosine: coat + (1 − coat weight) · (sheen + base · sheen scaling).
// Dirac lobes are not included.
fn bsdf_eval(m: Material, wo: vec3<f32>, wi: vec3<f32>, eta: f32) -> vec3<f32> {
    let base = base_eval(m, wo, wi, eta);
    if (!has_layers(m)) {
        return base;
    }
    if (wo.z <= 0.0 || wi.z == 0.0) {
        return vec3<f32>(0.0);
    }
    let coat = coat_weight(m, wo);
    var f = base * base_scaling(m, wo, wi, coat);
    if (wi.z > 0.0) {
        if (SHEEN) {
            f += (1.0 - coat) * m.sheen_color * sheen_brdf(wo, wi, m.sheen_roughness);
        }
        f += vec3<f32>(coat * coat_eval(m, wo, wi));
    }
    return f;
}

fn bsdf_pdf(m: Material, wo: vec3<f32>, wi: vec3<f32>, eta: f32) -> f32 {
    if (!has_layers(m)) {
        return base_pdf(m, wo, wi, eta);
    }
    if (wo.z <= 0.0 || wi.z == 0.0) {
        return 0.0;
    }
    let p = layer_probabilities(m, wo, eta);
    var pdf = p.z * base_pdf(m, wo, wi, eta);
    if (wi.z > 0.0) {
        pdf += p.x * coat_pdf(m, wo, wi) + p.y * UNIFORM_HEMISPHERE_PDF;
    }
    return pdf;
}

// Picks the base, the coat or the sheen with u.x, then a direction from it (the base with
// u.x rescaled to its share). Dirac lobes of the base keep its layers' scaling.
fn bsdf_sample(m: Material, wo: vec3<f32>, u: vec3<f32>, eta: f32) -> BsdfSample {
    if (!has_layers(m)) {
        return base_sample(m, wo, u, eta);
    }
    let none = BsdfSample(vec3<f32>(0.0, 0.0, 1.0), vec3<f32>(0.0), 0.0, false);
    if (wo.z <= 0.0) {
        return none;
    }
    let p = layer_probabilities(m, wo, eta);
    var wi: vec3<f32>;
    if (u.x < p.z) {
        let s = base_sample(m, wo, vec3<f32>(u.x / p.z, u.y, u.z), eta);
        if (s.pdf <= 0.0) {
            return none;
        }
        if (s.delta) {
            let scale = base_scaling(m, wo, s.wi, coat_weight(m, wo));
            return BsdfSample(s.wi, s.weight * (scale / p.z), s.pdf * p.z, true);
        }
        wi = s.wi;
    } else if (u.x < p.z + p.x) {
        wi = coat_sample(m, wo, u.yz);
        if (wi.z <= 0.0) {
            return none;
        }
        if (coat_alpha(m) < DELTA_ALPHA) {
            return BsdfSample(wi, vec3<f32>(coat_weight(m, wo) / p.x), p.x, true);
        }
    } else {
        if (p.y <= 0.0) {
            return none;
        }
        wi = sample_uniform_hemisphere(u.yz);
    }
    let pdf = bsdf_pdf(m, wo, wi, eta);
    if (wi.z == 0.0 || pdf <= 0.0) {
        return none;
    }
    return BsdfSample(wi, bsdf_eval(m, wo, wi, eta) * (abs(wi.z) / pdf), pdf, false);
}

// Whether every lobe the material samples from wo is a Dirac one (a mirror, smooth glass, a
// smooth thin sheet, under a smooth coat at most): the AOVs look through such surfaces.
fn bsdf_is_delta(m: Material, wo: vec3<f32>, eta: f32) -> bool {
    let alpha = m.roughness * m.roughness;
    let p = lobe_probabilities(m, wo.z, eta);
    let base = p.y <= 0.0 && p.w <= 0.0 && (p.x <= 0.0 || !specular_is_rough(m, alpha))
        && (p.z <= 0.0 || !transmission_is_rough(m, alpha, eta));
    if (!has_layers(m)) {
        return base;
    }
    let l = layer_probabilities(m, wo, eta);
    return l.y <= 0.0 && (l.z <= 0.0 || base) && (l.x <= 0.0 || coat_alpha(m) < DELTA_ALPHA);
}

// The albedo AOV of a surface seen from wo, in [0, 1]: the base's lobes' reflectances
// (specular Fresnel, diffuse and transmitted colour, textures included) under the sheen; a
// clear coat absorbs nothing and is left out, as Open Image Denoise advises.
fn bsdf_albedo(m: Material, wo: vec3<f32>, eta: f32) -> vec3<f32> {
    let c = max(wo.z, 0.0);
    let base = bsdf_fresnel(m, c, eta) + diffuse_albedo(m, c, eta) + transmission_albedo(m, c, eta)
        + diffuse_transmission_albedo(m, c, eta);
    var albedo = base;
    if (SHEEN && max_component(m.sheen_color) > 0.0) {
        let e = sheen_albedo(c, m.sheen_roughness);
        albedo = m.sheen_color * e + base * (1.0 - max_component(m.sheen_color) * e);
    }
    return clamp(albedo, vec3<f32>(0.0), vec3<f32>(1.0));
}
