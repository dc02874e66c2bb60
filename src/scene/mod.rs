//! `Scene`: the plain Rust description every backend starts from.
//!
//! Geometry is flattened to world-space triangles; materials and cameras are
//! already converted to the renderer's conventions (linear RGB, radiance).

pub mod camera;
pub mod environment;
#[doc(hidden)]
pub mod gltf;
#[doc(hidden)]
pub mod studio;
#[doc(hidden)]
pub mod tangents;

pub use camera::Camera;
pub use environment::{Environment, EnvironmentMap};
use glam::{Mat4, Vec2, Vec3, Vec4};

/// One world-space triangle. Counter-clockwise winding is the front face.
#[derive(Clone, Copy, Debug, Default)]
pub struct Triangle {
    pub positions: [Vec3; 3],
    /// Per-vertex shading normals (equal to the geometric normal for flat meshes).
    pub normals: [Vec3; 3],
    /// TEXCOORD_0 per vertex (zero when the mesh has none).
    pub uvs: [Vec2; 3],
    /// World-space tangent per vertex, w = handedness (±1) of the bitangent cross(n, t)·w;
    /// all zero when the triangle has no tangent frame (no UVs or no normal map).
    pub tangents: [Vec4; 3],
    pub material: u32,
    /// COLOR_0 per vertex (linear RGBA, multiplying the base color); None: white.
    pub colors: Option<[Vec4; 3]>,
    /// TEXCOORD_1 per vertex, read by textures that name it; None: the mesh has none.
    pub uvs1: Option<[Vec2; 3]>,
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

/// A sampler's wrap mode along one texture axis.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum Wrap {
    #[default]
    Repeat = 0,
    MirroredRepeat = 1,
    ClampToEdge = 2,
}

/// A material's use of a texture: which image, how UVs map onto it, how it wraps.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TextureRef {
    /// Index into `Scene::textures`.
    pub texture: u32,
    /// The texture coordinate set it reads: 0 (TEXCOORD_0) or 1 (TEXCOORD_1).
    pub uv_set: u32,
    /// Affine UV transform (KHR_texture_transform): uv' = (row0 · (u, v, 1), row1 · (u, v, 1)).
    pub transform: [[f32; 3]; 2],
    pub wrap: [Wrap; 2],
}

impl TextureRef {
    pub const IDENTITY: [[f32; 3]; 2] = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0]];
}

/// An image as decoded: 8-bit RGBA, rows top to bottom (glTF's v = 0 is the top row).
#[derive(Clone, Debug, Default)]
pub struct Texture {
    pub name: String,
    pub width: u32,
    pub height: u32,
    pub rgba: Vec<u8>,
}

#[derive(Clone, Copy, Debug, PartialEq, Default)]
pub enum AlphaMode {
    #[default]
    Opaque,
    /// Surfaces with alpha below the cutoff are not there.
    Mask(f32),
    /// Surfaces are there with probability alpha (stochastic transparency).
    Blend,
}

/// KHR_lights_punctual: a light with no area, reached by next-event estimation only.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum PunctualKind {
    /// Intensity in candela (W/sr in veach's radiometric units).
    Point,
    /// Point light within a cone (cosines of the inner and outer half-angles).
    Spot { cos_inner: f32, cos_outer: f32 },
    /// Illuminance in lux (W/m²) on a surface facing the light.
    Directional,
}

