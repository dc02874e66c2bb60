//! The light BVH as the kernel reads it: three rows per node, then the emitters' trails,
//! four per row, then the clusters' entries, two per row, after the alias table in the
//! `lights` buffer (see `PackedScene::light_rows`).
//!
//! Node rows: (lo.xyz, phi), (hi.xyz, octahedral axis), (cos θ_o, cos θ_e, first child or
//! emitter | LIGHT_LEAF | LIGHT_TWO_SIDED, or a cluster's first entry | LIGHT_LEAF |
//! LIGHT_CLUSTER [| LIGHT_PLANAR], sin θ_o). A cluster entry is (emitter [| CLUSTER_LAST],
//! its probability in the cluster as f32 bits). Floats are stored as f32 bits,
//! unquantized, so the boxes are exact; only the axis is quantized, and θ_o is widened by
//! its error so the cone still holds every emitter's normal. sin θ_o is stored so both
//! twins read the same value instead of each computing it per visit.

use super::layout::{
    CLUSTER_LAST, LIGHT_CLUSTER, LIGHT_INDEX_MASK, LIGHT_LEAF, LIGHT_PLANAR, LIGHT_TWO_SIDED, PUNCTUAL_SPOT, Punctual,
};
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

/// The binary tree's grandchildren (a child that is a leaf stands for itself) become a node's
/// children: the walk takes half the steps and weighs up to four subtrees against each other.
const LIGHT_TREE_WIDTH: usize = super::layout::LIGHT_TREE_WIDTH as usize;

/// Subtrees of at most this many emitters whose normals lie within `CLUSTER_COS_O` and whose
/// triangles fill their box (`CLUSTER_FILL`) become
/// one leaf, a cluster chosen inside by power alone: the walk stops levels earlier (the
/// lamps of a typical scene are meshes of many small triangles that face one way, where the
/// importance of each triangle would hardly differ).
pub const CLUSTER_EMITTERS: usize = 16;
/// The widest orientation cone (cos θ_o) of a cluster (26°): a cluster is chosen by power
/// alone, so a point that sees some of its triangles from behind wastes the samples that
/// choose those (two faces of a small octahedron, 35° apart, lost the glossy hall 30 % in
/// error at 37°; BENCHMARKS.md session 25).
const CLUSTER_COS_O: f32 = 0.9;
/// A cluster's triangles cover at least this share of its box's squared diagonal (one lamp's
/// patch of surface, not several lamps apart: across a gap the distance to each matters, and
/// a glossy lobe that sees one of them would lose it to the others' power).
const CLUSTER_FILL: f64 = 0.2;

/// The packed tree.
pub struct PackedLightTree {
    /// Node rows, trail rows, then cluster entry rows.
    pub rows: Vec<[u32; 4]>,
    /// Node records (three rows each): the root, then groups of `LIGHT_TREE_WIDTH` siblings.
    pub nodes: usize,
    pub trail_offset: u32,
    /// Deepest leaf of the packed tree (the root is depth 0).
    pub depth: u32,
    /// Leaves that are clusters of several emitters.
    pub clusters: usize,
    pub build_seconds: f64,
}

/// Whether one-sided triangles `corners` (emitter ids `members`) lie in one plane facing one
/// way, within float tolerance.
fn coplanar(members: &[u32], corners: &[[Vec3; 3]]) -> bool {
    let Some(&[p0, p1, p2]) = members.first().and_then(|&m| corners.get(m as usize)) else { return false };
    let n = (p1 - p0).cross(p2 - p0).normalize_or_zero();
    if n == Vec3::ZERO {
        return false;
    }
    let scale = members
        .iter()
        .filter_map(|&m| corners.get(m as usize))
        .flatten()
        .fold(0.0f32, |a, v| a.max((*v - p0).abs().max_element()));
    members.iter().all(|&m| {
        corners.get(m as usize).is_some_and(|&[a, b, c]| {
            let nm = (b - a).cross(c - a).normalize_or_zero();
            nm.dot(n) > 1.0 - 1e-6 && [a, b, c].iter().all(|v| n.dot(*v - p0).abs() <= 1e-6 * scale.max(1e-6))
        })
    })
}

