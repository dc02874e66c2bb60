//! BSDF sampling is right: `sample` draws directions with the density `pdf` says (chi-square
//! over the sphere, as pbrt and Mitsuba test theirs), and `eval·cos/pdf` averages to the
//! albedo a quadrature of `eval·cos` gives. Rough glass (KHR_materials_transmission) is
//! tested from both sides, entering (η = 1.5) and leaving (η = 1/1.5, with total internal
//! reflection). The layers over the base — KHR_materials_clearcoat's coat (with a coat
//! normal of its own) and KHR_materials_sheen's sheen — are tested alone, together and over
//! metal, plastic and glass. KHR_materials_diffuse_transmission's Lambertian lobe through
//! the surface is tested alone, beside rough thin glass and under a coat.

mod common;

use common::rng::Lcg;

use common::chi2::{self, direction};
use glam::Vec3;
use std::f32::consts::PI;
use veach::cpu::bsdf::{bsdf_eval, bsdf_pdf, bsdf_sample};
use veach::packed::{Material as PackedMaterial, pack_material};
use veach::scene::Material;

fn material(base: f32, metallic: f32, roughness: f32, specular: f32) -> PackedMaterial {
    pack_material(
        &Material {
            base_color: Vec3::new(base, base * 0.8, base * 0.6),
            metallic,
            roughness,
            specular_factor: specular,
            ..Material::default()
        },
        &[],
    )
}

/// A coat of strength 1 and this roughness over `base`, its normal tilted by `tilt` (radians).
fn coated(base: Material, roughness: f32, tilt: f32) -> PackedMaterial {
    let mut m = pack_material(&Material { clearcoat: 1.0, clearcoat_roughness: roughness, ..base }, &[]);
    m.coat_normal = [tilt.sin(), 0.3 * tilt.sin(), tilt.cos()];
    m.coat_normal = Vec3::from(m.coat_normal).normalize().into();
    m
}

fn sheened(base: Material, color: Vec3, roughness: f32) -> Material {
    Material { sheen_color: color, sheen_roughness: roughness, ..base }
}

fn plastic(base: f32, roughness: f32) -> Material {
    Material { base_color: Vec3::new(base, base * 0.8, base * 0.6), metallic: 0.0, roughness, ..Material::default() }
}

/// KHR_materials_diffuse_transmission of this share and colour over `base`.
fn translucent(base: Material, share: f32, color: Vec3) -> Material {
    Material { diffuse_transmission: share, diffuse_transmission_color: color, ..base }
}

fn thin(roughness: f32, transmission: f32) -> PackedMaterial {
    pack_material(
        &Material {
            base_color: Vec3::new(1.0, 0.9, 0.8),
            metallic: 0.0,
            roughness,
            transmission,
            thin_walled: true,
            ..Material::default()
        },
        &[],
    )
}

fn glass(roughness: f32, transmission: f32) -> PackedMaterial {
    pack_material(
        &Material { base_color: Vec3::ONE, metallic: 0.0, roughness, transmission, ..Material::default() },
        &[],
    )
}

