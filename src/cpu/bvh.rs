//! Twin of `shaders/bvh.wgsl`: the same traversal over the same nodes.

pub use super::common::{INF, Ray};
use super::instance::{load_instance, transform_dir, transform_point};
use super::material::alpha_passes;
use crate::packed::{BvhNode, CwNode, PackedScene, TRI_ALPHA, Triangle};
use glam::{IVec3, UVec2, UVec3, Vec3, Vec3A, Vec4};

pub const NO_HIT: u32 = u32::MAX;
// One group per tree level: accel refuses deeper mesh BVHs.
const STACK_SIZE: usize = crate::accel::MAX_DEPTH as usize;
pub const TLAS_STACK_SIZE: usize = 64;

#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Hit {
    pub t: f32,
    pub tri: u32,
    pub u: f32,
    pub v: f32,
    pub instance: u32,
}

pub fn intersect_triangle(ray: &Ray, tri: &Triangle) -> Vec3 {
    let (p0, e1, e2) = (Vec3::from(tri.p0), Vec3::from(tri.e1), Vec3::from(tri.e2));
    let pvec = ray.dir.cross(e2);
    let det = e1.dot(pvec);
    if det == 0.0 {
        return Vec3::new(INF, 0.0, 0.0);
    }
    let inv_det = 1.0 / det;
    let tvec = ray.origin - p0;
    let u = tvec.dot(pvec) * inv_det;
    if !(0.0..=1.0).contains(&u) {
        return Vec3::new(INF, 0.0, 0.0);
    }
    let qvec = tvec.cross(e1);
    let v = ray.dir.dot(qvec) * inv_det;
    if v < 0.0 || u + v > 1.0 {
        return Vec3::new(INF, 0.0, 0.0);
    }
    let t = e2.dot(qvec) * inv_det;
    Vec3::new(if t > 0.0 { t } else { INF }, u, v)
}

/// Slab test of a top-level node in SSE lanes (glam's Vec3A); `inv_dir` from safe_inv_dir,
/// so no slab is NaN.
#[inline(always)]
pub fn intersect_node(node: &BvhNode, origin: Vec3, inv_dir: Vec3, t_max: f32) -> f32 {
    let (origin, inv_dir) = (Vec3A::from(origin), Vec3A::from(inv_dir));
    let t0 = (Vec3A::from(node.min) - origin) * inv_dir;
    let t1 = (Vec3A::from(node.max) - origin) * inv_dir;
    let near = t0.min(t1);
    let far = t0.max(t1);
    let t_enter = near.x.max(near.y).max(near.z.max(0.0));
    let t_exit = far.x.min(far.y).min(far.z.min(t_max));
    if t_enter <= t_exit { t_enter } else { INF }
}

/// The node of the mesh BVHs at index `i` (three slots from slot `3 i`).
#[inline(always)]
pub fn load_cw_node(scene: &PackedScene, i: u32) -> &CwNode {
    let s = 3 * i as usize;
    bytemuck::from_bytes(bytemuck::cast_slice(&scene.nodes[s..s + 3]))
}

