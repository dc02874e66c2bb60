//! `veach info SCENE`: what a glTF file holds and what veach loads of it.

use super::{Choice, glb::glb_chunks, load_with};
use crate::Error;
use std::path::Path;

/// What `veach info SCENE` says of a glTF file: what veach renders of it with a choice of
/// scene, variant and camera (triangles, meshes, instances, lights and bounds of the chosen
/// scene, as `veach render` with the same flags loads it), and what the file holds as a whole.
/// The command line prints it (`Display`); embedders (the Python package) read its fields.
#[derive(Clone, Debug, serde::Serialize)]
pub struct Description {
    pub path: String,
    /// The scene rendered: its index, its name, and how many the file has.
    pub scene: usize,
    pub scene_name: Option<String>,
    pub scenes: usize,
    pub variant: Option<String>,
    /// The camera used (None: a view framing the scene).
    pub camera: Option<String>,
    /// Triangles drawn (instances counted once per placement), stored, and emissive.
    pub triangles: usize,
    pub triangles_stored: usize,
    pub emissive_triangles: usize,
    /// Distinct meshes drawn by the chosen scene, and meshes in the file.
    pub meshes_drawn: usize,
    pub meshes_in_file: usize,
    /// Nodes with a mesh, and of those the placements of meshes stored once.
    pub instances: usize,
    pub instances_stored_once: usize,
    pub meshes_stored_once: usize,
    pub materials: usize,
    pub textures: usize,
    pub images: usize,
    pub punctual_lights: usize,
    pub cameras: Vec<String>,
    pub extensions_used: Vec<String>,
    pub extensions_required: Vec<String>,
    /// The scene's bounds (None: empty).
    pub bounds: Option<[[f32; 3]; 2]>,
}

/// `describe_scene` as `veach info` prints it.
pub fn describe_file(path: &Path, choice: &Choice, camera: Option<&str>) -> Result<String, Error> {
    describe_scene(path, choice, camera).map(|d| d.to_string())
}

pub fn describe_scene(path: &Path, choice: &Choice, camera: Option<&str>) -> Result<Description, Error> {
    let scene = load_with(path, choice)?;
    let fail = |m: String| Error::Input(format!("{}: {m}", path.display()));
    let bytes = std::fs::read(path).map_err(|e| fail(format!("cannot read: {e}")))?;
    let json = if bytes.starts_with(b"glTF") { glb_chunks(&bytes).map_err(fail)?.0 } else { &bytes[..] };
    let raw: serde_json::Value = serde_json::from_slice(json).map_err(|e| fail(format!("invalid glTF JSON: {e}")))?;
    let count = |key: &str| raw.get(key).and_then(|v| v.as_array()).map_or(0, |a| a.len());
    let (scene_index, drawing_nodes, drawn_meshes) = chosen_scene_meshes(&raw, choice.scene);
    let list = |key: &str| -> Vec<String> {
        raw.get(key)
            .and_then(|v| v.as_array())
            .map(|a| a.iter().filter_map(|x| x.as_str()).map(str::to_string).collect())
            .unwrap_or_default()
    };
    let b = scene.bounds();
    let cameras: Vec<String> = scene.cameras.iter().map(|c| c.name.clone()).collect();
    scene.camera(camera).map_err(fail)?;
    Ok(Description {
        path: path.display().to_string(),
        scene: scene_index,
        scene_name: raw.pointer(&format!("/scenes/{scene_index}/name")).and_then(|v| v.as_str()).map(str::to_string),
        scenes: count("scenes"),
        variant: choice.variant.clone(),
        camera: camera.map(str::to_string).or_else(|| cameras.first().cloned()),
        triangles: scene.drawn_triangle_count(),
        triangles_stored: scene.triangles.len() + scene.meshes.iter().map(|m| m.triangles.len()).sum::<usize>(),
        emissive_triangles: scene.emissive_triangle_count(),
        meshes_drawn: drawn_meshes,
        meshes_in_file: count("meshes"),
        instances: drawing_nodes,
        instances_stored_once: scene.instances.len(),
        meshes_stored_once: scene.meshes.len(),
        materials: count("materials"),
        textures: count("textures"),
        images: count("images"),
        punctual_lights: scene.punctual_lights.len(),
        cameras,
        extensions_used: list("extensionsUsed"),
        extensions_required: list("extensionsRequired"),
        bounds: (!b.is_empty()).then(|| [b.min.to_array(), b.max.to_array()]),
    })
}

