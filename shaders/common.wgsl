// Shared constants and the packed-scene layouts (twins of src/packed/layout.rs, src/accel and
// src/params.rs; tests/layout.rs checks them).

const PI: f32 = 3.14159265358979;
const INV_PI: f32 = 0.31830988618379;
const INF: f32 = 3.4e38;

const STRATEGY_BSDF: u32 = 0u;
const STRATEGY_LIGHT: u32 = 1u;
const STRATEGY_MIS_BALANCE: u32 = 2u;
const STRATEGY_MIS_POWER: u32 = 3u;

// Features compiled in or out per scene (pipeline-overridable constants, set by the host from
// what the scene uses). lavapipe runs the kernel as SIMD code where unused branches still
// cost: an alpha test in the traversal loop alone made a scene without alpha 2.5× slower.
override ALPHA_TEST: bool = true;
override TEXTURES: bool = true;
override PUNCTUAL_LIGHTS: bool = true;
override TRANSMISSION: bool = true;
override INSTANCING: bool = true;
override CLEARCOAT: bool = true;
override SHEEN: bool = true;
override ANISOTROPY: bool = true;
override IRIDESCENCE: bool = true;
override DIFFUSE_TRANSMISSION: bool = true;
// A refracting material disperses: paths pick a colour channel there (integrator.wgsl).
override DISPERSION: bool = true;
// The render accumulates AOVs (aov.wgsl); not a scene feature but a setting.
override AOVS: bool = false;
// Triangles carry COLOR_0 or TEXCOORD_1 (material.wgsl, triangle_uv and vertex_color).
override VERTEX_EXTRAS: bool = true;

struct BvhNode {
    min: vec3<f32>,
    index: u32,
    max: vec3<f32>,
    count: u32,
}

// Compressed 8-wide BVH node (src/packed.rs CwNode): three BvhNode slots, the last 16 bytes
// padding, so loaders read five 16-byte words.
struct CwNode {
    // Grid origin p (f32 bits) and the cell exponents (bytes 0–2) | imask << 24.
    w0: vec4<u32>,
    // child_base, primitive_base, child_meta (eight bytes).
    w1: vec4<u32>,
    // Quantised child bounds: min (two words of four bytes), then max.
    qx: vec4<u32>,
    qy: vec4<u32>,
    qz: vec4<u32>,
}

struct Triangle {
    p0: vec3<f32>,
    material: u32,
    e1: vec3<f32>,
    light_pdf_area: f32,
    e2: vec3<f32>,
    flags: u32,
}

const TRI_HAS_NORMALS: u32 = 1u;
const TRI_HAS_TANGENTS: u32 = 2u;
const TRI_ALPHA: u32 = 4u;
const TRI_TANGENT_SIGN_SHIFT: u32 = 3u;
// Set on a triangle moved to world space by a mirroring instance: its winding is reversed.
const TRI_MIRRORED: u32 = 64u;
// Bits 8–31: the triangle's emitter index + 1 in the light tree (0: not an emitter).
const TRI_EMITTER_SHIFT: u32 = 8u;

const PROJECTION_PERSPECTIVE: u32 = 0u;
const PROJECTION_ORTHOGRAPHIC: u32 = 1u;
const LIGHT_SAMPLER_POWER: u32 = 0u;
const LIGHT_SAMPLER_TREE: u32 = 1u;
// Light-tree nodes: rows per node, the leaf bit of the index word, the two-sided flag.
// The largest f32 below 1: rescaled numbers stay in [0, 1).
const ONE_MINUS_EPSILON: f32 = 0.99999994;
const LIGHT_NODE_ROWS: u32 = 3u;
const LIGHT_TREE_WIDTH: u32 = 4u;
const LIGHT_LEAF: u32 = 0x80000000u;
const LIGHT_TWO_SIDED: u32 = 0x40000000u;
const LIGHT_CLUSTER: u32 = 0x20000000u;
const LIGHT_PLANAR: u32 = 0x10000000u;
const LIGHT_INDEX_MASK: u32 = 0x0fffffffu;
const CLUSTER_LAST: u32 = 0x80000000u;

