//! Twin of `shaders/material.wgsl`: textured material, alpha and the normal-mapped shading normal.

use super::common::{Ray, oct_decode};
use super::instance::{load_instance, transform_dir, transform_normal};
use super::rng::pcg_hash;
use super::texture::sample_texture;
use crate::packed::{
    MAT_ALPHA_MASK, Material, NO_TEXTURE, PackedScene, TRI_HAS_NORMALS, TRI_HAS_TANGENTS, TRI_MIRRORED,
    TRI_TANGENT_SIGN_SHIFT, TextureRef, Triangle,
};
use glam::{Vec2, Vec3, Vec4};

/// TEXCOORD_0 (xy) and TEXCOORD_1 (zw, 0 without it) at barycentrics (u, v) of vertices 1
/// and 2. Twin of `triangle_uv`.
pub fn triangle_uv(scene: &PackedScene, index: u32, u: f32, v: f32) -> Vec4 {
    let at = |a: &crate::packed::Attributes| {
        (1.0 - u - v) * Vec2::from(a.uv[0]) + u * Vec2::from(a.uv[1]) + v * Vec2::from(a.uv[2])
    };
    let uv0 = at(&scene.attributes[index as usize]);
    let uv1 =
        if scene.extras_base > 0 { at(&scene.attributes[(scene.extras_base + index) as usize]) } else { Vec2::ZERO };
    Vec4::new(uv0.x, uv0.y, uv1.x, uv1.y)
}

/// COLOR_0 at barycentrics (u, v) (white without it). Twin of `vertex_color`.
pub fn vertex_color(scene: &PackedScene, index: u32, u: f32, v: f32) -> Vec4 {
    if scene.extras_base == 0 {
        return Vec4::ONE;
    }
    let e = &scene.attributes[(scene.extras_base + index) as usize];
    let w = [e.n[0], e.n[1], e.n[2], e.t0, e.t12[0], e.t12[1]];
    let unorm = |bits: u32| Vec2::new((bits & 0xffff) as f32 / 65535.0, (bits >> 16) as f32 / 65535.0);
    let c = |k: usize| {
        let (rg, ba) = (unorm(w[2 * k]), unorm(w[2 * k + 1]));
        Vec4::new(rg.x, rg.y, ba.x, ba.y)
    };
    (1.0 - u - v) * c(0) + u * c(1) + v * c(2)
}

/// The material at a surface point: its factors times its textures at `uv` (both UV sets) and
/// the vertex colour `color` (COLOR_0 multiplies the base colour and alpha).
pub fn material_at(scene: &PackedScene, m: &Material, uv: Vec4, color: Vec4) -> Material {
    let mut r = *m;
    if color != Vec4::ONE {
        r.base_color = (Vec3::from(m.base_color) * color.truncate()).into();
        r.alpha = m.alpha * color.w;
    }
    if m.base_color_texture.atlas != NO_TEXTURE {
        let c = sample_texture(scene, &m.base_color_texture, uv);
        r.base_color = (Vec3::from(r.base_color) * c.truncate()).into();
        r.alpha *= c.w;
    }
    if m.metallic_roughness_texture.atlas != NO_TEXTURE {
        let c = sample_texture(scene, &m.metallic_roughness_texture, uv);
        r.roughness = m.roughness * c.y;
        r.metallic = m.metallic * c.z;
    }
    if m.emissive_texture.atlas != NO_TEXTURE {
        r.emission = (Vec3::from(m.emission) * sample_texture(scene, &m.emissive_texture, uv).truncate()).into();
    }
    if m.transmission_texture.atlas != NO_TEXTURE {
        r.transmission = m.transmission * sample_texture(scene, &m.transmission_texture, uv).x;
    }
    if m.specular_texture.atlas != NO_TEXTURE || m.specular_color_texture.atlas != NO_TEXTURE {
        let mut factor = m.dielectric_f90;
        let mut f0 = Vec3::from(m.specular_f0);
        if m.specular_texture.atlas != NO_TEXTURE {
            factor *= sample_texture(scene, &m.specular_texture, uv).w;
        }
        if m.specular_color_texture.atlas != NO_TEXTURE {
            f0 *= sample_texture(scene, &m.specular_color_texture, uv).truncate();
        }
        r.dielectric_f0 = (f0.min(Vec3::ONE) * factor).into();
        r.dielectric_f90 = factor;
    }
    if m.clearcoat_texture.atlas != NO_TEXTURE {
        r.clearcoat = m.clearcoat * sample_texture(scene, &m.clearcoat_texture, uv).x;
    }
    if m.clearcoat_roughness_texture.atlas != NO_TEXTURE {
        r.clearcoat_roughness = m.clearcoat_roughness * sample_texture(scene, &m.clearcoat_roughness_texture, uv).y;
    }
    if m.sheen_color_texture.atlas != NO_TEXTURE {
        r.sheen_color =
            (Vec3::from(m.sheen_color) * sample_texture(scene, &m.sheen_color_texture, uv).truncate()).into();
    }
    if m.sheen_roughness_texture.atlas != NO_TEXTURE {
        r.sheen_roughness = m.sheen_roughness * sample_texture(scene, &m.sheen_roughness_texture, uv).w;
    }
    if m.anisotropy_texture.atlas != NO_TEXTURE {
        r.anisotropy = m.anisotropy * sample_texture(scene, &m.anisotropy_texture, uv).z;
    }
    if m.iridescence_texture.atlas != NO_TEXTURE {
        r.iridescence = m.iridescence * sample_texture(scene, &m.iridescence_texture, uv).x;
    }
    if m.iridescence_thickness_texture.atlas != NO_TEXTURE {
        let t = sample_texture(scene, &m.iridescence_thickness_texture, uv).y;
        r.iridescence_thickness_max =
            m.iridescence_thickness_min + (m.iridescence_thickness_max - m.iridescence_thickness_min) * t;
    }
    if m.diffuse_transmission_texture.atlas != NO_TEXTURE {
        r.diffuse_transmission = m.diffuse_transmission * sample_texture(scene, &m.diffuse_transmission_texture, uv).w;
    }
    if m.diffuse_transmission_color_texture.atlas != NO_TEXTURE {
        let c = sample_texture(scene, &m.diffuse_transmission_color_texture, uv).truncate();
        r.diffuse_transmission_color = (Vec3::from(m.diffuse_transmission_color) * c).into();
    }
    r
}

