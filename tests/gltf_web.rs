//! glTF as the web ships it (#17): quantized and sparse accessors, skins and morph targets at
//! rest, meshopt and Draco compression, WebP and Basis Universal textures. Files made by the
//! real tools (gltfpack, glTF-Transform, ktx2-encoder: bench/gltf-variants.sh) render like
//! their originals; damaged compressed streams are errors, never panics.

mod common;

use base64::Engine;
use glam::{Vec2, Vec3};
use serde_json::json;
use std::path::PathBuf;
use veach::Settings;

fn web(name: &str) -> PathBuf {
    common::root().join("tests/data/web").join(name)
}

/// A glTF whose buffer is `bin` (a data: URI), with `accessors`, `views` and one mesh
/// primitive of `attributes` (+ `indices`), drawn by a node with `node` properties.
fn document(
    bin: &[u8],
    views: serde_json::Value,
    accessors: serde_json::Value,
    primitive: serde_json::Value,
    node: serde_json::Value,
    required: &[&str],
) -> Vec<u8> {
    let uri = format!("data:application/octet-stream;base64,{}", base64::engine::general_purpose::STANDARD.encode(bin));
    let mut node = node;
    node["mesh"] = json!(0);
    serde_json::to_vec(&json!({
        "asset": {"version": "2.0"},
        "extensionsUsed": required, "extensionsRequired": required,
        "scene": 0, "scenes": [{"nodes": [0]}],
        "nodes": [node],
        "meshes": [{"primitives": [primitive]}],
        "buffers": [{"uri": uri, "byteLength": bin.len()}],
        "bufferViews": views,
        "accessors": accessors,
    }))
    .unwrap()
}

fn push<T: bytemuck::Pod>(bin: &mut Vec<u8>, values: &[T]) -> (usize, usize) {
    while !bin.len().is_multiple_of(4) {
        bin.push(0);
    }
    let at = bin.len();
    bin.extend_from_slice(bytemuck::cast_slice(values));
    (at, bin.len() - at)
}

