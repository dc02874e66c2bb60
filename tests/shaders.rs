//! Every WGSL file, after the include step, parses and validates with naga (no GPU needed).

use veach::gpu::shaders::{Geometry, INTEGRATOR, SOURCES, compose, compose_with};

fn validate(name: &str) -> naga::Module {
    let src = compose(name).unwrap_or_else(|e| panic!("{name}: {e}"));
    let module = naga::front::wgsl::parse_str(&src).unwrap_or_else(|e| panic!("{name}:\n{}", e.emit_to_string(&src)));
    naga::valid::Validator::new(naga::valid::ValidationFlags::all(), naga::valid::Capabilities::default())
        .validate(&module)
        .unwrap_or_else(|e| panic!("{name}: {}", e.emit_to_string(&src)));
    module
}

#[test]
fn every_shader_file_validates_after_includes() {
    assert!(SOURCES.len() >= 10);
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
fn include_step_reports_unknown_files() {
    assert!(compose("no-such-file.wgsl").is_err());
}
