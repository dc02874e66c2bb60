//! The records of the scene buffers as the kernel reads them. Each has a twin of the same
//! name in `shaders/common.wgsl` with the same field order (std430, 16-byte rows);
//! tests/layout.rs checks sizes and offsets with naga.

use bytemuck::{Pod, Zeroable};

/// A triangle as intersected: vertex 0 and two edges (Möller–Trumbore form).
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable, PartialEq)]
pub struct Triangle {
    pub p0: [f32; 3],
    pub material: u32,
    pub e1: [f32; 3],
    /// Probability of picking this triangle in light sampling divided by its area
    /// (the area-measure light pdf); 0 when it is not a light.
    pub light_pdf_area: f32,
    pub e2: [f32; 3],
    /// TRI_* bits.
    pub flags: u32,
}

/// Has vertex normals (else the shading normal is the geometric normal).
pub const TRI_HAS_NORMALS: u32 = 1;
/// Has a tangent frame (its material has a normal map).
pub const TRI_HAS_TANGENTS: u32 = 2;
/// Its material's alpha (MASK or BLEND) decides whether a ray hits it.
pub const TRI_ALPHA: u32 = 4;
/// Bits 3, 4, 5: vertex 0, 1, 2's tangent has handedness −1.
pub const TRI_TANGENT_SIGN_SHIFT: u32 = 3;
/// Set on a triangle moved to world space by a mirroring instance (winding reversed).
pub const TRI_MIRRORED: u32 = 64;
/// Bits 8–31: the triangle's emitter index + 1 in the light tree (0: not an emitter).
pub const TRI_EMITTER_SHIFT: u32 = 8;
/// Emitters the triangle flags can name.
pub const MAX_EMITTERS: usize = (1 << (32 - TRI_EMITTER_SHIFT)) - 1;

/// Rows (vec4<u32>) per light-tree node in the `lights` buffer.
pub const LIGHT_NODE_ROWS: u32 = 3;
/// Children of an interior light-tree node: a group of this many consecutive records (the
/// binary tree's grandchildren; unused slots have no power).
pub const LIGHT_TREE_WIDTH: u32 = 4;
/// A light-tree node's index word: set on leaves (the rest is the emitter, or an interior
/// node's first child).
pub const LIGHT_LEAF: u32 = 1 << 31;
/// A light-tree node's index word: some emitter below emits from both faces.
pub const LIGHT_TWO_SIDED: u32 = 1 << 30;
/// A leaf's index word: the leaf is a cluster of emitters (the rest is the first of its
/// entries, counted in pairs of words from the trails' first row), chosen inside by power.
pub const LIGHT_CLUSTER: u32 = 1 << 29;
/// A cluster's index word: its emitters are one-sided triangles in one plane (the first
/// entry's), so a point behind that plane gets none of them.
pub const LIGHT_PLANAR: u32 = 1 << 28;
/// A cluster entry's emitter word: the cluster's last entry.
pub const CLUSTER_LAST: u32 = 1 << 31;
/// Index bits of a light-tree node's index word.
pub const LIGHT_INDEX_MASK: u32 = LIGHT_PLANAR - 1;

/// Per-triangle vertex attributes: octahedron-encoded normals and tangents
/// (`pack2x16snorm`) and TEXCOORD_0, one of each per vertex.
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable, PartialEq)]
pub struct Attributes {
    pub n: [u32; 3],
    pub t0: u32,
    pub t12: [u32; 2],
    pub uv: [[f32; 2]; 3],
}

/// A material's texture: where the image sits in the texture atlas (page in bits 24–31, x in
/// 12–23, y in 0–11; NO_TEXTURE: none), UV transform rows, and mode bits (wrap s in bits 0–1,
/// wrap t in 2–3, sRGB-encoded in bit 4, TEXCOORD_1 in bit 5, width − 1 in 6–18, height − 1
/// in 19–31).
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable, PartialEq)]
pub struct TextureRef {
    pub row0: [f32; 3],
    pub atlas: u32,
    pub row1: [f32; 3],
    pub mode: u32,
}

pub const NO_TEXTURE: u32 = u32::MAX;
pub const TEX_SRGB: u32 = 16;
/// The texture reads TEXCOORD_1.
pub const TEX_UV1: u32 = 32;
/// The atlas word: page << TEX_PAGE_SHIFT | x << TEX_X_SHIFT | y, x and y within TEX_COORD_MASK.
pub const TEX_PAGE_SHIFT: u32 = 24;
pub const TEX_X_SHIFT: u32 = 12;
pub const TEX_COORD_MASK: u32 = 0xfff;
/// The image's size in the mode word: (width − 1) << TEX_WIDTH_SHIFT | (height − 1) <<
/// TEX_HEIGHT_SHIFT, each within TEX_SIZE_MASK.
pub const TEX_WIDTH_SHIFT: u32 = 6;
pub const TEX_HEIGHT_SHIFT: u32 = 19;
pub const TEX_SIZE_MASK: u32 = 0x1fff;

