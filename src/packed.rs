//! The packed scene: the exact buffers the GPU reads, and the CPU reference reads too.
//!
//! Every struct here has a twin in `shaders/common.wgsl` with the same field order
//! (std430 layout, 16-byte aligned rows).

use crate::accel;
use crate::scene::{AlphaMode, Material, PunctualKind, Scene, Texture, TextureRef};
use bytemuck::{Pod, Zeroable};
use glam::{Vec2, Vec3};

/// BVH2 node of the top level over instances: an inner node's children are `index` and
/// `index + 1`; a leaf (`count > 0`) holds instances `index .. index + count`. Also the slot
/// size of the node buffer: mesh BVH nodes take three slots, instance records four.
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable, PartialEq)]
pub struct BvhNode {
    pub min: [f32; 3],
    pub index: u32,
    pub max: [f32; 3],
    pub count: u32,
}

/// Compressed 8-wide BVH node (Ylitie, Karras & Laine 2017, built by obvhs) over a mesh's
/// triangles, in three BvhNode slots (80 bytes and 16 of padding): node `i` of the buffer
/// starts at slot `3 i`. Child boxes are quantised to 8 bits on a grid with origin `p` and
/// power-of-two cell sizes, rounded outwards.
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable, PartialEq)]
pub struct CwNode {
    pub p: [f32; 3],
    /// Exponents of the cell sizes (bytes 0–2) and the inner-child mask `imask` (byte 3).
    pub e_imask: u32,
    /// First inner child; the others follow in slot order.
    pub child_base: u32,
    /// First triangle of the leaves; each leaf child's offset is in its `child_meta`.
    pub primitive_base: u32,
    /// One byte a child: 0 empty; inner: 0b001_11sss (slot s); leaf: triangle count in
    /// unary (bits 5–7) and offset from `primitive_base` (bits 0–4).
    pub child_meta: [u32; 2],
    /// Quantised child bounds, one byte a child: x min (8 bytes), x max (8), then y, then z.
    pub qx: [u32; 4],
    pub qy: [u32; 4],
    pub qz: [u32; 4],
    pub pad: [u32; 4],
}

/// A triangle as intersected: vertex 0 and two edges (Möller–Trumbore form).
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable, PartialEq)]
pub struct PackedTriangle {
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

/// Per-triangle vertex attributes: octahedron-encoded normals and tangents
/// (`pack2x16snorm`) and TEXCOORD_0, one of each per vertex.
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable, PartialEq)]
pub struct PackedAttributes {
    pub n: [u32; 3],
    pub t0: u32,
    pub t12: [u32; 2],
    pub uv: [[f32; 2]; 3],
}

/// A material's texture: layer of the texture array (NO_TEXTURE: none), UV transform rows,
/// and mode bits (wrap s in bits 0–1, wrap t in 2–3, sRGB-encoded in bit 4).
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable, PartialEq)]
pub struct PackedTextureRef {
    pub row0: [f32; 3],
    pub layer: u32,
    pub row1: [f32; 3],
    pub mode: u32,
}

pub const NO_TEXTURE: u32 = u32::MAX;
pub const TEX_SRGB: u32 = 16;

/// Material flags.
pub const MAT_ALPHA_MASK: u32 = 1;
pub const MAT_ALPHA_BLEND: u32 = 2;
pub const MAT_DOUBLE_SIDED: u32 = 4;

#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable, PartialEq)]
pub struct PackedMaterial {
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
    pub pad: [f32; 3],
    pub base_color_texture: PackedTextureRef,
    pub metallic_roughness_texture: PackedTextureRef,
    pub emissive_texture: PackedTextureRef,
    pub normal_texture: PackedTextureRef,
}

