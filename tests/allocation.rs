//! The CPU engine allocates nothing per sample: once warm, a render's heap allocations do not
//! grow with its samples or its pixels (a counting global allocator over this test binary,
//! which holds this one test so that no other test's allocations are counted).

mod common;

use std::alloc::{GlobalAlloc, Layout, System};
use std::sync::atomic::{AtomicUsize, Ordering};
use veach::aov::Aov;
use veach::{Backend, LightSampler, PackedScene, Renderer, Settings};

struct Counting;

static ALLOCATIONS: AtomicUsize = AtomicUsize::new(0);

// SAFETY: forwards every call to the system allocator, only counting them.
unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        ALLOCATIONS.fetch_add(1, Ordering::Relaxed);
        unsafe { System.alloc(layout) }
    }
    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        unsafe { System.dealloc(ptr, layout) }
    }
    unsafe fn realloc(&self, ptr: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
        ALLOCATIONS.fetch_add(1, Ordering::Relaxed);
        unsafe { System.realloc(ptr, layout, new_size) }
    }
}

#[global_allocator]
static GLOBAL: Counting = Counting;

/// Allocations made while `f` runs.
fn allocations(f: impl FnOnce()) -> usize {
    let before = ALLOCATIONS.load(Ordering::SeqCst);
    f();
    ALLOCATIONS.load(Ordering::SeqCst) - before
}

#[test]
fn the_cpu_engine_allocates_nothing_per_sample() {
    let (w, h) = (48u32, 32u32);
    let cases = [
        ("cornell-box.gltf", LightSampler::Tree, vec![]),
        ("cornell-box.gltf", LightSampler::Power, vec![Aov::Albedo, Aov::Normal, Aov::Depth]),
        ("cornell-glass.gltf", LightSampler::Tree, vec![]),
        ("veach-mis.gltf", LightSampler::Tree, vec![]),
    ];
    for (name, light_sampler, aovs) in cases {
        let loaded = veach::load(&common::asset(name), None).expect("asset loads");
        let settings =
            Settings { width: w, height: h, max_depth: 8, light_sampler, aovs: aovs.clone(), ..Default::default() };
        let packed = PackedScene::new(&loaded.scene);
        let mut r = Renderer::new(packed, &loaded.camera, &settings, Backend::Cpu).expect("renderer");
        r.render_samples(0, 2).expect("warm-up");
        let one = allocations(|| r.render_samples(2, 1).expect("render"));
        let sixteen = allocations(|| r.render_samples(3, 16).expect("render"));
        eprintln!("{name} {light_sampler:?} {aovs:?}: {one} allocations for 1 spp, {sixteen} for 16 spp");
        // The per-call bookkeeping (one task a row, the thread pool's jobs) is allowed; a
        // per-sample or per-pixel allocation would be ≥ w·h = 1536 per sample.
        assert!(one <= 2 * h as usize + 16, "{name}: {one} allocations for one sample of {w}x{h}");
        assert!(sixteen <= one + 16, "{name}: {sixteen} allocations for 16 samples, {one} for one");
        let film = r.film().expect("film");
        assert_eq!(film.nonfinite_samples(), 0);
    }
}
