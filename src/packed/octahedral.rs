//! Octahedral unit-vector encoding (Cigolle et al. 2014) into `pack2x16snorm` bits: the
//! normals and tangents of `Attributes`.

use glam::{Vec2, Vec3};

/// Octahedral normal encoding into `pack2x16snorm` bits (decoded by `oct_decode`).
pub fn oct_encode(n: Vec3) -> u32 {
    let n = n / (n.x.abs() + n.y.abs() + n.z.abs()).max(1e-30);
    let mut e = Vec2::new(n.x, n.y);
    if n.z < 0.0 {
        let s = Vec2::new(if n.x >= 0.0 { 1.0 } else { -1.0 }, if n.y >= 0.0 { 1.0 } else { -1.0 });
        e = (Vec2::ONE - Vec2::new(n.y.abs(), n.x.abs())) * s;
    }
    let q = |v: f32| ((v.clamp(-1.0, 1.0) * 32767.0).round() as i16) as u16 as u32;
    q(e.x) | (q(e.y) << 16)
}

/// WGSL's `unpack2x16snorm` followed by the octahedral decode.
pub fn oct_decode(bits: u32) -> Vec3 {
    let u = |b: u32| ((b as u16 as i16) as f32 / 32767.0).max(-1.0);
    let (x, y) = (u(bits & 0xffff), u(bits >> 16));
    let z = 1.0 - x.abs() - y.abs();
    let t = (-z).max(0.0);
    let x = x + if x >= 0.0 { -t } else { t };
    let y = y + if y >= 0.0 { -t } else { t };
    Vec3::new(x, y, z).normalize()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn octahedral_normals_round_trip() {
        for i in 0..1000 {
            let a = i as f32 * 0.37;
            let b = (i as f32 * 0.11).sin();
            let n = Vec3::new(a.cos() * (1.0 - b * b).sqrt(), a.sin() * (1.0 - b * b).sqrt(), b).normalize();
            let d = oct_decode(oct_encode(n));
            assert!(d.dot(n) > 0.99999, "{n} -> {d}");
        }
    }
}