#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PunctualLight {
    pub kind: PunctualKind,
    pub position: Vec3,
    /// Unit direction the light travels (the node's −Z).
    pub direction: Vec3,
    /// color × intensity.
    pub intensity: Vec3,
    /// Distance where the light fades to zero (glTF's recommended window); infinite when absent.
    pub range: f32,
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
    /// baseColorFactor's alpha.
    pub alpha: f32,
    pub alpha_mode: AlphaMode,
    pub double_sided: bool,
    /// KHR_materials_transmission.transmissionFactor: the share of the non-metal part that
    /// refracts instead of scattering diffusely.
    pub transmission: f32,
    /// Thin-walled transmission (KHR_materials_transmission without KHR_materials_volume, or
    /// with thicknessFactor 0): transmitted light passes through without bending, as through
    /// a sheet with no inside.
    pub thin_walled: bool,
    /// KHR_materials_volume: the color white light reaches after `attenuation_distance` inside.
    pub attenuation_color: Vec3,
    pub attenuation_distance: f32,
    pub base_color_texture: Option<TextureRef>,
    /// Green = roughness, blue = metallic.
    pub metallic_roughness_texture: Option<TextureRef>,
    pub emissive_texture: Option<TextureRef>,
    pub normal_texture: Option<TextureRef>,
    pub normal_scale: f32,
    /// KHR_materials_transmission.transmissionTexture (red multiplies `transmission`).
    pub transmission_texture: Option<TextureRef>,
    /// KHR_materials_specular's textures: alpha multiplies `specular_factor`, RGB (sRGB)
    /// multiplies `specular_color`.
    pub specular_texture: Option<TextureRef>,
    pub specular_color_texture: Option<TextureRef>,
    /// KHR_materials_clearcoat: a GGX dielectric coat (ior 1.5) of this strength and roughness
    /// over the rest (0: no coat). Red of `clearcoat_texture` multiplies the strength, green of
    /// `clearcoat_roughness_texture` the roughness; the coat has its own normal map (without
    /// one it follows the interpolated normal, not the base's normal map).
    pub clearcoat: f32,
    pub clearcoat_roughness: f32,
    pub clearcoat_texture: Option<TextureRef>,
    pub clearcoat_roughness_texture: Option<TextureRef>,
    pub clearcoat_normal_texture: Option<TextureRef>,
    pub clearcoat_normal_scale: f32,
    /// KHR_materials_sheen: the Charlie sheen of this color and roughness over the base (black:
    /// no sheen). RGB (sRGB) of `sheen_color_texture` multiplies the color, alpha of
    /// `sheen_roughness_texture` the roughness.
    pub sheen_color: Vec3,
    pub sheen_roughness: f32,
    pub sheen_color_texture: Option<TextureRef>,
    pub sheen_roughness_texture: Option<TextureRef>,
    /// KHR_materials_anisotropy: the specular lobe's roughness stretched along a direction
    /// of the tangent frame, `rotation` radians counter-clockwise from the tangent (0: none).
    /// The texture's RG is a direction in the tangent frame, its B multiplies the strength.
    pub anisotropy: f32,
    pub anisotropy_rotation: f32,
    pub anisotropy_texture: Option<TextureRef>,
    /// KHR_materials_iridescence: a thin dielectric film of this strength (0: none), ior and
    /// thickness (nm, from `thickness_min` to `thickness_max` by the thickness texture's
    /// green; `thickness_max` without it) over the specular lobe. Red of
    /// `iridescence_texture` multiplies the strength.
    pub iridescence: f32,
    pub iridescence_ior: f32,
    pub iridescence_thickness_min: f32,
    pub iridescence_thickness_max: f32,
    pub iridescence_texture: Option<TextureRef>,
    pub iridescence_thickness_texture: Option<TextureRef>,
    /// KHR_materials_diffuse_transmission: the share (0: none) of the non-specular,
    /// non-refracted light that passes to the other side as a Lambertian lobe of this colour
    /// (not the base colour). Alpha of `diffuse_transmission_texture` multiplies the share,
    /// RGB of the (sRGB) colour texture the colour.
    pub diffuse_transmission: f32,
    pub diffuse_transmission_color: Vec3,
    pub diffuse_transmission_texture: Option<TextureRef>,
    pub diffuse_transmission_color_texture: Option<TextureRef>,
    /// KHR_materials_dispersion: 20 / Abbe number (0: none); the ior is then Cauchy's fit
    /// through `ior` at 587.6 nm, per colour channel (refracting solids only).
    pub dispersion: f32,
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
            alpha: 1.0,
            alpha_mode: AlphaMode::Opaque,
            double_sided: false,
            transmission: 0.0,
            thin_walled: false,
            attenuation_color: Vec3::ONE,
            attenuation_distance: f32::INFINITY,
            base_color_texture: None,
            metallic_roughness_texture: None,
            emissive_texture: None,
            normal_texture: None,
            normal_scale: 1.0,
            transmission_texture: None,
            specular_texture: None,
            specular_color_texture: None,
            clearcoat: 0.0,
            clearcoat_roughness: 0.0,
            clearcoat_texture: None,
            clearcoat_roughness_texture: None,
            clearcoat_normal_texture: None,
            clearcoat_normal_scale: 1.0,
            sheen_color: Vec3::ZERO,
            sheen_roughness: 0.0,
            sheen_color_texture: None,
            sheen_roughness_texture: None,
            anisotropy: 0.0,
            anisotropy_rotation: 0.0,
            anisotropy_texture: None,
            iridescence: 0.0,
            iridescence_ior: 1.3,
            iridescence_thickness_min: 100.0,
            iridescence_thickness_max: 400.0,
            iridescence_texture: None,
            iridescence_thickness_texture: None,
            diffuse_transmission: 0.0,
            diffuse_transmission_color: Vec3::ONE,
            diffuse_transmission_texture: None,
            diffuse_transmission_color_texture: None,
            dispersion: 0.0,
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

/// A mesh stored once in object space and drawn by several nodes (instancing).
#[derive(Clone, Debug, Default)]
pub struct Mesh {
    pub name: String,
    pub triangles: Vec<Triangle>,
}