/// KHR_mesh_quantization: positions as plain int16 (the node's scale dequantizes them),
/// normals as normalised int8, texture coordinates as normalised uint16; a sparse accessor
/// moves one position.
#[test]
fn quantized_and_sparse_accessors_read_as_their_floats() {
    let mut bin = Vec::new();
    let (pa, pl) = push(&mut bin, &[0i16, 0, 0, 0, 1000, 0, 0, 0, 0, 0, 1000, 0]); // 3 × (x, y, z, pad)
    let (na, nl) = push(&mut bin, &[0i8, 0, 127, 0, 0, 0, 127, 0, 0, 0, 127, 0]);
    let (ua, ul) = push(&mut bin, &[0u16, 0, 65535, 0, 0, 65535]);
    let (ia, il) = push(&mut bin, &[2u32]); // sparse: vertex 2 ...
    let (va, vl) = push(&mut bin, &[-1000i16, 1000, 0, 0]); // ... moves to (−1000, 1000, 0)
    let views = json!([
        {"buffer": 0, "byteOffset": pa, "byteLength": pl, "byteStride": 8},
        {"buffer": 0, "byteOffset": na, "byteLength": nl, "byteStride": 4},
        {"buffer": 0, "byteOffset": ua, "byteLength": ul},
        {"buffer": 0, "byteOffset": ia, "byteLength": il},
        {"buffer": 0, "byteOffset": va, "byteLength": vl},
    ]);
    let accessors = json!([
        {"bufferView": 0, "componentType": 5122, "count": 3, "type": "VEC3", "min": [-1000, 0, 0], "max": [1000, 1000, 0],
         "sparse": {"count": 1, "indices": {"bufferView": 3, "componentType": 5125}, "values": {"bufferView": 4}}},
        {"bufferView": 1, "componentType": 5120, "normalized": true, "count": 3, "type": "VEC3"},
        {"bufferView": 2, "componentType": 5123, "normalized": true, "count": 3, "type": "VEC2"},
    ]);
    let prim = json!({"attributes": {"POSITION": 0, "NORMAL": 1, "TEXCOORD_0": 2}});
    let bytes =
        document(&bin, views, accessors, prim, json!({"scale": [0.001, 0.001, 0.001]}), &["KHR_mesh_quantization"]);
    let loaded = veach::load_bytes(&bytes, None, None).expect("a quantized file loads");
    let t = &loaded.scene.triangles;
    assert_eq!(t.len(), 1);
    let close = |a: Vec3, b: Vec3| (a - b).abs().max_element() < 1e-5;
    assert!(close(t[0].positions[1], Vec3::new(1.0, 0.0, 0.0)), "{:?}", t[0].positions);
    assert!(close(t[0].positions[2], Vec3::new(-1.0, 1.0, 0.0)), "the sparse value: {:?}", t[0].positions);
    assert!(t[0].normals.iter().all(|n| close(*n, Vec3::Z)), "{:?}", t[0].normals);
    assert!((t[0].uvs[1] - Vec2::new(1.0, 0.0)).length() < 1e-6 && (t[0].uvs[2] - Vec2::new(0.0, 1.0)).length() < 1e-6);
    // The same positions as normalised int16 are a different number: the flag matters.
    let mut bin2 = bin.clone();
    bin2.truncate(bin.len());
    let accessors = json!([
        {"bufferView": 0, "componentType": 5122, "normalized": true, "count": 3, "type": "VEC3", "min": [0, 0, 0], "max": [1, 1, 0]},
    ]);
    let views = json!([{"buffer": 0, "byteOffset": pa, "byteLength": pl, "byteStride": 8}]);
    let bytes = document(
        &bin2,
        views,
        accessors,
        json!({"attributes": {"POSITION": 0}}),
        json!({}),
        &["KHR_mesh_quantization"],
    );
    let t = veach::load_bytes(&bytes, None, None).unwrap().scene.triangles;
    assert!(close(t[0].positions[1], Vec3::new(1000.0 / 32767.0, 0.0, 0.0)), "{:?}", t[0].positions);
    // A sparse index past the accessor's count is an error.
    let mut bad = bin.clone();
    bad[ia..ia + 4].copy_from_slice(&7u32.to_le_bytes());
    let views = json!([
        {"buffer": 0, "byteOffset": pa, "byteLength": pl, "byteStride": 8},
        {"buffer": 0, "byteOffset": ia, "byteLength": il},
        {"buffer": 0, "byteOffset": va, "byteLength": vl},
    ]);
    let accessors = json!([{"bufferView": 0, "componentType": 5122, "count": 3, "type": "VEC3", "min": [-1000, 0, 0], "max": [1000, 1000, 0],
        "sparse": {"count": 1, "indices": {"bufferView": 1, "componentType": 5125}, "values": {"bufferView": 2}}}]);
    let bytes = document(&bad, views, accessors, json!({"attributes": {"POSITION": 0}}), json!({}), &[]);
    let e = veach::load_bytes(&bytes, None, None).err().expect("refused").to_string();
    assert!(e.contains("sparse index 7"), "{e}");
}

fn bounds(scene: &veach::Scene) -> (Vec3, Vec3) {
    let ps = scene.triangles.iter().flat_map(|t| t.positions);
    ps.fold((Vec3::splat(f32::MAX), Vec3::splat(f32::MIN)), |(lo, hi), p| (lo.min(p), hi.max(p)))
}

/// Skins at their rest pose and morph targets at their default weights, on Khronos' samples:
/// SimpleSkin's strip stands where its joints put it, SimpleMorph's top vertex rises by the
/// half weight of its targets, a file with sparse morph data loads.
#[test]
fn skins_and_morph_targets_take_their_rest_pose() {
    let Some(dir) = common::shared_models() else { return };
    // SimpleSkin: raw vertices span x 0..1; the skin's joints (the root translated, the
    // inverse bind matrices undoing it) place the strip as the file's nodes say.
    let skin = veach::load(&dir.join("SimpleSkin/SimpleSkin.gltf"), None).unwrap();
    let (lo, hi) = bounds(&skin.scene);
    eprintln!("SimpleSkin bounds {lo} .. {hi}");
    assert!((lo.x + 0.5).abs() < 1e-4 && (hi.x - 0.5).abs() < 1e-4, "skinned: {lo} .. {hi}");
    // SimpleMorph: weights [0.5, 0.5]; the raw top vertex at y 0.5 rises to 1.5.
    let morph = veach::load(&dir.join("SimpleMorph/SimpleMorph.gltf"), None).unwrap();
    let (_, hi) = bounds(&morph.scene);
    assert!((hi.y - 1.5).abs() < 1e-4, "morphed top at {}", hi.y);
    // A tetrahedron and two triangles with morph targets, a sparse accessor among their data.
    let sparse = veach::load(&dir.join("SparseMorphTargets-blenderio/23_multi_prim_vertex_attribute.gltf"), None);
    let sparse = sparse.unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(sparse.scene.triangles.len(), 6, "12 + 6 indices");
}

