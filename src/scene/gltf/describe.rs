//! `veach info SCENE`: what a glTF file holds and what veach loads of it.

use super::{glb::glb_chunks, load};
use crate::Error;
use std::path::Path;

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
