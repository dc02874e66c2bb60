//! The light BVH: a binary tree over every emitter of the scene (emissive triangles, point
//! and spot lights) that light sampling walks from the root, choosing a child by its
//! importance to the shading point (`cpu/light_tree.rs`, `shaders/light_tree.wgsl`).
//!
//! Each node bounds its emitters' positions (a box), their total power and the directions
//! they emit into: an orientation cone (axis, θ_o) that holds every emitter's axis, plus the
//! spread θ_e beyond it (a one-sided triangle emits into the hemisphere around its normal:
//! θ_o = 0, θ_e = π/2). The build is top-down with the surface-area-and-orientation heuristic
//! (SAOH) over 12 buckets per axis; one emitter per leaf (the packer makes small subtrees
//! that face one way clusters: `packed/light_tree.rs`), nodes in depth-first order (child 0
//! follows its parent). Each emitter keeps the trail of child choices from the root (bit k:
//! the child taken at depth k), which gives the exact probability of choosing it for MIS.
//!
//! Speed (1 M emitters in ~2 s on 2 cores, BENCHMARKS.md): the SAOH only ranks splits, so it
//! works on f32 guides without transcendental calls, on one axis in small nodes and on a
//! sample of the emitters in large ones; the nodes' own cones are exact (f64) unions.
//! Sibling subtrees are built in parallel into slots known in advance.

use glam::{DVec3, Vec3};

/// Deepest leaf: a trail is one u32, one bit per level.
pub const MAX_LIGHT_DEPTH: u32 = 32;
const BUCKETS: usize = 12;

/// What a node knows of its emitters.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LightBounds {
    pub lo: Vec3,
    pub hi: Vec3,
    /// Power bound (in units where importance = phi · cos θ' / d² bounds the irradiance).
    pub phi: f32,
    /// Orientation cone: unit axis and cos θ_o (−1: every direction).
    pub axis: Vec3,
    pub cos_o: f32,
    /// cos θ_e: emission spread beyond the cone (0: a hemisphere).
    pub cos_e: f32,
    pub two_sided: bool,
}

impl LightBounds {
    fn centroid(&self) -> Vec3 {
        0.5 * (self.lo + self.hi)
    }

    /// The bounds of both: boxes and cones united, powers summed, the smaller cos θ_e.
    pub fn union(&self, b: &LightBounds) -> LightBounds {
        if self.phi <= 0.0 {
            return *b;
        }
        if b.phi <= 0.0 {
            return *self;
        }
        let (axis, cos_o) = cone_union(self.axis, self.cos_o, b.axis, b.cos_o);
        LightBounds {
            lo: self.lo.min(b.lo),
            hi: self.hi.max(b.hi),
            phi: self.phi + b.phi,
            axis,
            cos_o,
            cos_e: self.cos_e.min(b.cos_e),
            two_sided: self.two_sided || b.two_sided,
        }
    }
}

/// The smallest cone around both cones (pbrt-v4's `DirectionCone` union), in f64.
fn cone_union(wa: Vec3, cos_a: f32, wb: Vec3, cos_b: f32) -> (Vec3, f32) {
    let (wa, wb) = (wa.as_dvec3(), wb.as_dvec3());
    let theta_a = (cos_a as f64).clamp(-1.0, 1.0).acos();
    let theta_b = (cos_b as f64).clamp(-1.0, 1.0).acos();
    let theta_d = angle_between(wa, wb);
    let pi = std::f64::consts::PI;
    if (theta_d + theta_b).min(pi) <= theta_a {
        return (wa.as_vec3(), cos_a);
    }
    if (theta_d + theta_a).min(pi) <= theta_b {
        return (wb.as_vec3(), cos_b);
    }
    let theta_o = 0.5 * (theta_a + theta_d + theta_b);
    if theta_o >= pi {
        return (Vec3::Z, -1.0);
    }
    // Rotate wa towards wb by θ_o − θ_a about their common normal (Rodrigues).
    // Opposite axes: any common normal will do.
    let k = wa.cross(wb).try_normalize().unwrap_or_else(|| wa.any_orthonormal_vector());
    let (sin_r, cos_r) = (theta_o - theta_a).sin_cos();
    let w = wa * cos_r + k.cross(wa) * sin_r + k * k.dot(wa) * (1.0 - cos_r);
    // Rounded towards the wider cone, so it still holds both.
    let theta = theta_o + 1e-6;
    (w.normalize().as_vec3(), if theta >= pi { -1.0 } else { theta.cos() as f32 })
}