/// One placement of a `Mesh`: object-to-world transform (invertible).
#[derive(Clone, Copy, Debug)]
pub struct Instance {
    pub mesh: u32,
    pub transform: Mat4,
}

#[derive(Clone, Debug, Default)]
pub struct Scene {
    /// World-space triangles: every mesh drawn once, and every emitter.
    pub triangles: Vec<Triangle>,
    /// Meshes drawn by several nodes, stored once (object space), and their placements.
    pub meshes: Vec<Mesh>,
    pub instances: Vec<Instance>,
    pub materials: Vec<Material>,
    pub cameras: Vec<Camera>,
    /// What rays that leave the scene see.
    pub environment: Environment,
    pub textures: Vec<Texture>,
    pub punctual_lights: Vec<PunctualLight>,
    /// Things the loader ignored, one line each (unknown optional extensions, ...).
    pub warnings: Vec<String>,
}

impl Scene {
    /// Checks what the loader guarantees and an embedder building a `Scene` by hand might not:
    /// every material, mesh and texture index in range, every texture's pixels its size.
    pub fn validate(&self) -> Result<(), crate::Error> {
        let fail = |m: String| Err(crate::Error::Input(format!("invalid scene: {m}")));
        let materials = self.materials.len();
        let triangles = self.triangles.iter().chain(self.meshes.iter().flat_map(|m| &m.triangles));
        if let Some(t) = triangles.clone().find(|t| t.material as usize >= materials) {
            return fail(format!("a triangle uses material {} of {materials}", t.material));
        }
        if let Some(t) = triangles.clone().find(|t| !t.positions.iter().all(|p| p.is_finite())) {
            return fail(format!("a triangle has non-finite positions {:?}", t.positions));
        }
        if let Some(i) = self.instances.iter().find(|i| i.mesh as usize >= self.meshes.len()) {
            return fail(format!("an instance draws mesh {} of {}", i.mesh, self.meshes.len()));
        }
        if let Some(i) = self.instances.iter().find(|i| !i.transform.is_finite() || i.transform.determinant() == 0.0) {
            return fail(format!("an instance's transform {:?} cannot be inverted", i.transform));
        }
        for (k, t) in self.textures.iter().enumerate() {
            if t.rgba.len() as u64 != t.width as u64 * t.height as u64 * 4 || t.width == 0 || t.height == 0 {
                return fail(format!("texture {k} is {}x{} but holds {} bytes", t.width, t.height, t.rgba.len()));
            }
        }
        for (k, m) in self.materials.iter().enumerate() {
            let refs = [m.base_color_texture, m.metallic_roughness_texture, m.emissive_texture, m.normal_texture];
            if let Some(r) = refs.iter().flatten().find(|r| r.texture as usize >= self.textures.len()) {
                return fail(format!("material {k} uses texture {} of {}", r.texture, self.textures.len()));
            }
        }
        Ok(())
    }

    pub fn bounds(&self) -> Bounds {
        let mut b = Bounds::empty();
        for t in &self.triangles {
            for p in t.positions {
                b.grow(p);
            }
        }
        for inst in &self.instances {
            let ib = self.instance_bounds(inst);
            if !ib.is_empty() {
                b.grow(ib.min);
                b.grow(ib.max);
            }
        }
        b
    }

    /// World-space bounds of an instance (its mesh's box, transformed).
    pub fn instance_bounds(&self, inst: &Instance) -> Bounds {
        let mut local = Bounds::empty();
        for t in &self.meshes[inst.mesh as usize].triangles {
            for p in t.positions {
                local.grow(p);
            }
        }
        let mut b = Bounds::empty();
        if local.is_empty() {
            return b;
        }
        for k in 0..8 {
            let c = Vec3::new(
                if k & 1 == 0 { local.min.x } else { local.max.x },
                if k & 2 == 0 { local.min.y } else { local.max.y },
                if k & 4 == 0 { local.min.z } else { local.max.z },
            );
            b.grow(inst.transform.transform_point3(c));
        }
        b
    }

    /// Triangles drawn, instanced ones counted once per instance.
    pub fn drawn_triangle_count(&self) -> usize {
        self.triangles.len()
            + self.instances.iter().map(|i| self.meshes[i.mesh as usize].triangles.len()).sum::<usize>()
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

    /// Whether the scene has an emitter of its own: an emissive triangle or a punctual light.
    pub fn has_lights(&self) -> bool {
        self.emissive_triangle_count() > 0 || !self.punctual_lights.is_empty()
    }

    pub fn emissive_triangle_count(&self) -> usize {
        self.triangles.iter().filter(|t| self.materials[t.material as usize].is_emissive() && t.area() > 0.0).count()
    }
}
