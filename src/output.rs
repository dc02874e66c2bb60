//! Writing images: PNG (exposure, clamp, sRGB) and EXR (linear f32 RGB), always through a
//! temporary file renamed into place so a reader never sees a partial image.

use crate::Error;
use crate::film::Film;
use std::path::{Path, PathBuf};

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Format {
    Png,
    Exr,
}

/// The output format from the extension, and a check that the file can be written,
/// made before any rendering starts.
pub fn check_output(path: &Path) -> Result<Format, Error> {
    let ext = path.extension().and_then(|e| e.to_str()).map(str::to_ascii_lowercase);
    let format = match ext.as_deref() {
        Some("png") => Format::Png,
        Some("exr") => Format::Exr,
        _ => {
            return Err(Error::Input(format!(
                "{}: unknown output format (use a .png or .exr extension)",
                path.display()
            )));
        }
    };
    if path.is_dir() {
        return Err(Error::Input(format!("{}: is a directory", path.display())));
    }
    let probe = temp_path(path);
    std::fs::write(&probe, b"").map_err(|e| Error::Input(format!("{}: cannot write output: {e}", path.display())))?;
    let _ = std::fs::remove_file(&probe);
    Ok(format)
}

fn temp_path(path: &Path) -> PathBuf {
    let name = path.file_name().map(|n| n.to_string_lossy().into_owned()).unwrap_or_default();
    path.with_file_name(format!(".{name}.{}.tmp", std::process::id()))
}

/// Linear radiance → 8-bit sRGB, after scaling by 2^exposure and clamping.
pub fn to_srgb8(linear: f32, exposure: f32) -> u8 {
    let v = (linear * exposure.exp2()).clamp(0.0, 1.0);
    let s = if v <= 0.0031308 { 12.92 * v } else { 1.055 * v.powf(1.0 / 2.4) - 0.055 };
    (s * 255.0 + 0.5) as u8
}

/// The film's mean, exposed, clamped and sRGB-encoded.
pub fn tonemap(film: &Film, exposure: f32) -> image::RgbImage {
    let mut img = image::RgbImage::new(film.width, film.height);
    for (i, px) in img.pixels_mut().enumerate() {
        let m = film.mean(i);
        *px = image::Rgb([to_srgb8(m.x, exposure), to_srgb8(m.y, exposure), to_srgb8(m.z, exposure)]);
    }
    img
}

pub fn write(film: &Film, path: &Path, exposure: f32) -> Result<(), Error> {
    match check_output(path)? {
        Format::Png => write_png(&tonemap(film, exposure), path),
        Format::Exr => {
            let mut img = image::Rgb32FImage::new(film.width, film.height);
            for (i, px) in img.pixels_mut().enumerate() {
                let m = film.mean(i);
                *px = image::Rgb([m.x, m.y, m.z]);
            }
            save_atomic(path, |tmp| img.save_with_format(tmp, image::ImageFormat::OpenExr))
        }
    }
}

pub fn write_png(img: &image::RgbImage, path: &Path) -> Result<(), Error> {
    save_atomic(path, |tmp| img.save_with_format(tmp, image::ImageFormat::Png))
}

fn save_atomic(path: &Path, save: impl FnOnce(&Path) -> image::ImageResult<()>) -> Result<(), Error> {
    let tmp = temp_path(path);
    let io = |e: String| Error::Input(format!("{}: cannot write output: {e}", path.display()));
    let result = save(&tmp);
    if let Err(e) = result {
        let _ = std::fs::remove_file(&tmp);
        return Err(io(e.to_string()));
    }
    std::fs::rename(&tmp, path).map_err(|e| {
        let _ = std::fs::remove_file(&tmp);
        io(e.to_string())
    })
}

/// Reads a linear RGB EXR (references, tests).
pub fn read_exr(path: &Path) -> Result<(u32, u32, Vec<f32>), Error> {
    let img = image::open(path).map_err(|e| Error::Input(format!("{}: {e}", path.display())))?;
    let rgb = img.to_rgb32f();
    Ok((rgb.width(), rgb.height(), rgb.into_raw()))
}
