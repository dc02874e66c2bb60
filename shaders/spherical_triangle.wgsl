// Sampling a triangle uniformly in the solid angle it subtends (Arvo 1995, in the form
// pbrt-v4 uses), for the light tree's triangles; below SOLID_ANGLE_MIN and above
// SOLID_ANGLE_MAX the light sampler samples by area instead, and the pdf of a BSDF hit takes
// the same branch through `spherical_triangle_area`. Twin: src/cpu/spherical_triangle.rs.
#include "common.wgsl"

const SOLID_ANGLE_MIN: f32 = 0.1;
const SOLID_ANGLE_MAX: f32 = 6.22;

fn normalize_or_zero(v: vec3<f32>) -> vec3<f32> {
    let len2 = dot(v, v);
    return select(vec3<f32>(0.0), v * (1.0 / sqrt(len2)), len2 > 0.0);
}

// Whether the triangle's solid angle from `p` is surely below SOLID_ANGLE_MIN, without the
// exact formula: the triangle lies in the ball of radius r about its centroid c, whose cap
// subtends at most 2π r²/d² (d = |p − c|), and each of its points is at least d − r from p,
// so Ω ≤ A·h/(d − r)³ (A·h = |(e1 × e2)·(p − p0)|/2); widened by 1 % and 10 % so rounding
// never skips a triangle the exact formula keeps.
fn surely_below_solid_angle_min(p: vec3<f32>, p0: vec3<f32>, e1: vec3<f32>, e2: vec3<f32>) -> bool {
    let c = p0 + (e1 + e2) * (1.0 / 3.0);
    let a = p0 - c;
    let b = p0 + e1 - c;
    let d = p0 + e2 - c;
    let r2 = max(max(dot(a, a), dot(b, b)), dot(d, d));
    let pc = p - c;
    let d2 = dot(pc, pc);
    if (6.35 * r2 < SOLID_ANGLE_MIN * d2) {
        return true;
    }
    let gap = sqrt(d2) - sqrt(r2);
    return gap > 0.0 && 0.55 * abs(dot(cross(e1, e2), p - p0)) < SOLID_ANGLE_MIN * (gap * gap * gap);
}

// The solid angle of the triangle seen from `p` (van Oosterom & Strackee).
fn spherical_triangle_area(p: vec3<f32>, v0: vec3<f32>, v1: vec3<f32>, v2: vec3<f32>) -> f32 {
    return unit_triangle_area(normalize_or_zero(v0 - p), normalize_or_zero(v1 - p), normalize_or_zero(v2 - p));
}

// sin x for |x| ≤ π by our own polynomial (Taylor to x¹³ on [−π/2, π/2]), the same
// operations as the Rust twin: WGSL bounds its sin and cos only to 2⁻¹¹ absolute.
fn bounded_sin(x: f32) -> f32 {
    var y = x;
    if (x > 0.5 * PI) {
        y = PI - x;
    } else if (x < -0.5 * PI) {
        y = -PI - x;
    }
    let y2 = y * y;
    var p = 1.0 / 6227020800.0;
    p = -1.0 / 39916800.0 + y2 * p;
    p = 1.0 / 362880.0 + y2 * p;
    p = -1.0 / 5040.0 + y2 * p;
    p = 1.0 / 120.0 + y2 * p;
    p = -1.0 / 6.0 + y2 * p;
    return y * (1.0 + y2 * p);
}

// cos x for |x| ≤ π, as sin(x + π/2) brought back into [−π, π].
fn bounded_cos(x: f32) -> f32 {
    let y = x + 0.5 * PI;
    return bounded_sin(select(y, y - 2.0 * PI, y > PI));
}

// The angle between unit vectors, 2·atan(|a − b| / |a + b|): accurate near 0 and π.
fn angle_between(a: vec3<f32>, b: vec3<f32>) -> f32 {
    return 2.0 * atan2(length(a - b), length(a + b));
}

fn orthonormal_part(v: vec3<f32>, w: vec3<f32>) -> vec3<f32> {
    return normalize_or_zero(v - w * dot(v, w));
}

struct SphericalSample {
    w: vec3<f32>,
    ok: bool,
}

