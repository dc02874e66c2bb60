//! Denoising with Intel Open Image Denoise's trained RT U-Net, run by veach itself: a Rust
//! twin on the CPU ([`denoise_cpu`]) and WGSL compute passes on any wgpu device
//! ([`gpu::GpuDenoiser`]), from OIDN's own weights (Apache-2.0, `assets/oidn/`, embedded).
//!
//! The input is a linear HDR colour image with, optionally, the first visible surface's
//! albedo and shading normal (veach's AOVs); the output is the denoised colour. Images of
//! any size are cut into tiles that overlap by half the network's receptive field, each
//! writing only its interior, so a tiled denoise equals a whole one; the exposure is
//! measured once on the whole image.
//!
//! ```
//! # fn main() -> Result<(), veach::Error> {
//! use veach::denoise::{Images, Options, denoise_cpu};
//! let (w, h) = (20, 12);
//! let color = vec![0.5f32; w * h * 3];
//! let out = denoise_cpu(&Images { width: w, height: h, color: &color, albedo: None, normal: None }, &Options::default())?;
//! assert_eq!(out.len(), color.len());
//! # Ok(()) }
//! ```

pub mod cpu;
pub mod gpu;
pub mod network;
pub mod tiles;
pub mod transfer;
pub mod tza;

pub use network::Network;
pub use tiles::{Tile, plan_tiles};
pub use transfer::Images;

use crate::Error;

/// Which network: OIDN's "fast" (the small U-Net, half the work) or "balanced" (the base
/// U-Net; OIDN's "high" quality uses the same one for these inputs).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Quality {
    Fast,
    #[default]
    Balanced,
}

impl std::str::FromStr for Quality {
    type Err = String;
    fn from_str(s: &str) -> Result<Quality, String> {
        match s {
            "fast" => Ok(Quality::Fast),
            "balanced" => Ok(Quality::Balanced),
            _ => Err(format!("unknown denoise quality '{s}' (use fast or balanced)")),
        }
    }
}

impl Quality {
    pub fn name(self) -> &'static str {
        match self {
            Quality::Fast => "fast",
            Quality::Balanced => "balanced",
        }
    }
}

/// The weight archive for a quality and the number of input channels (3: colour; 6: with
/// albedo; 9: with albedo and normal), and its file name. Only the 9-channel input has a
/// small network; the others fall back to the base one, as OIDN does.
pub fn weight_file(quality: Quality, channels: usize) -> (&'static str, &'static [u8]) {
    match (quality, channels) {
        (Quality::Fast, 9) => {
            ("rt_hdr_alb_nrm_small.tza", include_bytes!("../../assets/oidn/rt_hdr_alb_nrm_small.tza"))
        }
        (_, 9) => ("rt_hdr_alb_nrm.tza", include_bytes!("../../assets/oidn/rt_hdr_alb_nrm.tza")),
        (_, 6) => ("rt_hdr_alb.tza", include_bytes!("../../assets/oidn/rt_hdr_alb.tza")),
        _ => ("rt_hdr.tza", include_bytes!("../../assets/oidn/rt_hdr.tza")),
    }
}

/// The network for a quality and input channel count, from the embedded weights.
pub fn network(quality: Quality, channels: usize) -> Result<Network, Error> {
    let (name, bytes) = weight_file(quality, channels);
    let tensors = tza::parse(bytes).map_err(|e| Error::Input(format!("{name}: {e}")))?;
    Network::from_tensors(&tensors).map_err(|e| Error::Input(format!("{name}: {e}")))
}

/// How to denoise.
#[derive(Clone, Copy, Debug, Default)]
pub struct Options {
    pub quality: Quality,
    /// The scale that brings the colour to the network's units (1 = 100 cd/m²); None measures
    /// it (OIDN's automatic exposure).
    pub input_scale: Option<f32>,
    /// The most pixels one tile's tensors may have (None: as large as the engine allows).
    pub max_tile_pixels: Option<usize>,
}

/// Pixels per tile the CPU twin uses at most: about 1.1 GB of activations for the base
/// network (OIDN's CPU device tiles only images above 2160² too).
pub const CPU_TILE_PIXELS: usize = 2160 * 2160;

