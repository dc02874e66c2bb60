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
    // Child 1 (interior) or the emitter (leaf).
    index: u32,
    leaf: bool,
    two_sided: bool,
}


fn load_light_node(node: u32) -> LightNode {
    let base = params.tree_base + LIGHT_NODE_ROWS * node;
    let r0 = lights[base];
    let r1 = lights[base + 1u];
    let r2 = lights[base + 2u];
    return LightNode(
        bitcast<vec3<f32>>(r0.xyz), bitcast<f32>(r0.w), bitcast<vec3<f32>>(r1.xyz), oct_decode(r1.w),
        bitcast<f32>(r2.x), bitcast<f32>(r2.w), bitcast<f32>(r2.y), r2.z & ~(LIGHT_LEAF | LIGHT_TWO_SIDED),
        (r2.z & LIGHT_LEAF) != 0u, (r2.z & LIGHT_TWO_SIDED) != 0u
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

// A child's importances in the walk: a leaf holding a one-sided triangle is also tested
// against the triangle's own plane, so a point behind it (even inside its bounding sphere,
// where the cone test cannot tell) gets probability 0.
fn child_importance(ctx: LightContext, node: LightNode) -> vec2<f32> {
    let importance = node_importance(ctx, node);
    if (importance.x > 0.0 && node.leaf && !node.two_sided && node.index < params.light_count) {
        let tri = load_triangle(lights[node.index].x);
        if (dot(cross(tri.e1, tri.e2), ctx.point - tri.p0) <= 0.0) {
            return vec2<f32>(0.0);
        }
    }
    return importance;
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

// The children of interior node `node` (stored at index `at`) with their importances;
// ok = false at a dead end (neither child can contribute). Both walks step through this.
struct Children {
    c0: LightNode,
    c1: LightNode,
    i0: vec2<f32>,
    i1: vec2<f32>,
    total: vec2<f32>,
    ok: bool,
}

fn children(ctx: LightContext, node: LightNode, at: u32) -> Children {
    let c0 = load_light_node(at + 1u);
    let c1 = load_light_node(node.index);
    let i0 = child_importance(ctx, c0);
    let i1 = child_importance(ctx, c1);
    let total = i0 + i1;
    return Children(c0, c1, i0, i1, total, total.x > 0.0);
}

fn sample_light_tree(ctx: LightContext, u_in: f32) -> TreeChoice {
    var node = load_light_node(0u);
    if (node.leaf) {
        return TreeChoice(node.index, select(0.0, 1.0, child_importance(ctx, node).x > 0.0));
    }
    var at = 0u;
    var u = u_in;
    var pmf = 1.0;
    loop {
        let ch = children(ctx, node, at);
        if (!ch.ok) {
            return TreeChoice(0u, 0.0);
        }
        let p0 = child_share(ch.i0, ch.total);
        if (u < p0) {
            u = min(u / p0, ONE_MINUS_EPSILON);
            pmf *= p0;
            at += 1u;
            node = ch.c0;
        } else {
            u = min((u - p0) / (1.0 - p0), ONE_MINUS_EPSILON);
            pmf *= child_share(ch.i1, ch.total);
            at = node.index;
            node = ch.c1;
        }
        if (node.leaf) {
            return TreeChoice(node.index, pmf);
        }
    }
    return TreeChoice(0u, 0.0);
}

fn light_tree_pmf(ctx: LightContext, emitter: u32) -> f32 {
    var node = load_light_node(0u);
    if (node.leaf) {
        return select(0.0, 1.0, child_importance(ctx, node).x > 0.0);
    }
    var trail = lights[params.trail_base + emitter / 4u][emitter % 4u];
    var at = 0u;
    var pmf = 1.0;
    loop {
        let ch = children(ctx, node, at);
        if (!ch.ok) {
            return 0.0;
        }
        if ((trail & 1u) == 0u) {
            pmf *= child_share(ch.i0, ch.total);
            at += 1u;
            node = ch.c0;
        } else {
            pmf *= child_share(ch.i1, ch.total);
            at = node.index;
            node = ch.c1;
        }
        trail = trail >> 1u;
        if (node.leaf) {
            return pmf;
        }
    }
    return 0.0;
}
