//! The bytes a glTF file refers to: buffers and images from the GLB chunk, `data:` URIs or
//! files beside the glTF. Reads are bounded: a buffer reads at most its declared
//! `byteLength`, an image file at most `MAX_IMAGE_FILE_BYTES`, only regular files are opened
//! (never `/dev/zero` or a FIFO), and URIs with a scheme other than `data:` are refused.

use base64::Engine;
use std::io::Read;
use std::path::{Path, PathBuf};

/// Largest encoded image file read.
pub const MAX_IMAGE_FILE_BYTES: u64 = 256 << 20;

/// Where a relative URI resolves: a directory, or nowhere (bytes loaded without one).
#[derive(Clone, Copy)]
pub struct Base<'a>(pub Option<&'a Path>);

impl Base<'_> {
    /// The file a relative URI names, after refusing schemes, absolute paths and a missing
    /// base directory.
    fn resolve(&self, uri: &str) -> Result<PathBuf, String> {
        let scheme = uri
            .split_once(':')
            .map(|(s, _)| s)
            .filter(|s| s.len() > 1 && s.chars().all(|c| c.is_ascii_alphanumeric() || matches!(c, '+' | '-' | '.')));
        if let Some(s) = scheme {
            return Err(format!("URI scheme '{s}:' is not supported (only relative paths and data: URIs)"));
        }
        let decoded = percent_encoding::percent_decode_str(uri)
            .decode_utf8()
            .map_err(|_| format!("URI '{}' is not UTF-8 once decoded", short(uri)))?;
        let relative = Path::new(decoded.as_ref());
        if relative.is_absolute() || decoded.starts_with('/') || decoded.starts_with('\\') {
            return Err(format!("URI '{}' is an absolute path (only relative paths are read)", short(uri)));
        }
        match self.0 {
            Some(dir) => Ok(dir.join(relative)),
            None => Err(format!("URI '{}' names an external file, but no base directory was given", short(uri))),
        }
    }

    /// Up to `limit` bytes of the regular file `uri` names; `exact` asks for all `limit` of them.
    fn read(&self, uri: &str, limit: u64, exact: bool) -> Result<Vec<u8>, String> {
        let path = self.resolve(uri)?;
        let shown = path.display();
        let meta = std::fs::metadata(&path).map_err(|e| format!("{shown}: {e}"))?;
        if !meta.is_file() {
            return Err(format!("{shown} is not a regular file"));
        }
        if exact && meta.len() < limit {
            return Err(format!("{shown} has {} bytes, fewer than the {limit} declared", meta.len()));
        }
        if !exact && meta.len() > limit {
            return Err(format!("{shown} has {} bytes, above the {limit}-byte limit", meta.len()));
        }
        let file = std::fs::File::open(&path).map_err(|e| format!("{shown}: {e}"))?;
        let mut bytes = Vec::with_capacity(limit.min(meta.len()) as usize);
        file.take(limit).read_to_end(&mut bytes).map_err(|e| format!("{shown}: {e}"))?;
        if exact && (bytes.len() as u64) < limit {
            return Err(format!("{shown} ended after {} of {limit} bytes", bytes.len()));
        }
        Ok(bytes)
    }
}

/// A URI for messages: at most 80 characters (data: URIs are long).
fn short(uri: &str) -> String {
    if uri.len() <= 80 { uri.to_string() } else { format!("{}…", &uri[..uri.floor_char_boundary(77)]) }
}

/// The payload of a `data:` URI (base64 or percent-encoded), or None for other URIs.
fn data_uri(uri: &str) -> Option<Result<Vec<u8>, String>> {
    let rest = uri.strip_prefix("data:")?;
    let Some((meta, payload)) = rest.split_once(',') else {
        return Some(Err("data: URI without a ',' before its payload".into()));
    };
    Some(if meta.ends_with(";base64") {
        base64::engine::general_purpose::STANDARD
            .decode(payload.trim_end())
            .map_err(|e| format!("data: URI with invalid base64: {e}"))
    } else {
        Ok(percent_encoding::percent_decode_str(payload).collect())
    })
}

/// Every buffer's bytes, each exactly its declared `byteLength` (extra bytes are cut).
pub fn load_buffers(doc: &gltf::Document, blob: Option<&[u8]>, base: Base) -> Result<Vec<gltf::buffer::Data>, String> {
    let mut out = Vec::new();
    for buffer in doc.buffers() {
        let i = buffer.index();
        let length = buffer.length() as u64;
        let fail = |e: String| format!("buffer {i}: {e}");
        // A meshopt fallback buffer has no bytes: every view into it is stored compressed
        // elsewhere (reading one that is not is refused by `accessor::Views`).
        let fallback = ["EXT_meshopt_compression", "KHR_meshopt_compression"]
            .iter()
            .any(|e| buffer.extension_value(e).and_then(|v| v.get("fallback")).and_then(|f| f.as_bool()) == Some(true));
        if fallback && matches!(buffer.source(), gltf::buffer::Source::Bin) {
            out.push(gltf::buffer::Data(Vec::new()));
            continue;
        }
        let mut bytes = match buffer.source() {
            gltf::buffer::Source::Bin => blob.map(<[u8]>::to_vec).ok_or_else(|| fail("no GLB binary chunk".into()))?,
            gltf::buffer::Source::Uri(uri) => match data_uri(uri) {
                Some(r) => r.map_err(fail)?,
                None => base.read(uri, length, true).map_err(fail)?,
            },
        };
        if (bytes.len() as u64) < length {
            return Err(fail(format!("holds {} bytes, fewer than the {length} declared", bytes.len())));
        }
        bytes.truncate(length as usize);
        out.push(gltf::buffer::Data(bytes));
    }
    Ok(out)
}

/// An image's encoded bytes (PNG, JPEG, ...), from a buffer view, a data: URI or a file.
pub fn image_bytes(image: &gltf::Image, buffers: &[gltf::buffer::Data], base: Base) -> Result<Vec<u8>, String> {
    match image.source() {
        gltf::image::Source::View { view, .. } => {
            let data = buffers.get(view.buffer().index()).ok_or("its buffer is missing")?;
            let end = view.offset().checked_add(view.length()).filter(|&e| e <= data.0.len());
            let end = end.ok_or("its buffer view runs past the buffer")?;
            Ok(data.0[view.offset()..end].to_vec())
        }
        gltf::image::Source::Uri { uri, .. } => match data_uri(uri) {
            Some(r) => r,
            None => base.read(uri, MAX_IMAGE_FILE_BYTES, false),
        },
    }
}
