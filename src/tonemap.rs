//! Twin of `shaders/tonemap.wgsl`: the tone mappers of PNG output and the viewer.

use glam::{Mat3, Vec3};

#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
#[cfg_attr(feature = "cli", derive(clap::ValueEnum))]
#[repr(u32)]
pub enum Tonemap {
    /// Exposure, then clamp to [0, 1].
    #[default]
    Clamp = 0,
    /// Narkowicz's fit of ACES filmic.
    Aces = 1,
    /// Troy Sobotka's AgX.
    Agx = 2,
    /// Khronos PBR Neutral.
    Neutral = 3,
}

impl Tonemap {
    pub const ALL: [Tonemap; 4] = [Tonemap::Clamp, Tonemap::Aces, Tonemap::Agx, Tonemap::Neutral];

    pub fn name(self) -> &'static str {
        match self {
            Tonemap::Clamp => "linear clamp",
            Tonemap::Aces => "ACES",
            Tonemap::Agx => "AgX",
            Tonemap::Neutral => "Khronos PBR Neutral",
        }
    }
}

pub fn tonemap_aces(x: Vec3) -> Vec3 {
    ((x * (2.51 * x + 0.03)) / (x * (2.43 * x + 0.59) + 0.14)).clamp(Vec3::ZERO, Vec3::ONE)
}

// The matrices keep the published digits so the twin reads like the WGSL.
#[allow(clippy::excessive_precision)]
pub fn tonemap_agx(c: Vec3) -> Vec3 {
    let inset = Mat3::from_cols(
        Vec3::new(0.842479062253094, 0.0423282422610123, 0.0423756549057051),
        Vec3::new(0.0784335999999992, 0.878468636469772, 0.0784336),
        Vec3::new(0.0792237451477643, 0.0791661274605434, 0.879142973793104),
    );
    let outset = Mat3::from_cols(
        Vec3::new(1.19687900512017, -0.0528968517574562, -0.0529716355144438),
        Vec3::new(-0.0980208811401368, 1.15190312990417, -0.0980434501171241),
        Vec3::new(-0.0990297440797205, -0.0989611768448433, 1.15107367264116),
    );
    let (min_ev, max_ev) = (-12.47393f32, 4.026069f32);
    let x = inset * c.max(Vec3::splat(1e-10));
    let x = (Vec3::new(x.x.log2(), x.y.log2(), x.z.log2()).clamp(Vec3::splat(min_ev), Vec3::splat(max_ev)) - min_ev)
        / (max_ev - min_ev);
    let (x2, x4) = (x * x, x * x * x * x);
    let x = 15.5 * x4 * x2 - 40.14 * x4 * x + 31.96 * x4 - 6.868 * x2 * x + 0.4298 * x2 + 0.1191 * x - 0.00232;
    (outset * x).clamp(Vec3::ZERO, Vec3::ONE).powf(2.2)
}

pub fn tonemap_neutral(c: Vec3) -> Vec3 {
    let (start, desaturation) = (0.8 - 0.04, 0.15);
    let x = c.min_element();
    let offset = if x < 0.08 { x - 6.25 * x * x } else { 0.04 };
    let c = c - offset;
    let peak = c.max_element();
    if peak < start {
        return c.clamp(Vec3::ZERO, Vec3::ONE);
    }
    let d = 1.0 - start;
    let new_peak = 1.0 - d * d / (peak + d - start);
    let c = c * (new_peak / peak);
    let g = 1.0 - 1.0 / (desaturation * (peak - new_peak) + 1.0);
    c.lerp(Vec3::splat(new_peak), g).clamp(Vec3::ZERO, Vec3::ONE)
}

pub fn tonemap(c: Vec3, operator: Tonemap) -> Vec3 {
    match operator {
        Tonemap::Aces => tonemap_aces(c),
        Tonemap::Agx => tonemap_agx(c),
        Tonemap::Neutral => tonemap_neutral(c),
        Tonemap::Clamp => c.clamp(Vec3::ZERO, Vec3::ONE),
    }
}

pub fn srgb_encode(v: f32) -> f32 {
    if v <= 0.0031308 { 12.92 * v } else { 1.055 * v.powf(1.0 / 2.4) - 0.055 }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn tone_mappers_are_monotone_and_bounded() {
        for op in Tonemap::ALL {
            let mut prev = -1.0;
            for k in 0..200 {
                let x = (k as f32 * 0.1 - 8.0).exp2();
                let y = tonemap(Vec3::splat(x), op);
                assert!(y.is_finite() && y.min_element() >= 0.0 && y.max_element() <= 1.0, "{op:?} {x} → {y}");
                assert!(y.x >= prev - 1e-4, "{op:?} not monotone at {x}");
                prev = y.x;
            }
            assert!(tonemap(Vec3::splat(1e4), op).x > 0.9, "{op:?} saturates to white");
            assert!(tonemap(Vec3::ZERO, op).x < 0.01, "{op:?} keeps black");
        }
    }
}
