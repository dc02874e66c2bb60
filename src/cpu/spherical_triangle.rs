//! Twin of `shaders/spherical_triangle.wgsl`: sampling a triangle uniformly in the solid
//! angle it subtends (Arvo 1995, in the form pbrt-v4 uses), for the light tree's triangles.
//! Below `SOLID_ANGLE_MIN` (tiny or distant triangles, where area sampling is as good and
//! the spherical formulas lose precision) and above `SOLID_ANGLE_MAX` (nearly a hemisphere)
//! the light sampler samples by area instead; sampling and the pdf of a BSDF hit take the
//! same branch through `spherical_triangle_area`. Within the range the sample square is
//! first warped towards the receiver's cosine (`lights::receiver_cosine_weights`), and a BSDF
//! hit reads that warp's density through `invert_spherical_triangle_sample`.

use super::trig::{atan2, bounded_cos, bounded_sin};
use glam::{Vec2, Vec3};

/// Below 0.1 sr (a cone of ~10° half-angle; a right triangle of area 0.5 seen from 2.2 units
/// away) the inverse-square and cosine factors vary little over the triangle, so area
/// sampling's noise is close to solid angle sampling's at a fraction of the cost: on the
/// Cornell box 1.6 % more error per sample for 1.2× the samples per second, 7 % less error at
/// equal time (BENCHMARKS.md, session 20; 0.02 before, session 15).
pub const SOLID_ANGLE_MIN: f32 = 0.1;
pub const SOLID_ANGLE_MAX: f32 = 6.22;

/// Whether the triangle's solid angle from `p` is surely below `SOLID_ANGLE_MIN`, without
/// the exact formula's three normalisations and arc tangent. Two bounds: the triangle lies in
/// the ball of radius r about its centroid c, whose cap subtends 2π(1 − √(1 − r²/d²)) ≤
/// 2π r²/d² (d = |p − c|; when p is inside the ball the bound exceeds 2π and never skips);
/// and every point x of the triangle is at least d − r from p, so Ω = ∫ h/|x − p|³ dA ≤
/// A·h/(d − r)³, h the distance to its plane (A·h = |(e1 × e2)·(p − p0)|/2: no square root
/// but d's and r's) — the one that skips the points near a lamp but off to its side, where
/// the ball's cap is large (the walls and ceiling of the Cornell box). Widened by 1 % and 10 %
/// so rounding never skips a triangle the exact formula would keep: the choice is the same.
pub fn surely_below_solid_angle_min(p: Vec3, p0: Vec3, e1: Vec3, e2: Vec3) -> bool {
    let c = p0 + (e1 + e2) * (1.0 / 3.0);
    let r2 = (p0 - c).length_squared().max((p0 + e1 - c).length_squared()).max((p0 + e2 - c).length_squared());
    let d2 = (p - c).length_squared();
    if 6.35 * r2 < SOLID_ANGLE_MIN * d2 {
        return true;
    }
    let gap = d2.sqrt() - r2.sqrt();
    gap > 0.0 && 0.55 * e1.cross(e2).dot(p - p0).abs() < SOLID_ANGLE_MIN * (gap * gap * gap)
}

/// The solid angle of the triangle (v0, v1, v2) seen from `p` (van Oosterom & Strackee).
pub fn spherical_triangle_area(p: Vec3, v0: Vec3, v1: Vec3, v2: Vec3) -> f32 {
    unit_triangle_area((v0 - p).normalize_or_zero(), (v1 - p).normalize_or_zero(), (v2 - p).normalize_or_zero())
}

/// The angle between unit vectors, 2·atan(|a − b| / |a + b|): accurate near 0 and π.
fn angle_between(a: Vec3, b: Vec3) -> f32 {
    2.0 * atan2((a - b).length(), (a + b).length())
}

/// `v` made orthogonal to unit `w`, normalised.
fn orthonormal_part(v: Vec3, w: Vec3) -> Vec3 {
    (v - w * v.dot(w)).normalize_or_zero()
}

