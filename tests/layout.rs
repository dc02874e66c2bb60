//! The Rust↔WGSL contract, checked without a GPU: every record shared by the host and the
//! kernel has the same size and member offsets on both sides (naga's layouter), the shared
//! constants have the same values, every override constant the host sets exists in the
//! kernel, and the shader list is the `shaders/` folder.

use bytemuck::Zeroable;
use std::collections::HashMap;
use veach::accel::{BvhNode, CwNode, Instance};
use veach::denoise::gpu::ConvParams;
use veach::gpu::shaders::{self, Geometry, SOURCES};
use veach::packed::{Attributes, LightEntry, Material, Punctual, TextureRef, Triangle};
use veach::params::Params;

fn module(entry: &str, geometry: Geometry) -> naga::Module {
    let src = shaders::compose_with(entry, geometry).unwrap_or_else(|e| panic!("{entry}: {e}"));
    naga::front::wgsl::parse_str(&src).unwrap_or_else(|e| panic!("{entry}: {}", e.emit_to_string(&src)))
}

/// Every named struct of the modules: name → (size, [(member, offset, size)]).
/// A record's size and its (member, offset, size) list.
type Layout = (u32, Vec<(String, u32, u32)>);

fn wgsl_structs(modules: &[naga::Module]) -> HashMap<String, Layout> {
    let mut out = HashMap::new();
    for m in modules {
        let mut layouter = naga::proc::Layouter::default();
        layouter.update(m.to_ctx()).expect("layout");
        for (handle, ty) in m.types.iter() {
            if let (Some(name), naga::TypeInner::Struct { members, span }) = (&ty.name, &ty.inner) {
                let members = members
                    .iter()
                    .map(|mb| (mb.name.clone().unwrap_or_default(), mb.offset, layouter[mb.ty].size))
                    .collect();
                let _ = handle;
                out.insert(name.clone(), (*span, members));
            }
        }
    }
    out
}

/// A Rust record's size and (field, offset, size) list.
macro_rules! rust_layout {
    ($t:ty { $($f:ident),* $(,)? }) => {{
        let z = <$t>::zeroed();
        (
            std::mem::size_of::<$t>() as u32,
            vec![$((stringify!($f).to_string(), std::mem::offset_of!($t, $f) as u32, std::mem::size_of_val(&z.$f) as u32)),*],
        )
    }};
}

/// Where a WGSL member that has no Rust field of its name lives in the Rust record: (struct,
/// WGSL member) → (Rust field, byte offset inside it). Arrays in Rust are single members in
/// WGSL where WGSL cannot express them in the same layout (vec2 arrays, padding scalars); the
/// CWBVH node is read as five 16-byte words (field-wise loads were 12 % slower on lavapipe).
const RENAMED: &[(&str, &str, &str, u32)] = &[
    ("Attributes", "uv0", "uv", 0),
    ("Attributes", "uv1", "uv", 8),
    ("Attributes", "uv2", "uv", 16),
    ("Punctual", "pad0", "pad", 0),
    ("Punctual", "pad1", "pad", 4),
    ("Punctual", "pad2", "pad", 8),
    ("CwNode", "w0", "p", 0),
    ("CwNode", "w1", "child_base", 0),
];

/// Records stored in 32-byte slots of the node buffer: Rust pads them to whole slots, WGSL
/// reads them field by field, so only the Rust size rounds up.
const SLOT_RECORDS: &[&str] = &["CwNode", "Instance"];