/// (name, material, η seen from wo).
fn cases() -> Vec<(String, PackedMaterial, f32)> {
    let mut v = vec![("lambert".to_string(), material(0.8, 0.0, 1.0, 0.0), 1.5)];
    for r in [0.3, 0.5, 0.8] {
        v.push((format!("metal r={r}"), material(0.9, 1.0, r, 1.0), 1.5));
        v.push((format!("plastic r={r}"), material(0.5, 0.0, r, 1.0), 1.5));
        v.push((format!("half-metal r={r}"), material(0.7, 0.5, r, 0.5), 1.5));
    }
    // Rougher than the metals: the refracted lobe is narrower than the reflected one, and the
    // chi-square quadrature must resolve it.
    for r in [0.5, 0.8] {
        v.push((format!("glass entering r={r}"), glass(r, 1.0), 1.5));
        v.push((format!("glass leaving r={r}"), glass(r, 1.0), 1.0 / 1.5));
    }
    v.push(("half-transmissive r=0.4".to_string(), glass(0.4, 0.5), 1.5));
    // KHR_materials_anisotropy: the lobe stretched along a direction turned from the frame's x.
    for (name, base, strength, tangent) in [
        ("aniso metal s=0.8 r=0.4", Material { metallic: 1.0, ..plastic(0.9, 0.4) }, 0.8, [0.6, 0.8]),
        ("aniso plastic s=0.5 r=0.3", plastic(0.5, 0.3), 0.5, [1.0, 0.0]),
    ] {
        let mut m = pack_material(&Material { anisotropy: strength, ..base }, &[]);
        m.anisotropy_tangent = tangent;
        v.push((name.to_string(), m, 1.5));
    }
    // KHR_materials_iridescence: a film over plastic and over metal.
    let film =
        |base: Material| Material { iridescence: 1.0, iridescence_ior: 1.3, iridescence_thickness_max: 350.0, ..base };
    v.push(("iridescent plastic r=0.4".to_string(), pack_material(&film(plastic(0.5, 0.4)), &[]), 1.5));
    v.push((
        "iridescent metal r=0.3".to_string(),
        pack_material(&film(Material { metallic: 1.0, ..plastic(0.9, 0.3) }), &[]),
        1.5,
    ));
    // Thin walls (no volume): seen from either side the sheet has air behind it (η = ior).
    v.push(("thin glass r=0.4".to_string(), thin(0.4, 1.0), 1.5));
    v.push(("thin half-transmissive r=0.7".to_string(), thin(0.7, 0.5), 1.5));
    v.push(("coat r=0.3 over plastic".to_string(), coated(plastic(0.5, 0.6), 0.3, 0.0), 1.5));
    v.push((
        "coat r=0.5 tilted over metal".to_string(),
        coated(Material { metallic: 1.0, ..plastic(0.9, 0.3) }, 0.5, 0.25),
        1.5,
    ));
    v.push((
        "sheen r=0.5 over lambert".to_string(),
        pack_material(&sheened(plastic(0.8, 1.0), Vec3::new(1.0, 0.7, 0.5), 0.5), &[]),
        1.5,
    ));
    v.push((
        "sheen r=0.15 over plastic".to_string(),
        pack_material(&sheened(plastic(0.5, 0.5), Vec3::ONE, 0.15), &[]),
        1.5,
    ));
    v.push((
        "coat r=0.4 over sheen r=0.8".to_string(),
        coated(sheened(plastic(0.6, 0.7), Vec3::splat(0.8), 0.8), 0.4, 0.1),
        1.5,
    ));
    v.push((
        "diffuse transmission 1 under plastic r=0.5".to_string(),
        pack_material(&translucent(plastic(0.6, 0.5), 1.0, Vec3::new(0.9, 0.6, 0.3)), &[]),
        1.5,
    ));
    v.push((
        "thin glass r=0.5 beside diffuse transmission 0.6".to_string(),
        pack_material(
            &translucent(Material { transmission: 0.5, thin_walled: true, ..plastic(0.8, 0.5) }, 0.6, Vec3::ONE),
            &[],
        ),
        1.5,
    ));
    v.push((
        "coat r=0.3 over diffuse transmission 0.5".to_string(),
        coated(translucent(plastic(0.7, 0.4), 0.5, Vec3::new(0.5, 0.8, 1.0)), 0.3, 0.1),
        1.5,
    ));
    v.push((
        "coat r=0.3 over rough glass".to_string(),
        coated(Material { transmission: 1.0, ..plastic(1.0, 0.5) }, 0.3, 0.0),
        1.5,
    ));
    v
}

#[test]
fn bsdf_sample_matches_pdf_chi_square() {
    // Sub-cells per bin side: the midpoint rule must resolve the α = 0.09 lobe (12 is too
    // coarse); the bins at the poles, where the refracted lobe of glass concentrates, get 8×.
    let bins = chi2::SphereBins { theta: 20, phi: 40, sub: 32, pole_sub: 256 };
    let mut rng = Lcg(1);
    let n_cases = cases().len() * 3;
    for (name, m, eta) in cases() {
        for theta_o in [10f32, 45.0, 80.0] {
            let t = theta_o.to_radians();
            let wo = Vec3::new(t.sin(), 0.0, t.cos());
            let what = format!("{name} θo={theta_o}");
            let sample = || {
                let s = bsdf_sample(&m, wo, Vec3::new(rng.f(), rng.f(), rng.f()), eta);
                if s.pdf <= 0.0 {
                    return None;
                }
                assert!(!s.delta, "{name}: no Dirac lobe here");
                let pdf = bsdf_pdf(&m, wo, s.wi, eta);
                assert!((pdf - s.pdf).abs() <= 1e-3 * pdf, "{name}: sample pdf {} vs pdf() {pdf}", s.pdf);
                Some(s.wi)
            };
            let r = chi2::sphere(&what, bins, 400_000, sample, |wi| bsdf_pdf(&m, wo, wi, eta) as f64);
            assert!(r.total < 1.0 + 2e-3, "{what}: pdf integrates to {}", r.total);
            // 1 % significance over all cases.
            r.assert_passes(&what, 0.01, n_cases);
        }
    }
}

