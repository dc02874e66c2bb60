//! `veach info SCENE`: what a glTF file holds and what veach loads of it.

use super::{Choice, glb::glb_chunks, load_with};
use crate::Error;
use std::path::Path;

/// A summary of a glTF file for `veach info SCENE`: what veach renders of it with this choice
/// of scene, variant and camera (triangles, meshes, instances, lights and bounds of the chosen
/// scene, as `veach render` with the same flags loads it), and what the file holds as a whole.
pub fn describe_file(path: &Path, choice: &Choice, camera: Option<&str>) -> Result<String, Error> {
    let scene = load_with(path, choice)?;
    let fail = |m: String| Error::Input(format!("{}: {m}", path.display()));
    let bytes = std::fs::read(path).map_err(|e| fail(format!("cannot read: {e}")))?;
    let json = if bytes.starts_with(b"glTF") { glb_chunks(&bytes).map_err(fail)?.0 } else { &bytes[..] };
    let raw: serde_json::Value = serde_json::from_slice(json).map_err(|e| fail(format!("invalid glTF JSON: {e}")))?;
    let count = |key: &str| raw.get(key).and_then(|v| v.as_array()).map_or(0, |a| a.len());
    let (scene_index, drawing_nodes, drawn_meshes) = chosen_scene_meshes(&raw, choice.scene);
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
    scene.camera(camera).map_err(fail)?;
    let chosen_camera = match camera {
        Some(name) => name.to_string(),
        None => cameras.first().map_or("none: a view framing the scene".to_string(), |c| c.to_string()),
    };
    let scene_name = raw.pointer(&format!("/scenes/{scene_index}/name")).and_then(|v| v.as_str());
    let scenes = count("scenes");
    Ok(format!(
        "{}\n  scene {scene_index}{} of {scenes}, variant {}, camera {chosen_camera}\n  \
         triangles {} ({} stored, {} emissive)\n  meshes {} drawn ({} in the file)\n  \
         instances (nodes with a mesh) {} ({} drawing {} meshes stored once)\n  materials {}\n  textures {} (images {})\n  \
         punctual lights {}\n  cameras {} ({})\n  extensions used: {}\n  extensions required: {}\n  bounds {}",
        path.display(),
        scene_name.map_or(String::new(), |n| format!(" \"{n}\"")),
        choice.variant.as_deref().unwrap_or("default"),
        scene.drawn_triangle_count(),
        scene.triangles.len() + scene.meshes.iter().map(|m| m.triangles.len()).sum::<usize>(),
        scene.emissive_triangle_count(),
        drawn_meshes,
        count("meshes"),
        drawing_nodes,
        scene.instances.len(),
        scene.meshes.len(),
        count("materials"),
        count("textures"),
        count("images"),
        scene.punctual_lights.len(),
        cameras.len(),
        cameras.join(", "),
        list("extensionsUsed"),
        list("extensionsRequired"),
        bounds,
    ))
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
