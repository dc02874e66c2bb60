//! The CPU engine's fast path (packets of paths through the integrator's stages, `cpu::lanes`)
//! renders the reference kernel's films bit for bit: every scene and setting that changes
//! what a path does — light samplers, samplers, strategies, glass, textures with alpha,
//! instancing, punctual lights, environments, AOVs, adaptive sampling, clamping, tiles, a lens
//! — and images whose width is not a multiple of the packet or below it, so that lanes take
//! new paths (`lanes::render_row`) from pixels and samples in every arrangement.

mod common;

use common::scenes::features_scene;
use std::path::Path;
use veach::cpu::Kernel;
use veach::{Backend, LightSampler, Renderer, SamplerKind, Settings, Strategy, Tile};

/// The film words of `spp` samples of `scene` with `kernel`.
fn film(scene: &Path, settings: &Settings, spp: u32, kernel: Kernel) -> Vec<u32> {
    let (s, camera) = common::load_pair(scene, settings.camera.as_deref()).expect("scene loads");
    let packed = veach::PackedScene::new(&s);
    let mut r = Renderer::new(packed, &camera, settings, Backend::Cpu).expect("renderer");
    r.set_cpu_kernel(kernel);
    r.render_samples(0, spp).expect("render");
    r.film().expect("film").data
}

fn base(width: u32, height: u32, max_depth: u32) -> Settings {
    Settings { width, height, max_depth, seed: 11, ..Settings::default() }
}

/// False (after saying so) where the CPU cannot run the lanes (x86-64 without AVX2: the
/// engine renders with its reference kernel there, so there is nothing to compare).
fn lanes_run(test: &str) -> bool {
    let ok = veach::cpu::lanes::available();
    if !ok {
        eprintln!("SKIPPED {test}: this CPU cannot run the lanes (x86-64 without AVX2)");
    }
    ok
}

#[test]
fn packets_of_paths_render_the_reference_films_bit_for_bit() {
    if !lanes_run("packets_of_paths_render_the_reference_films_bit_for_bit") {
        return;
    }
    let features = features_scene("lanes");
    let asset = common::asset;
    let mut cases: Vec<(String, std::path::PathBuf, Settings, u32)> = vec![
        ("cornell tree sobol".into(), asset("cornell-box.gltf"), base(45, 37, 8), 4),
        (
            "cornell power independent".into(),
            asset("cornell-box.gltf"),
            Settings { sampler: SamplerKind::Independent, light_sampler: LightSampler::Power, ..base(40, 24, 8) },
            4,
        ),
        (
            "cornell unlimited depth, clamped".into(),
            asset("cornell-box.gltf"),
            Settings { clamp_direct: Some(2.0), clamp_indirect: Some(0.5), ..base(33, 17, 0) },
            3,
        ),
        (
            "glass with AOVs".into(),
            asset("cornell-glass.gltf"),
            Settings {
                aovs: vec![veach::aov::Aov::Albedo, veach::aov::Aov::Normal, veach::aov::Aov::Depth],
                ..base(41, 41, 8)
            },
            4,
        ),
        ("furnace".into(), asset("furnace-a080.gltf"), base(24, 24, 8), 4),
        // Rows narrower than a packet: a pixel's next sample waits for its last (a lane idles).
        ("cornell three pixels wide".into(), asset("cornell-box.gltf"), base(3, 16, 8), 6),
        (
            "cornell adaptive".into(),
            asset("cornell-box.gltf"),
            Settings { noise_threshold: Some(0.2), min_samples: Some(4), ..base(32, 32, 8) },
            20,
        ),
        (
            "cornell tile and lens".into(),
            asset("cornell-box.gltf"),
            Settings { tile: Some(Tile { x: 13, y: 7, width: 29, height: 21 }), aperture: 0.05, ..base(64, 48, 8) },
            3,
        ),
    ];
    for strategy in [Strategy::MisPower, Strategy::MisBalance, Strategy::Bsdf, Strategy::Light] {
        cases.push((
            format!("veach {strategy:?}"),
            asset("veach-mis.gltf"),
            Settings { strategy, ..base(44, 30, 2) },
            4,
        ));
    }
    for light_sampler in LightSampler::ALL {
        cases.push((
            format!("features {light_sampler:?}"),
            features.clone(),
            Settings { env_color: Some([0.2, 0.25, 0.3]), light_sampler, ..base(47, 35, 6) },
            4,
        ));
    }
    for (name, scene, settings, spp) in &cases {
        let lanes = film(scene, settings, *spp, Kernel::Lanes);
        let reference = film(scene, settings, *spp, Kernel::Reference);
        assert!(lanes.iter().any(|&w| w != 0), "{name}: the film is empty");
        let differing = lanes.iter().zip(&reference).filter(|(a, b)| a != b).count();
        assert_eq!(differing, 0, "{name}: {differing} film words differ between the kernels");
        assert_eq!(lanes.len(), reference.len(), "{name}: film sizes");
    }
}