/// The angle between unit vectors, accurate near 0 and π.
fn angle_between(a: DVec3, b: DVec3) -> f64 {
    if a.dot(b) < 0.0 {
        std::f64::consts::PI - 2.0 * ((a + b).length() / 2.0).min(1.0).asin()
    } else {
        2.0 * ((b - a).length() / 2.0).min(1.0).asin()
    }
}

/// cos(θ + δ) for cos θ = c: the cone widened by δ radians.
pub fn widen(c: f64, delta: f64) -> f32 {
    let theta = c.clamp(-1.0, 1.0).acos() + delta;
    if theta >= std::f64::consts::PI { -1.0 } else { theta.cos() as f32 }
}

/// A node: its bounds, and the index of child 1 (interior; child 0 is the next node) or of
/// its emitter (leaf).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LightNode {
    pub bounds: LightBounds,
    pub index: u32,
    pub leaf: bool,
}

pub struct LightBvh {
    pub nodes: Vec<LightNode>,
    /// Per emitter: its root-to-leaf path, bit k = 1 when the walk takes child 1 at depth k.
    pub trails: Vec<u32>,
    /// Deepest leaf (the root is depth 0).
    pub depth: u32,
    pub build_seconds: f64,
}

fn ceil_log2(n: usize) -> u32 {
    if n <= 1 { 0 } else { usize::BITS - (n - 1).leading_zeros() }
}

/// An emitter during the build: items are partitioned in place, so each subtree's emitters
/// are contiguous (sequential memory, and disjoint slices for building subtrees in parallel).
#[derive(Clone, Copy)]
struct Item {
    bounds: LightBounds,
    centroid: Vec3,
    id: u32,
    trail: u32,
}

/// Subtrees larger than this are built in parallel with their sibling.
const PARALLEL_ITEMS: usize = 1024;

/// Nodes of at most this many emitters consider one split axis.
const SMALL_NODE: usize = 16;

/// Nodes of at most this many emitters are split at the median: the SAOH's bookkeeping
/// costs more than its choice among so few gains.
const MEDIAN_NODE: usize = 4;

/// Nodes of more emitters than this rank their splits on a sample of about this many.
const SAMPLED_EMITTERS: usize = 4096;

/// Builds the tree over `emitters` (every phi > 0). Depth stays ≤ MAX_LIGHT_DEPTH: a split
/// is kept only if both sides could still be split evenly within it, else the node is
/// split at the median.
pub fn build_light_bvh(emitters: &[LightBounds]) -> LightBvh {
    let t0 = std::time::Instant::now();
    let mut bvh = LightBvh { nodes: Vec::new(), trails: vec![0; emitters.len()], depth: 0, build_seconds: 0.0 };
    if emitters.is_empty() {
        return bvh;
    }
    assert!(ceil_log2(emitters.len()) <= MAX_LIGHT_DEPTH, "too many emitters for the light BVH");
    let mut items: Vec<Item> = emitters
        .iter()
        .enumerate()
        .map(|(id, b)| Item { bounds: *b, centroid: b.centroid(), id: id as u32, trail: 0 })
        .collect();
    // A subtree over m emitters has exactly 2m − 1 nodes, so every subtree's place in the
    // depth-first array is known before it is built: siblings fill disjoint slices.
    let placeholder = LightNode { bounds: emitters[0], index: 0, leaf: true };
    bvh.nodes = vec![placeholder; 2 * emitters.len() - 1];
    let (_, depth) = build_node(&mut items, 0, 0, &mut bvh.nodes, 0);
    for it in &items {
        bvh.trails[it.id as usize] = it.trail;
    }
    bvh.depth = depth;
    bvh.build_seconds = t0.elapsed().as_secs_f64();
    bvh
}

