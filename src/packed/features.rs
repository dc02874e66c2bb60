//! Which optional parts of the kernel a scene needs: the shaders' override constants, and
//! the run-time conditions of the CPU twin.

use super::PackedScene;
use super::layout::{Material, NO_TEXTURE, TRI_ALPHA};

/// Which optional parts of the kernel a scene needs (the shaders' override constants).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Features {
    pub alpha_test: bool,
    pub textures: bool,
    pub punctual_lights: bool,
    pub transmission: bool,
    pub instancing: bool,
    pub clearcoat: bool,
    pub sheen: bool,
    pub anisotropy: bool,
    pub iridescence: bool,
    /// KHR_materials_diffuse_transmission.
    pub diffuse_transmission: bool,
    /// KHR_materials_dispersion on a refracting material.
    pub dispersion: bool,
    /// The render accumulates AOVs (a setting, not a property of the scene: false here, set
    /// by the engine).
    pub aovs: bool,
    /// Triangles carry COLOR_0 or TEXCOORD_1.
    pub vertex_extras: bool,
}

impl Features {
    /// The pipeline constants of `shaders/common.wgsl`.
    pub fn constants(&self) -> [(&'static str, f64); 13] {
        let f = |b: bool| if b { 1.0 } else { 0.0 };
        [
            ("ALPHA_TEST", f(self.alpha_test)),
            ("TEXTURES", f(self.textures)),
            ("PUNCTUAL_LIGHTS", f(self.punctual_lights)),
            ("TRANSMISSION", f(self.transmission)),
            ("INSTANCING", f(self.instancing)),
            ("CLEARCOAT", f(self.clearcoat)),
            ("SHEEN", f(self.sheen)),
            ("ANISOTROPY", f(self.anisotropy)),
            ("IRIDESCENCE", f(self.iridescence)),
            ("DIFFUSE_TRANSMISSION", f(self.diffuse_transmission)),
            ("DISPERSION", f(self.dispersion)),
            ("AOVS", f(self.aovs)),
            ("VERTEX_EXTRAS", f(self.vertex_extras)),
        ]
    }
}

impl PackedScene {
    pub fn features(&self) -> Features {
        let textured = |m: &Material| {
            [
                m.base_color_texture,
                m.metallic_roughness_texture,
                m.emissive_texture,
                m.normal_texture,
                m.transmission_texture,
                m.specular_texture,
                m.specular_color_texture,
                m.clearcoat_texture,
                m.clearcoat_roughness_texture,
                m.clearcoat_normal_texture,
                m.sheen_color_texture,
                m.sheen_roughness_texture,
                m.anisotropy_texture,
                m.iridescence_texture,
                m.iridescence_thickness_texture,
                m.diffuse_transmission_texture,
                m.diffuse_transmission_color_texture,
            ]
            .iter()
            .any(|t| t.atlas != NO_TEXTURE)
        };
        Features {
            alpha_test: self.triangles.iter().any(|t| t.flags & TRI_ALPHA != 0),
            textures: self.materials.iter().any(textured),
            punctual_lights: self.punctual_count > 0,
            transmission: self.materials.iter().any(|m| m.transmission > 0.0 || m.attenuation != [0.0; 3]),
            instancing: self.instance_count > 0,
            clearcoat: self.materials.iter().any(|m| m.clearcoat > 0.0),
            sheen: self.materials.iter().any(|m| m.sheen_color.iter().any(|&c| c > 0.0)),
            anisotropy: self.materials.iter().any(|m| m.anisotropy > 0.0),
            iridescence: self.materials.iter().any(|m| m.iridescence > 0.0),
            diffuse_transmission: self.materials.iter().any(|m| m.diffuse_transmission > 0.0),
            dispersion: self.materials.iter().any(|m| m.dispersion > 0.0 && m.transmission > 0.0),
            aovs: false,
            vertex_extras: self.extras_base > 0,
        }
    }
}
