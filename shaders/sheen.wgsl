// KHR_materials_sheen's lobe: the "Charlie" sheen of Estevez & Kulla (2017), fibres around the
// normal with an exponentiated-sine distribution and their fitted Smith visibility, and the
// directional albedo table (computed on the host by quadrature, in light_data from
// params.sheen_base) that scales the base under it. Twin: src/sheen.rs.
#include "bindings.wgsl"

const SHEEN_MIN_ROUGHNESS: f32 = 0.07;
const SHEEN_TABLE_COS: u32 = 32u;
const SHEEN_TABLE_ROUGHNESS: u32 = 32u;

// The table's coordinates of (cos θ, roughness): √cos θ and √((r − r_min)/(1 − r_min)).
fn sheen_table_coords(cos_theta: f32, roughness: f32) -> vec2<f32> {
    let r = (clamp(roughness, SHEEN_MIN_ROUGHNESS, 1.0) - SHEEN_MIN_ROUGHNESS) / (1.0 - SHEEN_MIN_ROUGHNESS);
    return vec2<f32>(sqrt(clamp(cos_theta, 0.0, 1.0)), sqrt(r));
}

fn sheen_alpha(roughness: f32) -> f32 {
    let r = clamp(roughness, SHEEN_MIN_ROUGHNESS, 1.0);
    return r * r;
}

fn charlie_d(cos_h: f32, alpha: f32) -> f32 {
    let inv = 1.0 / alpha;
    let sin2 = max(1.0 - cos_h * cos_h, 0.0);
    if (sin2 <= 0.0) {
        return 0.0;
    }
    return (2.0 + inv) * pow(sin2, 0.5 * inv) / (2.0 * PI);
}

fn sheen_l(x: f32, alpha: f32) -> f32 {
    let t = (1.0 - alpha) * (1.0 - alpha);
    let a = mix(21.5473, 25.3245, t);
    let b = mix(3.82987, 3.32435, t);
    let c = mix(0.19823, 0.16801, t);
    let d = mix(-1.97760, -1.27393, t);
    let e = mix(-4.32054, -4.85967, t);
    return a / (1.0 + b * pow(max(x, 0.0), c)) + d * x + e;
}

fn sheen_lambda(cos_theta: f32, alpha: f32) -> f32 {
    let c = abs(cos_theta);
    if (c < 0.5) {
        return exp(sheen_l(c, alpha));
    }
    return exp(2.0 * sheen_l(0.5, alpha) - sheen_l(1.0 - c, alpha));
}

fn sheen_brdf(wo: vec3<f32>, wi: vec3<f32>, roughness: f32) -> f32 {
    if (wo.z <= 0.0 || wi.z <= 0.0) {
        return 0.0;
    }
    let alpha = sheen_alpha(roughness);
    let h = normalize(wo + wi);
    let g2 = 1.0 / (1.0 + sheen_lambda(wo.z, alpha) + sheen_lambda(wi.z, alpha));
    return charlie_d(h.z, alpha) * g2 / (4.0 * wo.z * wi.z);
}

fn sheen_table(i: u32) -> f32 {
    return light_data[params.sheen_base + i / 4u][i % 4u];
}

fn sheen_albedo(cos_theta: f32, roughness: f32) -> f32 {
    let c = sheen_table_coords(cos_theta, roughness);
    let x = c.x * f32(SHEEN_TABLE_COS - 1u);
    let y = c.y * f32(SHEEN_TABLE_ROUGHNESS - 1u);
    let x0 = min(u32(floor(x)), SHEEN_TABLE_COS - 2u);
    let y0 = min(u32(floor(y)), SHEEN_TABLE_ROUGHNESS - 2u);
    let fx = x - f32(x0);
    let fy = y - f32(y0);
    let r0 = y0 * SHEEN_TABLE_COS + x0;
    let r1 = r0 + SHEEN_TABLE_COS;
    let top = sheen_table(r0) + (sheen_table(r0 + 1u) - sheen_table(r0)) * fx;
    let bottom = sheen_table(r1) + (sheen_table(r1 + 1u) - sheen_table(r1)) * fx;
    return top + (bottom - top) * fy;
}

fn sheen_albedo_scaling(color: vec3<f32>, roughness: f32, cos_o: f32, cos_i: f32) -> f32 {
    let c = max_component(color);
    return min(1.0 - c * sheen_albedo(cos_o, roughness), 1.0 - c * sheen_albedo(cos_i, roughness));
}
