//! Writes `assets/studio.hdr`, veach's default environment, from its generator
//! (`veach::scene::studio::generate_studio`). Run: `cargo run --release --example studio-environment`.

use veach::scene::studio::{STUDIO_HEIGHT, STUDIO_WIDTH, generate_studio};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let map = generate_studio(STUDIO_WIDTH, STUDIO_HEIGHT);
    let pixels: Vec<image::Rgb<f32>> = map.texels.iter().map(|t| image::Rgb(t.to_array())).collect();
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("assets/studio.hdr");
    let mut bytes = Vec::new();
    image::codecs::hdr::HdrEncoder::new(&mut bytes).encode(&pixels, map.width as usize, map.height as usize)?;
    std::fs::write(&path, &bytes)?;
    println!("wrote {} ({}x{}, {} bytes)", path.display(), map.width, map.height, bytes.len());
    Ok(())
}
