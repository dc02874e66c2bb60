//! Equirectangular environment maps (.hdr, .exr): linear RGB radiance over the sphere.
//!
//! Texel (i, j) of a W×H map covers θ ∈ [π i/H, π (i+1)/H] from +Y (up) and
//! φ ∈ [2π j/W − π, 2π (j+1)/W − π] around it, with φ = 0 looking down −Z (glTF's forward).

use crate::Error;
use glam::Vec3;
use std::path::Path;

/// Largest accepted map: its texels must fit one 128 MiB storage binding as vec4<f32>.
pub const MAX_TEXELS: usize = 8 << 20;

/// What rays that leave the scene see: a constant radiance, or a map scaled by it. A
/// swappable input of a render (`Renderer::set_environment`): changing it rebuilds no BVH.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Environment {
    pub map: Option<std::sync::Arc<EnvironmentMap>>,
    /// The constant radiance, or the tint of the map.
    pub radiance: Vec3,
}

impl Environment {
    pub fn constant(radiance: Vec3) -> Environment {
        Environment { map: None, radiance }
    }

    pub fn map(map: EnvironmentMap, tint: Vec3) -> Environment {
        Environment { map: Some(std::sync::Arc::new(map)), radiance: tint }
    }

    /// Whether it lights the scene at all.
    pub fn is_black(&self) -> bool {
        self.radiance.max_element() <= 0.0
    }
}

#[derive(Clone, Debug, PartialEq)]
pub struct EnvironmentMap {
    pub width: u32,
    pub height: u32,
    pub texels: Vec<Vec3>,
}

impl EnvironmentMap {
    pub fn load(path: &Path) -> Result<EnvironmentMap, Error> {
        let fail = |m: String| Error::Input(format!("{}: {m}", path.display()));
        let ext = path.extension().and_then(|e| e.to_str()).map(str::to_ascii_lowercase);
        if !matches!(ext.as_deref(), Some("hdr") | Some("exr")) {
            return Err(fail("environment maps must be .hdr or .exr".into()));
        }
        let reader = image::ImageReader::open(path).map_err(|e| fail(format!("cannot read: {e}")))?;
        let (w, h) = reader
            .with_guessed_format()
            .map_err(|e| fail(e.to_string()))?
            .into_dimensions()
            .map_err(|e| fail(format!("invalid image: {e}")))?;
        if w == 0 || h == 0 || (w as usize).saturating_mul(h as usize) > MAX_TEXELS {
            return Err(fail(format!("{w}x{h} texels: an environment map holds 1..={MAX_TEXELS} texels")));
        }
        let img = image::open(path).map_err(|e| fail(format!("invalid image: {e}")))?.to_rgb32f();
        let texels = img
            .pixels()
            .map(|p| Vec3::new(p[0], p[1], p[2]))
            .map(|c| if c.is_finite() { c.max(Vec3::ZERO) } else { Vec3::ZERO });
        Ok(EnvironmentMap { width: w, height: h, texels: texels.collect() })
    }

    /// A map of one constant color (tests; equals a constant environment).
    pub fn constant(width: u32, height: u32, c: Vec3) -> EnvironmentMap {
        EnvironmentMap { width, height, texels: vec![c; (width * height) as usize] }
    }
}