/// Builds the subtree over `items` into `out` (2 · items − 1 nodes, the first at index
/// `base`); returns its bounds and deepest leaf.
fn build_node(items: &mut [Item], depth: u32, trail: u32, out: &mut [LightNode], base: u32) -> (LightBounds, u32) {
    if items.len() == 1 {
        items[0].trail = trail;
        out[0] = LightNode { bounds: items[0].bounds, index: items[0].id, leaf: true };
        return (items[0].bounds, depth);
    }
    let mid = split(items, depth);
    let (left, right) = items.split_at_mut(mid);
    let (head, rest) = out.split_at_mut(1);
    let (out0, out1) = rest.split_at_mut(2 * mid - 1);
    let child1 = base + 2 * mid as u32;
    let trail1 = trail | (1 << depth);
    let ((b0, d0), (b1, d1)) = if left.len().min(right.len()) > PARALLEL_ITEMS {
        rayon::join(
            || build_node(left, depth + 1, trail, out0, base + 1),
            || build_node(right, depth + 1, trail1, out1, child1),
        )
    } else {
        (build_node(left, depth + 1, trail, out0, base + 1), build_node(right, depth + 1, trail1, out1, child1))
    };
    let b = b0.union(&b1);
    head[0] = LightNode { bounds: b, index: child1, leaf: false };
    (b, d0.max(d1))
}

/// What the SAOH needs of a bucket or of a side: box, power and an orientation cone that is
/// a bound but not the tightest (the nodes' own cones are `LightBounds::union`'s).
#[derive(Clone, Copy)]
struct Guide {
    lo: Vec3,
    hi: Vec3,
    phi: f32,
    axis: Vec3,
    cos_o: f32,
    cos_e: f32,
}

/// cos(a + b) from cos a and cos b (angles in [0, π]); −1 once the sum passes π.
fn cos_sum(ca: f32, cb: f32) -> f32 {
    let (sa, sb) = ((1.0 - ca * ca).max(0.0).sqrt(), (1.0 - cb * cb).max(0.0).sqrt());
    // sin(a + b) < 0 with cos(a + b) < 0: past π.
    if ca * sb + sa * cb < 0.0 && ca * cb - sa * sb < 0.0 { -1.0 } else { (ca * cb - sa * sb).max(-1.0) }
}

impl Guide {
    /// The cone of `b` re-centred on `w`.
    fn around(w: Vec3, b: &LightBounds) -> Guide {
        let cos_d = w.dot(b.axis).clamp(-1.0, 1.0);
        // One-sided triangles (θ_o = 0) are most emitters: skip the trigonometry.
        let cos_o = if b.cos_o >= 1.0 {
            cos_d
        } else if b.cos_o <= -1.0 {
            -1.0
        } else {
            cos_sum(cos_d, b.cos_o)
        };
        Guide { lo: b.lo, hi: b.hi, phi: b.phi, axis: w, cos_o, cos_e: b.cos_e }
    }

    /// Both: around the power-weighted mean axis, wide enough for each cone.
    fn union(&self, b: &Guide) -> Guide {
        let w = (self.axis * self.phi + b.axis * b.phi).try_normalize().unwrap_or(self.axis);
        let cone = |g: &Guide| if g.cos_o <= -1.0 { -1.0 } else { cos_sum(w.dot(g.axis).clamp(-1.0, 1.0), g.cos_o) };
        Guide {
            lo: self.lo.min(b.lo),
            hi: self.hi.max(b.hi),
            phi: self.phi + b.phi,
            axis: w,
            cos_o: cone(self).min(cone(b)),
            cos_e: self.cos_e.min(b.cos_e),
        }
    }

