//! The include step: `#include "file.wgsl"` pulls a file in once (later includes of the same
//! file are dropped), so every shader file can name what it needs and still compose.

/// All shader sources, embedded so the binary runs from any directory.
pub const SOURCES: &[(&str, &str)] = &[
    ("common.wgsl", include_str!("../../shaders/common.wgsl")),
    ("bindings.wgsl", include_str!("../../shaders/bindings.wgsl")),
    ("rng.wgsl", include_str!("../../shaders/rng.wgsl")),
    ("sampler.wgsl", include_str!("../../shaders/sampler.wgsl")),
    ("sampling.wgsl", include_str!("../../shaders/sampling.wgsl")),
    ("frame.wgsl", include_str!("../../shaders/frame.wgsl")),
    ("mis.wgsl", include_str!("../../shaders/mis.wgsl")),
    ("geometry_buffers.wgsl", include_str!("../../shaders/geometry_buffers.wgsl")),
    ("geometry_textures.wgsl", include_str!("../../shaders/geometry_textures.wgsl")),
    ("texture.wgsl", include_str!("../../shaders/texture.wgsl")),
    ("instance.wgsl", include_str!("../../shaders/instance.wgsl")),
    ("material.wgsl", include_str!("../../shaders/material.wgsl")),
    ("bvh.wgsl", include_str!("../../shaders/bvh.wgsl")),
    ("camera.wgsl", include_str!("../../shaders/camera.wgsl")),
    ("microfacet.wgsl", include_str!("../../shaders/microfacet.wgsl")),
    ("bsdf.wgsl", include_str!("../../shaders/bsdf.wgsl")),
    ("environment.wgsl", include_str!("../../shaders/environment.wgsl")),
    ("lights.wgsl", include_str!("../../shaders/lights.wgsl")),
    ("film.wgsl", include_str!("../../shaders/film.wgsl")),
    ("integrator.wgsl", include_str!("../../shaders/integrator.wgsl")),
    ("trace.wgsl", include_str!("../../shaders/trace.wgsl")),
    ("tonemap.wgsl", include_str!("../../shaders/tonemap.wgsl")),
    ("display.wgsl", include_str!("../../shaders/display.wgsl")),
];

/// The kernels' entry files.
pub const INTEGRATOR: &str = "integrator.wgsl";
/// The ray-throughput kernel of `veach bench` (entry point `trace_rays`).
pub const TRACE: &str = "trace.wgsl";
pub const DISPLAY: &str = "display.wgsl";

/// Where the kernel reads scene geometry from: `#include "geometry.wgsl"` resolves to one of
/// two files with the same load_* functions.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Geometry {
    /// Storage buffers (fastest; each binding at most max_storage_buffer_binding_size).
    Buffers,
    /// 2D textures of 16-byte texels, for scenes beyond a storage binding.
    Textures,
}

/// Composes `entry` and everything it includes into one WGSL source (geometry in buffers).
pub fn compose(entry: &str) -> Result<String, String> {
    compose_with(entry, Geometry::Buffers)
}

pub fn compose_with(entry: &str, geometry: Geometry) -> Result<String, String> {
    let mut out = String::new();
    let mut included = Vec::new();
    include(entry, geometry, &mut included, &mut out, 0)?;
    Ok(out)
}

fn include(
    name: &str,
    geometry: Geometry,
    included: &mut Vec<String>,
    out: &mut String,
    depth: usize,
) -> Result<(), String> {
    let name = match (name, geometry) {
        ("geometry.wgsl", Geometry::Buffers) => "geometry_buffers.wgsl",
        ("geometry.wgsl", Geometry::Textures) => "geometry_textures.wgsl",
        (n, _) => n,
    };
    if included.iter().any(|n| n == name) {
        return Ok(());
    }
    if depth > 32 {
        return Err(format!("{name}: includes nest deeper than 32"));
    }
    let source =
        SOURCES.iter().find(|(n, _)| *n == name).map(|(_, s)| *s).ok_or_else(|| format!("no shader named {name}"))?;
    included.push(name.to_string());
    out.push_str(&format!("// ---- {name}\n"));
    for line in source.lines() {
        match line.trim().strip_prefix("#include") {
            Some(rest) => include(rest.trim().trim_matches('"'), geometry, included, out, depth + 1)?,
            None => {
                out.push_str(line);
                out.push('\n');
            }
        }
    }
    Ok(())
}
