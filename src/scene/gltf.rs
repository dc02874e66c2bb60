//! glTF 2.0 import (.gltf and .glb) into a flat world-space `Scene`.

use super::{Camera, Material, Scene, Triangle};
use crate::Error;
use glam::{Mat3, Mat4, Vec3};
use std::path::Path;

/// Refuse scenes beyond this before allocating for them (hostile counts).
pub const MAX_TRIANGLES: usize = 64 << 20;
/// Largest glTF/GLB file or buffer accepted.
pub const MAX_FILE_BYTES: u64 = 4 << 30;
/// Most node visits while flattening the hierarchy (shared subtrees multiply).
pub const MAX_NODE_VISITS: usize = 1 << 20;

/// Extensions veach reads (or can safely ignore) when a file requires them.
pub const SUPPORTED_EXTENSIONS: &[&str] =
    &["KHR_materials_emissive_strength", "KHR_materials_specular", "KHR_materials_ior"];

/// Extensions veach knows and ignores for now (textures, transmission, lights come later);
/// files that merely use them render, with one warning each.
const KNOWN_UNIMPLEMENTED: &[&str] =
    &["KHR_texture_transform", "KHR_materials_transmission", "KHR_materials_volume", "KHR_lights_punctual"];

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
/// embedded data). Errors are the problem alone, without the file name.
pub fn load_bytes(bytes: &[u8], base: Option<&Path>) -> Result<Scene, String> {
    let json = if bytes.starts_with(b"glTF") { glb_json_chunk(bytes)? } else { bytes };
    let raw: serde_json::Value = serde_json::from_slice(json).map_err(|e| format!("invalid glTF JSON: {e}"))?;
    let mut warnings = Vec::new();
    check_extensions(&raw, &mut warnings)?;
    let gltf = contained(|| gltf::Gltf::from_slice(bytes))?.map_err(|e| describe(&e))?;
    for buffer in gltf.document.buffers() {
        if buffer.length() as u64 > MAX_FILE_BYTES {
            return Err(format!("buffer {} declares {} bytes, above the limit", buffer.index(), buffer.length()));
        }
    }
    let blob = gltf.blob.clone();
    let buffers = contained(|| gltf::import_buffers(&gltf.document, base.or(Some(Path::new("."))), blob))?
        .map_err(|e| describe(&e))?;
    let mut scene = from_document(&gltf.document, &buffers)?;
    scene.warnings = warnings;
    Ok(scene)
}

thread_local! {
    static CONTAINED: std::cell::Cell<bool> = const { std::cell::Cell::new(false) };
}

/// Runs a call into the gltf crate, turning a panic into an error. Its validator indexes
/// arrays with unchecked indices from the file (gltf-json 1.4.1, mesh.rs:151), so a hostile
/// file can make it panic; while contained, the panic prints nothing.
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
    CONTAINED.with(|c| c.set(true));
    let result = std::panic::catch_unwind(std::panic::AssertUnwindSafe(f));
    CONTAINED.with(|c| c.set(false));
    result.map_err(|_| "invalid glTF: an index or reference is out of range".to_string())
}

