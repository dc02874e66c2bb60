//! Named layers of EXR images (`albedo.R`, `normal.X`, `denoised.R`, ...), as Blender, tev
//! and OpenImageIO read them: the inputs of a denoise, and layers added to a written image.

use crate::Error as VeachError;
use std::path::Path;

/// The images a denoise needs from an EXR: colour (`R`, `G`, `B`) and, when present, the
/// `albedo` and `normal` layers; three floats a pixel, row-major.
#[derive(Clone, Debug)]
pub struct Layers {
    pub width: usize,
    pub height: usize,
    pub color: Vec<f32>,
    pub albedo: Option<Vec<f32>>,
    pub normal: Option<Vec<f32>>,
}

type ExrImage = exr::image::Image<exr::image::Layer<exr::image::AnyChannels<exr::image::FlatSamples>>>;

fn read_image(path: &Path) -> Result<ExrImage, VeachError> {
    use exr::prelude::*;
    let fail = |m: String| VeachError::Input(format!("{}: {m}", path.display()));
    crate::output::check_exr_size(path).map_err(fail)?;
    read()
        .no_deep_data()
        .largest_resolution_level()
        .all_channels()
        .first_valid_layer()
        .all_attributes()
        .from_file(path)
        .map_err(|e| fail(format!("cannot read EXR: {e}")))
}

fn channel_f32(samples: &exr::image::FlatSamples) -> Vec<f32> {
    use exr::image::FlatSamples;
    match samples {
        FlatSamples::F16(v) => v.iter().map(|h| h.to_f32()).collect(),
        FlatSamples::F32(v) => v.clone(),
        FlatSamples::U32(v) => v.iter().map(|&u| u as f32).collect(),
    }
}

/// Reads the colour and the albedo and normal layers of an EXR.
pub fn read_layers(path: &Path) -> Result<Layers, VeachError> {
    let image = read_image(path)?;
    let layer = &image.layer_data;
    let (width, height) = (layer.size.width(), layer.size.height());
    let find = |names: &[&str]| -> Option<Vec<f32>> {
        let mut out = vec![0.0; width * height * 3];
        for (c, name) in names.iter().enumerate() {
            let channel = layer.channel_data.list.iter().find(|ch| ch.name == **name)?;
            for (i, v) in channel_f32(&channel.sample_data).into_iter().enumerate().take(width * height) {
                out[i * 3 + c] = v;
            }
        }
        Some(out)
    };
    let color = find(&["R", "G", "B"])
        .ok_or_else(|| VeachError::Input(format!("{}: no R, G and B channels to denoise", path.display())))?;
    let albedo = find(&["albedo.R", "albedo.G", "albedo.B"]);
    let normal = find(&["normal.X", "normal.Y", "normal.Z"]).or_else(|| find(&["normal.R", "normal.G", "normal.B"]));
    Ok(Layers { width, height, color, albedo, normal })
}

/// Writes `input` again to `output` (atomically) with a layer `name` of three channels
/// (`name.R`, `name.G`, `name.B`) added or replaced; every other channel and attribute is
/// kept, so a veach render stays resumable and mergeable.
pub fn write_with_layer(input: &Path, output: &Path, name: &str, rgb: &[f32]) -> Result<(), VeachError> {
    use exr::prelude::*;
    let mut image = read_image(input)?;
    let layer = &mut image.layer_data;
    let pixels = layer.size.width() * layer.size.height();
    if rgb.len() != pixels * 3 {
        return Err(VeachError::Input(format!("{}: the {name} layer has the wrong size", output.display())));
    }
    let prefix = format!("{name}.");
    let mut channels: Vec<AnyChannel<FlatSamples>> =
        layer.channel_data.list.drain(..).filter(|c| !c.name.to_string().starts_with(&prefix)).collect();
    for (c, suffix) in ["R", "G", "B"].iter().enumerate() {
        let data = (0..pixels).map(|i| rgb[i * 3 + c]).collect();
        channels.push(AnyChannel::new(format!("{name}.{suffix}").as_str(), FlatSamples::F32(data)));
    }
    layer.channel_data = AnyChannels::sort(channels.into());
    crate::output::save_atomic(output, |tmp| {
        image.write().to_file(tmp).map_err(|e| image::ImageError::IoError(std::io::Error::other(e.to_string())))
    })
}
