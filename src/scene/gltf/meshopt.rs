//! EXT_meshopt_compression and KHR_meshopt_compression (gltfpack's and `gltf-transform
//! optimize`'s compression): a buffer view stored as a meshoptimizer stream in another buffer,
//! decoded by the reference decoder (the `meshopt` crate, which vendors zeux's meshoptimizer).
//! Every parameter the C decoder asserts on is checked here first, and the decoded size is
//! checked against the view before allocating.

use serde_json::Value;

/// The decoded bytes of `view` when it is stored compressed (None: read it in place).
pub fn decode_view(view: &gltf::buffer::View, buffers: &[gltf::buffer::Data]) -> Result<Option<Vec<u8>>, String> {
    let (ext, khr) = match view.extension_value("KHR_meshopt_compression") {
        Some(e) => (e, true),
        None => match view.extension_value("EXT_meshopt_compression") {
            Some(e) => (e, false),
            None => return Ok(None),
        },
    };
    decode(ext, khr, view.length(), buffers)
        .map(Some)
        .map_err(|e| format!("buffer view {}: meshopt: {e}", view.index()))
}

fn field(ext: &Value, key: &str) -> Result<usize, String> {
    ext.get(key).and_then(Value::as_u64).map(|v| v as usize).ok_or_else(|| format!("no valid {key}"))
}

fn decode(ext: &Value, khr: bool, view_length: usize, buffers: &[gltf::buffer::Data]) -> Result<Vec<u8>, String> {
    let buffer = buffers.get(field(ext, "buffer")?).ok_or("its source buffer is missing")?;
    let offset = ext.get("byteOffset").and_then(Value::as_u64).unwrap_or(0) as usize;
    let length = field(ext, "byteLength")?;
    let stride = field(ext, "byteStride")?;
    let count = field(ext, "count")?;
    let mode = ext.get("mode").and_then(Value::as_str).ok_or("no mode")?;
    let filter = ext.get("filter").and_then(Value::as_str).unwrap_or("NONE");
    let source = offset.checked_add(length).and_then(|end| buffer.0.get(offset..end)).ok_or_else(|| {
        format!("its stream (bytes {offset}..+{length}) lies past its buffer's {} bytes", buffer.0.len())
    })?;
    let size = count.checked_mul(stride).ok_or("count × stride overflows")?;
    if size > view_length {
        return Err(format!("{count} × {stride} bytes do not fit the view's {view_length}"));
    }
    if count > super::MAX_ELEMENTS {
        return Err(format!("{count} elements, above the limit"));
    }
    let mut out = vec![0u8; size];
    let code = match mode {
        "ATTRIBUTES" => {
            if stride == 0 || stride > 256 || !stride.is_multiple_of(4) {
                return Err(format!("attribute stride {stride} (must be 4..=256, a multiple of 4)"));
            }
            if count == 0 {
                0
            } else {
                // SAFETY: `out` holds count × stride bytes and `source` its length.
                unsafe {
                    meshopt::ffi::meshopt_decodeVertexBuffer(
                        out.as_mut_ptr().cast(),
                        count,
                        stride,
                        source.as_ptr(),
                        source.len(),
                    )
                }
            }
        }
        "TRIANGLES" | "INDICES" => {
            if stride != 2 && stride != 4 {
                return Err(format!("index stride {stride} (must be 2 or 4)"));
            }
            if mode == "TRIANGLES" && !count.is_multiple_of(3) {
                return Err(format!("{count} indices are not whole triangles"));
            }
            // SAFETY: as above.
            unsafe {
                if mode == "TRIANGLES" {
                    meshopt::ffi::meshopt_decodeIndexBuffer(
                        out.as_mut_ptr().cast(),
                        count,
                        stride,
                        source.as_ptr(),
                        source.len(),
                    )
                } else {
                    meshopt::ffi::meshopt_decodeIndexSequence(
                        out.as_mut_ptr().cast(),
                        count,
                        stride,
                        source.as_ptr(),
                        source.len(),
                    )
                }
            }
        }
        m => return Err(format!("unknown mode {m}")),
    };
    if code != 0 {
        return Err(format!("the {mode} stream is damaged (decoder error {code})"));
    }
    if mode == "ATTRIBUTES" && count > 0 {
        let ptr = out.as_mut_ptr().cast();
        // SAFETY: `out` holds count × stride bytes; each filter's stride is checked first.
        match filter {
            "NONE" => {}
            "OCTAHEDRAL" if stride == 4 || stride == 8 => unsafe {
                meshopt::ffi::meshopt_decodeFilterOct(ptr, count, stride)
            },
            "QUATERNION" if stride == 8 => unsafe { meshopt::ffi::meshopt_decodeFilterQuat(ptr, count, stride) },
            "EXPONENTIAL" => unsafe { meshopt::ffi::meshopt_decodeFilterExp(ptr, count, stride) },
            "COLOR" if khr && (stride == 4 || stride == 8) => unsafe {
                meshopt::ffi::meshopt_decodeFilterColor(ptr, count, stride)
            },
            f => return Err(format!("filter {f} with stride {stride} is not valid")),
        }
    } else if filter != "NONE" {
        return Err(format!("filter {filter} on a {mode} stream"));
    }
    Ok(out)
}