#[test]
fn sampled_albedo_equals_quadrature() {
    let mut rng = Lcg(2);
    for (name, m, eta) in cases() {
        for theta_o in [10f32, 45.0, 80.0] {
            let t = theta_o.to_radians();
            let wo = Vec3::new(t.sin(), 0.0, t.cos());
            // Quadrature of f·|cos| over the sphere in (cos θ, φ); the refracted part (thick
            // glass) also times η², which undoes the radiance scaling: that sum is the energy
            // kept. Diffuse transmission does not bend light, nor scale radiance.
            let (nc, np) = (1600usize, 400usize);
            let mut quad = Vec3::ZERO.as_dvec3();
            let mut energy = 0.0f64;
            for i in 0..nc {
                let c = -1.0 + 2.0 * (i as f32 + 0.5) / nc as f32;
                for j in 0..np {
                    let p = (j as f32 + 0.5) / np as f32 * 2.0 * PI;
                    let wi = direction(c, p);
                    let fc = (bsdf_eval(&m, wo, wi, eta) * c.abs()).as_dvec3();
                    quad += fc;
                    let thin_wall = m.flags & veach::packed::MAT_THIN_WALLED != 0;
                    let refracts = c < 0.0 && !thin_wall && m.transmission > 0.0;
                    energy += fc.y * if refracts { (eta * eta) as f64 } else { 1.0 };
                }
            }
            let scale = 4.0 * std::f64::consts::PI / (nc * np) as f64;
            quad *= scale;
            energy *= scale;
            // Monte Carlo with the BSDF's own sampling.
            let n = 200_000;
            let mut mc = Vec3::ZERO.as_dvec3();
            let mut mc2 = Vec3::ZERO.as_dvec3();
            for _ in 0..n {
                let s = bsdf_sample(&m, wo, Vec3::new(rng.f(), rng.f(), rng.f()), eta);
                mc += s.weight.as_dvec3();
                mc2 += (s.weight * s.weight).as_dvec3();
            }
            mc /= n as f64;
            let stderr = ((mc2 / n as f64 - mc * mc) / n as f64).max(glam::DVec3::ZERO).sqrt();
            for c in 0..3 {
                let tol = 4.0 * stderr[c] + 2e-3 * quad[c];
                assert!(
                    (mc[c] - quad[c]).abs() <= tol,
                    "{name} θo={theta_o}: sampled albedo {mc} vs quadrature {quad} (stderr {stderr})"
                );
            }
            assert!(energy <= 1.0 + 1e-3, "{name} θo={theta_o}: energy {energy} above 1");
        }
    }
}

/// Near-mirror GGX (α² below f32's epsilon, roughness 0.0101–0.016) must stay finite: the
/// textbook D(h) cancels to 0/0 there (found on NormalTangentTest, roughness 0.0106). Both
/// sampled and evaluated values, for directions around the normal, on both lobe kinds.
#[test]
fn near_mirror_ggx_is_finite() {
    let mut rng = Lcg(11);
    for roughness in [0.0, 0.0101, 0.0106, 0.012, 0.016] {
        // A stretched mirror (anisotropy over roughness 0): rough along, nearly smooth across.
        let mut stretched = material(0.9, 1.0, roughness, 1.0);
        (stretched.anisotropy, stretched.anisotropy_tangent) = (0.7, [0.6, 0.8]);
        for m in
            [material(0.9, 1.0, roughness, 1.0), material(0.5, 0.0, roughness, 1.0), glass(roughness, 1.0), stretched]
        {
            for k in 0..20_000 {
                // Half of the directions within 0.01 rad of the normal, where D peaks.
                let spread = if k % 2 == 0 { 0.01 } else { 1.0 };
                let (a, b) = (rng.f() * spread, rng.f() * 2.0 * PI);
                let wo = Vec3::new(a.sin() * b.cos(), a.sin() * b.sin(), a.cos()).normalize();
                let s = bsdf_sample(&m, wo, Vec3::new(rng.f(), rng.f(), rng.f()), 1.5);
                assert!(s.pdf.is_finite() && s.weight.is_finite(), "r={roughness} wo={wo}: {s:?}");
                let wi = Vec3::new(-wo.x, -wo.y, wo.z);
                assert!(bsdf_eval(&m, wo, wi, 1.5).is_finite() && bsdf_pdf(&m, wo, wi, 1.5).is_finite());
            }
        }
    }
}