/// Packs the binary light BVH as a 4-wide tree. Record 0 is the root; an interior record's
/// index names the first of its group of four children (records `LIGHT_TREE_WIDTH` apart,
/// children first, unused slots zero: no power, never chosen). An emitter's trail holds the
/// slot taken at each level, two bits a level (depth ≤ 16: the binary tree's ≤ 32 halved);
/// the emitters of a cluster share its trail. `corners` are the vertices of the emissive
/// triangles (the first emitters), to find clusters that lie in one plane.
pub fn pack_light_tree(emitters: &[LightBounds], corners: &[[Vec3; 3]]) -> PackedLightTree {
    let t0 = std::time::Instant::now();
    let LightBvh { nodes, trails: _, depth: _, build_seconds: _ } = build_light_bvh(emitters);
    // Emitters below each binary node (children follow their parent in the array).
    let mut count = vec![0usize; nodes.len()];
    for i in (0..nodes.len()).rev() {
        count[i] = if nodes[i].leaf { 1 } else { count[i + 1] + count[nodes[i].index as usize] };
    }
    // Emissive area below each node (−∞ below a punctual light: never a cluster).
    let mut area = vec![0.0f64; nodes.len()];
    for i in (0..nodes.len()).rev() {
        area[i] = if nodes[i].leaf {
            corners.get(nodes[i].index as usize).map_or(f64::NEG_INFINITY, |&[p0, p1, p2]| {
                0.5 * (p1 - p0).as_dvec3().cross((p2 - p0).as_dvec3()).length()
            })
        } else {
            area[i + 1] + area[nodes[i].index as usize]
        };
    }
    let is_cluster = |i: usize| {
        let b = &nodes[i].bounds;
        let diag2 = (b.hi - b.lo).as_dvec3().length_squared();
        !nodes[i].leaf
            && count[i] <= CLUSTER_EMITTERS
            && !b.two_sided
            && b.cos_o >= CLUSTER_COS_O
            && b.phi > 0.0
            && area[i] >= CLUSTER_FILL * diag2
    };
    let leafish = |i: usize| nodes[i].leaf || is_cluster(i);
    // Every binary node's three rows (its index field filled in below).
    let mut encoded: Vec<[[u32; 4]; 3]> = vec![[[0; 4]; 3]; nodes.len()];
    encoded.par_iter_mut().zip(nodes.par_iter()).for_each(|(out, n)| {
        let b = &n.bounds;
        let axis_bits = oct_encode(b.axis);
        // Widen the cone by the quantized axis' error, plus slack for the GPU's decode.
        let err = (oct_decode(axis_bits).dot(b.axis) as f64).clamp(-1.0, 1.0).acos();
        let cos_o = if b.cos_o <= -1.0 { -1.0 } else { widen(b.cos_o as f64, err + 2e-5) };
        let sin_o = (1.0 - cos_o * cos_o).max(0.0).sqrt();
        let f = |x: f32| x.to_bits();
        let flags = if n.leaf { LIGHT_LEAF | n.index } else { 0 } | if b.two_sided { LIGHT_TWO_SIDED } else { 0 };
        out[0] = [f(b.lo.x), f(b.lo.y), f(b.lo.z), f(b.phi)];
        out[1] = [f(b.hi.x), f(b.hi.y), f(b.hi.z), axis_bits];
        out[2] = [f(cos_o), f(b.cos_e), flags, f(sin_o)];
    });
    let mut records: Vec<[[u32; 4]; 3]> = Vec::with_capacity(nodes.len());
    let mut trails = vec![0u32; emitters.len()];
    // Cluster entries (emitter | CLUSTER_LAST on the last, probability bits), in pairs.
    let mut entries: Vec<[u32; 2]> = Vec::new();
    let mut clusters = 0;
    // A leaf's record and its emitters' trails; a cluster's entries.
    let mut leaf = |records: &mut Vec<[[u32; 4]; 3]>, r: usize, k: usize, t: u32| {
        if nodes[k].leaf {
            trails[nodes[k].index as usize] = t;
            return;
        }
        let mut members = Vec::with_capacity(count[k]);
        let mut stack = vec![k];
        while let Some(i) = stack.pop() {
            if nodes[i].leaf {
                members.push(nodes[i].index);
            } else {
                stack.push(nodes[i].index as usize);
                stack.push(i + 1);
            }
        }
        // By power: each entry's probability stored, so both walks read the same number.
        let total: f64 = members.iter().map(|&m| emitters[m as usize].phi as f64).sum();
        let start = entries.len() as u32;
        let positive: Vec<u32> = members.iter().copied().filter(|&m| emitters[m as usize].phi > 0.0).collect();
        for (j, &m) in positive.iter().enumerate() {
            let p = (emitters[m as usize].phi as f64 / total) as f32;
            let last = if j + 1 == positive.len() { CLUSTER_LAST } else { 0 };
            entries.push([m | last, p.to_bits()]);
        }
        for &m in &members {
            trails[m as usize] = t;
        }
        let planar = if coplanar(&members, corners) { LIGHT_PLANAR } else { 0 };
        records[r][2][2] = LIGHT_LEAF | LIGHT_CLUSTER | planar | start;
        clusters += 1;
    };
    let mut depth = 0;
    if let Some(root) = encoded.first() {
        records.push(*root);
    }
    // (binary node, its record, trail so far, level of its children)
    let mut stack: Vec<(usize, usize, u32, u32)> = Vec::new();
    if !nodes.is_empty() {
        if leafish(0) {
            leaf(&mut records, 0, 0, 0);
        } else {
            stack.push((0, 0, 0, 0));
        }
    }
    while let Some((b, r, trail, level)) = stack.pop() {
        let mut kids = [0usize; LIGHT_TREE_WIDTH];
        let mut filled = 0;
        for c in [b + 1, nodes[b].index as usize] {
            if leafish(c) {
                kids[filled] = c;
                filled += 1;
            } else {
                kids[filled] = c + 1;
                kids[filled + 1] = nodes[c].index as usize;
                filled += 2;
            }
        }
        let group = records.len();
        records[r][2][2] |= group as u32;
        records.extend(std::iter::repeat_n([[0; 4]; 3], LIGHT_TREE_WIDTH));
        depth = depth.max(level + 1);
        for (slot, &k) in kids[..filled].iter().enumerate() {
            let t = trail | (slot as u32) << (2 * level);
            records[group + slot] = encoded[k];
            if leafish(k) {
                leaf(&mut records, group + slot, k, t);
            } else {
                stack.push((k, group + slot, t, level + 1));
            }
        }
    }
    let trail_rows = trails.len().div_ceil(4);
    // Cluster entries are counted in pairs from the trails' first row.
    let entry_base = 2 * trail_rows as u32;
    assert!(entry_base as usize + entries.len() <= LIGHT_INDEX_MASK as usize, "too many emitters for the light tree");
    for rec in &mut records {
        if rec[2][2] & (LIGHT_LEAF | LIGHT_CLUSTER) == LIGHT_LEAF | LIGHT_CLUSTER {
            rec[2][2] += entry_base;
        }
    }
    let mut rows: Vec<[u32; 4]> = Vec::with_capacity(3 * records.len() + trail_rows + entries.len().div_ceil(2));
    rows.extend(records.iter().flatten());
    let trail_offset = rows.len() as u32;
    for chunk in trails.chunks(4) {
        let mut row = [0; 4];
        row[..chunk.len()].copy_from_slice(chunk);
        rows.push(row);
    }
    for pair in entries.chunks(2) {
        let second = pair.get(1).copied().unwrap_or([0, 0]);
        rows.push([pair[0][0], pair[0][1], second[0], second[1]]);
    }
    let build_seconds = t0.elapsed().as_secs_f64();
    PackedLightTree { rows, nodes: records.len(), trail_offset, depth, clusters, build_seconds }
}

