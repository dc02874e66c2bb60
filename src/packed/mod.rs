//! The packed scene: the exact buffers the GPU reads, and the CPU reference reads too.
//!
//! `layout` holds the records (twins of `shaders/common.wgsl`); the other files pack one
//! kind of scene data each. The node buffer's slot layout is described in `accel`.

mod environment;
mod features;
mod geometry;
mod instances;
pub mod layout;
mod light_tree;
mod lights;
mod materials;
mod octahedral;
mod textures;
mod triangle_lanes;

pub use crate::accel::{BvhNode, CwNode, INSTANCE_MIRRORED, Instance};
pub use features::Features;
pub use layout::*;
pub use light_tree::{CLUSTER_EMITTERS, LightGroup};
pub use materials::{dielectric_f0, luminance, pack_material};
pub use octahedral::{oct_decode, oct_encode};
pub use textures::{
    MAX_PAGE_SIDE, MAX_PAGES, Placement, TEXTURE_BUDGET_BYTES, TextureAtlas, atlas_sizes, pack_textures,
    pack_textures_within, shelf_pack,
};
pub use triangle_lanes::{TRIANGLE_LANES, TriangleLanes};

use crate::accel::{self, cw_slots};
use crate::scene::{Environment, Scene};
use bytemuck::Zeroable;
use environment::pack_environment;
use geometry::{pack_attributes, pack_extras, pack_triangle};
use glam::Vec3;
use instances::build_instances;
use light_tree::{pack_light_tree, punctual_bounds, triangle_bounds};

/// Does the material read any texture?
fn has_texture(m: &Material) -> bool {
    [
        &m.base_color_texture,
        &m.metallic_roughness_texture,
        &m.emissive_texture,
        &m.normal_texture,
        &m.transmission_texture,
        &m.specular_texture,
        &m.specular_color_texture,
        &m.clearcoat_texture,
        &m.clearcoat_roughness_texture,
        &m.clearcoat_normal_texture,
        &m.sheen_color_texture,
        &m.sheen_roughness_texture,
        &m.anisotropy_texture,
        &m.iridescence_texture,
        &m.iridescence_thickness_texture,
        &m.diffuse_transmission_texture,
        &m.diffuse_transmission_color_texture,
    ]
    .iter()
    .any(|t| t.atlas != NO_TEXTURE)
}