    /// SAOH cost of a side (pbrt-v4's `EvaluateCost`): power × the solid angle its cone and
    /// spread reach (M_Ω) × the box's surface area, scaled for thin boxes along the axis.
    /// Without transcendental calls but one arccosine polynomial: it only ranks splits.
    fn cost(&self, k_r: f32) -> f32 {
        use std::f32::consts::PI;
        let (cos_o, cos_e) = (self.cos_o.clamp(-1.0, 1.0), self.cos_e.clamp(-1.0, 1.0));
        let sin_o = (1.0 - cos_o * cos_o).max(0.0).sqrt();
        let sin_e = (1.0 - cos_e * cos_e).max(0.0).sqrt();
        let (theta_o, theta_e) = (acos_approx(cos_o), acos_approx(cos_e));
        // θ_w = min(θ_o + θ_e, π); cos(θ_o − 2θ_w) by the angle-sum identities.
        let (span, cos_term) = if theta_o + theta_e >= PI {
            (PI - theta_o, cos_o)
        } else {
            let (cos_2e, sin_2e) = (2.0 * cos_e * cos_e - 1.0, 2.0 * sin_e * cos_e);
            (theta_e, cos_o * cos_2e - sin_o * sin_2e)
        };
        let m_omega = 2.0 * PI * (1.0 - cos_o) + PI / 2.0 * (2.0 * span * sin_o - cos_term + cos_o);
        let d = self.hi - self.lo;
        let area = 2.0 * (d.x * d.y + d.y * d.z + d.z * d.x);
        self.phi * m_omega * k_r * area.max(1e-30)
    }
}

/// arccos to ~7e-5 rad (Abramowitz & Stegun 4.4.45), for ranking splits.
fn acos_approx(x: f32) -> f32 {
    let a = x.abs();
    let r = (1.0 - a).max(0.0).sqrt() * (1.570_728_8 + a * (-0.212_114_4 + a * (0.074_261_0 + a * -0.018_729_3)));
    if x >= 0.0 { r } else { std::f32::consts::PI - r }
}

