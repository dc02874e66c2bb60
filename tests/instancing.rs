//! Instancing: a mesh drawn by several nodes is stored once (two-level BVH) and renders like
//! the same scene with every copy flattened into world space — including mirrored and
//! non-uniformly scaled copies of absorbing glass, where the facing of every normal matters
//! (refraction in or out, and absorption only on the way out of the volume).

mod common;

use common::build::{GltfBuilder, MeshData};
use common::{agreement, film_stats, gpu};
use glam::{Quat, Vec3};
use serde_json::json;
use std::path::PathBuf;
use veach::packed::PackedScene;
use veach::{Backend, Settings};

/// A unit cube centred at the origin with flat faces (24 vertices), wedge-cut so that a
/// mirror image differs: the +x face is tilted.
fn wedge() -> MeshData {
    let mut m = MeshData::default();
    let faces: [([f32; 3], [f32; 3], [f32; 3]); 6] = [
        ([0.0, 0.0, 1.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]),
        ([0.0, 0.0, -1.0], [-1.0, 0.0, 0.0], [0.0, 1.0, 0.0]),
        ([1.0, 0.0, 0.0], [0.0, 0.0, -1.0], [0.0, 1.0, 0.0]),
        ([-1.0, 0.0, 0.0], [0.0, 0.0, 1.0], [0.0, 1.0, 0.0]),
        ([0.0, 1.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, -1.0]),
        ([0.0, -1.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, 1.0]),
    ];
    for (n, u, v) in faces {
        let (n, u, v) = (Vec3::from(n), Vec3::from(u), Vec3::from(v));
        let base = m.positions.len() as u32;
        for (a, b) in [(-1.0, -1.0), (1.0, -1.0), (1.0, 1.0), (-1.0, 1.0)] {
            let mut p = 0.5 * (n + a * u + b * v);
            // The wedge: the top edge of the +x side leans in.
            if p.x > 0.0 && p.y > 0.0 {
                p.x -= 0.4;
            }
            m.positions.push(p.to_array());
        }
        m.indices.extend([base, base + 1, base + 2, base, base + 2, base + 3]);
    }
    m
}

/// Floor, a light and `placements` of the glass wedge: one shared mesh, or a copy each.
fn scene(name: &str, placements: &[serde_json::Value], shared: bool) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("veach-instancing-{}-{name}", std::process::id()));
    let mut b = GltfBuilder::new(&dir, name);
    b.use_extension("KHR_materials_transmission");
    b.use_extension("KHR_materials_volume");
    let grey =
        b.material(json!({"pbrMetallicRoughness": {"baseColorFactor": [0.7, 0.7, 0.7, 1], "metallicFactor": 0}}));
    let light =
        b.material(json!({"pbrMetallicRoughness": {"baseColorFactor": [0, 0, 0, 1]}, "emissiveFactor": [8, 8, 8]}));
    let glass = b.material(json!({"pbrMetallicRoughness": {"baseColorFactor": [0.9, 0.8, 1.0, 1], "metallicFactor": 0,
        "roughnessFactor": 0.2}, "extensions": {"KHR_materials_transmission": {"transmissionFactor": 1.0},
        "KHR_materials_volume": {"attenuationColor": [0.2, 0.5, 1.0], "attenuationDistance": 0.5,
        "thicknessFactor": 1.0}}}));
    let floor = b.mesh(&MeshData::quad(-6.0, -6.0, 6.0, 6.0, 0.0, MeshData::UPRIGHT), grey);
    b.node(json!({"mesh": floor, "rotation": Quat::from_rotation_x(-std::f32::consts::FRAC_PI_2).to_array()}));
    // The light faces down from y = 5.
    let lamp = b.mesh(&MeshData::quad(-1.5, -1.5, 1.5, 1.5, 0.0, MeshData::UPRIGHT), light);
    b.node(json!({"mesh": lamp, "translation": [0, 5, 0], "rotation": Quat::from_rotation_x(std::f32::consts::FRAC_PI_2).to_array()}));
    let mut mesh = None;
    for p in placements {
        let m = match (shared, mesh) {
            (true, Some(m)) => m,
            _ => b.mesh(&wedge(), glass),
        };
        mesh = Some(m);
        let mut node = p.clone();
        node["mesh"] = json!(m);
        b.node(node);
    }
    b.camera(0.9, 1.0, [0.0, 4.0, 9.0]);
    let path = b.write();
    // Aim the camera at the wedges: rewrite its node with a look-at rotation.
    let mut doc: serde_json::Value = serde_json::from_slice(&std::fs::read(&path).unwrap()).unwrap();
    let look = Quat::from_rotation_x(-0.35);
    for n in doc["nodes"].as_array_mut().unwrap() {
        if n.get("camera").is_some() {
            n["rotation"] = json!(look.to_array());
        }
    }
    std::fs::write(&path, serde_json::to_vec(&doc).unwrap()).unwrap();
    path
}

