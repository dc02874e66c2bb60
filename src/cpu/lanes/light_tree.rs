//! The light tree's walk for a packet of paths: each lane's walk is `sample_light_tree`'s,
//! step for step, the lanes taking their steps side by side. Where several paths stand at
//! the same group (all of them at the root; neighbouring paths often below it) the group's
//! four children are tested against all of them at once, one path a SIMD lane
//! (`group_shares_lanes`: the operations `group_importance` and `group_shares` do lane by
//! lane, so the same shares, the same bits) and the paths there choose their children side by
//! side (`choose_child_lanes`); paths alone at their groups step two at a time, each one's four
//! children in half of the lanes (`group_shares_pair`). A vertex's light candidates walk
//! together (`sample_light_tree_candidates`): a path's candidates at the same group step from
//! one evaluation of its children.

use super::lane::{F8, M8, U8, V3};
use super::{LANES, lanes_of};
use crate::cpu::common::ONE_MINUS_EPSILON;
use crate::cpu::light_tree::{
    LightContext, LightNode, choose_child, choose_in_cluster, cluster_entry, group_shares, leaf_emitter,
    load_light_node, plane_tested, root_word,
};
use crate::packed::{LIGHT_CLUSTER, LIGHT_INDEX_MASK, LIGHT_LEAF, LIGHT_TWO_SIDED, LightGroup, PackedScene};
use crate::params::Params;
use glam::Vec3;

/// Children of a light-tree group (`packed::LIGHT_TREE_WIDTH`).
const WIDTH: usize = crate::packed::LIGHT_TREE_WIDTH as usize;

/// Paths at one group from which the group is tested in lanes (fewer step in pairs: measured,
/// BENCHMARKS.md sessions 18 and 23).
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

/// Light-tree children in lanes: lane j holds one child's bounds, power, cone and leaf plane,
/// as `group_importance` has a group's child k in its lane k. The lanes may hold children of
/// one group seen from eight paths, or of two groups seen from two paths.
struct ChildLanes {
    phi: F8,
    lo: [F8; 3],
    hi: [F8; 3],
    axis: [F8; 3],
    sin_o: F8,
    cos_o: F8,
    cos_e: F8,
    two_sided: M8,
    /// One-sided leaf triangles (`group_shares`' plane test), with their planes.
    one_sided: M8,
    plane_p0: [F8; 3],
    plane_n: [F8; 3],
}

impl ChildLanes {
    /// Every lane: slot `k` of group `g` (one group seen from eight paths).
    #[inline(always)]
    fn splat(g: &LightGroup, k: usize) -> ChildLanes {
        let f = |x: &[f32; 4]| F8::splat(x[k]);
        let v = |x: &[[f32; 4]; 3]| axes(|a| F8::splat(x[a][k]));
        ChildLanes {
            phi: f(&g.phi),
            lo: v(&g.lo),
            hi: v(&g.hi),
            axis: v(&g.axis),
            sin_o: f(&g.sin_o),
            cos_o: f(&g.cos_o),
            cos_e: f(&g.cos_e),
            two_sided: M8::splat(g.next[k] & LIGHT_TWO_SIDED != 0),
            one_sided: M8::splat(g.one_sided[k] != 0),
            plane_p0: v(&g.plane_p0),
            plane_n: v(&g.plane_n),
        }
    }

    /// Lanes 0–3: group `a`'s four slots, lanes 4–7: group `b`'s (two paths, each at its own
    /// group). Each field is two 16-byte halves, as the groups store them.
    #[inline(always)]
    fn pair(a: &LightGroup, b: &LightGroup) -> ChildLanes {
        let f = |x: &[f32; 4], y: &[f32; 4]| F8(join(*x, *y));
        let v = |x: &[[f32; 4]; 3], y: &[[f32; 4]; 3]| axes(|k| F8(join(x[k], y[k])));
        let m = |x: [u32; 4], y: [u32; 4], flag: u32| U8(join(x, y)).map(|w| w & flag).gt(0);
        ChildLanes {
            phi: f(&a.phi, &b.phi),
            lo: v(&a.lo, &b.lo),
            hi: v(&a.hi, &b.hi),
            axis: v(&a.axis, &b.axis),
            sin_o: f(&a.sin_o, &b.sin_o),
            cos_o: f(&a.cos_o, &b.cos_o),
            cos_e: f(&a.cos_e, &b.cos_e),
            two_sided: m(a.next, b.next, LIGHT_TWO_SIDED),
            one_sided: m(a.one_sided, b.one_sided, u32::MAX),
            plane_p0: v(&a.plane_p0, &b.plane_p0),
            plane_n: v(&a.plane_n, &b.plane_n),
        }
    }
}

