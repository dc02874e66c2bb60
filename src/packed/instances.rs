//! The two-level scene: every stored mesh's CWBVH and triangles after the world mesh's, the
//! instance records, and the top level over them (layout in `accel`).

use super::geometry::{pack_attributes, pack_extras, pack_triangle};
use super::layout::{Attributes, Triangle as PackedTriangle};
use crate::accel::{self, BvhNode, CwNode, INSTANCE_MIRRORED, Instance, cw_slots, tlas::build_tlas, tlas::rows};
use crate::scene::Scene;
use bytemuck::Zeroable;
use glam::Vec3;

/// Two-level BVH: each stored mesh's BVH (object space) after the world mesh's, the instance
/// records after them, and a top-level BVH over instance bounds at node 0. Returns the nodes,
/// the first instance slot, the build time, the node count and the deepest mesh BVH's depth.
pub fn build_instances(
    scene: &Scene,
    world_nodes: Vec<CwNode>,
    world_depth: u32,
    triangles: &mut Vec<PackedTriangle>,
    attributes: &mut Vec<Attributes>,
    extras: &mut Vec<Attributes>,
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
            attributes.push(Attributes::zeroed());
            extras.push(Attributes::zeroed());
        }
        for &i in &bvh.order {
            let t = &mesh.triangles[i as usize];
            triangles.push(pack_triangle(scene, t, 0.0));
            attributes.push(pack_attributes(t));
            extras.push(pack_extras(t));
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
    let item_bounds: Vec<crate::scene::Bounds> = items.iter().map(|it| it.bounds).collect();
    let (mut tlas, order) = build_tlas(&item_bounds);
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
        let record = Instance {
            object_to_world: rows(it.transform),
            world_to_object: rows(it.transform.inverse()),
            blas_root: it.blas_root + blas_base,
            flags: if glam::Mat3::from_mat4(it.transform).determinant() < 0.0 { INSTANCE_MIRRORED } else { 0 },
            pad: [0; 6],
        };
        nodes.extend_from_slice(bytemuck::cast_slice::<Instance, BvhNode>(&[record]));
    }
    (nodes, instance_base, seconds, node_count, depth)
}