/// The children of an interior node of the light tree (a group of `LIGHT_TREE_WIDTH`
/// records), decoded for the CPU engine, which evaluates their importances at once in SIMD
/// lanes (lane k: slot k). The values are the node rows' own bits (the axis decoded as the
/// kernel decodes it), so both twins compute the same numbers.
#[derive(Clone, Copy, Debug, Default)]
#[repr(C, align(16))]
pub struct LightGroup {
    pub lo: [[f32; 4]; 3],
    pub hi: [[f32; 4]; 3],
    pub axis: [[f32; 4]; 3],
    pub phi: [f32; 4],
    pub cos_o: [f32; 4],
    pub sin_o: [f32; 4],
    pub cos_e: [f32; 4],
    /// Per slot: a leaf's emitter | LIGHT_LEAF | LIGHT_TWO_SIDED (a cluster's first entry
    /// | LIGHT_LEAF | LIGHT_CLUSTER, with LIGHT_PLANAR), or an interior child's own group
    /// index | LIGHT_TWO_SIDED.
    pub next: [u32; 4],
    /// Per slot holding a one-sided emissive triangle (a leaf, not two-sided, an emitter
    /// below the scene's light count) or a cluster of them in one plane: all bits set, and
    /// the (first) triangle's plane (a vertex and
    /// e1 × e2, as `PackedScene::light_planes` has them), so that the walk tests the four
    /// slots' planes at once (`attach_planes`).
    pub one_sided: [u32; 4],
    pub plane_p0: [[f32; 4]; 3],
    pub plane_n: [[f32; 4]; 3],
}

