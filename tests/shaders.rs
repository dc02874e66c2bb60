//! Every WGSL file, after the include step, parses and validates with naga (no GPU needed).

use veach::gpu::shaders::{Geometry, INTEGRATOR, SOURCES, compose, compose_with};

fn validate(name: &str) -> naga::Module {
    veach::gpu::shaders::check(name, Geometry::Buffers).unwrap_or_else(|e| panic!("{e}"))
}

#[test]
fn every_shader_file_validates_after_includes() {
    // That SOURCES is the shaders/ folder is checked in tests/layout.rs.
    for (name, _) in SOURCES {
        validate(name);
    }
}

#[test]
fn integrator_kernel_fits_default_limits() {
    let module = validate(INTEGRATOR);
    let limits = wgpu::Limits::default();
    let ep = module.entry_points.iter().find(|e| e.name == "render_sample").expect("render_sample entry point");
    let [x, y, z] = ep.workgroup_size;
    assert!(x * y * z <= limits.max_compute_invocations_per_workgroup);
    let storage =
        module.global_variables.iter().filter(|(_, g)| matches!(g.space, naga::AddressSpace::Storage { .. })).count()
            as u32;
    assert!(storage <= limits.max_storage_buffers_per_shader_stage, "{storage} storage buffers");
}

#[test]
fn paged_geometry_kernel_validates() {
    let src = compose_with(INTEGRATOR, Geometry::Textures).unwrap();
    let module = naga::front::wgsl::parse_str(&src).unwrap_or_else(|e| panic!("{}", e.emit_to_string(&src)));
    naga::valid::Validator::new(naga::valid::ValidationFlags::all(), naga::valid::Capabilities::default())
        .validate(&module)
        .unwrap_or_else(|e| panic!("{}", e.emit_to_string(&src)));
    assert!(src.contains("triangle_texels") && !src.contains("array<Triangle>"));
}

#[test]
fn shader_errors_name_the_file_and_line() {
    // The composed source of the integrator, with an error planted on a known line of
    // mis.wgsl: the message names mis.wgsl and that line, not the composed text.
    let composed = veach::gpu::shaders::compose_mapped(INTEGRATOR, Geometry::Buffers).unwrap();
    let at = composed.text.find("fn power_heuristic").expect("power_heuristic in the kernel");
    let (file, line, column) = composed.locate(at);
    assert_eq!(file, "mis.wgsl");
    let expected = veach::gpu::shaders::SOURCES
        .iter()
        .find(|(n, _)| *n == "mis.wgsl")
        .map(|(_, s)| s.lines().position(|l| l.contains("fn power_heuristic")).unwrap() as u32 + 1)
        .unwrap();
    assert_eq!((line, column), (expected, 1));
    let broken = composed.text.replacen("fn power_heuristic", "fn power_heuristic_", 1);
    let err = naga::front::wgsl::parse_str(&broken).expect_err("a missing function");
    let span = err.labels().next().map(|(s, _)| s.to_range().unwrap().start).unwrap();
    let (file, _, _) = composed.locate(span);
    assert!(file.ends_with(".wgsl") && file != "?", "{file}");
}

#[test]
fn include_step_reports_unknown_files() {
    assert!(compose("no-such-file.wgsl").is_err());
}

/// The denoiser's f16 variant (tensors stored as vec4<f16> on devices with shader-f16)
/// parses and validates with naga's f16 capability, and is the f32 kernel otherwise.
#[test]
fn the_denoiser_s_f16_variant_validates() {
    let src = veach::gpu::shaders::denoise_source(true).unwrap();
    assert!(src.starts_with("enable f16;") && src.contains("alias tensor4 = vec4<f16>;"));
    let module = naga::front::wgsl::parse_str(&src).unwrap_or_else(|e| panic!("{}", e.emit_to_string(&src)));
    naga::valid::Validator::new(naga::valid::ValidationFlags::all(), naga::valid::Capabilities::SHADER_FLOAT16)
        .validate(&module)
        .unwrap_or_else(|e| panic!("{e:?}"));
    assert_eq!(veach::gpu::shaders::denoise_source(false).unwrap(), compose(veach::gpu::shaders::DENOISE).unwrap());
}
