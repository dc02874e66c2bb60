//! Hostile and broken glTF: every input gives a scene or one clear error, never a panic, and
//! nothing is allocated for counts the file cannot back.

mod common;

use common::rng::Lcg;

use glam::Vec3;
use serde_json::{Value, json};
use veach::scene::gltf::load_bytes;

fn base64(bytes: &[u8]) -> String {
    const T: &[u8] = b"ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    let mut out = String::new();
    for c in bytes.chunks(3) {
        let n = (c[0] as u32) << 16 | (*c.get(1).unwrap_or(&0) as u32) << 8 | *c.get(2).unwrap_or(&0) as u32;
        for k in 0..4 {
            if k <= c.len() {
                out.push(T[(n >> (18 - 6 * k) & 63) as usize] as char);
            } else {
                out.push('=');
            }
        }
    }
    out
}

/// A one-mesh glTF built from raw positions and indices, for targeted breakage.
fn triangle_gltf(positions: &[f32], indices: &[u32], count_override: Option<u64>) -> Vec<u8> {
    let mut bin: Vec<u8> = positions.iter().flat_map(|f| f.to_le_bytes()).collect();
    let pos_len = bin.len();
    bin.extend(indices.iter().flat_map(|i| i.to_le_bytes()));
    let doc = json!({
        "asset": {"version": "2.0"},
        "scene": 0,
        "scenes": [{"nodes": [0]}],
        "nodes": [{"mesh": 0}],
        "meshes": [{"primitives": [{"attributes": {"POSITION": 0}, "indices": 1, "material": 0}]}],
        "materials": [{"emissiveFactor": [1.0, 1.0, 1.0]}],
        "buffers": [{"byteLength": bin.len(), "uri": format!("data:application/octet-stream;base64,{}", base64(&bin))}],
        "bufferViews": [
            {"buffer": 0, "byteOffset": 0, "byteLength": pos_len},
            {"buffer": 0, "byteOffset": pos_len, "byteLength": bin.len() - pos_len}
        ],
        "accessors": [
            {"bufferView": 0, "componentType": 5126, "count": count_override.unwrap_or((positions.len() / 3) as u64),
             "type": "VEC3", "min": [-1e38, -1e38, -1e38], "max": [1e38, 1e38, 1e38]},
            {"bufferView": 1, "componentType": 5125, "count": indices.len(), "type": "SCALAR"}
        ]
    });
    serde_json::to_vec(&doc).unwrap()
}

fn glb(json: &[u8]) -> Vec<u8> {
    let mut chunk = json.to_vec();
    while !chunk.len().is_multiple_of(4) {
        chunk.push(b' ');
    }
    let mut out = b"glTF".to_vec();
    out.extend(2u32.to_le_bytes());
    out.extend(((20 + chunk.len()) as u32).to_le_bytes());
    out.extend((chunk.len() as u32).to_le_bytes());
    out.extend(0x4E4F534Au32.to_le_bytes());
    out.extend(chunk);
    out
}

fn expect_error(bytes: &[u8], needle: &str) {
    match load_bytes(bytes, None) {
        Ok(_) => panic!("expected an error containing '{needle}'"),
        Err(e) => assert!(e.contains(needle), "'{e}' should mention '{needle}'"),
    }
}

#[test]
fn targeted_breakage_gives_clear_errors() {
    let ok = [0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0, 0.0];
    let scene = load_bytes(&triangle_gltf(&ok, &[0, 1, 2], None), None).expect("valid triangle");
    assert_eq!(scene.triangles.len(), 1);
    expect_error(&triangle_gltf(&ok, &[0, 1, 7], None), "out of range");
    expect_error(&triangle_gltf(&[f32::NAN, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0, 0.0], &[0, 1, 2], None), "non-finite");
    expect_error(&triangle_gltf(&ok, &[0, 1, 2], Some(4_000_000_000)), "4000000000 elements");
    expect_error(&triangle_gltf(&ok, &[0, 1, 2], Some(5)), "elements need");
    expect_error(b"{\"asset\": {\"version\": \"2.0\"", "invalid glTF JSON");
    expect_error(b"glTF\x02\x00\x00\x00\xff\xff\xff\x7f", "GLB");
    expect_error(&glb(b"{}")[..18], "GLB");
    let mut unknown: Value = serde_json::from_slice(&triangle_gltf(&ok, &[0, 1, 2], None)).unwrap();
    unknown["extensionsUsed"] = json!(["MSFT_lod", "EXT_lights_ies"]);
    unknown["extensionsRequired"] = json!(["MSFT_lod", "EXT_lights_ies"]);
    expect_error(&serde_json::to_vec(&unknown).unwrap(), "MSFT_lod, EXT_lights_ies");
    // Optional unknown extensions are ignored with one warning each.
    unknown.as_object_mut().unwrap().remove("extensionsRequired");
    let scene = load_bytes(&serde_json::to_vec(&unknown).unwrap(), None).expect("optional extensions load");
    assert_eq!(scene.warnings.len(), 2, "{:?}", scene.warnings);
}

