//! Twin of `shaders/light_tree.wgsl`: walking the light BVH (`accel/light_bvh.rs`) from the
//! root with one random number, and the exact probability of choosing an emitter.

use crate::packed::{
    CLUSTER_LAST, LIGHT_CLUSTER, LIGHT_INDEX_MASK, LIGHT_LEAF, LIGHT_NODE_ROWS, LIGHT_PLANAR, LIGHT_TWO_SIDED,
    LightGroup, PackedScene,
};
use crate::params::Params;
use glam::{BVec4A, Vec2, Vec3, Vec4};

/// What light selection knows of the shading point. A BSDF hit on an emitter recomputes the
/// selection probability with the context of the vertex the ray left, bit for bit the one
/// next-event estimation used there.
#[derive(Clone, Copy, Debug, PartialEq, Default)]
pub struct LightContext {
    pub point: Vec3,
    /// Shading normal facing the outgoing direction.
    pub normal: Vec3,
    /// The BSDF only reflects: emitters below the tangent plane cannot contribute.
    pub reflect_only: bool,
}

#[derive(Clone, Copy, Debug)]
pub struct LightNode {
    pub lo: Vec3,
    pub phi: f32,
    pub hi: Vec3,
    pub axis: Vec3,
    pub cos_o: f32,
    pub sin_o: f32,
    pub cos_e: f32,
    /// Child 1 (interior), the emitter (leaf) or a cluster's first entry.
    pub index: u32,
    pub leaf: bool,
    pub two_sided: bool,
    /// A leaf of several emitters (`index`: its first entry), in one plane when `planar`.
    pub cluster: bool,
    pub planar: bool,
}

use super::common::ONE_MINUS_EPSILON;

pub fn load_light_node(scene: &PackedScene, params: &Params, node: u32) -> LightNode {
    let base = (params.tree_base + LIGHT_NODE_ROWS * node) as usize;
    let [r0, r1, r2] = [scene.light_rows[base], scene.light_rows[base + 1], scene.light_rows[base + 2]];
    let f = f32::from_bits;
    LightNode {
        lo: Vec3::new(f(r0[0]), f(r0[1]), f(r0[2])),
        phi: f(r0[3]),
        hi: Vec3::new(f(r1[0]), f(r1[1]), f(r1[2])),
        // oct_decode(r1[3]), decoded once when packed.
        axis: scene.light_axes[node as usize],
        cos_o: f(r2[0]),
        sin_o: f(r2[3]),
        cos_e: f(r2[1]),
        index: r2[2] & LIGHT_INDEX_MASK,
        leaf: r2[2] & LIGHT_LEAF != 0,
        two_sided: r2[2] & LIGHT_TWO_SIDED != 0,
        cluster: r2[2] & LIGHT_CLUSTER != 0,
        planar: r2[2] & LIGHT_PLANAR != 0,
    }
}

fn safe_sqrt(x: f32) -> f32 {
    x.max(0.0).sqrt()
}

/// cos(max(0, θa − θb)) from the sines and cosines.
fn cos_sub_clamped(sin_a: f32, cos_a: f32, sin_b: f32, cos_b: f32) -> f32 {
    if cos_a > cos_b { 1.0 } else { cos_a * cos_b + sin_a * sin_b }
}

/// sin(max(0, θa − θb)).
fn sin_sub_clamped(sin_a: f32, cos_a: f32, sin_b: f32, cos_b: f32) -> f32 {
    if cos_a > cos_b { 0.0 } else { sin_a * cos_b - cos_a * sin_b }
}