/// A KHR_lights_punctual light as four rows of the light-data buffer.
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable, PartialEq)]
pub struct PackedPunctual {
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

/// Largest side of a texture-array layer, and the budget of the whole array.
pub const MAX_TEXTURE_LAYER_SIDE: u32 = 2048;
pub const TEXTURE_BUDGET_BYTES: u64 = 256 << 20;

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

#[derive(Clone)]
pub struct PackedScene {
    /// BVH nodes in BvhNode-sized slots. Without instances: the mesh's CWBVH (CwNode, three
    /// slots each) from slot 0. With instances: the top-level BVH2 over instances from slot 0,
    /// then the world mesh's and each stored mesh's CWBVH (starting at a multiple of three
    /// slots), then the instance records (four slots each, from `instance_base`).
    pub nodes: Vec<BvhNode>,
    pub instance_base: u32,
    /// Instance records, the world mesh's (identity) included; 0 without instancing.
    pub instance_count: u32,
    pub triangles: Vec<PackedTriangle>,
    pub attributes: Vec<PackedAttributes>,
    pub materials: Vec<PackedMaterial>,
    pub lights: Vec<LightEntry>,
    /// Original scene index of each packed triangle.
    pub order: Vec<u32>,
    pub bvh_build_seconds: f64,
    /// BVH nodes: the meshes' CWBVH nodes and the top level's BVH2 nodes.
    pub bvh_nodes: usize,
    /// Levels of the deepest mesh BVH (see accel::MAX_DEPTH).
    pub bvh_depth: u32,
    pub environment: Vec3,
    /// Environment map texels (rgb, conditional CDF of the row up to this texel), then one
    /// row per map row (marginal CDF up to this row, 0, 0, 0). One zeroed element when there
    /// is no map. Punctual lights follow, four rows each, from `punctual_base`.
    pub env: Vec<[f32; 4]>,
    pub punctual_base: u32,
    pub punctual_count: u32,
    /// Texture array: `texture_layers` square layers of `texture_size`² RGBA8 texels (one
    /// u32 each, R in the low byte), row-major, layer after layer. At least one layer.
    pub texels: Vec<u32>,
    pub texture_size: u32,
    pub texture_layers: u32,
    pub env_width: u32,
    pub env_height: u32,
    /// Σ luminance × sin θ over all texels: the normaliser of the sampling pmf.
    pub env_total: f32,
    /// Scene bounds' diagonal length (scale for ray epsilons where needed).
    pub extent: f32,
}

impl PackedScene {
    pub fn new(scene: &Scene) -> PackedScene {
        let verts: Vec<[Vec3; 3]> = scene.triangles.iter().map(|t| t.positions).collect();
        let bvh = accel::build(&verts);
        let ordered: Vec<&crate::scene::Triangle> = bvh.order.iter().map(|&i| &scene.triangles[i as usize]).collect();

        let materials: Vec<PackedMaterial> = scene.materials.iter().map(pack_material).collect();

        // Lights: emissive triangles with positive area, chosen proportional to power.
        let mut light_tris = Vec::new();
        let mut weights = Vec::new();
        for (i, t) in ordered.iter().enumerate() {
            let m = &scene.materials[t.material as usize];
            let area = t.area();
            let power = area * luminance(m.emission);
            if m.is_emissive() && area > 0.0 && power.is_finite() && power > 0.0 {
                light_tris.push(i as u32);
                weights.push(power as f64);
            }
        }
        let lights = build_alias_table(&light_tris, &weights);
        let mut light_pdf = vec![0.0f32; ordered.len()];
        for l in &lights {
            let area = ordered[l.triangle as usize].area();
            light_pdf[l.triangle as usize] = l.pmf / area;
        }

        let mut triangles: Vec<PackedTriangle> =
            ordered.iter().zip(&light_pdf).map(|(t, &pdf)| pack_triangle(scene, t, pdf)).collect();
        if triangles.is_empty() {
            // No triangle is referenced (the empty BVH's root has no children), but a storage
            // binding needs at least one element.
            triangles.push(PackedTriangle::zeroed());
        }
        let mut attributes: Vec<PackedAttributes> = ordered.iter().map(|t| pack_attributes(t)).collect();
        attributes.resize(triangles.len(), PackedAttributes::zeroed());
        let (nodes, instance_base, build_seconds, bvh_nodes, bvh_depth) = if scene.instances.is_empty() {
            (cw_slots(&bvh.nodes), 0, bvh.build_seconds, bvh.nodes.len(), bvh.depth)
        } else {
            build_instances(scene, bvh.nodes, bvh.depth, &mut triangles, &mut attributes, bvh.build_seconds)
        };
        let nodes_len = nodes.len();
        let (mut env, env_width, env_height, env_total) = match &scene.environment_map {
            Some(map) => pack_environment(map),
            None => (vec![[0.0; 4]], 0, 0, 0.0),
        };
        let punctual_base = env.len() as u32;
        for l in &scene.punctual_lights {
            let (kind, cos_inner, cos_outer) = match l.kind {
                PunctualKind::Point => (PUNCTUAL_POINT, -1.0, -1.0),
                PunctualKind::Spot { cos_inner, cos_outer } => (PUNCTUAL_SPOT, cos_inner, cos_outer),
                PunctualKind::Directional => (PUNCTUAL_DIRECTIONAL, -1.0, -1.0),
            };
            let p = PackedPunctual {
                position: l.position.into(),
                kind,
                direction: l.direction.into(),
                range: if l.range.is_finite() { l.range } else { 0.0 },
                intensity: l.intensity.into(),
                cos_inner,
                cos_outer,
                pad: [0.0; 3],
            };
            env.extend_from_slice(bytemuck::cast_slice::<PackedPunctual, [f32; 4]>(&[p]));
        }
        let (texels, texture_size, texture_layers) = pack_textures(&scene.textures);
        let bounds = scene.bounds();
        let extent = if bounds.is_empty() { 1.0 } else { bounds.diagonal().length() };
        PackedScene {
            nodes,
            instance_base,
            instance_count: if scene.instances.is_empty() {
                0
            } else {
                (nodes_len - instance_base as usize) as u32 / 4
            },
            triangles,
            attributes,
            materials,
            lights,
            order: bvh.order,
            bvh_build_seconds: build_seconds,
            bvh_nodes,
            bvh_depth,
            environment: scene.environment,
            env,
            punctual_base,
            punctual_count: scene.punctual_lights.len() as u32,
            texels,
            texture_size,
            texture_layers,
            env_width,
            env_height,
            env_total,
            extent,
        }
    }
}

/// Which optional parts of the kernel a scene needs (the shaders' override constants).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Features {
    pub alpha_test: bool,
    pub textures: bool,
    pub punctual_lights: bool,
    pub transmission: bool,
    pub instancing: bool,
}

