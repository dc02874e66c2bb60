//! glTF materials (metallic-roughness and the KHR extensions veach reads) as `Material`.

use crate::scene::{AlphaMode, Material, TextureRef, Wrap};
use glam::Vec3;

/// Largest emitted radiance kept: far above any physical source in scene units, yet far from
/// f32's overflow when divided by a small light pdf.
pub const MAX_RADIANCE: f32 = 1e15;

pub fn convert_material(m: &gltf::Material, image_slot: &[Option<u32>], warnings: &mut Vec<String>) -> Material {
    let pbr = m.pbr_metallic_roughness();
    let [r, g, b, a] = pbr.base_color_factor();
    let strength = m.emissive_strength().unwrap_or(1.0);
    let (specular_factor, specular_color) = match m.specular() {
        Some(s) => (s.specular_factor(), Vec3::from(s.specular_color_factor())),
        None => (1.0, Vec3::ONE),
    };
    let sane = |v: f32, lo: f32, hi: f32, default: f32| if v.is_finite() { v.clamp(lo, hi) } else { default };
    let sane3 = |v: Vec3| if v.is_finite() { v.max(Vec3::ZERO) } else { Vec3::ZERO };
    let name = m.name().map_or_else(|| format!("material {}", m.index().unwrap_or(usize::MAX)), str::to_string);
    type Transform = ([f32; 2], f32, [f32; 2]);
    let mut texture = |info: Option<(gltf::texture::Texture, u32, Option<Transform>)>| {
        let (tex, tex_coord, transform) = info?;
        let slot = image_slot.get(tex.source().index()).copied().flatten()?;
        if tex_coord != 0 {
            warnings.push(format!("{name}: a texture reads TEXCOORD_{tex_coord}; veach reads TEXCOORD_0 only"));
        }
        let wrap = |w: gltf::texture::WrappingMode| match w {
            gltf::texture::WrappingMode::ClampToEdge => Wrap::ClampToEdge,
            gltf::texture::WrappingMode::MirroredRepeat => Wrap::MirroredRepeat,
            gltf::texture::WrappingMode::Repeat => Wrap::Repeat,
        };
        let sampler = tex.sampler();
        Some(TextureRef {
            texture: slot,
            transform: transform.map_or(TextureRef::IDENTITY, |(o, r, s)| uv_transform(o, r, s)),
            wrap: [wrap(sampler.wrap_s()), wrap(sampler.wrap_t())],
        })
    };
    fn info<'a>(i: Option<gltf::texture::Info<'a>>) -> Option<(gltf::texture::Texture<'a>, u32, Option<Transform>)> {
        i.map(|i| {
            let tt = i.texture_transform();
            let tex_coord = tt.as_ref().and_then(|t| t.tex_coord()).unwrap_or(i.tex_coord());
            (i.texture(), tex_coord, tt.map(|t| (t.offset(), t.rotation(), t.scale())))
        })
    }
    let base_color_texture = texture(info(pbr.base_color_texture()));
    let metallic_roughness_texture = texture(info(pbr.metallic_roughness_texture()));
    let emissive_texture = texture(info(m.emissive_texture()));
    let normal = m.normal_texture();
    let normal_scale = normal.as_ref().map_or(1.0, |n| n.scale());
    // NormalTexture has no accessor for KHR_texture_transform in gltf 1.4; read its JSON.
    let normal_texture = texture(normal.map(|n| {
        let tt = n
            .extension_value("KHR_texture_transform")
            .and_then(|v| serde_json::from_value::<gltf::json::extensions::texture::TextureTransform>(v.clone()).ok());
        let tex_coord = tt.as_ref().and_then(|t| t.tex_coord).unwrap_or(n.tex_coord());
        (n.texture(), tex_coord, tt.map(|t| (t.offset.0, t.rotation.0, t.scale.0)))
    }));
    let alpha_mode = match m.alpha_mode() {
        gltf::material::AlphaMode::Opaque => AlphaMode::Opaque,
        gltf::material::AlphaMode::Mask => AlphaMode::Mask(sane(m.alpha_cutoff().unwrap_or(0.5), 0.0, 1.0, 0.5)),
        gltf::material::AlphaMode::Blend => AlphaMode::Blend,
    };
    let (attenuation_color, attenuation_distance) = match m.volume() {
        Some(v) => (sane3(Vec3::from(v.attenuation_color())).min(Vec3::ONE), v.attenuation_distance()),
        None => (Vec3::ONE, f32::INFINITY),
    };
    if m.transmission().and_then(|t| t.transmission_texture()).is_some() {
        warnings.push(format!("{name}: transmissionTexture is not supported; using transmissionFactor"));
    }
    let material = Material {
        // glTF's factors are in [0, 1]; a hostile 1e20 would overflow a path's throughput.
        base_color: sane3(Vec3::new(r, g, b)).min(Vec3::ONE),
        metallic: sane(pbr.metallic_factor(), 0.0, 1.0, 1.0),
        roughness: sane(pbr.roughness_factor(), 0.0, 1.0, 1.0),
        emission: sane3(Vec3::from(m.emissive_factor()) * strength).min(Vec3::splat(MAX_RADIANCE)),
        specular_factor: sane(specular_factor, 0.0, 1.0, 1.0),
        specular_color: sane3(specular_color),
        ior: sane(m.ior().unwrap_or(1.5), 1.0, 10.0, 1.5),
        alpha: sane(a, 0.0, 1.0, 1.0),
        alpha_mode,
        double_sided: m.double_sided(),
        transmission: sane(m.transmission().map_or(0.0, |t| t.transmission_factor()), 0.0, 1.0, 0.0),
        attenuation_color,
        attenuation_distance: if attenuation_distance.is_finite() && attenuation_distance > 0.0 {
            attenuation_distance
        } else {
            f32::INFINITY
        },
        base_color_texture,
        metallic_roughness_texture,
        emissive_texture,
        normal_texture,
        normal_scale: sane(normal_scale, -100.0, 100.0, 1.0),
    };
    if m.extension_value("KHR_materials_unlit").is_some() { unlit(material) } else { material }
}

/// KHR_materials_unlit: the surface shows its base color (factor × texture) whatever the
/// light, so it becomes an emitter of that radiance with a black BSDF: it reflects and
/// transmits nothing, keeps its alpha (the base color texture stays for it), and, being an
/// emitter, lights the scene as a lamp of its color would. Like every emitter it emits from
/// its front face.
fn unlit(m: Material) -> Material {
    Material {
        emission: m.base_color,
        emissive_texture: m.base_color_texture,
        base_color: Vec3::ZERO,
        metallic: 0.0,
        specular_factor: 0.0,
        transmission: 0.0,
        normal_texture: None,
        ..m
    }
}

/// KHR_texture_transform's translation × rotation × scale, as two rows of an affine map.
pub fn uv_transform(offset: [f32; 2], rotation: f32, scale: [f32; 2]) -> [[f32; 3]; 2] {
    let (s, c) = rotation.sin_cos();
    // u' = c·u + s·v, v' = −s·u + c·v after the scale: the UVs turn counter-clockwise in the
    // image's frame (v down), as Khronos' TextureTransformTest shows (arrow on "Correct").
    let m = [[c * scale[0], s * scale[1], offset[0]], [-s * scale[0], c * scale[1], offset[1]]];
    if m.iter().flatten().all(|v| v.is_finite()) { m } else { TextureRef::IDENTITY }
}
