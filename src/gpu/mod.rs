//! The GPU engine: devices (`context`), the kernel's bindings (`bindings`), the scene on the
//! device (`geometry`, `textures`), the film (`film`), the integrator (`renderer`), the bench's
//! ray kernels (`trace`) and the include step of the shaders (`shaders`).

mod bindings;
mod context;
mod display;
mod film;
mod geometry;
mod renderer;
#[doc(hidden)]
pub mod shaders;
mod textures;
#[cfg(feature = "bench")]
mod trace;

#[doc(hidden)]
pub use bindings::TABLE as BINDINGS;
pub use context::{GeometryPlacement, GpuContext, GpuOptions, NO_ADAPTER_HINT, adapter_info, adapters};
pub use display::{Display, Look};
#[doc(hidden)]
pub use renderer::{GpuRenderer, WORKGROUP_SIDE};

use crate::Error;
use wgpu::util::DeviceExt;

/// Texels per row of the paged-geometry textures, as a power of two (PAGE_ROW_LOG2 in
/// shaders/geometry_textures.wgsl).
pub const PAGE_ROW_LOG2: u32 = 12;

/// Samples per submission: enough to amortise the submit, few enough to stay responsive.
pub const MAX_BATCH: u32 = 64;

pub(crate) fn check_limit(what: &str, bytes: u64, limit: u64, name: &str) -> Result<(), Error> {
    if bytes > limit {
        // Only the film shrinks with a tile; the scene's buffers do not.
        let advice = if what == "film" { "; render tiles (--tile)" } else { "" };
        return Err(Error::Limit(format!(
            "the {what} buffer needs {bytes} bytes, above the device limit {name} = {limit}{advice}"
        )));
    }
    Ok(())
}

/// A read-only storage buffer holding `bytes`, within the device's binding limits.
pub(crate) fn storage_buffer(device: &wgpu::Device, label: &str, bytes: &[u8]) -> Result<wgpu::Buffer, Error> {
    let limits = device.limits();
    let len = bytes.len() as u64;
    check_limit(label, len, limits.max_storage_buffer_binding_size, "max_storage_buffer_binding_size")?;
    check_limit(label, len, limits.max_buffer_size, "max_buffer_size")?;
    // Zero-sized bindings are invalid; an empty array gets one zeroed element.
    let padded;
    let contents = if bytes.is_empty() {
        padded = vec![0u8; 16];
        &padded[..]
    } else {
        bytes
    };
    Ok(device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
        label: Some(label),
        contents,
        usage: wgpu::BufferUsages::STORAGE,
    }))
}