// Per-triangle vertex attributes: octahedral normals and tangents, TEXCOORD_0.
struct Attributes {
    n: vec3<u32>,
    t0: u32,
    t12: vec2<u32>,
    uv0: vec2<f32>,
    uv1: vec2<f32>,
    uv2: vec2<f32>,
}

// A material's texture: its place in the atlas (page, x, y; NO_TEXTURE: none), UV transform
// rows, wrap/sRGB/UV-set bits and the image's size (layout in src/packed/layout.rs).
struct TextureRef {
    row0: vec3<f32>,
    atlas: u32,
    row1: vec3<f32>,
    mode: u32,
}

const MAT_ALPHA_MASK: u32 = 1u;
const MAT_ALPHA_BLEND: u32 = 2u;
const MAT_DOUBLE_SIDED: u32 = 4u;
const MAT_THIN_WALLED: u32 = 8u;

struct Material {
    base_color: vec3<f32>,
    metallic: f32,
    emission: vec3<f32>,
    roughness: f32,
    dielectric_f0: vec3<f32>,
    ior: f32,
    dielectric_f90: f32,
    transmission: f32,
    alpha: f32,
    alpha_cutoff: f32,
    // Absorption coefficient inside the volume (KHR_materials_volume).
    attenuation: vec3<f32>,
    flags: u32,
    normal_scale: f32,
    // KHR_materials_clearcoat (0: no coat) and KHR_materials_sheen (black: no sheen).
    clearcoat: f32,
    clearcoat_roughness: f32,
    clearcoat_normal_scale: f32,
    sheen_color: vec3<f32>,
    sheen_roughness: f32,
    // The coat's normal in the local shading frame: (0, 0, 1) in the buffer, set per hit.
    coat_normal: vec3<f32>,
    // KHR_materials_anisotropy's strength (0: isotropic).
    anisotropy: f32,
    // ((ior − 1)/(ior + 1))² × specularColor before clamping, for specular textures.
    specular_f0: vec3<f32>,
    // KHR_materials_diffuse_transmission's share of the diffuse lobe (0: none) and colour.
    diffuse_transmission: f32,
    // (cos, sin) of the anisotropy's rotation, and its direction in the local frame's xy
    // plane ((1, 0) in the buffer, set per hit).
    anisotropy_rotation: vec2<f32>,
    anisotropy_tangent: vec2<f32>,
    // KHR_materials_iridescence: strength (0: none), film ior, thickness range (nm; the
    // thickness at the point is iridescence_thickness_max after material_at).
    iridescence: f32,
    iridescence_ior: f32,
    iridescence_thickness_min: f32,
    iridescence_thickness_max: f32,
    diffuse_transmission_color: vec3<f32>,
    // KHR_materials_dispersion: 20 / Abbe number (0: none).
    dispersion: f32,
    base_color_texture: TextureRef,
    metallic_roughness_texture: TextureRef,
    emissive_texture: TextureRef,
    normal_texture: TextureRef,
    transmission_texture: TextureRef,
    specular_texture: TextureRef,
    specular_color_texture: TextureRef,
    clearcoat_texture: TextureRef,
    clearcoat_roughness_texture: TextureRef,
    clearcoat_normal_texture: TextureRef,
    sheen_color_texture: TextureRef,
    sheen_roughness_texture: TextureRef,
    anisotropy_texture: TextureRef,
    iridescence_texture: TextureRef,
    iridescence_thickness_texture: TextureRef,
    diffuse_transmission_texture: TextureRef,
    diffuse_transmission_color_texture: TextureRef,
}

// KHR_lights_punctual, four rows of the light-data buffer each.
struct Punctual {
    position: vec3<f32>,
    kind: f32,
    direction: vec3<f32>,
    range: f32,
    intensity: vec3<f32>,
    cos_inner: f32,
    cos_outer: f32,
    pad0: f32,
    pad1: f32,
    pad2: f32,
}