/// The sheen's albedo table (src/sheen.rs, built by a quadrature in cos² spacing) against
/// Monte Carlo with uniform directions, off the table's nodes: bilinear interpolation and
/// the quadrature stay within 1.5 % + 0.002.
#[test]
fn sheen_albedo_table_matches_monte_carlo() {
    use veach::cpu::sampling::{UNIFORM_HEMISPHERE_PDF, sample_uniform_hemisphere};
    use veach::sheen::{sheen_albedo, sheen_brdf};
    let mut rng = Lcg(21);
    for roughness in [0.1f32, 0.33, 0.52, 0.77, 1.0] {
        for mu in [0.05f32, 0.23, 0.5, 0.81, 0.97] {
            let wo = Vec3::new((1.0 - mu * mu).sqrt(), 0.0, mu);
            let n = 400_000;
            let (mut sum, mut sum2) = (0.0f64, 0.0f64);
            for _ in 0..n {
                let wi = sample_uniform_hemisphere(glam::Vec2::new(rng.f(), rng.f()));
                let v = (sheen_brdf(wo, wi, roughness) * wi.z / UNIFORM_HEMISPHERE_PDF) as f64;
                sum += v;
                sum2 += v * v;
            }
            let mean = sum / n as f64;
            let se = ((sum2 / n as f64 - mean * mean) / n as f64).sqrt();
            let table = sheen_albedo(mu, roughness) as f64;
            assert!(
                (table - mean).abs() <= 4.0 * se + 0.015 * mean + 0.002,
                "r={roughness} μ={mu}: table {table} vs Monte Carlo {mean} ± {se}"
            );
        }
    }
}

/// White furnaces of the layers over a white Lambertian base (no specular), by quadrature:
/// - a coat keeps 1 − w + w·E_ggx(μ), w = its Fresnel weight: it loses only what its
///   single-scattering GGX lobe loses (E_ggx from an independent quadrature of D·G2);
/// - a white sheen never gains, and loses at most E_max − E(μo): the albedo scaling takes
///   the smaller of the two directions' transmittances.
#[test]
fn white_furnaces_of_the_layers_lose_only_what_their_model_explains() {
    use veach::cpu::microfacet::{ggx_d, ggx_g2};
    use veach::sheen::sheen_albedo;
    let lambert = Material { base_color: Vec3::ONE, metallic: 0.0, specular_factor: 0.0, ..Material::default() };
    let quad = |f: &dyn Fn(Vec3) -> f64| {
        let (nc, np) = (800usize, 200usize);
        let mut sum = 0.0;
        for i in 0..nc {
            let c = (i as f32 + 0.5) / nc as f32;
            for j in 0..np {
                sum += f(direction(c, (j as f32 + 0.5) / np as f32 * 2.0 * PI)) * c as f64;
            }
        }
        sum * 2.0 * std::f64::consts::PI / (nc * np) as f64
    };
    for theta_o in [5f32, 30.0, 60.0, 85.0] {
        let t = theta_o.to_radians();
        let wo = Vec3::new(t.sin(), 0.0, t.cos());
        for roughness in [0.3f32, 0.7] {
            let m = coated(lambert, roughness, 0.0);
            let energy = quad(&|wi| bsdf_eval(&m, wo, wi, 1.5).y as f64);
            let a = roughness * roughness;
            let e_ggx = quad(&|wi| {
                let h = (wo + wi).normalize();
                (ggx_d(h, a) * ggx_g2(wo, wi, a) / (4.0 * wo.z * wi.z)) as f64
            });
            let w = 0.04 + 0.96 * (1.0 - wo.z as f64).powi(5);
            let expected = 1.0 - w + w * e_ggx;
            assert!(
                (energy - expected).abs() < 2e-3,
                "coat r={roughness} θo={theta_o}: energy {energy}, model {expected} (E_ggx {e_ggx})"
            );
        }
        for roughness in [0.1f32, 0.4, 1.0] {
            let m = pack_material(&sheened(lambert, Vec3::ONE, roughness), &[]);
            let energy = quad(&|wi| bsdf_eval(&m, wo, wi, 1.5).y as f64);
            let e_max = (0..=100).map(|i| sheen_albedo(i as f32 / 100.0, roughness)).fold(0.0f32, f32::max) as f64;
            let loss_bound = e_max - sheen_albedo(wo.z, roughness) as f64;
            assert!(energy <= 1.0 + 2e-3, "sheen r={roughness} θo={theta_o}: energy {energy} above 1");
            assert!(
                energy >= 1.0 - loss_bound - 2e-3,
                "sheen r={roughness} θo={theta_o}: energy {energy} loses more than {loss_bound}"
            );
        }
    }
}