/// Material flags.
pub const MAT_ALPHA_MASK: u32 = 1;
pub const MAT_ALPHA_BLEND: u32 = 2;
pub const MAT_DOUBLE_SIDED: u32 = 4;
/// Thin-walled transmission: light passes through without bending (and no volume inside).
pub const MAT_THIN_WALLED: u32 = 8;

#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable, PartialEq)]
pub struct Material {
    pub base_color: [f32; 3],
    pub metallic: f32,
    pub emission: [f32; 3],
    pub roughness: f32,
    /// Fresnel reflectance at normal incidence of the dielectric (non-metal) part:
    /// ((ior − 1)/(ior + 1))² × specularColor, clamped to 1, × specularFactor.
    pub dielectric_f0: [f32; 3],
    pub ior: f32,
    /// Grazing reflectance of the dielectric part (= specularFactor).
    pub dielectric_f90: f32,
    /// Share of the non-metal part that refracts (KHR_materials_transmission).
    pub transmission: f32,
    /// baseColorFactor alpha, and the MASK cutoff.
    pub alpha: f32,
    pub alpha_cutoff: f32,
    /// Absorption coefficient inside (KHR_materials_volume): −ln(color) / distance.
    pub attenuation: [f32; 3],
    /// MAT_* bits.
    pub flags: u32,
    pub normal_scale: f32,
    /// KHR_materials_clearcoat: strength (0: no coat), roughness, normal-map scale.
    pub clearcoat: f32,
    pub clearcoat_roughness: f32,
    pub clearcoat_normal_scale: f32,
    /// KHR_materials_sheen (black: no sheen).
    pub sheen_color: [f32; 3],
    pub sheen_roughness: f32,
    /// The coat's normal in the local shading frame. Not scene data: (0, 0, 1) in the buffer,
    /// set per hit by the integrator when the coat's normal differs from the shading normal.
    pub coat_normal: [f32; 3],
    /// KHR_materials_anisotropy's strength (0: isotropic).
    pub anisotropy: f32,
    /// ((ior − 1)/(ior + 1))² × specularColor before clamping, for specular textures.
    pub specular_f0: [f32; 3],
    /// KHR_materials_diffuse_transmission's share of the diffuse lobe (0: none).
    pub diffuse_transmission: f32,
    /// (cos, sin) of the anisotropy's rotation from the tangent.
    pub anisotropy_rotation: [f32; 2],
    /// The anisotropy direction in the local shading frame's xy plane. Not scene data:
    /// (1, 0) in the buffer, set per hit by the integrator.
    pub anisotropy_tangent: [f32; 2],
    /// KHR_materials_iridescence: strength (0: none), film ior, thickness range (nm); the
    /// thickness at a point is `iridescence_thickness_max` after `material_at`.
    pub iridescence: f32,
    pub iridescence_ior: f32,
    pub iridescence_thickness_min: f32,
    pub iridescence_thickness_max: f32,
    /// The colour of the diffusely transmitted light.
    pub diffuse_transmission_color: [f32; 3],
    /// KHR_materials_dispersion: 20 / Abbe number (0: none).
    pub dispersion: f32,
    pub base_color_texture: TextureRef,
    pub metallic_roughness_texture: TextureRef,
    pub emissive_texture: TextureRef,
    pub normal_texture: TextureRef,
    pub transmission_texture: TextureRef,
    pub specular_texture: TextureRef,
    pub specular_color_texture: TextureRef,
    pub clearcoat_texture: TextureRef,
    pub clearcoat_roughness_texture: TextureRef,
    pub clearcoat_normal_texture: TextureRef,
    pub sheen_color_texture: TextureRef,
    pub sheen_roughness_texture: TextureRef,
    pub anisotropy_texture: TextureRef,
    pub iridescence_texture: TextureRef,
    pub iridescence_thickness_texture: TextureRef,
    pub diffuse_transmission_texture: TextureRef,
    pub diffuse_transmission_color_texture: TextureRef,
}

/// A KHR_lights_punctual light as four rows of the light-data buffer.
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable, PartialEq)]
pub struct Punctual {
    pub position: [f32; 3],
    /// PUNCTUAL_* kind.
    pub kind: f32,
    pub direction: [f32; 3],
    pub range: f32,
    pub intensity: [f32; 3],
    pub cos_inner: f32,
    pub cos_outer: f32,
    pub pad: [f32; 3],
}

pub const PUNCTUAL_POINT: f32 = 0.0;
pub const PUNCTUAL_SPOT: f32 = 1.0;
pub const PUNCTUAL_DIRECTIONAL: f32 = 2.0;

/// One entry of the light alias table (Vose): pick entry `i` uniformly, keep it with
/// probability `prob`, else take `alias`.
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable, PartialEq)]
pub struct LightEntry {
    pub triangle: u32,
    pub alias_slot: u32,
    pub prob: f32,
    /// Probability that this light is chosen (for reference and tests).
    pub pmf: f32,
}
