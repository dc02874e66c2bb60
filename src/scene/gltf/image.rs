//! glTF images decoded to 8-bit RGBA within limits on size and memory.

use super::resources;
use crate::scene::Texture;

/// Largest image side decoded; bigger images are refused with a warning.
pub const MAX_DECODED_IMAGE_SIDE: u32 = 16384;

/// One glTF image as 8-bit RGBA, decoded within limits on size and memory.
pub fn decode_image(
    image: &gltf::Image,
    base: resources::Base,
    buffers: &[gltf::buffer::Data],
) -> Result<Texture, String> {
    use image::DynamicImage;
    let encoded = resources::image_bytes(image, buffers, base)?;
    let name = image.name().map(str::to_string).unwrap_or_else(|| format!("image {}", image.index()));
    if encoded.starts_with(&KTX2_MAGIC) {
        return decode_ktx2(&encoded, name);
    }
    let mut reader = image::ImageReader::new(std::io::Cursor::new(&encoded[..]))
        .with_guessed_format()
        .map_err(|e| format!("cannot decode: {e}"))?;
    let mut limits = image::Limits::default();
    limits.max_image_width = Some(MAX_DECODED_IMAGE_SIDE);
    limits.max_image_height = Some(MAX_DECODED_IMAGE_SIDE);
    limits.max_alloc = Some(MAX_DECODED_IMAGE_BYTES);
    reader.limits(limits);
    let decoded = reader.decode().map_err(|e| format!("cannot decode: {e}"))?;
    let (w, h) = (decoded.width(), decoded.height());
    if w == 0 || h == 0 || w > MAX_DECODED_IMAGE_SIDE || h > MAX_DECODED_IMAGE_SIDE {
        return Err(format!("{w}×{h} pixels is outside 1..{MAX_DECODED_IMAGE_SIDE}"));
    }
    // 8-bit images as they are; 16-bit by their high byte; float by clamping (the channel
    // layouts glTF's images come in).
    let (channels, decoded) = match decoded {
        DynamicImage::ImageLuma8(_) | DynamicImage::ImageLuma16(_) => (1, decoded),
        DynamicImage::ImageLumaA8(_) | DynamicImage::ImageLumaA16(_) => (2, decoded),
        DynamicImage::ImageRgb8(_) | DynamicImage::ImageRgb16(_) | DynamicImage::ImageRgb32F(_) => (3, decoded),
        other => (4, other),
    };
    let (is16, is32) = (
        matches!(
            decoded,
            DynamicImage::ImageLuma16(_)
                | DynamicImage::ImageLumaA16(_)
                | DynamicImage::ImageRgb16(_)
                | DynamicImage::ImageRgba16(_)
        ),
        matches!(decoded, DynamicImage::ImageRgb32F(_) | DynamicImage::ImageRgba32F(_)),
    );
    let decoded = match decoded {
        d @ (DynamicImage::ImageLuma8(_)
        | DynamicImage::ImageLumaA8(_)
        | DynamicImage::ImageRgb8(_)
        | DynamicImage::ImageRgba8(_)
        | DynamicImage::ImageLuma16(_)
        | DynamicImage::ImageLumaA16(_)
        | DynamicImage::ImageRgb16(_)
        | DynamicImage::ImageRgba16(_)
        | DynamicImage::ImageRgb32F(_)
        | DynamicImage::ImageRgba32F(_)) => d,
        other => DynamicImage::ImageRgba8(other.to_rgba8()),
    };
    let data = DecodedPixels { width: w, height: h, pixels: decoded.into_bytes() };
    let (w, h) = (data.width, data.height);
    if w == 0 || h == 0 || w > MAX_DECODED_IMAGE_SIDE || h > MAX_DECODED_IMAGE_SIDE {
        return Err(format!("{w}×{h} pixels is outside 1..{MAX_DECODED_IMAGE_SIDE}"));
    }
    let px = &data.pixels;
    let n = (w * h) as usize;
    let bytes_per_channel = if is32 {
        4
    } else if is16 {
        2
    } else {
        1
    };
    if px.len() != n * channels * bytes_per_channel {
        return Err(format!("decoded to {} bytes, not {w}×{h}×{channels} channels", px.len()));
    }
    let u16_at = |i: usize| (u16::from_ne_bytes([px[2 * i], px[2 * i + 1]]) >> 8) as u8;
    let f32_at = |i: usize| {
        let v = f32::from_ne_bytes([px[4 * i], px[4 * i + 1], px[4 * i + 2], px[4 * i + 3]]);
        (v.clamp(0.0, 1.0) * 255.0 + 0.5) as u8
    };
    let get: &dyn Fn(usize) -> u8 = if is32 {
        &f32_at
    } else if is16 {
        &u16_at
    } else {
        &|i| px[i]
    };
    let mut rgba = Vec::with_capacity(4 * n);
    for p in 0..n {
        let c = |k: usize| get(p * channels + k);
        let texel = match channels {
            1 => [c(0), c(0), c(0), 255],
            2 => [c(0), c(0), c(0), c(1)],
            3 => [c(0), c(1), c(2), 255],
            _ => [c(0), c(1), c(2), c(3)],
        };
        rgba.extend_from_slice(&texel);
    }
    Ok(Texture { name, width: w, height: h, rgba })
}

/// The identifier that opens every KTX2 file.
const KTX2_MAGIC: [u8; 12] = [0xAB, 0x4B, 0x54, 0x58, 0x20, 0x32, 0x30, 0xBB, 0x0D, 0x0A, 0x1A, 0x0A];

/// A KTX2 image of KHR_texture_basisu (Basis Universal: ETC1S or UASTC), its first level
/// transcoded to 8-bit RGBA by the pure-Rust `basisu` transcoder.
fn decode_ktx2(encoded: &[u8], name: String) -> Result<Texture, String> {
    let fail = |e: basisu::Error| format!("cannot decode KTX2/Basis Universal: {e:?}");
    let transcoder = basisu::Transcoder::new(encoded).map_err(fail)?;
    let (w, h) = transcoder.base_dimensions();
    if w == 0 || h == 0 || w > MAX_DECODED_IMAGE_SIDE || h > MAX_DECODED_IMAGE_SIDE {
        return Err(format!("{w}×{h} pixels is outside 1..{MAX_DECODED_IMAGE_SIDE}"));
    }
    let rgba = transcoder.transcode(0, basisu::TargetFormat::Rgba32, basisu::DecodeFlags::NONE).map_err(fail)?;
    if rgba.len() != (w * h * 4) as usize {
        return Err(format!("transcoded to {} bytes, not {w}×{h} RGBA", rgba.len()));
    }
    Ok(Texture { name, width: w, height: h, rgba })
}

/// Decoded pixels in the decoder's channel layout.
struct DecodedPixels {
    width: u32,
    height: u32,
    pixels: Vec<u8>,
}

/// Largest decoded image held (RGBA32F at the largest side would be 4 GiB).
const MAX_DECODED_IMAGE_BYTES: u64 = 1 << 30;
