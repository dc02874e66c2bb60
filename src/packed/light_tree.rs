//! The light BVH as the kernel reads it: three rows per node, then the emitters' trails,
//! four per row, after the alias table in the `lights` buffer (see `PackedScene::light_rows`).
//!
//! Node rows: (lo.xyz, phi), (hi.xyz, octahedral axis), (cos θ_o, cos θ_e, child 1 or
//! emitter | LIGHT_LEAF | LIGHT_TWO_SIDED, sin θ_o). Floats are stored as f32 bits,
//! unquantized, so the boxes are exact; only the axis is quantized, and θ_o is widened by
//! its error so the cone still holds every emitter's normal. sin θ_o is stored so both
//! twins read the same value instead of each computing it per visit.

use super::layout::{LIGHT_LEAF, LIGHT_TWO_SIDED, PUNCTUAL_SPOT, Punctual};
use super::octahedral::{oct_decode, oct_encode};
use crate::accel::light_bvh::{LightBounds, LightBvh, build_light_bvh, widen};
use glam::Vec3;
use rayon::prelude::*;

/// The bounds of one emissive triangle: it emits from its front face (cross(e1, e2)) into
/// the hemisphere there, with power bound radiance luminance × area (importance then bounds
/// the irradiance it gives).
pub fn triangle_bounds(positions: [Vec3; 3], luminance: f32) -> LightBounds {
    let [p0, p1, p2] = positions;
    let c = (p1 - p0).cross(p2 - p0);
    LightBounds {
        lo: p0.min(p1).min(p2),
        hi: p0.max(p1).max(p2),
        phi: finite_power(luminance * 0.5 * c.length()),
        axis: c.normalize_or_zero(),
        cos_o: 1.0,
        cos_e: 0.0,
        two_sided: false,
    }
}

/// The bounds of a point or spot light: intensity luminance as its power; a spot emits into
/// its outer cone (θ_o the inner angle, θ_e the rest, as pbrt-v4 bounds spots).
pub fn punctual_bounds(l: &Punctual, luminance: f32) -> LightBounds {
    let p = Vec3::from(l.position);
    let (axis, cos_o, cos_e) = if l.kind == PUNCTUAL_SPOT {
        let cos_inner = l.cos_inner.max(l.cos_outer);
        let inner = (cos_inner as f64).clamp(-1.0, 1.0).acos();
        let outer = (l.cos_outer as f64).clamp(-1.0, 1.0).acos();
        // A little spread even for hard-edged spots: θ' ≥ θ_e then culls only what is outside.
        (Vec3::from(l.direction), cos_inner, widen((outer - inner).max(0.0).cos(), 1e-4))
    } else {
        (Vec3::Z, -1.0, 0.0)
    };
    LightBounds { lo: p, hi: p, phi: finite_power(luminance), axis, cos_o, cos_e, two_sided: false }
}

/// Power as the tree stores it: non-finite or negative power is none (never chosen).
fn finite_power(phi: f32) -> f32 {
    if phi.is_finite() { phi.max(0.0) } else { 0.0 }
}

/// The packed tree.
pub struct PackedLightTree {
    /// Node rows then trail rows.
    pub rows: Vec<[u32; 4]>,
    pub nodes: usize,
    pub trail_offset: u32,
    pub depth: u32,
    pub build_seconds: f64,
}