/// Hit mask of a compressed node's children (see shaders/bvh.wgsl), four children per SSE
/// register: the same operations per child as the shader's loop.
#[inline(always)]
pub fn intersect_cw_node(node: &CwNode, origin: Vec3, inv_dir: Vec3, t_max: f32, oct_inv4: u32) -> u32 {
    let e = UVec3::splat(node.e_imask) >> UVec3::new(0, 8, 16) & UVec3::splat(0xff);
    let scale = Vec3::new(f32::from_bits(e.x << 23), f32::from_bits(e.y << 23), f32::from_bits(e.z << 23)) * inv_dir;
    let shift = (Vec3::from(node.p) - origin) * inv_dir;
    let mut mask = 0;
    for half in 0..2 {
        let slab = |q: &[u32; 4], axis: usize| {
            let t0 = byte_lanes(q[half]) * scale[axis] + Vec4::splat(shift[axis]);
            let t1 = byte_lanes(q[2 + half]) * scale[axis] + Vec4::splat(shift[axis]);
            (t0.min(t1), t0.max(t1))
        };
        let ((near_x, far_x), (near_y, far_y), (near_z, far_z)) =
            (slab(&node.qx, 0), slab(&node.qy, 1), slab(&node.qz, 2));
        let t_enter = near_x.max(near_y).max(near_z.max(Vec4::ZERO));
        let t_exit = far_x.min(far_y).min(far_z.min(Vec4::splat(t_max)));
        let mut hits = t_enter.cmple(t_exit).bitmask();
        while hits != 0 {
            let lane = hits.trailing_zeros();
            hits &= hits - 1;
            let child_meta = (node.child_meta[half] >> (8 * lane)) & 0xff;
            let is_inner = child_meta & (child_meta << 1) & 0x10 != 0;
            let bit_index = (child_meta ^ if is_inner { oct_inv4 & 0xff } else { 0 }) & 0x1f;
            mask |= ((child_meta >> 5) & 7) << bit_index;
        }
    }
    mask
}

/// `intersect_cw_node` with the eight children in one AVX2 register: per child the same
/// operations in the same order (multiply, then add; min and max with the same operands
/// first), so the same mask bit for bit.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
#[inline]
unsafe fn intersect_cw_node_avx2(node: &CwNode, origin: Vec3, inv_dir: Vec3, t_max: f32, oct_inv4: u32) -> u32 {
    use std::arch::x86_64::*;
    let e = UVec3::splat(node.e_imask) >> UVec3::new(0, 8, 16) & UVec3::splat(0xff);
    let scale = Vec3::new(f32::from_bits(e.x << 23), f32::from_bits(e.y << 23), f32::from_bits(e.z << 23)) * inv_dir;
    let shift = (Vec3::from(node.p) - origin) * inv_dir;
    // Eight bytes (children 0..8, low byte first) as eight floats.
    let bytes = |lo: u32, hi: u32| _mm256_cvtepi32_ps(_mm256_cvtepu8_epi32(_mm_set_epi32(0, 0, hi as i32, lo as i32)));
    let slab = |q: &[u32; 4], axis: usize| {
        let (s, sh) = (_mm256_set1_ps(scale[axis]), _mm256_set1_ps(shift[axis]));
        let t0 = _mm256_add_ps(_mm256_mul_ps(bytes(q[0], q[1]), s), sh);
        let t1 = _mm256_add_ps(_mm256_mul_ps(bytes(q[2], q[3]), s), sh);
        (_mm256_min_ps(t0, t1), _mm256_max_ps(t0, t1))
    };
    let ((near_x, far_x), (near_y, far_y), (near_z, far_z)) = (slab(&node.qx, 0), slab(&node.qy, 1), slab(&node.qz, 2));
    let t_enter = _mm256_max_ps(_mm256_max_ps(near_x, near_y), _mm256_max_ps(near_z, _mm256_setzero_ps()));
    let t_exit = _mm256_min_ps(_mm256_min_ps(far_x, far_y), _mm256_min_ps(far_z, _mm256_set1_ps(t_max)));
    let hits = _mm256_castps_si256(_mm256_cmp_ps::<_CMP_LE_OS>(t_enter, t_exit));
    // Each hit child's bits, all eight at once (no branch per child: which children a ray
    // hits is unpredictable): the scalar loop's `child_meta`, `is_inner` and `bit_index`.
    let meta = _mm256_cvtepu8_epi32(_mm_set_epi32(0, 0, node.child_meta[1] as i32, node.child_meta[0] as i32));
    let marker = _mm256_set1_epi32(0x10);
    let is_inner =
        _mm256_cmpeq_epi32(_mm256_and_si256(_mm256_and_si256(meta, _mm256_slli_epi32::<1>(meta)), marker), marker);
    let flip = _mm256_and_si256(is_inner, _mm256_set1_epi32((oct_inv4 & 0xff) as i32));
    let bit_index = _mm256_and_si256(_mm256_xor_si256(meta, flip), _mm256_set1_epi32(0x1f));
    let bits = _mm256_and_si256(_mm256_srli_epi32::<5>(meta), _mm256_set1_epi32(7));
    let m = _mm256_and_si256(_mm256_sllv_epi32(bits, bit_index), hits);
    // OR of the eight lanes.
    let m = _mm_or_si128(_mm256_castsi256_si128(m), _mm256_extracti128_si256::<1>(m));
    let m = _mm_or_si128(m, _mm_shuffle_epi32::<0b01_00_11_10>(m));
    let m = _mm_or_si128(m, _mm_shuffle_epi32::<0b10_11_00_01>(m));
    _mm_cvtsi128_si32(m) as u32
}

