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
    ("clearcoat.wgsl", include_str!("../../shaders/clearcoat.wgsl")),
    ("iridescence.wgsl", include_str!("../../shaders/iridescence.wgsl")),
    ("sheen.wgsl", include_str!("../../shaders/sheen.wgsl")),
    ("bsdf.wgsl", include_str!("../../shaders/bsdf.wgsl")),
    ("environment.wgsl", include_str!("../../shaders/environment.wgsl")),
    ("spherical_triangle.wgsl", include_str!("../../shaders/spherical_triangle.wgsl")),
    ("light_tree.wgsl", include_str!("../../shaders/light_tree.wgsl")),
    ("lights.wgsl", include_str!("../../shaders/lights.wgsl")),
    ("film_layout.wgsl", include_str!("../../shaders/film_layout.wgsl")),
    ("film.wgsl", include_str!("../../shaders/film.wgsl")),
    ("adaptive.wgsl", include_str!("../../shaders/adaptive.wgsl")),
    ("aov.wgsl", include_str!("../../shaders/aov.wgsl")),
    ("integrator.wgsl", include_str!("../../shaders/integrator.wgsl")),
    ("trace.wgsl", include_str!("../../shaders/trace.wgsl")),
    ("tonemap.wgsl", include_str!("../../shaders/tonemap.wgsl")),
    ("display.wgsl", include_str!("../../shaders/display.wgsl")),
    ("denoise.wgsl", include_str!("../../shaders/denoise.wgsl")),
];

/// The kernels' entry files.
pub const INTEGRATOR: &str = "integrator.wgsl";
/// The ray-throughput kernel of `veach bench` (entry point `trace_rays`).
pub const TRACE: &str = "trace.wgsl";
pub const DISPLAY: &str = "display.wgsl";
/// The denoiser's convolution layer (src/denoise/gpu.rs).
pub const DENOISE: &str = "denoise.wgsl";

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
    Ok(compose_mapped(entry, geometry)?.text)
}

/// A composed source and, for each of its lines, the file and line it came from.
pub struct Composed {
    pub text: String,
    pub origins: Vec<(&'static str, u32)>,
}

impl Composed {
    /// The (file, line, column) of a byte offset into `text`.
    pub fn locate(&self, offset: usize) -> (&'static str, u32, u32) {
        let before = &self.text[..offset.min(self.text.len())];
        let line = before.matches('\n').count();
        let column = before.len() - before.rfind('\n').map_or(0, |i| i + 1) + 1;
        let (file, l) = self.origins.get(line).copied().unwrap_or(("?", 0));
        (file, l, column as u32)
    }
}

pub fn compose_mapped(entry: &str, geometry: Geometry) -> Result<Composed, String> {
    let mut out = Composed { text: String::new(), origins: Vec::new() };
    let mut included = Vec::new();
    include(entry, geometry, &mut included, &mut out, 0)?;
    Ok(out)
}

/// Parses and validates a kernel with naga; errors name the shader file and line they are
/// in, not the composed source.
pub fn check(entry: &str, geometry: Geometry) -> Result<naga::Module, String> {
    let composed = compose_mapped(entry, geometry)?;
    let at = |span: Option<naga::Span>| {
        span.and_then(|s| s.to_range()).map_or_else(String::new, |r| {
            let (file, line, column) = composed.locate(r.start);
            format!("{file}:{line}:{column}: ")
        })
    };
    let module = naga::front::wgsl::parse_str(&composed.text).map_err(|e| {
        let span = e.labels().next().map(|(span, _)| span);
        format!("{}{}", at(span), e.message())
    })?;
    naga::valid::Validator::new(naga::valid::ValidationFlags::all(), naga::valid::Capabilities::default())
        .validate(&module)
        .map_err(|e| {
            let span = e.spans().next().map(|(span, _)| *span);
            format!("{}{}", at(span), e.as_inner())
        })?;
    Ok(module)
}

fn include(
    name: &str,
    geometry: Geometry,
    included: &mut Vec<String>,
    out: &mut Composed,
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
    let (file, source) =
        SOURCES.iter().find(|(n, _)| *n == name).copied().ok_or_else(|| format!("no shader named {name}"))?;
    included.push(name.to_string());
    out.text.push_str(&format!("// ---- {name}\n"));
    out.origins.push((file, 0));
    for (i, line) in source.lines().enumerate() {
        match line.trim().strip_prefix("#include") {
            Some(rest) => include(rest.trim().trim_matches('"'), geometry, included, out, depth + 1)?,
            None => {
                out.text.push_str(line);
                out.text.push('\n');
                out.origins.push((file, i as u32 + 1));
            }
        }
    }
    Ok(())
}

/// The denoiser's layer kernel, its tensors stored in f16 when `f16` (the device has
/// shader-f16): `enable f16;` first, and its storage alias rewritten.
pub fn denoise_source(f16: bool) -> Result<String, String> {
    let source = compose(DENOISE)?;
    if !f16 {
        return Ok(source);
    }
    const ALIAS: &str = "alias tensor4 = vec4<f32>;";
    if !source.contains(ALIAS) {
        return Err(format!("{DENOISE} has no `{ALIAS}` to store f16 in"));
    }
    Ok(format!("enable f16;\n{}", source.replace(ALIAS, "alias tensor4 = vec4<f16>;")))
}

/// The kernel `entry` as a shader module on `ctx`'s device; a compile error names the shader
/// file and line.
pub fn module(ctx: &super::GpuContext, entry: &str, geometry: Geometry) -> Result<wgpu::ShaderModule, crate::Error> {
    let source = compose_with(entry, geometry).map_err(crate::Error::Gpu)?;
    let module = ctx.device.create_shader_module(wgpu::ShaderModuleDescriptor {
        label: Some(entry),
        source: wgpu::ShaderSource::Wgsl(source.into()),
    });
    if let Err(e) = ctx.check() {
        return Err(check(entry, geometry).err().map_or(e, crate::Error::Gpu));
    }
    Ok(module)
}