impl Features {
    /// The pipeline constants of `shaders/common.wgsl`.
    pub fn constants(&self) -> [(&'static str, f64); 5] {
        let f = |b: bool| if b { 1.0 } else { 0.0 };
        [
            ("ALPHA_TEST", f(self.alpha_test)),
            ("TEXTURES", f(self.textures)),
            ("PUNCTUAL_LIGHTS", f(self.punctual_lights)),
            ("TRANSMISSION", f(self.transmission)),
            ("INSTANCING", f(self.instancing)),
        ]
    }
}

impl PackedScene {
    pub fn features(&self) -> Features {
        let textured = |m: &PackedMaterial| {
            [m.base_color_texture, m.metallic_roughness_texture, m.emissive_texture, m.normal_texture]
                .iter()
                .any(|t| t.layer != NO_TEXTURE)
        };
        Features {
            alpha_test: self.triangles.iter().any(|t| t.flags & TRI_ALPHA != 0),
            textures: self.materials.iter().any(textured),
            punctual_lights: self.punctual_count > 0,
            transmission: self.materials.iter().any(|m| m.transmission > 0.0 || m.attenuation != [0.0; 3]),
            instancing: self.instance_count > 0,
        }
    }
}

fn pack_triangle(scene: &Scene, t: &crate::scene::Triangle, light_pdf_area: f32) -> PackedTriangle {
    let [p0, p1, p2] = t.positions;
    let ng = t.cross().normalize_or_zero();
    let m = &scene.materials[t.material as usize];
    let mut flags = 0;
    if !t.normals.iter().all(|n| n.dot(ng) > 0.99999) {
        flags |= TRI_HAS_NORMALS;
    }
    if t.tangents.iter().all(|v| v.truncate() != Vec3::ZERO) {
        flags |= TRI_HAS_TANGENTS;
        for (k, v) in t.tangents.iter().enumerate() {
            if v.w < 0.0 {
                flags |= 1 << (TRI_TANGENT_SIGN_SHIFT + k as u32);
            }
        }
    }
    let cutout = match m.alpha_mode {
        AlphaMode::Opaque => false,
        AlphaMode::Mask(_) => true,
        AlphaMode::Blend => m.alpha < 1.0 || m.base_color_texture.is_some(),
    };
    if cutout {
        flags |= TRI_ALPHA;
    }
    PackedTriangle {
        p0: p0.into(),
        material: t.material,
        e1: (p1 - p0).into(),
        light_pdf_area,
        e2: (p2 - p0).into(),
        flags,
    }
}

fn pack_attributes(t: &crate::scene::Triangle) -> PackedAttributes {
    let tan = t.tangents.map(|v| oct_encode(v.truncate()));
    PackedAttributes { n: t.normals.map(oct_encode), t0: tan[0], t12: [tan[1], tan[2]], uv: t.uvs.map(|v| v.into()) }
}

/// An instance as the kernel reads it: object→world and world→object as 3×4 rows, the root
/// of its mesh's BVH and whether it mirrors; four BvhNode-sized slots.
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable, PartialEq)]
pub struct PackedInstance {
    pub object_to_world: [[f32; 4]; 3],
    pub world_to_object: [[f32; 4]; 3],
    pub blas_root: u32,
    /// INSTANCE_MIRRORED when the transform flips handedness.
    pub flags: u32,
    pub pad: [u32; 6],
}

