// The light BVH (src/accel/light_bvh.rs), walked from the root with one random number: at
// each node a child is chosen in proportion to its importance to the shading point, and the
// number is rescaled into the chosen share. `light_tree_pmf` repeats the walk along an
// emitter's trail for the exact probability MIS needs. Twin: src/cpu/light_tree.rs.
#include "bindings.wgsl"
#include "material.wgsl"

// What light selection knows of the shading point; a BSDF hit on an emitter uses the
// context of the vertex the ray left, exactly as next-event estimation saw it.
struct LightContext {
    point: vec3<f32>,
    // Shading normal facing the outgoing direction.
    normal: vec3<f32>,
    // The BSDF only reflects: emitters below the tangent plane cannot contribute.
    reflect_only: bool,
}

struct LightNode {
    lo: vec3<f32>,
    phi: f32,
    hi: vec3<f32>,
    axis: vec3<f32>,
    cos_o: f32,
    sin_o: f32,
    cos_e: f32,
    // The first child (interior), the emitter (leaf) or a cluster's first entry.
    index: u32,
    leaf: bool,
    two_sided: bool,
    // A leaf of several emitters, in one plane when `planar`.
    cluster: bool,
    planar: bool,
}


fn load_light_node(node: u32) -> LightNode {
    let base = params.tree_base + LIGHT_NODE_ROWS * node;
    let r0 = lights[base];
    let r1 = lights[base + 1u];
    let r2 = lights[base + 2u];
    return LightNode(
        bitcast<vec3<f32>>(r0.xyz), bitcast<f32>(r0.w), bitcast<vec3<f32>>(r1.xyz), oct_decode(r1.w),
        bitcast<f32>(r2.x), bitcast<f32>(r2.w), bitcast<f32>(r2.y), r2.z & LIGHT_INDEX_MASK,
        (r2.z & LIGHT_LEAF) != 0u, (r2.z & LIGHT_TWO_SIDED) != 0u, (r2.z & LIGHT_CLUSTER) != 0u,
        (r2.z & LIGHT_PLANAR) != 0u
    );
}

fn safe_sqrt(x: f32) -> f32 {
    return sqrt(max(x, 0.0));
}

// cos(max(0, θa − θb)) and sin(max(0, θa − θb)) from sines and cosines.
fn cos_sub_clamped(sin_a: f32, cos_a: f32, sin_b: f32, cos_b: f32) -> f32 {
    return select(cos_a * cos_b + sin_a * sin_b, 1.0, cos_a > cos_b);
}

fn sin_sub_clamped(sin_a: f32, cos_a: f32, sin_b: f32, cos_b: f32) -> f32 {
    return select(sin_a * cos_b - cos_a * sin_b, 0.0, cos_a > cos_b);
}

// Two estimates of the irradiance the node's emitters give the point: phi · cos θ' / d² times
// the receiver-cosine bound, d to the box's centre (x, clamped by the bounding sphere's
// radius) and to its nearest point (y, clamped by half that radius); the walk mixes their
// shares. Zero when no emitter faces the point or (reflection-only BSDFs) the node lies
// below the tangent plane.
fn node_importance(ctx: LightContext, node: LightNode) -> vec2<f32> {
    if (node.phi <= 0.0) {
        return vec2<f32>(0.0);
    }
    let p = ctx.point;
    let pc = 0.5 * (node.lo + node.hi);
    let half = 0.5 * (node.hi - node.lo);
    if (ctx.reflect_only && dot(pc - p, ctx.normal) + dot(half, abs(ctx.normal)) <= 0.0) {
        return vec2<f32>(0.0);
    }
    let r2 = dot(half, half);
    let to_p = p - pc;
    let dist2 = dot(to_p, to_p);
    let outside = p - clamp(p, node.lo, node.hi);
    let d2 = max(vec2<f32>(max(dist2, r2), max(dot(outside, outside), 0.25 * r2)), vec2<f32>(1e-20));
    if (dist2 <= r2) {
        return node.phi / d2;
    }
    let inv_d = 1.0 / sqrt(dist2);
    let wi = to_p * inv_d;
    var cos_w = dot(node.axis, wi);
    if (node.two_sided) {
        cos_w = abs(cos_w);
    }
    let sin_w = safe_sqrt(1.0 - cos_w * cos_w);
    let sin2_b = r2 * (inv_d * inv_d);
    let cos_b = safe_sqrt(1.0 - sin2_b);
    let sin_b = sqrt(sin2_b);
    let cos_x = cos_sub_clamped(sin_w, cos_w, node.sin_o, node.cos_o);
    let sin_x = sin_sub_clamped(sin_w, cos_w, node.sin_o, node.cos_o);
    let cos_p = cos_sub_clamped(sin_x, cos_x, sin_b, cos_b);
    if (cos_p <= node.cos_e) {
        return vec2<f32>(0.0);
    }
    let cos_i = abs(dot(wi, ctx.normal));
    let sin_i = safe_sqrt(1.0 - cos_i * cos_i);
    let cos_pi = cos_sub_clamped(sin_i, cos_i, sin_b, cos_b);
    return max(node.phi * cos_p * cos_pi / d2, vec2<f32>(0.0));
}

