//! Loading a scene for rendering: glTF from a file or from bytes, and its camera.

use crate::Error;
use crate::scene::{Camera, Scene};
use std::path::Path;

/// A loaded scene, the camera chosen, and what the loader ignored (one line each).
pub struct Loaded {
    pub scene: Scene,
    pub camera: Camera,
    pub warnings: Vec<String>,
}

/// Loads a glTF file (.gltf or .glb) and the camera named `camera` (None: the first camera,
/// else a view framing the scene).
pub fn load(path: &Path, camera: Option<&str>) -> Result<Loaded, Error> {
    let scene = crate::scene::gltf::load(path)?;
    finish(scene, camera, &path.display().to_string())
}

/// Loads glTF from memory. External URIs resolve against `base`; without one, only
/// embedded data (GLB chunks, data: URIs) is read.
pub fn load_bytes(bytes: &[u8], base: Option<&Path>, camera: Option<&str>) -> Result<Loaded, Error> {
    let scene = crate::scene::gltf::load_bytes(bytes, base).map_err(|e| Error::Input(format!("glTF: {e}")))?;
    finish(scene, camera, "glTF")
}

fn finish(mut scene: Scene, camera: Option<&str>, what: &str) -> Result<Loaded, Error> {
    let camera = scene.camera(camera).map_err(|e| Error::Input(format!("{what}: {e}")))?;
    let warnings = std::mem::take(&mut scene.warnings);
    Ok(Loaded { scene, camera, warnings })
}