/// Wavelengths (nm) the colour channels stand for under KHR_materials_dispersion: Fraunhofer's
/// C, d and F lines, whose iors define the Abbe number (the extension's own per-channel
/// example spreads red and blue by the same (n_F − n_C)/2 about green).
pub const CHANNEL_WAVELENGTHS: [f32; 3] = [656.3, 587.6, 486.1];

/// KHR_materials_dispersion's ior at colour channel `channel`: Cauchy's n(λ) = A + B/λ²
/// through `ior` at 587.6 nm with Abbe number 20 / `dispersion`, at least 1. Twin of
/// `dispersed_ior`.
pub fn dispersed_ior(ior: f32, dispersion: f32, channel: u32) -> f32 {
    let l = CHANNEL_WAVELENGTHS[channel.min(2) as usize];
    (ior + (ior - 1.0) * (dispersion / 20.0) * (523655.0 / (l * l) - 1.5168)).max(1.0)
}

/// The tangent frame at (u, v) around the unit normal `n`: the interpolated vertex tangent
/// (to world space with instancing) Gram-Schmidt'd against n, and the bitangent n × t times
/// the handedness of the nearest vertex (all three agree within a UV island), flipped by
/// mirroring. None without tangents, or when the tangent is parallel to n.
pub fn tangent_frame(
    scene: &PackedScene,
    tri: &Triangle,
    index: u32,
    instance: u32,
    u: f32,
    v: f32,
    n: Vec3,
) -> Option<(Vec3, Vec3)> {
    if tri.flags & TRI_HAS_TANGENTS == 0 {
        return None;
    }
    let a = &scene.attributes[index as usize];
    let mut t_interp = (1.0 - u - v) * oct_decode(a.t0) + u * oct_decode(a.t12[0]) + v * oct_decode(a.t12[1]);
    if scene.instance_count > 0 {
        t_interp = transform_dir(&load_instance(scene, instance).object_to_world, t_interp);
    }
    let t_ortho = t_interp - n * n.dot(t_interp);
    let len2 = t_ortho.dot(t_ortho);
    if len2 <= 1e-12 {
        return None;
    }
    let t = t_ortho / len2.sqrt();
    let mut w = if (tri.flags >> (TRI_TANGENT_SIGN_SHIFT + nearest_vertex(u, v))) & 1 != 0 { -1.0 } else { 1.0 };
    if tri.flags & TRI_MIRRORED != 0 {
        w = -w;
    }
    Some((t, n.cross(t) * w))
}

