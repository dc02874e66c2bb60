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

/// What to take from a file: a camera by name (None: the first camera, else a view framing
/// the scene), a scene by index (None: the file's default), a material variant by name
/// (KHR_materials_variants; None: the default materials).
#[derive(Clone, Copy, Debug, Default)]
pub struct LoadOptions<'a> {
    pub camera: Option<&'a str>,
    pub scene: Option<usize>,
    pub variant: Option<&'a str>,
}

impl crate::Settings {
    /// The load options these settings name.
    pub fn load_options(&self) -> LoadOptions<'_> {
        LoadOptions { camera: self.camera.as_deref(), scene: self.scene, variant: self.variant.as_deref() }
    }
}

fn choice(options: &LoadOptions) -> crate::scene::gltf::Choice {
    crate::scene::gltf::Choice { scene: options.scene, variant: options.variant.map(str::to_string) }
}

/// Loads a glTF file (.gltf or .glb) and the camera named `camera` (None: the first camera,
/// else a view framing the scene).
pub fn load(path: &Path, camera: Option<&str>) -> Result<Loaded, Error> {
    load_with(path, &LoadOptions { camera, ..Default::default() })
}

/// Loads a glTF file with the choices of `options`.
pub fn load_with(path: &Path, options: &LoadOptions) -> Result<Loaded, Error> {
    let scene = crate::scene::gltf::load_with(path, &choice(options))?;
    finish(scene, options.camera, &path.display().to_string())
}

/// Loads glTF from memory. External URIs resolve against `base`; without one, only
/// embedded data (GLB chunks, data: URIs) is read.
pub fn load_bytes(bytes: &[u8], base: Option<&Path>, camera: Option<&str>) -> Result<Loaded, Error> {
    load_bytes_with(bytes, base, &LoadOptions { camera, ..Default::default() })
}

pub fn load_bytes_with(bytes: &[u8], base: Option<&Path>, options: &LoadOptions) -> Result<Loaded, Error> {
    let scene = crate::scene::gltf::load_bytes_with(bytes, base, &choice(options))
        .map_err(|e| Error::Input(format!("glTF: {e}")))?;
    finish(scene, options.camera, "glTF")
}

fn finish(mut scene: Scene, camera: Option<&str>, what: &str) -> Result<Loaded, Error> {
    let camera = scene.camera(camera).map_err(|e| Error::Input(format!("{what}: {e}")))?;
    let warnings = std::mem::take(&mut scene.warnings);
    Ok(Loaded { scene, camera, warnings })
}