pub const INSTANCE_MIRRORED: u32 = 1;

fn rows(m: glam::Mat4) -> [[f32; 4]; 3] {
    let r = m.transpose().to_cols_array_2d();
    [r[0], r[1], r[2]]
}

/// Two-level BVH: each stored mesh's BVH (object space) after the world mesh's, the instance
/// records after them, and a top-level BVH over instance bounds at node 0. Returns the nodes,
/// the first instance slot, the build time, the node count and the deepest mesh BVH's depth.
fn build_instances(
    scene: &Scene,
    world_nodes: Vec<CwNode>,
    world_depth: u32,
    triangles: &mut Vec<PackedTriangle>,
    attributes: &mut Vec<PackedAttributes>,
    mut seconds: f64,
) -> (Vec<BvhNode>, u32, f64, usize, u32) {
    // Items: the world mesh (identity) when it has triangles, then every instance.
    struct Item {
        blas_root: u32,
        transform: glam::Mat4,
        bounds: crate::scene::Bounds,
    }
    let mut blas_nodes: Vec<CwNode> = Vec::new();
    let mut depth = world_depth;
    let mut items = Vec::new();
    let world_bounds = {
        let mut b = crate::scene::Bounds::empty();
        scene.triangles.iter().flat_map(|t| t.positions).for_each(|p| b.grow(p));
        b
    };
    // Node indices are fixed up once the top level's size is known: BLAS roots are relative
    // to the start of the BLAS block for now.
    let append_blas = |nodes: &[CwNode], tri_offset: u32, blas_nodes: &mut Vec<CwNode>| -> u32 {
        let base = blas_nodes.len() as u32;
        blas_nodes.extend(nodes.iter().map(|n| {
            let mut n = *n;
            n.child_base += base;
            n.primitive_base += tri_offset;
            n
        }));
        base
    };
    if !scene.triangles.is_empty() {
        let root = append_blas(&world_nodes, 0, &mut blas_nodes);
        items.push(Item { blas_root: root, transform: glam::Mat4::IDENTITY, bounds: world_bounds });
    }
    let mut mesh_roots = Vec::new();
    for mesh in &scene.meshes {
        let verts: Vec<[Vec3; 3]> = mesh.triangles.iter().map(|t| t.positions).collect();
        let bvh = accel::build(&verts);
        seconds += bvh.build_seconds;
        depth = depth.max(bvh.depth);
        let tri_offset = triangles.len() as u32;
        if mesh.triangles.is_empty() {
            triangles.push(PackedTriangle::zeroed());
            attributes.push(PackedAttributes::zeroed());
        }
        for &i in &bvh.order {
            let t = &mesh.triangles[i as usize];
            triangles.push(pack_triangle(scene, t, 0.0));
            attributes.push(pack_attributes(t));
        }
        mesh_roots.push(append_blas(&bvh.nodes, tri_offset, &mut blas_nodes));
    }
    for inst in &scene.instances {
        items.push(Item {
            blas_root: mesh_roots[inst.mesh as usize],
            transform: inst.transform,
            bounds: scene.instance_bounds(inst),
        });
    }
    // Top level: median splits over item centroids, children allocated in pairs.
    let mut order: Vec<usize> = (0..items.len()).collect();
    let mut tlas = vec![BvhNode::zeroed()];
    let bounds_of = |ids: &[usize]| {
        let mut b = crate::scene::Bounds::empty();
        for &i in ids {
            if !items[i].bounds.is_empty() {
                b.grow(items[i].bounds.min);
                b.grow(items[i].bounds.max);
            }
        }
        if b.is_empty() { crate::scene::Bounds { min: Vec3::ZERO, max: Vec3::ZERO } } else { b }
    };
    let mut work = vec![(0usize, 0usize, order.len())];
    while let Some((node, lo, hi)) = work.pop() {
        let b = bounds_of(&order[lo..hi]);
        if hi - lo <= 2 {
            tlas[node] = BvhNode { min: b.min.into(), index: lo as u32, max: b.max.into(), count: (hi - lo) as u32 };
            continue;
        }
        let axis = b.diagonal().max_position();
        order[lo..hi].sort_by(|&x, &y| {
            let c = |i: usize| items[i].bounds.center()[axis];
            c(x).total_cmp(&c(y))
        });
        let mid = (lo + hi) / 2;
        let left = tlas.len();
        tlas.push(BvhNode::zeroed());
        tlas.push(BvhNode::zeroed());
        tlas[node] = BvhNode { min: b.min.into(), index: left as u32, max: b.max.into(), count: 0 };
        work.push((left, lo, mid));
        work.push((left + 1, mid, hi));
    }
    let node_count = tlas.len() + blas_nodes.len();
    // The mesh BVHs start at a node index of their own: a multiple of three slots.
    tlas.resize(tlas.len().next_multiple_of(3), BvhNode::zeroed());
    let blas_base = tlas.len() as u32 / 3;
    for n in &mut blas_nodes {
        n.child_base += blas_base;
    }
    let mut nodes = tlas;
    nodes.extend(cw_slots(&blas_nodes));
    let instance_base = nodes.len() as u32;
    for &i in &order {
        let it = &items[i];
        let record = PackedInstance {
            object_to_world: rows(it.transform),
            world_to_object: rows(it.transform.inverse()),
            blas_root: it.blas_root + blas_base,
            flags: if glam::Mat3::from_mat4(it.transform).determinant() < 0.0 { INSTANCE_MIRRORED } else { 0 },
            pad: [0; 6],
        };
        nodes.extend_from_slice(bytemuck::cast_slice::<PackedInstance, BvhNode>(&[record]));
    }
    (nodes, instance_base, seconds, node_count, depth)
}

