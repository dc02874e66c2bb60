//! The film on the device: a storage buffer of `WORDS_PER_PIXEL` u32 words a pixel
//! (src/film.rs), its readback buffer, and uploads for resume.

use super::{GpuContext, check_limit};
use crate::Error;
use crate::film::{Film, WORDS_PER_PIXEL};

pub struct DeviceFilm {
    pub buffer: wgpu::Buffer,
    readback: wgpu::Buffer,
    pub width: u32,
    pub height: u32,
}

impl DeviceFilm {
    /// A zeroed film of `width`×`height` pixels, within the device's binding limit.
    pub fn new(ctx: &GpuContext, width: u32, height: u32) -> Result<DeviceFilm, Error> {
        let limits = ctx.device.limits();
        let bytes = width as u64 * height as u64 * (WORDS_PER_PIXEL * 4) as u64;
        check_limit("film", bytes, limits.max_storage_buffer_binding_size, "max_storage_buffer_binding_size")?;
        let buffer = ctx.device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("film"),
            size: bytes,
            usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_SRC | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        let readback = ctx.device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("film readback"),
            size: bytes,
            usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        Ok(DeviceFilm { buffer, readback, width, height })
    }

    /// Zeroes the film.
    pub fn clear(&self, ctx: &GpuContext) {
        let mut encoder = ctx.device.create_command_encoder(&Default::default());
        encoder.clear_buffer(&self.buffer, 0, None);
        ctx.queue.submit([encoder.finish()]);
    }

    /// Replaces the film's words (resume); the caller checked the size.
    pub fn upload(&self, ctx: &GpuContext, film: &Film) {
        ctx.queue.write_buffer(&self.buffer, 0, bytemuck::cast_slice(&film.data));
    }

    /// Copies the film back to the host.
    pub fn read(&self, ctx: &GpuContext) -> Result<Film, Error> {
        let mut encoder = ctx.device.create_command_encoder(&Default::default());
        encoder.copy_buffer_to_buffer(&self.buffer, 0, &self.readback, 0, self.buffer.size());
        let index = ctx.queue.submit([encoder.finish()]);
        let (tx, rx) = std::sync::mpsc::channel();
        self.readback.slice(..).map_async(wgpu::MapMode::Read, move |r| {
            let _ = tx.send(r);
        });
        ctx.wait(index)?;
        rx.recv()
            .map_err(|_| Error::Gpu("film readback was dropped".into()))?
            .map_err(|e| Error::Gpu(format!("film readback: {e}")))?;
        let mut film = Film::new(self.width, self.height);
        {
            let view = self.readback.slice(..).get_mapped_range().map_err(|e| Error::Gpu(e.to_string()))?;
            film.data.copy_from_slice(bytemuck::cast_slice(&view));
        }
        self.readback.unmap();
        Ok(film)
    }
}