/// A direction from `p` uniformly distributed over the triangle's solid angle (its density
/// is 1 / `spherical_triangle_area`), or None when the triangle is degenerate from `p`.
pub fn sample_spherical_triangle(p: Vec3, v0: Vec3, v1: Vec3, v2: Vec3, u0: f32, u1: f32) -> Option<Vec3> {
    let a = (v0 - p).normalize_or_zero();
    let b = (v1 - p).normalize_or_zero();
    let c = (v2 - p).normalize_or_zero();
    let (n_ab, n_bc, n_ca) = (a.cross(b), b.cross(c), c.cross(a));
    if n_ab.length_squared() == 0.0 || n_bc.length_squared() == 0.0 || n_ca.length_squared() == 0.0 {
        return None;
    }
    let (n_ab, n_ca) = (n_ab.normalize(), n_ca.normalize());
    // The angle at a; the area by van Oosterom–Strackee (as `spherical_triangle_area` and the
    // inversion compute it: the angle sum α + β + γ − π loses small triangles in f32).
    let alpha = angle_between(n_ab, -n_ca);
    let area = unit_triangle_area(a, b, c);
    if area.is_nan() || area <= 0.0 {
        return None;
    }
    // The sub-triangle of area A' = u0·A fixes c' on the arc a→c; sin and cos are taken of
    // A' − α, which lies in [−π, π] (WGSL's sin and cos are only bounded there).
    let ap = u0 * area;
    let d = ap - alpha;
    let (sin_phi, cos_phi) = (-bounded_sin(d), -bounded_cos(d));
    let (sin_alpha, cos_alpha) = (bounded_sin(alpha), bounded_cos(alpha));
    let k1 = cos_phi + cos_alpha;
    let k2 = sin_phi - sin_alpha * a.dot(b);
    let cos_bp = ((k2 + (k2 * cos_phi - k1 * sin_phi) * cos_alpha) / ((k2 * sin_phi + k1 * cos_phi) * sin_alpha))
        .clamp(-1.0, 1.0);
    if cos_bp.is_nan() {
        return None;
    }
    let sin_bp = (1.0 - cos_bp * cos_bp).max(0.0).sqrt();
    let cp = cos_bp * a + sin_bp * orthonormal_part(c, a);
    // u1 picks the point on the arc b→c'; 1 − x·y = ½|x − y|² keeps the small differences.
    let cos_theta = 1.0 - u1 * 0.5 * (cp - b).length_squared();
    let sin_theta = (1.0 - cos_theta * cos_theta).max(0.0).sqrt();
    let w = cos_theta * b + sin_theta * orthonormal_part(cp, b);
    if !w.is_finite() {
        return None;
    }
    Some(w.normalize())
}

/// The (u0, u1) that `sample_spherical_triangle` maps to the direction `w` (Arvo's
/// inversion, as pbrt-v4 does it, but with both areas from the van Oosterom–Strackee formula:
/// the angle sum loses the small sub-triangles in f32, and pbrt's 0.1° cut-off near vertex 0
/// moves u0 by percents on small triangles). The density of a BSDF hit under the
/// receiver-cosine warp is read there. (0.5, 0.5) when the triangle is degenerate from `p`.
pub fn invert_spherical_triangle_sample(p: Vec3, v0: Vec3, v1: Vec3, v2: Vec3, w: Vec3) -> Vec2 {
    let centre = Vec2::splat(0.5);
    let a = (v0 - p).normalize_or_zero();
    let b = (v1 - p).normalize_or_zero();
    let c = (v2 - p).normalize_or_zero();
    // c': where the great circle through b and w meets the arc a→c.
    let mut cp = b.cross(w).cross(c.cross(a)).normalize_or_zero();
    if cp.dot(a + c) < 0.0 {
        cp = -cp;
    }
    let area = unit_triangle_area(a, b, c);
    let u0 = unit_triangle_area(a, b, cp) / area;
    // 1 − x·y as ½|x − y|², as the sampling computes it.
    let u1 = (w - b).length_squared() / (cp - b).length_squared();
    let u = Vec2::new(u0, u1);
    if u.is_finite() { u.clamp(Vec2::ZERO, Vec2::ONE) } else { centre }
}

/// The solid angle of the spherical triangle of unit vectors a, b, c.
fn unit_triangle_area(a: Vec3, b: Vec3, c: Vec3) -> f32 {
    (2.0 * atan2(a.dot(b.cross(c)), 1.0 + a.dot(b) + a.dot(c) + b.dot(c))).abs()
}