/// Denoises on the CPU: the Rust twin of the network.
pub fn denoise_cpu(images: &Images, options: &Options) -> Result<Vec<f32>, Error> {
    images.validate().map_err(Error::Input)?;
    let net = network(options.quality, images.channels())?;
    Ok(denoise_cpu_with(&net, images, options))
}

/// Where the network runs.
#[derive(Clone, Copy)]
pub enum Engine<'a> {
    /// The Rust twin.
    Cpu,
    /// The WGSL passes on this device.
    Gpu(&'a crate::gpu::GpuContext),
}

impl Engine<'_> {
    pub fn name(&self) -> &'static str {
        match self {
            Engine::Cpu => "cpu",
            Engine::Gpu(_) => "gpu",
        }
    }

    /// How the engine stores tensors: f32, or f16 on a device with shader-f16.
    pub fn precision(&self) -> &'static str {
        match self {
            Engine::Gpu(ctx) if ctx.device.features().contains(wgpu::Features::SHADER_F16) => "f16",
            _ => "f32",
        }
    }
}

/// The device the network runs on (None: the CPU twin), and why: `auto` takes a hardware GPU
/// and otherwise the CPU, whose twin outruns a software adapter's kernel.
pub fn device(backend: crate::Backend) -> Result<(Option<crate::gpu::GpuContext>, String), Error> {
    match backend {
        crate::Backend::Cpu => Ok((None, "requested".into())),
        crate::Backend::Gpu => Ok((Some(crate::gpu::GpuContext::new()?), "requested".into())),
        crate::Backend::Auto => match crate::gpu::adapter_info() {
            Ok(info) if info.device_type != wgpu::DeviceType::Cpu => {
                Ok((Some(crate::gpu::GpuContext::new()?), format!("auto: hardware GPU adapter ({})", info.name)))
            }
            Ok(info) => Ok((None, format!("auto: the only GPU adapter ({}) is a software one", info.name))),
            Err(Error::NoAdapter(_)) => Ok((None, "auto: no GPU adapter".into())),
            Err(e) => Err(e),
        },
    }
}

/// Denoises `images` on `engine`.
pub fn denoise(images: &Images, options: &Options, engine: Engine) -> Result<Vec<f32>, Error> {
    images.validate().map_err(Error::Input)?;
    let net = network(options.quality, images.channels())?;
    match engine {
        Engine::Cpu => Ok(denoise_cpu_with(&net, images, options)),
        Engine::Gpu(ctx) => gpu::GpuDenoiser::new(ctx, &net)?.denoise(images, options),
    }
}

/// Denoises a film's mean (three floats a pixel, linear RGB), with its albedo and normal AOVs
/// when it has them.
pub fn denoise_film(film: &crate::Film, options: &Options, engine: Engine) -> Result<Vec<f32>, Error> {
    let color = film.to_rgb32f();
    let albedo = film.aov_image(crate::aov::Aov::Albedo);
    let normal = film.aov_image(crate::aov::Aov::Normal);
    let (width, height) = (film.width as usize, film.height as usize);
    let images = Images { width, height, color: &color, albedo: albedo.as_deref(), normal: normal.as_deref() };
    denoise(&images, options, engine)
}

/// Denoises on the CPU with a given network (its input channels match the images').
pub fn denoise_cpu_with(net: &Network, images: &Images, options: &Options) -> Vec<f32> {
    let scale =
        options.input_scale.unwrap_or_else(|| transfer::autoexposure(images.color, images.width, images.height));
    let cpu_net = cpu::CpuNetwork::new(net);
    let mut out = vec![0.0; images.width * images.height * 3];
    let max = options.max_tile_pixels.unwrap_or(CPU_TILE_PIXELS);
    for tile in plan_tiles(images.width, images.height, max) {
        let input = cpu::input_tensor(images, tile.x, tile.y, tile.width, tile.height, scale);
        let result = cpu_net.run(input);
        cpu::write_output(&mut out, images.width, &result, (tile.x, tile.y), tile.interior, scale);
    }
    out
}