#[test]
fn degenerate_empty_and_huge_scenes_render_finite_images() {
    // Zero-area emissive triangles are never lights; a huge one still renders.
    let zero = [0.0, 0.0, 0.0, 1.0, 1.0, 1.0, 2.0, 2.0, 2.0];
    let scene = load_bytes(&triangle_gltf(&zero, &[0, 1, 2], None), None).expect("degenerate triangle loads");
    assert_eq!(veach::packed::PackedScene::new(&scene).lights.len(), 0);
    let huge = [-1e30, -1e30, 0.0, 1e30, -1e30, 0.0, 0.0, 1e30, 0.0];
    for bytes in [triangle_gltf(&huge, &[0, 1, 2], None), triangle_gltf(&zero, &[0, 1, 2], None)] {
        let mut scene = load_bytes(&bytes, None).expect("loads");
        scene.environment = veach::Environment::constant(Vec3::splat(0.5));
        let camera = scene.camera(None).expect("camera");
        let packed = veach::packed::PackedScene::new(&scene);
        let mut r = veach::Renderer::new(packed, &camera, &common::settings(16, 8, 0), veach::Backend::Cpu).unwrap();
        r.render_samples(0, 4).unwrap();
        let film = r.film().unwrap();
        assert!((0..film.pixel_count()).all(|i| film.mean(i).is_finite()));
    }
    let empty = json!({"asset": {"version": "2.0"}, "scenes": [{"nodes": []}], "scene": 0});
    let scene = load_bytes(&serde_json::to_vec(&empty).unwrap(), None).expect("an empty scene loads");
    assert!(scene.triangles.is_empty());
}

/// Every numeric leaf of a JSON document, as a path of keys and indices.
fn numeric_paths(v: &Value, path: &mut Vec<Value>, out: &mut Vec<Vec<Value>>) {
    match v {
        Value::Number(_) => out.push(path.clone()),
        Value::Array(a) => {
            for (i, x) in a.iter().enumerate() {
                path.push(json!(i));
                numeric_paths(x, path, out);
                path.pop();
            }
        }
        Value::Object(o) => {
            for (k, x) in o {
                path.push(json!(k));
                numeric_paths(x, path, out);
                path.pop();
            }
        }
        _ => {}
    }
}

fn at<'a>(v: &'a mut Value, path: &[Value]) -> &'a mut Value {
    path.iter().fold(v, |v, k| match k {
        Value::String(s) => &mut v[s.as_str()],
        Value::Number(n) => &mut v[n.as_u64().unwrap() as usize],
        _ => unreachable!(),
    })
}

/// GPU time the mutation test spends rendering what loads (after the first six, always).
const GPU_BUDGET_SECONDS: f64 = 45.0;

/// The mutation test's inputs, the same sequence on every call: (round, bytes).
fn mutated_inputs() -> impl Iterator<Item = (usize, Vec<u8>)> {
    let mut rng = Lcg(12345);
    let originals: Vec<Vec<u8>> = ["cornell-box.gltf", "veach-mis.gltf"]
        .iter()
        .map(|n| std::fs::read(common::asset(n)).expect("asset"))
        .chain([triangle_gltf(&[0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0, 0.0], &[0, 1, 2], None)])
        .collect();
    let hostile =
        [json!(-1), json!(0), json!(1), json!(3), json!(65535), json!(4294967295u64), json!(1e20), json!(0.5)];
    (0..3000).map(move |round| {
        let base = &originals[round % originals.len()];
        let bytes = match round % 3 {
            // Structured: a few numbers (indices, counts, offsets, strides, types) made hostile.
            0 | 1 => {
                let mut doc: Value = serde_json::from_slice(base).unwrap();
                let mut paths = Vec::new();
                numeric_paths(&doc, &mut Vec::new(), &mut paths);
                for _ in 0..1 + rng.below(3) {
                    let p = &paths[rng.below(paths.len())];
                    *at(&mut doc, p) = hostile[rng.below(hostile.len())].clone();
                }
                let bytes = serde_json::to_vec(&doc).unwrap();
                if round % 6 == 1 { glb(&bytes) } else { bytes }
            }
            // Bytes: flips, truncation, duplication (of the JSON or of a GLB around it).
            _ => {
                let mut b = if rng.below(2) == 0 { glb(base) } else { base.clone() };
                match rng.below(3) {
                    0 => {
                        for _ in 0..1 + rng.below(8) {
                            let i = rng.below(b.len());
                            b[i] ^= 1 << rng.below(8);
                        }
                    }
                    1 => b.truncate(rng.below(b.len())),
                    _ => {
                        let i = rng.below(b.len());
                        let chunk = b[i..(i + rng.below(64)).min(b.len())].to_vec();
                        let j = rng.below(b.len());
                        b.splice(j..j, chunk);
                    }
                }
                b
            }
        };
        (round, bytes)
    })
}

