//! Writing images: PNG (exposure, clamp, sRGB) and EXR (linear f32 RGB), always through a
//! temporary file renamed into place so a reader never sees a partial image.

use crate::film::{Film, WORDS_PER_PIXEL};
use crate::tonemap::Tonemap;
use crate::{Error, Job};
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
    check_writable(path)?;
    Ok(format)
}

fn temp_path(path: &Path) -> PathBuf {
    let name = path.file_name().map(|n| n.to_string_lossy().into_owned()).unwrap_or_default();
    path.with_file_name(format!(".{name}.{}.tmp", std::process::id()))
}

/// The film's mean, exposed, tone-mapped and sRGB-encoded.
pub fn tonemap(film: &Film, exposure: f32, operator: Tonemap) -> image::RgbImage {
    tonemap_pixels(film.width, film.height, |i| film.mean(i), exposure, operator)
}

/// Linear RGB pixels (`pixel(i)`, row-major), exposed, tone-mapped and sRGB-encoded.
pub fn tonemap_pixels(
    width: u32,
    height: u32,
    pixel: impl Fn(usize) -> glam::Vec3,
    exposure: f32,
    operator: Tonemap,
) -> image::RgbImage {
    let mut img = image::RgbImage::new(width, height);
    let scale = exposure.exp2();
    for (i, px) in img.pixels_mut().enumerate() {
        let c = crate::tonemap::tonemap(pixel(i) * scale, operator);
        let q = |v: f32| (crate::tonemap::srgb_encode(v) * 255.0 + 0.5) as u8;
        *px = image::Rgb([q(c.x), q(c.y), q(c.z)]);
    }
    img
}

/// Writes a linear RGB image (three floats a pixel, row-major): a tone-mapped PNG or a
/// linear EXR of R, G and B.
pub fn write_rgb(
    rgb: &[f32],
    width: u32,
    height: u32,
    path: &Path,
    exposure: f32,
    operator: Tonemap,
) -> Result<(), Error> {
    let pixel = |i: usize| glam::Vec3::from_slice(&rgb[i * 3..i * 3 + 3]);
    match check_output(path)? {
        Format::Png => write_png(&tonemap_pixels(width, height, pixel, exposure, operator), path),
        Format::Exr => {
            use exr::prelude::*;
            let size = (width as usize, height as usize);
            let channels = SpecificChannels::rgb(|p: Vec2<usize>| {
                let c = pixel(p.y() * width as usize + p.x());
                (c.x, c.y, c.z)
            });
            let image = Image::from_channels(size, channels);
            save_atomic(path, |tmp| {
                image.write().to_file(tmp).map_err(|e| image::ImageError::IoError(std::io::Error::other(e.to_string())))
            })
        }
    }
}

/// Writes the film's image: a tone-mapped PNG, or a linear EXR that also carries the film
/// (sums, counts) and the job, so it can be resumed or merged with other parts.
pub fn write(film: &Film, path: &Path, exposure: f32, job: Option<&Job>) -> Result<(), Error> {
    write_with(film, path, exposure, Tonemap::Clamp, job)
}

pub fn write_with(film: &Film, path: &Path, exposure: f32, operator: Tonemap, job: Option<&Job>) -> Result<(), Error> {
    match check_output(path)? {
        Format::Png => write_png(&tonemap(film, exposure, operator), path),
        Format::Exr => write_exr(film, path, job, None),
    }
}

/// Writes a denoised render: a PNG of the denoised image (`denoised`: linear RGB, three
/// floats a pixel), or the film's EXR (noisy R, G, B, the AOVs, film and job) with a
/// `denoised` layer.
pub fn write_denoised(
    film: &Film,
    denoised: &[f32],
    path: &Path,
    exposure: f32,
    operator: Tonemap,
    job: Option<&Job>,
) -> Result<(), Error> {
    match check_output(path)? {
        Format::Png => write_rgb(denoised, film.width, film.height, path, exposure, operator),
        Format::Exr => write_exr(film, path, job, Some(denoised)),
    }
}