/// (nodes, depth, build seconds, bytes) of the packed light tree over `emitters`: `veach
/// bench`'s scale test.
pub fn pack_light_tree_for_bench(emitters: &[crate::accel::light_bvh::LightBounds]) -> (usize, u32, f64, usize) {
    let t0 = std::time::Instant::now();
    let t = pack_light_tree(emitters, &[]);
    (t.nodes, t.depth, t0.elapsed().as_secs_f64(), t.rows.len() * 16)
}
use lights::{build_alias_table, pack_punctual};

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
    pub triangles: Vec<Triangle>,
    /// `triangles` as a structure of arrays for the CPU walk (`triangle_lanes()`).
    pub(crate) triangle_lanes: std::sync::OnceLock<TriangleLanes>,
    pub attributes: Vec<Attributes>,
    /// First record of the triangles' extra vertex data (COLOR_0, TEXCOORD_1) in
    /// `attributes`, one a triangle in the same order (`geometry::pack_extras`); 0: none.
    pub extras_base: u32,
    pub materials: Vec<Material>,
    /// Per material: has it a texture (CPU only: a hit on one without needs no UVs).
    pub material_textured: Vec<bool>,
    pub lights: Vec<LightEntry>,
    /// The `lights` buffer: the alias table (one row per entry, `LightEntry` as u32 bits),
    /// then from `tree_base` the light tree's node records (`LIGHT_NODE_ROWS` rows each: the
    /// root, then groups of `LIGHT_TREE_WIDTH` siblings) and from
    /// `trail_base` its emitters' trails, four per row, then its clusters' entries, two per
    /// row (a cluster's index word counts entries from `trail_base`). At least one row.
    pub light_rows: Vec<[u32; 4]>,
    /// The light tree's node axes decoded (`oct_decode` of each node's axis word), for the
    /// CPU engine: decoding is a normalization per node visit.
    pub light_axes: Vec<Vec3>,
    /// The tree's groups of siblings decoded (`light_tree::light_groups`), for the CPU
    /// engine's four-lane walk; empty when the root is a leaf or there is no tree.
    pub light_groups: Vec<LightGroup>,
    /// Per emissive triangle of the alias table: its first vertex and cross(e1, e2), the plane
    /// the walk tests one-sided leaves against (the same products the triangle gives).
    pub light_planes: Vec<[Vec3; 2]>,
    /// Emitters in the light tree (0: no tree): the alias table's triangles, then the point
    /// and spot lights (the punctual lights after the first `directional_count`).
    pub tree_emitters: u32,
    pub tree_base: u32,
    pub trail_base: u32,
    pub directional_count: u32,
    pub light_tree_nodes: usize,
    pub light_tree_depth: u32,
    /// Leaves of the light tree that are clusters of several emitters.
    pub light_tree_clusters: usize,
    pub light_tree_seconds: f64,
    /// Original scene index of each packed triangle.
    pub order: Vec<u32>,
    pub bvh_build_seconds: f64,
    /// BVH nodes: the meshes' CWBVH nodes and the top level's BVH2 nodes.
    pub bvh_nodes: usize,
    /// Levels of the deepest mesh BVH (see accel::MAX_DEPTH).
    pub bvh_depth: u32,
    /// Constant environment radiance, or the tint of the environment map.
    pub environment: Vec3,
    /// The scene's own environment (what settings without environment flags render).
    pub scene_environment: Environment,
    /// The light-data buffer: environment map texels (rgb, conditional CDF of the row up to
    /// this texel), then one row per map row (marginal CDF up to this row, 0, 0, 0); one
    /// zeroed row when there is no map. The punctual lights follow, four rows each, from
    /// `punctual_base`. One buffer because lavapipe binds at most 8 storage buffers.
    pub light_data: Vec<[f32; 4]>,
    /// The punctual lights (also in `light_data`), kept to rebuild it for a new environment.
    pub punctuals: Vec<Punctual>,
    pub punctual_base: u32,
    /// First row of the sheen albedo table (after the punctual lights) in `light_data`.
    pub sheen_base: u32,
    pub punctual_count: u32,
    /// The texture atlas: `texture_pages` square pages of `texture_size`² RGBA8 texels (one
    /// u32 each, R in the low byte), row-major, page after page; at least one page. Each
    /// image keeps its own size (see `textures::pack_textures`).
    pub texels: Vec<u32>,
    pub texture_size: u32,
    pub texture_pages: u32,
    /// Texels the images cover over those of the pages.
    pub texture_occupancy: f64,
    /// What packing changed that the user should hear of (images stored smaller), one line each.
    pub warnings: Vec<String>,
    pub env_width: u32,
    pub env_height: u32,
    /// Σ luminance × sin θ over all texels: the normaliser of the sampling pmf.
    pub env_total: f32,
    /// Scene bounds' diagonal length (scale for ray epsilons where needed).
    pub extent: f32,
}

impl PackedScene {
    /// Packs a scene after `Scene::validate`: the way for scenes built by hand.
    pub fn try_new(scene: &Scene) -> Result<PackedScene, crate::Error> {
        scene.validate()?;
        Ok(PackedScene::new(scene))
    }

