//! Generated benchmark and test scenes: a many-light floor and a glossy hall, written as
//! .gltf files with an embedded buffer.

use glam::{Quat, Vec3};

/// A deterministic stream of numbers in [0, 1) (a 64-bit LCG): the scenes are the same on
/// every machine.
fn uniform_stream(mut state: u64) -> impl FnMut() -> f32 {
    move || {
        state = state.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
        (state >> 40) as f32 / (1u64 << 24) as f32
    }
}

/// Triangles sharing one vertex array, grouped by material: one glTF primitive per group.
#[derive(Default)]
struct MeshBuilder {
    positions: Vec<Vec3>,
    groups: Vec<(serde_json::Value, Vec<u32>)>,
}

impl MeshBuilder {
    /// A new material; its triangles go into the primitive this returns.
    fn material(&mut self, material: serde_json::Value) -> usize {
        self.groups.push((material, Vec::new()));
        self.groups.len() - 1
    }

    /// The quad `center ± u ± v`, facing along u × v (emitters shine to their front only).
    fn quad(&mut self, group: usize, center: Vec3, u: Vec3, v: Vec3) {
        self.grid(group, center, u, v, 1);
    }

    /// The quad `center ± u ± v` as an n × n grid of quads.
    fn grid(&mut self, group: usize, center: Vec3, u: Vec3, v: Vec3, n: u32) {
        let base = self.positions.len() as u32;
        for j in 0..=n {
            for i in 0..=n {
                let (a, b) = (2.0 * i as f32 / n as f32 - 1.0, 2.0 * j as f32 / n as f32 - 1.0);
                self.positions.push(center + a * u + b * v);
            }
        }
        let w = n + 1;
        let indices = &mut self.groups[group].1;
        for j in 0..n {
            for i in 0..n {
                let a = base + j * w + i;
                indices.extend([a, a + 1, a + w + 1, a, a + w + 1, a + w]);
            }
        }
    }

    /// An octahedron of radius `r` around `center`, facing out: a small round lamp.
    fn octahedron(&mut self, group: usize, center: Vec3, r: f32) {
        let base = self.positions.len() as u32;
        for axis in [Vec3::X, -Vec3::X, Vec3::Y, -Vec3::Y, Vec3::Z, -Vec3::Z] {
            self.positions.push(center + r * axis);
        }
        let indices = &mut self.groups[group].1;
        for (x, y, z) in [(0, 2, 4), (1, 4, 2), (0, 5, 2), (1, 2, 5), (0, 4, 3), (1, 3, 4), (0, 3, 5), (1, 5, 3)] {
            indices.extend([base + x, base + y, base + z]);
        }
    }