/// Eight lanes from two groups' four slots (two 16-byte moves, not eight scalar inserts).
#[inline(always)]
fn join<T: Copy + Default>(lo: [T; WIDTH], hi: [T; WIDTH]) -> [T; LANES] {
    let mut x = [T::default(); LANES];
    x[..WIDTH].copy_from_slice(&lo);
    x[WIDTH..].copy_from_slice(&hi);
    x
}

/// `group_importance` and `group_shares`' plane test, lane by lane: the far and near
/// importance of child lanes `c` seen from points `p` with normals `n`.
#[inline(always)]
fn child_importance_lanes(p: [F8; 3], n: [F8; 3], reflect_only: M8, c: &ChildLanes) -> (F8, F8) {
    let zero = F8::splat(0.0);
    let one = F8::splat(1.0);
    let dot3 = |a: [F8; 3], b: [F8; 3]| a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
    let (lo, hi) = (c.lo, c.hi);
    let pc = axes(|a| 0.5 * (lo[a] + hi[a]));
    let half = axes(|a| 0.5 * (hi[a] - lo[a]));
    let below = dot3(axes(|a| pc[a] - p[a]), n) + dot3(half, axes(|a| n[a].abs()));
    let dead = c.phi.le(zero) | (reflect_only & below.le(zero));
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
    let cos_w = dot3(c.axis, wi);
    let cos_w = F8::select(c.two_sided, cos_w.abs(), cos_w);
    let safe_sqrt = |x: F8| max_ps(x, zero).sqrt();
    let cos_sub = |sa: F8, ca: F8, sb: F8, cb: F8| F8::select(ca.gt(cb), one, ca * cb + sa * sb);
    let sin_sub = |sa: F8, ca: F8, sb: F8, cb: F8| F8::select(ca.gt(cb), zero, sa * cb - ca * sb);
    let sin_w = safe_sqrt(1.0 - cos_w * cos_w);
    let sin2_b = r2 * (inv_d * inv_d);
    let cos_b = safe_sqrt(1.0 - sin2_b);
    let sin_b = sin2_b.sqrt();
    let cos_x = cos_sub(sin_w, cos_w, c.sin_o, c.cos_o);
    let sin_x = sin_sub(sin_w, cos_w, c.sin_o, c.cos_o);
    let cos_p = cos_sub(sin_x, cos_x, sin_b, cos_b);
    let culled = cos_p.le(c.cos_e);
    let cos_i = dot3(wi, n).abs();
    let sin_i = safe_sqrt(1.0 - cos_i * cos_i);
    let cos_pi = cos_sub(sin_i, cos_i, sin_b, cos_b);
    // One division per estimate (`group_importance`'s: the same values).
    let lit = F8::select(inside, c.phi, F8::select(culled, zero, c.phi * cos_p * cos_pi));
    let (mut f, mut e) = (max_ps(lit / d2_far, zero), max_ps(lit / d2_near, zero));
    f = F8::select(dead, zero, f);
    e = F8::select(dead, zero, e);
    if c.one_sided.bits() != 0 {
        let side = dot3(c.plane_n, axes(|a| p[a] - c.plane_p0[a]));
        let behind = f.gt(zero) & c.one_sided & side.le(zero);
        f = F8::select(behind, zero, f);
        e = F8::select(behind, zero, e);
    }
    (f, e)
}