/// Reorders `items` and returns the size of the first side.
fn split(items: &mut [Item], depth: u32) -> usize {
    let n = items.len();
    let (mut clo, mut chi) = (Vec3::splat(f32::INFINITY), Vec3::splat(f32::NEG_INFINITY));
    let (mut blo, mut bhi) = (clo, chi);
    for it in items.iter() {
        clo = clo.min(it.centroid);
        chi = chi.max(it.centroid);
        blo = blo.min(it.bounds.lo);
        bhi = bhi.max(it.bounds.hi);
    }
    let diag = bhi - blo;
    if n <= MEDIAN_NODE {
        return median_split(items, (chi - clo).max_position());
    }
    let fits = |a: usize| depth + 1 + ceil_log2(a.max(n - a)) <= MAX_LIGHT_DEPTH;
    let mut best: Option<(f32, usize, usize)> = None; // (cost, axis, first bucket of side 1)
    // Bucket statistics for the three axes in two passes over the items (the upper levels
    // do not fit in cache: passes, not arithmetic, are the cost).
    let scale = Vec3::select((chi - clo).cmpgt(Vec3::ZERO), BUCKETS as f32 / (chi - clo), Vec3::ZERO);
    let bucket_of =
        |c: Vec3, axis: usize| (((c[axis] - clo[axis]) * scale[axis]) as i32).clamp(0, BUCKETS as i32 - 1) as usize;
    // Small nodes (most of them) try only the axis of widest spread: three times cheaper,
    // and their splits matter little.
    let widest = (chi - clo).max_position();
    let axes: &[usize] = if n <= SMALL_NODE { std::slice::from_ref(&widest) } else { &[0, 1, 2] };
    // Large nodes rank their splits on an even sample of their emitters.
    let stride = n.div_ceil(SAMPLED_EMITTERS);
    let m = n.div_ceil(stride);
    let mut counts = [[0usize; BUCKETS]; 3];
    let mut sum_axis = [[Vec3::ZERO; BUCKETS]; 3];
    for it in items.iter().step_by(stride) {
        let w = it.bounds.axis * it.bounds.phi;
        for &axis in axes {
            let k = bucket_of(it.centroid, axis);
            counts[axis][k] += 1;
            sum_axis[axis][k] += w;
        }
    }
    // A bucket's cone: around the power-weighted mean of its axes, wide enough for each
    // (cheaper than pairwise unions, and still a bound).
    let mean = sum_axis.map(|a| a.map(|s| s.try_normalize().unwrap_or(Vec3::Z)));
    let empty = Guide { lo: Vec3::INFINITY, hi: Vec3::NEG_INFINITY, phi: 0.0, axis: Vec3::Z, cos_o: 1.0, cos_e: 1.0 };
    let mut guides = [[empty; BUCKETS]; 3];
    for it in items.iter().step_by(stride) {
        for &axis in axes {
            let k = bucket_of(it.centroid, axis);
            let one = Guide::around(mean[axis][k], &it.bounds);
            let acc = &mut guides[axis][k];
            *acc = Guide {
                lo: acc.lo.min(one.lo),
                hi: acc.hi.max(one.hi),
                phi: acc.phi + one.phi,
                axis: one.axis,
                cos_o: acc.cos_o.min(one.cos_o),
                cos_e: acc.cos_e.min(one.cos_e),
            };
        }
    }
    for &axis in axes {
        if chi[axis] <= clo[axis] {
            continue;
        }
        let count = &counts[axis];
        let buckets: [Option<Guide>; BUCKETS] =
            std::array::from_fn(|k| if count[k] > 0 { Some(guides[axis][k]) } else { None });
        let k_r = diag.max_element() / diag[axis].max(1e-30);
        // Prefix unions, then suffixes against them. Only a split just below a non-empty
        // bucket is a distinct partition.
        let mut below = [None; BUCKETS];
        let mut acc: Option<Guide> = None;
        for k in 0..BUCKETS {
            if let Some(b) = buckets[k] {
                acc = Some(acc.map_or(b, |a| a.union(&b)));
            }
            below[k] = acc;
        }
        let mut acc: Option<Guide> = None;
        let mut n_below = m;
        for k in (1..BUCKETS).rev() {
            let Some(b) = buckets[k] else { continue };
            acc = Some(acc.map_or(b, |a| a.union(&b)));
            n_below -= count[k];
            if let (Some(l), Some(r)) = (below[k - 1], acc) {
                if n_below == 0 || n_below == m || (stride == 1 && !fits(n_below)) {
                    continue;
                }
                let c = l.cost(k_r) + r.cost(k_r);
                if best.is_none_or(|(bc, _, _)| c < bc) {
                    best = Some((c, axis, k));
                }
            }
        }
    }
    if let Some((_, axis, k)) = best {
        let mut mid = 0;
        for j in 0..n {
            if bucket_of(items[j].centroid, axis) < k {
                items.swap(j, mid);
                mid += 1;
            }
        }
        if mid > 0 && mid < n && fits(mid) {
            return mid;
        }
    }
    median_split(items, (chi - clo).max_position())
}

/// Splits at the median centroid along `axis`.
fn median_split(items: &mut [Item], axis: usize) -> usize {
    let mid = items.len() / 2;
    items.select_nth_unstable_by(mid, |a, b| a.centroid[axis].total_cmp(&b.centroid[axis]).then(a.id.cmp(&b.id)));
    mid
}

#[cfg(test)]
mod tests {
    use super::*;

    fn tri(x: f32, normal: Vec3, phi: f32) -> LightBounds {
        let p = Vec3::new(x, 0.0, 0.0);
        LightBounds { lo: p - 0.1, hi: p + 0.1, phi, axis: normal, cos_o: 1.0, cos_e: 0.0, two_sided: false }
    }

    #[test]
    fn cone_union_holds_both_cones() {
        let cases = [
            (Vec3::Z, 1.0, Vec3::X, 1.0),
            (Vec3::Z, 0.5, -Vec3::Z, 0.9),
            (Vec3::Y, 0.0, Vec3::new(0.6, 0.8, 0.0), 0.99),
        ];
        for (wa, ca, wb, cb) in cases {
            let (w, c) = cone_union(wa, ca, wb, cb);
            assert!(c > -1.0, "{wa} {ca} {wb} {cb}: the union is narrower than the sphere");
            for (v, cv) in [(wa, ca), (wb, cb)] {
                // The cone (v, cv) lies inside (w, c): angle(w, v) + θ_v ≤ θ_c.
                let lhs = angle_between(w.as_dvec3(), v.as_dvec3()) + (cv as f64).acos();
                assert!(lhs <= (c as f64).acos() + 1e-5, "{wa} {ca} {wb} {cb}: {w} {c}");
            }
        }
    }