#[test]
fn shared_records_have_the_same_layout_in_rust_and_wgsl() {
    let modules = [
        module(shaders::INTEGRATOR, Geometry::Buffers),
        module(shaders::INTEGRATOR, Geometry::Textures),
        module(shaders::DENOISE, Geometry::Buffers),
    ];
    let wgsl = wgsl_structs(&modules);
    let rust: Vec<(&str, Layout)> = vec![
        (
            "Params",
            rust_layout!(Params {
                cam_position,
                film_width,
                cam_right,
                film_height,
                cam_up,
                sample_index,
                cam_forward,
                seed,
                environment,
                max_depth,
                strategy,
                light_count,
                rr_depth,
                image_width,
                image_height,
                tile_x,
                tile_y,
                env_select,
                env_width,
                env_height,
                env_total,
                aperture,
                focus_distance,
                row_offset,
                punctual_base,
                punctual_count,
                instance_base,
                sampler,
                light_sampler,
                tree_emitters,
                tree_base,
                trail_base,
                separate_punctuals,
                clamp_direct,
                clamp_indirect,
                noise_threshold,
                adaptive_min_samples,
                adaptive_step,
                sheen_base,
                aov_base,
                projection,
                extras_base,
                light_candidates,
                pad0,
                pad1,
                pad2
            }),
        ),
        ("Triangle", rust_layout!(Triangle { p0, material, e1, light_pdf_area, e2, flags })),
        ("Attributes", rust_layout!(Attributes { n, t0, t12, uv })),
        ("TextureRef", rust_layout!(TextureRef { row0, atlas, row1, mode })),
        (
            "Material",
            rust_layout!(Material {
                base_color,
                metallic,
                emission,
                roughness,
                dielectric_f0,
                ior,
                dielectric_f90,
                transmission,
                alpha,
                alpha_cutoff,
                attenuation,
                flags,
                normal_scale,
                clearcoat,
                clearcoat_roughness,
                clearcoat_normal_scale,
                sheen_color,
                sheen_roughness,
                coat_normal,
                anisotropy,
                specular_f0,
                diffuse_transmission,
                anisotropy_rotation,
                anisotropy_tangent,
                iridescence,
                iridescence_ior,
                iridescence_thickness_min,
                iridescence_thickness_max,
                diffuse_transmission_color,
                dispersion,
                base_color_texture,
                metallic_roughness_texture,
                emissive_texture,
                normal_texture,
                transmission_texture,
                specular_texture,
                specular_color_texture,
                clearcoat_texture,
                clearcoat_roughness_texture,
                clearcoat_normal_texture,
                sheen_color_texture,
                sheen_roughness_texture,
                anisotropy_texture,
                iridescence_texture,
                iridescence_thickness_texture,
                diffuse_transmission_texture,
                diffuse_transmission_color_texture
            }),
        ),
        ("LightEntry", rust_layout!(LightEntry { triangle, alias_slot, prob, pmf })),
        ("Punctual", rust_layout!(Punctual { position, kind, direction, range, intensity, cos_inner, cos_outer, pad })),
        ("Instance", rust_layout!(Instance { object_to_world, world_to_object, blas_root, flags, pad })),
        ("BvhNode", rust_layout!(BvhNode { min, index, max, count })),
        ("CwNode", rust_layout!(CwNode { p, e_imask, child_base, primitive_base, child_meta, qx, qy, qz, pad })),
        (
            "ConvParams",
            rust_layout!(ConvParams { width, height, a_blocks, b_blocks, out_blocks, a_half, pool, quad_row_offset }),
        ),
    ];
    let mut wrong = Vec::new();
    for (name, (rust_size, fields)) in &rust {
        let Some((wgsl_size, members)) = wgsl.get(*name) else {
            wrong.push(format!("{name}: no WGSL struct of that name"));
            continue;
        };
        let expected = if SLOT_RECORDS.contains(name) { wgsl_size.next_multiple_of(32) } else { *wgsl_size };
        if *rust_size != expected {
            wrong.push(format!("{name}: {rust_size} bytes in Rust, {wgsl_size} in WGSL"));
        }
        let mut covered = vec![false; *rust_size as usize];
        for (member, offset, size) in members {
            let (field, within) = match RENAMED.iter().find(|r| r.0 == *name && r.1 == member) {
                Some(r) => (r.2, r.3),
                None => (member.as_str(), 0),
            };
            match fields.iter().find(|f| f.0 == field) {
                None => wrong.push(format!("{name}.{member}: no Rust field {field}")),
                Some((_, rust_offset, _)) if rust_offset + within != *offset => wrong.push(format!(
                    "{name}.{member}: offset {offset} in WGSL, {} in Rust ({field})",
                    rust_offset + within
                )),
                Some(_) => covered[*offset as usize..(*offset + *size) as usize].iter_mut().for_each(|c| *c = true),
            }
        }
        // Every Rust field is read by the kernel (trailing slot padding aside).
        for (field, offset, size) in fields {
            let read = covered[*offset as usize..(*offset + *size) as usize].iter().all(|c| *c);
            let slot_padding = field == "pad" && SLOT_RECORDS.contains(name);
            if !read && !slot_padding {
                wrong.push(format!("{name}.{field}: not covered by the WGSL struct"));
            }
        }
    }
    assert!(wrong.is_empty(), "layout mismatches:\n{}", wrong.join("\n"));
}