/// A smooth coat (roughness 0, the extension's default) is a Dirac lobe: sampled with the
/// coat's Fresnel weight as its expected value, found neither by eval nor pdf.
#[test]
fn a_smooth_coat_is_a_mirror_of_its_fresnel_weight() {
    let black = Material { base_color: Vec3::ZERO, metallic: 0.0, specular_factor: 0.0, ..Material::default() };
    let m = coated(black, 0.0, 0.2);
    let nc = Vec3::from(m.coat_normal);
    let mut rng = Lcg(5);
    for theta_o in [10f32, 50.0, 75.0] {
        let t = theta_o.to_radians();
        let wo = Vec3::new(t.sin(), 0.0, t.cos());
        let expected = 0.04 + 0.96 * (1.0 - nc.dot(wo)).powi(5);
        let n = 20_000;
        let mut sum = 0.0f64;
        for _ in 0..n {
            let s = bsdf_sample(&m, wo, Vec3::new(rng.f(), rng.f(), rng.f()), 1.5);
            if s.pdf > 0.0 {
                assert!(s.delta, "θo={theta_o}: a black base under a smooth coat has only the coat's mirror");
                let mirror = 2.0 * wo.dot(nc) * nc - wo;
                assert!((s.wi - mirror).length() < 1e-5, "θo={theta_o}: {} is not the mirror {mirror}", s.wi);
                sum += s.weight.y as f64;
            }
        }
        let mean = sum / n as f64;
        assert!((mean - expected as f64).abs() < 1e-4, "θo={theta_o}: mean weight {mean}, coat Fresnel {expected}");
        let mirror = 2.0 * wo.dot(nc) * nc - wo;
        assert_eq!(bsdf_eval(&m, wo, mirror, 1.5), Vec3::ZERO);
        assert_eq!(bsdf_pdf(&m, wo, mirror, 1.5), 0.0);
    }
}

/// A smooth thin wall lets light straight through (wi = −wo) with 1 − F of the sheet's ior,
/// as a Dirac lobe: no bending, no 1/η² (the light leaves into the medium it came from).
#[test]
fn a_smooth_thin_wall_passes_light_straight_through() {
    use veach::cpu::bsdf::fresnel_dielectric;
    let m = thin(0.0, 1.0);
    let mut rng = Lcg(9);
    for theta_o in [0f32, 30.0, 60.0, 80.0] {
        let t = theta_o.to_radians();
        let wo = Vec3::new(t.sin(), 0.0, t.cos());
        let (n, mut through) = (20_000, 0.0f64);
        for _ in 0..n {
            let s = bsdf_sample(&m, wo, Vec3::new(rng.f(), rng.f(), rng.f()), 1.5);
            assert!(s.delta && s.pdf > 0.0, "θo={theta_o}: {s:?}");
            if s.wi.z < 0.0 {
                assert!((s.wi + wo).length() < 1e-6, "θo={theta_o}: {} bent from {}", s.wi, -wo);
                through += s.weight.x as f64;
            }
        }
        let expected = 1.0 - fresnel_dielectric(wo.z, 1.5) as f64;
        let got = through / n as f64;
        assert!((got - expected).abs() < 0.01 * expected, "θo={theta_o}: transmitted {got}, 1 − F = {expected}");
    }
}

/// Rough glass of ior 1 bends nothing: whatever its roughness, light passes straight through
/// (wi = −wo, a Dirac lobe) with weight 1 − F = 1; within 5e-5 of ior 1, from either side, the
/// refracted lobe is about as narrow as a mirror's (a Dirac lobe below DELTA_ALPHA's width),
/// within 1e-2 of −wo. Its eval and
/// pdf stay finite everywhere (the generalised half vector ωo + η ωi vanishes at η = 1).
#[test]
fn rough_glass_of_ior_one_passes_light_straight_through() {
    let mut rng = Lcg(31);
    for roughness in [0.1f32, 0.5, 1.0] {
        for eta in [1.0f32, 1.00005, 1.0 / 1.00005] {
            let m = glass(roughness, 1.0);
            for theta_o in [0f32, 30.0, 60.0, 85.0] {
                let t = theta_o.to_radians();
                let wo = Vec3::new(t.sin(), 0.0, t.cos());
                let what = format!("roughness {roughness} η={eta} θo={theta_o}");
                let (n, mut through) = (4000, 0.0f64);
                for _ in 0..n {
                    let s = bsdf_sample(&m, wo, Vec3::new(rng.f(), rng.f(), rng.f()), eta);
                    assert!(s.pdf > 0.0 && s.weight.is_finite(), "{what}: {s:?}");
                    if s.wi.z < 0.0 {
                        assert!(s.delta || eta != 1.0, "{what}: a rough transmission sample {s:?}");
                        let tol = if eta == 1.0 { 1e-6 } else { 1e-2 };
                        assert!((s.wi + wo).length() < tol, "{what}: {} bent from {}", s.wi, -wo);
                    }
                    through += s.weight.y as f64 * (s.wi.z < 0.0) as u32 as f64;
                    let wi = direction(2.0 * rng.f() - 1.0, 2.0 * PI * rng.f());
                    let (f, pdf) = (bsdf_eval(&m, wo, wi, eta), bsdf_pdf(&m, wo, wi, eta));
                    assert!(f.is_finite() && pdf.is_finite(), "{what}: f {f} pdf {pdf} at {wi}");
                }
                let got = through / n as f64;
                assert!((got - 1.0).abs() < 1e-3, "{what}: transmitted {got}, expected 1");
            }
        }
    }
}