/// The leaf triangles `tris` (bits k: triangle `base + k`) of a node against `ray`, eight at a
/// time from the structure-of-arrays copy: per lane the operations of `intersect_triangle` in
/// its order (so the same t, u, v bits), its rejections as masks (a NaN fails them as the
/// scalar comparisons fail). The lanes that beat the closest hit so far are then accepted in
/// the scalar loop's order — descending k, strictly closer, alpha tested — so the hit is the
/// one the scalar loop keeps, ties included. Returns true when an any-hit query is answered.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2,popcnt,lzcnt")]
#[inline]
#[allow(clippy::too_many_arguments)]
unsafe fn intersect_leaves_avx2(
    scene: &PackedScene,
    lanes: Option<&crate::packed::TriangleLanes>,
    ray: &Ray,
    base: u32,
    tris: u32,
    hit: &mut Hit,
    any_hit: bool,
    instance: u32,
) -> bool {
    use std::arch::x86_64::*;
    let Some(lanes) = lanes else { return false };
    let splat = |x: f32| _mm256_set1_ps(x);
    let (dx, dy, dz) = (splat(ray.dir.x), splat(ray.dir.y), splat(ray.dir.z));
    let (ox, oy, oz) = (splat(ray.origin.x), splat(ray.origin.y), splat(ray.origin.z));
    let (zero, one) = (_mm256_setzero_ps(), splat(1.0));
    let mut t_out = [0.0f32; 8];
    let mut u_out = [0.0f32; 8];
    let mut v_out = [0.0f32; 8];
    // Chunks of eight from the highest, as the scalar loop takes k from the highest.
    for chunk in (0..3u32).rev() {
        let bits = (tris >> (8 * chunk)) & 0xff;
        if bits == 0 {
            continue;
        }
        let Some((first, stride)) = lanes.chunk((base + 8 * chunk) as usize) else { continue };
        // SAFETY: an unaligned load of component c's eight floats, inside the arrays
        // (`TriangleLanes::chunk`).
        let load = |c: usize| unsafe { _mm256_loadu_ps(first.add(c * stride)) };
        let (p0x, p0y, p0z) = (load(0), load(1), load(2));
        let (e1x, e1y, e1z) = (load(3), load(4), load(5));
        let (e2x, e2y, e2z) = (load(6), load(7), load(8));
        let mul = |a, b| _mm256_mul_ps(a, b);
        let sub = |a, b| _mm256_sub_ps(a, b);
        let add = |a, b| _mm256_add_ps(a, b);
        // glam's cross and dot, term by term: (a.y b.z − b.y a.z, ...), (x x' + y y') + z z'.
        let cross = |ax, ay, az, bx, by, bz| {
            (sub(mul(ay, bz), mul(by, az)), sub(mul(az, bx), mul(bz, ax)), sub(mul(ax, by), mul(bx, ay)))
        };
        let dot = |ax, ay, az, bx, by, bz| add(add(mul(ax, bx), mul(ay, by)), mul(az, bz));
        let (px, py, pz) = cross(dx, dy, dz, e2x, e2y, e2z);
        let det = dot(e1x, e1y, e1z, px, py, pz);
        let inv_det = _mm256_div_ps(one, det);
        let (tx, ty, tz) = (sub(ox, p0x), sub(oy, p0y), sub(oz, p0z));
        let u = mul(dot(tx, ty, tz, px, py, pz), inv_det);
        let (qx, qy, qz) = cross(tx, ty, tz, e1x, e1y, e1z);
        let v = mul(dot(dx, dy, dz, qx, qy, qz), inv_det);
        let t = mul(dot(e2x, e2y, e2z, qx, qy, qz), inv_det);
        // det != 0, 0 <= u <= 1, !(v < 0), !(u + v > 1).
        let ok = _mm256_and_ps(
            _mm256_and_ps(_mm256_cmp_ps::<_CMP_NEQ_UQ>(det, zero), _mm256_cmp_ps::<_CMP_GE_OQ>(u, zero)),
            _mm256_cmp_ps::<_CMP_LE_OQ>(u, one),
        );
        let ok = _mm256_and_ps(
            _mm256_and_ps(ok, _mm256_cmp_ps::<_CMP_NLT_UQ>(v, zero)),
            _mm256_cmp_ps::<_CMP_NGT_UQ>(add(u, v), one),
        );
        // What intersect_triangle returns: (INF, 0, 0) when a test above fails, (INF, u, v)
        // when only t > 0 does (a miss, yet `hit.t` above INF would take it, as the scalar
        // loop does).
        let inf = splat(INF);
        let u = _mm256_and_ps(u, ok);
        let v = _mm256_and_ps(v, ok);
        let t = _mm256_blendv_ps(inf, t, _mm256_and_ps(ok, _mm256_cmp_ps::<_CMP_GT_OQ>(t, zero)));
        let mut candidates = _mm256_movemask_ps(_mm256_cmp_ps::<_CMP_LT_OQ>(t, splat(hit.t))) as u32 & bits;
        if candidates == 0 {
            continue;
        }
        // SAFETY: stores of eight floats into arrays of eight.
        unsafe {
            _mm256_storeu_ps(t_out.as_mut_ptr(), t);
            _mm256_storeu_ps(u_out.as_mut_ptr(), u);
            _mm256_storeu_ps(v_out.as_mut_ptr(), v);
        }
        while candidates != 0 {
            let k = 31 - candidates.leading_zeros();
            candidates &= !(1 << k);
            let i = base + 8 * chunk + k;
            let (t, u, v) = (t_out[k as usize], u_out[k as usize], v_out[k as usize]);
            let tri = &scene.triangles[i as usize];
            if t < hit.t && (tri.flags & TRI_ALPHA == 0 || alpha_passes(scene, i, u, v, ray)) {
                *hit = Hit { t, tri: i, u, v, instance };
                if any_hit {
                    return true;
                }
            }
        }
    }
    false
}