/// Renders a loaded mutated input on one engine: its count of non-finite samples, or None
/// when it has no camera or the engine refuses it (an error, not a panic).
fn nonfinite_samples_of(scene: &veach::Scene, ctx: Option<veach::gpu::GpuContext>) -> Option<u64> {
    let camera = scene.camera(None).ok()?;
    let packed = veach::PackedScene::new(scene);
    let s = veach::Settings { width: 8, height: 8, max_depth: 4, env_color: Some([0.5; 3]), ..Default::default() };
    let mut r = common::renderer(packed, &camera, &s, ctx).ok()?;
    r.render_samples(0, 2).ok()?;
    Some(r.film().ok()?.nonfinite_samples())
}

/// Checks one mutated input's render on an engine: no panic, no non-finite sample. Whether
/// it rendered at all.
fn render_mutated(round: usize, bytes: &[u8], scene: &veach::Scene, ctx: Option<veach::gpu::GpuContext>) -> bool {
    let engine = if ctx.is_some() { "gpu" } else { "cpu" };
    let nonfinite = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| nonfinite_samples_of(scene, ctx)));
    match nonfinite {
        Ok(Some(count)) => {
            if count > 0 {
                let _ = std::fs::write(std::env::temp_dir().join("veach-nonfinite-input.gltf"), bytes);
                panic!(
                    "input {round} renders {count} non-finite samples on the {engine} (saved to veach-nonfinite-input.gltf)"
                );
            }
            true
        }
        Ok(None) => false,
        Err(_) => {
            let _ = std::fs::write(std::env::temp_dir().join("veach-panic-input.gltf"), bytes);
            panic!("input {round} panicked while rendering on the {engine} (saved to veach-panic-input.gltf)");
        }
    }
}

#[test]
fn mutated_assets_never_panic() {
    let (mut loaded, mut refused, mut inputs) = (0, 0, 0);
    let start = std::time::Instant::now();
    for (round, bytes) in mutated_inputs() {
        inputs += 1;
        let result = std::panic::catch_unwind(|| load_bytes(&bytes, None));
        match result {
            Ok(Ok(scene)) => {
                loaded += 1;
                // What loads renders without a panic and with no non-finite sample on the CPU
                // engine (on the GPU: mutated_assets_never_panic_on_the_gpu).
                render_mutated(round, &bytes, &scene, None);
            }
            Ok(Err(e)) => {
                assert!(!e.is_empty() && !e.contains('\n'), "one line: {e}");
                refused += 1;
            }
            Err(_) => {
                let _ = std::fs::write(std::env::temp_dir().join("veach-panic-input.gltf"), &bytes);
                panic!("input {round} panicked (saved to veach-panic-input.gltf in the temp dir)");
            }
        }
    }
    eprintln!("{inputs} mutated inputs: {loaded} loaded, {refused} refused, {:.1} s", start.elapsed().as_secs_f64());
    assert!(loaded > 100 && refused > 100, "the mutations exercise both outcomes");
}

/// The mutated inputs that load render on the GPU without a panic and with no non-finite
/// sample, as many as fit a time budget (each GPU renderer compiles its pipeline: about a
/// second on lavapipe), at least six. Loading them is mutated_assets_never_panic's business.
#[test]
#[cfg_attr(veach_no_gpu, ignore = "needs a GPU adapter (no Vulkan driver on this machine)")]
fn mutated_assets_never_panic_on_the_gpu() {
    let Some(gpu_ctx) = common::gpu("mutated_assets_never_panic_on_the_gpu") else { return };
    let (mut loaded, mut gpu_runs) = (0, 0usize);
    let mut gpu_seconds = 0.0;
    let start = std::time::Instant::now();
    for (round, bytes) in mutated_inputs() {
        if gpu_runs >= 6 && gpu_seconds >= GPU_BUDGET_SECONDS {
            break;
        }
        let Ok(Ok(scene)) = std::panic::catch_unwind(|| load_bytes(&bytes, None)) else { continue };
        loaded += 1;
        let gpu_start = std::time::Instant::now();
        if render_mutated(round, &bytes, &scene, Some(gpu_ctx.clone())) {
            gpu_runs += 1;
            gpu_seconds += gpu_start.elapsed().as_secs_f64();
        }
    }
    eprintln!(
        "{loaded} mutated inputs loaded, {gpu_runs} rendered on the GPU in {gpu_seconds:.1} s, {:.1} s in all",
        start.elapsed().as_secs_f64()
    );
}