fn placements() -> Vec<serde_json::Value> {
    vec![
        json!({"translation": [-3.0, 0.5, 0.0]}),
        json!({"translation": [-1.0, 0.5, 0.5], "scale": [-1.0, 1.0, 1.0]}),
        json!({"translation": [1.0, 0.6, 0.0], "rotation": Quat::from_rotation_y(0.8).to_array()}),
        json!({"translation": [3.0, 0.25, 0.5], "scale": [1.5, 0.5, 1.0]}),
        json!({"translation": [0.0, 0.5, -2.0], "scale": [1.0, 1.0, -1.0], "rotation": Quat::from_rotation_y(-0.5).to_array()}),
        json!({"translation": [-2.0, 1.5, -2.5], "rotation": Quat::from_rotation_z(0.6).to_array(), "scale": [0.7, 0.7, 0.7]}),
    ]
}

fn render(path: &std::path::Path, ctx: Option<veach::gpu::GpuContext>) -> veach::film::Film {
    let (scene, camera) = common::load_pair(path, None).unwrap();
    let settings = Settings { width: 48, height: 48, max_depth: 8, ..Settings::default() };
    let mut r = common::renderer(PackedScene::new(&scene), &camera, &settings, ctx).unwrap();
    r.render_samples(0, 96).unwrap();
    r.film().unwrap()
}

/// The shared-mesh scene and its flattened copy, loaded and checked, rendered on one engine
/// and compared.
fn instanced_meshes_render_like_flattened_copies_on(ctx: Option<veach::gpu::GpuContext>) {
    let backend = if ctx.is_some() { Backend::Gpu } else { Backend::Cpu };
    let shared = scene(&format!("shared-{backend:?}"), &placements(), true);
    let copies = scene(&format!("copies-{backend:?}"), &placements(), false);
    let (s, _) = common::load_pair(&shared, None).unwrap();
    assert_eq!((s.meshes.len(), s.instances.len()), (1, 6));
    let (c, _) = common::load_pair(&copies, None).unwrap();
    assert_eq!((c.meshes.len(), c.instances.len()), (0, 0));
    assert_eq!(s.drawn_triangle_count(), c.triangles.len());

    let (am, av) = film_stats(&render(&shared, ctx.clone()));
    let (bm, bv) = film_stats(&render(&copies, ctx));
    let a = agreement(&am, &av, &bm, &bv);
    eprintln!("{backend:?}: {a:?}");
    assert!(a.mean_z.abs().max_element() < 5.0, "{backend:?}: instanced vs flattened {a:?}");
    // The wedges cover ~2 % of the pixels: a wrong facing on the two mirrored ones shows as
    // ~0.6 % of pixel channels beyond |z| = 4 (measured by breaking it); chance gives ~0.01 %.
    assert!(a.outliers < 0.002, "{backend:?}: instanced vs flattened {a:?}");
}

#[test]
fn instanced_meshes_render_like_flattened_copies() {
    instanced_meshes_render_like_flattened_copies_on(None);
}

#[test]
#[cfg_attr(veach_no_gpu, ignore = "needs a GPU adapter (no Vulkan driver on this machine)")]
fn instanced_meshes_render_like_flattened_copies_on_the_gpu() {
    let Some(ctx) = gpu("instanced_meshes_render_like_flattened_copies_on_the_gpu") else { return };
    instanced_meshes_render_like_flattened_copies_on(Some(ctx));
}

#[test]
fn instances_cost_a_transform_not_a_mesh() {
    let geometry = |n: usize| {
        let p: Vec<serde_json::Value> =
            (0..n).map(|i| json!({"translation": [i as f32 * 1.5 - 10.0, 0.5, (i / 10) as f32 * -1.5]})).collect();
        let (scene, _) = common::load_pair(&scene(&format!("n{n}"), &p, true), None).unwrap();
        let packed = PackedScene::new(&scene);
        (std::mem::size_of_val(&packed.nodes[..])
            + std::mem::size_of_val(&packed.triangles[..])
            + std::mem::size_of_val(&packed.attributes[..])) as f64
    };
    let (two, hundred) = (geometry(2), geometry(100));
    // 98 more instances: a 128-byte record each and about one top-level node pair (64 bytes).
    let per_instance = (hundred - two) / 98.0;
    eprintln!("bytes per extra instance: {per_instance}");
    assert!(per_instance <= 200.0, "{per_instance} bytes per instance");
}
