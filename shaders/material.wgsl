// The material at a surface point: glTF factors times textures (base color and alpha,
// metallic-roughness with G = roughness and B = metallic, emissive), alpha for MASK and
// BLEND, and the shading normal with the normal map applied in the vertex tangent frame.
// Twin: src/cpu/material.rs.
#include "bindings.wgsl"
#include "rng.wgsl"
#include "frame.wgsl"
#include "texture.wgsl"
#include "instance.wgsl"

// TEXCOORD_0 (xy) and TEXCOORD_1 (zw; 0 without it) at barycentrics (u, v) of vertices 1
// and 2. A triangle's TEXCOORD_1 and COLOR_0 are an Attributes record of the region from
// params.extras_base (src/packed/geometry.rs, pack_extras).
fn triangle_uv(index: u32, u: f32, v: f32) -> vec4<f32> {
    let a = load_attributes(index);
    var uv1 = vec2<f32>(0.0);
    if (VERTEX_EXTRAS) {
        let e = load_attributes(params.extras_base + index);
        uv1 = (1.0 - u - v) * e.uv0 + u * e.uv1 + v * e.uv2;
    }
    return vec4<f32>((1.0 - u - v) * a.uv0 + u * a.uv1 + v * a.uv2, uv1);
}

// COLOR_0 at barycentrics (u, v) (white without it): per vertex two words of 16-bit unorm,
// (r, g) and (b, a), in the record's normal and tangent words.
fn vertex_color(index: u32, u: f32, v: f32) -> vec4<f32> {
    if (!VERTEX_EXTRAS) {
        return vec4<f32>(1.0);
    }
    let e = load_attributes(params.extras_base + index);
    let c0 = vec4<f32>(unpack2x16unorm(e.n.x), unpack2x16unorm(e.n.y));
    let c1 = vec4<f32>(unpack2x16unorm(e.n.z), unpack2x16unorm(e.t0));
    let c2 = vec4<f32>(unpack2x16unorm(e.t12.x), unpack2x16unorm(e.t12.y));
    return (1.0 - u - v) * c0 + u * c1 + v * c2;
}

// The material at a surface point: its factors times its textures at `uv` (both UV sets) and
// the vertex colour `color` (COLOR_0 multiplies the base colour and alpha).
fn material_at(m: Material, uv: vec4<f32>, color: vec4<f32>) -> Material {
    var r = m;
    if (VERTEX_EXTRAS) {
        r.base_color = m.base_color * color.xyz;
        r.alpha = m.alpha * color.w;
    }
    if (TEXTURES && m.base_color_texture.atlas != NO_TEXTURE) {
        let c = sample_texture(m.base_color_texture, uv);
        r.base_color = r.base_color * c.xyz;
        r.alpha = r.alpha * c.w;
    }
    if (TEXTURES && m.metallic_roughness_texture.atlas != NO_TEXTURE) {
        let c = sample_texture(m.metallic_roughness_texture, uv);
        r.roughness = m.roughness * c.y;
        r.metallic = m.metallic * c.z;
    }
    if (TEXTURES && m.emissive_texture.atlas != NO_TEXTURE) {
        r.emission = m.emission * sample_texture(m.emissive_texture, uv).xyz;
    }
    if (TEXTURES && TRANSMISSION && m.transmission_texture.atlas != NO_TEXTURE) {
        r.transmission = m.transmission * sample_texture(m.transmission_texture, uv).x;
    }
    if (TEXTURES && (m.specular_texture.atlas != NO_TEXTURE || m.specular_color_texture.atlas != NO_TEXTURE)) {
        var factor = m.dielectric_f90;
        var f0 = m.specular_f0;
        if (m.specular_texture.atlas != NO_TEXTURE) {
            factor *= sample_texture(m.specular_texture, uv).w;
        }
        if (m.specular_color_texture.atlas != NO_TEXTURE) {
            f0 *= sample_texture(m.specular_color_texture, uv).xyz;
        }
        r.dielectric_f0 = min(f0, vec3<f32>(1.0)) * factor;
        r.dielectric_f90 = factor;
    }
    if (TEXTURES && CLEARCOAT && m.clearcoat_texture.atlas != NO_TEXTURE) {
        r.clearcoat = m.clearcoat * sample_texture(m.clearcoat_texture, uv).x;
    }
    if (TEXTURES && CLEARCOAT && m.clearcoat_roughness_texture.atlas != NO_TEXTURE) {
        r.clearcoat_roughness = m.clearcoat_roughness * sample_texture(m.clearcoat_roughness_texture, uv).y;
    }
    if (TEXTURES && SHEEN && m.sheen_color_texture.atlas != NO_TEXTURE) {
        r.sheen_color = m.sheen_color * sample_texture(m.sheen_color_texture, uv).xyz;
    }
    if (TEXTURES && SHEEN && m.sheen_roughness_texture.atlas != NO_TEXTURE) {
        r.sheen_roughness = m.sheen_roughness * sample_texture(m.sheen_roughness_texture, uv).w;
    }
    if (TEXTURES && ANISOTROPY && m.anisotropy_texture.atlas != NO_TEXTURE) {
        r.anisotropy = m.anisotropy * sample_texture(m.anisotropy_texture, uv).z;
    }
    if (TEXTURES && IRIDESCENCE && m.iridescence_texture.atlas != NO_TEXTURE) {
        r.iridescence = m.iridescence * sample_texture(m.iridescence_texture, uv).x;
    }
    if (TEXTURES && IRIDESCENCE && m.iridescence_thickness_texture.atlas != NO_TEXTURE) {
        let t = sample_texture(m.iridescence_thickness_texture, uv).y;
        r.iridescence_thickness_max = mix(m.iridescence_thickness_min, m.iridescence_thickness_max, t);
    }
    if (TEXTURES && DIFFUSE_TRANSMISSION && m.diffuse_transmission_texture.atlas != NO_TEXTURE) {
        r.diffuse_transmission = m.diffuse_transmission * sample_texture(m.diffuse_transmission_texture, uv).w;
    }
    if (TEXTURES && DIFFUSE_TRANSMISSION && m.diffuse_transmission_color_texture.atlas != NO_TEXTURE) {
        r.diffuse_transmission_color = m.diffuse_transmission_color
            * sample_texture(m.diffuse_transmission_color_texture, uv).xyz;
    }
    return r;
}