/// One text attribute (exr keeps attributes in a hash map: a single one keeps the bytes of
/// the header deterministic): `{"samples": N, "job": {...}}`.
const ATTRIBUTE: &str = "veach";
/// The film's exact words. Sums of squares are not stored: as f32 sums they would not merge
/// bit-exactly, and merged or resumed renders must equal uninterrupted ones byte for byte.
const FILM_CHANNELS: [&str; 8] = [
    "veach.film.hi.R",
    "veach.film.hi.G",
    "veach.film.hi.B",
    "veach.film.count",
    "veach.film.lo.R",
    "veach.film.lo.G",
    "veach.film.lo.B",
    "veach.film.nonfinite",
];

/// An adaptive render's state (src/adaptive.rs), exact, so that it resumes exactly: the
/// half buffer (f32 bits), the last test's result and the convergence flag.
const ADAPTIVE_CHANNELS: [&str; 5] = [
    "veach.adaptive.half.R",
    "veach.adaptive.half.G",
    "veach.adaptive.half.B",
    "veach.adaptive.passed",
    "veach.adaptive.converged",
];

/// The AOVs' exact sums (src/aov.rs), so that renders with AOVs resume and merge exactly.
const AOV_CHANNELS: [&str; 15] = [
    "veach.aov.albedo.hi.R",
    "veach.aov.albedo.hi.G",
    "veach.aov.albedo.hi.B",
    "veach.aov.depth.hi",
    "veach.aov.albedo.lo.R",
    "veach.aov.albedo.lo.G",
    "veach.aov.albedo.lo.B",
    "veach.aov.depth.lo",
    "veach.aov.normal.hi.X",
    "veach.aov.normal.hi.Y",
    "veach.aov.normal.hi.Z",
    "veach.aov.depth.hits",
    "veach.aov.normal.lo.X",
    "veach.aov.normal.lo.Y",
    "veach.aov.normal.lo.Z",
];

/// The AOV layers as image channels: name, and the AOV's component it holds.
fn aov_layer_channels(aov: crate::aov::Aov) -> &'static [&'static str] {
    match aov {
        crate::aov::Aov::Albedo => &["albedo.R", "albedo.G", "albedo.B"],
        crate::aov::Aov::Normal => &["normal.X", "normal.Y", "normal.Z"],
        crate::aov::Aov::Depth => &["depth.Z"],
    }
}

/// Where word `k` of `ADAPTIVE_CHANNELS` of pixel `i` lives in an adaptive film's data.
fn adaptive_word(film: &Film, k: usize, i: usize) -> usize {
    if k < crate::film::ADAPTIVE_WORDS { film.adaptive_record(i) + k } else { film.converged_flag(i) }
}

/// JSON for an EXR text attribute, which holds Latin-1 only: escape the rest.
fn ascii_json(value: &serde_json::Value) -> String {
    let json = value.to_string();
    let mut out = String::with_capacity(json.len());
    for ch in json.chars() {
        if ch.is_ascii() {
            out.push(ch);
        } else {
            let mut buf = [0u16; 2];
            for unit in ch.encode_utf16(&mut buf) {
                out.push_str(&format!("\\u{unit:04x}"));
            }
        }
    }
    out
}

