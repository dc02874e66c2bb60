//! Acceleration structures, built on the CPU and walked by both engines: a compressed 8-wide
//! BVH per mesh (`cwbvh`) under a BVH2 over instances (`tlas`), all in one node buffer of
//! 32-byte slots:
//!
//! ```text
//! slot 0 ..              TLAS BvhNodes (with instances), or the one mesh's CwNodes (3 slots each)
//! 3·k ..                 each mesh's CwNodes (a CwNode index i is slot 3 i)
//! instance_base + 4 j .. instance record j (Instance, 4 slots)
//! ```

pub mod cwbvh;
pub mod light_bvh;
pub mod tlas;

pub use cwbvh::{Bvh, CwNode, build, cw_slots};
pub use tlas::{BvhNode, INSTANCE_MIRRORED, Instance};

/// The deepest BVH the traversal stacks can walk without dropping a subtree: a walk pushes at
/// most one group of children per level. The CPU walk sizes its stack from it; STACK_SIZE in
/// shaders/bvh.wgsl is its twin (tests/layout.rs compares them).
pub const MAX_DEPTH: u32 = 32;

/// BvhNode slots per CwNode, and per instance record.
pub const CW_NODE_SLOTS: u32 = 3;
pub const INSTANCE_SLOTS: u32 = 4;