/// Two estimates, up to a constant, of the irradiance the node's emitters give the shading
/// point: phi · cos θ' / d² times the bound of the receiver's cosine (pbrt-v4's light-bounds
/// importance), θ' the smallest angle between the emitters' cone and the direction to the
/// point, with d the distance to the box's centre (x: the far estimate, clamped below by the
/// bounding sphere's radius) and to its nearest point (y: the near one, clamped by half that
/// radius). The walk mixes the two (as Cycles mixes its minimum and maximum importance): the
/// centre alone starves a bright emitter at the near edge of a large box. Both are zero when
/// no emitter faces the point or (reflection-only BSDFs) the node lies below the tangent plane.
pub fn node_importance(ctx: &LightContext, node: &LightNode) -> Vec2 {
    if node.phi <= 0.0 {
        return Vec2::ZERO;
    }
    let p = ctx.point;
    let pc = 0.5 * (node.lo + node.hi);
    let half = 0.5 * (node.hi - node.lo);
    if ctx.reflect_only && (pc - p).dot(ctx.normal) + half.dot(ctx.normal.abs()) <= 0.0 {
        return Vec2::ZERO;
    }
    let r2 = half.dot(half);
    let to_p = p - pc;
    let dist2 = to_p.dot(to_p);
    let outside = p - p.clamp(node.lo, node.hi);
    let d2 = Vec2::new(dist2.max(r2), outside.dot(outside).max(0.25 * r2)).max(Vec2::splat(1e-20));
    if dist2 <= r2 {
        // Inside the bounding sphere every direction is possible.
        return node.phi / d2;
    }
    let inv_d = 1.0 / dist2.sqrt();
    let wi = to_p * inv_d;
    let mut cos_w = node.axis.dot(wi);
    if node.two_sided {
        cos_w = cos_w.abs();
    }
    let sin_w = safe_sqrt(1.0 - cos_w * cos_w);
    let sin2_b = r2 * (inv_d * inv_d);
    let cos_b = safe_sqrt(1.0 - sin2_b);
    let sin_b = sin2_b.sqrt();
    let cos_x = cos_sub_clamped(sin_w, cos_w, node.sin_o, node.cos_o);
    let sin_x = sin_sub_clamped(sin_w, cos_w, node.sin_o, node.cos_o);
    let cos_p = cos_sub_clamped(sin_x, cos_x, sin_b, cos_b);
    if cos_p <= node.cos_e {
        return Vec2::ZERO;
    }
    let cos_i = wi.dot(ctx.normal).abs();
    let sin_i = safe_sqrt(1.0 - cos_i * cos_i);
    let cos_pi = cos_sub_clamped(sin_i, cos_i, sin_b, cos_b);
    (node.phi * cos_p * cos_pi / d2).max(Vec2::ZERO)
}

/// A child's importances in the walk: a leaf holding a one-sided triangle (or a cluster of
/// them in one plane) is also tested against the triangle's own plane, so that a point
/// behind it (even inside its bounding sphere, where the cone test cannot tell) gets
/// probability 0.
pub fn child_importance(scene: &PackedScene, params: &Params, ctx: &LightContext, node: &LightNode) -> Vec2 {
    let importance = node_importance(ctx, node);
    if !(importance.x > 0.0 && plane_tested(node)) {
        return importance;
    }
    // A cluster's plane is its first entry's (read only where the test applies).
    let emitter = if node.cluster { cluster_entry(scene, params, node.index).0 } else { node.index };
    if emitter < params.light_count {
        // The emitter triangle's plane (p0, e1 × e2), as packed for the group walk.
        let [p0, n] = scene.light_planes[emitter as usize];
        if n.dot(ctx.point - p0) <= 0.0 {
            return Vec2::ZERO;
        }
    }
    importance
}

/// Is a point behind the node's plane given probability 0? A leaf of one one-sided triangle, or
/// a cluster of them in one plane (tested with its first entry's).
#[inline(always)]
pub fn plane_tested(node: &LightNode) -> bool {
    node.leaf && !node.two_sided && (!node.cluster || node.planar)
}

/// Entry `k` of the clusters' list: (emitter, its probability in the cluster, whether it is
/// the cluster's last), two entries a row from the trails' first row.
#[inline(always)]
pub fn cluster_entry(scene: &PackedScene, params: &Params, k: u32) -> (u32, f32, bool) {
    let row = scene.light_rows[(params.trail_base + k / 2) as usize];
    let word = row[2 * (k % 2) as usize];
    (word & !CLUSTER_LAST, f32::from_bits(row[2 * (k % 2) as usize + 1]), word & CLUSTER_LAST != 0)
}

