//! glTF materials (metallic-roughness and the KHR extensions veach reads) as `Material`.

use crate::scene::{AlphaMode, Material, Texture, TextureRef, Wrap};
use glam::Vec3;
use serde_json::Value;

/// Largest emitted radiance kept: far above any physical source in scene units, yet far from
/// f32's overflow when divided by a small light pdf.
pub const MAX_RADIANCE: f32 = 1e15;

pub fn convert_material(
    m: &gltf::Material,
    doc: &gltf::Document,
    image_slot: &[Option<u32>],
    textures: &mut Vec<Texture>,
    warnings: &mut Vec<String>,
) -> Material {
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
        if tex_coord > 1 {
            warnings.push(format!("{name}: a texture reads TEXCOORD_{tex_coord}; veach reads TEXCOORD_0 and _1 only"));
        }
        let wrap = |w: gltf::texture::WrappingMode| match w {
            gltf::texture::WrappingMode::ClampToEdge => Wrap::ClampToEdge,
            gltf::texture::WrappingMode::MirroredRepeat => Wrap::MirroredRepeat,
            gltf::texture::WrappingMode::Repeat => Wrap::Repeat,
        };
        let sampler = tex.sampler();
        Some(TextureRef {
            texture: slot,
            uv_set: (tex_coord == 1) as u32,
            transform: transform.map_or(TextureRef::IDENTITY, |(o, r, s)| uv_transform(o, r, s)),
            wrap: [wrap(sampler.wrap_s()), wrap(sampler.wrap_t())],
        })
    };
    // A textureInfo of an extension the gltf crate does not model, from its JSON (its scale
    // too, for normal textures).
    let json_info = |v: Option<&Value>| -> Option<(gltf::texture::Texture, u32, Option<Transform>, f32)> {
        let v = v?;
        let tex = doc.textures().nth(v.get("index")?.as_u64()? as usize)?;
        let tt = v
            .get("extensions")
            .and_then(|e| e.get("KHR_texture_transform"))
            .and_then(|t| serde_json::from_value::<gltf::json::extensions::texture::TextureTransform>(t.clone()).ok());
        let coord = v.get("texCoord").and_then(Value::as_u64).unwrap_or(0) as u32;
        let coord = tt.as_ref().and_then(|t| t.tex_coord).unwrap_or(coord);
        let scale = v.get("scale").and_then(Value::as_f64).unwrap_or(1.0) as f32;
        Some((tex, coord, tt.map(|t| (t.offset.0, t.rotation.0, t.scale.0)), scale))
    };
    fn without_scale<'a>(
        i: Option<(gltf::texture::Texture<'a>, u32, Option<Transform>, f32)>,
    ) -> Option<(gltf::texture::Texture<'a>, u32, Option<Transform>)> {
        i.map(|(t, c, x, _)| (t, c, x))
    }
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
    let transmission_texture = texture(info(m.transmission().and_then(|t| t.transmission_texture())));
    let specular_texture = texture(info(m.specular().and_then(|s| s.specular_texture())));
    let specular_color_texture = texture(info(m.specular().and_then(|s| s.specular_color_texture())));
    let coat = m.extension_value("KHR_materials_clearcoat");
    let number = |v: Option<&Value>, key: &str, default: f32| {
        v.and_then(|v| v.get(key)).and_then(Value::as_f64).map_or(default, |x| x as f32)
    };
    let clearcoat_texture = texture(without_scale(json_info(coat.and_then(|c| c.get("clearcoatTexture")))));
    let clearcoat_roughness_texture =
        texture(without_scale(json_info(coat.and_then(|c| c.get("clearcoatRoughnessTexture")))));
    let coat_normal = json_info(coat.and_then(|c| c.get("clearcoatNormalTexture")));
    let clearcoat_normal_scale = coat_normal.as_ref().map_or(1.0, |n| n.3);
    let clearcoat_normal_texture = texture(without_scale(coat_normal));
    let sheen = m.extension_value("KHR_materials_sheen");
    let sheen_color_texture = texture(without_scale(json_info(sheen.and_then(|c| c.get("sheenColorTexture")))));
    let sheen_roughness_texture = texture(without_scale(json_info(sheen.and_then(|c| c.get("sheenRoughnessTexture")))));
    let sheen_color = sheen
        .and_then(|v| v.get("sheenColorFactor"))
        .and_then(|v| serde_json::from_value::<[f32; 3]>(v.clone()).ok())
        .map_or(Vec3::ZERO, Vec3::from);
    let irid = m.extension_value("KHR_materials_iridescence");
    let iridescence_texture = texture(without_scale(json_info(irid.and_then(|c| c.get("iridescenceTexture")))));
    let iridescence_thickness_texture =
        texture(without_scale(json_info(irid.and_then(|c| c.get("iridescenceThicknessTexture")))));
    let aniso = m.extension_value("KHR_materials_anisotropy");
    let anisotropy_texture = texture(without_scale(json_info(aniso.and_then(|c| c.get("anisotropyTexture")))));
    let dt = m.extension_value("KHR_materials_diffuse_transmission");
    let diffuse_transmission_texture =
        texture(without_scale(json_info(dt.and_then(|c| c.get("diffuseTransmissionTexture")))));
    let diffuse_transmission_color_texture =
        texture(without_scale(json_info(dt.and_then(|c| c.get("diffuseTransmissionColorTexture")))));
    let diffuse_transmission_color = dt
        .and_then(|v| v.get("diffuseTransmissionColorFactor"))
        .and_then(|v| serde_json::from_value::<[f32; 3]>(v.clone()).ok())
        .map_or(Vec3::ONE, Vec3::from);
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
        // The volume's thickness decides thin or thick; only a positive one makes a solid.
        thin_walled: m.volume().is_none_or(|v| v.thickness_factor().is_nan() || v.thickness_factor() <= 0.0),
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
        transmission_texture,
        specular_texture,
        specular_color_texture,
        clearcoat: sane(number(coat, "clearcoatFactor", 0.0), 0.0, 1.0, 0.0),
        clearcoat_roughness: sane(number(coat, "clearcoatRoughnessFactor", 0.0), 0.0, 1.0, 0.0),
        clearcoat_texture,
        clearcoat_roughness_texture,
        clearcoat_normal_texture,
        clearcoat_normal_scale: sane(clearcoat_normal_scale, -100.0, 100.0, 1.0),
        sheen_color: sane3(sheen_color).min(Vec3::ONE),
        sheen_roughness: sane(number(sheen, "sheenRoughnessFactor", 0.0), 0.0, 1.0, 0.0),
        sheen_color_texture,
        sheen_roughness_texture,
        anisotropy: sane(number(aniso, "anisotropyStrength", 0.0), 0.0, 1.0, 0.0),
        anisotropy_rotation: sane(number(aniso, "anisotropyRotation", 0.0), -1e4, 1e4, 0.0),
        anisotropy_texture,
        iridescence: sane(number(irid, "iridescenceFactor", 0.0), 0.0, 1.0, 0.0),
        iridescence_ior: sane(number(irid, "iridescenceIor", 1.3), 1.0, 10.0, 1.3),
        iridescence_thickness_min: sane(number(irid, "iridescenceThicknessMinimum", 100.0), 0.0, 1e5, 100.0),
        iridescence_thickness_max: sane(number(irid, "iridescenceThicknessMaximum", 400.0), 0.0, 1e5, 400.0),
        iridescence_texture,
        iridescence_thickness_texture,
        diffuse_transmission: sane(number(dt, "diffuseTransmissionFactor", 0.0), 0.0, 1.0, 0.0),
        diffuse_transmission_color: sane3(diffuse_transmission_color).min(Vec3::ONE),
        diffuse_transmission_texture,
        diffuse_transmission_color_texture,
        dispersion: sane(number(m.extension_value("KHR_materials_dispersion"), "dispersion", 0.0), 0.0, 100.0, 0.0),
    };
    let material = match m.pbr_specular_glossiness() {
        Some(sg) => {
            let (material, missing) = specular_glossiness(material, &sg, &mut texture, textures);
            if missing {
                warnings.push(format!("{name}: its specular-glossiness texture is missing"));
            }
            material
        }
        None => material,
    };
    if m.extension_value("KHR_materials_unlit").is_some() { unlit(material) } else { material }
}

