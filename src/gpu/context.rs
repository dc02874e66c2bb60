//! Devices: the adapters of every compute backend, and a device whose errors are captured
//! instead of panicking.

use crate::Error;
use std::sync::{Arc, Mutex};

pub const NO_ADAPTER_HINT: &str = "no GPU adapter found (Vulkan, Metal or DX12); for the GPU path install a Vulkan driver (Debian/Ubuntu: apt-get install mesa-vulkan-drivers)";

/// The native backends that run compute shaders; WGPU_BACKEND narrows them.
const BACKENDS: wgpu::Backends = wgpu::Backends::VULKAN.union(wgpu::Backends::METAL).union(wgpu::Backends::DX12);

fn instance() -> wgpu::Instance {
    wgpu::Instance::new(wgpu::InstanceDescriptor {
        backends: BACKENDS.with_env(),
        flags: wgpu::InstanceFlags::empty().with_env(),
        ..wgpu::InstanceDescriptor::new_without_display_handle()
    })
}

/// Every adapter found on the compute backends, with its limits.
pub fn adapters() -> Vec<(wgpu::AdapterInfo, wgpu::Limits)> {
    let inst = instance();
    pollster::block_on(inst.enumerate_adapters(BACKENDS.with_env()))
        .iter()
        .map(|a| (a.get_info(), a.limits()))
        .collect()
}

/// A device and queue, with wgpu errors captured instead of panicking.
#[derive(Clone)]
pub struct GpuContext {
    pub device: wgpu::Device,
    pub queue: wgpu::Queue,
    pub info: wgpu::AdapterInfo,
    errors: Arc<Mutex<Option<String>>>,
    /// Choices of how scenes are placed on this device.
    pub options: GpuOptions,
}

/// How the GPU engine places a scene.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct GpuOptions {
    pub geometry: GeometryPlacement,
}

/// Where the kernel reads geometry from.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum GeometryPlacement {
    /// Storage buffers, or textures when a buffer exceeds the device's binding limit.
    #[default]
    Auto,
    /// Always textures (tests of the paged path on small scenes).
    Textures,
}

/// The adapter `GpuContext::new` opens: WGPU_ADAPTER_NAME's, else the high-performance one.
fn choose_adapter() -> Result<wgpu::Adapter, Error> {
    let inst = instance();
    // WGPU_ADAPTER_NAME picks an adapter by name; an unmatched name is our error, not a panic.
    let wanted = std::env::var("WGPU_ADAPTER_NAME").ok().map(|s| s.to_lowercase());
    match wanted {
        Some(name) => pollster::block_on(inst.enumerate_adapters(BACKENDS.with_env()))
            .into_iter()
            .find(|a| a.get_info().name.to_lowercase().contains(&name))
            .ok_or_else(|| Error::NoAdapter(format!("no GPU adapter matches WGPU_ADAPTER_NAME={name}"))),
        None => pollster::block_on(inst.request_adapter(&wgpu::RequestAdapterOptions {
            power_preference: wgpu::PowerPreference::HighPerformance,
            ..Default::default()
        }))
        .map_err(|_| Error::NoAdapter(NO_ADAPTER_HINT.to_string())),
    }
}

/// What `GpuContext::new` would open, without opening a device.
pub fn adapter_info() -> Result<wgpu::AdapterInfo, Error> {
    Ok(choose_adapter()?.get_info())
}

impl GpuContext {
    /// Wraps a device opened elsewhere (the viewer's window), capturing its errors.
    pub fn from_device(device: wgpu::Device, queue: wgpu::Queue, info: wgpu::AdapterInfo) -> GpuContext {
        let errors = Arc::new(Mutex::new(None));
        let sink = errors.clone();
        device.on_uncaptured_error(Arc::new(move |e: wgpu::Error| {
            if let Ok(mut slot) = sink.lock() {
                slot.get_or_insert_with(|| e.to_string());
            }
        }));
        GpuContext { device, queue, info, errors, options: GpuOptions::default() }
    }

    /// The adapter's driver, as `veach info` prints it.
    pub fn driver(&self) -> String {
        format!("{} {}", self.info.driver, self.info.driver_info)
    }

    pub fn new() -> Result<GpuContext, Error> {
        let adapter = choose_adapter()?;
        let info = adapter.get_info();
        let limits = adapter.limits();
        let (device, queue) = pollster::block_on(adapter.request_device(&wgpu::DeviceDescriptor {
            label: Some("veach"),
            required_limits: limits,
            // f16 arithmetic and storage where the adapter has them: the denoiser keeps its
            // tensors in f16 there (half the bytes read).
            required_features: adapter.features() & wgpu::Features::SHADER_F16,
            ..Default::default()
        }))
        .map_err(|e| Error::Gpu(format!("cannot open {}: {e}", info.name)))?;
        let ctx = GpuContext::from_device(device, queue, info);
        let lost = ctx.errors.clone();
        ctx.device.set_device_lost_callback(move |_reason, msg| {
            if let Ok(mut slot) = lost.lock() {
                slot.get_or_insert_with(|| format!("device lost: {msg}"));
            }
        });
        Ok(ctx)
    }

    pub fn check(&self) -> Result<(), Error> {
        match self.errors.lock().ok().and_then(|mut e| e.take()) {
            Some(msg) => Err(Error::Gpu(msg)),
            None => Ok(()),
        }
    }

    /// Waits for a submission and reports any error the device raised meanwhile.
    pub fn wait(&self, index: wgpu::SubmissionIndex) -> Result<(), Error> {
        self.device
            .poll(wgpu::PollType::Wait { submission_index: Some(index), timeout: None })
            .map_err(|e| Error::Gpu(format!("waiting for the GPU: {e}")))?;
        self.check()
    }

    pub fn adapter_name(&self) -> String {
        format!("{} ({:?}, {})", self.info.name, self.info.device_type, self.info.driver)
    }
}