/// Fills the groups' per-slot triangle planes from `planes` (one per emissive triangle): a
/// leaf's own triangle, or the first entry's of a cluster in one plane (`LIGHT_PLANAR`).
/// `rows` are the `lights` buffer's rows, cluster entries counted from row `trail_base`.
pub fn attach_planes(groups: &mut [LightGroup], planes: &[[Vec3; 2]], rows: &[[u32; 4]], trail_base: u32) {
    for g in groups {
        for lane in 0..LIGHT_TREE_WIDTH {
            let next = g.next[lane];
            let index = next & LIGHT_INDEX_MASK;
            let emitter = match next & (LIGHT_LEAF | LIGHT_TWO_SIDED | LIGHT_CLUSTER | LIGHT_PLANAR) {
                LIGHT_LEAF => index as usize,
                f if f == LIGHT_LEAF | LIGHT_CLUSTER | LIGHT_PLANAR => {
                    let row = rows[(trail_base + index / 2) as usize];
                    (row[2 * (index % 2) as usize] & !CLUSTER_LAST) as usize
                }
                _ => continue,
            };
            if emitter < planes.len() {
                let [p0, n] = planes[emitter];
                g.one_sided[lane] = u32::MAX;
                for k in 0..3 {
                    g.plane_p0[k][lane] = p0[k];
                    g.plane_n[k][lane] = n[k];
                }
            }
        }
    }
}

/// The groups of the tree whose node rows are `rows` (`nodes` records, axes decoded in
/// `axes`), group g holding records 1 + 4g ..; empty when the root is a leaf.
pub fn light_groups(rows: &[[u32; 4]], nodes: usize, axes: &[Vec3]) -> Vec<LightGroup> {
    if nodes <= 1 {
        return Vec::new();
    }
    let group_of = |record: u32| (record - 1) / LIGHT_TREE_WIDTH as u32;
    (0..(nodes - 1) / LIGHT_TREE_WIDTH)
        .into_par_iter()
        .map(|g| {
            let mut p = LightGroup::default();
            for lane in 0..LIGHT_TREE_WIDTH {
                let c = 1 + LIGHT_TREE_WIDTH * g + lane;
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
                let index = r2[2] & !(LIGHT_LEAF | LIGHT_TWO_SIDED);
                p.next[lane] = if r2[2] & LIGHT_LEAF != 0 || f(r0[3]) <= 0.0 {
                    r2[2] | LIGHT_LEAF
                } else {
                    group_of(index) | (r2[2] & LIGHT_TWO_SIDED)
                };
            }
            p
        })
        .collect()
}