// Wavelengths (nm) the colour channels stand for under KHR_materials_dispersion: Fraunhofer's
// C, d and F lines, whose iors define the Abbe number.
const CHANNEL_WAVELENGTHS = array<f32, 3>(656.3, 587.6, 486.1);

// KHR_materials_dispersion's ior at colour channel `channel`: Cauchy's n(λ) = A + B/λ² through
// `ior` at 587.6 nm with Abbe number 20 / dispersion, at least 1.
fn dispersed_ior(ior: f32, dispersion: f32, channel: u32) -> f32 {
    let l = CHANNEL_WAVELENGTHS[min(channel, 2u)];
    return max(ior + (ior - 1.0) * (dispersion / 20.0) * (523655.0 / (l * l) - 1.5168), 1.0);
}

struct TangentFrame {
    t: vec3<f32>,
    b: vec3<f32>,
    found: bool,
}

// The tangent frame at (u, v) around the unit normal n: the interpolated vertex tangent (to
// world space with instancing) Gram-Schmidt'd against n, and the bitangent n × t times the
// handedness of the nearest vertex (all three agree within a UV island), flipped by
// mirroring. Not found without tangents, or when the tangent is parallel to n.
fn tangent_frame(tri: Triangle, index: u32, instance: u32, u: f32, v: f32, n: vec3<f32>) -> TangentFrame {
    let none = TangentFrame(vec3<f32>(0.0), vec3<f32>(0.0), false);
    if ((tri.flags & TRI_HAS_TANGENTS) == 0u) {
        return none;
    }
    let a = load_attributes(index);
    var t_interp = (1.0 - u - v) * oct_decode(a.t0) + u * oct_decode(a.t12.x) + v * oct_decode(a.t12.y);
    if (INSTANCING) {
        t_interp = transform_dir(load_instance(instance).object_to_world, t_interp);
    }
    let t_ortho = t_interp - n * dot(n, t_interp);
    let len2 = dot(t_ortho, t_ortho);
    if (len2 <= 1e-12) {
        return none;
    }
    let t = t_ortho * inverseSqrt(len2);
    var w = select(1.0, -1.0, ((tri.flags >> (TRI_TANGENT_SIGN_SHIFT + nearest_vertex(u, v))) & 1u) != 0u);
    if ((tri.flags & TRI_MIRRORED) != 0u) {
        w = -w;
    }
    return TangentFrame(t, cross(n, t) * w, true);
}

// KHR_materials_anisotropy's direction at the point (world space): the tangent frame (vertex
// tangents Gram-Schmidt'd against the shading normal n) turned by the texture's direction (RG
// in [−1, 1]) and the rotation. Zero without tangents.
fn anisotropy_direction(
    tri: Triangle, index: u32, instance: u32, u: f32, v: f32, n: vec3<f32>, m: Material, uv: vec4<f32>
) -> vec3<f32> {
    let f = tangent_frame(tri, index, instance, u, v, n);
    if (!f.found) {
        return vec3<f32>(0.0);
    }
    var d = vec2<f32>(1.0, 0.0);
    if (TEXTURES && m.anisotropy_texture.atlas != NO_TEXTURE) {
        let e = sample_texture(m.anisotropy_texture, uv).xy * 2.0 - 1.0;
        if (dot(e, e) > 1e-8) {
            d = normalize(e);
        }
    }
    let r = m.anisotropy_rotation;
    return f.t * (r.x * d.x - r.y * d.y) + f.b * (r.y * d.x + r.x * d.y);
}

