//! Twin of `shaders/sheen.wgsl`: KHR_materials_sheen's lobe, the "Charlie" sheen of Estevez &
//! Kulla (2017) — an exponentiated-sine distribution of fibres around the normal with their
//! fitted Smith visibility — and the directional albedo table that scales the base under it
//! (the extension's albedo scaling). Shared by the packing (which puts the table in the light
//! data the kernel reads) and the CPU engine, as `adaptive.rs` is.

use glam::Vec3;
use std::f32::consts::PI;
use std::sync::OnceLock;

/// Sheen roughness is clamped to this: at 0 the distribution is a Dirac at the horizon that
/// no sample finds (inv α = 200 at the clamp is already a rim a few degrees wide).
pub const SHEEN_MIN_ROUGHNESS: f32 = 0.07;
/// Albedo table resolution: cos θ by sheen roughness, bilinear in √cos θ and
/// √((r − r_min)/(1 − r_min)), where the albedo changes fastest: at grazing angles and low
/// roughness (1/α runs from 204 to 56 between r = 0.07 and 0.13).
pub const SHEEN_TABLE_COS: u32 = 32;
pub const SHEEN_TABLE_ROUGHNESS: u32 = 32;

/// The table's coordinates of (cos θ, roughness), in [0, 1]².
pub fn sheen_table_coords(cos_theta: f32, roughness: f32) -> (f32, f32) {
    let r = (roughness.clamp(SHEEN_MIN_ROUGHNESS, 1.0) - SHEEN_MIN_ROUGHNESS) / (1.0 - SHEEN_MIN_ROUGHNESS);
    (cos_theta.clamp(0.0, 1.0).sqrt(), r.sqrt())
}

/// α of the distribution for a sheen roughness: r² as the extension says.
pub fn sheen_alpha(roughness: f32) -> f32 {
    let r = roughness.clamp(SHEEN_MIN_ROUGHNESS, 1.0);
    r * r
}

/// D(h) = (2 + 1/α) sin^(1/α) θh / 2π.
pub fn charlie_d(cos_h: f32, alpha: f32) -> f32 {
    let inv = 1.0 / alpha;
    let sin2 = (1.0 - cos_h * cos_h).max(0.0);
    if sin2 <= 0.0 {
        return 0.0;
    }
    (2.0 + inv) * sin2.powf(0.5 * inv) / (2.0 * PI)
}

/// The fitted exponent of Λ (Estevez & Kulla's table 1, interpolated by (1 − α)²).
fn sheen_l(x: f32, alpha: f32) -> f32 {
    let t = (1.0 - alpha) * (1.0 - alpha);
    let lerp = |a: f32, b: f32| a + (b - a) * t;
    let (a, b, c) = (lerp(21.5473, 25.3245), lerp(3.82987, 3.32435), lerp(0.19823, 0.16801));
    let (d, e) = (lerp(-1.97760, -1.27393), lerp(-4.32054, -4.85967));
    a / (1.0 + b * x.max(0.0).powf(c)) + d * x + e
}

/// Λ(θ) of the sheen's fibres, mirrored about cos θ = ½ as the fit prescribes.
pub fn sheen_lambda(cos_theta: f32, alpha: f32) -> f32 {
    let c = cos_theta.abs();
    if c < 0.5 { sheen_l(c, alpha).exp() } else { (2.0 * sheen_l(0.5, alpha) - sheen_l(1.0 - c, alpha)).exp() }
}

/// f(wo, wi) of a white sheen (local frame, both above the surface): D · G2 / (4 cos cos).
pub fn sheen_brdf(wo: Vec3, wi: Vec3, roughness: f32) -> f32 {
    if wo.z <= 0.0 || wi.z <= 0.0 {
        return 0.0;
    }
    let alpha = sheen_alpha(roughness);
    let h = (wo + wi).normalize();
    let g2 = 1.0 / (1.0 + sheen_lambda(wo.z, alpha) + sheen_lambda(wi.z, alpha));
    charlie_d(h.z, alpha) * g2 / (4.0 * wo.z * wi.z)
}

