//! The light tree's walk for a packet of paths: each lane's walk is `sample_light_tree`'s,
//! step for step, the lanes taking their steps side by side. Where several paths stand at
//! the same group (all of them at the root; neighbouring paths often below it) the group's
//! four children are tested against all of them at once, one path a SIMD lane
//! (`group_shares_lanes`: the operations `group_importance` and `group_shares` do lane by
//! lane, so the same shares, the same bits); a path alone at its group takes the scalar step.

use super::lane::{F8, M8, V3};
use super::{LANES, lanes_of};
use crate::cpu::light_tree::{LightContext, child_importance, choose_child, group_shares, load_light_node};
use crate::packed::{LIGHT_LEAF, LIGHT_TWO_SIDED, LightGroup, PackedScene};
use crate::params::Params;

/// Children of a light-tree group (`packed::LIGHT_TREE_WIDTH`).
const WIDTH: usize = crate::packed::LIGHT_TREE_WIDTH as usize;

/// Paths at one group from which the group is tested in lanes (fewer take the scalar step:
/// measured, BENCHMARKS.md session 18).
const SHARED_GROUP: u32 = 4;

/// SSE's max and min (`light_tree::max_ps`, `min_ps`).
#[inline(always)]
fn max_ps(a: F8, b: F8) -> F8 {
    F8::select(a.gt(b), a, b)
}

#[inline(always)]
fn min_ps(a: F8, b: F8) -> F8 {
    F8::select(a.lt(b), a, b)
}

/// The points, normals and reflect-only flags of the paths' light contexts, in lanes.
struct Contexts {
    point: V3,
    normal: V3,
    reflect_only: M8,
}

/// `[f(0), f(1), f(2)]`, inlined (an array's `map` is a call).
#[inline(always)]
fn axes(f: impl Fn(usize) -> F8) -> [F8; 3] {
    [f(0), f(1), f(2)]
}

/// `group_shares` of group `g` for every path in lanes: the four children's shares (lane i:
/// path i), and the lanes at a dead end.
#[inline(always)]
fn group_shares_lanes(c: &Contexts, g: &LightGroup) -> ([F8; WIDTH], M8) {
    let zero = F8::splat(0.0);
    let one = F8::splat(1.0);
    let p = [c.point.x, c.point.y, c.point.z];
    let n = [c.normal.x, c.normal.y, c.normal.z];
    let dot3 = |a: [F8; 3], b: [F8; 3]| a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
    let mut far = [zero; WIDTH];
    let mut near = [zero; WIDTH];
    for k in 0..WIDTH {
        if g.phi[k] <= 0.0 {
            // No power (an empty slot): dead for every path, as the selects below make it.
            continue;
        }
        // The child's constants, as `group_importance` has them in its lane k.
        let phi = F8::splat(g.phi[k]);
        let lo = axes(|a| F8::splat(g.lo[a][k]));
        let hi = axes(|a| F8::splat(g.hi[a][k]));
        let pc = axes(|a| F8::splat(0.5 * (g.lo[a][k] + g.hi[a][k])));
        let half = axes(|a| F8::splat(0.5 * (g.hi[a][k] - g.lo[a][k])));
        let below = dot3(axes(|a| pc[a] - p[a]), n) + dot3(half, axes(|a| n[a].abs()));
        let dead = phi.le(zero) | (c.reflect_only & below.le(zero));
        let r2 = dot3(half, half);
        let to_p = axes(|a| p[a] - pc[a]);
        let dist2 = dot3(to_p, to_p);
        let outside = axes(|a| p[a] - min_ps(max_ps(p[a], lo[a]), hi[a]));
        let tiny = F8::splat(1e-20);
        let d2_far = max_ps(max_ps(dist2, r2), tiny);
        let d2_near = max_ps(max_ps(dot3(outside, outside), 0.25 * r2), tiny);
        let inside = dist2.le(r2);
        let inv_d = 1.0 / dist2.sqrt();
        let wi = axes(|a| to_p[a] * inv_d);
        let mut cos_w = dot3(axes(|a| F8::splat(g.axis[a][k])), wi);
        if g.next[k] & LIGHT_TWO_SIDED != 0 {
            cos_w = cos_w.abs();
        }
        let safe_sqrt = |x: F8| max_ps(x, zero).sqrt();
        let cos_sub = |sa: F8, ca: F8, sb: F8, cb: F8| F8::select(ca.gt(cb), one, ca * cb + sa * sb);
        let sin_sub = |sa: F8, ca: F8, sb: F8, cb: F8| F8::select(ca.gt(cb), zero, sa * cb - ca * sb);
        let sin_w = safe_sqrt(1.0 - cos_w * cos_w);
        let sin2_b = r2 * (inv_d * inv_d);
        let cos_b = safe_sqrt(1.0 - sin2_b);
        let sin_b = sin2_b.sqrt();
        let (sin_o, cos_o) = (F8::splat(g.sin_o[k]), F8::splat(g.cos_o[k]));
        let cos_x = cos_sub(sin_w, cos_w, sin_o, cos_o);
        let sin_x = sin_sub(sin_w, cos_w, sin_o, cos_o);
        let cos_p = cos_sub(sin_x, cos_x, sin_b, cos_b);
        let culled = cos_p.le(F8::splat(g.cos_e[k]));
        let cos_i = dot3(wi, n).abs();
        let sin_i = safe_sqrt(1.0 - cos_i * cos_i);
        let cos_pi = cos_sub(sin_i, cos_i, sin_b, cos_b);
        let lit = phi * cos_p * cos_pi;
        let (mut f, mut e) = (max_ps(lit / d2_far, zero), max_ps(lit / d2_near, zero));
        f = F8::select(culled, zero, f);
        e = F8::select(culled, zero, e);
        f = F8::select(inside, phi / d2_far, f);
        e = F8::select(inside, phi / d2_near, e);
        f = F8::select(dead, zero, f);
        e = F8::select(dead, zero, e);
        // `group_shares`' plane test of a one-sided leaf triangle.
        if g.one_sided[k] != 0 {
            let plane_n = axes(|a| F8::splat(g.plane_n[a][k]));
            let side = dot3(plane_n, axes(|a| p[a] - F8::splat(g.plane_p0[a][k])));
            let behind = f.gt(zero) & side.le(zero);
            f = F8::select(behind, zero, f);
            e = F8::select(behind, zero, e);
        }
        (far[k], near[k]) = (f, e);
    }
    let total_far = far[0] + far[1] + far[2] + far[3];
    let total_near = near[0] + near[1] + near[2] + near[3];
    // NaN or ≤ 0: a dead end.
    let end = !total_far.gt(zero);
    let share = |k: usize| 0.5 * (far[k] / total_far + near[k] / total_near);
    let shares = [share(0), share(1), share(2), share(3)];
    (shares, end)
}

