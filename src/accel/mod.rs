//! Acceleration structure: a BVH2 built on the CPU with obvhs (PLOC + reinsertion, SAH
//! quality), flattened into 32-byte nodes that the WGSL traversal and the CPU reference share.

use crate::packed::BvhNode;
use glam::Vec3;
use obvhs::{BvhBuildParams, bvh2::builder::build_bvh2_from_tris, triangle::Triangle as BvhTriangle};
use std::time::{Duration, Instant};

pub struct Bvh {
    pub nodes: Vec<BvhNode>,
    /// Triangle order of the leaves: leaf primitive `i` is scene triangle `order[i]`.
    pub order: Vec<u32>,
    pub build_seconds: f64,
}

/// Builds the BVH over triangles given by their three vertices.
pub fn build(triangles: &[[Vec3; 3]]) -> Bvh {
    let start = Instant::now();
    if triangles.is_empty() {
        // One leaf holding one degenerate triangle (added by the packer): rays can enter
        // it, but a zero-area triangle is never hit, so traversal needs no special case.
        let node = BvhNode { min: [0.0; 3], index: 0, max: [0.0; 3], count: 1 };
        return Bvh { nodes: vec![node], order: Vec::new(), build_seconds: 0.0 };
    }
    let tris: Vec<BvhTriangle> =
        triangles.iter().map(|t| BvhTriangle { v0: t[0].into(), v1: t[1].into(), v2: t[2].into() }).collect();
    let bvh = build_bvh2_from_tris(&tris, BvhBuildParams::medium_build(), &mut Duration::default());
    let nodes = bvh
        .nodes
        .iter()
        .map(|n| BvhNode { min: n.aabb.min.into(), index: n.first_index, max: n.aabb.max.into(), count: n.prim_count })
        .collect();
    Bvh { nodes, order: bvh.primitive_indices, build_seconds: start.elapsed().as_secs_f64() }
}