/// The compressed and re-encoded variants made by gltfpack and glTF-Transform render like
/// the originals: same camera, same seed, the image means within 1 %, and every pixel within
/// error bars (|difference| ≤ 5 σ of the two means' difference, the independent sampler's
/// per-pixel variance; up to 1 % of values beyond it, where vertex quantization moved an edge).
/// Per-pixel noise is not the same bits: a tool that reorders the emissive triangles changes
/// which light a random number picks.
#[test]
fn web_variants_render_like_their_originals() {
    let settings =
        Settings { width: 32, height: 32, seed: 5, sampler: veach::SamplerKind::Independent, ..Settings::default() };
    let original = common::render(&common::asset("cornell-box.gltf"), &settings, 32, None);
    for v in ["quantized", "meshopt", "draco", "gt-meshopt"] {
        let path = web(&format!("cornell-box.{v}.glb"));
        let film = common::render(&path, &settings, 32, None);
        let (a, b) = (original.to_rgb32f(), film.to_rgb32f());
        let (va, vb) = (original.variance(), film.variance());
        let mean = |v: &[f32]| v.iter().map(|x| *x as f64).sum::<f64>() / v.len() as f64;
        let (ma, mb) = (mean(&a), mean(&b));
        assert!((ma - mb).abs() < 0.01 * ma, "{v}: mean {mb} vs {ma}");
        let outliers = (0..a.len()).filter(|&i| (a[i] - b[i]).abs() > 5.0 * (va[i] + vb[i]).sqrt() + 1e-4).count();
        eprintln!("{v}: means {ma:.5} / {mb:.5}, {outliers} of {} values beyond 5 σ", a.len());
        assert!(outliers as f64 <= 0.01 * a.len() as f64, "{v}: {outliers} values beyond 5 σ");
    }
}

/// WebP and Basis Universal textures decode to the PNG's pixels (within the codecs' loss).
#[test]
fn webp_and_basisu_textures_decode_to_the_png_s_pixels() {
    let Some(dir) = common::shared_models() else { return };
    // The image the box's material reads (a file keeps its PNG beside the KTX2 as fallback).
    let base_color = |scene: &veach::Scene| {
        let t = scene.materials[0].base_color_texture.expect("a base color texture");
        scene.textures[t.texture as usize].clone()
    };
    let png = veach::load(&dir.join("BoxTextured/BoxTextured.gltf"), None).unwrap();
    let reference = &base_color(&png.scene);
    for file in
        ["box-textured.webp.glb", "box-textured.basisu.gltf", "box-textured.ktx2.glb", "box-textured.quantized.glb"]
    {
        let loaded = veach::load(&web(file), None).unwrap_or_else(|e| panic!("{file}: {e}"));
        assert!(loaded.warnings.iter().all(|w| !w.contains("image")), "{file}: {:?}", loaded.warnings);
        let t = &base_color(&loaded.scene);
        assert_eq!((t.width, t.height), (reference.width, reference.height), "{file}");
        let err = t.rgba.iter().zip(&reference.rgba).map(|(a, b)| (*a as f64 - *b as f64).abs()).sum::<f64>()
            / t.rgba.len() as f64;
        eprintln!("{file}: mean absolute texel difference {err:.2} / 255");
        assert!(err < 12.0, "{file}: mean texel difference {err}");
    }
    // A KTX2 image that does not decode gives way to its texture's PNG fallback, with a warning.
    let dir = common::cli::temp_dir("basisu-fallback");
    for f in ["box-textured.basisu.gltf", "BoxTextured0.bin", "CesiumLogoFlat.png", "CesiumLogoFlat.ktx2"] {
        std::fs::copy(web(f), dir.path().join(f)).unwrap();
    }
    let ktx = dir.path().join("CesiumLogoFlat.ktx2");
    let mut bytes = std::fs::read(&ktx).unwrap();
    bytes.truncate(bytes.len() / 2);
    std::fs::write(&ktx, bytes).unwrap();
    let loaded = veach::load(&dir.path().join("box-textured.basisu.gltf"), None).unwrap();
    assert!(loaded.warnings.iter().any(|w| w.contains("fallback")), "{:?}", loaded.warnings);
    assert_eq!(base_color(&loaded.scene).rgba, reference.rgba, "the PNG, exactly");
}

