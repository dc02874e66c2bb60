//! Reading accessors as veach needs them: every component type glTF allows (floats, and
//! normalised or plain integers: KHR_mesh_quantization), sparse accessors, accessors without a
//! buffer view (zeros), and buffer views stored compressed (EXT_/KHR_meshopt_compression,
//! decoded once by `Views::new`). Every size is checked against its view before anything is
//! allocated or read.

use super::MAX_ELEMENTS;
use gltf::accessor::DataType;
use std::collections::HashMap;

/// The bytes of every buffer view: a slice of its buffer, or its decoded bytes when the view
/// is stored compressed.
pub struct Views<'a> {
    buffers: &'a [gltf::buffer::Data],
    decoded: HashMap<usize, Vec<u8>>,
}

impl<'a> Views<'a> {
    /// Decodes the compressed views of `doc` (meshopt); the others are read in place.
    pub fn new(doc: &gltf::Document, buffers: &'a [gltf::buffer::Data]) -> Result<Views<'a>, String> {
        let mut decoded = HashMap::new();
        for view in doc.views() {
            if let Some(bytes) = super::meshopt::decode_view(&view, buffers)? {
                decoded.insert(view.index(), bytes);
            }
        }
        Ok(Views { buffers, decoded })
    }

    /// A view's bytes, checked against its buffer.
    pub fn bytes(&self, view: &gltf::buffer::View) -> Result<&[u8], String> {
        if let Some(bytes) = self.decoded.get(&view.index()) {
            return Ok(bytes);
        }
        let buffer = self.buffers.get(view.buffer().index()).ok_or("its buffer is missing")?;
        let start = view.offset();
        let end = start.checked_add(view.length()).ok_or("view overflows")?;
        buffer.0.get(start..end).ok_or_else(|| {
            format!(
                "buffer view {} ends at byte {end}, past its buffer's {} bytes{}",
                view.index(),
                buffer.0.len(),
                if buffer.0.is_empty() {
                    " (a compression fallback buffer, and the view is not compressed)"
                } else {
                    ""
                }
            )
        })
    }
}

fn component_size(t: DataType) -> usize {
    match t {
        DataType::I8 | DataType::U8 => 1,
        DataType::I16 | DataType::U16 => 2,
        DataType::U32 | DataType::F32 => 4,
    }
}

/// One component as f32: floats as they are, normalised integers mapped to [0, 1] or
/// [−1, 1] by glTF's rules, other integers by value.
#[inline]
fn component(t: DataType, normalized: bool, b: &[u8]) -> f32 {
    match (t, normalized) {
        (DataType::F32, _) => f32::from_le_bytes([b[0], b[1], b[2], b[3]]),
        (DataType::U8, true) => b[0] as f32 / 255.0,
        (DataType::U8, false) => b[0] as f32,
        (DataType::I8, true) => (b[0] as i8 as f32 / 127.0).max(-1.0),
        (DataType::I8, false) => b[0] as i8 as f32,
        (DataType::U16, true) => u16::from_le_bytes([b[0], b[1]]) as f32 / 65535.0,
        (DataType::U16, false) => u16::from_le_bytes([b[0], b[1]]) as f32,
        (DataType::I16, true) => (i16::from_le_bytes([b[0], b[1]]) as f32 / 32767.0).max(-1.0),
        (DataType::I16, false) => i16::from_le_bytes([b[0], b[1]]) as f32,
        (DataType::U32, _) => u32::from_le_bytes([b[0], b[1], b[2], b[3]]) as f32,
    }
}

/// Where `count` elements of `elem` bytes at `offset` with `stride` lie in `data`, checked.
fn check_span(data: &[u8], offset: usize, stride: usize, elem: usize, count: usize) -> Result<(), String> {
    if count == 0 {
        return Ok(());
    }
    if stride < elem {
        return Err(format!("byte stride {stride} is smaller than an element ({elem} bytes)"));
    }
    let need = stride
        .checked_mul(count - 1)
        .and_then(|x| x.checked_add(offset))
        .and_then(|x| x.checked_add(elem))
        .ok_or("count overflows")?;
    if need > data.len() {
        return Err(format!("{count} elements need {need} bytes, its view has {}", data.len()));
    }
    Ok(())
}

/// An accessor's elements as f32, `components` a element (its type must have that many),
/// sparse values substituted.
pub fn read_floats(a: &gltf::Accessor, views: &Views, components: usize) -> Result<Vec<f32>, String> {
    let comps = a.dimensions().multiplicity();
    if comps != components {
        return Err(format!("has {comps} components, expected {components}"));
    }
    let (n, ty, normalized) = (a.count(), a.data_type(), a.normalized());
    if n > MAX_ELEMENTS {
        return Err(format!("{n} elements, above the limit of {MAX_ELEMENTS}"));
    }
    let size = component_size(ty);
    let elem = comps * size;
    let mut out = vec![0.0f32; n * comps];
    if let Some(view) = a.view() {
        let data = views.bytes(&view)?;
        let stride = view.stride().unwrap_or(elem);
        check_span(data, a.offset(), stride, elem, n)?;
        for (i, dst) in out.chunks_exact_mut(comps).enumerate() {
            let at = a.offset() + i * stride;
            for (c, d) in dst.iter_mut().enumerate() {
                *d = component(ty, normalized, &data[at + c * size..]);
            }
        }
    }
    // (A sparse block of no values is what `normalise` gives accessors with no data at all.)
    if let Some(sparse) = a.sparse().filter(|s| s.count() > 0) {
        let indices = sparse_indices(&sparse, n, views)?;
        let values = sparse.values();
        let data = views.bytes(&values.view())?;
        check_span(data, values.offset(), elem, elem, indices.len())?;
        for (j, &i) in indices.iter().enumerate() {
            let at = values.offset() + j * elem;
            for c in 0..comps {
                out[i * comps + c] = component(ty, normalized, &data[at + c * size..]);
            }
        }
    }
    Ok(out)
}

/// The element indices a sparse accessor replaces, each below `count`.
fn sparse_indices(sparse: &gltf::accessor::sparse::Sparse, count: usize, views: &Views) -> Result<Vec<usize>, String> {
    use gltf::accessor::sparse::IndexType;
    let k = sparse.count();
    if k > count {
        return Err(format!("sparse count {k} exceeds the accessor's {count} elements"));
    }
    let idx = sparse.indices();
    let data = views.bytes(&idx.view())?;
    let size = match idx.index_type() {
        IndexType::U8 => 1,
        IndexType::U16 => 2,
        IndexType::U32 => 4,
    };
    check_span(data, idx.offset(), size, size, k)?;
    let mut out = Vec::with_capacity(k);
    for j in 0..k {
        let b = &data[idx.offset() + j * size..];
        let i = match size {
            1 => b[0] as usize,
            2 => u16::from_le_bytes([b[0], b[1]]) as usize,
            _ => u32::from_le_bytes([b[0], b[1], b[2], b[3]]) as usize,
        };
        if i >= count {
            return Err(format!("sparse index {i} is out of range ({count} elements)"));
        }
        out.push(i);
    }
    Ok(out)
}

/// An accessor of unsigned integers (indices, joints) as u32, sparse values substituted.
pub fn read_uints(a: &gltf::Accessor, views: &Views, components: usize) -> Result<Vec<u32>, String> {
    if !matches!(a.data_type(), DataType::U8 | DataType::U16 | DataType::U32) || a.normalized() {
        return Err(format!("component type {:?} is not an unsigned integer", a.data_type()));
    }
    // Integers up to 2^24 are exact as f32; larger indices go through the exact path.
    if a.data_type() != DataType::U32 {
        return Ok(read_floats(a, views, components)?.into_iter().map(|v| v as u32).collect());
    }
    let comps = a.dimensions().multiplicity();
    if comps != components {
        return Err(format!("has {comps} components, expected {components}"));
    }
    let n = a.count();
    if n > MAX_ELEMENTS {
        return Err(format!("{n} elements, above the limit of {MAX_ELEMENTS}"));
    }
    let elem = comps * 4;
    let mut out = vec![0u32; n * comps];
    let word = |b: &[u8]| u32::from_le_bytes([b[0], b[1], b[2], b[3]]);
    if let Some(view) = a.view() {
        let data = views.bytes(&view)?;
        let stride = view.stride().unwrap_or(elem);
        check_span(data, a.offset(), stride, elem, n)?;
        for (i, dst) in out.chunks_exact_mut(comps).enumerate() {
            for (c, d) in dst.iter_mut().enumerate() {
                *d = word(&data[a.offset() + i * stride + c * 4..]);
            }
        }
    }
    if let Some(sparse) = a.sparse().filter(|s| s.count() > 0) {
        let indices = sparse_indices(&sparse, n, views)?;
        let values = sparse.values();
        let data = views.bytes(&values.view())?;
        check_span(data, values.offset(), elem, elem, indices.len())?;
        for (j, &i) in indices.iter().enumerate() {
            for c in 0..comps {
                out[i * comps + c] = word(&data[values.offset() + j * elem + c * 4..]);
            }
        }
    }
    Ok(out)
}
