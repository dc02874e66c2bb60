//! A tiny glTF writer for test scenes built in code: one .bin buffer, PNG images beside it.

use serde_json::{Value, json};
use std::path::{Path, PathBuf};

pub struct GltfBuilder {
    dir: PathBuf,
    name: String,
    doc: Value,
    bin: Vec<u8>,
    roots: Vec<usize>,
}

/// One triangle mesh primitive's attributes.
#[derive(Default)]
pub struct MeshData {
    pub positions: Vec<[f32; 3]>,
    pub normals: Vec<[f32; 3]>,
    pub uvs: Vec<[f32; 2]>,
    pub tangents: Vec<[f32; 4]>,
    pub indices: Vec<u32>,
}

impl MeshData {
    /// An axis-aligned quad in the z = `z` plane facing +z, corners (x0, y0)–(x1, y1), with
    /// the UV of each corner given (bottom-left, bottom-right, top-right, top-left).
    pub fn quad(x0: f32, y0: f32, x1: f32, y1: f32, z: f32, uvs: [[f32; 2]; 4]) -> MeshData {
        MeshData {
            positions: vec![[x0, y0, z], [x1, y0, z], [x1, y1, z], [x0, y1, z]],
            normals: vec![[0.0, 0.0, 1.0]; 4],
            uvs: uvs.to_vec(),
            tangents: Vec::new(),
            indices: vec![0, 1, 2, 0, 2, 3],
        }
    }

    /// The image upright on the quad: u along +x, v down the image (−y).
    pub const UPRIGHT: [[f32; 2]; 4] = [[0.0, 1.0], [1.0, 1.0], [1.0, 0.0], [0.0, 0.0]];
}

impl GltfBuilder {
    pub fn new(dir: &Path, name: &str) -> GltfBuilder {
        std::fs::create_dir_all(dir).expect("test directory");
        GltfBuilder {
            dir: dir.to_path_buf(),
            name: name.to_string(),
            doc: json!({
                "asset": {"version": "2.0"},
                "scene": 0,
                "scenes": [{"nodes": []}],
                "nodes": [], "meshes": [], "materials": [], "accessors": [], "bufferViews": [],
                "buffers": [], "images": [], "textures": [], "samplers": [], "cameras": [],
                "extensionsUsed": [],
            }),
            bin: Vec::new(),
            roots: Vec::new(),
        }
    }

    fn push(&mut self, key: &str, value: Value) -> usize {
        let a = self.doc[key].as_array_mut().expect("array");
        a.push(value);
        a.len() - 1
    }

    pub fn use_extension(&mut self, name: &str) {
        if !self.doc["extensionsUsed"].as_array().unwrap().iter().any(|v| v == name) {
            self.push("extensionsUsed", json!(name));
        }
    }

    fn view(&mut self, bytes: &[u8]) -> usize {
        while !self.bin.len().is_multiple_of(4) {
            self.bin.push(0);
        }
        let offset = self.bin.len();
        self.bin.extend_from_slice(bytes);
        self.push("bufferViews", json!({"buffer": 0, "byteOffset": offset, "byteLength": bytes.len()}))
    }

    fn accessor_f32<const N: usize>(&mut self, data: &[[f32; N]], ty: &str) -> usize {
        let bytes: Vec<u8> = data.iter().flatten().flat_map(|v| v.to_le_bytes()).collect();
        let view = self.view(&bytes);
        let mut a = json!({"bufferView": view, "componentType": 5126, "count": data.len(), "type": ty});
        if N == 3 {
            let min: Vec<f32> = (0..N).map(|k| data.iter().map(|v| v[k]).fold(f32::INFINITY, f32::min)).collect();
            let max: Vec<f32> = (0..N).map(|k| data.iter().map(|v| v[k]).fold(f32::NEG_INFINITY, f32::max)).collect();
            a["min"] = json!(min);
            a["max"] = json!(max);
        }
        self.push("accessors", a)
    }

