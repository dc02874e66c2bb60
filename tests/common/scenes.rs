//! Scenes built in code that several tests render.

use super::build::{GltfBuilder, MeshData};
use serde_json::json;
use std::path::PathBuf;

/// A scene that turns on every optional part of the kernel: a texture with alpha MASK, BLEND,
/// a spot light, glass with absorption, instancing, a constant environment. Written to a
/// directory of the caller's (`engine`): the two tests run at once.
pub fn features_scene(engine: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("veach-films-{}-{engine}", std::process::id()));
    let mut b = GltfBuilder::new(&dir, "features");
    b.use_extension("KHR_materials_transmission");
    b.use_extension("KHR_materials_volume");
    let checker = image::RgbaImage::from_fn(8, 8, |x, y| {
        let on = (x + y) % 2 == 0;
        image::Rgba(if on { [220, 40, 40, 255] } else { [40, 220, 40, 60] })
    });
    let tex = b.texture(&checker, 10497);
    let masked = b.material(json!({"pbrMetallicRoughness": {"baseColorTexture": {"index": tex},
        "metallicFactor": 0}, "alphaMode": "MASK", "alphaCutoff": 0.5}));
    let blended = b.material(json!({"pbrMetallicRoughness": {"baseColorFactor": [0.2, 0.4, 0.9, 0.5],
        "metallicFactor": 0, "roughnessFactor": 0.4}, "alphaMode": "BLEND"}));
    let glass = b.material(json!({"pbrMetallicRoughness": {"baseColorFactor": [1, 1, 1, 1], "metallicFactor": 0,
        "roughnessFactor": 0.1}, "extensions": {"KHR_materials_transmission": {"transmissionFactor": 1.0},
        "KHR_materials_volume": {"attenuationColor": [0.3, 0.6, 1.0], "attenuationDistance": 0.5,
        "thicknessFactor": 1.0}}}));
    let lamp = b.material(json!({"pbrMetallicRoughness": {"baseColorFactor": [0, 0, 0, 1]},
        "emissiveFactor": [4, 4, 4]}));
    let floor = b.mesh(&MeshData::quad(-3.0, -3.0, 3.0, 3.0, -1.0, MeshData::UPRIGHT), masked);
    b.node(json!({"mesh": floor}));
    let veil = b.mesh(&MeshData::quad(-1.0, -1.0, 0.0, 0.0, 0.5, MeshData::UPRIGHT), blended);
    b.node(json!({"mesh": veil}));
    let pane = b.mesh(&MeshData::quad(-0.4, -0.4, 0.4, 0.4, 0.0, MeshData::UPRIGHT), glass);
    b.node(json!({"mesh": pane, "translation": [0.8, 0.3, 0.0]}));
    b.node(json!({"mesh": pane, "translation": [-0.6, 0.9, 0.2], "scale": [1.5, 0.7, 1.0]}));
    let light = b.mesh(&MeshData::quad(-0.5, -0.5, 0.5, 0.5, 0.0, MeshData::UPRIGHT), lamp);
    b.node(json!({"mesh": light, "translation": [2.0, -2.0, 2.5], "rotation": [1, 0, 0, 0]}));
    b.light(
        json!({"type": "spot", "color": [1, 0.9, 0.7], "intensity": 6, "spot": {"outerConeAngle": 0.6}}),
        json!({"translation": [1.5, 1.5, 2.0], "rotation": [0.3, -0.3, 0.0, 0.9055]}),
    );
    b.camera(0.9, 1.0, [0.0, 0.0, 4.0]);
    b.write()
}
