//! BSDF sampling is right: `sample` draws directions with the density `pdf` says (chi-square
//! over the sphere, as pbrt and Mitsuba test theirs), and `eval·cos/pdf` averages to the
//! albedo a quadrature of `eval·cos` gives. Rough glass (KHR_materials_transmission) is
//! tested from both sides, entering (η = 1.5) and leaving (η = 1/1.5, with total internal
//! reflection).

mod common;

use common::rng::Lcg;

use common::chi2::{self, direction};
use glam::Vec3;
use std::f32::consts::PI;
use veach::cpu::bsdf::{bsdf_eval, bsdf_pdf, bsdf_sample};
use veach::packed::{Material as PackedMaterial, pack_material};
use veach::scene::Material;

fn material(base: f32, metallic: f32, roughness: f32, specular: f32) -> PackedMaterial {
    pack_material(&Material {
        base_color: Vec3::new(base, base * 0.8, base * 0.6),
        metallic,
        roughness,
        specular_factor: specular,
        ..Material::default()
    })
}

fn glass(roughness: f32, transmission: f32) -> PackedMaterial {
    pack_material(&Material { base_color: Vec3::ONE, metallic: 0.0, roughness, transmission, ..Material::default() })
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
            // Quadrature of f·|cos| over the sphere in (cos θ, φ); the transmitted part also
            // times η², which undoes the radiance scaling: that sum is the energy kept.
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
                    energy += fc.y * if c < 0.0 { (eta * eta) as f64 } else { 1.0 };
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
    for roughness in [0.0101, 0.0106, 0.012, 0.016] {
        for m in [material(0.9, 1.0, roughness, 1.0), material(0.5, 0.0, roughness, 1.0), glass(roughness, 1.0)] {
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