pub fn pack_light_tree(emitters: &[LightBounds]) -> PackedLightTree {
    let LightBvh { nodes, trails, depth, build_seconds } = build_light_bvh(emitters);
    let mut rows: Vec<[u32; 4]> = Vec::with_capacity(3 * nodes.len() + trails.len().div_ceil(4));
    rows.resize(3 * nodes.len(), [0; 4]);
    rows.par_chunks_mut(3).zip(nodes.par_iter()).for_each(|(out, n)| {
        let b = &n.bounds;
        let axis_bits = oct_encode(b.axis);
        // Widen the cone by the quantized axis' error, plus slack for the GPU's decode.
        let err = (oct_decode(axis_bits).dot(b.axis) as f64).clamp(-1.0, 1.0).acos();
        let cos_o = if b.cos_o <= -1.0 { -1.0 } else { widen(b.cos_o as f64, err + 2e-5) };
        let sin_o = (1.0 - cos_o * cos_o).max(0.0).sqrt();
        let f = |x: f32| x.to_bits();
        let index = n.index | if n.leaf { LIGHT_LEAF } else { 0 } | if b.two_sided { LIGHT_TWO_SIDED } else { 0 };
        out[0] = [f(b.lo.x), f(b.lo.y), f(b.lo.z), f(b.phi)];
        out[1] = [f(b.hi.x), f(b.hi.y), f(b.hi.z), axis_bits];
        out[2] = [f(cos_o), f(b.cos_e), index, f(sin_o)];
    });
    let trail_offset = rows.len() as u32;
    for chunk in trails.chunks(4) {
        let mut row = [0; 4];
        row[..chunk.len()].copy_from_slice(chunk);
        rows.push(row);
    }
    PackedLightTree { rows, nodes: nodes.len(), trail_offset, depth, build_seconds }
}

/// The two children of an interior node of the light tree, decoded for the CPU engine, which
/// evaluates both children's importance at once in SIMD lanes (lane 0: the first child, at the
/// parent's index + 1; lane 1: the second). The values are the node rows' own bits (the axis
/// decoded as the kernel decodes it), so both twins still compute the same numbers.
#[derive(Clone, Copy, Debug, Default)]
#[repr(C, align(8))]
pub struct LightPair {
    pub lo: [[f32; 2]; 3],
    pub hi: [[f32; 2]; 3],
    pub axis: [[f32; 2]; 3],
    pub phi: [f32; 2],
    pub cos_o: [f32; 2],
    pub sin_o: [f32; 2],
    pub cos_e: [f32; 2],
    /// Per child: a leaf's emitter | LIGHT_LEAF | LIGHT_TWO_SIDED, or an interior child's
    /// own pair index | LIGHT_TWO_SIDED.
    pub next: [u32; 2],
}

/// The pairs of the tree whose node rows are `rows` (`nodes` of them, axes decoded in
/// `axes`), indexed so that the root's children are pair 0; empty when the root is a leaf.
pub fn light_pairs(rows: &[[u32; 4]], nodes: usize, axes: &[Vec3]) -> Vec<LightPair> {
    let is_leaf = |n: usize| rows[3 * n + 2][2] & LIGHT_LEAF != 0;
    if nodes == 0 || is_leaf(0) {
        return Vec::new();
    }
    // Interior nodes in index order: pair k holds the children of the k-th interior node.
    let mut ordinal = vec![u32::MAX; nodes];
    let mut interior = Vec::new();
    for (n, o) in ordinal.iter_mut().enumerate() {
        if !is_leaf(n) {
            *o = interior.len() as u32;
            interior.push(n);
        }
    }
    let flags = LIGHT_LEAF | LIGHT_TWO_SIDED;
    interior
        .par_iter()
        .map(|&n| {
            let children = [n + 1, (rows[3 * n + 2][2] & !flags) as usize];
            let mut p = LightPair::default();
            for (lane, &c) in children.iter().enumerate() {
                let [r0, r1, r2] = [rows[3 * c], rows[3 * c + 1], rows[3 * c + 2]];
                let f = f32::from_bits;
                for k in 0..3 {
                    p.lo[k][lane] = f(r0[k]);
                    p.hi[k][lane] = f(r1[k]);
                    p.axis[k][lane] = axes[c][k];
                }
                p.phi[lane] = f(r0[3]);
                p.cos_o[lane] = f(r2[0]);
                p.cos_e[lane] = f(r2[1]);
                p.sin_o[lane] = f(r2[3]);
                p.next[lane] = if r2[2] & LIGHT_LEAF != 0 { r2[2] } else { ordinal[c] | (r2[2] & LIGHT_TWO_SIDED) };
            }
            p
        })
        .collect()
}