/// Near ior 1 the sampler and the pdf still agree: glass that transmits half (a Lambertian
/// base under the rest) at η = 1.0001, where the refracted lobe is a Dirac one (its mass the
/// harness's lost-sample bin), and at η = 1.05, where it is a GGX lobe 5 % of α wide.
#[test]
fn near_ior_one_sampling_matches_pdf_chi_square() {
    let bins = chi2::SphereBins { theta: 20, phi: 40, sub: 32, pole_sub: 256 };
    let mut rng = Lcg(37);
    let cases = [(1.0001f32, 0.5f32), (1.0 / 1.0001, 0.5), (1.05, 1.0), (1.0 / 1.05, 1.0)];
    for (eta, roughness) in cases {
        let m = glass(roughness, 0.5);
        // The η = 1.05 lobe is narrow enough that, away from the pole's finer cells, the
        // midpoint rule misses ~4e-4 of its mass: it is tested where the bins resolve it.
        let angles: &[f32] = if (eta - 1.0).abs() < 1e-3 { &[10.0, 45.0, 80.0] } else { &[10.0] };
        for &theta_o in angles {
            let t = theta_o.to_radians();
            let wo = Vec3::new(t.sin(), 0.0, t.cos());
            let what = format!("η={eta} roughness {roughness} θo={theta_o}");
            let sample = || {
                let s = bsdf_sample(&m, wo, Vec3::new(rng.f(), rng.f(), rng.f()), eta);
                if s.pdf <= 0.0 || s.delta {
                    return None;
                }
                let pdf = bsdf_pdf(&m, wo, s.wi, eta);
                assert!((pdf - s.pdf).abs() <= 1e-3 * pdf, "{what}: sample pdf {} vs pdf() {pdf}", s.pdf);
                Some(s.wi)
            };
            let r = chi2::sphere(&what, bins, 400_000, sample, |wi| bsdf_pdf(&m, wo, wi, eta) as f64);
            assert!(r.total < 1.0 + 2e-3, "{what}: pdf integrates to {}", r.total);
            r.assert_passes(&what, 0.01, 8);
        }
    }
}

/// Anisotropy stretches the lobe along its direction: at normal incidence the sampled
/// reflections' spread is widest along the anisotropy tangent (an eigenvector of their
/// second moments, within 3°), and wider than across it by far at strength 0.9.
#[test]
fn anisotropy_stretches_the_lobe_along_its_direction() {
    let base = Material { metallic: 1.0, ..plastic(0.9, 0.3) };
    let mut m = pack_material(&Material { anisotropy: 0.9, ..base }, &[]);
    let phi = 0.7f32;
    m.anisotropy_tangent = [phi.cos(), phi.sin()];
    let wo = Vec3::Z;
    let mut rng = Lcg(31);
    let (mut sxx, mut syy, mut sxy) = (0.0f64, 0.0f64, 0.0f64);
    for _ in 0..50_000 {
        let s = bsdf_sample(&m, wo, Vec3::new(rng.f(), rng.f(), rng.f()), 1.5);
        if s.pdf > 0.0 {
            let (x, y) = (s.wi.x as f64, s.wi.y as f64);
            sxx += x * x;
            syy += y * y;
            sxy += x * y;
        }
    }
    // Major axis of the 2×2 moment matrix.
    let angle = 0.5 * (2.0 * sxy).atan2(sxx - syy);
    let (c, s) = (angle.cos(), angle.sin());
    let along = c * c * sxx + 2.0 * c * s * sxy + s * s * syy;
    let across = s * s * sxx - 2.0 * c * s * sxy + c * c * syy;
    let off = ((angle - phi as f64 + std::f64::consts::FRAC_PI_2).rem_euclid(std::f64::consts::PI)
        - std::f64::consts::FRAC_PI_2)
        .abs();
    assert!(off < 3f64.to_radians(), "lobe's long axis at {angle} rad, anisotropy direction at {phi}");
    assert!(along > 4.0 * across, "spread along {along} vs across {across}");
}