/// Every `const` of every shader file, evaluated (scalar literals only).
fn wgsl_constants() -> HashMap<String, f64> {
    let mut out = HashMap::new();
    for (name, _) in SOURCES {
        let m = module(name, Geometry::Buffers);
        for (_, c) in m.constants.iter() {
            let value = match m.global_expressions[c.init] {
                naga::Expression::Literal(naga::Literal::U32(v)) => v as f64,
                naga::Expression::Literal(naga::Literal::I32(v)) => v as f64,
                naga::Expression::Literal(naga::Literal::F32(v)) => v as f64,
                naga::Expression::Literal(naga::Literal::AbstractInt(v)) => v as f64,
                naga::Expression::Literal(naga::Literal::AbstractFloat(v)) => v,
                _ => continue,
            };
            if let Some(n) = &c.name
                && let Some(previous) = out.insert(n.clone(), value)
            {
                assert_eq!(previous, value, "{n} has two values in the shaders");
            }
        }
    }
    out
}

#[test]
fn shared_constants_have_the_same_values() {
    use veach::packed as p;
    let wgsl = wgsl_constants();
    let rust: &[(&str, f64)] = &[
        ("STACK_SIZE", veach::accel::MAX_DEPTH as f64),
        ("TRI_HAS_NORMALS", p::TRI_HAS_NORMALS as f64),
        ("TRI_HAS_TANGENTS", p::TRI_HAS_TANGENTS as f64),
        ("TRI_ALPHA", p::TRI_ALPHA as f64),
        ("TRI_TANGENT_SIGN_SHIFT", p::TRI_TANGENT_SIGN_SHIFT as f64),
        ("TRI_MIRRORED", p::TRI_MIRRORED as f64),
        ("TRI_EMITTER_SHIFT", p::TRI_EMITTER_SHIFT as f64),
        ("LIGHT_NODE_ROWS", p::LIGHT_NODE_ROWS as f64),
        ("LIGHT_TREE_WIDTH", p::LIGHT_TREE_WIDTH as f64),
        ("LIGHT_LEAF", p::LIGHT_LEAF as f64),
        ("LIGHT_TWO_SIDED", p::LIGHT_TWO_SIDED as f64),
        ("LIGHT_CLUSTER", p::LIGHT_CLUSTER as f64),
        ("LIGHT_PLANAR", p::LIGHT_PLANAR as f64),
        ("LIGHT_INDEX_MASK", p::LIGHT_INDEX_MASK as f64),
        ("CLUSTER_LAST", p::CLUSTER_LAST as f64),
        ("LIGHT_SAMPLER_POWER", veach::LightSampler::Power as u32 as f64),
        ("PROJECTION_PERSPECTIVE", veach::params::PROJECTION_PERSPECTIVE as f64),
        ("PROJECTION_ORTHOGRAPHIC", veach::params::PROJECTION_ORTHOGRAPHIC as f64),
        ("LIGHT_SAMPLER_TREE", veach::LightSampler::Tree as u32 as f64),
        ("GLOSSY_ROUGHNESS", veach::cpu::integrator::GLOSSY_ROUGHNESS as f64),
        ("MAT_ALPHA_MASK", p::MAT_ALPHA_MASK as f64),
        ("MAT_ALPHA_BLEND", p::MAT_ALPHA_BLEND as f64),
        ("MAT_DOUBLE_SIDED", p::MAT_DOUBLE_SIDED as f64),
        ("MAT_THIN_WALLED", p::MAT_THIN_WALLED as f64),
        ("NO_TEXTURE", p::NO_TEXTURE as f64),
        ("TEX_SRGB", p::TEX_SRGB as f64),
        ("TEX_UV1", p::TEX_UV1 as f64),
        ("TEX_PAGE_SHIFT", p::TEX_PAGE_SHIFT as f64),
        ("TEX_X_SHIFT", p::TEX_X_SHIFT as f64),
        ("TEX_COORD_MASK", p::TEX_COORD_MASK as f64),
        ("TEX_WIDTH_SHIFT", p::TEX_WIDTH_SHIFT as f64),
        ("TEX_HEIGHT_SHIFT", p::TEX_HEIGHT_SHIFT as f64),
        ("TEX_SIZE_MASK", p::TEX_SIZE_MASK as f64),
        ("INSTANCE_MIRRORED", p::INSTANCE_MIRRORED as f64),
        ("PUNCTUAL_POINT", p::PUNCTUAL_POINT as f64),
        ("PUNCTUAL_SPOT", p::PUNCTUAL_SPOT as f64),
        ("PUNCTUAL_DIRECTIONAL", p::PUNCTUAL_DIRECTIONAL as f64),
        ("STRATEGY_BSDF", veach::Strategy::Bsdf as u32 as f64),
        ("STRATEGY_LIGHT", veach::Strategy::Light as u32 as f64),
        ("STRATEGY_MIS_BALANCE", veach::Strategy::MisBalance as u32 as f64),
        ("STRATEGY_MIS_POWER", veach::Strategy::MisPower as u32 as f64),
        ("SAMPLER_INDEPENDENT", veach::SamplerKind::Independent as u32 as f64),
        ("SAMPLER_SOBOL", veach::SamplerKind::Sobol as u32 as f64),
        ("TONEMAP_CLAMP", veach::tonemap::Tonemap::Clamp as u32 as f64),
        ("TONEMAP_ACES", veach::tonemap::Tonemap::Aces as u32 as f64),
        ("TONEMAP_AGX", veach::tonemap::Tonemap::Agx as u32 as f64),
        ("TONEMAP_NEUTRAL", veach::tonemap::Tonemap::Neutral as u32 as f64),
        ("FILM_WORDS", (veach::film::WORDS_PER_PIXEL / 4) as f64),
        ("ADAPTIVE_WORDS", veach::film::ADAPTIVE_WORDS as f64),
        ("AOV_ROWS", (veach::film::AOV_WORDS / 4) as f64),
        ("TLAS_STACK_SIZE", veach::cpu::bvh::TLAS_STACK_SIZE as f64),
        ("DENOISE_BLOCKS", veach::denoise::gpu::DENOISE_BLOCKS as f64),
        ("MAX_SAMPLE", veach::film::MAX_SAMPLE as f64),
        ("PAGE_ROW_LOG2", veach::gpu::PAGE_ROW_LOG2 as f64),
        ("NO_HIT", veach::cpu::bvh::NO_HIT as f64),
        ("INF", veach::cpu::common::INF as f64),
        ("DELTA_ALPHA", veach::cpu::bsdf::DELTA_ALPHA as f64),
        ("CLEARCOAT_F0", veach::cpu::clearcoat::CLEARCOAT_F0 as f64),
        ("SHEEN_MIN_ROUGHNESS", veach::sheen::SHEEN_MIN_ROUGHNESS as f64),
        ("SHEEN_TABLE_COS", veach::sheen::SHEEN_TABLE_COS as f64),
        ("SHEEN_TABLE_ROUGHNESS", veach::sheen::SHEEN_TABLE_ROUGHNESS as f64),
        ("UNIFORM_SPHERE_PDF", veach::cpu::sampling::UNIFORM_SPHERE_PDF as f64),
        ("UNIFORM_HEMISPHERE_PDF", veach::cpu::sampling::UNIFORM_HEMISPHERE_PDF as f64),
        ("SOLID_ANGLE_MIN", veach::cpu::spherical_triangle::SOLID_ANGLE_MIN as f64),
        ("SOLID_ANGLE_MAX", veach::cpu::spherical_triangle::SOLID_ANGLE_MAX as f64),
        ("ONE_MINUS_EPSILON", veach::cpu::common::ONE_MINUS_EPSILON as f64),
        ("ALL_CHANNELS", veach::cpu::integrator::ALL_CHANNELS as f64),
    ];
    let mut wrong = Vec::new();
    for (name, value) in rust {
        match wgsl.get(*name) {
            None => wrong.push(format!("{name}: no WGSL constant")),
            // f32 constants compare at f32 precision.
            Some(w) if (*w as f32) != (*value as f32) => wrong.push(format!("{name}: {w} in WGSL, {value} in Rust")),
            Some(_) => {}
        }
    }
    assert!(wrong.is_empty(), "constant mismatches:\n{}", wrong.join("\n"));
}