/// The four bytes of `w` as floats, low byte first (SSE2 unpacks on x86-64: the scalar
/// conversions took a tenth of the walk).
#[inline(always)]
fn byte_lanes(w: u32) -> Vec4 {
    #[cfg(target_arch = "x86_64")]
    {
        use std::arch::x86_64::{
            _mm_cvtepi32_ps, _mm_cvtsi32_si128, _mm_setzero_si128, _mm_unpacklo_epi8, _mm_unpacklo_epi16,
        };
        // SAFETY: SSE2 is part of the x86-64 baseline, so these instructions always exist.
        unsafe {
            let zero = _mm_setzero_si128();
            let words = _mm_unpacklo_epi16(_mm_unpacklo_epi8(_mm_cvtsi32_si128(w as i32), zero), zero);
            Vec4::from(_mm_cvtepi32_ps(words))
        }
    }
    #[cfg(not(target_arch = "x86_64"))]
    Vec4::new((w & 0xff) as f32, (w >> 8 & 0xff) as f32, (w >> 16 & 0xff) as f32, (w >> 24) as f32)
}

/// 1 / dir, with components nearer zero than 2⁻⁸⁰ replaced by ±2⁻⁸⁰, so that a quantised
/// box coordinate of 0 never meets an infinite reciprocal (0 · ∞ = NaN would fail the test).
#[inline(always)]
pub fn safe_inv_dir(dir: Vec3) -> Vec3 {
    const TINY: f32 = 8.271806e-25; // 2⁻⁸⁰
    let fix = |d: f32| {
        if d.abs() >= TINY {
            d
        } else if d < 0.0 {
            -TINY
        } else {
            TINY
        }
    };
    Vec3::ONE / Vec3::new(fix(dir.x), fix(dir.y), fix(dir.z))
}