/// The thin film of KHR_materials_iridescence: a vanishing film reflects at normal incidence
/// what the base does (the film's ior fades to the outside's; the fit's harmonics leave
/// < 0.01); a 350 nm film of ior 1.3 colours the
/// reflection (its channels differ by more than a tenth at some angle) and stays in [0, 1]
/// at every angle, thickness and base.
#[test]
fn thin_films_fade_to_the_base_and_stay_in_range() {
    use veach::cpu::iridescence::iridescence_fresnel;
    for f0 in [0.04f32, 0.2, 0.9] {
        let got = iridescence_fresnel(1.0, 1.3, 1.0, 0.0, Vec3::splat(f0));
        assert!((got - Vec3::splat(f0)).abs().max_element() < 0.01, "f0 {f0}: {got} at normal incidence");
    }
    let mut spread = 0.0f32;
    for i in 0..=20 {
        let c = i as f32 / 20.0;
        for thickness in [50.0f32, 200.0, 350.0, 800.0] {
            for base in [Vec3::splat(0.04), Vec3::new(0.9, 0.6, 0.3)] {
                let f = iridescence_fresnel(1.0, 1.3, c, thickness, base);
                assert!(f.min_element() >= 0.0 && f.max_element() <= 1.0 && f.is_finite(), "{f}");
                if thickness == 350.0 {
                    spread = spread.max(f.max_element() - f.min_element());
                }
            }
        }
    }
    assert!(spread > 0.1, "a 350 nm film does not colour its reflection (spread {spread})");
}

/// KHR_materials_diffuse_transmission moves a share of the Lambertian lobe to the other side
/// in its own colour: with specular 0 (no Fresnel), a quadrature of f·|cos| gives
/// (1 − share)·base colour above the surface and share·transmission colour below, from every
/// angle, and the sum of a white one is 1.
#[test]
fn diffuse_transmission_moves_its_share_to_the_other_side() {
    let (base, color, share) = (Vec3::new(0.2, 0.6, 0.9), Vec3::new(0.9, 0.5, 0.1), 0.3);
    let m = pack_material(
        &translucent(
            Material { base_color: base, metallic: 0.0, specular_factor: 0.0, ..Material::default() },
            share,
            color,
        ),
        &[],
    );
    for theta_o in [0f32, 40.0, 85.0] {
        let t = theta_o.to_radians();
        let wo = Vec3::new(t.sin(), 0.0, t.cos());
        let (nc, np) = (400usize, 100usize);
        let (mut above, mut below) = (glam::DVec3::ZERO, glam::DVec3::ZERO);
        for i in 0..nc {
            let c = -1.0 + 2.0 * (i as f32 + 0.5) / nc as f32;
            for j in 0..np {
                let wi = direction(c, (j as f32 + 0.5) / np as f32 * 2.0 * PI);
                let fc = (bsdf_eval(&m, wo, wi, 1.5) * c.abs()).as_dvec3();
                if c > 0.0 { above += fc } else { below += fc }
            }
        }
        let scale = 4.0 * std::f64::consts::PI / (nc * np) as f64;
        let (above, below) = (above * scale, below * scale);
        let (want_above, want_below) = (((1.0 - share) * base).as_dvec3(), (share * color).as_dvec3());
        assert!((above - want_above).abs().max_element() < 1e-3, "θo={theta_o}: reflected {above}, want {want_above}");
        assert!(
            (below - want_below).abs().max_element() < 1e-3,
            "θo={theta_o}: transmitted {below}, want {want_below}"
        );
    }
}

/// tests/data/principled.json: Mitsuba 3's own BSDF values (bench/principled_reference.py).
fn principled_reference() -> serde_json::Value {
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/principled.json");
    serde_json::from_slice(&std::fs::read(&path).unwrap()).unwrap()
}

/// A JSON array of three numbers.
fn v3(v: &serde_json::Value) -> Vec3 {
    Vec3::new(v[0].as_f64().unwrap() as f32, v[1].as_f64().unwrap() as f32, v[2].as_f64().unwrap() as f32)
}