fn write_exr(film: &Film, path: &Path, job: Option<&Job>, denoised: Option<&[f32]>) -> Result<(), Error> {
    use exr::prelude::*;
    let n = film.pixel_count();
    let mut channels: Vec<AnyChannel<FlatSamples>> = Vec::new();
    let means: Vec<glam::Vec3> = (0..n).map(|i| film.mean(i)).collect();
    for (c, name) in ["R", "G", "B"].iter().enumerate() {
        channels.push(AnyChannel::new(*name, FlatSamples::F32(means.iter().map(|m| m[c]).collect())));
    }
    for (w, name) in FILM_CHANNELS.iter().enumerate() {
        let words = (0..n).map(|i| film.data[i * WORDS_PER_PIXEL + w]);
        channels.push(AnyChannel::new(*name, FlatSamples::U32(words.collect())));
    }
    if film.is_adaptive() {
        for (k, name) in ADAPTIVE_CHANNELS.iter().enumerate() {
            let words = (0..n).map(|i| film.data[adaptive_word(film, k, i)]);
            channels.push(AnyChannel::new(*name, FlatSamples::U32(words.collect())));
        }
        // The per-pixel sample counts as an image (the `samples` AOV of adaptive sampling).
        let samples = (0..n).map(|i| film.taken(i) as f32);
        channels.push(AnyChannel::new("samples.Y", FlatSamples::F32(samples.collect())));
    }
    if film.has_aovs() {
        for (k, name) in AOV_CHANNELS.iter().enumerate() {
            let words = (0..n).map(|i| film.aov_words(i)[k]);
            channels.push(AnyChannel::new(*name, FlatSamples::U32(words.collect())));
        }
        // The layers asked for (all of them for a film written without its job).
        let asked = job.map_or(crate::aov::Aov::ALL.to_vec(), |j| j.settings.aovs.clone());
        for aov in asked {
            let Some(image) = film.aov_image(aov) else { continue };
            let names = aov_layer_channels(aov);
            for (c, name) in names.iter().enumerate() {
                let values = (0..n).map(|i| image[i * names.len() + c]);
                channels.push(AnyChannel::new(*name, FlatSamples::F32(values.collect())));
            }
        }
    }
    if let Some(rgb) = denoised {
        for (c, name) in ["denoised.R", "denoised.G", "denoised.B"].iter().enumerate() {
            channels.push(AnyChannel::new(*name, FlatSamples::F32((0..n).map(|i| rgb[i * 3 + c]).collect())));
        }
    }
    let mut attributes = LayerAttributes::named("veach");
    let meta = serde_json::json!({ "samples": film.samples(), "job": job });
    let json = Text::new_or_none(ascii_json(&meta)).unwrap_or_else(|| Text::from("{}"));
    attributes.other.insert(Text::from(ATTRIBUTE), AttributeValue::Text(json));
    let size = (film.width as usize, film.height as usize);
    let layer = Layer::new(size, attributes, Encoding::SMALL_LOSSLESS, AnyChannels::sort(channels.into()));
    let image = Image::from_layer(layer);
    save_atomic(path, |tmp| {
        image.write().to_file(tmp).map_err(|e| image::ImageError::IoError(std::io::Error::other(e.to_string())))
    })
}

/// The exr decoder allocates every channel at the size its header declares before reading a
/// pixel, and a failed allocation aborts the process: so the declared sizes are checked first,
/// against the limits a veach film has (each side at most `MAX_IMAGE_SIDE`, all channels
/// together at most `MAX_FILM_BYTES`, which a veach part of the largest film stays under).
pub(crate) fn check_exr_size(path: &Path) -> Result<(), String> {
    use crate::{MAX_FILM_BYTES, MAX_IMAGE_SIDE};
    let meta = exr::meta::MetaData::read_from_file(path, false).map_err(|e| format!("cannot read EXR: {e}"))?;
    for header in meta.headers.iter() {
        let (w, h) = (header.layer_size.width() as u64, header.layer_size.height() as u64);
        if w == 0 || h == 0 || w > MAX_IMAGE_SIDE as u64 || h > MAX_IMAGE_SIDE as u64 {
            return Err(format!("EXR layer is {w}x{h}, outside 1..={MAX_IMAGE_SIDE} per side"));
        }
        let bytes: u64 = header.channels.list.iter().map(|c| w * h * c.sample_type.bytes_per_sample() as u64).sum();
        if bytes > MAX_FILM_BYTES {
            return Err(format!(
                "EXR layer of {w}x{h} with {} channels needs {bytes} bytes, above veach's limit of {MAX_FILM_BYTES}",
                header.channels.list.len()
            ));
        }
    }
    Ok(())
}

