//! Twin of `shaders/frame.wgsl`: shading frames, world ↔ local (normal = +z).

use glam::Vec3;

#[derive(Clone, Copy, Debug)]
pub struct Frame {
    pub t: Vec3,
    pub b: Vec3,
    pub n: Vec3,
}

pub fn frame_from_normal(n: Vec3) -> Frame {
    let s = if n.z >= 0.0 { 1.0 } else { -1.0 };
    let a = -1.0 / (s + n.z);
    let b = n.x * n.y * a;
    let t = Vec3::new(1.0 + s * n.x * n.x * a, s * b, -s * n.x);
    let bt = Vec3::new(b, s + n.y * n.y * a, -n.y);
    Frame { t, b: bt, n }
}

pub fn to_local(f: &Frame, v: Vec3) -> Vec3 {
    Vec3::new(v.dot(f.t), v.dot(f.b), v.dot(f.n))
}

pub fn from_local(f: &Frame, v: Vec3) -> Vec3 {
    f.t * v.x + f.b * v.y + f.n * v.z
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn frames_are_orthonormal_and_invert() {
        for i in 0..500 {
            let a = i as f32 * 0.731;
            let z = (i as f32 * 0.0041) * 2.0 - 1.0;
            let r = (1.0 - z * z).max(0.0).sqrt();
            let n = Vec3::new(r * a.cos(), r * a.sin(), z).normalize();
            let f = frame_from_normal(n);
            assert!(f.t.dot(f.b).abs() < 1e-5 && f.t.dot(f.n).abs() < 1e-5 && f.b.dot(f.n).abs() < 1e-5);
            assert!((f.t.cross(f.b) - f.n).length() < 1e-5, "right-handed");
            let v = Vec3::new(0.3, -0.5, 0.81).normalize();
            assert!((from_local(&f, to_local(&f, v)) - v).length() < 1e-5);
            assert!((to_local(&f, n) - Vec3::Z).length() < 1e-5);
        }
    }
}