/// The light tree's choice in lanes (`choose_child_lanes`, eight walks at once) is the scalar
/// `choose_child` lane by lane: same child, same rescaled number, bit for bit — over random
/// shares with empty, NaN and negative slots, shares that do not sum to 1, and numbers at 0
/// and just below 1.
#[test]
fn choosing_a_child_in_lanes_matches_the_scalar_choice() {
    if !lanes_run("choosing_a_child_in_lanes_matches_the_scalar_choice") {
        return;
    }
    use veach::cpu::lanes::lane::F8;
    use veach::cpu::lanes::light_tree::choose_child_lanes;
    use veach::cpu::light_tree::choose_child;
    let mut state = 0x9e37_79b9_7f4a_7c15u64;
    let mut next = || {
        state ^= state << 13;
        state ^= state >> 7;
        state ^= state << 17;
        (state >> 40) as f32 / (1u64 << 24) as f32
    };
    let mut kinds = [0usize; 4];
    for round in 0..50_000 {
        let mut shares = [[0.0f32; 8]; 4];
        let mut u = [0.0f32; 8];
        for j in 0..8 {
            let mut raw = [0.0f32; 4];
            for s in raw.iter_mut() {
                *s = match (next() * 10.0) as u32 {
                    0 | 1 => 0.0,
                    2 => f32::NAN,
                    3 => -next(),
                    _ => next(),
                };
            }
            let total: f32 = raw.iter().filter(|s| **s > 0.0).sum();
            // Mostly normalised shares, as the walk makes them; some not.
            let scale = if round % 7 == 0 || total <= 0.0 { 1.0 } else { 1.0 / total };
            for k in 0..4 {
                shares[k][j] = raw[k] * scale;
            }
            u[j] = match round % 11 {
                0 => 0.0,
                1 => 1.0 - f32::EPSILON / 2.0,
                _ => next(),
            };
        }
        let lanes = [F8(shares[0]), F8(shares[1]), F8(shares[2]), F8(shares[3])];
        let (slot, rescaled) = choose_child_lanes(&lanes, F8(u));
        for j in 0..8 {
            let one = [shares[0][j], shares[1][j], shares[2][j], shares[3][j]];
            let (k, r) = choose_child(one, u[j]);
            assert_eq!(slot[j], k, "shares {one:?}, u {}: child", u[j]);
            assert_eq!(rescaled.0[j].to_bits(), r.to_bits(), "shares {one:?}, u {}: rescaled number", u[j]);
            kinds[k] += 1;
        }
    }
    // Every child was chosen often (the test saw each branch of the choice).
    assert!(kinds.iter().all(|&n| n > 10_000), "children chosen {kinds:?}");
}