/// The ray's octant, inverted, in each byte.
#[inline(always)]
pub fn octant_inv4(dir: Vec3) -> u32 {
    (if dir.x < 0.0 { 0 } else { 0x04040404 })
        | (if dir.y < 0.0 { 0 } else { 0x02020202 })
        | (if dir.z < 0.0 { 0 } else { 0x01010101 })
}

/// Closest (or, with `any_hit`, any) hit of `ray` in the mesh BVH at `root`, better than
/// `best`. On x86-64 CPUs with AVX2 (checked once, at run time: the binary targets baseline
/// x86-64) the walk runs compiled for them, testing a node's eight children in one pass and
/// counting bits with POPCNT/LZCNT; it makes the same decisions in the same order with the same
/// roundings as the baseline walk (no FMA contraction: Rust never fuses), so hits are the same
/// bits — tests/bvh.rs holds the two to that.
pub fn trace_blas(scene: &PackedScene, ray: &Ray, root: u32, best: Hit, any_hit: bool, instance: u32) -> Hit {
    #[cfg(target_arch = "x86_64")]
    if wide_walk_available() {
        // SAFETY: the CPU has the features the function is compiled for (checked just above).
        return unsafe { trace_blas_avx2(scene, ray, root, best, any_hit, instance) };
    }
    trace_blas_walk::<false>(scene, ray, root, best, any_hit, instance)
}

/// Whether this CPU runs the AVX2 walk (std caches the CPUID answer).
#[cfg(target_arch = "x86_64")]
#[inline(always)]
pub fn wide_walk_available() -> bool {
    std::arch::is_x86_feature_detected!("avx2")
        && std::arch::is_x86_feature_detected!("popcnt")
        && std::arch::is_x86_feature_detected!("lzcnt")
}

#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2,popcnt,lzcnt")]
unsafe fn trace_blas_avx2(scene: &PackedScene, ray: &Ray, root: u32, best: Hit, any_hit: bool, instance: u32) -> Hit {
    trace_blas_walk::<true>(scene, ray, root, best, any_hit, instance)
}

/// The child mask of a node: eight children at once when `WIDE` (only reached from the AVX2
/// walk), else four at a time.
#[inline(always)]
fn node_mask<const WIDE: bool>(node: &CwNode, origin: Vec3, inv_dir: Vec3, t_max: f32, oct_inv4: u32) -> u32 {
    #[cfg(target_arch = "x86_64")]
    if WIDE {
        // SAFETY: WIDE is true only inside `trace_blas_avx2`, called when the CPU has AVX2.
        return unsafe { intersect_cw_node_avx2(node, origin, inv_dir, t_max, oct_inv4) };
    }
    intersect_cw_node(node, origin, inv_dir, t_max, oct_inv4)
}

/// The walk itself (the shader's loop), for both instruction sets.
#[inline(always)]
fn trace_blas_walk<const WIDE: bool>(
    scene: &PackedScene,
    ray: &Ray,
    root: u32,
    best: Hit,
    any_hit: bool,
    instance: u32,
) -> Hit {
    let lanes = if WIDE { Some(scene.triangle_lanes()) } else { None };
    let mut walk = Walk::new(ray, root, best);
    while !walk.done {
        walk.step::<WIDE>(scene, lanes, ray, any_hit, instance);
    }
    walk.hit
}

