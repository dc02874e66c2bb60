//! `veach denoise`: an EXR's colour, with its albedo and normal layers, through Open Image
//! Denoise's network on the CPU twin (or the GPU passes).

use crate::args::DenoiseArgs;
use std::time::Instant;
use veach::Error;
use veach::denoise::{Engine, Images, Options};
use veach::output::Format;

pub fn run(args: &DenoiseArgs) -> Result<(), Error> {
    let format = veach::output::check_output(&args.output)?;
    let layers = veach::exr_layers::read_layers(&args.input)?;
    let images = Images {
        width: layers.width,
        height: layers.height,
        color: &layers.color,
        albedo: layers.albedo.as_deref(),
        normal: layers.normal.as_deref(),
    };
    let options = Options { quality: args.denoise_quality, input_scale: args.input_scale, max_tile_pixels: None };
    let (ctx, reason) = veach::denoise::device(args.backend)?;
    let engine = ctx.as_ref().map_or(Engine::Cpu, Engine::Gpu);
    let start = Instant::now();
    let out = veach::denoise::denoise(&images, &options, engine).map_err(|e| match e {
        Error::Input(m) => Error::Input(format!("{}: {m}", args.input.display())),
        e => e,
    })?;
    let seconds = start.elapsed().as_secs_f64();
    match format {
        Format::Png => veach::output::write_rgb(
            &out,
            layers.width as u32,
            layers.height as u32,
            &args.output,
            args.exposure,
            args.tonemap,
        )?,
        Format::Exr => veach::exr_layers::write_with_layer(&args.input, &args.output, "denoised", &out)?,
    }
    let (network, _) = veach::denoise::weight_file(args.denoise_quality, images.channels());
    let on = ctx.as_ref().map_or("the CPU".to_string(), |c| c.info.name.clone());
    eprintln!(
        "veach: denoised {} ({}x{}, {}) on {on} in {seconds:.2} s",
        args.input.display(),
        layers.width,
        layers.height,
        network
    );
    if let Some(path) = &args.stats_json {
        let stats = serde_json::json!({
            "width": layers.width,
            "height": layers.height,
            "network": network,
            "quality": args.denoise_quality.name(),
            "denoise_engine": engine.name(),
            "denoise_precision": engine.precision(),
            "denoise_engine_reason": reason,
            "denoise_seconds": seconds,
            "inputs": images.channels(),
        });
        let text = serde_json::to_string_pretty(&stats).unwrap_or_default();
        veach::output::write_atomic(path, text.as_bytes())?;
    }
    Ok(())
}