/// KHR_materials_pbrSpecularGlossiness as metallic-roughness, as Blender's importer does: the
/// diffuse color becomes the base color of a non-metal, roughness = 1 − glossiness, and the
/// specular color becomes the dielectric's F0 (specularColor = specular / 0.04 at ior 1.5,
/// with the RGB of the specular-glossiness texture as the specular color texture). A
/// glossiness texture (its alpha) becomes a new roughness texture, 1 − glossiness × alpha in
/// green.
fn specular_glossiness<'a>(
    m: Material,
    sg: &gltf::material::PbrSpecularGlossiness<'a>,
    texture: &mut impl FnMut(
        Option<(gltf::texture::Texture<'a>, u32, Option<([f32; 2], f32, [f32; 2])>)>,
    ) -> Option<TextureRef>,
    textures: &mut Vec<Texture>,
) -> (Material, bool) {
    let finite = |v: f32, default: f32| if v.is_finite() { v.clamp(0.0, 1.0) } else { default };
    let [r, g, b, a] = sg.diffuse_factor().map(|v| finite(v, 1.0));
    let glossiness = finite(sg.glossiness_factor(), 1.0);
    let specular = Vec3::from(sg.specular_factor().map(|v| finite(v, 1.0)));
    let info = |i: Option<gltf::texture::Info<'a>>| {
        i.map(|i| {
            let tt = i.texture_transform();
            let coord = tt.as_ref().and_then(|t| t.tex_coord()).unwrap_or(i.tex_coord());
            (i.texture(), coord, tt.map(|t| (t.offset(), t.rotation(), t.scale())))
        })
    };
    let sg_texture = texture(info(sg.specular_glossiness_texture()));
    let mut roughness = 1.0 - glossiness;
    let mut roughness_texture = None;
    let mut missing = false;
    if let Some(t) = sg_texture {
        match textures.get(t.texture as usize) {
            Some(source) => {
                let mut rgba = source.rgba.clone();
                for px in rgba.chunks_exact_mut(4) {
                    let gloss = glossiness * px[3] as f32 / 255.0;
                    px.copy_from_slice(&[0, ((1.0 - gloss) * 255.0).round() as u8, 0, 255]);
                }
                let derived = Texture { name: format!("{} (roughness)", source.name), rgba, ..*source };
                roughness = 1.0;
                roughness_texture = Some(TextureRef { texture: textures.len() as u32, ..t });
                textures.push(derived);
            }
            None => missing = true,
        }
    }
    let material = Material {
        base_color: Vec3::new(r, g, b),
        alpha: a,
        base_color_texture: texture(info(sg.diffuse_texture())),
        metallic: 0.0,
        roughness,
        metallic_roughness_texture: roughness_texture,
        ior: 1.5,
        specular_factor: 1.0,
        specular_color: specular / 0.04,
        specular_color_texture: sg_texture,
        specular_texture: None,
        ..m
    };
    (material, missing)
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