/// Two rays' walks in step, one iteration of each in turn: their dependency chains (node
/// load, box test, next node) interleave, so one ray's latencies hide behind the other's
/// work. Each walk is `trace_blas_walk`'s, so the hits are the same bits. Written out for two
/// (a loop over an array of walks, or four walks, lost the gain: BENCHMARKS.md session 29).
#[cfg(target_arch = "x86_64")]
#[inline(always)]
fn trace_blas_walk_pair<const WIDE: bool>(
    scene: &PackedScene,
    rays: [&Ray; 2],
    t_max: [f32; 2],
    any_hit: bool,
) -> [Hit; 2] {
    let lanes = if WIDE { Some(scene.triangle_lanes()) } else { None };
    let start = |t: f32| Hit { t, tri: NO_HIT, u: 0.0, v: 0.0, instance: 0 };
    let mut a = Walk::new(rays[0], 0, start(t_max[0]));
    let mut b = Walk::new(rays[1], 0, start(t_max[1]));
    while !(a.done && b.done) {
        if !a.done {
            a.step::<WIDE>(scene, lanes, rays[0], any_hit, 0);
        }
        if !b.done {
            b.step::<WIDE>(scene, lanes, rays[1], any_hit, 0);
        }
    }
    [a.hit, b.hit]
}

/// A walk's state between iterations of its loop.
struct Walk {
    hit: Hit,
    inv_dir: Vec3,
    oct_inv4: u32,
    // Not zero-filled per ray: only entries below `sp` are ever read, each written first.
    stack: [std::mem::MaybeUninit<UVec2>; STACK_SIZE],
    sp: usize,
    group: UVec2,
    done: bool,
}

impl Walk {
    #[inline(always)]
    fn new(ray: &Ray, root: u32, best: Hit) -> Walk {
        Walk {
            hit: best,
            inv_dir: safe_inv_dir(ray.dir),
            oct_inv4: octant_inv4(ray.dir),
            stack: [std::mem::MaybeUninit::<UVec2>::uninit(); STACK_SIZE],
            sp: 0,
            group: UVec2::new(root, 0x80000000),
            done: false,
        }
    }

    /// One iteration of the walk's loop: the next node's children tested (and its leaves'
    /// triangles), then the next group taken; `done` once the walk has ended.
    #[inline(always)]
    fn step<const WIDE: bool>(
        &mut self,
        scene: &PackedScene,
        lanes: Option<&crate::packed::TriangleLanes>,
        ray: &Ray,
        any_hit: bool,
        instance: u32,
    ) {
        let oct_inv4 = self.oct_inv4;
        if self.group.y > 0x00ffffff {
            let hits = self.group.y;
            let child_bit = 31 - hits.leading_zeros();
            self.group.y = hits & !(1 << child_bit);
            if self.group.y > 0x00ffffff && self.sp < STACK_SIZE {
                self.stack[self.sp].write(self.group);
                self.sp += 1;
            }
            let slot = (child_bit - 24) ^ (oct_inv4 & 0xff);
            let node = load_cw_node(scene, self.group.x + (hits & !(u32::MAX << slot)).count_ones());
            let mask = node_mask::<WIDE>(node, ray.origin, self.inv_dir, self.hit.t, oct_inv4);
            self.group = UVec2::new(node.child_base, (mask & 0xff000000) | (node.e_imask >> 24));
            let mut tris = mask & 0x00ffffff;
            #[cfg(target_arch = "x86_64")]
            if WIDE && tris != 0 {
                // SAFETY: WIDE is true only inside the AVX2 walks, called when the CPU has AVX2.
                if unsafe {
                    intersect_leaves_avx2(
                        scene,
                        lanes,
                        ray,
                        node.primitive_base,
                        tris,
                        &mut self.hit,
                        any_hit,
                        instance,
                    )
                } {
                    self.done = true;
                    return;
                }
                tris = 0;
            }
            #[cfg(not(target_arch = "x86_64"))]
            let _ = lanes;
            while tris != 0 {
                let k = 31 - tris.leading_zeros();
                tris &= !(1 << k);
                let i = node.primitive_base + k;
                let tri = &scene.triangles[i as usize];
                let r = intersect_triangle(ray, tri);
                if r.x < self.hit.t && (tri.flags & TRI_ALPHA == 0 || alpha_passes(scene, i, r.y, r.z, ray)) {
                    self.hit = Hit { t: r.x, tri: i, u: r.y, v: r.z, instance };
                    if any_hit {
                        self.done = true;
                        return;
                    }
                }
            }
        }
        if self.group.y <= 0x00ffffff {
            if self.sp == 0 {
                self.done = true;
                return;
            }
            self.sp -= 1;
            // SAFETY: every entry below the stack pointer was written by the push above.
            self.group = unsafe { self.stack[self.sp].assume_init() };
        }
    }
}