/// The paths (lanes) for which a root leaf has positive importance: `child_importance`'s
/// test of the root, the same operations for every path at once instead of path by path (a
/// scene whose lights are one leaf, such as the Cornell box, tests it at every vertex).
#[inline(always)]
fn root_lit_lanes(scene: &PackedScene, params: &Params, c: &Contexts, root: &LightNode) -> M8 {
    let s = F8::splat;
    let v = |x: Vec3| [s(x.x), s(x.y), s(x.z)];
    let tested = plane_tested(root);
    let emitter = if root.cluster { cluster_entry(scene, params, root.index).0 } else { root.index };
    let plane = (tested && emitter < params.light_count).then(|| scene.light_planes[emitter as usize]);
    let [p0, n] = plane.unwrap_or([Vec3::ZERO; 2]);
    let child = ChildLanes {
        phi: s(root.phi),
        lo: v(root.lo),
        hi: v(root.hi),
        axis: v(root.axis),
        sin_o: s(root.sin_o),
        cos_o: s(root.cos_o),
        cos_e: s(root.cos_e),
        two_sided: M8::splat(root.two_sided),
        one_sided: M8::splat(plane.is_some()),
        plane_p0: v(p0),
        plane_n: v(n),
    };
    let p = [c.point.x, c.point.y, c.point.z];
    let n = [c.normal.x, c.normal.y, c.normal.z];
    child_importance_lanes(p, n, c.reflect_only, &child).0.gt(F8::splat(0.0))
}

/// `group_shares` of group `g` for every path in lanes: the four children's shares (lane i:
/// path i), and the lanes at a dead end.
#[inline(always)]
fn group_shares_lanes(c: &Contexts, g: &LightGroup) -> ([F8; WIDTH], M8) {
    let zero = F8::splat(0.0);
    let p = [c.point.x, c.point.y, c.point.z];
    let n = [c.normal.x, c.normal.y, c.normal.z];
    let mut far = [zero; WIDTH];
    let mut near = [zero; WIDTH];
    for k in 0..WIDTH {
        if g.phi[k] <= 0.0 {
            // No power (an empty slot): dead for every path, as the selects make it.
            continue;
        }
        let child = ChildLanes::splat(g, k);
        (far[k], near[k]) = child_importance_lanes(p, n, c.reflect_only, &child);
    }
    let total_far = far[0] + far[1] + far[2] + far[3];
    let total_near = near[0] + near[1] + near[2] + near[3];
    // NaN or ≤ 0: a dead end.
    let end = !total_far.gt(zero);
    let share = |k: usize| 0.5 * (far[k] / total_far + near[k] / total_near);
    let shares = [share(0), share(1), share(2), share(3)];
    (shares, end)
}

/// `group_shares` of two paths at once, each at its own group: path a's four children in
/// lanes 0–3, path b's in lanes 4–7 (half the work of two scalar steps).
#[inline(always)]
fn group_shares_pair(a: (&LightContext, &LightGroup), b: (&LightContext, &LightGroup)) -> [Option<[f32; 4]>; 2] {
    let half = |j: usize| j >= WIDTH;
    let ctx = |j: usize| if half(j) { b.0 } else { a.0 };
    let p = axes(|k| F8::from_fn(|j| ctx(j).point[k]));
    let n = axes(|k| F8::from_fn(|j| ctx(j).normal[k]));
    let reflect_only = M8::from_fn(|j| ctx(j).reflect_only);
    let child = ChildLanes::pair(a.1, b.1);
    let (far, near) = child_importance_lanes(p, n, reflect_only, &child);
    // Each path's totals in slot order, as the scalar step adds them.
    let total = |x: F8, h: usize| ((x.0[h] + x.0[h + 1]) + x.0[h + 2]) + x.0[h + 3];
    let (ta, tb) = ((total(far, 0), total(near, 0)), (total(far, WIDTH), total(near, WIDTH)));
    let total_far = F8::from_fn(|j| if half(j) { tb.0 } else { ta.0 });
    let total_near = F8::from_fn(|j| if half(j) { tb.1 } else { ta.1 });
    let shares = 0.5 * (far / total_far + near / total_near);
    let of = |h: usize, t: f32| {
        // NaN or ≤ 0: a dead end.
        (t > 0.0).then(|| [shares.0[h], shares.0[h + 1], shares.0[h + 2], shares.0[h + 3]])
    };
    [of(0, ta.0), of(WIDTH, tb.0)]
}

