//! The light BVH: a binary tree over every emitter of the scene (emissive triangles, point
//! and spot lights) that light sampling walks from the root, choosing a child by its
//! importance to the shading point (`cpu/light_tree.rs`, `shaders/light_tree.wgsl`).
//!
//! Each node bounds its emitters' positions (a box), their total power and the directions
//! they emit into: an orientation cone (axis, θ_o) that holds every emitter's axis, plus the
//! spread θ_e beyond it (a one-sided triangle emits into the hemisphere around its normal:
//! θ_o = 0, θ_e = π/2). The build is top-down with the surface-area-and-orientation heuristic
//! (SAOH) over 12 buckets per axis; one emitter per leaf, nodes in depth-first order (child 0
//! follows its parent). Each emitter keeps the trail of child choices from the root (bit k:
//! the child taken at depth k), which gives the exact probability of choosing it for MIS.

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
    let r = theta_o - theta_a;
    let w = wa * r.cos() + k.cross(wa) * r.sin() + k * k.dot(wa) * (1.0 - r.cos());
    // Rounded towards the wider cone, so it still holds both.
    (w.normalize().as_vec3(), widen(theta_o.cos(), 1e-6))
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

/// SAOH cost of a side (pbrt-v4's `EvaluateCost`): power × the solid angle its cone and
/// spread reach (M_Ω) × the box's surface area, scaled for thin boxes along the axis.
fn cost(b: &LightBounds, k_r: f32) -> f64 {
    let cos_o = (b.cos_o as f64).clamp(-1.0, 1.0);
    let theta_o = cos_o.acos();
    let theta_e = (b.cos_e as f64).clamp(-1.0, 1.0).acos();
    let pi = std::f64::consts::PI;
    let theta_w = (theta_o + theta_e).min(pi);
    let sin_o = (1.0 - cos_o * cos_o).max(0.0).sqrt();
    let m_omega = 2.0 * pi * (1.0 - cos_o)
        + pi / 2.0 * (2.0 * theta_w * sin_o - (theta_o - 2.0 * theta_w).cos() - 2.0 * theta_o * sin_o + cos_o);
    let d = (b.hi - b.lo).as_dvec3();
    let area = 2.0 * (d.x * d.y + d.y * d.z + d.z * d.x);
    b.phi as f64 * m_omega * k_r as f64 * area.max(1e-30)
}

fn ceil_log2(n: usize) -> u32 {
    if n <= 1 { 0 } else { usize::BITS - (n - 1).leading_zeros() }
}

/// Builds the tree over `emitters` (every phi > 0). Depth stays ≤ MAX_LIGHT_DEPTH: a split
/// is kept only if both sides could still be split evenly within it, else the node is
/// split at the median.
pub fn build_light_bvh(emitters: &[LightBounds]) -> LightBvh {
    let t0 = std::time::Instant::now();
    let mut bvh = LightBvh {
        nodes: Vec::with_capacity(2 * emitters.len()),
        trails: vec![0; emitters.len()],
        depth: 0,
        build_seconds: 0.0,
    };
    if emitters.is_empty() {
        return bvh;
    }
    assert!(ceil_log2(emitters.len()) <= MAX_LIGHT_DEPTH, "too many emitters for the light BVH");
    let mut ids: Vec<u32> = (0..emitters.len() as u32).collect();
    build_node(emitters, &mut ids, 0, 0, &mut bvh);
    bvh.build_seconds = t0.elapsed().as_secs_f64();
    bvh
}

fn build_node(e: &[LightBounds], ids: &mut [u32], depth: u32, trail: u32, bvh: &mut LightBvh) -> LightBounds {
    let at = bvh.nodes.len();
    if ids.len() == 1 {
        let b = e[ids[0] as usize];
        bvh.nodes.push(LightNode { bounds: b, index: ids[0], leaf: true });
        bvh.trails[ids[0] as usize] = trail;
        bvh.depth = bvh.depth.max(depth);
        return b;
    }
    let mid = split(e, ids, depth);
    bvh.nodes.push(LightNode { bounds: e[ids[0] as usize], index: 0, leaf: false });
    let (left, right) = ids.split_at_mut(mid);
    let b0 = build_node(e, left, depth + 1, trail, bvh);
    let child1 = bvh.nodes.len() as u32;
    let b1 = build_node(e, right, depth + 1, trail | (1 << depth), bvh);
    let b = b0.union(&b1);
    bvh.nodes[at] = LightNode { bounds: b, index: child1, leaf: false };
    b
}