/// Every lane operation (AVX instructions on x86-64, loops elsewhere) is the scalar operation
/// lane by lane, bit for bit (any NaN for a NaN): arithmetic, square root, sign operations, the
/// comparisons (false with a NaN), selects, mask operations, integer steps, bit reversal and
/// the saturating `as i32` — over random bit patterns (NaNs, infinities, subnormals, both
/// zeros) and ordinary numbers.
#[test]
fn lane_operations_are_the_scalar_operations_bit_for_bit() {
    use veach::cpu::lanes::lane::{F8, M8, U8};
    if !lanes_run("lane_operations_are_the_scalar_operations_bit_for_bit") {
        return;
    }
    let mut state = 0x2545_f491_4f6c_dd1du64;
    let mut bits = || {
        state ^= state << 13;
        state ^= state >> 7;
        state ^= state << 17;
        state
    };
    let specials = [
        f32::NAN,
        f32::INFINITY,
        f32::NEG_INFINITY,
        0.0,
        -0.0,
        1.0,
        -1.0,
        2147483648.0,
        -2147483648.0,
        2147483520.0,
        -2147483904.0,
        1e-45,
        1.0 / 32.0,
    ];
    // The same bits, or both NaN (a NaN's payload is not specified by IEEE or Rust, and the
    // compiler may swap a product's operands).
    let same = |a: F8, b: [f32; 8], what: &str, x: [f32; 8], y: [f32; 8]| {
        for i in 0..8 {
            let (p, q) = (a.0[i], b[i]);
            assert!(p.to_bits() == q.to_bits() || p.is_nan() && q.is_nan(), "{what} of {} and {}: {p} {q}", x[i], y[i]);
        }
    };
    let mask = |m: M8, b: [bool; 8], what: &str, x: [f32; 8], y: [f32; 8]| {
        for i in 0..8 {
            assert_eq!(m.0[i], if b[i] { u32::MAX } else { 0 }, "{what} of {} and {}", x[i], y[i]);
        }
    };
    for _ in 0..100_000 {
        let mut value = || {
            let r = bits();
            match r % 4 {
                0 => specials[(r >> 8) as usize % specials.len()],
                1 => f32::from_bits((r >> 16) as u32),
                _ => ((r >> 40) as f32 / (1u64 << 24) as f32 - 0.5) * 600.0,
            }
        };
        let x: [f32; 8] = std::array::from_fn(|_| value());
        let y: [f32; 8] = std::array::from_fn(|_| value());
        let (a, b) = (F8(x), F8(y));
        let per = |f: &dyn Fn(f32, f32) -> f32| -> [f32; 8] { std::array::from_fn(|i| f(x[i], y[i])) };
        same(a + b, per(&|p, q| p + q), "+", x, y);
        same(a - b, per(&|p, q| p - q), "-", x, y);
        same(a * b, per(&|p, q| p * q), "*", x, y);
        same(a / b, per(&|p, q| p / q), "/", x, y);
        same(a * 3.5, per(&|p, _| p * 3.5), "* 3.5", x, y);
        same(0.25 - b, per(&|_, q| 0.25 - q), "0.25 -", x, y);
        same(a.sqrt(), per(&|p, _| p.sqrt()), "sqrt", x, y);
        same(a.abs(), per(&|p, _| p.abs()), "abs", x, y);
        same(-a, per(&|p, _| -p), "neg", x, y);
        let cmp = |f: &dyn Fn(f32, f32) -> bool| -> [bool; 8] { std::array::from_fn(|i| f(x[i], y[i])) };
        mask(a.lt(b), cmp(&|p, q| p < q), "<", x, y);
        mask(a.le(b), cmp(&|p, q| p <= q), "<=", x, y);
        mask(a.gt(b), cmp(&|p, q| p > q), ">", x, y);
        mask(a.ge(b), cmp(&|p, q| p >= q), ">=", x, y);
        mask(a.eq(b), cmp(&|p, q| p == q), "==", x, y);
        let (m, n) = (a.lt(b), a.eq(F8::splat(0.0)));
        let (mb, nb) = (cmp(&|p, q| p < q), cmp(&|p, _| p == 0.0));
        same(F8::select(m, a, b), per(&|p, q| if p < q { p } else { q }), "select", x, y);
        mask(m & n, std::array::from_fn(|i| mb[i] && nb[i]), "and", x, y);
        mask(m | n, std::array::from_fn(|i| mb[i] || nb[i]), "or", x, y);
        mask(!m, std::array::from_fn(|i| !mb[i]), "not", x, y);
        assert_eq!(m.bits(), (0..8).map(|i| u32::from(mb[i]) << i).sum::<u32>(), "bits of {x:?} < {y:?}");
        let (i, j) = (a.to_i32(), b.to_bits());
        for k in 0..8 {
            assert_eq!(i.0[k], x[k] as i32 as u32, "{} as i32", x[k]);
            assert_eq!(j.0[k], y[k].to_bits(), "to_bits of {}", y[k]);
        }
        assert_eq!(F8::from_bits(j).0.map(f32::to_bits), y.map(f32::to_bits), "from_bits");
        let (u, v) = (
            U8(std::array::from_fn(|_| bits() as u32)),
            U8(std::array::from_fn(|k| if k % 3 == 0 { i.0[k] } else { bits() as u32 })),
        );
        for (k, &less) in mb.iter().enumerate() {
            assert_eq!(u.reverse_bits().0[k], u.0[k].reverse_bits(), "reverse_bits of {}", u.0[k]);
            assert_eq!(u.wrapping_add(v).0[k], u.0[k].wrapping_add(v.0[k]), "wrapping_add");
            assert_eq!(u.wrapping_sub(v).0[k], u.0[k].wrapping_sub(v.0[k]), "wrapping_sub");
            assert_eq!(U8::select(m, u, v).0[k], if less { u.0[k] } else { v.0[k] }, "U8 select");
            assert_eq!(i.eq(v).0[k], if i.0[k] == v.0[k] { u32::MAX } else { 0 }, "U8 eq");
        }
    }
}