/// Mitsuba 3's `principled` BSDF with metallic 1 is the same lobe as glTF's metal under
/// KHR_materials_anisotropy: GGX with Schlick's Fresnel toward the base colour, its α along
/// and across the tangent from Disney's aspect (tests/data/principled.json, made by
/// bench/principled_reference.py: Mitsuba's own `eval` on 144 view/light pairs per case). The
/// parameterisations map exactly (veach: α_b = roughness², α_t = mix(α_b, 1, strength²)). The
/// one model difference is masking-shadowing: Mitsuba's is separable, G1(v)·G1(l), veach's
/// height-correlated, 1/(1 + Λ(v) + Λ(l)); with that factor (computed here from Λ's
/// definition) taken out the two agree to 0.01 %, and veach is never below Mitsuba before.
#[test]
fn metal_and_anisotropy_match_mitsubas_principled_bsdf() {
    let data = principled_reference();
    let base = v3(&data["base_color"]);
    let cases = data["cases"].as_array().unwrap();
    assert_eq!(cases.len(), 3);
    for case in cases {
        let name = case["name"].as_str().unwrap();
        let (ax, ay) = (case["alpha_x"].as_f64().unwrap(), case["alpha_y"].as_f64().unwrap());
        let strength = ((ax - ay) / (1.0 - ay)).max(0.0).sqrt() as f32;
        let m = pack_material(
            &Material {
                base_color: base,
                metallic: 1.0,
                roughness: (ay.sqrt()) as f32,
                anisotropy: strength,
                ..Material::default()
            },
            &[],
        );
        let lambda = |w: Vec3| {
            let (x, y, z) = (w.x as f64, w.y as f64, w.z as f64);
            0.5 * ((1.0 + (ax * ax * x * x + ay * ay * y * y) / (z * z)).sqrt() - 1.0)
        };
        let samples = case["samples"].as_array().unwrap();
        assert_eq!(samples.len(), 144, "{name}");
        let mut worst = 0.0f64;
        for s in samples {
            let (view, light, want) = (v3(&s["view"]), v3(&s["light"]), v3(&s["f_cos"]).as_dvec3());
            let got = (bsdf_eval(&m, view, light, 1.5) * light.z).as_dvec3();
            let (lv, ll) = (lambda(view), lambda(light));
            let separable_over_correlated = (1.0 + lv + ll) / ((1.0 + lv) * (1.0 + ll));
            let explained = got * separable_over_correlated;
            for c in 0..3 {
                assert!(
                    got[c] >= want[c] * (1.0 - 1e-4) - 1e-7,
                    "{name} v={view} l={light}: veach {got} below Mitsuba {want}"
                );
                let err = (explained[c] - want[c]).abs();
                assert!(
                    err <= 1e-3 * want[c] + 1e-6,
                    "{name} v={view} l={light}: veach {got} (×G ratio {explained}) vs Mitsuba {want}"
                );
                worst = worst.max(err / want[c].max(1e-6));
            }
        }
        eprintln!("{name}: worst relative difference {worst:.2e} after the masking factor");
    }
}

/// Below the surface Mitsuba 3's `principledthin` (eta 1: no specular; Disney's diff_trans =
/// 2 × the share) is KHR_materials_diffuse_transmission's Lambertian lobe with the base
/// colour as its colour (tests/data/principled.json): veach's transmitted f·|cos| is the same
/// to 0.01 %. (Above the surface principledthin has Disney's retro-reflective diffuse, which
/// glTF does not model.)
#[test]
fn diffuse_transmission_matches_mitsubas_thin_principled_bsdf() {
    let data = principled_reference();
    let base = v3(&data["base_color"]);
    let dt = &data["diffuse_transmission"];
    let share = dt["share"].as_f64().unwrap() as f32;
    let m = pack_material(
        &translucent(
            Material { base_color: base, metallic: 0.0, roughness: 0.5, specular_factor: 0.0, ..Material::default() },
            share,
            base,
        ),
        &[],
    );
    let samples = dt["samples"].as_array().unwrap();
    assert_eq!(samples.len(), 36);
    for s in samples {
        let (view, light, want) = (v3(&s["view"]), v3(&s["light"]), v3(&s["f_cos"]).as_dvec3());
        assert!(light.z < 0.0);
        let got = (bsdf_eval(&m, view, light, 1.5) * -light.z).as_dvec3();
        for c in 0..3 {
            assert!(
                (got[c] - want[c]).abs() <= 1e-4 * want[c] + 1e-7,
                "v={view} l={light}: veach {got} vs Mitsuba {want}"
            );
        }
    }
}