/// `sample_light_tree` from `ctx[i]` with number `u[i]` for the lanes `i` of `mask`:
/// (emitter, probability) per lane, (0, 0) elsewhere.
#[inline(always)]
pub fn sample_light_tree_lanes(
    scene: &PackedScene,
    params: &Params,
    ctx: &[LightContext; LANES],
    u: &[f32; LANES],
    mask: u32,
) -> [(u32, f32); LANES] {
    let mut out = [(0u32, 0.0f32); LANES];
    if mask == 0 {
        return out;
    }
    let root = load_light_node(scene, params, 0);
    if root.leaf {
        for i in lanes_of(mask) {
            out[i] = (root.index, if child_importance(scene, params, &ctx[i], &root).x > 0.0 { 1.0 } else { 0.0 });
        }
        return out;
    }
    let contexts = Contexts {
        point: V3::from_fn(|i| ctx[i].point),
        normal: V3::from_fn(|i| ctx[i].normal),
        reflect_only: M8::from_fn(|i| ctx[i].reflect_only),
    };
    let mut group = [0u32; LANES];
    let mut u = *u;
    let mut pmf = [1.0f32; LANES];
    let mut walking = mask;
    while walking != 0 {
        // The paths standing where the first walking one stands.
        let g = group[walking.trailing_zeros() as usize];
        let mut here = 0u32;
        for i in lanes_of(walking) {
            if group[i] == g {
                here |= 1 << i;
            }
        }
        let node = &scene.light_groups[g as usize];
        let in_lanes = if here.count_ones() >= SHARED_GROUP { Some(group_shares_lanes(&contexts, node)) } else { None };
        for i in lanes_of(here) {
            let shares = match &in_lanes {
                Some((s, end)) => (!end.lane(i)).then(|| [s[0].0[i], s[1].0[i], s[2].0[i], s[3].0[i]]),
                None => group_shares(scene, params, &ctx[i], node),
            };
            let Some(shares) = shares else {
                out[i] = (0, 0.0);
                walking &= !(1 << i);
                continue;
            };
            let (slot, rescaled) = choose_child(shares, u[i]);
            u[i] = rescaled;
            pmf[i] *= shares[slot];
            let next = node.next[slot];
            if next & LIGHT_LEAF != 0 {
                out[i] = (next & !(LIGHT_LEAF | LIGHT_TWO_SIDED), pmf[i]);
                walking &= !(1 << i);
            } else {
                group[i] = next & !LIGHT_TWO_SIDED;
            }
        }
    }
    out
}