    /// The glTF document: the mesh at the origin, a perspective camera (yfov, square) at
    /// `eye` turned by `rotation`.
    fn gltf(&self, eye: Vec3, rotation: Quat, yfov: f32) -> Vec<u8> {
        use base64::Engine;
        let mut bin: Vec<u8> = self.positions.iter().flat_map(|p| p.to_array()).flat_map(f32::to_le_bytes).collect();
        let index_offset = bin.len();
        let min = self.positions.iter().fold(Vec3::INFINITY, |a, &p| a.min(p));
        let max = self.positions.iter().fold(Vec3::NEG_INFINITY, |a, &p| a.max(p));
        let mut accessors = vec![serde_json::json!({"bufferView": 0, "componentType": 5126,
            "count": self.positions.len(), "type": "VEC3", "min": min.to_array(), "max": max.to_array()})];
        let mut primitives = Vec::new();
        let mut materials = Vec::new();
        for (k, (material, indices)) in self.groups.iter().enumerate() {
            accessors.push(serde_json::json!({"bufferView": 1, "byteOffset": bin.len() - index_offset,
                "componentType": 5125, "count": indices.len(), "type": "SCALAR"}));
            bin.extend(indices.iter().flat_map(|i| i.to_le_bytes()));
            primitives.push(serde_json::json!({"attributes": {"POSITION": 0}, "indices": k + 1, "material": k}));
            materials.push(material.clone());
        }
        let uri =
            format!("data:application/octet-stream;base64,{}", base64::engine::general_purpose::STANDARD.encode(&bin));
        let doc = serde_json::json!({
            "asset": {"version": "2.0", "generator": "veach bench"},
            "extensionsUsed": ["KHR_materials_emissive_strength"],
            "scene": 0,
            "scenes": [{"nodes": [0, 1]}],
            "nodes": [{"mesh": 0}, {"camera": 0, "translation": eye.to_array(), "rotation": rotation.to_array()}],
            "cameras": [{"type": "perspective", "perspective": {"yfov": yfov, "aspectRatio": 1.0, "znear": 0.01}}],
            "meshes": [{"primitives": primitives}],
            "materials": materials,
            "accessors": accessors,
            "bufferViews": [{"buffer": 0, "byteOffset": 0, "byteLength": index_offset},
                {"buffer": 0, "byteOffset": index_offset, "byteLength": bin.len() - index_offset}],
            "buffers": [{"byteLength": bin.len(), "uri": uri}],
        });
        serde_json::to_vec_pretty(&doc).expect("json")
    }
}

fn diffuse(name: &str, albedo: f32) -> serde_json::Value {
    serde_json::json!({"name": name,
        "pbrMetallicRoughness": {"baseColorFactor": [albedo, albedo, albedo, 1.0], "metallicFactor": 0.0}})
}

fn emitter(name: String, color: [f32; 3], strength: f32) -> serde_json::Value {
    serde_json::json!({"name": name, "emissiveFactor": color,
        "extensions": {"KHR_materials_emissive_strength": {"emissiveStrength": strength}},
        "pbrMetallicRoughness": {"baseColorFactor": [0.0, 0.0, 0.0, 1.0]}})
}

/// A many-light scene: a 40 × 40 floor under `lamps` small square lamps (4 × 4 grids, 32
/// triangles each) at heights 1–2.5, of radiance spanning two decades, facing down or
/// sideways, seen from above (the camera frames the middle 9 × 9). The same construction
/// as the many-light test (tests/light_tree.rs).
pub fn many_lights_gltf(lamps: u32) -> Vec<u8> {
    let mut f = uniform_stream(0x2545_f491_4f6c_dd1d);
    let mut mesh = MeshBuilder::default();
    let floor = mesh.material(diffuse("floor", 0.7));
    mesh.quad(floor, Vec3::ZERO, Vec3::new(20.0, 0.0, 0.0), Vec3::new(0.0, 20.0, 0.0));
    for k in 0..lamps {
        let strength = 0.2 * 10f32.powf(2.0 * f());
        let color = [0.5 + 0.5 * f(), 0.5 + 0.5 * f(), 0.5 + 0.5 * f()];
        let axis = if k % 3 == 0 {
            Vec3::new(f() - 0.5, f() - 0.5, -0.05 - 0.5 * f()).normalize()
        } else {
            Vec3::new(0.4 * (f() - 0.5), 0.4 * (f() - 0.5), -1.0).normalize()
        };
        let q = Quat::from_rotation_arc(Vec3::Z, axis);
        let t = Vec3::new(40.0 * (f() - 0.5), 40.0 * (f() - 0.5), 1.0 + 1.5 * f());
        let lamp = mesh.material(emitter(format!("lamp{k}"), color, strength));
        mesh.grid(lamp, t, q * Vec3::new(0.08, 0.0, 0.0), q * Vec3::new(0.0, 0.08, 0.0), 4);
    }
    mesh.gltf(Vec3::new(0.0, 0.0, 7.0), Quat::IDENTITY, 1.1)
}

