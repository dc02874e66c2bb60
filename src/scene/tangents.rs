//! Tangent frames for normal maps, when a mesh brings UVs but no TANGENT attribute.
//!
//! Per triangle, the tangent T and bitangent B solve ΔPos = ΔUV.x·T + ΔUV.y·B for both edges
//! (the theory's "Tangents and bitangents based on UVs"); each vertex averages the T and B of
//! its triangles, then T is made orthogonal to the vertex normal (Gram-Schmidt) and the
//! handedness w = ±1 records whether the normal map's +Y agrees with cross(N, T), so mirrored
//! UV islands keep their bumps the right way round.
//!
//! glTF's v runs down the image while normal maps store +Y up the image (the OpenGL
//! convention, as MikkTSpace sees UVs after loaders flip v): the map's +Y is −B, not B.

use glam::{Vec2, Vec3, Vec4};

/// The tangent and bitangent of one triangle (unnormalised: they carry the UV scale), or
/// None when its UVs are degenerate.
pub fn triangle_tangent(p: [Vec3; 3], uv: [Vec2; 3]) -> Option<(Vec3, Vec3)> {
    let (dp1, dp2) = (p[1] - p[0], p[2] - p[0]);
    let (duv1, duv2) = (uv[1] - uv[0], uv[2] - uv[0]);
    let det = duv2.y * duv1.x - duv1.y * duv2.x;
    if det.abs() < 1e-20 || !det.is_finite() {
        return None;
    }
    let t = (duv2.y * dp1 - duv1.y * dp2) / det;
    let b = (duv1.x * dp2 - duv2.x * dp1) / det;
    (t.is_finite() && b.is_finite()).then_some((t, b))
}

/// Per-vertex tangents (xyz unit, w = ±1) for an indexed triangle mesh; vertices touched only
/// by degenerate triangles get a tangent perpendicular to their normal.
pub fn generate_tangents(positions: &[Vec3], normals: &[Vec3], uvs: &[Vec2], triangles: &[[u32; 3]]) -> Vec<Vec4> {
    let mut t_sum = vec![Vec3::ZERO; positions.len()];
    let mut b_sum = vec![Vec3::ZERO; positions.len()];
    for tri in triangles {
        let idx = tri.map(|i| i as usize);
        if idx.iter().any(|&i| i >= positions.len() || i >= uvs.len()) {
            continue;
        }
        if let Some((t, b)) = triangle_tangent(idx.map(|i| positions[i]), idx.map(|i| uvs[i])) {
            // Weight by the triangle's area in UV-normalised form: larger faces count more.
            for i in idx {
                t_sum[i] += t;
                b_sum[i] += b;
            }
        }
    }
    (0..positions.len())
        .map(|i| {
            let n = normals.get(i).copied().unwrap_or(Vec3::Z);
            orthonormal_tangent(n, t_sum[i], b_sum[i])
        })
        .collect()
}

/// Gram-Schmidt of `t` against `n`, with the handedness of the normal map's +Y (= −b, b being
/// ∂P/∂v) relative to cross(n, t).
pub fn orthonormal_tangent(n: Vec3, t: Vec3, b: Vec3) -> Vec4 {
    let mut tt = (t - n * n.dot(t)).normalize_or_zero();
    if tt == Vec3::ZERO {
        tt = n.any_orthonormal_vector();
    }
    let w = if n.cross(tt).dot(-b) < 0.0 { -1.0 } else { 1.0 };
    tt.extend(w)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn seed_formula_on_a_known_triangle() {
        // UV axes along world x and y with a scale: T = dP/du, B = dP/dv exactly.
        let p = [Vec3::new(0.0, 0.0, 0.0), Vec3::new(2.0, 0.0, 0.0), Vec3::new(0.0, 4.0, 0.0)];
        let uv = [Vec2::new(0.0, 0.0), Vec2::new(1.0, 0.0), Vec2::new(0.0, 1.0)];
        let (t, b) = triangle_tangent(p, uv).unwrap();
        assert!((t - Vec3::new(2.0, 0.0, 0.0)).length() < 1e-6, "{t}");
        assert!((b - Vec3::new(0.0, 4.0, 0.0)).length() < 1e-6, "{b}");
        // A skewed, rotated case: both edges must be reproduced, ΔPos = ΔUV.x·T + ΔUV.y·B.
        let p = [Vec3::new(1.0, 2.0, 3.0), Vec3::new(1.5, 2.7, 2.0), Vec3::new(-0.3, 2.2, 3.9)];
        let uv = [Vec2::new(0.1, 0.9), Vec2::new(0.6, 0.7), Vec2::new(0.2, 0.3)];
        let (t, b) = triangle_tangent(p, uv).unwrap();
        for k in 1..3 {
            let duv = uv[k] - uv[0];
            let dp = p[k] - p[0];
            assert!((duv.x * t + duv.y * b - dp).length() < 1e-5);
        }
        assert!(triangle_tangent(p, [Vec2::ZERO; 3]).is_none());
    }

    #[test]
    fn mirrored_uvs_flip_the_handedness() {
        // A quad facing +z showing its image upright: u along +x, v (down the image) along −y.
        let p = [Vec3::ZERO, Vec3::X, -Vec3::Y];
        let n = [Vec3::Z; 3];
        let straight = generate_tangents(&p, &n, &[Vec2::ZERO, Vec2::X, Vec2::Y], &[[0, 1, 2]]);
        // The map's +Y (up the image) is world +y = cross(N, T): right-handed.
        assert_eq!(straight[0], Vec4::new(1.0, 0.0, 0.0, 1.0));
        // Mirrored: u runs along −x. T points to −x, and B = cross(N, T)·w must still be +y.
        let mirrored = generate_tangents(&p, &n, &[Vec2::ZERO, -Vec2::X, Vec2::Y], &[[0, 1, 2]]);
        assert_eq!(mirrored[0], Vec4::new(-1.0, 0.0, 0.0, -1.0));
        let b = Vec3::Z.cross(mirrored[0].truncate()) * mirrored[0].w;
        assert!((b - Vec3::Y).length() < 1e-6);
    }
}
