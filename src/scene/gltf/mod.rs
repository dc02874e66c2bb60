//! glTF 2.0 import (.gltf and .glb) into a flat world-space `Scene`.

mod resources;

use super::tangents::generate_tangents;
use super::{AlphaMode, Camera, Material, PunctualKind, PunctualLight, Scene, Texture, TextureRef, Triangle, Wrap};
use crate::Error;
use glam::{Mat3, Mat4, Vec2, Vec3, Vec4};
use std::path::Path;

/// Refuse scenes beyond this before allocating for them (hostile counts).
pub const MAX_TRIANGLES: usize = 64 << 20;
/// Largest glTF/GLB file or buffer accepted.
pub const MAX_FILE_BYTES: u64 = 4 << 30;
/// Most node visits while flattening the hierarchy (shared subtrees multiply).
pub const MAX_NODE_VISITS: usize = 1 << 20;

/// Extensions veach reads (or can safely ignore) when a file requires them.
pub const SUPPORTED_EXTENSIONS: &[&str] = &[
    "KHR_materials_emissive_strength",
    "KHR_materials_specular",
    "KHR_materials_ior",
    "KHR_texture_transform",
    "KHR_materials_transmission",
    "KHR_materials_volume",
    "KHR_lights_punctual",
];

/// Extensions veach knows and ignores for now; files that merely use them render, with one
/// warning each.
const KNOWN_UNIMPLEMENTED: &[&str] = &[
    "KHR_materials_clearcoat",
    "KHR_materials_sheen",
    "KHR_materials_iridescence",
    "KHR_materials_anisotropy",
    "KHR_materials_dispersion",
    "KHR_materials_unlit",
    "KHR_materials_variants",
    "KHR_texture_basisu",
    "EXT_texture_webp",
];

/// Largest image side decoded; bigger images are refused with a warning.
pub const MAX_IMAGE_SIDE: u32 = 16384;

pub fn load(path: &Path) -> Result<Scene, Error> {
    let fail = |msg: String| Error::Input(format!("{}: {msg}", path.display()));
    let meta = std::fs::metadata(path).map_err(|e| fail(format!("cannot read: {e}")))?;
    if meta.is_dir() {
        return Err(fail("is a directory, not a glTF file".into()));
    }
    if meta.len() > MAX_FILE_BYTES {
        return Err(fail(format!("{} bytes: larger than the {MAX_FILE_BYTES}-byte limit", meta.len())));
    }
    let bytes = std::fs::read(path).map_err(|e| fail(format!("cannot read: {e}")))?;
    load_bytes(&bytes, path.parent()).map_err(fail)
}

/// Loads a .gltf or .glb held in memory; external files resolve against `base` (none: only
/// embedded data, GLB chunks and data: URIs). Errors are the problem alone, without the file
/// name.
pub fn load_bytes(bytes: &[u8], base: Option<&Path>) -> Result<Scene, String> {
    let (json, blob) = if bytes.starts_with(b"glTF") { glb_chunks(bytes)? } else { (bytes, None) };
    let mut raw: serde_json::Value = serde_json::from_slice(json).map_err(|e| format!("invalid glTF JSON: {e}"))?;
    let mut warnings = Vec::new();
    check_extensions(&raw, &mut warnings)?;
    normalise(&mut raw);
    let root: gltf::json::Root = serde_json::from_value(raw).map_err(|e| format!("invalid glTF JSON: {e}"))?;
    let document = contained(|| gltf::Document::from_json(root))?.map_err(|e| describe(&e))?;
    for buffer in document.buffers() {
        if buffer.length() as u64 > MAX_FILE_BYTES {
            return Err(format!("buffer {} declares {} bytes, above the limit", buffer.index(), buffer.length()));
        }
    }
    let base = resources::Base(base);
    let buffers = resources::load_buffers(&document, blob, base)?;
    let mut scene = from_document(&document, &buffers, base, &mut warnings)?;
    scene.warnings = warnings;
    Ok(scene)
}

