//! Mesh BVHs: a compressed 8-wide BVH (Ylitie, Karras & Laine 2017) built on the
//! CPU by obvhs (PLOC + reinsertion, SAH quality, then collapsed to 8-wide nodes with
//! quantised child boxes), which the WGSL traversal and the CPU reference share.
//!
//! Why 8-wide and compressed: lavapipe loads storage buffers lane by lane and dword by dword,
//! so a ray's cost follows the bytes it reads; an 80-byte node holds eight child boxes where
//! a BVH2 reads 64 bytes for two (BENCHMARKS.md: 1.4× samples/s on lavapipe).

use super::tlas::BvhNode;
use bytemuck::{Pod, Zeroable};
use glam::Vec3;
use obvhs::{BvhBuildParams, cwbvh::builder::build_cwbvh_from_tris, triangle::Triangle as BvhTriangle};
use std::time::{Duration, Instant};

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

/// CWBVH nodes as node-buffer slots.
pub fn cw_slots(nodes: &[CwNode]) -> Vec<BvhNode> {
    bytemuck::cast_slice(nodes).to_vec()
}

pub struct Bvh {
    pub nodes: Vec<CwNode>,
    /// Triangle order of the leaves: leaf primitive `i` is scene triangle `order[i]`.
    pub order: Vec<u32>,
    pub build_seconds: f64,
    /// Levels of nodes from the root to the deepest leaf (1 for a root alone).
    pub depth: u32,
}

/// Builds the BVH over triangles given by their three vertices. Triangles of zero area (no
/// ray can hit them; glTF files have them where a node is scaled to 0 at rest) stay out of
/// the tree, after the leaves' triangles in `order`: hundreds at one point made PLOC chain
/// them 94 levels deep (AnimateAllTheThings).
pub fn build(triangles: &[[Vec3; 3]]) -> Bvh {
    let start = Instant::now();
    let (kept, degenerate): (Vec<u32>, Vec<u32>) = (0..triangles.len() as u32).partition(|&i| {
        let t = &triangles[i as usize];
        (t[1] - t[0]).cross(t[2] - t[0]).length_squared() > 0.0
    });
    if kept.is_empty() {
        // A root with no children: rays enter it and find nothing.
        return Bvh { nodes: vec![CwNode::zeroed()], order: degenerate, build_seconds: 0.0, depth: 1 };
    }
    let tris: Vec<BvhTriangle> = kept
        .iter()
        .map(|&i| triangles[i as usize])
        .map(|t| BvhTriangle { v0: t[0].into(), v1: t[1].into(), v2: t[2].into() })
        .collect();
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
    debug_assert_eq!(bvh.primitive_indices.len(), kept.len());
    let depth = depth(&nodes);
    let order = bvh.primitive_indices.iter().map(|&i| kept[i as usize]).chain(degenerate).collect();
    Bvh { nodes, order, build_seconds: start.elapsed().as_secs_f64(), depth }
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