/// `choose_child` for eight walks at once (lane j: shares `s[k].0[j]`, number `u.0[j]`): the
/// scalar's comparisons and roundings lane by lane, in its order, so the same child and the
/// same rescaled number (no branch on `u`, which no predictor guesses).
#[inline(always)]
pub fn choose_child_lanes(s: &[F8; WIDTH], u: F8) -> ([usize; LANES], F8) {
    let (zero, top) = (F8::splat(0.0), F8::splat(ONE_MINUS_EPSILON));
    let child = |k: usize| F8::splat(k as f32);
    // NaN or ≤ 0: no share.
    let valid = [s[0].gt(zero), s[1].gt(zero), s[2].gt(zero), s[3].gt(zero)];
    let mut last = zero;
    for (k, &v) in valid.iter().enumerate().skip(1) {
        last = F8::select(v, child(k), last);
    }
    // Nothing chosen below: (last, u), as the scalar's fall-through.
    let (mut slot, mut out) = (last, u);
    let mut open = M8::splat(true);
    let mut below = zero;
    for k in 0..WIDTH {
        let is_last = last.eq(child(k));
        let take_last = open & valid[k] & is_last;
        let take_inside = open & valid[k] & !is_last & u.lt(below + s[k]);
        let r_last = ((u - below) / (1.0 - below)).min_num(top);
        let r_inside = ((u - below) / s[k]).min_num(top);
        out = F8::select(take_last, r_last, F8::select(take_inside, r_inside, out));
        let taken = take_last | take_inside;
        slot = F8::select(taken, child(k), slot);
        open = open & !taken;
        below = F8::select(valid[k], below + s[k], below);
    }
    (std::array::from_fn(|j| slot.0[j] as usize), out)
}

/// The walks of a packet's paths, each where its own `sample_light_tree` would be: `N` walks,
/// walk e of path `e % LANES` (several walks per path when a vertex draws several light
/// candidates).
struct Walks<const N: usize> {
    group: [u32; N],
    u: [f32; N],
    pmf: [f32; N],
    walking: u32,
    out: [(u32, f32); N],
}

impl<const N: usize> Walks<N> {
    /// Walk e's step from its group with the children's `shares` (None: a dead end).
    #[inline(always)]
    fn step(&mut self, g: &LightGroup, e: usize, shares: Option<[f32; 4]>) {
        let Some(shares) = shares else {
            self.end(e);
            return;
        };
        let (slot, rescaled) = choose_child(shares, self.u[e]);
        self.take(g, e, slot, rescaled, shares[slot]);
    }

    /// Walk e at a dead end.
    #[inline(always)]
    fn end(&mut self, e: usize) {
        self.out[e] = (0, 0.0);
        self.walking &= !(1 << e);
    }

    /// Walk e goes on to child `slot` of `g`, chosen with probability `share`, with its
    /// number rescaled to `rescaled`.
    #[inline(always)]
    fn take(&mut self, g: &LightGroup, e: usize, slot: usize, rescaled: f32, share: f32) {
        self.u[e] = rescaled;
        self.pmf[e] *= share;
        let next = g.next[slot];
        if next & LIGHT_LEAF != 0 {
            // A cluster's emitter is chosen after the walks (`u[e]` keeps the number for it).
            self.out[e] = (next & (LIGHT_INDEX_MASK | LIGHT_CLUSTER), self.pmf[e]);
            self.walking &= !(1 << e);
        } else {
            self.group[e] = next & !LIGHT_TWO_SIDED;
        }
    }

    /// The walks among `mask` that stand at group `group`: eight walks' groups compared at
    /// once.
    #[inline(always)]
    fn at(&self, mask: u32, group: u32) -> u32 {
        let key = U8::splat(group);
        let mut here = 0u32;
        for c in (0..N).step_by(LANES) {
            here |= U8::from_fn(|j| self.group[c + j]).eq(key).bits() << c;
        }
        here & mask
    }
}

/// The walks (bits) of path `i` among `N` walks.
#[inline(always)]
fn walks_of_path<const N: usize>(i: usize) -> u32 {
    let mut bits = 0u32;
    let mut e = i;
    while e < N {
        bits |= 1 << e;
        e += LANES;
    }
    bits
}

/// The paths (bits) with a walk among the walks `walks`.
#[inline(always)]
fn paths_of<const N: usize>(walks: u32) -> u32 {
    let mut paths = 0u32;
    let mut shift = 0;
    while shift < N {
        paths |= walks >> shift;
        shift += LANES;
    }
    paths & ((1 << LANES) - 1)
}