/// Fills in what glTF lets a file leave out but the gltf crate's schema requires, so that
/// valid files load: a scene without `nodes` is an empty scene.
fn normalise(raw: &mut serde_json::Value) {
    if let Some(scenes) = raw.get_mut("scenes").and_then(|s| s.as_array_mut()) {
        for scene in scenes.iter_mut().filter_map(|s| s.as_object_mut()) {
            scene.entry("nodes").or_insert_with(|| serde_json::json!([]));
        }
    }
}

thread_local! {
    static CONTAINED: std::cell::Cell<bool> = const { std::cell::Cell::new(false) };
}

/// Runs the gltf crate's validator, turning a panic into an error. It indexes arrays with
/// unchecked indices from the file (gltf-json 1.4.1, mesh.rs:151), so a hostile file can make
/// it panic; while contained, the panic prints nothing. Only that call is contained: a panic
/// in veach's own code is a bug, and the fuzz target and the mutation test must see it.
fn contained<T>(f: impl FnOnce() -> T) -> Result<T, String> {
    static HOOK: std::sync::Once = std::sync::Once::new();
    HOOK.call_once(|| {
        let previous = std::panic::take_hook();
        std::panic::set_hook(Box::new(move |info| {
            if !CONTAINED.with(|c| c.get()) {
                previous(info);
            }
        }));
    });
    let outer = CONTAINED.with(|c| c.replace(true));
    let result = std::panic::catch_unwind(std::panic::AssertUnwindSafe(f));
    CONTAINED.with(|c| c.set(outer));
    result.map_err(|_| "invalid glTF: an index or reference is out of range".to_string())
}

/// A summary of a glTF file for `veach info SCENE`: what the file holds and what veach loads.
pub fn describe_file(path: &Path) -> Result<String, Error> {
    let scene = load(path)?;
    let fail = |m: String| Error::Input(format!("{}: {m}", path.display()));
    let bytes = std::fs::read(path).map_err(|e| fail(format!("cannot read: {e}")))?;
    let json = if bytes.starts_with(b"glTF") { glb_chunks(&bytes).map_err(fail)?.0 } else { &bytes[..] };
    let raw: serde_json::Value = serde_json::from_slice(json).map_err(|e| fail(format!("invalid glTF JSON: {e}")))?;
    let count = |key: &str| raw.get(key).and_then(|v| v.as_array()).map_or(0, |a| a.len());
    let instances = raw
        .get("nodes")
        .and_then(|v| v.as_array())
        .map_or(0, |nodes| nodes.iter().filter(|n| n.get("mesh").is_some()).count());
    let punctual =
        raw.pointer("/extensions/KHR_lights_punctual/lights").and_then(|v| v.as_array()).map_or(0, |a| a.len());
    let list = |key: &str| -> String {
        let v: Vec<&str> = raw
            .get(key)
            .and_then(|v| v.as_array())
            .map(|a| a.iter().filter_map(|x| x.as_str()).collect())
            .unwrap_or_default();
        if v.is_empty() { "none".into() } else { v.join(", ") }
    };
    let b = scene.bounds();
    let bounds = if b.is_empty() { "empty".to_string() } else { format!("{} .. {}", b.min, b.max) };
    let cameras: Vec<&str> = scene.cameras.iter().map(|c| c.name.as_str()).collect();
    Ok(format!(
        "{}\n  triangles {} ({} stored, {} emissive)\n  meshes {}\n  instances (nodes with a mesh) {} ({} drawing {} meshes stored once)\n  materials {}\n  textures {} (images {})\n  \
         punctual lights {}\n  cameras {} ({})\n  extensions used: {}\n  extensions required: {}\n  bounds {}",
        path.display(),
        scene.drawn_triangle_count(),
        scene.triangles.len() + scene.meshes.iter().map(|m| m.triangles.len()).sum::<usize>(),
        scene.emissive_triangle_count(),
        count("meshes"),
        instances,
        scene.instances.len(),
        scene.meshes.len(),
        count("materials"),
        count("textures"),
        count("images"),
        punctual,
        cameras.len(),
        cameras.join(", "),
        list("extensionsUsed"),
        list("extensionsRequired"),
        bounds,
    ))
}

