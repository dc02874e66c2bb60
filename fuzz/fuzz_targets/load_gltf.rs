//! Any bytes given to the glTF loader yield a scene or an error, never a panic.
#![no_main]

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    if let Ok(scene) = veach::scene::gltf::load_bytes(data, None) {
        let _ = veach::packed::PackedScene::new(&scene);
    }
});
