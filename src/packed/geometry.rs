//! Triangles and their vertex attributes as the kernel reads them.

use super::layout::{
    Attributes, TRI_ALPHA, TRI_HAS_NORMALS, TRI_HAS_TANGENTS, TRI_TANGENT_SIGN_SHIFT, Triangle as PackedTriangle,
};
use super::octahedral::oct_encode;
use crate::scene::{AlphaMode, Scene};
use glam::Vec3;

pub fn pack_triangle(scene: &Scene, t: &crate::scene::Triangle, light_pdf_area: f32) -> PackedTriangle {
    let [p0, p1, p2] = t.positions;
    let ng = t.cross().normalize_or_zero();
    let m = &scene.materials[t.material as usize];
    let mut flags = 0;
    if !t.normals.iter().all(|n| n.dot(ng) > 0.99999) {
        flags |= TRI_HAS_NORMALS;
    }
    if t.tangents.iter().all(|v| v.truncate() != Vec3::ZERO) {
        flags |= TRI_HAS_TANGENTS;
        for (k, v) in t.tangents.iter().enumerate() {
            if v.w < 0.0 {
                flags |= 1 << (TRI_TANGENT_SIGN_SHIFT + k as u32);
            }
        }
    }
    let cutout = match m.alpha_mode {
        AlphaMode::Opaque => false,
        AlphaMode::Mask(_) => true,
        AlphaMode::Blend => m.alpha < 1.0 || m.base_color_texture.is_some(),
    };
    if cutout {
        flags |= TRI_ALPHA;
    }
    PackedTriangle {
        p0: p0.into(),
        material: t.material,
        e1: (p1 - p0).into(),
        light_pdf_area,
        e2: (p2 - p0).into(),
        flags,
    }
}

/// A triangle's extra vertex data (COLOR_0 and TEXCOORD_1), in an `Attributes` record of the
/// region after the triangles' own (`extras_base`): per vertex two words of 16-bit unorm
/// colour, (r, g) and (b, a), in the six normal and tangent words; TEXCOORD_1 in the UVs.
/// White and zero where the triangle has none.
pub fn pack_extras(t: &crate::scene::Triangle) -> Attributes {
    let colors = t.colors.unwrap_or([glam::Vec4::ONE; 3]);
    let unorm = |x: f32| (x.clamp(0.0, 1.0) * 65535.0).round() as u32;
    let pair = |a: f32, b: f32| unorm(a) | unorm(b) << 16;
    let w: Vec<u32> = colors.iter().flat_map(|c| [pair(c.x, c.y), pair(c.z, c.w)]).collect();
    Attributes {
        n: [w[0], w[1], w[2]],
        t0: w[3],
        t12: [w[4], w[5]],
        uv: t.uvs1.unwrap_or([glam::Vec2::ZERO; 3]).map(|v| v.into()),
    }
}

pub fn pack_attributes(t: &crate::scene::Triangle) -> Attributes {
    let tan = t.tangents.map(|v| oct_encode(v.truncate()));
    Attributes { n: t.normals.map(oct_encode), t0: tan[0], t12: [tan[1], tan[2]], uv: t.uvs.map(|v| v.into()) }
}