#[test]
fn every_override_the_host_sets_exists_in_the_kernel() {
    let features = veach::packed::Features {
        alpha_test: true,
        textures: true,
        punctual_lights: true,
        transmission: true,
        instancing: true,
        clearcoat: true,
        sheen: true,
        anisotropy: true,
        iridescence: true,
        diffuse_transmission: true,
        dispersion: true,
        aovs: true,
        vertex_extras: true,
    };
    for (entry, extra) in [(shaders::INTEGRATOR, None), (shaders::TRACE, Some("TRACE_KIND"))] {
        for geometry in [Geometry::Buffers, Geometry::Textures] {
            let m = module(entry, geometry);
            let names: Vec<String> = m.overrides.iter().filter_map(|(_, o)| o.name.clone()).collect();
            for (name, _) in features.constants().iter().map(|(n, v)| (*n, *v)).chain(extra.map(|e| (e, 0.0))) {
                assert!(names.iter().any(|n| n == name), "{entry} ({geometry:?}) has no override {name}: {names:?}");
            }
        }
    }
}

#[test]
fn the_shader_list_is_the_shaders_folder() {
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("shaders");
    let mut files: Vec<String> = std::fs::read_dir(&dir)
        .expect("shaders/")
        .flatten()
        .map(|e| e.file_name().to_string_lossy().into_owned())
        .filter(|n| n.ends_with(".wgsl"))
        .collect();
    files.sort();
    let mut listed: Vec<String> = SOURCES.iter().map(|(n, _)| n.to_string()).collect();
    listed.sort();
    assert_eq!(files, listed, "gpu::shaders::SOURCES must list exactly the files in shaders/");
    for (name, text) in SOURCES {
        let on_disk = std::fs::read_to_string(dir.join(name)).expect("shader file");
        assert_eq!(&on_disk, text, "{name}: the embedded text is stale");
        for (i, line) in text.lines().enumerate() {
            assert!(line.chars().count() <= 120, "{name}:{}: {} characters (at most 120)", i + 1, line.chars().count());
        }
    }
}

#[test]
fn the_host_binding_table_is_the_kernel_s() {
    for geometry in [Geometry::Buffers, Geometry::Textures] {
        let m = module(shaders::INTEGRATOR, geometry);
        let mut kernel: Vec<(u32, String)> = m
            .global_variables
            .iter()
            .filter_map(|(_, g)| Some((g.binding.as_ref()?.binding, g.name.clone().unwrap_or_default())))
            .collect();
        kernel.sort();
        let host: Vec<u32> = veach::gpu::BINDINGS.iter().map(|b| b.0).collect();
        assert_eq!(kernel.iter().map(|k| k.0).collect::<Vec<_>>(), host, "{geometry:?}: binding numbers");
        if geometry == Geometry::Buffers {
            let names: Vec<&str> = veach::gpu::BINDINGS.iter().map(|b| b.2).collect();
            assert_eq!(kernel.iter().map(|k| k.1.as_str()).collect::<Vec<_>>(), names, "binding names");
        }
    }
}
