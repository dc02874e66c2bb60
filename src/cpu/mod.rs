//! The CPU reference backend: the same integrator as `shaders/`, one file per concept with
//! the same function names, run over pixels with rayon. It reads the same `PackedScene`,
//! draws the same random numbers and writes the same film, so GPU results can be checked
//! against it sample for sample in distribution.

pub mod bsdf;
pub mod bvh;
pub mod camera;
pub mod clearcoat;
pub mod common;
pub mod environment;
pub mod frame;
pub mod instance;
pub mod integrator;
pub mod iridescence;
pub mod lanes;
pub mod light_tree;
pub mod lights;
pub mod material;
pub mod microfacet;
pub mod mis;
pub mod renderer;
pub mod rng;
pub mod sampler;
pub mod sampling;
pub mod spherical_triangle;
pub mod texture;
pub mod trig;

pub use integrator::render_sample;
pub use renderer::{Kernel, Renderer};
