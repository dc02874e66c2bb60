// Ray–scene intersection: Möller–Trumbore triangles in each mesh's compressed 8-wide BVH
// (Ylitie, Karras & Laine 2017), under a BVH2 over instances when there are any; triangles
// with MASK or BLEND alpha are skipped where their alpha says the surface is not there.
// Twin: src/cpu/bvh.rs.
#include "bindings.wgsl"
#include "material.wgsl"
#include "instance.wgsl"

const NO_HIT: u32 = 0xffffffffu;
// A mesh walk pushes at most one group of up to eight children per tree level, and a renderer
// refuses mesh BVHs deeper than 32 levels (accel::MAX_DEPTH). The top level is a BVH2.
const STACK_SIZE: u32 = 32u;
const TLAS_STACK_SIZE: u32 = 64u;

// Traversal stacks at module scope: WGSL zero-initialises a function's local array on every
// call (a 256-byte memset per trace on lavapipe); private variables are initialised once per
// invocation. Measured: −17 % CPU time on the Veach scene (BENCHMARKS.md).
var<private> blas_stack: array<vec2<u32>, STACK_SIZE>;
var<private> tlas_stack: array<u32, TLAS_STACK_SIZE>;

struct Hit {
    t: f32,
    tri: u32,
    // Barycentrics of vertices 1 and 2.
    u: f32,
    v: f32,
    // Instance record of the hit (with instancing).
    instance: u32,
}

// Distance along the ray (t, u, v), or t = INF on a miss.
fn intersect_triangle(ray: Ray, tri: Triangle) -> vec3<f32> {
    let pvec = cross(ray.dir, tri.e2);
    let det = dot(tri.e1, pvec);
    if (det == 0.0) {
        return vec3<f32>(INF, 0.0, 0.0);
    }
    let inv_det = 1.0 / det;
    let tvec = ray.origin - tri.p0;
    let u = dot(tvec, pvec) * inv_det;
    if (u < 0.0 || u > 1.0) {
        return vec3<f32>(INF, 0.0, 0.0);
    }
    let qvec = cross(tvec, tri.e1);
    let v = dot(ray.dir, qvec) * inv_det;
    if (v < 0.0 || u + v > 1.0) {
        return vec3<f32>(INF, 0.0, 0.0);
    }
    let t = dot(tri.e2, qvec) * inv_det;
    return vec3<f32>(select(INF, t, t > 0.0), u, v);
}

// Entry distance of the ray into a top-level node's box within [0, t_max], or INF.
fn intersect_node(node: BvhNode, origin: vec3<f32>, inv_dir: vec3<f32>, t_max: f32) -> f32 {
    let t0 = (node.min - origin) * inv_dir;
    let t1 = (node.max - origin) * inv_dir;
    let near = min(t0, t1);
    let far = max(t0, t1);
    let t_enter = max(max(near.x, near.y), max(near.z, 0.0));
    let t_exit = min(min(far.x, far.y), min(far.z, t_max));
    return select(INF, t_enter, t_enter <= t_exit);
}

// Hit mask of a compressed node's children (Ylitie et al. 2017): a hit inner child sets bit
// 24 + its slot, permuted by the ray's octant so that higher bits are nearer children; a hit
// leaf sets one bit per triangle at its offset from primitive_base (bits 0–23). The quantised
// boxes are decoded here: on lavapipe the bytes a ray loads cost far more than this ALU.
fn intersect_cw_node(node: CwNode, origin: vec3<f32>, inv_dir: vec3<f32>, t_max: f32, oct_inv4: u32) -> u32 {
    let e = (vec3<u32>(node.w0.w) >> vec3<u32>(0u, 8u, 16u)) & vec3<u32>(0xffu);
    let scale = bitcast<vec3<f32>>(e << vec3<u32>(23u)) * inv_dir;
    let shift = (bitcast<vec3<f32>>(node.w0.xyz) - origin) * inv_dir;
    var mask = 0u;
    for (var i = 0u; i < 8u; i++) {
        let half = i >> 2u;
        let bits = 8u * (i & 3u);
        let child_meta = (node.w1[2u + half] >> bits) & 0xffu;
        if (child_meta == 0u) {
            continue;
        }
        let lo = vec3<f32>(
            (vec3<u32>(node.qx[half], node.qy[half], node.qz[half]) >> vec3<u32>(bits)) & vec3<u32>(0xffu)
        );
        let hi = vec3<f32>(
            (vec3<u32>(node.qx[2u + half], node.qy[2u + half], node.qz[2u + half]) >> vec3<u32>(bits))
                & vec3<u32>(0xffu)
        );
        let t0 = lo * scale + shift;
        let t1 = hi * scale + shift;
        let near = min(t0, t1);
        let far = max(t0, t1);
        let t_enter = max(max(near.x, near.y), max(near.z, 0.0));
        let t_exit = min(min(far.x, far.y), min(far.z, t_max));
        if (t_enter <= t_exit) {
            let is_inner = (child_meta & (child_meta << 1u) & 0x10u) != 0u;
            let bit_index = (child_meta ^ select(0u, oct_inv4 & 0xffu, is_inner)) & 0x1fu;
            mask |= ((child_meta >> 5u) & 7u) << bit_index;
        }
    }
    return mask;
}

// 1 / dir, with components nearer zero than 2⁻⁸⁰ replaced by ±2⁻⁸⁰, so that a quantised box
// coordinate of 0 never meets an infinite reciprocal (0 · ∞ = NaN would fail the test).
fn safe_inv_dir(dir: vec3<f32>) -> vec3<f32> {
    let tiny = vec3<f32>(8.271806e-25);
    let fixed = select(dir, select(tiny, -tiny, dir < vec3<f32>(0.0)), abs(dir) < tiny);
    return 1.0 / fixed;
}