/// Roughness of the glossy hall's metal runner: GGX α = roughness² ≈ 0.02.
pub const HALL_RUNNER_ROUGHNESS: f32 = 0.14;

/// Many small lights seen in a glossy surface: a hall 4 wide, 3 high and 30 long (along −z,
/// y up) lit by 100 small ceiling panels, 50 wall sconces and 30 small round lamps (octahedra)
/// of radiance spanning a decade, with diffuse walls, floor and ceiling and a polished metal
/// runner (GGX α ≈ 0.02) 1 wide down the middle of the floor; the camera stands at one end,
/// looking down the hall. The lower half of the image is mostly the runner.
pub fn glossy_hall_gltf() -> Vec<u8> {
    let mut f = uniform_stream(0x9e37_79b9_7f4a_7c15);
    let (x, y, z) = (Vec3::X, Vec3::Y, Vec3::Z);
    let mut mesh = MeshBuilder::default();
    let floor = mesh.material(diffuse("floor", 0.5));
    let walls = mesh.material(diffuse("walls", 0.6));
    let ceiling = mesh.material(diffuse("ceiling", 0.7));
    let runner = mesh.material(serde_json::json!({"name": "runner",
        "pbrMetallicRoughness": {"baseColorFactor": [0.9, 0.9, 0.9, 1.0], "metallicFactor": 1.0,
            "roughnessFactor": HALL_RUNNER_ROUGHNESS}}));
    let (half_len, mid) = (15.5, Vec3::new(0.0, 0.0, -14.5));
    // Floor strips either side of the runner, facing up (z × x = y).
    for side in [-1.25f32, 1.25] {
        mesh.quad(floor, mid + side * x, half_len * z, 0.75 * x);
    }
    mesh.quad(runner, mid + 0.001 * y, half_len * z, 0.5 * x);
    mesh.quad(ceiling, mid + 3.0 * y, 2.0 * x, half_len * z);
    mesh.quad(walls, mid + 1.5 * y - 2.0 * x, 1.5 * y, half_len * z);
    mesh.quad(walls, mid + 1.5 * y + 2.0 * x, half_len * z, 1.5 * y);
    mesh.quad(walls, mid + 1.5 * y - half_len * z, 2.0 * x, 1.5 * y);
    mesh.quad(walls, mid + 1.5 * y + half_len * z, 1.5 * y, 2.0 * x);
    let mut lamp = |mesh: &mut MeshBuilder, kind: &str, k: usize, strength: f32| {
        let warm = 0.8 + 0.2 * f();
        mesh.material(emitter(format!("{kind}{k}"), [1.0, warm, warm * warm], strength * 10f32.powf(f())))
    };
    for k in 0..100 {
        let g = lamp(&mut mesh, "panel", k, 4.0);
        let c = Vec3::new(if k % 2 == 0 { -0.8 } else { 0.8 }, 2.99, -0.6 - 0.58 * (k / 2) as f32);
        mesh.quad(g, c, 0.12 * x, 0.12 * z);
    }
    for k in 0..50 {
        let g = lamp(&mut mesh, "sconce", k, 8.0);
        let c = Vec3::new(0.0, 2.0, -1.0 - 1.14 * (k / 2) as f32);
        if k % 2 == 0 {
            mesh.quad(g, c - 1.99 * x, 0.1 * y, 0.05 * z);
        } else {
            mesh.quad(g, c + 1.99 * x, 0.05 * z, 0.1 * y);
        }
    }
    for k in 0..30 {
        let g = lamp(&mut mesh, "globe", k, 40.0);
        let c = Vec3::new(if k % 2 == 0 { -0.3 } else { 0.3 }, 2.4, -2.0 - 0.9 * k as f32);
        mesh.octahedron(g, c, 0.04);
    }
    // Eye height 1.6, turned down 12° about x.
    mesh.gltf(Vec3::new(0.0, 1.6, 0.0), Quat::from_rotation_x(-12f32.to_radians()), 0.9)
}
