//! Regression guard for restructuring: the films of the bundled scenes, for fixed seeds, hash
//! to the values recorded here. The films' correctness is checked elsewhere against
//! independent references (tests/render.rs); this test only proves that moving code around
//! changed no bit. A change that alters images on purpose updates the table and says why in
//! its commit. The CPU engine's arithmetic is IEEE-754 without fused multiply-adds, but its
//! transcendental functions come from the platform's libm, so the table is for x86_64 Linux
//! (glibc); elsewhere the test reports itself skipped.

mod common;

use common::scenes::features_scene;
use std::path::PathBuf;
use veach::Settings;

/// FNV-1a over the film's words: enough to detect any changed bit.
fn fnv(words: &[u32]) -> u64 {
    let mut h: u64 = 0xcbf2_9ce4_8422_2325;
    for w in words {
        for b in w.to_le_bytes() {
            h ^= b as u64;
            h = h.wrapping_mul(0x0000_0100_0000_01b3);
        }
    }
    h
}

/// (scene, max depth, sampler, light sampler, expected hash of a 48×48 film of 4 samples,
/// seed 7). The power rows were the films from before the light tree existed until the
/// roulette changed (session 27).
const FILMS: &[(&str, u32, veach::SamplerKind, veach::LightSampler, u64)] = &[
    ("cornell-box.gltf", 8, veach::SamplerKind::Sobol, veach::LightSampler::Power, 0x7a30ba78b292fe5f),
    ("cornell-box.gltf", 8, veach::SamplerKind::Independent, veach::LightSampler::Power, 0xef03a1cc87e6993d),
    ("cornell-glass.gltf", 8, veach::SamplerKind::Sobol, veach::LightSampler::Power, 0xde48f12891710357),
    ("veach-mis.gltf", 2, veach::SamplerKind::Sobol, veach::LightSampler::Power, 0x63ad93f527974cb0),
    ("furnace-a080.gltf", 8, veach::SamplerKind::Sobol, veach::LightSampler::Power, 0x3f62ef321f9cc55f),
    ("furnace-a100.gltf", 8, veach::SamplerKind::Independent, veach::LightSampler::Power, 0xa56d194a8e1ba903),
    ("cornell-box.gltf", 8, veach::SamplerKind::Sobol, veach::LightSampler::Tree, 0x21275055e8f0f806),
    // Session 25: light-tree leaves became clusters of up to 16 emitters chosen by power (the
    // Veach lamps; the Cornell box's light, two equal triangles, still splits 50/50: same film;
    // the features scene's lamps form no cluster).
    ("veach-mis.gltf", 2, veach::SamplerKind::Sobol, veach::LightSampler::Tree, 0x0fc958880cde94d1),
    // Session 27: Russian roulette from 4 segments instead of 3, on the throughput without
    // refraction's 1/η² (every film with paths of 4 segments or more changed; depth 2 and the
    // furnaces did not).
];

/// The films this test renders: (name, scene file, settings).
fn cases(engine: &str) -> Vec<(String, PathBuf, Settings)> {
    let mut out = Vec::new();
    for &(scene, max_depth, sampler, light_sampler, _) in FILMS {
        let settings =
            Settings { width: 48, height: 48, max_depth, seed: 7, sampler, light_sampler, ..Settings::default() };
        out.push((format!("{scene} depth {max_depth} {sampler:?} {light_sampler:?}"), common::asset(scene), settings));
    }
    for light_sampler in veach::LightSampler::ALL {
        let settings = Settings {
            width: 48,
            height: 48,
            max_depth: 6,
            seed: 3,
            env_color: Some([0.2, 0.25, 0.3]),
            light_sampler,
            ..Settings::default()
        };
        out.push((format!("features {light_sampler:?}"), features_scene(engine), settings));
    }
    out
}

/// Hashes of the features scene's CPU films (power, tree, ris).
const FEATURES_CPU: [u64; 3] = [0x49f4dcf21021f6bc, 0x2e2a287b1391f9af, 0x7704a8af4b99ae4b];

/// GPU films hash the same only on the same driver: (driver string, hashes in `cases()` order).
const GPU_FILMS: &[(&str, &[u64])] = &[(
    "llvmpipe Mesa 22.3.6 (LLVM 15.0.6)",
    &[
        0xfa6cb17d60fb1b57,
        0xa98313cf80fc23e5,
        0x0b0e33df641c0a14,
        0xa6a69cfc23b5ecae,
        0xcfe66b0f18714efc,
        0xbf1bac27a228f548,
        0xd8a88ffa067b07fd,
        0xf98f58096802469b,
        0x89c0422b13158940,
        0x59c627f906b4f6d4,
        0x915b321a1f3bc696,
    ],
)];

#[test]
#[cfg_attr(veach_no_gpu, ignore = "needs a GPU adapter (no Vulkan driver on this machine)")]
fn gpu_films_of_bundled_scenes_are_unchanged() {
    let Some(ctx) = common::gpu("gpu_films_of_bundled_scenes_are_unchanged") else { return };
    let driver = format!("{} {}", ctx.info.driver, ctx.info.driver_info);
    let Some((_, expected)) = GPU_FILMS.iter().find(|(d, _)| *d == driver) else {
        eprintln!("SKIPPED gpu_films_of_bundled_scenes_are_unchanged: no hashes recorded for driver '{driver}'");
        return;
    };
    let mut got = Vec::new();
    for (_, path, settings) in cases("gpu") {
        let film = common::render(&path, &settings, 4, Some(ctx.clone()));
        got.push(fnv(&film.data));
    }
    let shown: Vec<String> = got.iter().map(|h| format!("{h:#018x}")).collect();
    assert_eq!(&got[..], *expected, "GPU films changed: now [{}]", shown.join(", "));
}

#[test]
fn cpu_films_of_bundled_scenes_are_unchanged() {
    if !(cfg!(target_arch = "x86_64") && cfg!(target_os = "linux") && cfg!(target_env = "gnu")) {
        eprintln!("SKIPPED cpu_films_of_bundled_scenes_are_unchanged: hashes recorded on x86_64 Linux only");
        return;
    }
    let mut wrong = Vec::new();
    let expected: Vec<u64> = FILMS.iter().map(|f| f.4).chain(FEATURES_CPU).collect();
    let cases = cases("cpu");
    assert_eq!(cases.len(), expected.len(), "a hash recorded for each case");
    for ((name, path, settings), expected) in cases.into_iter().zip(expected) {
        let film = common::render(&path, &settings, 4, None);
        let h = fnv(&film.data);
        if h != expected {
            wrong.push(format!("{name}: {h:#018x}, recorded {expected:#018x}"));
        }
    }
    assert!(wrong.is_empty(), "films changed:\n{}", wrong.join("\n"));
}
