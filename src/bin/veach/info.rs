//! `veach info`: the GPU adapters and their limits, or a scene's contents.

use crate::args::InfoArgs;
use veach::Error;

pub fn run(args: &InfoArgs) -> Result<(), Error> {
    if let Some(path) = args.scene.as_deref() {
        let choice = veach::scene::gltf::Choice { scene: args.scene_index, variant: args.variant.clone() };
        println!("{}", veach::scene::gltf::describe_file(path, &choice, args.camera.as_deref())?);
        let options = veach::LoadOptions {
            camera: args.camera.as_deref(),
            scene: args.scene_index,
            variant: args.variant.as_deref(),
        };
        let loaded = veach::load_with(path, &options)?;
        if !loaded.scene.textures.is_empty() {
            let atlas = veach::packed::pack_textures(&loaded.scene.textures);
            let images: u64 = loaded.scene.textures.iter().map(|t| t.width as u64 * t.height as u64 * 4).sum();
            println!(
                "  texture atlas: {} page(s) of {}², {:.1} MiB ({:.1} MiB of images, {:.0} % of the pages used)",
                atlas.pages,
                atlas.side,
                atlas.bytes() as f64 / 1048576.0,
                images as f64 / 1048576.0,
                100.0 * atlas.occupancy()
            );
            for w in &atlas.warnings {
                println!("  {w}");
            }
        }
        return Ok(());
    }
    let adapters = veach::gpu::adapters();
    if adapters.is_empty() {
        return Err(Error::NoAdapter(veach::gpu::NO_ADAPTER_HINT.into()));
    }
    for (info, limits) in adapters {
        println!(
            "{} ({:?}, {:?}, driver {} {})",
            info.name, info.device_type, info.backend, info.driver, info.driver_info
        );
        println!("  max_storage_buffer_binding_size {}", limits.max_storage_buffer_binding_size);
        println!("  max_buffer_size {}", limits.max_buffer_size);
        println!("  max_texture_dimension_2d {}", limits.max_texture_dimension_2d);
        println!("  max_texture_array_layers {}", limits.max_texture_array_layers);
        println!("  max_compute_workgroups_per_dimension {}", limits.max_compute_workgroups_per_dimension);
        println!("  max_compute_invocations_per_workgroup {}", limits.max_compute_invocations_per_workgroup);
        println!("  max_storage_buffers_per_shader_stage {}", limits.max_storage_buffers_per_shader_stage);
        println!("  subgroup size {}..{}", info.subgroup_min_size, info.subgroup_max_size);
    }
    Ok(())
}