/// A damaged compressed stream (meshopt, Draco) or image (WebP, KTX2) is an error or a
/// warning, never a panic: byte flips and truncations of the real tools' files.
#[test]
fn damaged_compressed_streams_are_refused_not_crashed() {
    let mut rng = common::rng::Lcg(99);
    let mut refused = 0;
    for file in [
        "cornell-box.meshopt.glb",
        "cornell-box.draco.glb",
        "cornell-box.gt-meshopt.glb",
        "box-textured.webp.glb",
        "box-textured.ktx2.glb",
    ] {
        let bytes = std::fs::read(web(file)).unwrap();
        for _ in 0..150 {
            let mut b = bytes.clone();
            // Damage the binary chunk (after the JSON), where the streams are.
            let json_len = u32::from_le_bytes(b[12..16].try_into().unwrap()) as usize;
            let start = 20 + json_len + 8;
            for _ in 0..1 + rng.below(6) {
                let i = start + rng.below(b.len() - start);
                b[i] ^= 1 << rng.below(8);
            }
            match std::panic::catch_unwind(|| veach::load_bytes(&b, None, None)) {
                Ok(Err(e)) => {
                    assert!(!e.to_string().contains('\n'), "{e}");
                    refused += 1;
                }
                Ok(Ok(_)) => {}
                Err(_) => panic!("{file}: a damaged stream panicked"),
            }
        }
    }
    assert!(refused > 50, "damage is noticed ({refused} refused)");
}

/// EXT_mesh_gpu_instancing becomes instances of the two-level BVH: PlayCanvas' sample draws
/// one 12-triangle cube 125 times, stored once.
#[test]
fn gpu_instancing_draws_one_mesh_many_times() {
    let Some(dir) = common::shared_models() else { return };
    let loaded = veach::load(&dir.join("SimpleInstancing-playcanvas/simple-instancing.glb"), None).unwrap();
    let scene = &loaded.scene;
    assert_eq!(scene.instances.len(), 125);
    assert_eq!(scene.meshes.len(), 1);
    assert_eq!(scene.meshes[0].triangles.len(), 12);
    // Every instance in its own place.
    let mut origins: Vec<[i64; 3]> = scene
        .instances
        .iter()
        .map(|i| i.transform.w_axis.truncate().to_array().map(|c| (c * 1000.0).round() as i64))
        .collect();
    origins.sort();
    origins.dedup();
    assert_eq!(origins.len(), 125);
    let film = common::render(
        &dir.join("SimpleInstancing-playcanvas/simple-instancing.glb"),
        &Settings { width: 24, height: 24, ..Settings::default() },
        2,
        None,
    );
    assert_eq!(film.nonfinite_samples(), 0);
}

/// KHR_materials_variants: `--variant NAME` gives each primitive the material its mapping names
/// for that variant; an unknown name is an error naming the file's variants. `--scene N`
/// renders another scene of the file; one the file lacks is an error.
#[test]
fn variants_and_scenes_are_chosen_by_name_and_index() {
    if let Some(dir) = common::shared_models() {
        let path = dir.join("Variants-blenderio/18_variants.gltf");
        let materials = |variant: Option<&str>| -> Vec<u32> {
            let l = veach::load_with(&path, &veach::LoadOptions { variant, ..Default::default() }).unwrap();
            let mut m: Vec<u32> = l.scene.triangles.iter().map(|t| t.material).collect();
            m.sort();
            m.dedup();
            m
        };
        // Red (0), Orange (2), White (4) as Variant_Red; Blue (1), Green (3), White as Variant_Blue.
        assert_eq!(materials(Some("Variant_Red")), [0, 2, 4]);
        assert_eq!(materials(Some("Variant_Blue")), [1, 3, 4]);
        let e = veach::load_with(&path, &veach::LoadOptions { variant: Some("Purple"), ..Default::default() });
        let e = e.err().expect("unknown variant").to_string();
        assert!(e.contains("Variant_Red, Variant_Blue") && !e.contains('\n'), "{e}");
    }
    // Two scenes built in code: scene 1 holds two triangles, the default scene 0 one.
    let mut bin = Vec::new();
    let (pa, pl) = push(&mut bin, &[0.0f32, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0, 0.0]);
    let uri =
        format!("data:application/octet-stream;base64,{}", base64::engine::general_purpose::STANDARD.encode(&bin));
    let doc = serde_json::to_vec(&json!({
        "asset": {"version": "2.0"}, "scene": 0,
        "scenes": [{"nodes": [0]}, {"nodes": [0, 1]}],
        "nodes": [{"mesh": 0}, {"mesh": 0, "translation": [2, 0, 0]}],
        "meshes": [{"primitives": [{"attributes": {"POSITION": 0}}]}],
        "buffers": [{"uri": uri, "byteLength": bin.len()}],
        "bufferViews": [{"buffer": 0, "byteOffset": pa, "byteLength": pl}],
        "accessors": [{"bufferView": 0, "componentType": 5126, "count": 3, "type": "VEC3", "min": [0, 0, 0], "max": [1, 1, 0]}],
    }))
    .unwrap();
    let count = |scene: Option<usize>| {
        let l = veach::load_bytes_with(&doc, None, &veach::LoadOptions { scene, ..Default::default() });
        l.map(|l| l.scene.triangles.len() + l.scene.instances.len())
    };
    assert_eq!(count(None).unwrap(), 1);
    assert_eq!(count(Some(1)).unwrap(), 2);
    let e = count(Some(2)).expect_err("no scene 2").to_string();
    assert!(e.contains("no scene 2 (the file has 2)"), "{e}");
}