/// The emitter `u` chooses in the cluster whose entries start at `first` (by power: each
/// entry's stored probability; the last takes the rest up to 1), and that probability.
pub fn choose_in_cluster(scene: &PackedScene, params: &Params, first: u32, u: f32) -> (u32, f32) {
    let mut below = 0.0f32;
    let mut k = first;
    loop {
        let (emitter, p, last) = cluster_entry(scene, params, k);
        if last || u < below + p {
            return (emitter, p);
        }
        below += p;
        k += 1;
    }
}

/// The probability that `choose_in_cluster` chooses `emitter` in the cluster from `first`.
pub fn cluster_pmf(scene: &PackedScene, params: &Params, first: u32, emitter: u32) -> f32 {
    let mut k = first;
    loop {
        let (e, p, last) = cluster_entry(scene, params, k);
        if e == emitter {
            return p;
        }
        if last {
            return 0.0;
        }
        k += 1;
    }
}

/// A leaf's emitter and the probability of choosing it there: its own, or one of its
/// cluster's chosen with `u`.
#[inline(always)]
pub fn leaf_emitter(scene: &PackedScene, params: &Params, next: u32, u: f32) -> (u32, f32) {
    if next & LIGHT_CLUSTER != 0 {
        choose_in_cluster(scene, params, next & LIGHT_INDEX_MASK, u)
    } else {
        (next & LIGHT_INDEX_MASK, 1.0)
    }
}

/// The probability of choosing `emitter` at the leaf `next` (1 for a leaf of one emitter).
#[inline(always)]
pub fn leaf_pmf(scene: &PackedScene, params: &Params, next: u32, emitter: u32) -> f32 {
    if next & LIGHT_CLUSTER != 0 { cluster_pmf(scene, params, next & LIGHT_INDEX_MASK, emitter) } else { 1.0 }
}

/// The probability of taking the child with importances `i` when its sibling's sum with it
/// to `total`: the mean of the far and the near estimates' shares (0 when `total` is 0).
pub fn child_share(i: Vec2, total: Vec2) -> f32 {
    0.5 * (i.x / total.x + i.y / total.y)
}

#[inline(always)]
fn dot3(a: [Vec4; 3], b: [Vec4; 3]) -> Vec4 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

/// SSE's max: `a` where a > b, else `b` (so `b` on NaN and on equal zeros), on every platform
/// (the walk over paths in lanes, `cpu::lanes::light_tree`, computes the same).
#[inline(always)]
fn max_ps(a: Vec4, b: Vec4) -> Vec4 {
    Vec4::select(a.cmpgt(b), a, b)
}

/// SSE's min: `a` where a < b, else `b`.
#[inline(always)]
fn min_ps(a: Vec4, b: Vec4) -> Vec4 {
    Vec4::select(a.cmplt(b), a, b)
}