/// CWBVH nodes as node-buffer slots.
fn cw_slots(nodes: &[CwNode]) -> Vec<BvhNode> {
    bytemuck::cast_slice(nodes).to_vec()
}

/// The environment's texels with the CDFs of the piecewise-constant distribution
/// ∝ luminance × sin θ (marginal over rows, conditional within each row).
fn pack_environment(map: &crate::scene::EnvironmentMap) -> (Vec<[f32; 4]>, u32, u32, f32) {
    let (w, h) = (map.width as usize, map.height as usize);
    let mut env = Vec::with_capacity(w * h + h);
    let mut row_sums = Vec::with_capacity(h);
    for i in 0..h {
        let sin_theta = (std::f64::consts::PI * (i as f64 + 0.5) / h as f64).sin();
        let row = &map.texels[i * w..(i + 1) * w];
        let func: Vec<f64> = row.iter().map(|c| luminance(*c) as f64 * sin_theta).collect();
        let sum: f64 = func.iter().sum();
        let mut acc = 0.0;
        for (j, c) in row.iter().enumerate() {
            acc += func[j];
            let cdf = if sum > 0.0 { if j + 1 == w { 1.0 } else { acc / sum } } else { (j + 1) as f64 / w as f64 };
            env.push([c.x, c.y, c.z, cdf as f32]);
        }
        row_sums.push(sum);
    }
    let total: f64 = row_sums.iter().sum();
    let mut acc = 0.0;
    for (i, s) in row_sums.iter().enumerate() {
        acc += s;
        let cdf = if total > 0.0 { if i + 1 == h { 1.0 } else { acc / total } } else { 0.0 };
        env.push([cdf as f32, 0.0, 0.0, 0.0]);
    }
    (env, w as u32, h as u32, total as f32)
}