/// The hits of two rays (closest, or any with `any_hit`; each before its `t_max`): in a scene
/// without instances on a CPU with AVX2, their walks run in step (`trace_blas_walk_pair`),
/// else one after the other. Each hit is, bit for bit, the one `trace` finds for its ray.
pub fn trace_pair(scene: &PackedScene, rays: [&Ray; 2], t_max: [f32; 2], any_hit: bool) -> [Hit; 2] {
    #[cfg(target_arch = "x86_64")]
    if scene.instance_count == 0 && wide_walk_available() {
        // SAFETY: the CPU has the features the function is compiled for (checked just above).
        return unsafe { trace_pair_avx2(scene, rays, t_max, any_hit) };
    }
    [trace(scene, rays[0], t_max[0], any_hit), trace(scene, rays[1], t_max[1], any_hit)]
}

#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2,popcnt,lzcnt")]
unsafe fn trace_pair_avx2(scene: &PackedScene, rays: [&Ray; 2], t_max: [f32; 2], any_hit: bool) -> [Hit; 2] {
    trace_blas_walk_pair::<true>(scene, rays, t_max, any_hit)
}

/// The baseline walk, whatever the CPU: the reference the AVX2 walk is tested against.
pub fn trace_baseline(scene: &PackedScene, ray: &Ray, t_max: f32, any_hit: bool) -> Hit {
    trace_walk(scene, ray, t_max, any_hit, |scene, ray, root, best, any_hit, instance| {
        trace_blas_walk::<false>(scene, ray, root, best, any_hit, instance)
    })
}

pub fn trace(scene: &PackedScene, ray: &Ray, t_max: f32, any_hit: bool) -> Hit {
    trace_walk(scene, ray, t_max, any_hit, trace_blas)
}

/// The top-level walk over instances, each instance's mesh walked by `trace_blas`.
#[inline(always)]
fn trace_walk(
    scene: &PackedScene,
    ray: &Ray,
    t_max: f32,
    any_hit: bool,
    trace_blas: impl Fn(&PackedScene, &Ray, u32, Hit, bool, u32) -> Hit,
) -> Hit {
    let mut hit = Hit { t: t_max, tri: NO_HIT, u: 0.0, v: 0.0, instance: 0 };
    if scene.instance_count == 0 {
        return trace_blas(scene, ray, 0, hit, any_hit, 0);
    }
    let nodes = &scene.nodes[..];
    let inv_dir = safe_inv_dir(ray.dir);
    let mut stack = [0u32; TLAS_STACK_SIZE];
    let mut sp = 0usize;
    let mut index = 0usize;
    if intersect_node(&nodes[0], ray.origin, inv_dir, hit.t) == INF {
        return hit;
    }
    loop {
        let node = &nodes[index];
        if node.count > 0 {
            for k in node.index..node.index + node.count {
                let inst = load_instance(scene, k);
                let local = Ray {
                    origin: transform_point(&inst.world_to_object, ray.origin),
                    dir: transform_dir(&inst.world_to_object, ray.dir),
                };
                hit = trace_blas(scene, &local, inst.blas_root, hit, any_hit, k);
                if any_hit && hit.tri != NO_HIT {
                    return hit;
                }
            }
        } else {
            let (left, right) = (node.index as usize, node.index as usize + 1);
            let t_left = intersect_node(&nodes[left], ray.origin, inv_dir, hit.t);
            let t_right = intersect_node(&nodes[right], ray.origin, inv_dir, hit.t);
            if t_left != INF && t_right != INF {
                let near_is_left = t_left <= t_right;
                if sp < TLAS_STACK_SIZE {
                    stack[sp] = if near_is_left { right } else { left } as u32;
                    sp += 1;
                }
                index = if near_is_left { left } else { right };
                continue;
            }
            if t_left != INF {
                index = left;
                continue;
            }
            if t_right != INF {
                index = right;
                continue;
            }
        }
        if sp == 0 {
            break;
        }
        sp -= 1;
        index = stack[sp] as usize;
    }
    hit
}