    #[test]
    fn trails_lead_to_their_leaves_and_depth_is_capped() {
        // 3000 emitters in a row with powers spanning six decades: the SAOH wants a skewed tree.
        let e: Vec<LightBounds> = (0..3000)
            .map(|i| {
                tri(
                    i as f32,
                    if i % 2 == 0 { Vec3::Z } else { -Vec3::Y },
                    10f32.powi(i % 7 - 3) * if i == 5 { 1e9 } else { 1.0 },
                )
            })
            .collect();
        check_tree(&e);
    }

    #[test]
    fn large_trees_built_in_parallel_and_from_samples_hold_the_same_invariants() {
        // Above PARALLEL_ITEMS (subtrees built on other threads) and SAMPLED_EMITTERS (splits
        // ranked on a sample): a scattered cloud facing every way.
        let mut state = 7u64;
        let mut f = move || {
            state = state.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
            (state >> 40) as f32 / (1u64 << 24) as f32
        };
        let e: Vec<LightBounds> = (0..20_000)
            .map(|_| {
                let p = Vec3::new(f(), f(), f()) * 10.0;
                let n = Vec3::new(f() - 0.5, f() - 0.5, f() - 0.5).normalize_or(Vec3::Z);
                LightBounds {
                    lo: p,
                    hi: p + 0.01,
                    phi: 10f32.powf(3.0 * f()),
                    axis: n,
                    cos_o: 1.0,
                    cos_e: 0.0,
                    two_sided: false,
                }
            })
            .collect();
        assert!(e.len() > 2 * SAMPLED_EMITTERS && e.len() > 2 * PARALLEL_ITEMS);
        let bvh = check_tree(&e);
        // The same tree every time, whichever thread built what.
        assert_eq!(bvh.nodes, build_light_bvh(&e).nodes);
    }

    /// Every emitter's trail leads to its leaf, depth is capped, and every node bounds its
    /// children (boxes and cones).
    fn check_tree(e: &[LightBounds]) -> LightBvh {
        let bvh = build_light_bvh(e);
        assert_eq!(bvh.nodes.len(), 2 * e.len() - 1);
        assert!(bvh.depth <= MAX_LIGHT_DEPTH);
        for (k, &trail) in bvh.trails.iter().enumerate() {
            let mut at = 0usize;
            let mut bits = trail;
            let mut depth = 0;
            while !bvh.nodes[at].leaf {
                at = if bits & 1 == 0 { at + 1 } else { bvh.nodes[at].index as usize };
                bits >>= 1;
                depth += 1;
                assert!(depth <= MAX_LIGHT_DEPTH);
            }
            assert_eq!(bvh.nodes[at].index as usize, k);
        }
        // Every node bounds its children.
        for (i, n) in bvh.nodes.iter().enumerate() {
            if !n.leaf {
                for c in [&bvh.nodes[i + 1], &bvh.nodes[n.index as usize]] {
                    assert!(n.bounds.lo.cmple(c.bounds.lo).all() && n.bounds.hi.cmpge(c.bounds.hi).all());
                    let lhs = angle_between(n.bounds.axis.as_dvec3(), c.bounds.axis.as_dvec3())
                        + (c.bounds.cos_o as f64).acos();
                    assert!(n.bounds.cos_o <= -1.0 || lhs <= (n.bounds.cos_o as f64).acos() + 1e-4);
                }
            }
        }
        bvh
    }

    #[test]
    fn depth_cap_holds_for_pathological_powers() {
        // Powers doubling along a line make every SAOH split peel off one emitter.
        let e: Vec<LightBounds> = (0..200).map(|i| tri(i as f32, Vec3::Z, 2f32.powi(i.min(120)))).collect();
        let bvh = build_light_bvh(&e);
        assert!(bvh.depth <= MAX_LIGHT_DEPTH, "depth {}", bvh.depth);
    }
}