pub fn luminance(c: Vec3) -> f32 {
    0.2126 * c.x + 0.7152 * c.y + 0.0722 * c.z
}

pub fn pack_material(m: &Material) -> PackedMaterial {
    let (cutoff, mut flags) = match m.alpha_mode {
        AlphaMode::Opaque => (0.0, 0),
        AlphaMode::Mask(c) => (c, MAT_ALPHA_MASK),
        AlphaMode::Blend => (0.0, MAT_ALPHA_BLEND),
    };
    if m.double_sided {
        flags |= MAT_DOUBLE_SIDED;
    }
    let attenuation = if m.attenuation_distance.is_finite() {
        m.attenuation_color.max(Vec3::splat(1e-6)).map(|c| -c.ln() / m.attenuation_distance)
    } else {
        Vec3::ZERO
    };
    PackedMaterial {
        base_color: m.base_color.into(),
        metallic: m.metallic,
        emission: m.emission.into(),
        roughness: m.roughness,
        dielectric_f0: dielectric_f0(m).into(),
        ior: m.ior,
        dielectric_f90: m.specular_factor,
        transmission: m.transmission,
        alpha: m.alpha,
        alpha_cutoff: cutoff,
        attenuation: attenuation.into(),
        flags,
        normal_scale: m.normal_scale,
        pad: [0.0; 3],
        base_color_texture: pack_texture_ref(m.base_color_texture, true),
        metallic_roughness_texture: pack_texture_ref(m.metallic_roughness_texture, false),
        emissive_texture: pack_texture_ref(m.emissive_texture, true),
        normal_texture: pack_texture_ref(m.normal_texture, false),
    }
}

fn pack_texture_ref(t: Option<TextureRef>, srgb: bool) -> PackedTextureRef {
    match t {
        None => PackedTextureRef { row0: [1.0, 0.0, 0.0], layer: NO_TEXTURE, row1: [0.0, 1.0, 0.0], mode: 0 },
        Some(t) => PackedTextureRef {
            row0: t.transform[0],
            layer: t.texture,
            row1: t.transform[1],
            mode: t.wrap[0] as u32 | (t.wrap[1] as u32) << 2 | if srgb { TEX_SRGB } else { 0 },
        },
    }
}

/// The layer side for `textures`: the largest image side rounded up to a power of two, at
/// most MAX_TEXTURE_LAYER_SIDE, halved until the array fits TEXTURE_BUDGET_BYTES.
pub fn texture_layer_side(textures: &[Texture]) -> u32 {
    let largest = textures.iter().map(|t| t.width.max(t.height)).max().unwrap_or(1);
    let mut side = largest.next_power_of_two().min(MAX_TEXTURE_LAYER_SIDE);
    while side > 64 && textures.len() as u64 * (side as u64).pow(2) * 4 > TEXTURE_BUDGET_BYTES {
        side /= 2;
    }
    side
}

/// Every texture resampled (bilinear/triangle filter) to one square layer of a texture array:
/// lavapipe has no binding arrays, and UVs are relative, so a layer can hold any image.
fn pack_textures(textures: &[Texture]) -> (Vec<u32>, u32, u32) {
    if textures.is_empty() {
        return (vec![u32::MAX], 1, 1);
    }
    let side = texture_layer_side(textures);
    use rayon::prelude::*;
    let layers: Vec<Vec<u32>> = textures
        .par_iter()
        .map(|t| {
            let image = image::RgbaImage::from_raw(t.width, t.height, t.rgba.clone())
                .unwrap_or_else(|| image::RgbaImage::new(t.width.max(1), t.height.max(1)));
            let image = if image.dimensions() == (side, side) {
                image
            } else {
                image::imageops::resize(&image, side, side, image::imageops::FilterType::Triangle)
            };
            image.pixels().map(|p| u32::from_le_bytes(p.0)).collect()
        })
        .collect();
    (layers.concat(), side, textures.len() as u32)
}