    /// Packs a scene the loader made (valid by construction; an invalid one panics: use
    /// `try_new` for scenes built by hand).
    pub fn new(scene: &Scene) -> PackedScene {
        let verts: Vec<[Vec3; 3]> = scene.triangles.iter().map(|t| t.positions).collect();
        let bvh = accel::build(&verts);
        let ordered: Vec<&crate::scene::Triangle> = bvh.order.iter().map(|&i| &scene.triangles[i as usize]).collect();

        let atlas = pack_textures(&scene.textures);
        let materials: Vec<Material> = scene.materials.iter().map(|m| pack_material(m, &atlas.placements)).collect();

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

        let mut triangles: Vec<Triangle> =
            ordered.iter().zip(&light_pdf).map(|(t, &pdf)| pack_triangle(scene, t, pdf)).collect();

        // Punctual lights: directional ones first (they stay outside the light tree).
        let mut punctuals: Vec<Punctual> = scene.punctual_lights.iter().map(pack_punctual).collect();
        punctuals.sort_by_key(|l| l.kind != PUNCTUAL_DIRECTIONAL);
        let directional_count = punctuals.iter().filter(|l| l.kind == PUNCTUAL_DIRECTIONAL).count() as u32;
        let mut emitters: Vec<_> = lights
            .iter()
            .map(|l| {
                let t = ordered[l.triangle as usize];
                triangle_bounds(t.positions, luminance(scene.materials[t.material as usize].emission))
            })
            .collect();
        emitters.extend(
            punctuals[directional_count as usize..].iter().map(|l| punctual_bounds(l, luminance(l.intensity.into()))),
        );
        // (A black light keeps its place with no power: it is never chosen.)
        let tree = if !emitters.is_empty() && emitters.len() <= MAX_EMITTERS {
            for (i, l) in lights.iter().enumerate() {
                triangles[l.triangle as usize].flags |= (i as u32 + 1) << TRI_EMITTER_SHIFT;
            }
            let corners: Vec<[Vec3; 3]> = lights.iter().map(|l| ordered[l.triangle as usize].positions).collect();
            Some(pack_light_tree(&emitters, &corners))
        } else {
            // More emitters than the triangle flags can name: only the power sampler.
            None
        };
        let mut light_rows: Vec<[u32; 4]> = bytemuck::cast_slice(&lights).to_vec();
        let tree_base = light_rows.len() as u32;
        let mut light_axes = Vec::new();
        let mut light_groups = Vec::new();
        let light_tree_clusters = tree.as_ref().map_or(0, |t| t.clusters);
        let (tree_emitters, trail_base, light_tree_nodes, light_tree_depth, light_tree_seconds) = match tree {
            Some(t) => {
                light_rows.extend_from_slice(&t.rows);
                light_axes = t.rows[..3 * t.nodes].chunks(3).map(|r| octahedral::oct_decode(r[1][3])).collect();
                light_groups = light_tree::light_groups(&t.rows, t.nodes, &light_axes);
                (emitters.len() as u32, tree_base + t.trail_offset, t.nodes, t.depth, t.build_seconds)
            }
            None => (0, tree_base, 0, 0, 0.0),
        };
        if light_rows.is_empty() {
            light_rows.push([0; 4]);
        }
        if triangles.is_empty() {
            // No triangle is referenced (the empty BVH's root has no children), but a storage
            // binding needs at least one element.
            triangles.push(Triangle::zeroed());
        }
        let mut attributes: Vec<Attributes> = ordered.iter().map(|t| pack_attributes(t)).collect();
        attributes.resize(triangles.len(), Attributes::zeroed());
        let mut extras: Vec<Attributes> = ordered.iter().map(|t| pack_extras(t)).collect();
        extras.resize(triangles.len(), Attributes::zeroed());
        let (nodes, instance_base, build_seconds, bvh_nodes, bvh_depth) = if scene.instances.is_empty() {
            (cw_slots(&bvh.nodes), 0, bvh.build_seconds, bvh.nodes.len(), bvh.depth)
        } else {
            build_instances(
                scene,
                bvh.nodes,
                bvh.depth,
                &mut triangles,
                &mut attributes,
                &mut extras,
                bvh.build_seconds,
            )
        };
        // Vertex colours and second UVs, only for scenes that have them: a region after the
        // triangles' attributes (no new binding).
        let has_extras = scene
            .triangles
            .iter()
            .chain(scene.meshes.iter().flat_map(|m| &m.triangles))
            .any(|t| t.colors.is_some() || t.uvs1.is_some());
        let extras_base = if has_extras {
            let base = attributes.len() as u32;
            attributes.extend(extras);
            base
        } else {
            0
        };
        let nodes_len = nodes.len();
        let bounds = scene.bounds();
        let extent = if bounds.is_empty() { 1.0 } else { bounds.diagonal().length() };
        let mut packed = PackedScene {
            nodes,
            instance_base,
            instance_count: if scene.instances.is_empty() {
                0
            } else {
                (nodes_len - instance_base as usize) as u32 / 4
            },
            triangles,
            triangle_lanes: std::sync::OnceLock::new(),
            attributes,
            extras_base,
            material_textured: materials.iter().map(has_texture).collect(),
            materials,
            lights,
            light_rows,
            light_axes,
            light_groups,
            light_planes: Vec::new(),
            tree_emitters,
            tree_base,
            trail_base,
            directional_count,
            light_tree_nodes,
            light_tree_depth,
            light_tree_clusters,
            light_tree_seconds,
            order: bvh.order,
            bvh_build_seconds: build_seconds,
            bvh_nodes,
            bvh_depth,
            environment: Vec3::ZERO,
            scene_environment: scene.environment.clone(),
            light_data: Vec::new(),
            punctuals,
            punctual_base: 0,
            sheen_base: 0,
            punctual_count: scene.punctual_lights.len() as u32,
            texture_occupancy: atlas.occupancy(),
            texels: atlas.texels,
            texture_size: atlas.side,
            texture_pages: atlas.pages,
            warnings: atlas.warnings,
            env_width: 0,
            env_height: 0,
            env_total: 0.0,
            extent,
        };
        packed.light_planes = packed
            .lights
            .iter()
            .map(|l| {
                let t = &packed.triangles[l.triangle as usize];
                [Vec3::from(t.p0), Vec3::from(t.e1).cross(Vec3::from(t.e2))]
            })
            .collect();
        light_tree::attach_planes(
            &mut packed.light_groups,
            &packed.light_planes,
            &packed.light_rows,
            packed.trail_base,
        );
        packed.set_environment(&scene.environment);
        packed
    }