/// The triangle's glTF with its buffer moved to `uri` (byteLength kept).
fn with_buffer_uri(uri: &str) -> Vec<u8> {
    let ok = [0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0, 0.0];
    let mut doc: Value = serde_json::from_slice(&triangle_gltf(&ok, &[0, 1, 2], None)).unwrap();
    doc["buffers"][0]["uri"] = json!(uri);
    serde_json::to_vec(&doc).unwrap()
}

#[test]
fn external_uris_are_read_within_bounds() {
    let dir = tempfile::tempdir().unwrap();
    let base = Some(dir.path());
    // A device, an absolute path and other schemes are never opened.
    for (uri, needle) in [
        ("file:///dev/zero", "scheme"),
        ("/dev/zero", "absolute"),
        ("https://example.com/a.bin", "scheme"),
        ("../../../../../../dev/zero", "not a regular file"),
    ] {
        let e = veach::scene::gltf::load_bytes(&with_buffer_uri(uri), base).expect_err(uri);
        assert!(e.contains(needle), "{uri}: {e}");
    }
    // Without a base directory, bytes may not name external files at all.
    let e = veach::scene::gltf::load_bytes(&with_buffer_uri("tri.bin"), None).expect_err("no base");
    assert!(e.contains("no base directory"), "{e}");
    // A file larger than its declared byteLength is read only up to it: a huge sparse file
    // loads as fast as a small one.
    let doc: Value = serde_json::from_slice(&with_buffer_uri("tri.bin")).unwrap();
    let bin = {
        let ok = [0.0f32, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0, 0.0];
        let mut b: Vec<u8> = ok.iter().flat_map(|f| f.to_le_bytes()).collect();
        b.extend([0u32, 1, 2].iter().flat_map(|i| i.to_le_bytes()));
        b
    };
    let f = std::fs::File::create(dir.path().join("tri.bin")).unwrap();
    std::io::Write::write_all(&mut &f, &bin).unwrap();
    f.set_len(64 << 30).unwrap();
    let t = std::time::Instant::now();
    let scene = veach::scene::gltf::load_bytes(&serde_json::to_vec(&doc).unwrap(), base).expect("bounded read");
    assert_eq!(scene.triangles.len(), 1);
    assert!(t.elapsed().as_secs() < 10, "read more than the declared bytes");
    // Shorter than declared is an error naming the buffer.
    std::fs::write(dir.path().join("tri.bin"), &bin[..10]).unwrap();
    let e = veach::scene::gltf::load_bytes(&serde_json::to_vec(&doc).unwrap(), base).expect_err("short");
    assert!(e.contains("buffer 0") && e.contains("fewer"), "{e}");
    // Percent-encoded names resolve.
    std::fs::write(dir.path().join("a b.bin"), &bin).unwrap();
    let doc = with_buffer_uri("a%20b.bin");
    veach::scene::gltf::load_bytes(&doc, base).expect("percent-encoded URI");
}

#[test]
fn a_scene_without_nodes_is_empty_not_invalid() {
    let doc = json!({"asset": {"version": "2.0"}, "scenes": [{"name": "empty"}], "scene": 0});
    let scene = load_bytes(&serde_json::to_vec(&doc).unwrap(), None).expect("valid glTF");
    assert!(scene.triangles.is_empty());
}