// A direction from `p` uniform over the triangle's solid angle, or ok = false when the
// triangle is degenerate from `p`.
fn sample_spherical_triangle(
    p: vec3<f32>, v0: vec3<f32>, v1: vec3<f32>, v2: vec3<f32>, u0: f32, u1: f32
) -> SphericalSample {
    let fail = SphericalSample(vec3<f32>(0.0), false);
    let a = normalize_or_zero(v0 - p);
    let b = normalize_or_zero(v1 - p);
    let c = normalize_or_zero(v2 - p);
    let n_ab = cross(a, b);
    let n_bc = cross(b, c);
    let n_ca = cross(c, a);
    if (dot(n_ab, n_ab) == 0.0 || dot(n_bc, n_bc) == 0.0 || dot(n_ca, n_ca) == 0.0) {
        return fail;
    }
    // The angle at a; the area by van Oosterom–Strackee, as the pdf and the inversion
    // compute it (the angle sum α + β + γ − π loses small triangles in f32).
    let alpha = angle_between(normalize(n_ab), -normalize(n_ca));
    let area = unit_triangle_area(a, b, c);
    if (!(area > 0.0)) {
        return fail;
    }
    // sin and cos of A' − α, which lies in [−π, π] where WGSL bounds their error.
    let d = u0 * area - alpha;
    let sin_phi = -bounded_sin(d);
    let cos_phi = -bounded_cos(d);
    let sin_alpha = bounded_sin(alpha);
    let cos_alpha = bounded_cos(alpha);
    let k1 = cos_phi + cos_alpha;
    let k2 = sin_phi - sin_alpha * dot(a, b);
    let num = k2 + (k2 * cos_phi - k1 * sin_phi) * cos_alpha;
    let cos_bp = clamp(num / ((k2 * sin_phi + k1 * cos_phi) * sin_alpha), -1.0, 1.0);
    if (cos_bp != cos_bp) {
        return fail;
    }
    let sin_bp = sqrt(max(1.0 - cos_bp * cos_bp, 0.0));
    let cp = cos_bp * a + sin_bp * orthonormal_part(c, a);
    let cp_b = cp - b;
    let cos_theta = 1.0 - u1 * 0.5 * dot(cp_b, cp_b);
    let sin_theta = sqrt(max(1.0 - cos_theta * cos_theta, 0.0));
    let w = cos_theta * b + sin_theta * orthonormal_part(cp, b);
    if (!is_finite_vec3(w)) {
        return fail;
    }
    return SphericalSample(normalize(w), true);
}

// The (u0, u1) that `sample_spherical_triangle` maps to the direction `w` (Arvo's
// inversion, with both areas from the van Oosterom–Strackee formula, which keeps small
// sub-triangles in f32), for the density of a BSDF hit under the receiver-cosine warp.
fn invert_spherical_triangle_sample(
    p: vec3<f32>, v0: vec3<f32>, v1: vec3<f32>, v2: vec3<f32>, w: vec3<f32>
) -> vec2<f32> {
    let a = normalize_or_zero(v0 - p);
    let b = normalize_or_zero(v1 - p);
    let c = normalize_or_zero(v2 - p);
    // c': where the great circle through b and w meets the arc a→c.
    var cp = normalize_or_zero(cross(cross(b, w), cross(c, a)));
    if (dot(cp, a + c) < 0.0) {
        cp = -cp;
    }
    let u0 = unit_triangle_area(a, b, cp) / unit_triangle_area(a, b, c);
    // 1 − x·y as ½|x − y|², as the sampling computes it.
    let w_b = w - b;
    let cp_b = cp - b;
    let u = vec2<f32>(u0, dot(w_b, w_b) / dot(cp_b, cp_b));
    if (!(abs(u.x) < INF && abs(u.y) < INF)) {
        return vec2<f32>(0.5);
    }
    return clamp(u, vec2<f32>(0.0), vec2<f32>(1.0));
}

// The solid angle of the spherical triangle of unit vectors a, b, c.
fn unit_triangle_area(a: vec3<f32>, b: vec3<f32>, c: vec3<f32>) -> f32 {
    return abs(2.0 * atan2(dot(a, cross(b, c)), 1.0 + dot(a, b) + dot(a, c) + dot(b, c)));
}