struct LightEntry {
    triangle: u32,
    alias_slot: u32,
    prob: f32,
    pmf: f32,
}

// Render parameters; only sample_index changes from dispatch to dispatch. `cam_right` and
// `cam_up` are pre-scaled by the image-plane half extents so a camera ray is
// forward + x·right + y·up.
struct Params {
    cam_position: vec3<f32>,
    film_width: u32,
    cam_right: vec3<f32>,
    film_height: u32,
    cam_up: vec3<f32>,
    sample_index: u32,
    cam_forward: vec3<f32>,
    seed: u32,
    environment: vec3<f32>,
    max_depth: u32,
    strategy: u32,
    light_count: u32,
    rr_depth: u32,
    image_width: u32,
    image_height: u32,
    tile_x: u32,
    tile_y: u32,
    // Probability that light sampling picks the environment (the rest goes to triangles).
    env_select: f32,
    // Environment map size (0 × 0: the environment is the constant `environment`).
    env_width: u32,
    env_height: u32,
    env_total: f32,
    // Thin-lens radius in scene units (0: a pinhole), and the distance in focus.
    aperture: f32,
    focus_distance: f32,
    // First film row of this dispatch (the viewer renders a sample in bands of rows).
    row_offset: u32,
    // Punctual lights: first row in the light-data buffer, and how many.
    punctual_base: u32,
    punctual_count: u32,
    // First instance record in the node array (two-level BVH).
    instance_base: u32,
    // SAMPLER_INDEPENDENT or SAMPLER_SOBOL (sampler.wgsl).
    sampler: u32,
    // LIGHT_SAMPLER_POWER or LIGHT_SAMPLER_TREE (power when the scene has no tree).
    light_sampler: u32,
    // Emitters in the light tree: emissive triangles (the first light_count, in alias table
    // order), then point and spot lights.
    tree_emitters: u32,
    // Rows of `lights` where the tree's nodes and its emitters' trails start.
    tree_base: u32,
    trail_base: u32,
    // The first punctual lights, sampled in an estimate of their own (all with the power
    // sampler; the directional ones, which come first, with the tree).
    separate_punctuals: u32,
    // Firefly control: the largest component sum a contribution of direct light (paths of
    // at most 2 segments) or indirect light adds to the pixel (f32 max: off).
    clamp_direct: f32,
    clamp_indirect: f32,
    // Adaptive sampling (adaptive.wgsl): a pixel stops once its error estimate is below the
    // threshold (0: off), tested after adaptive_min_samples samples, then every adaptive_step.
    noise_threshold: f32,
    adaptive_min_samples: u32,
    adaptive_step: u32,
    // First row of the sheen albedo table in light_data (sheen.wgsl).
    sheen_base: u32,
    // First film row of the AOV region (aov.wgsl); 0: no AOVs.
    aov_base: u32,
    // PROJECTION_PERSPECTIVE, or PROJECTION_ORTHOGRAPHIC (cam_right and cam_up then hold the
    // view's half extents in scene units).
    projection: u32,
    // First record of the triangles' COLOR_0 and TEXCOORD_1 in the attributes (0: none).
    extras_base: u32,
    // Light candidates resampled at a glossy vertex (light_candidates in integrator.wgsl);
    // 1: one light sample, no resampling.
    light_candidates: u32,
    pad0: u32,
    pad1: u32,
    pad2: u32,
}

struct Ray {
    origin: vec3<f32>,
    dir: vec3<f32>,
}

fn max_component(v: vec3<f32>) -> f32 {
    return max(v.x, max(v.y, v.z));
}

fn is_finite_f32(x: f32) -> bool {
    return (bitcast<u32>(x) & 0x7f800000u) != 0x7f800000u;
}

fn is_finite_vec3(v: vec3<f32>) -> bool {
    return is_finite_f32(v.x) && is_finite_f32(v.y) && is_finite_f32(v.z);
}

fn luminance(c: vec3<f32>) -> f32 {
    return dot(c, vec3<f32>(0.2126, 0.7152, 0.0722));
}