/// E(μ, r) = ∫ f cos θi dωi of a white sheen, on the table's grid by quadrature (computed
/// once): cos θi = t² puts the nodes where the low-roughness lobe lives, at grazing angles.
pub fn sheen_albedo_table() -> &'static [f32] {
    static TABLE: OnceLock<Vec<f32>> = OnceLock::new();
    TABLE.get_or_init(|| {
        let (nt, np) = (96usize, 48usize);
        let mut table = Vec::with_capacity((SHEEN_TABLE_COS * SHEEN_TABLE_ROUGHNESS) as usize);
        for j in 0..SHEEN_TABLE_ROUGHNESS {
            let y = j as f32 / (SHEEN_TABLE_ROUGHNESS - 1) as f32;
            let r = SHEEN_MIN_ROUGHNESS + (1.0 - SHEEN_MIN_ROUGHNESS) * y * y;
            for i in 0..SHEEN_TABLE_COS {
                // The first node is just above grazing, where the albedo is finite.
                let x = i as f32 / (SHEEN_TABLE_COS - 1) as f32;
                let mu = (x * x).max(1e-3);
                let wo = Vec3::new((1.0 - mu * mu).sqrt(), 0.0, mu);
                let mut sum = 0.0f64;
                for a in 0..nt {
                    let t = (a as f32 + 0.5) / nt as f32;
                    let c = t * t;
                    let s = (1.0 - c * c).max(0.0).sqrt();
                    // φ over [0, π], doubled: the lobe is symmetric about the plane of wo.
                    for b in 0..np {
                        let phi = (b as f32 + 0.5) / np as f32 * PI;
                        let wi = Vec3::new(s * phi.cos(), s * phi.sin(), c);
                        sum += (sheen_brdf(wo, wi, r) * c * 2.0 * t) as f64;
                    }
                }
                table.push((sum * 2.0 * std::f64::consts::PI / (nt * np) as f64) as f32);
            }
        }
        table
    })
}

/// The table as rows of four for the light-data buffer.
pub fn sheen_albedo_rows() -> Vec<[f32; 4]> {
    sheen_albedo_table().chunks(4).map(|c| [c[0], c[1], c[2], c[3]]).collect()
}

/// Bilinear lookup of E(cos θ, roughness) in `texel(i)` = table entry i.
pub fn sheen_albedo_lookup(texel: impl Fn(u32) -> f32, cos_theta: f32, roughness: f32) -> f32 {
    let (u, v) = sheen_table_coords(cos_theta, roughness);
    let x = u * (SHEEN_TABLE_COS - 1) as f32;
    let y = v * (SHEEN_TABLE_ROUGHNESS - 1) as f32;
    let (x0, y0) = ((x.floor() as u32).min(SHEEN_TABLE_COS - 2), (y.floor() as u32).min(SHEEN_TABLE_ROUGHNESS - 2));
    let (fx, fy) = (x - x0 as f32, y - y0 as f32);
    let at = |i: u32, j: u32| texel(j * SHEEN_TABLE_COS + i);
    let top = at(x0, y0) + (at(x0 + 1, y0) - at(x0, y0)) * fx;
    let bottom = at(x0, y0 + 1) + (at(x0 + 1, y0 + 1) - at(x0, y0 + 1)) * fx;
    top + (bottom - top) * fy
}

/// E(cos θ, roughness) from the table.
pub fn sheen_albedo(cos_theta: f32, roughness: f32) -> f32 {
    let table = sheen_albedo_table();
    sheen_albedo_lookup(|i| table[i as usize], cos_theta, roughness)
}

/// The factor under the sheen (the extension's albedo scaling): the base gets what the sheen's
/// fibres let through from both directions.
pub fn sheen_albedo_scaling(color: Vec3, roughness: f32, cos_o: f32, cos_i: f32) -> f32 {
    let c = color.max_element();
    (1.0 - c * sheen_albedo(cos_o, roughness)).min(1.0 - c * sheen_albedo(cos_i, roughness))
}