/// The dielectric F0 of glTF's metallic-roughness model with KHR_materials_specular/_ior.
pub fn dielectric_f0(m: &Material) -> Vec3 {
    let r = (m.ior - 1.0) / (m.ior + 1.0);
    (r * r * m.specular_color).min(Vec3::ONE) * m.specular_factor
}

/// Vose's alias method: O(1) sampling of a discrete distribution, built in f64.
fn build_alias_table(items: &[u32], weights: &[f64]) -> Vec<LightEntry> {
    let n = items.len();
    if n == 0 {
        return Vec::new();
    }
    let total: f64 = weights.iter().sum();
    let mut scaled: Vec<f64> = weights.iter().map(|w| w * n as f64 / total).collect();
    let mut alias: Vec<usize> = (0..n).collect();
    let mut prob = vec![1.0f64; n];
    let (mut small, mut large): (Vec<usize>, Vec<usize>) = (0..n).partition(|&i| scaled[i] < 1.0);
    while let (Some(s), Some(&l)) = (small.pop(), large.last()) {
        prob[s] = scaled[s];
        alias[s] = l;
        scaled[l] -= 1.0 - scaled[s];
        if scaled[l] < 1.0 {
            large.pop();
            small.push(l);
        }
    }
    (0..n)
        .map(|i| LightEntry {
            triangle: items[i],
            alias_slot: alias[i] as u32,
            prob: prob[i] as f32,
            pmf: (weights[i] / total) as f32,
        })
        .collect()
}

/// Octahedral normal encoding into `pack2x16snorm` bits (decoded by `oct_decode`).
pub fn oct_encode(n: Vec3) -> u32 {
    let n = n / (n.x.abs() + n.y.abs() + n.z.abs()).max(1e-30);
    let mut e = Vec2::new(n.x, n.y);
    if n.z < 0.0 {
        let s = Vec2::new(if n.x >= 0.0 { 1.0 } else { -1.0 }, if n.y >= 0.0 { 1.0 } else { -1.0 });
        e = (Vec2::ONE - Vec2::new(n.y.abs(), n.x.abs())) * s;
    }
    let q = |v: f32| ((v.clamp(-1.0, 1.0) * 32767.0).round() as i16) as u16 as u32;
    q(e.x) | (q(e.y) << 16)
}

/// WGSL's `unpack2x16snorm` followed by the octahedral decode.
pub fn oct_decode(bits: u32) -> Vec3 {
    let u = |b: u32| ((b as u16 as i16) as f32 / 32767.0).max(-1.0);
    let (x, y) = (u(bits & 0xffff), u(bits >> 16));
    let z = 1.0 - x.abs() - y.abs();
    let t = (-z).max(0.0);
    let x = x + if x >= 0.0 { -t } else { t };
    let y = y + if y >= 0.0 { -t } else { t };
    Vec3::new(x, y, z).normalize()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn alias_table_reproduces_weights() {
        let w = [1.0, 2.0, 3.0, 10.0, 0.5];
        let t = build_alias_table(&[0, 1, 2, 3, 4], &w);
        let n = t.len() as f64;
        let mut p = [0.0f64; 5];
        for (i, e) in t.iter().enumerate() {
            p[i] += e.prob as f64 / n;
            p[e.alias_slot as usize] += (1.0 - e.prob as f64) / n;
        }
        let total: f64 = w.iter().sum();
        for i in 0..5 {
            assert!((p[i] - w[i] / total).abs() < 1e-6, "{i}: {} vs {}", p[i], w[i] / total);
        }
    }

    #[test]
    fn octahedral_normals_round_trip() {
        for i in 0..1000 {
            let a = i as f32 * 0.37;
            let b = (i as f32 * 0.11).sin();
            let n = Vec3::new(a.cos() * (1.0 - b * b).sqrt(), a.sin() * (1.0 - b * b).sqrt(), b).normalize();
            let d = oct_decode(oct_encode(n));
            assert!(d.dot(n) > 0.99999, "{n} -> {d}");
        }
    }
}
