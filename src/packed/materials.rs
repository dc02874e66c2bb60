//! Materials as the kernel reads them: glTF's metallic-roughness parameters, with the
//! dielectric Fresnel terms of KHR_materials_ior/_specular folded in.

use super::layout::{
    MAT_ALPHA_BLEND, MAT_ALPHA_MASK, MAT_DOUBLE_SIDED, MAT_THIN_WALLED, Material as PackedMaterial, NO_TEXTURE,
    TEX_HEIGHT_SHIFT, TEX_PAGE_SHIFT, TEX_SRGB, TEX_UV1, TEX_WIDTH_SHIFT, TEX_X_SHIFT, TextureRef as PackedTextureRef,
};
use super::textures::Placement;
use crate::scene::{AlphaMode, Material, TextureRef};
use glam::Vec3;

pub fn luminance(c: Vec3) -> f32 {
    0.2126 * c.x + 0.7152 * c.y + 0.0722 * c.z
}

/// `m` as the kernels read it; `atlas` places each of the scene's textures.
pub fn pack_material(m: &Material, atlas: &[Placement]) -> PackedMaterial {
    let pack_texture_ref = |t: Option<TextureRef>, srgb: bool| pack_texture_ref(t, srgb, atlas);
    let (cutoff, mut flags) = match m.alpha_mode {
        AlphaMode::Opaque => (0.0, 0),
        AlphaMode::Mask(c) => (c, MAT_ALPHA_MASK),
        AlphaMode::Blend => (0.0, MAT_ALPHA_BLEND),
    };
    if m.double_sided {
        flags |= MAT_DOUBLE_SIDED;
    }
    let thin = m.thin_walled && m.transmission > 0.0;
    if thin {
        flags |= MAT_THIN_WALLED;
    }
    // A thin wall (no volume, or thickness 0) holds no medium, whatever its lobes.
    let attenuation = if m.attenuation_distance.is_finite() && !m.thin_walled {
        m.attenuation_color.max(Vec3::splat(1e-6)).map(|c| -c.ln() / m.attenuation_distance)
    } else {
        Vec3::ZERO
    };
    PackedMaterial {
        base_color: m.base_color.into(),
        metallic: m.metallic,
        emission: m.emission.into(),
        roughness: m.roughness,
        dielectric_f0: dielectric_f0(m).into(),
        ior: m.ior,
        dielectric_f90: m.specular_factor,
        transmission: m.transmission,
        alpha: m.alpha,
        alpha_cutoff: cutoff,
        attenuation: attenuation.into(),
        flags,
        normal_scale: m.normal_scale,
        clearcoat: m.clearcoat,
        clearcoat_roughness: m.clearcoat_roughness,
        clearcoat_normal_scale: m.clearcoat_normal_scale,
        sheen_color: m.sheen_color.into(),
        sheen_roughness: m.sheen_roughness,
        coat_normal: [0.0, 0.0, 1.0],
        anisotropy: m.anisotropy,
        specular_f0: specular_f0(m).into(),
        diffuse_transmission: m.diffuse_transmission,
        anisotropy_rotation: [m.anisotropy_rotation.cos(), m.anisotropy_rotation.sin()],
        anisotropy_tangent: [1.0, 0.0],
        iridescence: m.iridescence,
        iridescence_ior: m.iridescence_ior,
        iridescence_thickness_min: m.iridescence_thickness_min,
        iridescence_thickness_max: m.iridescence_thickness_max,
        diffuse_transmission_color: m.diffuse_transmission_color.into(),
        dispersion: m.dispersion,
        base_color_texture: pack_texture_ref(m.base_color_texture, true),
        metallic_roughness_texture: pack_texture_ref(m.metallic_roughness_texture, false),
        emissive_texture: pack_texture_ref(m.emissive_texture, true),
        normal_texture: pack_texture_ref(m.normal_texture, false),
        transmission_texture: pack_texture_ref(m.transmission_texture, false),
        specular_texture: pack_texture_ref(m.specular_texture, false),
        specular_color_texture: pack_texture_ref(m.specular_color_texture, true),
        clearcoat_texture: pack_texture_ref(m.clearcoat_texture, false),
        clearcoat_roughness_texture: pack_texture_ref(m.clearcoat_roughness_texture, false),
        clearcoat_normal_texture: pack_texture_ref(m.clearcoat_normal_texture, false),
        sheen_color_texture: pack_texture_ref(m.sheen_color_texture, true),
        sheen_roughness_texture: pack_texture_ref(m.sheen_roughness_texture, false),
        anisotropy_texture: pack_texture_ref(m.anisotropy_texture, false),
        iridescence_texture: pack_texture_ref(m.iridescence_texture, false),
        iridescence_thickness_texture: pack_texture_ref(m.iridescence_thickness_texture, false),
        diffuse_transmission_texture: pack_texture_ref(m.diffuse_transmission_texture, false),
        diffuse_transmission_color_texture: pack_texture_ref(m.diffuse_transmission_color_texture, true),
    }
}

fn pack_texture_ref(t: Option<TextureRef>, srgb: bool, atlas: &[Placement]) -> PackedTextureRef {
    let none = PackedTextureRef { row0: [1.0, 0.0, 0.0], atlas: NO_TEXTURE, row1: [0.0, 1.0, 0.0], mode: 0 };
    let Some((t, p)) = t.and_then(|t| Some((t, atlas.get(t.texture as usize)?))) else {
        return none;
    };
    PackedTextureRef {
        row0: t.transform[0],
        atlas: p.page << TEX_PAGE_SHIFT | p.x << TEX_X_SHIFT | p.y,
        row1: t.transform[1],
        mode: t.wrap[0] as u32
            | (t.wrap[1] as u32) << 2
            | if srgb { TEX_SRGB } else { 0 }
            | if t.uv_set == 1 { TEX_UV1 } else { 0 }
            | (p.width - 1) << TEX_WIDTH_SHIFT
            | (p.height - 1) << TEX_HEIGHT_SHIFT,
    }
}

/// The dielectric F0 of glTF's metallic-roughness model with KHR_materials_specular/_ior.
pub fn dielectric_f0(m: &Material) -> Vec3 {
    specular_f0(m).min(Vec3::ONE) * m.specular_factor
}

/// ((ior − 1)/(ior + 1))² × specularColor, before the clamp to 1 and the specular factor.
pub fn specular_f0(m: &Material) -> Vec3 {
    let r = (m.ior - 1.0) / (m.ior + 1.0);
    r * r * m.specular_color
}