// Does a ray stop at this triangle? MASK: alpha at or above the cutoff. BLEND: with
// probability alpha (stochastic transparency), decided by a hash of the ray and the triangle
// so that the decision is the same for the closest-hit and the shadow query of one ray.
fn alpha_passes(index: u32, u: f32, v: f32, ray: Ray) -> bool {
    let tri = load_triangle(index);
    let m = materials[tri.material];
    var alpha = m.alpha;
    if (TEXTURES && m.base_color_texture.atlas != NO_TEXTURE) {
        alpha *= sample_texture(m.base_color_texture, triangle_uv(index, u, v)).w;
    }
    if (VERTEX_EXTRAS) {
        alpha *= vertex_color(index, u, v).w;
    }
    if ((m.flags & MAT_ALPHA_MASK) != 0u) {
        return alpha >= m.alpha_cutoff;
    }
    let o = bitcast<vec3<u32>>(ray.origin);
    let d = bitcast<vec3<u32>>(ray.dir);
    let h = pcg_hash(index ^ pcg_hash(o.x ^ pcg_hash(o.y ^ pcg_hash(o.z ^ pcg_hash(d.x ^ pcg_hash(d.y ^ d.z))))));
    return f32(h >> 8u) * (1.0 / 16777216.0) < alpha;
}

fn oct_decode(bits: u32) -> vec3<f32> {
    let e = unpack2x16snorm(bits);
    let z = 1.0 - abs(e.x) - abs(e.y);
    let t = max(-z, 0.0);
    let x = e.x + select(t, -t, e.x >= 0.0);
    let y = e.y + select(t, -t, e.y >= 0.0);
    return normalize(vec3<f32>(x, y, z));
}

// The front-facing shading normal at (u, v): interpolated vertex normals (else ng), then the
// normal map: n' = T·x + B·y + N·z with T Gram-Schmidt'd against N and B = cross(N, T)·w.
// Attributes are in object space: with instancing they move to world space here (normals by
// the inverse transpose, tangents by the transform, handedness flipped by mirroring).
fn shading_normal(
    tri: Triangle, index: u32, instance: u32, u: f32, v: f32, ng: vec3<f32>, m: Material, uv: vec4<f32>
) -> vec3<f32> {
    return mapped_normal(tri, index, instance, u, v, ng, m.normal_texture, m.normal_scale, uv);
}

// The clearcoat's normal: its own normal map, else the interpolated normal.
fn coat_normal(
    tri: Triangle, index: u32, instance: u32, u: f32, v: f32, ng: vec3<f32>, m: Material, uv: vec4<f32>
) -> vec3<f32> {
    return mapped_normal(tri, index, instance, u, v, ng, m.clearcoat_normal_texture, m.clearcoat_normal_scale, uv);
}

fn mapped_normal(
    tri: Triangle, index: u32, instance: u32, u: f32, v: f32, ng: vec3<f32>, map: TextureRef, scale: f32,
    uv: vec4<f32>
) -> vec3<f32> {
    var n = ng;
    let a = load_attributes(index);
    var inst: Instance;
    if (INSTANCING) {
        inst = load_instance(instance);
    }
    if ((tri.flags & TRI_HAS_NORMALS) != 0u) {
        var s = (1.0 - u - v) * oct_decode(a.n.x) + u * oct_decode(a.n.y) + v * oct_decode(a.n.z);
        if (INSTANCING) {
            s = transform_normal(inst.world_to_object, s);
        }
        let len2 = dot(s, s);
        n = select(ng, s * inverseSqrt(len2), len2 > 0.0);
    }
    if (!TEXTURES || map.atlas == NO_TEXTURE) {
        return n;
    }
    let f = tangent_frame(tri, index, instance, u, v, n);
    if (!f.found) {
        return n;
    }
    let c = sample_texture(map, uv).xyz * 2.0 - 1.0;
    let mapped = f.t * (c.x * scale) + f.b * (c.y * scale) + n * c.z;
    let mlen2 = dot(mapped, mapped);
    return select(n, mapped * inverseSqrt(mlen2), mlen2 > 1e-12);
}

// Index of the vertex with the largest barycentric weight.
fn nearest_vertex(u: f32, v: f32) -> u32 {
    let w0 = 1.0 - u - v;
    if (w0 >= u && w0 >= v) {
        return 0u;
    }
    return select(2u, 1u, u >= v);
}
