//! KHR_draco_mesh_compression (three.js/drei, model-viewer, Cesium, `gltf-transform draco`): a
//! primitive's indices and attributes decoded from one Draco stream by the pure-Rust
//! `draco-core` decoder, its attributes mapped to glTF semantics by the extension's ids and
//! read as the primitive's accessors describe them (normalised integers normalised). The
//! decoder's limits bound what a stream may claim, and the decoded counts must match the
//! accessors'.

use super::MAX_ELEMENTS;
use super::accessor::Views;
use gltf::accessor::DataType;
use std::collections::HashMap;

/// A primitive decoded from its Draco stream: triangle indices and, per glTF attribute name
/// (`POSITION`, `NORMAL`, `TEXCOORD_0`, ...), its values as f32, row-major.
pub struct Decoded {
    pub indices: Vec<u32>,
    pub attributes: HashMap<String, Vec<f32>>,
}

/// The primitive's Draco stream decoded (None: the primitive is not compressed).
pub fn decode_primitive(
    prim: &gltf::Primitive,
    doc: &gltf::Document,
    views: &Views,
) -> Result<Option<Decoded>, String> {
    let Some(ext) = prim.extension_value("KHR_draco_mesh_compression") else {
        return Ok(None);
    };
    let fail = |e: String| format!("Draco: {e}");
    let view_index = ext.get("bufferView").and_then(|v| v.as_u64()).ok_or_else(|| fail("no bufferView".into()))?;
    let view = doc.views().nth(view_index as usize).ok_or_else(|| fail(format!("no buffer view {view_index}")))?;
    let bytes = views.bytes(&view).map_err(fail)?;
    let limits = draco_core::DecodeLimits::default()
        .with_max_points(MAX_ELEMENTS as u64)
        .with_max_faces(super::MAX_TRIANGLES as u64)
        .with_max_decoded_bytes(1 << 31);
    let mut buffer = draco_core::DecoderBuffer::new(bytes).with_limits(limits);
    let mut mesh = draco_core::Mesh::new();
    draco_core::MeshDecoder::new().decode(&mut buffer, &mut mesh).map_err(|e| fail(format!("damaged stream: {e}")))?;
    let points = mesh.num_points();
    let indices: Vec<u32> = mesh.faces().iter().flat_map(|f| f.map(|p| p.0)).collect();
    if let Some(bad) = indices.iter().find(|&&i| i as usize >= points) {
        return Err(fail(format!("index {bad} is out of range ({points} points)")));
    }
    let mut attributes = HashMap::new();
    let ids = ext.get("attributes").and_then(|a| a.as_object()).ok_or_else(|| fail("no attributes".into()))?;
    for (name, id) in ids {
        let id = id.as_u64().ok_or_else(|| fail(format!("{name}: no attribute id")))? as u32;
        let attribute = mesh.attribute_by_unique_id(id).ok_or_else(|| fail(format!("{name}: no attribute {id}")))?;
        // The primitive's accessor describes the decoded values (type, normalisation).
        let Some(accessor) = prim.attributes().find(|(s, _)| s.to_string() == *name).map(|(_, a)| a) else {
            continue;
        };
        if accessor.count() != points {
            return Err(fail(format!("{name}: {points} points decoded, its accessor has {}", accessor.count())));
        }
        let components = accessor.dimensions().multiplicity();
        let mut values = attribute.read_f32s(points, components);
        if accessor.normalized() {
            let scale = match accessor.data_type() {
                DataType::U8 => 1.0 / 255.0,
                DataType::I8 => 1.0 / 127.0,
                DataType::U16 => 1.0 / 65535.0,
                DataType::I16 => 1.0 / 32767.0,
                _ => 1.0,
            };
            values.iter_mut().for_each(|v| *v = (*v * scale).max(-1.0));
        }
        attributes.insert(name.clone(), values);
    }
    Ok(Some(Decoded { indices, attributes }))
}