/// KHR_materials_anisotropy's direction at the point (world space): the tangent frame (vertex
/// tangents Gram-Schmidt'd against the shading normal `n`) turned by the texture's direction
/// (RG in [−1, 1]) and the rotation. Zero without tangents.
#[allow(clippy::too_many_arguments)]
pub fn anisotropy_direction(
    scene: &PackedScene,
    tri: &Triangle,
    index: u32,
    instance: u32,
    u: f32,
    v: f32,
    n: Vec3,
    m: &Material,
    uv: Vec4,
) -> Vec3 {
    let Some((t, b)) = tangent_frame(scene, tri, index, instance, u, v, n) else {
        return Vec3::ZERO;
    };
    let mut d = Vec2::X;
    if m.anisotropy_texture.atlas != NO_TEXTURE {
        let c = sample_texture(scene, &m.anisotropy_texture, uv);
        let e = Vec2::new(c.x, c.y) * 2.0 - Vec2::ONE;
        if e.dot(e) > 1e-8 {
            d = e.normalize();
        }
    }
    let r = Vec2::from(m.anisotropy_rotation);
    t * (r.x * d.x - r.y * d.y) + b * (r.y * d.x + r.x * d.y)
}

pub fn alpha_passes(scene: &PackedScene, index: u32, u: f32, v: f32, ray: &Ray) -> bool {
    let tri = &scene.triangles[index as usize];
    let m = &scene.materials[tri.material as usize];
    let mut alpha = m.alpha;
    if m.base_color_texture.atlas != NO_TEXTURE {
        alpha *= sample_texture(scene, &m.base_color_texture, triangle_uv(scene, index, u, v)).w;
    }
    if scene.extras_base > 0 {
        alpha *= vertex_color(scene, index, u, v).w;
    }
    if m.flags & MAT_ALPHA_MASK != 0 {
        return alpha >= m.alpha_cutoff;
    }
    let (o, d) = (ray.origin.to_array().map(f32::to_bits), ray.dir.to_array().map(f32::to_bits));
    let h = pcg_hash(index ^ pcg_hash(o[0] ^ pcg_hash(o[1] ^ pcg_hash(o[2] ^ pcg_hash(d[0] ^ pcg_hash(d[1] ^ d[2]))))));
    ((h >> 8) as f32 * (1.0 / 16777216.0)) < alpha
}

pub fn nearest_vertex(u: f32, v: f32) -> u32 {
    let w0 = 1.0 - u - v;
    if w0 >= u && w0 >= v {
        return 0;
    }
    if u >= v { 1 } else { 2 }
}

#[allow(clippy::too_many_arguments)]
pub fn shading_normal(
    scene: &PackedScene,
    tri: &Triangle,
    index: u32,
    instance: u32,
    u: f32,
    v: f32,
    ng: Vec3,
    m: &Material,
    uv: Vec4,
) -> Vec3 {
    mapped_normal(scene, tri, index, instance, u, v, ng, &m.normal_texture, m.normal_scale, uv)
}

/// The clearcoat's normal: its own normal map, else the interpolated normal.
#[allow(clippy::too_many_arguments)]
pub fn coat_normal(
    scene: &PackedScene,
    tri: &Triangle,
    index: u32,
    instance: u32,
    u: f32,
    v: f32,
    ng: Vec3,
    m: &Material,
    uv: Vec4,
) -> Vec3 {
    mapped_normal(scene, tri, index, instance, u, v, ng, &m.clearcoat_normal_texture, m.clearcoat_normal_scale, uv)
}

#[allow(clippy::too_many_arguments)]
pub fn mapped_normal(
    scene: &PackedScene,
    tri: &Triangle,
    index: u32,
    instance: u32,
    u: f32,
    v: f32,
    ng: Vec3,
    map: &TextureRef,
    scale: f32,
    uv: Vec4,
) -> Vec3 {
    let mut n = ng;
    let a = &scene.attributes[index as usize];
    let inst = (scene.instance_count > 0).then(|| load_instance(scene, instance));
    if tri.flags & TRI_HAS_NORMALS != 0 {
        let mut s = (1.0 - u - v) * oct_decode(a.n[0]) + u * oct_decode(a.n[1]) + v * oct_decode(a.n[2]);
        if let Some(inst) = &inst {
            s = transform_normal(&inst.world_to_object, s);
        }
        let len2 = s.dot(s);
        n = if len2 > 0.0 { s / len2.sqrt() } else { ng };
    }
    if map.atlas == NO_TEXTURE {
        return n;
    }
    let Some((t, b)) = tangent_frame(scene, tri, index, instance, u, v, n) else {
        return n;
    };
    let c = sample_texture(scene, map, uv).truncate() * 2.0 - Vec3::ONE;
    let mapped = t * (c.x * scale) + b * (c.y * scale) + n * c.z;
    let mlen2 = mapped.dot(mapped);
    if mlen2 > 1e-12 { mapped / mlen2.sqrt() } else { n }
}