/// `node_importance` of a group's four children at once, lane by lane the same operations in
/// the same order (so the same bits: SSE's min, max, sqrt and division round as the scalar
/// ones do, and take the same operand on NaN): far estimates in `.0`, near ones in `.1`.
#[inline(always)]
fn group_importance(ctx: &LightContext, g: &LightGroup) -> (Vec4, Vec4) {
    let zero = Vec4::ZERO;
    let phi = Vec4::from(g.phi);
    let p = [Vec4::splat(ctx.point.x), Vec4::splat(ctx.point.y), Vec4::splat(ctx.point.z)];
    let n = [Vec4::splat(ctx.normal.x), Vec4::splat(ctx.normal.y), Vec4::splat(ctx.normal.z)];
    let lo = g.lo.map(Vec4::from);
    let hi = g.hi.map(Vec4::from);
    let pc = [0, 1, 2].map(|k| Vec4::splat(0.5) * (lo[k] + hi[k]));
    let half = [0, 1, 2].map(|k| Vec4::splat(0.5) * (hi[k] - lo[k]));
    let mut dead = phi.cmple(zero);
    if ctx.reflect_only {
        let below = dot3([0, 1, 2].map(|k| pc[k] - p[k]), n) + dot3(half, n.map(Vec4::abs));
        dead |= below.cmple(zero);
    }
    let r2 = dot3(half, half);
    let to_p = [0, 1, 2].map(|k| p[k] - pc[k]);
    let dist2 = dot3(to_p, to_p);
    let outside = [0, 1, 2].map(|k| p[k] - min_ps(max_ps(p[k], lo[k]), hi[k]));
    let tiny = Vec4::splat(1e-20);
    let d2_far = max_ps(max_ps(dist2, r2), tiny);
    let d2_near = max_ps(max_ps(dot3(outside, outside), Vec4::splat(0.25) * r2), tiny);
    let inside = dist2.cmple(r2);
    let inv_d = Vec4::ONE / dist2.sqrt();
    let wi = to_p.map(|c| c * inv_d);
    let mut cos_w = dot3(g.axis.map(Vec4::from), wi);
    let two_sided = g.next.map(|x| x & LIGHT_TWO_SIDED != 0);
    cos_w = Vec4::select(BVec4A::from_array(two_sided), cos_w.abs(), cos_w);
    let safe_sqrt = |x: Vec4| max_ps(x, zero).sqrt();
    let cos_sub = |sa: Vec4, ca: Vec4, sb: Vec4, cb: Vec4| Vec4::select(ca.cmpgt(cb), Vec4::ONE, ca * cb + sa * sb);
    let sin_sub = |sa: Vec4, ca: Vec4, sb: Vec4, cb: Vec4| Vec4::select(ca.cmpgt(cb), zero, sa * cb - ca * sb);
    let sin_w = safe_sqrt(Vec4::ONE - cos_w * cos_w);
    let sin2_b = r2 * (inv_d * inv_d);
    let cos_b = safe_sqrt(Vec4::ONE - sin2_b);
    let sin_b = sin2_b.sqrt();
    let (sin_o, cos_o) = (Vec4::from(g.sin_o), Vec4::from(g.cos_o));
    let cos_x = cos_sub(sin_w, cos_w, sin_o, cos_o);
    let sin_x = sin_sub(sin_w, cos_w, sin_o, cos_o);
    let cos_p = cos_sub(sin_x, cos_x, sin_b, cos_b);
    let culled = cos_p.cmple(Vec4::from(g.cos_e));
    let cos_i = dot3(wi, n).abs();
    let sin_i = safe_sqrt(Vec4::ONE - cos_i * cos_i);
    let cos_pi = cos_sub(sin_i, cos_i, sin_b, cos_b);
    // One division per estimate: inside the sphere phi / d², culled 0 / d² = 0, else the
    // lit power over d² — the scalar's values exactly (phi > 0 where not dead).
    let lit = Vec4::select(inside, phi, Vec4::select(culled, zero, phi * cos_p * cos_pi));
    let (far, near) = (max_ps(lit / d2_far, zero), max_ps(lit / d2_near, zero));
    (Vec4::select(dead, zero, far), Vec4::select(dead, zero, near))
}

/// The shares of a group's children (`child_importance` of each: the group's lanes, then the
/// plane test of one-sided leaf triangles; `child_share` against their sum), or None at a
/// dead end (no child can contribute). Both walks step through this.
#[inline(always)]
pub(crate) fn group_shares(
    scene: &PackedScene,
    params: &Params,
    ctx: &LightContext,
    g: &LightGroup,
) -> Option<[f32; 4]> {
    let _ = (scene, params);
    let (far, near) = group_importance(ctx, g);
    // A one-sided leaf triangle whose plane the point is behind (`child_importance`'s test,
    // the four slots at once: n · (p − p0) lane by lane in the scalar order).
    let p = [Vec4::splat(ctx.point.x), Vec4::splat(ctx.point.y), Vec4::splat(ctx.point.z)];
    let to_p = [0, 1, 2].map(|k| p[k] - Vec4::from(g.plane_p0[k]));
    let side = dot3(g.plane_n.map(Vec4::from), to_p);
    let one_sided = BVec4A::from_array(g.one_sided.map(|m| m != 0));
    let behind = far.cmpgt(Vec4::ZERO) & one_sided & side.cmple(Vec4::ZERO);
    let (far, near) = (Vec4::select(behind, Vec4::ZERO, far), Vec4::select(behind, Vec4::ZERO, near));
    // In slot order, as the kernel adds them.
    let total = Vec2::new(((far.x + far.y) + far.z) + far.w, ((near.x + near.y) + near.z) + near.w);
    if total.x.is_nan() || total.x <= 0.0 {
        return None;
    }
    // `child_share` of the four slots: 0.5 (far / total far + near / total near).
    Some((Vec4::splat(0.5) * (far / Vec4::splat(total.x) + near / Vec4::splat(total.y))).to_array())
}