/// Reads back a film and its job from an EXR written by veach.
pub fn read_film(path: &Path) -> Result<(Film, Job), crate::Error> {
    use exr::prelude::*;
    let fail = |m: String| crate::Error::Input(format!("{}: {m}", path.display()));
    check_exr_size(path).map_err(fail)?;
    let image = read()
        .no_deep_data()
        .largest_resolution_level()
        .all_channels()
        .first_valid_layer()
        .all_attributes()
        .from_file(path)
        .map_err(|e| fail(format!("cannot read EXR: {e}")))?;
    let layer = &image.layer_data;
    let job = match layer.attributes.other.get(&Text::from(ATTRIBUTE)) {
        Some(AttributeValue::Text(t)) => {
            let meta: serde_json::Value =
                serde_json::from_str(&t.to_string()).map_err(|e| fail(format!("invalid veach metadata: {e}")))?;
            serde_json::from_value::<Job>(meta.get("job").cloned().unwrap_or_default())
                .map_err(|e| fail(format!("no render job in the veach metadata: {e}")))?
        }
        _ => return Err(fail("not a veach render (no film metadata)".into())),
    };
    job.validate().map_err(|e| fail(format!("invalid render job in the veach metadata: {e}")))?;
    let (w, h) = (layer.size.width(), layer.size.height());
    let window = job.window();
    if (w, h) != (window.width as usize, window.height as usize) {
        return Err(fail(format!("film is {w}x{h} but its job says {}x{}", window.width, window.height)));
    }
    let adaptive = job.settings.adaptive();
    let mut film = Film::with_layout(w as u32, h as u32, job.settings.film_layout());
    let u32_channel = |name: &str| -> std::result::Result<Vec<u32>, crate::Error> {
        let channel = layer
            .channel_data
            .list
            .iter()
            .find(|c| c.name == *name)
            .ok_or_else(|| fail(format!("missing film channel {name}")))?;
        let words: Vec<u32> = match &channel.sample_data {
            FlatSamples::U32(v) => v.clone(),
            _ => return Err(fail(format!("film channel {name} has the wrong sample type"))),
        };
        if words.len() != w * h {
            return Err(fail(format!("film channel {name} has {} samples, expected {}", words.len(), w * h)));
        }
        Ok(words)
    };
    for (k, name) in FILM_CHANNELS.iter().enumerate() {
        for (i, word) in u32_channel(name)?.into_iter().enumerate() {
            film.data[i * WORDS_PER_PIXEL + k] = word;
        }
    }
    if adaptive {
        for (k, name) in ADAPTIVE_CHANNELS.iter().enumerate() {
            for (i, word) in u32_channel(name)?.into_iter().enumerate() {
                let at = adaptive_word(&film, k, i);
                film.data[at] = word;
            }
        }
    }
    if film.has_aovs() {
        for (k, name) in AOV_CHANNELS.iter().enumerate() {
            for (i, word) in u32_channel(name)?.into_iter().enumerate() {
                let at = film.aov_record(i) + k;
                film.data[at] = word;
            }
        }
    }
    // Every pixel took the same samples, at most the job's (with adaptive sampling: every
    // pixel still sampling; converged ones took fewer): anything else is a damaged file.
    let counts = |i: usize| film.taken(i) as u64;
    let most = (0..film.pixel_count()).map(counts).max().unwrap_or(0);
    if (0..film.pixel_count()).any(|i| counts(i) != most && !(film.converged(i) && counts(i) < most))
        || most > job.spp() as u64
    {
        return Err(fail(format!(
            "the film's sample counts disagree with each other or exceed the job's {} spp",
            job.spp()
        )));
    }
    Ok((film, job))
}

pub fn write_png(img: &image::RgbImage, path: &Path) -> Result<(), Error> {
    save_atomic(path, |tmp| img.save_with_format(tmp, image::ImageFormat::Png))
}

/// Fails early when `path` cannot be written, leaving nothing behind.
pub fn check_writable(path: &Path) -> Result<(), Error> {
    let probe = temp_path(path);
    std::fs::write(&probe, b"").map_err(|e| Error::io(path, "cannot write", e))?;
    let _ = std::fs::remove_file(&probe);
    Ok(())
}

/// Writes `bytes` to `path` through a temporary file renamed into place.
pub fn write_atomic(path: &Path, bytes: &[u8]) -> Result<(), Error> {
    let tmp = temp_path(path);
    std::fs::write(&tmp, bytes).map_err(|e| Error::io(path, "cannot write", e))?;
    std::fs::rename(&tmp, path).map_err(|e| {
        let _ = std::fs::remove_file(&tmp);
        Error::io(path, "cannot write", e)
    })
}

pub(crate) fn save_atomic(path: &Path, save: impl FnOnce(&Path) -> image::ImageResult<()>) -> Result<(), Error> {
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
