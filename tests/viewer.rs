//! `veach view` as a user meets it: under Xvfb with lavapipe it opens the Cornell box, renders
//! some frames and saves a screenshot of the whole window, with the render (red wall left,
//! green wall right) beside the settings panel.

use std::process::Command;

mod common;

#[test]
#[cfg_attr(veach_no_gpu, ignore = "needs a GPU adapter (no Vulkan driver on this machine)")]
fn viewer_screenshot_shows_the_render_and_the_panel() {
    let has_xvfb = Command::new("sh").args(["-c", "command -v xvfb-run"]).output().is_ok_and(|o| o.status.success());
    let required = std::env::var("VEACH_REQUIRE_GPU").as_deref() == Ok("1");
    if !has_xvfb || common::gpu("viewer_screenshot").is_none() {
        assert!(!required, "VEACH_REQUIRE_GPU=1 but xvfb-run or the GPU is missing");
        eprintln!("skipping viewer_screenshot: needs xvfb-run (apt-get install xvfb xauth) and a Vulkan adapter");
        return;
    }
    // Auto picks the CPU engine on a software adapter (its film uploaded to the window); gpu
    // forces the kernel, its film displayed in place.
    for backend in ["auto", "gpu"] {
        screenshot_shows_the_render_and_the_panel(backend);
    }
    // The samples heat map replaces the image: no wall colours are left.
    let img = screenshot("auto", &["--heat-map"]);
    let green = img.pixels().filter(|p| p.0[1] > 40 && p.0[1] as u32 > 2 * p.0[0] as u32 + 2 * p.0[2] as u32).count();
    assert!(green < 50, "{green} green-wall pixels in the heat map");
    // The denoiser: the same frames, the image far smoother (the screenshot waits for its
    // first result), the walls still where they were.
    let noisy = screenshot("auto", &[]);
    let clean = screenshot("auto", &["--denoise"]);
    let (a, b) = (roughness(&noisy), roughness(&clean));
    assert!(b < 0.6 * a, "denoised roughness {b:.2} vs noisy {a:.2}");
    screenshot_shows_the_render_and_the_panel_in(&clean, "auto --denoise");
}

/// Mean absolute difference of horizontally adjacent pixels in the image area (right of the
/// panel): noise raises it; edges count alike with and without denoising.
fn roughness(img: &image::RgbImage) -> f64 {
    let (w, h) = img.dimensions();
    let mut sum = 0u64;
    let mut n = 0u64;
    for y in h / 8..h - h / 8 {
        for x in 320..w - 20 {
            let (p, q) = (img.get_pixel(x, y).0, img.get_pixel(x + 1, y).0);
            sum += (0..3).map(|c| (p[c] as i32 - q[c] as i32).unsigned_abs() as u64).sum::<u64>();
            n += 1;
        }
    }
    sum as f64 / n as f64
}

fn screenshot(backend: &str, extra: &[&str]) -> image::RgbImage {
    let out = std::env::temp_dir().join(format!("veach-view-{}-{backend}-{}.png", std::process::id(), extra.len()));
    let scene = common::asset("cornell-box.gltf");
    let status = Command::new("xvfb-run")
        .args(["-a", "-s", "-screen 0 1024x768x24", env!("CARGO_BIN_EXE_veach"), "view"])
        .arg(&scene)
        .args(["--screenshot", out.to_str().unwrap(), "--frames", "8", "--window", "640x400", "--render-scale", "0.4"])
        .args(["--backend", backend])
        .args(extra)
        .env_remove("WAYLAND_DISPLAY")
        .output()
        .expect("run xvfb-run");
    assert!(status.status.success(), "{}", String::from_utf8_lossy(&status.stderr));
    let img = image::open(&out).expect("a screenshot").to_rgb8();
    let _ = std::fs::remove_file(&out);
    img
}

fn screenshot_shows_the_render_and_the_panel(backend: &str) {
    screenshot_shows_the_render_and_the_panel_in(&screenshot(backend, &[]), backend);
}

fn screenshot_shows_the_render_and_the_panel_in(img: &image::RgbImage, backend: &str) {
    assert!(img.width() >= 600 && img.height() >= 380, "{}x{}", img.width(), img.height());
    // Red-wall and green-wall pixels in the image area (right of the panel), red left of green.
    let (mut red, mut green) = (Vec::new(), Vec::new());
    for (x, _, p) in img.enumerate_pixels() {
        let [r, g, b] = p.0.map(|c| c as i32);
        if r > 60 && r > 2 * g && r > 2 * b {
            red.push(x);
        }
        if g > 40 && g > 2 * r && g > 2 * b {
            green.push(x);
        }
    }
    assert!(
        red.len() > 500 && green.len() > 500,
        "{backend}: walls visible: {} red, {} green pixels",
        red.len(),
        green.len()
    );
    let mean = |v: &[u32]| v.iter().map(|&x| x as f64).sum::<f64>() / v.len() as f64;
    assert!(mean(&red) < mean(&green), "red wall on the left");
    assert!(mean(&red) > 250.0, "the render sits right of the side panel");
    // The side panel: light text on a dark background in the left strip.
    let text =
        (0..200).flat_map(|x| (0..200).map(move |y| (x, y))).filter(|&(x, y)| img.get_pixel(x, y).0[0] > 150).count();
    assert!(text > 200, "the side panel shows text ({text} light pixels)");
}

/// The viewer accumulates a sample in bands of rows (to keep frames short); the film it builds
/// is bit for bit the film `veach render` builds from whole-image dispatches.
fn bands_build_the_same_film(ctx: Option<veach::gpu::GpuContext>) {
    let (scene, camera) = common::load_pair(&common::asset("cornell-box.gltf"), None).unwrap();
    // Uniform (3 samples), and adaptive (32 samples: the last band of a sample settles the
    // tests at 16, 24 and 32).
    let cases = [(ctx.clone(), None, 3), (ctx, Some(0.2), 32)];
    for (ctx, noise_threshold, spp) in cases {
        let backend = if ctx.is_some() { veach::Backend::Gpu } else { veach::Backend::Cpu };
        let s = veach::Settings { width: 40, height: 28, noise_threshold, ..common::settings(40, 8, 3) };
        let packed = veach::packed::PackedScene::new(&scene);
        let mut whole = veach::Renderer::new(packed.clone(), &camera, &s, veach::Backend::Cpu).unwrap();
        if backend == veach::Backend::Gpu {
            whole = common::renderer(packed.clone(), &camera, &s, common::gpu("bands")).unwrap();
        }
        whole.render_samples(0, spp).unwrap();
        let mut bands = common::renderer(packed, &camera, &s, ctx).unwrap();
        for sample in 0..spp {
            for (y0, rows) in [(0, 8), (8, 16), (24, 8)] {
                bands.render_rows(sample, y0, rows).unwrap();
            }
        }
        let film = whole.film().unwrap();
        assert!(noise_threshold.is_none() || film.converged_fraction().is_some_and(|c| c > 0.0 && c < 1.0));
        assert!(film == bands.film().unwrap(), "{backend:?}, {noise_threshold:?}: bands = whole samples");
    }
}

#[test]
fn viewer_bands_build_the_same_film_as_render() {
    bands_build_the_same_film(None);
}

#[test]
#[cfg_attr(veach_no_gpu, ignore = "needs a GPU adapter (no Vulkan driver on this machine)")]
fn viewer_bands_build_the_same_film_as_render_on_the_gpu() {
    let Some(ctx) = common::gpu("viewer_bands_build_the_same_film_as_render_on_the_gpu") else { return };
    bands_build_the_same_film(Some(ctx));
}
