//! The default environment: a neutral photographic studio for scenes that bring no light of
//! their own (most glTF files: FlightHelmet, DamagedHelmet, Sketchfab and Blender exports),
//! as every model viewer lights them.
//!
//! A grey cyclorama (dark floor, lighter walls and ceiling) with four grey softboxes: a key
//! light above and to the left of the default camera (which looks down −Z from +Z), a fill on
//! the right, a rim strip behind the subject and a soft top light. All of it is grey, so
//! materials keep their colors; the whole is scaled so that a white diffuse surface facing
//! the camera reads 1.
//!
//! [`generate_studio`] is the source; `assets/studio.hdr` is its output, stored so users can
//! look at it and pass it to `--env` (`cargo run --example studio-environment` rewrites it).
//! Renders decode the stored file ([`Environment::studio`]); a test holds it to the generator.

use super::{Environment, EnvironmentMap};
use glam::Vec3;
use std::sync::{Arc, OnceLock};

/// The stored map's size: softboxes span ~30° (40 texels), sharp enough in mirrors.
pub const STUDIO_WIDTH: u32 = 512;
pub const STUDIO_HEIGHT: u32 = 256;

/// The stored map (Radiance RGBE), `generate_studio(STUDIO_WIDTH, STUDIO_HEIGHT)`.
const STUDIO_HDR: &[u8] = include_bytes!(concat!(env!("CARGO_MANIFEST_DIR"), "/assets/studio.hdr"));

/// A softbox: a rectangle facing the origin, `half` its half extents in tangent-plane units.
struct Softbox {
    towards: Vec3,
    half: (f32, f32),
    radiance: f32,
}

const SOFTBOXES: [Softbox; 4] = [
    // Key: above left, in front of the subject (behind the camera).
    Softbox { towards: Vec3::new(-0.62, 0.55, 0.56), half: (0.28, 0.38), radiance: 9.0 },
    // Fill: right, lower and dimmer.
    Softbox { towards: Vec3::new(0.78, 0.22, 0.58), half: (0.30, 0.30), radiance: 2.5 },
    // Rim: a tall strip high behind the subject (above the default view), for edges.
    Softbox { towards: Vec3::new(0.45, 0.75, -0.5), half: (0.10, 0.40), radiance: 7.0 },
    // Top: a large soft panel overhead.
    Softbox { towards: Vec3::Y, half: (0.40, 0.40), radiance: 2.0 },
];

fn smoothstep(e0: f32, e1: f32, x: f32) -> f32 {
    let t = ((x - e0) / (e1 - e0)).clamp(0.0, 1.0);
    t * t * (3.0 - 2.0 * t)
}

/// Unscaled radiance of the studio seen along the unit direction `d`.
fn studio_radiance(d: Vec3) -> f32 {
    let cyclorama = 0.10 + 0.08 * smoothstep(-0.3, 0.05, d.y) + 0.22 * smoothstep(0.0, 1.0, d.y);
    let mut l = cyclorama;
    for b in &SOFTBOXES {
        let c = b.towards.normalize();
        let facing = d.dot(c);
        if facing <= 0.0 {
            continue;
        }
        let t = if c.y.abs() > 0.99 { Vec3::X } else { Vec3::Y.cross(c).normalize() };
        let s = c.cross(t);
        // Gnomonic coordinates: a flat rectangle, soft at its edges (a diffuser's falloff).
        let (u, v) = (d.dot(t) / facing, d.dot(s) / facing);
        let inside = |x: f32, h: f32| 1.0 - smoothstep(0.9 * h, 1.1 * h, x.abs());
        l = l.max(cyclorama + b.radiance * inside(u, b.half.0) * inside(v, b.half.1));
    }
    l
}

/// Direction of the centre of texel (row, column) of a W×H equirectangular map (the
/// convention of `environment.rs`: θ from +Y, φ = 0 down −Z).
fn texel_direction(row: u32, column: u32, width: u32, height: u32) -> Vec3 {
    let theta = std::f32::consts::PI * (row as f32 + 0.5) / height as f32;
    let phi = std::f32::consts::TAU * (column as f32 + 0.5) / width as f32 - std::f32::consts::PI;
    Vec3::new(theta.sin() * phi.sin(), theta.cos(), -theta.sin() * phi.cos())
}

/// The studio as a `width`×`height` equirectangular map, scaled so that the irradiance on a
/// surface facing +Z (the default camera) is π: a white diffuse surface there reads 1.
pub fn generate_studio(width: u32, height: u32) -> EnvironmentMap {
    let mut radiance = Vec::with_capacity((width * height) as usize);
    let mut irradiance = 0.0f64;
    for row in 0..height {
        // Solid angle of a texel of this row.
        let (t0, t1) = (
            std::f64::consts::PI * row as f64 / height as f64,
            std::f64::consts::PI * (row + 1) as f64 / height as f64,
        );
        let texel_sr = std::f64::consts::TAU / width as f64 * (t0.cos() - t1.cos());
        for column in 0..width {
            let d = texel_direction(row, column, width, height);
            let l = studio_radiance(d);
            irradiance += l as f64 * d.z.max(0.0) as f64 * texel_sr;
            radiance.push(l);
        }
    }
    let scale = (std::f64::consts::PI / irradiance) as f32;
    EnvironmentMap { width, height, texels: radiance.into_iter().map(|l| Vec3::splat(l * scale)).collect() }
}

impl EnvironmentMap {
    /// The stored studio map (`assets/studio.hdr`), decoded once.
    pub fn studio() -> Arc<EnvironmentMap> {
        static STUDIO: OnceLock<Arc<EnvironmentMap>> = OnceLock::new();
        STUDIO
            .get_or_init(|| {
                // The bytes are ours and checked by a test; an undecodable build falls back
                // to the generator rather than failing a render.
                let decoded = image::load_from_memory_with_format(STUDIO_HDR, image::ImageFormat::Hdr).ok();
                Arc::new(match decoded {
                    Some(img) => {
                        let img = img.to_rgb32f();
                        let texels = img.pixels().map(|p| Vec3::new(p[0], p[1], p[2])).collect();
                        EnvironmentMap { width: img.width(), height: img.height(), texels }
                    }
                    None => generate_studio(STUDIO_WIDTH, STUDIO_HEIGHT),
                })
            })
            .clone()
    }
}

impl Environment {
    /// The default studio environment, untinted.
    pub fn studio() -> Environment {
        Environment { map: Some(EnvironmentMap::studio()), radiance: Vec3::ONE }
    }
}