/// The JSON chunk of a GLB and its BIN chunk if any, after checking the container's header
/// and chunk bounds.
fn glb_chunks(bytes: &[u8]) -> Result<(&[u8], Option<&[u8]>), String> {
    let word = |at: usize| -> Result<u32, String> {
        bytes
            .get(at..at + 4)
            .map(|b| u32::from_le_bytes([b[0], b[1], b[2], b[3]]))
            .ok_or_else(|| "truncated GLB".to_string())
    };
    let (version, length) = (word(4)?, word(8)? as usize);
    if version != 2 {
        return Err(format!("GLB version {version} (only 2 is glTF 2.0)"));
    }
    if length < 20 || length > bytes.len() {
        return Err(format!("GLB header says {length} bytes, the file has {}", bytes.len()));
    }
    let (chunk_len, chunk_type) = (word(12)? as usize, word(16)?);
    if chunk_type != 0x4E4F534A {
        return Err("GLB's first chunk is not JSON".into());
    }
    let end = 20usize.checked_add(chunk_len).filter(|&e| e <= length).ok_or("GLB JSON chunk runs past the file")?;
    // Chunks start at multiples of 4 bytes.
    let bin_at = end.next_multiple_of(4);
    let mut bin = None;
    if bin_at + 8 <= length {
        let (bin_len, bin_type) = (word(bin_at)? as usize, word(bin_at + 4)?);
        let bin_end = (bin_at + 8).checked_add(bin_len).filter(|&e| e <= length);
        let bin_end = bin_end.ok_or("GLB BIN chunk runs past the file")?;
        if bin_type == 0x004E4942 {
            bin = Some(&bytes[bin_at + 8..bin_end]);
        }
    }
    Ok((&bytes[20..end], bin))
}

/// Required extensions veach cannot honour are an error naming them; used ones it does not
/// know get one warning each.
fn check_extensions(raw: &serde_json::Value, warnings: &mut Vec<String>) -> Result<(), String> {
    let list = |key: &str| -> Vec<String> {
        raw.get(key)
            .and_then(|v| v.as_array())
            .map(|a| a.iter().filter_map(|x| x.as_str().map(str::to_string)).collect())
            .unwrap_or_default()
    };
    let missing: Vec<String> =
        list("extensionsRequired").into_iter().filter(|e| !SUPPORTED_EXTENSIONS.contains(&e.as_str())).collect();
    if !missing.is_empty() {
        return Err(format!("requires glTF extensions veach does not support: {}", missing.join(", ")));
    }
    for e in list("extensionsUsed") {
        if !SUPPORTED_EXTENSIONS.contains(&e.as_str()) {
            let what = if KNOWN_UNIMPLEMENTED.contains(&e.as_str()) { "not implemented yet" } else { "unknown" };
            warnings.push(format!("extension {e} is {what}; ignoring it"));
        }
    }
    Ok(())
}