pub fn intersect_closest(scene: &PackedScene, ray: &Ray) -> Hit {
    trace(scene, ray, INF, false)
}

pub fn occluded(scene: &PackedScene, ray: &Ray, t_max: f32) -> bool {
    trace(scene, ray, t_max, true).tri != NO_HIT
}

/// The closest hits of a batch of rays, `hits[i]` for `rays[i]` (rays in order; a batch API
/// for engines and tools that trace many rays at once: the benchmark's throughput, a
/// wavefront's stage). Two at a time (`trace_pair`), as the renderer traces them.
pub fn intersect_closest_batch(scene: &PackedScene, rays: &[Ray], hits: &mut [Hit]) {
    let n = rays.len().min(hits.len());
    let (rays, hits) = (&rays[..n], &mut hits[..n]);
    for (r, h) in rays.chunks(2).zip(hits.chunks_mut(2)) {
        match r {
            [a, b] => h.copy_from_slice(&trace_pair(scene, [a, b], [INF; 2], false)),
            _ => h[0] = intersect_closest(scene, &r[0]),
        }
    }
}

/// Occlusion of a batch of segments: `blocked[i]` when something lies on `rays[i]` before
/// `t_max[i]` (any hit). Two at a time (`trace_pair`), as the renderer traces them.
pub fn occluded_batch(scene: &PackedScene, rays: &[Ray], t_max: &[f32], blocked: &mut [bool]) {
    let n = rays.len().min(t_max.len()).min(blocked.len());
    let (rays, t_max, blocked) = (&rays[..n], &t_max[..n], &mut blocked[..n]);
    for ((r, t), b) in rays.chunks(2).zip(t_max.chunks(2)).zip(blocked.chunks_mut(2)) {
        match (r, t) {
            ([ra, rb], &[ta, tb]) => {
                let [ha, hb] = trace_pair(scene, [ra, rb], [ta, tb], true);
                b.copy_from_slice(&[ha.tri != NO_HIT, hb.tri != NO_HIT]);
            }
            _ => b[0] = occluded(scene, &r[0], t[0]),
        }
    }
}

pub fn offset_ray(p: Vec3, n: Vec3) -> Vec3 {
    let of_i = (256.0 * n).as_ivec3();
    let bump =
        |pc: f32, o: i32| f32::from_bits((pc.to_bits() as i32).wrapping_add(if pc < 0.0 { -o } else { o }) as u32);
    let p_i = Vec3::new(bump(p.x, of_i.x), bump(p.y, of_i.y), bump(p.z, of_i.z));
    let pick = |pc: f32, pi: f32, nc: f32| if pc.abs() < 1.0 / 32.0 { pc + (1.0 / 65536.0) * nc } else { pi };
    let _: IVec3 = of_i;
    Vec3::new(pick(p.x, p_i.x, n.x), pick(p.y, p_i.y, n.y), pick(p.z, p_i.z, n.z))
}