    pub fn mesh(&mut self, data: &MeshData, material: usize) -> usize {
        let mut attributes = serde_json::Map::new();
        attributes.insert("POSITION".into(), json!(self.accessor_f32(&data.positions, "VEC3")));
        if !data.normals.is_empty() {
            attributes.insert("NORMAL".into(), json!(self.accessor_f32(&data.normals, "VEC3")));
        }
        if !data.uvs.is_empty() {
            attributes.insert("TEXCOORD_0".into(), json!(self.accessor_f32(&data.uvs, "VEC2")));
        }
        if !data.tangents.is_empty() {
            attributes.insert("TANGENT".into(), json!(self.accessor_f32(&data.tangents, "VEC4")));
        }
        let bytes: Vec<u8> = data.indices.iter().flat_map(|v| v.to_le_bytes()).collect();
        let view = self.view(&bytes);
        let indices = self.push(
            "accessors",
            json!({"bufferView": view, "componentType": 5125, "count": data.indices.len(), "type": "SCALAR"}),
        );
        self.push(
            "meshes",
            json!({"primitives": [{"attributes": attributes, "indices": indices, "material": material}]}),
        )
    }

    pub fn material(&mut self, m: Value) -> usize {
        self.push("materials", m)
    }

    /// A texture over a PNG written beside the glTF; `wrap` is a GL wrap mode for s and t.
    pub fn texture(&mut self, image: &image::RgbaImage, wrap: u32) -> usize {
        let file = format!("{}-{}.png", self.name, self.doc["images"].as_array().unwrap().len());
        image.save(self.dir.join(&file)).expect("write test texture");
        let source = self.push("images", json!({"uri": file}));
        let sampler = self.push("samplers", json!({"wrapS": wrap, "wrapT": wrap}));
        self.push("textures", json!({"source": source, "sampler": sampler}))
    }

    /// A root node (mesh, camera or light, with its transform).
    pub fn node(&mut self, n: Value) -> usize {
        let i = self.push("nodes", n);
        self.roots.push(i);
        i
    }

    pub fn camera(&mut self, yfov: f32, aspect: f32, translation: [f32; 3]) -> usize {
        let cam = self.push(
            "cameras",
            json!({"type": "perspective", "perspective": {"yfov": yfov, "aspectRatio": aspect, "znear": 0.01}}),
        );
        self.node(json!({"camera": cam, "translation": translation}))
    }

    /// An orthographic camera of half extents `xmag` × `ymag`, looking down −z from `translation`.
    pub fn orthographic_camera(&mut self, xmag: f32, ymag: f32, translation: [f32; 3]) -> usize {
        let cam = self.push(
            "cameras",
            json!({"type": "orthographic", "orthographic": {"xmag": xmag, "ymag": ymag, "znear": 0.01, "zfar": 100}}),
        );
        self.node(json!({"camera": cam, "translation": translation}))
    }

    pub fn light(&mut self, light: Value, node: Value) -> usize {
        self.use_extension("KHR_lights_punctual");
        if self.doc.pointer("/extensions/KHR_lights_punctual").is_none() {
            self.doc["extensions"] = json!({"KHR_lights_punctual": {"lights": []}});
        }
        let lights = self.doc.pointer_mut("/extensions/KHR_lights_punctual/lights").unwrap().as_array_mut().unwrap();
        lights.push(light);
        let index = lights.len() - 1;
        let mut node = node;
        node["extensions"] = json!({"KHR_lights_punctual": {"light": index}});
        self.node(node)
    }

    pub fn write(mut self) -> PathBuf {
        let bin_name = format!("{}.bin", self.name);
        std::fs::write(self.dir.join(&bin_name), &self.bin).expect("write bin");
        self.doc["buffers"] = json!([{"uri": bin_name, "byteLength": self.bin.len()}]);
        self.doc["scenes"][0]["nodes"] = json!(self.roots);
        let obj = self.doc.as_object_mut().unwrap();
        obj.retain(|_, v| !v.as_array().is_some_and(|a| a.is_empty()));
        let path = self.dir.join(format!("{}.gltf", self.name));
        std::fs::write(&path, serde_json::to_vec_pretty(&self.doc).unwrap()).expect("write gltf");
        path
    }
}