/// A summary of a glTF file for `veach info SCENE`: what the file holds and what veach loads.
pub fn describe_file(path: &Path) -> Result<String, Error> {
    let scene = load(path)?;
    let fail = |m: String| Error::Input(format!("{}: {m}", path.display()));
    let bytes = std::fs::read(path).map_err(|e| fail(format!("cannot read: {e}")))?;
    let json = if bytes.starts_with(b"glTF") { glb_json_chunk(&bytes).map_err(fail)? } else { &bytes[..] };
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
        "{}\n  triangles {} ({} emissive)\n  meshes {}\n  instances (nodes with a mesh) {}\n  materials {}\n  textures {} (images {})\n  \
         punctual lights {}\n  cameras {} ({})\n  extensions used: {}\n  extensions required: {}\n  bounds {}",
        path.display(),
        scene.triangles.len(),
        scene.emissive_triangle_count(),
        count("meshes"),
        instances,
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

/// The JSON chunk of a GLB, after checking the container's header and chunk bounds.
fn glb_json_chunk(bytes: &[u8]) -> Result<&[u8], String> {
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
    if end + 8 <= length {
        let bin_len = word(end)? as usize;
        if end.checked_add(8).and_then(|s| s.checked_add(bin_len)).is_none_or(|e| e > length) {
            return Err("GLB BIN chunk runs past the file".into());
        }
    }
    Ok(&bytes[20..end])
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

fn from_document(doc: &gltf::Document, buffers: &[gltf::buffer::Data]) -> Result<Scene, String> {
    let mut scene = Scene::default();

    for m in doc.materials() {
        scene.materials.push(convert_material(&m));
    }
    // Primitives without a material use glTF's default one, appended last.
    let default_material = scene.materials.len() as u32;
    scene.materials.push(Material::default());

    let gltf_scene = doc.default_scene().or_else(|| doc.scenes().next());
    let Some(gltf_scene) = gltf_scene else {
        return Err("the file has no scene".into());
    };
    if let Some(env) = environment_from_extras(gltf_scene.extras()) {
        scene.environment = env;
    }

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
            load_mesh(&mesh, world, buffers, default_material, &mut scene)?;
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

fn convert_material(m: &gltf::Material) -> Material {
    let pbr = m.pbr_metallic_roughness();
    let [r, g, b, _a] = pbr.base_color_factor();
    let strength = m.emissive_strength().unwrap_or(1.0);
    let (specular_factor, specular_color) = match m.specular() {
        Some(s) => (s.specular_factor(), Vec3::from(s.specular_color_factor())),
        None => (1.0, Vec3::ONE),
    };
    let sane = |v: f32, lo: f32, hi: f32, default: f32| if v.is_finite() { v.clamp(lo, hi) } else { default };
    let sane3 = |v: Vec3| if v.is_finite() { v.max(Vec3::ZERO) } else { Vec3::ZERO };
    Material {
        base_color: sane3(Vec3::new(r, g, b)),
        metallic: sane(pbr.metallic_factor(), 0.0, 1.0, 1.0),
        roughness: sane(pbr.roughness_factor(), 0.0, 1.0, 1.0),
        emission: sane3(Vec3::from(m.emissive_factor()) * strength),
        specular_factor: sane(specular_factor, 0.0, 1.0, 1.0),
        specular_color: sane3(specular_color),
        ior: sane(m.ior().unwrap_or(1.5), 1.0, 10.0, 1.5),
    }
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
        let attrs = [
            ("POSITION", prim.get(&gltf::Semantic::Positions), gltf::accessor::Dimensions::Vec3),
            ("NORMAL", prim.get(&gltf::Semantic::Normals), gltf::accessor::Dimensions::Vec3),
            ("indices", prim.indices(), gltf::accessor::Dimensions::Scalar),
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
        let positions: Vec<Vec3> = positions.map(Vec3::from).collect();
        let normals: Option<Vec<Vec3>> = reader.read_normals().map(|n| n.map(Vec3::from).collect());
        let indices: Vec<u32> = match reader.read_indices() {
            Some(i) => i.into_u32().collect(),
            None => (0..positions.len() as u32).collect(),
        };
        let tris = triangulate(&indices, mode);
        if scene.triangles.len() + tris.len() > super::gltf::MAX_TRIANGLES {
            return Err(format!("more than {MAX_TRIANGLES} triangles"));
        }
        let material = prim.material().index().map_or(default_material, |i| i as u32);
        for [a, b, c] in tris {
            let mut idx = [a, b, c];
            if mirrored {
                idx.swap(1, 2);
            }
            if let Some(bad) = idx.iter().find(|&&i| i as usize >= positions.len()) {
                return Err(format!("{name}: index {bad} is out of range ({} vertices)", positions.len()));
            }
            let p = idx.map(|i| world.transform_point3(positions[i as usize]));
            if !p.iter().all(|v| v.is_finite()) {
                return Err(format!("{name}: non-finite vertex position"));
            }
            let ng = (p[1] - p[0]).cross(p[2] - p[0]).normalize_or_zero();
            let n = match &normals {
                Some(ns) if ns.len() == positions.len() => idx.map(|i| {
                    let n = (normal_matrix * ns[i as usize]).normalize_or_zero();
                    if n == Vec3::ZERO || !n.is_finite() { ng } else { n }
                }),
                _ => [ng; 3],
            };
            scene.triangles.push(Triangle { positions: p, normals: n, material });
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
