//! The film on the device: a storage buffer of `WORDS_PER_PIXEL` u32 words a pixel, and
//! adaptive sampling's and the AOVs' regions after them (src/film.rs), its readback buffer,
//! and uploads for resume.

use super::{GpuContext, check_limit};
use crate::Error;
use crate::film::{ADAPTIVE_WORDS, Film, FilmLayout, WORDS_PER_PIXEL};

pub struct DeviceFilm {
    pub buffer: wgpu::Buffer,
    readback: wgpu::Buffer,
    pub width: u32,
    pub height: u32,
    pub layout: FilmLayout,
}

impl DeviceFilm {
    /// A zeroed film of `width`×`height` pixels, within the device's binding limit.
    pub fn new(ctx: &GpuContext, width: u32, height: u32, layout: FilmLayout) -> Result<DeviceFilm, Error> {
        let limits = ctx.device.limits();
        let bytes = Film::bytes(width, height, layout);
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
        Ok(DeviceFilm { buffer, readback, width, height, layout })
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
        let mut film = Film::with_layout(self.width, self.height, self.layout);
        let words = self.read_words(ctx, 0, film.data.len())?;
        film.data.copy_from_slice(&words);
        Ok(film)
    }

    /// How many pixels have converged (adaptive films; a readback of one word a pixel).
    pub fn converged_pixels(&self, ctx: &GpuContext) -> Result<u64, Error> {
        let pixels = self.width as usize * self.height as usize;
        let flags = self.read_words(ctx, pixels * (WORDS_PER_PIXEL + ADAPTIVE_WORDS), pixels)?;
        Ok(flags.iter().filter(|f| **f != 0).count() as u64)
    }

    /// `count` words of the film from word `first`, through the readback buffer.
    fn read_words(&self, ctx: &GpuContext, first: usize, count: usize) -> Result<Vec<u32>, Error> {
        let bytes = (count * 4) as u64;
        let mut encoder = ctx.device.create_command_encoder(&Default::default());
        encoder.copy_buffer_to_buffer(&self.buffer, (first * 4) as u64, &self.readback, 0, bytes);
        let index = ctx.queue.submit([encoder.finish()]);
        let (tx, rx) = std::sync::mpsc::channel();
        self.readback.slice(..bytes).map_async(wgpu::MapMode::Read, move |r| {
            let _ = tx.send(r);
        });
        ctx.wait(index)?;
        rx.recv()
            .map_err(|_| Error::Gpu("film readback was dropped".into()))?
            .map_err(|e| Error::Gpu(format!("film readback: {e}")))?;
        let words = {
            let view = self.readback.slice(..bytes).get_mapped_range().map_err(|e| Error::Gpu(e.to_string()))?;
            bytemuck::cast_slice::<u8, u32>(&view).to_vec()
        };
        self.readback.unmap();
        Ok(words)
    }
}
