//! glTF 2.0 import (.gltf and .glb) into a flat world-space `Scene`.

mod accessor;
mod describe;
mod draco;
mod extensions;
mod glb;
mod image;
mod light;
mod material;
mod mesh;
mod meshopt;
mod resources;

pub use describe::{Description, describe_file, describe_scene};
pub use extensions::SUPPORTED_EXTENSIONS;
pub use image::MAX_DECODED_IMAGE_SIDE;
pub use material::uv_transform;

use super::{Camera, Material, Scene, Texture};
use crate::Error;
use extensions::check_extensions;
use glam::{Mat3, Mat4};
use glb::glb_chunks;
use image::decode_image;
use light::{convert_light, environment_from_extras};
use material::convert_material;
use mesh::load_mesh;
use std::path::Path;

/// Refuse scenes beyond this before allocating for them (hostile counts).
pub const MAX_TRIANGLES: usize = 64 << 20;
/// The most elements one accessor (or decoded stream) may have: three vertices per triangle
/// of the limit.
pub const MAX_ELEMENTS: usize = 3 * MAX_TRIANGLES;
/// Largest glTF/GLB file or buffer accepted.
pub const MAX_FILE_BYTES: u64 = 4 << 30;
/// Most node visits while flattening the hierarchy (shared subtrees multiply).
pub const MAX_NODE_VISITS: usize = 1 << 20;

/// Which of a file's choices to load: a scene other than its default one, a material variant
/// (KHR_materials_variants) other than the default materials.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Choice {
    pub scene: Option<usize>,
    pub variant: Option<String>,
}

pub fn load(path: &Path) -> Result<Scene, Error> {
    load_with(path, &Choice::default())
}

pub fn load_with(path: &Path, choice: &Choice) -> Result<Scene, Error> {
    let fail = |msg: String| Error::Input(format!("{}: {msg}", path.display()));
    let meta = std::fs::metadata(path).map_err(|e| fail(format!("cannot read: {e}")))?;
    if meta.is_dir() {
        return Err(fail("is a directory, not a glTF file".into()));
    }
    // A device or a pipe (/dev/zero, a FIFO named by a damaged EXR's job) would be read
    // forever or block: only regular files, and never more than the limit.
    if !meta.is_file() {
        return Err(fail("not a regular file".into()));
    }
    if meta.len() > MAX_FILE_BYTES {
        return Err(fail(format!("{} bytes: larger than the {MAX_FILE_BYTES}-byte limit", meta.len())));
    }
    let mut bytes = Vec::new();
    let file = std::fs::File::open(path).map_err(|e| fail(format!("cannot read: {e}")))?;
    std::io::Read::read_to_end(&mut std::io::Read::take(file, MAX_FILE_BYTES + 1), &mut bytes)
        .map_err(|e| fail(format!("cannot read: {e}")))?;
    if bytes.len() as u64 > MAX_FILE_BYTES {
        return Err(fail(format!("larger than the {MAX_FILE_BYTES}-byte limit")));
    }
    load_bytes_with(&bytes, path.parent(), choice).map_err(fail)
}

/// Loads a .gltf or .glb held in memory; external files resolve against `base` (none: only
/// embedded data, GLB chunks and data: URIs). Errors are the problem alone, without the file
/// name.
pub fn load_bytes(bytes: &[u8], base: Option<&Path>) -> Result<Scene, String> {
    load_bytes_with(bytes, base, &Choice::default())
}

pub fn load_bytes_with(bytes: &[u8], base: Option<&Path>, choice: &Choice) -> Result<Scene, String> {
    let (json, blob) = if bytes.starts_with(b"glTF") { glb_chunks(bytes)? } else { (bytes, None) };
    let mut raw: serde_json::Value = serde_json::from_slice(json).map_err(|e| format!("invalid glTF JSON: {e}"))?;
    let mut warnings = Vec::new();
    check_extensions(&raw, &mut warnings)?;
    let fallbacks = normalise(&mut raw);
    let root: gltf::json::Root = serde_json::from_value(raw).map_err(|e| format!("invalid glTF JSON: {e}"))?;
    let document = contained(|| gltf::Document::from_json(root))?.map_err(|e| describe(&e))?;
    for buffer in document.buffers() {
        if buffer.length() as u64 > MAX_FILE_BYTES {
            return Err(format!("buffer {} declares {} bytes, above the limit", buffer.index(), buffer.length()));
        }
    }
    let base = resources::Base(base);
    let buffers = resources::load_buffers(&document, blob, base)?;
    let mut scene = from_document(&document, &buffers, base, &fallbacks, choice, &mut warnings)?;
    scene.warnings = warnings;
    Ok(scene)
}