/// A unit quad seen straight on by an orthographic camera filling the image, lit by a white
/// sky, as a rough metal whose colour is COLOR_0 (red, green, blue, white at its corners) or a
/// texture read through TEXCOORD_1 (TEXCOORD_0 all zero): the albedo AOV shows the colours
/// where they are, on both engines.
fn vertex_extras_scene(texture_on_uv1: bool) -> Vec<u8> {
    let mut bin = Vec::new();
    let (pa, pl) = push(&mut bin, &[-1.0f32, -1.0, 0.0, 1.0, -1.0, 0.0, 1.0, 1.0, 0.0, -1.0, 1.0, 0.0]);
    let (na, nl) = push(&mut bin, &[0.0f32, 0.0, 1.0, 0.0, 0.0, 1.0, 0.0, 0.0, 1.0, 0.0, 0.0, 1.0]);
    let (ca, cl) = push(&mut bin, &[255u8, 0, 0, 255, 0, 255, 0, 255, 0, 0, 255, 255, 255, 255, 255, 255]);
    let (u0a, u0l) = push(&mut bin, &[0.0f32; 8]);
    let (u1a, u1l) = push(&mut bin, &[0.0f32, 1.0, 1.0, 1.0, 1.0, 0.0, 0.0, 0.0]);
    let (ia, il) = push(&mut bin, &[0u16, 1, 2, 0, 2, 3]);
    // An 8×8 PNG: the left half red, the right half green.
    let img =
        image::RgbaImage::from_fn(8, 8, |x, _| image::Rgba(if x < 4 { [255, 0, 0, 255] } else { [0, 255, 0, 255] }));
    let mut png = Vec::new();
    image::DynamicImage::ImageRgba8(img)
        .write_to(&mut std::io::Cursor::new(&mut png), image::ImageFormat::Png)
        .unwrap();
    let png_uri = format!("data:image/png;base64,{}", base64::engine::general_purpose::STANDARD.encode(&png));
    let uri =
        format!("data:application/octet-stream;base64,{}", base64::engine::general_purpose::STANDARD.encode(&bin));
    let mut attributes = json!({"POSITION": 0, "NORMAL": 1, "TEXCOORD_0": 3, "TEXCOORD_1": 4});
    let mut pbr = json!({"baseColorFactor": [1, 1, 1, 1], "metallicFactor": 1, "roughnessFactor": 0.5});
    if texture_on_uv1 {
        pbr["baseColorTexture"] = json!({"index": 0, "texCoord": 1});
    } else {
        attributes["COLOR_0"] = json!(2);
    }
    serde_json::to_vec(&json!({
        "asset": {"version": "2.0"}, "scene": 0, "scenes": [{"nodes": [0, 1]}],
        "nodes": [{"mesh": 0}, {"camera": 0, "translation": [0, 0, 3]}],
        "cameras": [{"type": "orthographic", "orthographic": {"xmag": 1, "ymag": 1, "znear": 0.1, "zfar": 10}}],
        "meshes": [{"primitives": [{"attributes": attributes, "indices": 5, "material": 0}]}],
        "materials": [{"pbrMetallicRoughness": pbr}],
        "textures": [{"source": 0, "sampler": 0}],
        "samplers": [{"magFilter": 9728, "wrapS": 33071, "wrapT": 33071}],
        "images": [{"uri": png_uri}],
        "buffers": [{"uri": uri, "byteLength": bin.len()}],
        "bufferViews": [
            {"buffer": 0, "byteOffset": pa, "byteLength": pl}, {"buffer": 0, "byteOffset": na, "byteLength": nl},
            {"buffer": 0, "byteOffset": ca, "byteLength": cl}, {"buffer": 0, "byteOffset": u0a, "byteLength": u0l},
            {"buffer": 0, "byteOffset": u1a, "byteLength": u1l}, {"buffer": 0, "byteOffset": ia, "byteLength": il},
        ],
        "accessors": [
            {"bufferView": 0, "componentType": 5126, "count": 4, "type": "VEC3", "min": [-1, -1, 0], "max": [1, 1, 0]},
            {"bufferView": 1, "componentType": 5126, "count": 4, "type": "VEC3"},
            {"bufferView": 2, "componentType": 5121, "normalized": true, "count": 4, "type": "VEC4"},
            {"bufferView": 3, "componentType": 5126, "count": 4, "type": "VEC2"},
            {"bufferView": 4, "componentType": 5126, "count": 4, "type": "VEC2"},
            {"bufferView": 5, "componentType": 5123, "count": 6, "type": "SCALAR"},
        ],
    }))
    .unwrap()
}