fn from_document(
    doc: &gltf::Document,
    buffers: &[gltf::buffer::Data],
    base: resources::Base,
    warnings: &mut Vec<String>,
) -> Result<Scene, String> {
    let mut scene = Scene::default();

    // Images, decoded once each (in parallel: PNG/JPEG decoding dominates loading big models).
    let images: Vec<gltf::Image> = doc.images().collect();
    let decoded: Vec<Result<Texture, String>> = {
        use rayon::prelude::*;
        images.par_iter().map(|image| decode_image(image, base, buffers)).collect()
    };
    let mut image_slot = vec![None; images.len()];
    for (i, result) in decoded.into_iter().enumerate() {
        match result {
            Ok(texture) => {
                image_slot[i] = Some(scene.textures.len() as u32);
                scene.textures.push(texture);
            }
            Err(e) => warnings.push(format!("image {i}: {e}; rendering without it")),
        }
    }
    for m in doc.materials() {
        scene.materials.push(convert_material(&m, &image_slot, warnings));
    }
    // Primitives without a material use glTF's default one, appended last.
    let default_material = scene.materials.len() as u32;
    scene.materials.push(Material::default());

    let gltf_scene = doc.default_scene().or_else(|| doc.scenes().next());
    let Some(gltf_scene) = gltf_scene else {
        return Err("the file has no scene".into());
    };
    if let Some(env) = environment_from_extras(gltf_scene.extras()) {
        scene.environment.radiance = env;
    }

    // Meshes drawn by several nodes are stored once and instanced, unless they emit (lights
    // are sampled per world-space triangle) or a transform cannot be inverted.
    let mut uses = vec![0usize; doc.meshes().len()];
    {
        let mut stack: Vec<(gltf::Node, usize)> = gltf_scene.nodes().map(|n| (n, 0)).collect();
        let mut visits = 0usize;
        while let Some((node, depth)) = stack.pop() {
            visits += 1;
            if visits > MAX_NODE_VISITS || depth > 256 {
                break; // reported by the main walk below
            }
            if let Some(m) = node.mesh()
                && let Some(u) = uses.get_mut(m.index())
            {
                *u += 1;
            }
            stack.extend(node.children().map(|c| (c, depth + 1)));
        }
    }
    let mut stored: Vec<Option<u32>> = vec![None; uses.len()];
    let mut stack: Vec<(gltf::Node, Mat4, usize)> = gltf_scene.nodes().map(|n| (n, Mat4::IDENTITY, 0)).collect();
    let mut visits = 0usize;
    while let Some((node, parent, depth)) = stack.pop() {
        visits += 1;
        if visits > MAX_NODE_VISITS {
            return Err(format!("the node hierarchy expands to more than {MAX_NODE_VISITS} nodes"));
        }
        if depth > 256 {
            return Err("node hierarchy deeper than 256 levels (a cycle?)".into());
        }
        let local = Mat4::from_cols_array_2d(&node.transform().matrix());
        let world = parent * local;
        if !world.is_finite() {
            return Err(format!("node {} has a non-finite transform", node.index()));
        }
        if let Some(cam) = node.camera()
            && let gltf::camera::Projection::Perspective(p) = cam.projection()
        {
            let name = node
                .name()
                .or(cam.name())
                .map(str::to_string)
                .unwrap_or_else(|| format!("camera{}", scene.cameras.len()));
            scene.cameras.push(Camera::from_matrix(name, world, p.yfov()));
        }
        if let Some(mesh) = node.mesh() {
            let emits = mesh.primitives().any(|p| {
                let m = p.material().index().map_or(default_material as usize, |i| i);
                scene.materials.get(m).is_some_and(Material::is_emissive)
            });
            let det = Mat3::from_mat4(world).determinant();
            let invertible = det.is_finite() && det.abs() > 1e-24 && world.inverse().is_finite();
            if uses.get(mesh.index()).is_some_and(|&u| u >= 2) && !emits && invertible {
                let id = match stored[mesh.index()] {
                    Some(id) => id,
                    None => {
                        let world_triangles = std::mem::take(&mut scene.triangles);
                        let loaded = load_mesh(&mesh, Mat4::IDENTITY, buffers, default_material, &mut scene);
                        let object = std::mem::replace(&mut scene.triangles, world_triangles);
                        loaded?;
                        let name = mesh.name().map_or_else(|| format!("mesh {}", mesh.index()), str::to_string);
                        scene.meshes.push(super::Mesh { name, triangles: object });
                        let id = scene.meshes.len() as u32 - 1;
                        stored[mesh.index()] = Some(id);
                        id
                    }
                };
                scene.instances.push(super::Instance { mesh: id, transform: world });
            } else {
                load_mesh(&mesh, world, buffers, default_material, &mut scene)?;
            }
        }
        if let Some(light) = node.light() {
            scene.punctual_lights.extend(convert_light(&light, world));
        }
        for child in node.children() {
            stack.push((child, world, depth + 1));
        }
    }
    // Depth-first order above reversed the cameras; keep the file's order for "first camera".
    let order = camera_order(doc);
    scene.cameras.sort_by_key(|c| order.iter().position(|n| n == &c.name).unwrap_or(usize::MAX));
    Ok(scene)
}

fn camera_order(doc: &gltf::Document) -> Vec<String> {
    doc.nodes()
        .filter_map(|n| {
            let cam = n.camera()?;
            Some(n.name().or(cam.name()).map(str::to_string).unwrap_or_default())
        })
        .collect()
}

fn describe(e: &gltf::Error) -> String {
    match e {
        gltf::Error::Io(io) => format!("cannot read: {io}"),
        gltf::Error::Deserialize(j) => format!("invalid glTF JSON: {j}"),
        gltf::Error::Validation(v) => {
            let first: Vec<String> = v.iter().take(3).map(|(p, e)| format!("{}: {e}", p.as_str())).collect();
            format!("invalid glTF: {}", first.join("; "))
        }
        other => format!("invalid glTF: {other}"),
    }
}

