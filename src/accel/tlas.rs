//! The top level of the two-level BVH: a BVH2 over instance bounds, and the instance records
//! it leads to, both stored in slots of the node buffer.

use crate::scene::Bounds;
use bytemuck::{Pod, Zeroable};
use glam::Vec3;

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

/// An instance as the kernel reads it: object→world and world→object as 3×4 rows, the root
/// of its mesh's BVH and whether it mirrors; four BvhNode-sized slots.
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable, PartialEq)]
pub struct Instance {
    pub object_to_world: [[f32; 4]; 3],
    pub world_to_object: [[f32; 4]; 3],
    pub blas_root: u32,
    /// INSTANCE_MIRRORED when the transform flips handedness.
    pub flags: u32,
    pub pad: [u32; 6],
}

pub const INSTANCE_MIRRORED: u32 = 1;

pub fn rows(m: glam::Mat4) -> [[f32; 4]; 3] {
    let r = m.transpose().to_cols_array_2d();
    [r[0], r[1], r[2]]
}

/// A BVH2 over item bounds by median splits of the centroids, children allocated in pairs.
/// Returns the nodes (leaf `index` into the returned order) and the item order of the leaves.
pub fn build_tlas(bounds: &[Bounds]) -> (Vec<BvhNode>, Vec<usize>) {
    let mut order: Vec<usize> = (0..bounds.len()).collect();
    let mut tlas = vec![BvhNode::zeroed()];
    let bounds_of = |ids: &[usize]| {
        let mut b = Bounds::empty();
        for &i in ids {
            if !bounds[i].is_empty() {
                b.grow(bounds[i].min);
                b.grow(bounds[i].max);
            }
        }
        if b.is_empty() { Bounds { min: Vec3::ZERO, max: Vec3::ZERO } } else { b }
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
            let c = |i: usize| bounds[i].center()[axis];
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
    (tlas, order)
}
