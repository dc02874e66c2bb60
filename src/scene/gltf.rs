//! glTF 2.0 import (.gltf and .glb) into a flat world-space `Scene`.

use super::{Camera, Material, Scene, Triangle};
use crate::Error;
use glam::{Mat3, Mat4, Vec3};
use std::path::Path;

/// Refuse scenes beyond this before allocating for them (hostile counts).
pub const MAX_TRIANGLES: usize = 64 << 20;

pub fn load(path: &Path) -> Result<Scene, Error> {
    let fail = |msg: String| Error::Input(format!("{}: {msg}", path.display()));
    let meta = std::fs::metadata(path).map_err(|e| fail(format!("cannot read: {e}")))?;
    if meta.is_dir() {
        return Err(fail("is a directory, not a glTF file".into()));
    }
    let (doc, buffers, _images) = gltf::import(path).map_err(|e| fail(describe(&e)))?;
    let mut scene = Scene::default();

    for m in doc.materials() {
        scene.materials.push(convert_material(&m));
    }
    // Primitives without a material use glTF's default one, appended last.
    let default_material = scene.materials.len() as u32;
    scene.materials.push(Material::default());

    let gltf_scene = doc.default_scene().or_else(|| doc.scenes().next());
    let Some(gltf_scene) = gltf_scene else {
        return Err(fail("the file has no scene".into()));
    };
    if let Some(env) = environment_from_extras(gltf_scene.extras()) {
        scene.environment = env;
    }

    let mut stack: Vec<(gltf::Node, Mat4, usize)> = gltf_scene.nodes().map(|n| (n, Mat4::IDENTITY, 0)).collect();
    while let Some((node, parent, depth)) = stack.pop() {
        if depth > 256 {
            return Err(fail("node hierarchy deeper than 256 levels (a cycle?)".into()));
        }
        let local = Mat4::from_cols_array_2d(&node.transform().matrix());
        let world = parent * local;
        if !world.is_finite() {
            return Err(fail(format!("node {} has a non-finite transform", node.index())));
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
            load_mesh(&mesh, world, &buffers, default_material, &mut scene).map_err(fail)?;
        }
        for child in node.children() {
            stack.push((child, world, depth + 1));
        }
    }
    // Depth-first order above reversed the cameras; keep the file's order for "first camera".
    scene.cameras.sort_by_key(|c| c.name.clone());
    let order = camera_order(&doc);
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
        let name = mesh.name().map_or_else(|| format!("mesh {}", mesh.index()), str::to_string);
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