// The ray's octant, inverted, in each byte: XORed into an inner child's slot it gives the
// child's traversal priority.
fn octant_inv4(dir: vec3<f32>) -> u32 {
    return select(0x04040404u, 0u, dir.x < 0.0) | select(0x02020202u, 0u, dir.y < 0.0)
        | select(0x01010101u, 0u, dir.z < 0.0);
}

// Closest hit with t < t_max in the BVH under `root`, starting from `best`; `any_hit` stops
// at the first one (shadow rays). Hits are tagged with `instance`. A node group is
// (child_base, hit bits of inner children | imask): the stack holds groups with children
// left to visit, nearest first by octant order; a node's hit triangles are tested at once.
fn trace_blas(ray: Ray, root: u32, best: Hit, any_hit: bool, instance: u32) -> Hit {
    var hit = best;
    let inv_dir = safe_inv_dir(ray.dir);
    let oct_inv4 = octant_inv4(ray.dir);
    var sp = 0u;
    // The root as the only inner child (slot 7 ^ octant, no lower imask bits) of a group.
    var group = vec2<u32>(root, 0x80000000u);
    loop {
        if (group.y > 0x00ffffffu) {
            let hits = group.y;
            let child_bit = firstLeadingBit(hits);
            group.y = hits & ~(1u << child_bit);
            if (group.y > 0x00ffffffu && sp < STACK_SIZE) {
                blas_stack[sp] = group;
                sp += 1u;
            }
            let slot = (child_bit - 24u) ^ (oct_inv4 & 0xffu);
            let node = load_cw_node(group.x + countOneBits(hits & ~(0xffffffffu << slot)));
            let mask = intersect_cw_node(node, ray.origin, inv_dir, hit.t, oct_inv4);
            group = vec2<u32>(node.w1.x, (mask & 0xff000000u) | (node.w0.w >> 24u));
            var tris = mask & 0x00ffffffu;
            while (tris != 0u) {
                let k = firstLeadingBit(tris);
                tris &= ~(1u << k);
                let i = node.w1.y + k;
                let tri = load_triangle(i);
                let r = intersect_triangle(ray, tri);
                if (r.x < hit.t && (!ALPHA_TEST || (tri.flags & TRI_ALPHA) == 0u || alpha_passes(i, r.y, r.z, ray))) {
                    hit = Hit(r.x, i, r.y, r.z, instance);
                    if (any_hit) {
                        return hit;
                    }
                }
            }
        }
        if (group.y <= 0x00ffffffu) {
            if (sp == 0u) {
                break;
            }
            sp -= 1u;
            group = blas_stack[sp];
        }
    }
    return hit;
}

// Closest (or any) hit with t < t_max. With instancing, node 0 is the top level over
// instances; a leaf's instances are entered with the ray in object space (the direction is
// not renormalised, so t stays the world distance parameter).
fn trace(ray: Ray, t_max: f32, any_hit: bool) -> Hit {
    var hit = Hit(t_max, NO_HIT, 0.0, 0.0, 0u);
    if (!INSTANCING) {
        return trace_blas(ray, 0u, hit, any_hit, 0u);
    }
    let inv_dir = safe_inv_dir(ray.dir);
    var sp = 0u;
    var index = 0u;
    if (intersect_node(load_node(0u), ray.origin, inv_dir, hit.t) == INF) {
        return hit;
    }
    loop {
        let node = load_node(index);
        if (node.count > 0u) {
            for (var k = node.index; k < node.index + node.count; k++) {
                let inst = load_instance(k);
                let local = Ray(
                    transform_point(inst.world_to_object, ray.origin),
                    transform_dir(inst.world_to_object, ray.dir)
                );
                hit = trace_blas(local, inst.blas_root, hit, any_hit, k);
                if (any_hit && hit.tri != NO_HIT) {
                    return hit;
                }
            }
        } else {
            let left = node.index;
            let right = node.index + 1u;
            let t_left = intersect_node(load_node(left), ray.origin, inv_dir, hit.t);
            let t_right = intersect_node(load_node(right), ray.origin, inv_dir, hit.t);
            if (t_left != INF && t_right != INF) {
                let near_is_left = t_left <= t_right;
                if (sp < TLAS_STACK_SIZE) {
                    tlas_stack[sp] = select(left, right, near_is_left);
                    sp += 1u;
                }
                index = select(right, left, near_is_left);
                continue;
            }
            if (t_left != INF) {
                index = left;
                continue;
            }
            if (t_right != INF) {
                index = right;
                continue;
            }
        }
        if (sp == 0u) {
            break;
        }
        sp -= 1u;
        index = tlas_stack[sp];
    }
    return hit;
}

fn intersect_closest(ray: Ray) -> Hit {
    return trace(ray, INF, false);
}

// True when something blocks the segment origin → origin + dir·t_max.
fn occluded(ray: Ray, t_max: f32) -> bool {
    return trace(ray, t_max, true).tri != NO_HIT;
}

// Moves a surface point off its surface along the normal by a few ulps, so a spawned ray
// cannot hit the surface it starts on at any scene scale (Wächter & Binder, Ray Tracing
// Gems ch. 6).
fn offset_ray(p: vec3<f32>, n: vec3<f32>) -> vec3<f32> {
    let of_i = vec3<i32>(256.0 * n);
    let p_i = bitcast<vec3<f32>>(bitcast<vec3<i32>>(p) + select(of_i, -of_i, p < vec3<f32>(0.0)));
    let near_origin = abs(p) < vec3<f32>(1.0 / 32.0);
    return select(p_i, p + (1.0 / 65536.0) * n, near_origin);
}