    /// Whether the scene has an emitter of its own: an emissive triangle or a punctual light.
    /// The triangles as a structure of arrays, made on first use (the CPU walk's leaf test).
    pub fn triangle_lanes(&self) -> &TriangleLanes {
        self.triangle_lanes.get_or_init(|| TriangleLanes::new(&self.triangles))
    }

    pub fn has_lights(&self) -> bool {
        !self.lights.is_empty() || self.punctual_count > 0
    }

    /// Replaces the environment (map and radiance) without touching geometry: the light-data
    /// buffer is rebuilt, the BVH is not.
    pub fn set_environment(&mut self, environment: &Environment) {
        let (mut rows, w, h, total) = match &environment.map {
            Some(map) => pack_environment(map),
            None => (vec![[0.0; 4]], 0, 0, 0.0),
        };
        self.punctual_base = rows.len() as u32;
        rows.extend_from_slice(bytemuck::cast_slice::<Punctual, [f32; 4]>(&self.punctuals));
        // The table only when a material has sheen: it costs the quadrature once per process.
        self.sheen_base = rows.len() as u32;
        if self.materials.iter().any(|m| m.sheen_color.iter().any(|&c| c > 0.0)) {
            rows.extend(crate::sheen::sheen_albedo_rows());
        }
        self.light_data = rows;
        (self.env_width, self.env_height, self.env_total) = (w, h, total);
        self.environment = environment.radiance;
    }
}
