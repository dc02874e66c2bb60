//! veach: a physically based path tracer built around multiple importance sampling.
//!
//! Data flows one way: glTF → [`Scene`] → [`PackedScene`] (the buffers both engines read) →
//! an engine (the WGSL kernel through wgpu, or the CPU reference) inside a [`Renderer`] →
//! [`Film`] → PNG/EXR ([`output`]) or a window. The command line and the viewer are thin
//! shells over this API.
//!
//! ```
//! # fn main() -> Result<(), veach::Error> {
//! let loaded = veach::load("assets/cornell-box.gltf".as_ref(), None)?;
//! let settings = veach::Settings { width: 32, height: 32, ..Default::default() };
//! let packed = veach::PackedScene::new(&loaded.scene);
//! let mut renderer = veach::Renderer::new(packed, &loaded.camera, &settings, veach::Backend::Cpu)?;
//! renderer.render_samples(0, 4)?;
//! let film = renderer.film()?;
//! assert_eq!(film.samples(), 4);
//! veach::output::write(&film, &std::env::temp_dir().join("veach-doc.png"), 0.0, None)?;
//! # Ok(()) }
//! ```
//!
//! `examples/embed.rs` shows the rest: loading from bytes, time budgets with progress and
//! cancellation, film access, checkpoints, resume, merge and a swapped environment.

#[doc(hidden)]
pub mod accel;
#[doc(hidden)]
pub mod adaptive;
pub mod aov;
#[cfg(feature = "bench")]
pub mod bench;
#[doc(hidden)]
pub mod cpu;
pub mod denoise;
mod engine;
mod error;
pub mod exr_layers;
pub mod film;
pub mod gpu;
mod job;
mod load;
pub mod metrics;
pub mod output;
#[doc(hidden)]
pub mod packed;
#[doc(hidden)]
pub mod params;
mod render_loop;
mod renderer;
pub mod scene;
mod settings;
#[doc(hidden)]
pub mod sheen;
mod stats;
mod tile;
pub mod tonemap;
#[cfg(feature = "viewer")]
pub mod viewer;

pub use error::Error;
pub use film::Film;
pub use job::{Job, Part, merge};
pub use load::{LoadOptions, Loaded, load, load_bytes, load_bytes_with, load_with};
pub use packed::PackedScene;
pub use render_loop::{Budget, CHUNK_SECONDS, Control, MAX_CHUNK, Progress, render_progressive};
pub use renderer::{ROW_BAND, Renderer};
pub use scene::{Camera, Environment, EnvironmentMap, Scene};
pub use settings::{
    Backend, EnvironmentSource, LightSampler, MAX_FILM_BYTES, MAX_IMAGE_SIDE, SamplerKind, Settings, Strategy,
};
pub use stats::{extend_stats, render_stats};
pub use tile::Tile;