/// Most light candidates walked together (`Walks`' bits are one u32).
pub const MAX_CANDIDATES: usize = 32 / LANES;

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
    sample_light_tree_candidates::<LANES>(scene, params, ctx, u, mask)
}

/// `sample_light_tree` for `N / LANES` light candidates of each path at once: walk e from
/// `ctx[e % LANES]` with number `u[e]`, for the walks e of `mask`. A path's candidates that
/// stand at the same group take their steps from one evaluation of its children (the same
/// point, so the same shares), and more walks side by side fill more lanes.
#[inline(always)]
pub fn sample_light_tree_candidates<const N: usize>(
    scene: &PackedScene,
    params: &Params,
    ctx: &[LightContext; LANES],
    u: &[f32; N],
    mask: u32,
) -> [(u32, f32); N] {
    const { assert!(N.is_multiple_of(LANES) && N <= 32) };
    let mut out = [(0u32, 0.0f32); N];
    if mask == 0 {
        return out;
    }
    let root = load_light_node(scene, params, 0);
    let contexts = Contexts {
        point: V3::from_fn(|i| ctx[i].point),
        normal: V3::from_fn(|i| ctx[i].normal),
        reflect_only: M8::from_fn(|i| ctx[i].reflect_only),
    };
    if root.leaf {
        let lit = root_lit_lanes(scene, params, &contexts, &root);
        for e in lanes_of(mask) {
            out[e] = if lit.lane(e % LANES) {
                leaf_emitter(scene, params, root_word(&root), u[e])
            } else {
                (root.index, 0.0)
            };
        }
        return out;
    }
    let mut w = Walks { group: [0; N], u: *u, pmf: [1.0; N], walking: mask, out };
    while w.walking != 0 {
        // The walks standing where the first walking one stands, and their paths.
        let first = w.walking.trailing_zeros() as usize;
        let g = &scene.light_groups[w.group[first] as usize];
        let here = w.at(w.walking, w.group[first]);
        let paths_here = paths_of::<N>(here);
        if paths_here.count_ones() >= SHARED_GROUP {
            let (s, end) = group_shares_lanes(&contexts, g);
            // Walks 8c..8c + 8 are one walk of each path, in the shares' lanes: they choose
            // side by side.
            for c in (0..N).step_by(LANES) {
                let walks = (here >> c) & ((1 << LANES) - 1);
                if walks == 0 {
                    continue;
                }
                let (slot, rescaled) = choose_child_lanes(&s, F8::from_fn(|j| w.u[c + j]));
                for j in lanes_of(walks) {
                    if end.lane(j) {
                        w.end(c + j);
                    } else {
                        w.take(g, c + j, slot[j], rescaled.0[j], s[slot[j]].0[j]);
                    }
                }
            }
            continue;
        }
        // Fewer paths here: the first walk's path steps (all its walks at this group) with
        // the next walk elsewhere or of another path, wherever that stands.
        let (a, a_walks) = (first % LANES, here & walks_of_path::<N>(first % LANES));
        let rest = w.walking & !a_walks;
        if rest == 0 {
            let shares = group_shares(scene, params, &ctx[a], g);
            for e in lanes_of(a_walks) {
                w.step(g, e, shares);
            }
            continue;
        }
        let second = rest.trailing_zeros() as usize;
        let b = second % LANES;
        let g2 = &scene.light_groups[w.group[second] as usize];
        let b_walks = w.at(rest & walks_of_path::<N>(b), w.group[second]);
        let [sa, sb] = group_shares_pair((&ctx[a], g), (&ctx[b], g2));
        for e in lanes_of(a_walks) {
            w.step(g, e, sa);
        }
        for e in lanes_of(b_walks) {
            w.step(g2, e, sb);
        }
    }
    if scene.light_tree_clusters > 0 {
        for e in lanes_of(mask) {
            let (word, pmf) = w.out[e];
            if word & LIGHT_CLUSTER != 0 {
                let (emitter, p) = choose_in_cluster(scene, params, word & LIGHT_INDEX_MASK, w.u[e]);
                w.out[e] = (emitter, pmf * p);
            }
        }
    }
    w.out
}