// Is a point behind the node's plane given probability 0? A leaf of one one-sided triangle, or
// a cluster of them in one plane (tested with its first entry's).
fn plane_tested(node: LightNode) -> bool {
    return node.leaf && !node.two_sided && (!node.cluster || node.planar);
}

// A child's importances in the walk: a leaf holding a one-sided triangle (or a cluster of
// them in one plane) is also tested against the triangle's own plane, so a point behind it
// (even inside its bounding sphere, where the cone test cannot tell) gets probability 0.
fn child_importance(ctx: LightContext, node: LightNode) -> vec2<f32> {
    let importance = node_importance(ctx, node);
    if (!(importance.x > 0.0 && plane_tested(node))) {
        return importance;
    }
    // A cluster's plane is its first entry's (read only where the test applies).
    var emitter = node.index;
    if (node.cluster) {
        emitter = cluster_entry(node.index).emitter;
    }
    if (emitter < params.light_count) {
        let tri = load_triangle(lights[emitter].x);
        if (dot(cross(tri.e1, tri.e2), ctx.point - tri.p0) <= 0.0) {
            return vec2<f32>(0.0);
        }
    }
    return importance;
}

struct ClusterEntry {
    emitter: u32,
    // Its probability in the cluster.
    p: f32,
    last: bool,
}

// Entry k of the clusters' list, two a row from the trails' first row.
fn cluster_entry(k: u32) -> ClusterEntry {
    let row = lights[params.trail_base + k / 2u];
    let pair = select(row.xy, row.zw, (k & 1u) != 0u);
    return ClusterEntry(pair.x & ~CLUSTER_LAST, bitcast<f32>(pair.y), (pair.x & CLUSTER_LAST) != 0u);
}

// The emitter `u` chooses in the cluster from entry `first` (by power: the entries' stored
// probabilities; the last takes the rest up to 1), and that probability.
fn choose_in_cluster(first: u32, u: f32) -> TreeChoice {
    var below = 0.0;
    var k = first;
    loop {
        let e = cluster_entry(k);
        if (e.last || u < below + e.p) {
            return TreeChoice(e.emitter, e.p);
        }
        below += e.p;
        k++;
    }
    return TreeChoice(0u, 0.0);
}

// The probability that `choose_in_cluster` chooses `emitter` in the cluster from `first`.
fn cluster_pmf(first: u32, emitter: u32) -> f32 {
    var k = first;
    loop {
        let e = cluster_entry(k);
        if (e.emitter == emitter) {
            return e.p;
        }
        if (e.last) {
            return 0.0;
        }
        k++;
    }
    return 0.0;
}

// A leaf's emitter and its probability there: its own, or one of its cluster's chosen by u.
fn leaf_emitter(index: u32, cluster: bool, u: f32) -> TreeChoice {
    if (cluster) {
        return choose_in_cluster(index, u);
    }
    return TreeChoice(index, 1.0);
}

fn leaf_pmf(index: u32, cluster: bool, emitter: u32) -> f32 {
    if (cluster) {
        return cluster_pmf(index, emitter);
    }
    return 1.0;
}

// The mean of the far and the near estimates' shares.
fn child_share(i: vec2<f32>, total: vec2<f32>) -> f32 {
    return 0.5 * (i.x / total.x + i.y / total.y);
}