fn convert_material(m: &gltf::Material, image_slot: &[Option<u32>], warnings: &mut Vec<String>) -> Material {
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
    Material {
        base_color: sane3(Vec3::new(r, g, b)),
        metallic: sane(pbr.metallic_factor(), 0.0, 1.0, 1.0),
        roughness: sane(pbr.roughness_factor(), 0.0, 1.0, 1.0),
        emission: sane3(Vec3::from(m.emissive_factor()) * strength),
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

/// One glTF image as 8-bit RGBA, decoded within limits on size and memory.
fn decode_image(image: &gltf::Image, base: resources::Base, buffers: &[gltf::buffer::Data]) -> Result<Texture, String> {
    use image::DynamicImage;
    let encoded = resources::image_bytes(image, buffers, base)?;
    let mut reader = image::ImageReader::new(std::io::Cursor::new(&encoded[..]))
        .with_guessed_format()
        .map_err(|e| format!("cannot decode: {e}"))?;
    let mut limits = image::Limits::default();
    limits.max_image_width = Some(MAX_IMAGE_SIDE);
    limits.max_image_height = Some(MAX_IMAGE_SIDE);
    limits.max_alloc = Some(MAX_DECODED_IMAGE_BYTES);
    reader.limits(limits);
    let decoded = reader.decode().map_err(|e| format!("cannot decode: {e}"))?;
    let (w, h) = (decoded.width(), decoded.height());
    if w == 0 || h == 0 || w > MAX_IMAGE_SIDE || h > MAX_IMAGE_SIDE {
        return Err(format!("{w}×{h} pixels is outside 1..{MAX_IMAGE_SIDE}"));
    }
    // 8-bit images as they are; 16-bit by their high byte; float by clamping (the channel
    // layouts glTF's images come in).
    let (channels, decoded) = match decoded {
        DynamicImage::ImageLuma8(_) | DynamicImage::ImageLuma16(_) => (1, decoded),
        DynamicImage::ImageLumaA8(_) | DynamicImage::ImageLumaA16(_) => (2, decoded),
        DynamicImage::ImageRgb8(_) | DynamicImage::ImageRgb16(_) | DynamicImage::ImageRgb32F(_) => (3, decoded),
        other => (4, other),
    };
    let (is16, is32) = (
        matches!(
            decoded,
            DynamicImage::ImageLuma16(_)
                | DynamicImage::ImageLumaA16(_)
                | DynamicImage::ImageRgb16(_)
                | DynamicImage::ImageRgba16(_)
        ),
        matches!(decoded, DynamicImage::ImageRgb32F(_) | DynamicImage::ImageRgba32F(_)),
    );
    let decoded = match decoded {
        d @ (DynamicImage::ImageLuma8(_)
        | DynamicImage::ImageLumaA8(_)
        | DynamicImage::ImageRgb8(_)
        | DynamicImage::ImageRgba8(_)
        | DynamicImage::ImageLuma16(_)
        | DynamicImage::ImageLumaA16(_)
        | DynamicImage::ImageRgb16(_)
        | DynamicImage::ImageRgba16(_)
        | DynamicImage::ImageRgb32F(_)
        | DynamicImage::ImageRgba32F(_)) => d,
        other => DynamicImage::ImageRgba8(other.to_rgba8()),
    };
    let data = DecodedPixels { width: w, height: h, pixels: decoded.into_bytes() };
    let (w, h) = (data.width, data.height);
    if w == 0 || h == 0 || w > MAX_IMAGE_SIDE || h > MAX_IMAGE_SIDE {
        return Err(format!("{w}×{h} pixels is outside 1..{MAX_IMAGE_SIDE}"));
    }
    let px = &data.pixels;
    let n = (w * h) as usize;
    let bytes_per_channel = if is32 {
        4
    } else if is16 {
        2
    } else {
        1
    };
    if px.len() != n * channels * bytes_per_channel {
        return Err(format!("decoded to {} bytes, not {w}×{h}×{channels} channels", px.len()));
    }
    let u16_at = |i: usize| (u16::from_ne_bytes([px[2 * i], px[2 * i + 1]]) >> 8) as u8;
    let f32_at = |i: usize| {
        let v = f32::from_ne_bytes([px[4 * i], px[4 * i + 1], px[4 * i + 2], px[4 * i + 3]]);
        (v.clamp(0.0, 1.0) * 255.0 + 0.5) as u8
    };
    let get: &dyn Fn(usize) -> u8 = if is32 {
        &f32_at
    } else if is16 {
        &u16_at
    } else {
        &|i| px[i]
    };
    let mut rgba = Vec::with_capacity(4 * n);
    for p in 0..n {
        let c = |k: usize| get(p * channels + k);
        let texel = match channels {
            1 => [c(0), c(0), c(0), 255],
            2 => [c(0), c(0), c(0), c(1)],
            3 => [c(0), c(1), c(2), 255],
            _ => [c(0), c(1), c(2), c(3)],
        };
        rgba.extend_from_slice(&texel);
    }
    let name = image.name().map(str::to_string).unwrap_or_else(|| format!("image {}", image.index()));
    Ok(Texture { name, width: w, height: h, rgba })
}

/// Decoded pixels in the decoder's channel layout.
struct DecodedPixels {
    width: u32,
    height: u32,
    pixels: Vec<u8>,
}

/// Largest decoded image held (RGBA32F at the largest side would be 4 GiB).
const MAX_DECODED_IMAGE_BYTES: u64 = 1 << 30;

/// A KHR_lights_punctual light placed by its node's world transform.
fn convert_light(light: &gltf::khr_lights_punctual::Light, world: Mat4) -> Option<PunctualLight> {
    use gltf::khr_lights_punctual::Kind;
    let intensity = Vec3::from(light.color()).max(Vec3::ZERO) * light.intensity().max(0.0);
    let position = world.transform_point3(Vec3::ZERO);
    let direction = world.transform_vector3(Vec3::NEG_Z).normalize_or_zero();
    let kind = match light.kind() {
        Kind::Point => PunctualKind::Point,
        Kind::Directional => PunctualKind::Directional,
        Kind::Spot { inner_cone_angle, outer_cone_angle } => {
            let outer = outer_cone_angle.clamp(0.0, std::f32::consts::FRAC_PI_2);
            let inner = inner_cone_angle.clamp(0.0, outer);
            PunctualKind::Spot { cos_inner: inner.cos(), cos_outer: outer.cos() }
        }
    };
    let range = light.range().filter(|r| r.is_finite() && *r > 0.0).unwrap_or(f32::INFINITY);
    let ok = intensity.is_finite() && position.is_finite() && direction != Vec3::ZERO && direction.is_finite();
    (ok && intensity.max_element() > 0.0).then_some(PunctualLight { kind, position, direction, intensity, range })
}

/// `extras.environment = {"type": "constant", "radiance": [r, g, b]}` on the scene, as the
/// reference scenes store it (glTF itself cannot describe an environment).
fn environment_from_extras(extras: &gltf::json::Extras) -> Option<Vec3> {
    let raw = extras.as_ref()?;
    let v: serde_json::Value = serde_json::from_str(raw.get()).ok()?;
    let env = v.get("environment")?;
    if env.get("type")?.as_str()? != "constant" {
        return None;
    }
    let r = env.get("radiance")?.as_array()?;
    let c: Vec<f32> = r.iter().filter_map(|x| x.as_f64().map(|x| x as f32)).collect();
    (c.len() == 3 && c.iter().all(|x| x.is_finite() && *x >= 0.0)).then(|| Vec3::new(c[0], c[1], c[2]))
}

fn load_mesh(
    mesh: &gltf::Mesh,
    world: Mat4,
    buffers: &[gltf::buffer::Data],
    default_material: u32,
    scene: &mut Scene,
) -> Result<(), String> {
    let normal_matrix = Mat3::from_mat4(world).inverse().transpose();
    // A mirroring transform flips the winding; swap two vertices to keep the front face.
    let mirrored = Mat3::from_mat4(world).determinant() < 0.0;
    for prim in mesh.primitives() {
        use gltf::mesh::Mode;
        let mode = prim.mode();
        if !matches!(mode, Mode::Triangles | Mode::TriangleStrip | Mode::TriangleFan) {
            continue; // points and lines have no area to render
        }
        let name = mesh.name().map_or_else(|| format!("mesh {}", mesh.index()), str::to_string);
        // Check every accessor we read against its buffer before the reader touches it.
        use gltf::accessor::Dimensions;
        let attrs = [
            ("POSITION", prim.get(&gltf::Semantic::Positions), Dimensions::Vec3),
            ("NORMAL", prim.get(&gltf::Semantic::Normals), Dimensions::Vec3),
            ("TEXCOORD_0", prim.get(&gltf::Semantic::TexCoords(0)), Dimensions::Vec2),
            ("TANGENT", prim.get(&gltf::Semantic::Tangents), Dimensions::Vec4),
            ("indices", prim.indices(), Dimensions::Scalar),
        ];
        for (what, accessor, dims) in attrs {
            if let Some(a) = accessor {
                check_accessor(&a, Some(dims), buffers)
                    .map_err(|e| format!("{name}: {what} accessor {}: {e}", a.index()))?;
            }
        }
        let reader = prim.reader(|b| buffers.get(b.index()).map(|d| &d.0[..]));
        let Some(positions) = reader.read_positions() else {
            continue;
        };
        let positions: Vec<Vec3> = positions.map(|p| world.transform_point3(Vec3::from(p))).collect();
        let nv = positions.len();
        let normals: Option<Vec<Vec3>> = reader
            .read_normals()
            .map(|n| n.map(|n| (normal_matrix * Vec3::from(n)).normalize_or_zero()).collect())
            .filter(|n: &Vec<Vec3>| n.len() == nv);
        let uvs: Option<Vec<Vec2>> = reader
            .read_tex_coords(0)
            .map(|t| t.into_f32().map(Vec2::from).collect())
            .filter(|t: &Vec<Vec2>| t.len() == nv);
        let indices: Vec<u32> = match reader.read_indices() {
            Some(i) => i.into_u32().collect(),
            None => (0..nv as u32).collect(),
        };
        let mut tris = triangulate(&indices, mode);
        if scene.triangles.len() + tris.len() > super::gltf::MAX_TRIANGLES {
            return Err(format!("more than {MAX_TRIANGLES} triangles"));
        }
        if let Some(bad) = tris.iter().flatten().find(|&&i| i as usize >= nv) {
            return Err(format!("{name}: index {bad} is out of range ({nv} vertices)"));
        }
        if mirrored {
            for t in &mut tris {
                t.swap(1, 2);
            }
        }
        let material = prim.material().index().map_or(default_material, |i| i as u32);
        let wants_tangents = scene.materials.get(material as usize).is_some_and(|m| m.normal_texture.is_some());
        // Tangents: the file's (a direction: transformed by the upper 3×3; a mirroring
        // transform flips the bitangent's handedness), else generated from UVs.
        let tangents: Option<Vec<Vec4>> = match (&uvs, wants_tangents) {
            (Some(uvs), true) => {
                let given: Option<Vec<Vec4>> = reader
                    .read_tangents()
                    .map(|t| {
                        t.map(|t| {
                            let v = (Mat3::from_mat4(world) * Vec3::new(t[0], t[1], t[2])).normalize_or_zero();
                            let w = if (t[3] < 0.0) != mirrored { -1.0 } else { 1.0 };
                            v.extend(w)
                        })
                        .collect()
                    })
                    .filter(|t: &Vec<Vec4>| t.len() == nv && t.iter().all(|v| v.is_finite()));
                Some(given.unwrap_or_else(|| {
                    let vertex_normals = normals.clone().unwrap_or_else(|| face_normals_per_vertex(&positions, &tris));
                    generate_tangents(&positions, &vertex_normals, uvs, &tris)
                }))
            }
            _ => None,
        };
        for idx in tris {
            let p = idx.map(|i| positions[i as usize]);
            if !p.iter().all(|v| v.is_finite()) {
                return Err(format!("{name}: non-finite vertex position"));
            }
            let ng = (p[1] - p[0]).cross(p[2] - p[0]).normalize_or_zero();
            let n = match &normals {
                Some(ns) => idx.map(|i| {
                    let n = ns[i as usize];
                    if n == Vec3::ZERO || !n.is_finite() { ng } else { n }
                }),
                None => [ng; 3],
            };
            let uv = match &uvs {
                Some(t) => idx.map(|i| {
                    let v = t[i as usize];
                    if v.is_finite() { v } else { Vec2::ZERO }
                }),
                None => [Vec2::ZERO; 3],
            };
            let tangents = tangents.as_ref().map_or([Vec4::ZERO; 3], |t| idx.map(|i| t[i as usize]));
            scene.triangles.push(Triangle { positions: p, normals: n, uvs: uv, tangents, material });
        }
    }
    Ok(())
}

/// An accessor's bytes lie inside its view, and its view inside its buffer; its type is one
/// veach reads.
fn check_accessor(
    a: &gltf::Accessor,
    dims: Option<gltf::accessor::Dimensions>,
    buffers: &[gltf::buffer::Data],
) -> Result<(), String> {
    use gltf::accessor::{DataType, Dimensions};
    if a.sparse().is_some() {
        return Err("sparse accessors are not supported".into());
    }
    if let Some(d) = dims
        && a.dimensions() != d
    {
        return Err(format!("is {:?}, expected {:?}", a.dimensions(), d));
    }
    let ok_type = match a.dimensions() {
        Dimensions::Scalar => matches!(a.data_type(), DataType::U8 | DataType::U16 | DataType::U32),
        // Texture coordinates may be normalised integers.
        Dimensions::Vec2 => a.data_type() == DataType::F32 || (a.normalized() && a.data_type() != DataType::U32),
        _ => a.data_type() == DataType::F32,
    };
    if !ok_type {
        return Err(format!("component type {:?} is not supported here", a.data_type()));
    }
    let view = a.view().ok_or("has no buffer view")?;
    let buffer = buffers.get(view.buffer().index()).ok_or("its buffer is missing")?;
    let view_end = (view.offset() as u64).checked_add(view.length() as u64).ok_or("view overflows")?;
    if view_end > buffer.0.len() as u64 {
        return Err(format!("its view ends at byte {view_end}, past the buffer's {} bytes", buffer.0.len()));
    }
    let elem = a.size() as u64;
    let stride = view.stride().map_or(elem, |s| s as u64);
    if stride < elem {
        return Err(format!("byte stride {stride} is smaller than an element ({elem} bytes)"));
    }
    if a.count() == 0 {
        return Ok(());
    }
    let need = (a.offset() as u64)
        .checked_add(stride.checked_mul(a.count() as u64 - 1).ok_or("count overflows")?)
        .and_then(|x| x.checked_add(elem))
        .ok_or("count overflows")?;
    if need > view.length() as u64 {
        return Err(format!("{} elements need {need} bytes, its view has {}", a.count(), view.length()));
    }
    Ok(())
}

/// Area-weighted face normals averaged per vertex (for tangent generation without NORMAL).
fn face_normals_per_vertex(positions: &[Vec3], tris: &[[u32; 3]]) -> Vec<Vec3> {
    let mut n = vec![Vec3::ZERO; positions.len()];
    for t in tris {
        let p = t.map(|i| positions[i as usize]);
        let c = (p[1] - p[0]).cross(p[2] - p[0]);
        for i in t {
            n[*i as usize] += c;
        }
    }
    n.into_iter().map(|v| v.normalize_or(Vec3::Z)).collect()
}

fn triangulate(indices: &[u32], mode: gltf::mesh::Mode) -> Vec<[u32; 3]> {
    use gltf::mesh::Mode;
    match mode {
        Mode::TriangleStrip => (2..indices.len())
            .map(|i| {
                if i % 2 == 0 {
                    [indices[i - 2], indices[i - 1], indices[i]]
                } else {
                    [indices[i - 1], indices[i - 2], indices[i]]
                }
            })
            .collect(),
        Mode::TriangleFan => (2..indices.len()).map(|i| [indices[0], indices[i - 1], indices[i]]).collect(),
        _ => indices.chunks_exact(3).map(|c| [c[0], c[1], c[2]]).collect(),
    }
}
