//! `Scene`: the plain Rust description every backend starts from.
//!
//! Geometry is flattened to world-space triangles; materials and cameras are
//! already converted to the renderer's conventions (linear RGB, radiance).

pub mod camera;
pub mod environment;
pub mod gltf;

pub use camera::Camera;
pub use environment::EnvironmentMap;
use glam::Vec3;

/// One world-space triangle. Counter-clockwise winding is the front face.
#[derive(Clone, Copy, Debug)]
pub struct Triangle {
    pub positions: [Vec3; 3],
    /// Per-vertex shading normals (equal to the geometric normal for flat meshes).
    pub normals: [Vec3; 3],
    pub material: u32,
}

impl Triangle {
    /// Unnormalised geometric normal, cross(v1 − v0, v2 − v0): length = 2 × area.
    pub fn cross(&self) -> Vec3 {
        (self.positions[1] - self.positions[0]).cross(self.positions[2] - self.positions[0])
    }

    pub fn area(&self) -> f32 {
        0.5 * self.cross().length()
    }
}

/// glTF metallic-roughness material, as path tracers read it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Material {
    pub base_color: Vec3,
    pub metallic: f32,
    pub roughness: f32,
    /// Emitted radiance (emissiveFactor × emissiveStrength), front face only.
    pub emission: Vec3,
    /// KHR_materials_specular.specularFactor (1 when the extension is absent).
    pub specular_factor: f32,
    pub specular_color: Vec3,
    pub ior: f32,
}

impl Default for Material {
    fn default() -> Self {
        // glTF's default material: white, fully metallic, fully rough.
        Material {
            base_color: Vec3::ONE,
            metallic: 1.0,
            roughness: 1.0,
            emission: Vec3::ZERO,
            specular_factor: 1.0,
            specular_color: Vec3::ONE,
            ior: 1.5,
        }
    }
}

impl Material {
    pub fn is_emissive(&self) -> bool {
        self.emission.max_element() > 0.0
    }
}

/// Axis-aligned bounds of a scene.
#[derive(Clone, Copy, Debug)]
pub struct Bounds {
    pub min: Vec3,
    pub max: Vec3,
}

impl Bounds {
    pub fn empty() -> Self {
        Bounds { min: Vec3::splat(f32::INFINITY), max: Vec3::splat(f32::NEG_INFINITY) }
    }
    pub fn grow(&mut self, p: Vec3) {
        self.min = self.min.min(p);
        self.max = self.max.max(p);
    }
    pub fn is_empty(&self) -> bool {
        self.min.x > self.max.x
    }
    pub fn center(&self) -> Vec3 {
        0.5 * (self.min + self.max)
    }
    pub fn diagonal(&self) -> Vec3 {
        self.max - self.min
    }
}

#[derive(Clone, Debug, Default)]
pub struct Scene {
    pub triangles: Vec<Triangle>,
    pub materials: Vec<Material>,
    pub cameras: Vec<Camera>,
    /// Environment radiance seen by rays that leave the scene: a constant color, or the
    /// scale of `environment_map` when there is one.
    pub environment: Vec3,
    pub environment_map: Option<EnvironmentMap>,
    /// Things the loader ignored, one line each (unknown optional extensions, ...).
    pub warnings: Vec<String>,
}

impl Scene {
    pub fn bounds(&self) -> Bounds {
        let mut b = Bounds::empty();
        for t in &self.triangles {
            for p in t.positions {
                b.grow(p);
            }
        }
        b
    }

    /// The named camera, the first one, or a default framing of the bounds.
    pub fn camera(&self, name: Option<&str>) -> Result<Camera, String> {
        match name {
            Some(n) => self.cameras.iter().find(|c| c.name == n).cloned().ok_or_else(|| {
                let names: Vec<&str> = self.cameras.iter().map(|c| c.name.as_str()).collect();
                format!("no camera named '{n}' (cameras in the scene: {})", names.join(", "))
            }),
            None => Ok(self.cameras.first().cloned().unwrap_or_else(|| Camera::framing(self.bounds()))),
        }
    }

    pub fn emissive_triangle_count(&self) -> usize {
        self.triangles.iter().filter(|t| self.materials[t.material as usize].is_emissive() && t.area() > 0.0).count()
    }
}