/// Degenerate vertex data users' files carry: zero-length and opposite normals, identical or
/// collinear UVs under a normal map without tangents (generated tangents degenerate), a
/// sliver triangle, a light seen edge-on. Both engines must take 0 non-finite samples:
/// dropping them would hide a bias.
fn degenerate_vertex_data_on(ctx: Option<veach::gpu::GpuContext>) {
    use common::build::{GltfBuilder, MeshData};
    use std::f32::consts::FRAC_1_SQRT_2;
    let dir = tempfile::tempdir().unwrap();
    let mut b = GltfBuilder::new(dir.path(), "degenerate");
    let bumps = image::RgbaImage::from_fn(8, 8, |x, y| image::Rgba([(x * 32) as u8, (y * 32) as u8, 200, 255]));
    let normal_map = b.texture(&bumps, 10497);
    let mat = b.material(json!({"pbrMetallicRoughness": {"baseColorFactor": [0.8, 0.8, 0.8, 1], "metallicFactor": 0.5,
        "roughnessFactor": 0.3}, "normalTexture": {"index": normal_map, "scale": 4.0}, "doubleSided": true}));
    let lamp = b.material(json!({"emissiveFactor": [5, 5, 5]}));
    let mesh = MeshData {
        positions: vec![
            [-1.0, -1.0, 0.0],
            [1.0, -1.0, 0.0],
            [1.0, 1.0, 0.0],
            [-1.0, 1.0, 0.0],
            [0.0, 0.0, 0.0],
            [2.0, 0.0, 1e-7],
            [4.0, 0.0, 0.0],
            [0.5, 0.5, 0.2],
        ],
        normals: vec![
            [0.0, 0.0, 0.0],
            [0.0, 0.0, -1.0],
            [0.0, 0.0, 1.0],
            [1e-30, 0.0, 0.0],
            [0.0, 0.0, 1.0],
            [0.0, 1.0, 0.0],
            [0.0, 0.0, 0.0],
            [0.0, 0.0, -1.0],
        ],
        uvs: vec![[0.5, 0.5], [0.5, 0.5], [0.5, 0.5], [0.0, 1.0], [0.0, 0.0], [1.0, 0.0], [2.0, 0.0], [0.5, 0.5]],
        tangents: Vec::new(),
        indices: vec![0, 1, 2, 0, 2, 3, 4, 5, 6, 0, 7, 2, 3, 7, 1],
    };
    let m = b.mesh(&mesh, mat);
    b.node(json!({"mesh": m}));
    let light = b.mesh(&MeshData::quad(-0.5, -0.5, 0.5, 0.5, 0.0, MeshData::UPRIGHT), lamp);
    // Edge-on to the scene's plane, and one facing it.
    b.node(
        json!({"mesh": light, "translation": [0.0, 0.0, 2.0], "rotation": [FRAC_1_SQRT_2, 0.0, 0.0, FRAC_1_SQRT_2]}),
    );
    b.node(json!({"mesh": light, "translation": [0.0, 0.0, 3.0], "rotation": [1.0, 0.0, 0.0, 0.0]}));
    b.camera(1.0, 1.0, [0.3, 0.2, 4.0]);
    let path = b.write();
    let (scene, camera) = common::load_pair(&path, None).expect("loads");
    let packed = veach::PackedScene::new(&scene);
    let settings =
        veach::Settings { width: 48, height: 48, max_depth: 6, env_color: Some([0.3; 3]), ..Default::default() };
    let gpu = ctx.is_some();
    let mut r = common::renderer(packed, &camera, &settings, ctx).unwrap();
    r.render_samples(0, 32).unwrap();
    let film = r.film().unwrap();
    assert_eq!(film.nonfinite_samples(), 0, "gpu {gpu}: non-finite samples");
    assert!(film.samples() == 32 && film.mean(24 * 48 + 24).max_element() > 0.0, "gpu {gpu}: an empty image");
}

#[test]
fn degenerate_vertex_data_gives_no_non_finite_samples() {
    degenerate_vertex_data_on(None);
}

#[test]
#[cfg_attr(veach_no_gpu, ignore = "needs a GPU adapter (no Vulkan driver on this machine)")]
fn degenerate_vertex_data_gives_no_non_finite_samples_on_the_gpu() {
    let Some(ctx) = common::gpu("degenerate_vertex_data_gives_no_non_finite_samples_on_the_gpu") else { return };
    degenerate_vertex_data_on(Some(ctx));
}

#[test]
fn hand_built_scenes_are_validated() {
    let ok = [0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0, 0.0];
    let scene = load_bytes(&triangle_gltf(&ok, &[0, 1, 2], None), None).unwrap();
    assert!(veach::PackedScene::try_new(&scene).is_ok());
    let mut bad = scene.clone();
    bad.triangles[0].material = 99;
    let e = veach::PackedScene::try_new(&bad).err().expect("material out of range").to_string();
    assert!(e.contains("material 99"), "{e}");
    let mut bad = scene.clone();
    bad.textures.push(veach::scene::Texture { name: "t".into(), width: 4, height: 4, rgba: vec![0; 7] });
    let e = veach::PackedScene::try_new(&bad).err().expect("short texture").to_string();
    assert!(e.contains("texture 0 is 4x4"), "{e}");
    let mut bad = scene;
    bad.instances.push(veach::scene::Instance { mesh: 3, transform: glam::Mat4::IDENTITY });
    assert!(veach::PackedScene::try_new(&bad).is_err());
}
