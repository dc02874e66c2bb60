//! `veach bench`: samples/s and traversal throughput per backend (see BENCHMARKS.md).

use crate::args::BenchArgs;
use veach::{Backend, Error};

pub fn run(args: &BenchArgs) -> Result<(), Error> {
    if args.width == 0 || args.height == 0 || args.spp == 0 || args.large_grid == 0 || args.large_grid > 32 {
        return Err(Error::Input("bench: sizes and spp must be positive, --large-grid in 1..=32".into()));
    }
    if let Some(dir) = &args.write_scenes {
        let io = |e: std::io::Error| Error::Input(format!("{}: {e}", dir.display()));
        std::fs::create_dir_all(dir).map_err(io)?;
        veach::output::write_atomic(&dir.join("spheres-large.glb"), &veach::bench::large_scene_glb(args.large_grid))?;
        veach::output::write_atomic(
            &dir.join("many-lights.gltf"),
            &veach::bench::many_lights_gltf(veach::bench::MANY_LIGHTS),
        )?;
        veach::output::write_atomic(&dir.join("glossy-hall.gltf"), &veach::bench::glossy_hall_gltf())?;
        eprintln!("veach bench: wrote spheres-large.glb, many-lights.gltf and glossy-hall.gltf to {}", dir.display());
        return Ok(());
    }
    let backends = if args.backend.is_empty() { vec![Backend::Gpu, Backend::Cpu] } else { args.backend.clone() };
    let opts = veach::bench::BenchOptions {
        width: args.width,
        height: args.height,
        spp: args.spp,
        max_depth: args.max_depth,
        large_grid: args.large_grid,
        tree_emitters: args.tree_emitters,
    };
    let report = veach::bench::run(&opts, &backends, &mut |line| eprintln!("veach bench: {line}"))?;
    print!("{}", veach::bench::format_report(&report));
    if let Some(path) = &args.json {
        veach::output::write_atomic(path, serde_json::to_string_pretty(&report).unwrap_or_default().as_bytes())?;
    }
    Ok(())
}