/// The slot `u` chooses among children with `shares` (of which at least one is positive),
/// and `u` rescaled into its interval: slots of no share are passed over, and the last one
/// with a share takes the interval's rest up to 1, so that rounding never leaves `u` unchosen.
/// With two children this is the binary walk's choice exactly.
#[inline(always)]
pub fn choose_child(shares: [f32; 4], u: f32) -> (usize, f32) {
    let mut last = 0;
    for (k, &s) in shares.iter().enumerate() {
        if s > 0.0 {
            last = k;
        }
    }
    let mut below = 0.0f32;
    for (k, &s) in shares.iter().enumerate() {
        if s.is_nan() || s <= 0.0 {
            continue;
        }
        if k == last {
            return (k, ((u - below) / (1.0 - below)).min(ONE_MINUS_EPSILON));
        }
        if u < below + s {
            return (k, ((u - below) / s).min(ONE_MINUS_EPSILON));
        }
        below += s;
    }
    (last, u)
}

/// Chooses an emitter: at each node a child by its share, `u` rescaled into the chosen
/// interval. Returns (emitter, probability); probability 0: nothing to choose (every emitter
/// of the subtree reached provably contributes nothing).
pub fn sample_light_tree(scene: &PackedScene, params: &Params, ctx: &LightContext, u: f32) -> (u32, f32) {
    let root = load_light_node(scene, params, 0);
    if root.leaf {
        if child_importance(scene, params, ctx, &root).x > 0.0 {
            return leaf_emitter(scene, params, root_word(&root), u);
        }
        return (root.index, 0.0);
    }
    let mut group = &scene.light_groups[0];
    let mut u = u;
    let mut pmf = 1.0f32;
    loop {
        let Some(shares) = group_shares(scene, params, ctx, group) else { return (0, 0.0) };
        let (slot, rescaled) = choose_child(shares, u);
        u = rescaled;
        pmf *= shares[slot];
        let next = group.next[slot];
        if next & LIGHT_LEAF != 0 {
            let (emitter, p) = leaf_emitter(scene, params, next, u);
            return (emitter, pmf * p);
        }
        group = &scene.light_groups[(next & !LIGHT_TWO_SIDED) as usize];
    }
}

/// The root's index word as a group's `next` holds a leaf's.
pub fn root_word(root: &LightNode) -> u32 {
    root.index | if root.cluster { LIGHT_CLUSTER } else { 0 }
}

/// The probability that `sample_light_tree` chooses `emitter` from `ctx`: the walk down its
/// trail (two bits a level: the slot taken), multiplying the same shares in the same order.
pub fn light_tree_pmf(scene: &PackedScene, params: &Params, ctx: &LightContext, emitter: u32) -> f32 {
    let root = load_light_node(scene, params, 0);
    if root.leaf {
        let lit = child_importance(scene, params, ctx, &root).x > 0.0;
        return if lit { leaf_pmf(scene, params, root_word(&root), emitter) } else { 0.0 };
    }
    let row = scene.light_rows[(params.trail_base + emitter / 4) as usize];
    let mut trail = row[(emitter % 4) as usize];
    let mut group = &scene.light_groups[0];
    let mut pmf = 1.0f32;
    loop {
        let Some(shares) = group_shares(scene, params, ctx, group) else { return 0.0 };
        let slot = (trail & 3) as usize;
        pmf *= shares[slot];
        let next = group.next[slot];
        trail >>= 2;
        if next & LIGHT_LEAF != 0 {
            return pmf * leaf_pmf(scene, params, next, emitter);
        }
        group = &scene.light_groups[(next & !LIGHT_TWO_SIDED) as usize];
    }
}