impl std::fmt::Display for Description {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let list = |v: &[String]| if v.is_empty() { "none".to_string() } else { v.join(", ") };
        let bounds = match self.bounds {
            Some([lo, hi]) => format!("{} .. {}", glam::Vec3::from(lo), glam::Vec3::from(hi)),
            None => "empty".to_string(),
        };
        write!(
            f,
            "{}\n  scene {}{} of {}, variant {}, camera {}\n  \
             triangles {} ({} stored, {} emissive)\n  meshes {} drawn ({} in the file)\n  \
             instances (nodes with a mesh) {} ({} drawing {} meshes stored once)\n  materials {}\n  textures {} (images {})\n  \
             punctual lights {}\n  cameras {} ({})\n  extensions used: {}\n  extensions required: {}\n  bounds {}",
            self.path,
            self.scene,
            self.scene_name.as_ref().map_or(String::new(), |n| format!(" \"{n}\"")),
            self.scenes,
            self.variant.as_deref().unwrap_or("default"),
            self.camera.as_deref().unwrap_or("none: a view framing the scene"),
            self.triangles,
            self.triangles_stored,
            self.emissive_triangles,
            self.meshes_drawn,
            self.meshes_in_file,
            self.instances,
            self.instances_stored_once,
            self.meshes_stored_once,
            self.materials,
            self.textures,
            self.images,
            self.punctual_lights,
            self.cameras.len(),
            self.cameras.join(", "),
            list(&self.extensions_used),
            list(&self.extensions_required),
            bounds,
        )
    }
}

/// The scene `veach render` would draw (the chosen one, else the file's default, else 0) and,
/// over the nodes it reaches, how many carry a mesh and how many distinct meshes they draw.
/// Walks the raw JSON once per node (a node reached twice, or a cycle the loader would refuse,
/// is counted once).
fn chosen_scene_meshes(raw: &serde_json::Value, chosen: Option<usize>) -> (usize, usize, usize) {
    let index = chosen.or_else(|| raw.get("scene").and_then(|v| v.as_u64()).map(|i| i as usize)).unwrap_or(0);
    let nodes = raw.get("nodes").and_then(|v| v.as_array()).map_or(&[][..], |a| &a[..]);
    let as_indices = |v: Option<&serde_json::Value>| -> Vec<usize> {
        v.and_then(|v| v.as_array())
            .map(|a| a.iter().filter_map(|i| i.as_u64()).map(|i| i as usize).collect())
            .unwrap_or_default()
    };
    // Without scenes, glTF leaves what to draw to the application: veach draws every node.
    let mut stack = match raw.get("scenes").and_then(|v| v.as_array()) {
        Some(scenes) => as_indices(scenes.get(index).and_then(|s| s.get("nodes"))),
        None => (0..nodes.len()).collect(),
    };
    let mut seen = vec![false; nodes.len()];
    let mut meshes = std::collections::BTreeSet::new();
    let mut drawing = 0;
    while let Some(n) = stack.pop() {
        if n >= nodes.len() || std::mem::replace(&mut seen[n], true) {
            continue;
        }
        if let Some(m) = nodes[n].get("mesh").and_then(|v| v.as_u64()) {
            drawing += 1;
            meshes.insert(m);
        }
        stack.extend(as_indices(nodes[n].get("children")));
    }
    (index, drawing, meshes.len())
}