/// Reorders `ids` and returns the size of the first side.
fn split(e: &[LightBounds], ids: &mut [u32], depth: u32) -> usize {
    let n = ids.len();
    let (mut clo, mut chi) = (Vec3::splat(f32::INFINITY), Vec3::splat(f32::NEG_INFINITY));
    let (mut blo, mut bhi) = (clo, chi);
    for &i in ids.iter() {
        let b = &e[i as usize];
        clo = clo.min(b.centroid());
        chi = chi.max(b.centroid());
        blo = blo.min(b.lo);
        bhi = bhi.max(b.hi);
    }
    let diag = bhi - blo;
    let fits = |a: usize| depth + 1 + ceil_log2(a.max(n - a)) <= MAX_LIGHT_DEPTH;
    let mut best: Option<(f64, usize, usize)> = None; // (cost, axis, first bucket of side 1)
    for axis in 0..3 {
        let (lo, hi) = (clo[axis], chi[axis]);
        if hi <= lo {
            continue;
        }
        let bucket = |c: Vec3| (((c[axis] - lo) / (hi - lo) * BUCKETS as f32) as usize).min(BUCKETS - 1);
        // A bucket's cone: around the mean of its axes, wide enough for each (cheaper than
        // pairwise unions, and still a bound).
        let mut count = [0usize; BUCKETS];
        let mut sum_axis = [DVec3::ZERO; BUCKETS];
        for &i in ids.iter() {
            let b = &e[i as usize];
            let k = bucket(b.centroid());
            count[k] += 1;
            sum_axis[k] += b.axis.as_dvec3() * b.phi as f64;
        }
        let mut buckets: [Option<LightBounds>; BUCKETS] = [None; BUCKETS];
        let mean: Vec<DVec3> = sum_axis.iter().map(|s| s.try_normalize().unwrap_or(DVec3::Z)).collect();
        for &i in ids.iter() {
            let b = &e[i as usize];
            let k = bucket(b.centroid());
            let w = mean[k];
            let cos_d = w.dot(b.axis.as_dvec3()).clamp(-1.0, 1.0);
            let (cos_o, sin_o) = (b.cos_o as f64, (1.0 - (b.cos_o as f64).powi(2)).max(0.0).sqrt());
            let sin_d = (1.0 - cos_d * cos_d).max(0.0).sqrt();
            // cos(θ_d + θ_o), −1 once the sum passes π.
            let c = if cos_d * sin_o + sin_d * cos_o < 0.0 && cos_d * cos_o - sin_d * sin_o < 0.0 {
                -1.0
            } else {
                cos_d * cos_o - sin_d * sin_o
            };
            let one = LightBounds { axis: w.as_vec3(), cos_o: c as f32, ..*b };
            buckets[k] = Some(match buckets[k] {
                None => one,
                Some(acc) => LightBounds {
                    lo: acc.lo.min(b.lo),
                    hi: acc.hi.max(b.hi),
                    phi: acc.phi + b.phi,
                    axis: w.as_vec3(),
                    cos_o: acc.cos_o.min(one.cos_o),
                    cos_e: acc.cos_e.min(b.cos_e),
                    two_sided: acc.two_sided || b.two_sided,
                },
            });
        }
        let k_r = diag.max_element() / diag[axis].max(1e-30);
        // Prefix and suffix unions of the buckets.
        let mut below = [None; BUCKETS];
        let mut acc: Option<LightBounds> = None;
        for k in 0..BUCKETS {
            if let Some(b) = buckets[k] {
                acc = Some(acc.map_or(b, |a| a.union(&b)));
            }
            below[k] = acc;
        }
        let mut acc: Option<LightBounds> = None;
        let mut n_below = count.iter().sum::<usize>();
        for k in (1..BUCKETS).rev() {
            if let Some(b) = buckets[k] {
                acc = Some(acc.map_or(b, |a| a.union(&b)));
            }
            n_below -= count[k];
            if let (Some(l), Some(r)) = (below[k - 1], acc) {
                if n_below == 0 || n_below == n || !fits(n_below) {
                    continue;
                }
                let c = cost(&l, k_r) + cost(&r, k_r);
                if best.is_none_or(|(bc, _, _)| c < bc) {
                    best = Some((c, axis, k));
                }
            }
        }
    }
    if let Some((_, axis, k)) = best {
        let (lo, hi) = (clo[axis], chi[axis]);
        let bucket = |c: Vec3| (((c[axis] - lo) / (hi - lo) * BUCKETS as f32) as usize).min(BUCKETS - 1);
        let mut mid = 0;
        for j in 0..n {
            if bucket(e[ids[j] as usize].centroid()) < k {
                ids.swap(j, mid);
                mid += 1;
            }
        }
        if mid > 0 && mid < n {
            return mid;
        }
    }
    // Median along the widest spread of centroids.
    let axis = (chi - clo).max_position();
    let mid = n / 2;
    ids.select_nth_unstable_by(mid, |a, b| {
        e[*a as usize].centroid()[axis].total_cmp(&e[*b as usize].centroid()[axis]).then(a.cmp(b))
    });
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
        let bvh = build_light_bvh(&e);
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
    }

    #[test]
    fn depth_cap_holds_for_pathological_powers() {
        // Powers doubling along a line make every SAOH split peel off one emitter.
        let e: Vec<LightBounds> = (0..200).map(|i| tri(i as f32, Vec3::Z, 2f32.powi(i.min(120)))).collect();
        let bvh = build_light_bvh(&e);
        assert!(bvh.depth <= MAX_LIGHT_DEPTH, "depth {}", bvh.depth);
    }
}