struct TreeChoice {
    emitter: u32,
    // 0: nothing to choose.
    pmf: f32,
}

// The children of an interior node: a group of LIGHT_TREE_WIDTH records from `first`, with
// their shares (child_importance of each against their sum, added in slot order); ok = false
// at a dead end (no child can contribute). Both walks step through this.
struct Children {
    share: array<f32, 4>,
    index: array<u32, 4>,
    leaf: array<bool, 4>,
    cluster: array<bool, 4>,
    ok: bool,
}

fn children(ctx: LightContext, first: u32) -> Children {
    var ch: Children;
    var far = array<f32, 4>();
    var near = array<f32, 4>();
    var total = vec2<f32>(0.0);
    for (var k = 0u; k < LIGHT_TREE_WIDTH; k++) {
        let c = load_light_node(first + k);
        let i = child_importance(ctx, c);
        far[k] = i.x;
        near[k] = i.y;
        ch.index[k] = c.index;
        ch.leaf[k] = c.leaf;
        ch.cluster[k] = c.cluster;
        total += i;
    }
    for (var k = 0u; k < LIGHT_TREE_WIDTH; k++) {
        ch.share[k] = child_share(vec2<f32>(far[k], near[k]), total);
    }
    ch.ok = total.x > 0.0;
    return ch;
}

struct Choice {
    slot: u32,
    u: f32,
}

// The slot `u` chooses by the shares (at least one positive), and `u` rescaled into its
// interval: slots of no share are passed over, and the last with a share takes the rest up
// to 1, so rounding never leaves `u` unchosen. With two children: the binary walk's choice.
fn choose_child(share: array<f32, 4>, u: f32) -> Choice {
    var last = 0u;
    for (var k = 0u; k < LIGHT_TREE_WIDTH; k++) {
        if (share[k] > 0.0) {
            last = k;
        }
    }
    var below = 0.0;
    for (var k = 0u; k < LIGHT_TREE_WIDTH; k++) {
        let s = share[k];
        if (!(s > 0.0)) {
            continue;
        }
        if (k == last) {
            return Choice(k, min((u - below) / (1.0 - below), ONE_MINUS_EPSILON));
        }
        if (u < below + s) {
            return Choice(k, min((u - below) / s, ONE_MINUS_EPSILON));
        }
        below += s;
    }
    return Choice(last, u);
}

fn sample_light_tree(ctx: LightContext, u_in: f32) -> TreeChoice {
    let root = load_light_node(0u);
    if (root.leaf) {
        if (child_importance(ctx, root).x > 0.0) {
            return leaf_emitter(root.index, root.cluster, u_in);
        }
        return TreeChoice(root.index, 0.0);
    }
    var first = root.index;
    var u = u_in;
    var pmf = 1.0;
    loop {
        let ch = children(ctx, first);
        if (!ch.ok) {
            return TreeChoice(0u, 0.0);
        }
        let choice = choose_child(ch.share, u);
        u = choice.u;
        pmf *= ch.share[choice.slot];
        if (ch.leaf[choice.slot]) {
            let chosen = leaf_emitter(ch.index[choice.slot], ch.cluster[choice.slot], u);
            return TreeChoice(chosen.emitter, pmf * chosen.pmf);
        }
        first = ch.index[choice.slot];
    }
    return TreeChoice(0u, 0.0);
}

// The walk down an emitter's trail: two bits a level, the slot taken.
fn light_tree_pmf(ctx: LightContext, emitter: u32) -> f32 {
    let root = load_light_node(0u);
    if (root.leaf) {
        return select(0.0, leaf_pmf(root.index, root.cluster, emitter), child_importance(ctx, root).x > 0.0);
    }
    var trail = lights[params.trail_base + emitter / 4u][emitter % 4u];
    var first = root.index;
    var pmf = 1.0;
    loop {
        let ch = children(ctx, first);
        if (!ch.ok) {
            return 0.0;
        }
        let slot = trail & 3u;
        pmf *= ch.share[slot];
        if (ch.leaf[slot]) {
            return pmf * leaf_pmf(ch.index[slot], ch.cluster[slot], emitter);
        }
        first = ch.index[slot];
        trail = trail >> 2u;
    }
    return 0.0;
}
