//! Acceleration structure: a compressed 8-wide BVH (Ylitie, Karras & Laine 2017) built on the
//! CPU by obvhs (PLOC + reinsertion, SAH quality, then collapsed to 8-wide nodes with
//! quantised child boxes), which the WGSL traversal and the CPU reference share.
//!
//! Why 8-wide and compressed: lavapipe loads storage buffers lane by lane and dword by dword,
//! so a ray's cost follows the bytes it reads; an 80-byte node holds eight child boxes where
//! a BVH2 reads 64 bytes for two (BENCHMARKS.md: 1.4× samples/s on lavapipe).

use crate::packed::CwNode;
use bytemuck::Zeroable;
use glam::Vec3;
use obvhs::{BvhBuildParams, cwbvh::builder::build_cwbvh_from_tris, triangle::Triangle as BvhTriangle};
use std::time::{Duration, Instant};

pub struct Bvh {
    pub nodes: Vec<CwNode>,
    /// Triangle order of the leaves: leaf primitive `i` is scene triangle `order[i]`.
    pub order: Vec<u32>,
    pub build_seconds: f64,
    /// Levels of nodes from the root to the deepest leaf (1 for a root alone).
    pub depth: u32,
}

/// The deepest BVH the traversal stacks can walk without dropping a subtree: a walk pushes at
/// most one group of children per level. The CPU walk sizes its stack from it; STACK_SIZE in
/// shaders/bvh.wgsl is its twin.
pub const MAX_DEPTH: u32 = 32;

/// Builds the BVH over triangles given by their three vertices.
pub fn build(triangles: &[[Vec3; 3]]) -> Bvh {
    let start = Instant::now();
    if triangles.is_empty() {
        // A root with no children: rays enter it and find nothing.
        return Bvh { nodes: vec![CwNode::zeroed()], order: Vec::new(), build_seconds: 0.0, depth: 1 };
    }
    let tris: Vec<BvhTriangle> =
        triangles.iter().map(|t| BvhTriangle { v0: t[0].into(), v1: t[1].into(), v2: t[2].into() }).collect();
    let bvh = build_cwbvh_from_tris(&tris, BvhBuildParams::medium_build(), &mut Duration::default());
    // obvhs's node is our CwNode without the padding (same field order, little-endian bytes).
    let nodes: Vec<CwNode> = bvh
        .nodes
        .iter()
        .map(|n| {
            let mut node = CwNode::zeroed();
            bytemuck::bytes_of_mut(&mut node)[..80].copy_from_slice(bytemuck::bytes_of(n));
            node
        })
        .collect();
    debug_assert_eq!(bvh.primitive_indices.len(), triangles.len());
    let depth = depth(&nodes);
    Bvh { nodes, order: bvh.primitive_indices, build_seconds: start.elapsed().as_secs_f64(), depth }
}

/// Levels of the tree under node 0: PLOC bounds no depth, so it is measured, and a renderer
/// refuses a scene deeper than MAX_DEPTH rather than miss hits.
fn depth(nodes: &[CwNode]) -> u32 {
    let mut deepest = 0;
    let mut work = vec![(0usize, 1u32)];
    while let Some((i, level)) = work.pop() {
        deepest = deepest.max(level);
        let n = &nodes[i];
        let inner = (n.e_imask >> 24).count_ones() as usize;
        work.extend((0..inner).map(|k| (n.child_base as usize + k, level + 1)));
    }
    deepest
}