fn vertex_extras_on(ctx: Option<veach::gpu::GpuContext>) {
    let engine = if ctx.is_some() { "gpu" } else { "cpu" };
    let size = 16u32;
    let settings = Settings {
        width: size,
        height: size,
        env_color: Some([1.0; 3]),
        aovs: vec![veach::aov::Aov::Albedo],
        ..Settings::default()
    };
    for uv1 in [false, true] {
        let loaded = veach::load_bytes(&vertex_extras_scene(uv1), None, None).unwrap();
        let mut r =
            common::renderer(veach::PackedScene::new(&loaded.scene), &loaded.camera, &settings, ctx.clone()).unwrap();
        r.render_samples(0, 4).unwrap();
        let albedo = r.film().unwrap().aov_image(veach::aov::Aov::Albedo).unwrap();
        for y in 0..size {
            for x in 0..size {
                // The pixel centre in the quad's coordinates (x right, y up, −1..1).
                let (px, py) = ((x as f32 + 0.5) / size as f32 * 2.0 - 1.0, 1.0 - (y as f32 + 0.5) / size as f32 * 2.0);
                let got = Vec3::from_slice(&albedo[3 * (y * size + x) as usize..]);
                let want = if uv1 {
                    if px < 0.0 { Vec3::X } else { Vec3::Y }
                } else {
                    // Triangles (0, 1, 2) below the diagonal, (0, 2, 3) above; skip pixels on it.
                    if (px - py).abs() < 0.2 {
                        continue;
                    }
                    let (s, t) = ((px + 1.0) / 2.0, (py + 1.0) / 2.0);
                    let (red, green, blue, white) = (Vec3::X, Vec3::Y, Vec3::Z, Vec3::ONE);
                    if s > t {
                        red * (1.0 - s) + green * (s - t) + blue * t
                    } else {
                        red * (1.0 - t) + blue * s + white * (t - s)
                    }
                };
                let tol = if uv1 { 0.02 } else { 0.01 };
                if uv1 && (px.abs() < 0.15) {
                    continue; // the texture's bilinear edge between its halves
                }
                assert!((got - want).abs().max_element() < tol, "{engine} uv1 {uv1}: pixel {x},{y}: {got} vs {want}");
            }
        }
    }
}

#[test]
fn vertex_colors_and_second_uvs_reach_the_material() {
    vertex_extras_on(None);
}

#[test]
#[cfg_attr(veach_no_gpu, ignore = "needs a GPU adapter (no Vulkan driver on this machine)")]
fn vertex_colors_and_second_uvs_reach_the_material_on_the_gpu() {
    let Some(ctx) = common::gpu("vertex_colors_and_second_uvs_reach_the_material_on_the_gpu") else { return };
    vertex_extras_on(Some(ctx));
}
