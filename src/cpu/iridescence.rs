//! Twin of `shaders/iridescence.wgsl`: KHR_materials_iridescence's thin film, the analytic
//! Airy reflectance of a dielectric film over the base integrated against the CIE observer
//! in Fourier space (Belcour & Barla 2017, "A Practical Extension to Microfacet Theory for the
//! Modeling of Varying Iridescence"), two harmonics, as the extension's reference does.

use glam::{Mat3, Vec3};
use std::f32::consts::PI;

/// XYZ → linear Rec.709 (columns).
const XYZ_TO_REC709: Mat3 = Mat3::from_cols(
    Vec3::new(3.240_454_2, -0.969_266, 0.055_643_4),
    Vec3::new(-1.537_138_5, 1.876_010_8, -0.204_025_9),
    Vec3::new(-0.498_531_4, 0.041_556, 1.057_225_2),
);

pub fn ior_to_fresnel0(transmitted: f32, incident: f32) -> f32 {
    let r = (transmitted - incident) / (transmitted + incident);
    r * r
}

/// The ior of a dielectric of normal reflectance f0 (per channel, f0 < 1).
pub fn fresnel0_to_ior(f0: Vec3) -> Vec3 {
    let s = f0.clamp(Vec3::ZERO, Vec3::splat(0.9999)).map(f32::sqrt);
    (Vec3::ONE + s) / (Vec3::ONE - s)
}

/// The CIE sensitivity's Fourier transform at optical path difference `opd` (nm), as RGB.
pub fn eval_sensitivity(opd: f32, shift: Vec3) -> Vec3 {
    let phase = 2.0 * PI * opd * 1e-9;
    let val = Vec3::new(5.4856e-13, 4.4201e-13, 5.2481e-13);
    let pos = Vec3::new(1.6810e6, 1.7953e6, 2.2084e6);
    let var = Vec3::new(4.3278e9, 9.3046e9, 6.6121e9);
    let arg = pos * phase + shift;
    let mut xyz = val
        * (2.0 * PI * var).map(f32::sqrt)
        * Vec3::new(arg.x.cos(), arg.y.cos(), arg.z.cos())
        * (-phase * phase * var).map(f32::exp);
    xyz.x += 9.7470e-14
        * (2.0 * PI * 4.5282e9f32).sqrt()
        * (2.2399e6 * phase + shift.x).cos()
        * (-4.5282e9 * phase * phase).exp();
    XYZ_TO_REC709 * (xyz / 1.0685e-7)
}

/// Reflectance of a film of ior `film_ior` and `thickness` nm between the outside (ior
/// `outside`) and a base of normal reflectance `base_f0`, at incidence cos θ1; in [0, 1].
pub fn iridescence_fresnel(outside: f32, film_ior: f32, cos_theta1: f32, thickness: f32, base_f0: Vec3) -> Vec3 {
    // A vanishing film is no film.
    let t = (thickness / 0.03).clamp(0.0, 1.0);
    let film = outside + (film_ior - outside) * (t * t * (3.0 - 2.0 * t));
    let c1 = cos_theta1.clamp(0.0, 1.0);
    let sin2_t2 = (outside / film) * (outside / film) * (1.0 - c1 * c1);
    let cos2_t2 = 1.0 - sin2_t2;
    if cos2_t2 < 0.0 {
        return Vec3::ONE;
    }
    let c2 = cos2_t2.sqrt();
    let schlick = |f0: f32, c: f32| {
        let m = (1.0 - c).clamp(0.0, 1.0);
        f0 + (1.0 - f0) * m * m * m * m * m
    };
    // First interface (outside → film) and its phase shift.
    let r12 = schlick(ior_to_fresnel0(film, outside), c1);
    let t121 = 1.0 - r12;
    let phi12 = if film < outside { PI } else { 0.0 };
    let phi21 = PI - phi12;
    // Second interface (film → base).
    let base_ior = fresnel0_to_ior(base_f0);
    let r1 = base_ior.map(|b| ior_to_fresnel0(b, film));
    let r23 = r1.map(|f| schlick(f, c2));
    let phi23 = base_ior.map(|b| if b < film { PI } else { 0.0 });
    let opd = 2.0 * film * thickness * c2;
    let phi = Vec3::splat(phi21) + phi23;
    let r123 = (r12 * r23).clamp(Vec3::splat(1e-5), Vec3::splat(0.9999));
    let sqrt_r123 = r123.map(f32::sqrt);
    let rs = t121 * t121 * r23 / (Vec3::ONE - r123);
    let mut i = r12 + rs;
    let mut cm = rs - t121;
    for m in 1..=2 {
        cm *= sqrt_r123;
        i += cm * 2.0 * eval_sensitivity(m as f32 * opd, m as f32 * phi);
    }
    i.clamp(Vec3::ZERO, Vec3::ONE)
}