/// Fills in what glTF lets a file leave out but the gltf crate's schema requires, so that
/// valid files load: a scene without `nodes` is an empty scene. Animations are dropped:
/// veach renders the rest pose, and KHR_animation_pointer's channels (no `node`) would fail
/// the crate's schema. `extensionsRequired` is dropped once `check_extensions` has accepted
/// it: the crate's validator refuses every required extension outside its own feature list
/// (KHR_materials_unlit among them), even the ones veach implements itself.
///
/// A texture whose image comes from EXT_texture_webp or KHR_texture_basisu gets that image as
/// its `source` (the crate knows neither extension and needs a source); its own `source`, the
/// PNG/JPEG fallback, is returned as (preferred image, fallback image) to use when the
/// preferred one cannot be decoded.
fn normalise(raw: &mut serde_json::Value) -> Vec<(usize, usize)> {
    if let Some(root) = raw.as_object_mut() {
        root.remove("animations");
        root.remove("extensionsRequired");
    }
    let mut fallbacks = Vec::new();
    if let Some(textures) = raw.get_mut("textures").and_then(|t| t.as_array_mut()) {
        for texture in textures.iter_mut().filter_map(|t| t.as_object_mut()) {
            let preferred = ["EXT_texture_webp", "KHR_texture_basisu"].iter().find_map(|e| {
                texture.get("extensions").and_then(|x| x.get(e)).and_then(|x| x.get("source")).and_then(|s| s.as_u64())
            });
            if let Some(image) = preferred {
                if let Some(fallback) = texture.get("source").and_then(|s| s.as_u64()) {
                    fallbacks.push((image as usize, fallback as usize));
                }
                texture.insert("source".into(), serde_json::json!(image));
            }
        }
    }
    if let Some(scenes) = raw.get_mut("scenes").and_then(|s| s.as_array_mut()) {
        for scene in scenes.iter_mut().filter_map(|s| s.as_object_mut()) {
            scene.entry("nodes").or_insert_with(|| serde_json::json!([]));
        }
    }
    // An accessor with neither a buffer view nor sparse values holds zeros (glTF allows it;
    // Draco's accessors are all like this), but the crate's schema refuses it: it gets a
    // sparse block of no values, which `accessor.rs` reads as zeros.
    let has_views = raw.get("bufferViews").and_then(|v| v.as_array()).is_some_and(|v| !v.is_empty());
    if has_views && let Some(accessors) = raw.get_mut("accessors").and_then(|a| a.as_array_mut()) {
        for a in accessors.iter_mut().filter_map(|a| a.as_object_mut()) {
            if !a.contains_key("bufferView") && !a.contains_key("sparse") {
                a.insert(
                    "sparse".into(),
                    serde_json::json!({"count": 0, "indices": {"bufferView": 0, "componentType": 5125},
                        "values": {"bufferView": 0}}),
                );
            }
        }
    }
    fallbacks
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

/// The transforms a node draws its mesh with: its own, or with EXT_mesh_gpu_instancing one per
/// instance (the node's transform times the instance's translation, rotation and scale).
fn gpu_instances(
    node: &gltf::Node,
    doc: &gltf::Document,
    views: &accessor::Views,
    world: Mat4,
) -> Result<Vec<Mat4>, String> {
    let Some(attributes) = node.extension_value("EXT_mesh_gpu_instancing").and_then(|e| e.get("attributes")) else {
        return Ok(vec![world]);
    };
    let fail = |e: String| format!("node {}: EXT_mesh_gpu_instancing: {e}", node.index());
    let read = |name: &str, comps: usize| -> Result<Option<Vec<f32>>, String> {
        let Some(i) = attributes.get(name).and_then(|v| v.as_u64()) else { return Ok(None) };
        let a = doc.accessors().nth(i as usize).ok_or_else(|| fail(format!("no accessor {i}")))?;
        accessor::read_floats(&a, views, comps).map(Some).map_err(|e| fail(format!("{name}: {e}")))
    };
    let (t, r, s) = (read("TRANSLATION", 3)?, read("ROTATION", 4)?, read("SCALE", 3)?);
    let count = [t.as_ref().map(|v| v.len() / 3), r.as_ref().map(|v| v.len() / 4), s.as_ref().map(|v| v.len() / 3)];
    let n = count.iter().flatten().copied().max().unwrap_or(0);
    if count.iter().flatten().any(|&c| c != n) {
        return Err(fail("its attributes have different counts".into()));
    }
    if n > MAX_NODE_VISITS {
        return Err(fail(format!("{n} instances, above the limit of {MAX_NODE_VISITS}")));
    }
    Ok((0..n)
        .map(|i| {
            let translation = t.as_ref().map_or(glam::Vec3::ZERO, |v| glam::Vec3::from_slice(&v[3 * i..]));
            let rotation = r.as_ref().map_or(glam::Quat::IDENTITY, |v| {
                glam::Vec4::from_slice(&v[4 * i..]).try_normalize().map_or(glam::Quat::IDENTITY, glam::Quat::from_vec4)
            });
            let scale = s.as_ref().map_or(glam::Vec3::ONE, |v| glam::Vec3::from_slice(&v[3 * i..]));
            world * Mat4::from_scale_rotation_translation(scale, rotation, translation)
        })
        .collect())
}

/// The index of the KHR_materials_variants variant named `name`.
fn variant_index(doc: &gltf::Document, name: &str) -> Result<usize, String> {
    let names: Vec<String> = doc
        .extension_value("KHR_materials_variants")
        .and_then(|v| v.get("variants"))
        .and_then(|v| v.as_array())
        .map(|a| a.iter().map(|v| v.get("name").and_then(|n| n.as_str()).unwrap_or("").to_string()).collect())
        .unwrap_or_default();
    names.iter().position(|n| n == name).ok_or_else(|| {
        if names.is_empty() {
            format!("no material variant '{name}': the file has none (KHR_materials_variants)")
        } else {
            format!("no material variant '{name}' (the file has: {})", names.join(", "))
        }
    })
}

/// Every node's world transform (its parents' chain, whether or not the scene draws it):
/// skins place their joints with them.
fn node_globals(doc: &gltf::Document) -> Result<Vec<Mat4>, String> {
    let n = doc.nodes().len();
    let mut parent = vec![None; n];
    for node in doc.nodes() {
        for child in node.children() {
            if let Some(p) = parent.get_mut(child.index()) {
                *p = Some(node.index());
            }
        }
    }
    let locals: Vec<Mat4> = doc.nodes().map(|node| Mat4::from_cols_array_2d(&node.transform().matrix())).collect();
    let mut globals = vec![None; n];
    for start in 0..n {
        // Walk up to a node whose transform is known (or a root), then back down.
        let mut chain = vec![start];
        while let Some(p) = parent[*chain.last().unwrap_or(&start)] {
            if globals[p].is_some() {
                break;
            }
            if chain.len() > 256 {
                return Err("node hierarchy deeper than 256 levels (a cycle?)".into());
            }
            chain.push(p);
        }
        let top = *chain.last().unwrap_or(&start);
        let mut m = parent[top].and_then(|p| globals[p]).unwrap_or(Mat4::IDENTITY);
        for &k in chain.iter().rev() {
            if globals[k].is_none() {
                m *= locals[k];
                globals[k] = Some(m);
            } else {
                m = globals[k].unwrap_or(m);
            }
        }
    }
    Ok(globals.into_iter().map(|g| g.unwrap_or(Mat4::IDENTITY)).collect())
}

fn from_document(
    doc: &gltf::Document,
    buffers: &[gltf::buffer::Data],
    base: resources::Base,
    fallbacks: &[(usize, usize)],
    choice: &Choice,
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
            Err(e) => {
                let fallback = fallbacks.iter().find(|f| f.0 == i).map(|f| f.1);
                let what = if fallback.is_some() { "using its fallback image" } else { "rendering without it" };
                warnings.push(format!("image {i}: {e}; {what}"));
            }
        }
    }
    // A WebP or Basis Universal image that did not decode gives way to its texture's fallback.
    for &(preferred, fallback) in fallbacks {
        if image_slot.get(preferred).is_some_and(Option::is_none)
            && let Some(&Some(slot)) = image_slot.get(fallback)
        {
            image_slot[preferred] = Some(slot);
        }
    }
    for m in doc.materials() {
        scene.materials.push(convert_material(&m, doc, &image_slot, &mut scene.textures, warnings));
    }
    // Primitives without a material use glTF's default one, appended last.
    let default_material = scene.materials.len() as u32;
    scene.materials.push(Material::default());

    let gltf_scene = match choice.scene {
        Some(k) => doc.scenes().nth(k).ok_or_else(|| format!("no scene {k} (the file has {})", doc.scenes().len()))?,
        None => match doc.default_scene().or_else(|| doc.scenes().next()) {
            Some(s) => s,
            None => return Err("the file has no scene".into()),
        },
    };
    let variant = match &choice.variant {
        Some(name) => Some(variant_index(doc, name)?),
        None => None,
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
    let views = accessor::Views::new(doc, buffers)?;
    let globals = node_globals(doc)?;
    let sources = mesh::MeshSources { doc, views: &views, globals: &globals, variant };
    let mut stored: Vec<Option<u32>> = vec![None; uses.len()];
    let mut stack: Vec<(gltf::Node, Mat4, usize)> = gltf_scene.nodes().map(|n| (n, Mat4::IDENTITY, 0)).collect();
    let mut visits = 0usize;
    let mut camera_nodes = Vec::new();
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
        if let Some(cam) = node.camera() {
            let name = node.name().or(cam.name()).map(str::to_string).unwrap_or_default();
            let camera = match cam.projection() {
                gltf::camera::Projection::Perspective(p) => Camera::from_matrix(name, world, p.yfov()),
                gltf::camera::Projection::Orthographic(o) => {
                    let ymag = o.ymag().abs();
                    if !(ymag.is_finite() && ymag > 0.0) {
                        return Err(format!("camera {}: orthographic ymag {} (expected > 0)", cam.index(), o.ymag()));
                    }
                    Camera::orthographic(name, world, ymag)
                }
            };
            scene.cameras.push(camera);
            camera_nodes.push(node.index());
        }
        if let Some(mesh) = node.mesh() {
            let emits = mesh.primitives().any(|p| {
                let m = p.material().index().map_or(default_material as usize, |i| i);
                scene.materials.get(m).is_some_and(Material::is_emissive)
            });
            // EXT_mesh_gpu_instancing: the node draws its mesh once per instance transform.
            let placements = gpu_instances(&node, doc, &views, world)?;
            let many = placements.len() > 1 || uses.get(mesh.index()).is_some_and(|&u| u >= 2);
            // A skin or the node's own morph weights make the node's geometry its own.
            let shared = node.skin().is_none() && node.weights().is_none();
            for world in placements {
                let det = Mat3::from_mat4(world).determinant();
                let invertible = det.is_finite() && det.abs() > 1e-24 && world.inverse().is_finite();
                if many && !emits && invertible && shared {
                    let id = match stored[mesh.index()] {
                        Some(id) => id,
                        None => {
                            let world_triangles = std::mem::take(&mut scene.triangles);
                            let loaded =
                                load_mesh(&mesh, Mat4::IDENTITY, Some(&node), &sources, default_material, &mut scene);
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
                    load_mesh(&mesh, world, Some(&node), &sources, default_material, &mut scene)?;
                }
            }
        }
        if let Some(light) = node.light() {
            scene.punctual_lights.extend(convert_light(&light, world));
        }
        for child in node.children() {
            stack.push((child, world, depth + 1));
        }
    }
    // The walk above is depth-first from a stack; the "first camera" is the first camera node
    // of the file. Unnamed cameras are then named in that order.
    let mut cameras: Vec<(usize, Camera)> = camera_nodes.into_iter().zip(std::mem::take(&mut scene.cameras)).collect();
    cameras.sort_by_key(|(node, _)| *node);
    scene.cameras = cameras.into_iter().map(|(_, c)| c).collect();
    for (k, c) in scene.cameras.iter_mut().enumerate() {
        if c.name.is_empty() {
            c.name = format!("camera{k}");
        }
    }
    Ok(scene)
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
