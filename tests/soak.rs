//! Long runs do not grow memory: 100k progressive dispatches (run with `--ignored`).

mod common;

fn resident_bytes() -> u64 {
    let statm = std::fs::read_to_string("/proc/self/statm").unwrap_or_default();
    statm.split_whitespace().nth(1).and_then(|p| p.parse::<u64>().ok()).unwrap_or(0) * 4096
}

#[test]
#[ignore = "soak test: about a minute or more on lavapipe"]
fn hundred_thousand_dispatches_do_not_grow_memory() {
    let Some(ctx) = common::gpu("soak") else { return };
    let (scene, camera) = common::load_pair(&common::asset("cornell-box.gltf"), None).unwrap();
    let packed = veach::packed::PackedScene::new(&scene);
    let mut r = common::renderer(packed, &camera, &common::settings(8, 8, 0), Some(ctx)).unwrap();
    r.render_samples(0, 10_000).unwrap();
    let after_warmup = resident_bytes();
    let t = std::time::Instant::now();
    r.render_samples(10_000, 90_000).unwrap();
    let film = r.film().unwrap();
    let grown = resident_bytes() as i64 - after_warmup as i64;
    eprintln!(
        "soak: 100000 dispatches, resident {} MiB after 10k, grew {} KiB over 90k more ({:.1} s)",
        after_warmup >> 20,
        grown >> 10,
        t.elapsed().as_secs_f64()
    );
    assert_eq!(film.samples(), 100_000);
    assert!(grown < 8 << 20, "memory grew by {grown} bytes");
}
