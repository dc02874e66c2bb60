//! The command line as a user meets it: bad input gets one line and exit code 2, and never
//! leaves a partial output file.

use std::path::PathBuf;
use std::process::{Command, Output};

mod common;

fn veach(args: &[&str], envs: &[(&str, &str)]) -> Output {
    let mut cmd = Command::new(env!("CARGO_BIN_EXE_veach"));
    cmd.args(args);
    for (k, v) in envs {
        cmd.env(k, v);
    }
    cmd.output().expect("run veach")
}

fn temp_dir(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("veach-cli-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).expect("temp dir");
    d
}

/// `veach render SCENE -o OUT --width N --height N --spp SPP`, to extend with more flags.
fn render_args<'a>(scene: &'a std::path::Path, out: &'a std::path::Path, side: &'a str, spp: &'a str) -> Vec<&'a str> {
    let path = |p: &'a std::path::Path| p.to_str().expect("utf-8 path");
    vec!["render", path(scene), "-o", path(out), "--width", side, "--height", side, "--spp", spp]
}

fn assert_user_error(out: &Output, needle: &str) {
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "stderr: {stderr}");
    assert!(stderr.contains(needle), "expected '{needle}' in: {stderr}");
    let lines: Vec<&str> = stderr.lines().filter(|l| !l.contains("XDG_RUNTIME_DIR")).collect();
    assert_eq!(lines.len(), 1, "one line expected: {stderr}");
    assert!(!stderr.contains("panicked"), "{stderr}");
}

#[test]
fn bad_inputs_exit_2_with_one_line_and_no_output() {
    let d = temp_dir("bad");
    let out_png = d.join("out.png");
    let out = out_png.to_str().expect("utf8");
    let cbox = common::asset("cornell-box.gltf");
    let cbox = cbox.to_str().expect("utf8");

    let missing = d.join("missing.gltf");
    assert_user_error(&veach(&["render", missing.to_str().unwrap(), "-o", out], &[]), "missing.gltf");

    let broken = d.join("broken.gltf");
    std::fs::write(&broken, b"{ \"asset\": { \"version\": ").unwrap();
    assert_user_error(&veach(&["render", broken.to_str().unwrap(), "-o", out], &[]), "broken.gltf");

    let glb = d.join("truncated.glb");
    std::fs::write(&glb, b"glTF\x02\x00\x00\x00\xff\xff").unwrap();
    assert_user_error(&veach(&["render", glb.to_str().unwrap(), "-o", out], &[]), "truncated.glb");

    assert_user_error(&veach(&["render", cbox, "-o", d.join("out.jpg").to_str().unwrap()], &[]), "out.jpg");
    assert_user_error(&veach(&["render", cbox, "-o", d.join("no/such/dir/out.png").to_str().unwrap()], &[]), "out.png");
    assert_user_error(&veach(&["render", cbox, "-o", out, "--camera", "nope"], &[]), "nope");
    // Flags clap refuses are one line too, naming the flag.
    assert_user_error(&veach(&["render", cbox, "-o", out, "--spp", "many"], &[]), "--spp");
    assert_user_error(&veach(&["render", cbox], &[]), "--output");
    assert_user_error(&veach(&["render", cbox, "-o", out, "--no-such-flag"], &[]), "--no-such-flag");

    // Leftover files only: the failed runs wrote nothing (broken inputs are ours).
    let mut left: Vec<String> =
        std::fs::read_dir(&d).unwrap().map(|e| e.unwrap().file_name().to_string_lossy().into_owned()).collect();
    left.sort();
    assert_eq!(left, ["broken.gltf", "truncated.glb"]);
    let _ = std::fs::remove_dir_all(&d);
}

#[test]
fn renders_png_and_exr_with_stats() {
    let d = temp_dir("ok");
    let cbox = common::asset("cornell-box.gltf");
    for name in ["a.png", "a.exr"] {
        let out = d.join(name);
        let stats = d.join("stats.json");
        let r = veach(
            &[
                "render",
                cbox.to_str().unwrap(),
                "-o",
                out.to_str().unwrap(),
                "--width",
                "24",
                "--height",
                "16",
                "--spp",
                "2",
                "--backend",
                "cpu",
                "--stats-json",
                stats.to_str().unwrap(),
            ],
            &[],
        );
        assert!(r.status.success(), "{}", String::from_utf8_lossy(&r.stderr));
        let img = image::open(&out).expect("readable image");
        assert_eq!((img.width(), img.height()), (24, 16));
        let s: serde_json::Value = serde_json::from_slice(&std::fs::read(&stats).unwrap()).unwrap();
        for key in [
            "scene",
            "width",
            "height",
            "spp",
            "max_depth",
            "seed",
            "adapter",
            "backend",
            "backend_reason",
            "seconds_total",
            "seconds_render",
            "samples_per_second",
            "triangles",
            "bvh_nodes",
            "bvh_build_seconds",
        ] {
            assert!(s.get(key).is_some(), "stats lack {key}: {s}");
        }
        assert_eq!(s["triangles"], 32);
        assert_eq!(s["environment"], "scene", "the Cornell box has a lamp: no default studio");
        assert_eq!(s["backend"], "cpu");
    }
    let _ = std::fs::remove_dir_all(&d);
}

#[test]
fn environment_maps_from_hdr_and_exr() {
    let d = temp_dir("env");
    let scene = common::asset("furnace-a080.gltf");
    let mut sky = image::Rgb32FImage::new(32, 16);
    for (x, y, p) in sky.enumerate_pixels_mut() {
        *p = image::Rgb([1.0 + x as f32 / 32.0, 0.5, 2.0 * (y < 8) as u8 as f32]);
    }
    for name in ["sky.hdr", "sky.exr"] {
        let env = d.join(name);
        sky.save(&env).expect("write map");
        let out = d.join("a.exr");
        let r = veach(
            &[
                "render",
                scene.to_str().unwrap(),
                "-o",
                out.to_str().unwrap(),
                "--env",
                env.to_str().unwrap(),
                "--env-strength",
                "2",
                "--width",
                "16",
                "--height",
                "16",
                "--spp",
                "4",
                "--backend",
                "cpu",
            ],
            &[],
        );
        assert!(r.status.success(), "{name}: {}", String::from_utf8_lossy(&r.stderr));
        let img = image::open(&out).expect("exr").to_rgb32f();
        // The corner pixel sees the map directly: 2 × a texel, whose green is 0.5.
        assert!((img.get_pixel(0, 0)[1] - 1.0).abs() < 1e-4, "{name}: {:?}", img.get_pixel(0, 0));
    }
    let bad = d.join("sky.txt");
    std::fs::write(&bad, b"not an image").unwrap();
    let out = d.join("b.png");
    assert_user_error(
        &veach(&["render", scene.to_str().unwrap(), "-o", out.to_str().unwrap(), "--env", bad.to_str().unwrap()], &[]),
        "sky.txt",
    );
    assert!(!out.exists());
    let _ = std::fs::remove_dir_all(&d);
}

#[test]
fn info_describes_a_scene() {
    let scene = common::asset("cornell-box.gltf");
    let r = veach(&["info", scene.to_str().unwrap()], &[]);
    let out = String::from_utf8_lossy(&r.stdout);
    assert!(r.status.success(), "{}", String::from_utf8_lossy(&r.stderr));
    for needle in [
        "triangles 32 (32 stored, 2 emissive)",
        "meshes 8",
        "instances (nodes with a mesh) 8",
        "materials 4",
        "cameras 1",
        "KHR_materials_emissive_strength",
        "bounds",
    ] {
        assert!(out.contains(needle), "'{needle}' missing in:\n{out}");
    }
}

#[test]
fn strategies_sheet_has_four_labelled_panels() {
    let d = temp_dir("sheet");
    let out = d.join("sheet.png");
    let scene = common::asset("veach-mis.gltf");
    let r = veach(
        &[
            "strategies",
            scene.to_str().unwrap(),
            "-o",
            out.to_str().unwrap(),
            "--spp",
            "2",
            "--width",
            "32",
            "--height",
            "24",
            "--backend",
            "cpu",
        ],
        &[],
    );
    assert!(r.status.success(), "{}", String::from_utf8_lossy(&r.stderr));
    let img = image::open(&out).expect("sheet").to_rgb8();
    assert_eq!(img.width(), 4 * 32);
    assert!(img.height() > 24, "a label bar above the panels");
    // Each panel's label is drawn in white in the bar.
    for k in 0..4 {
        let white =
            (0..img.height() - 24).any(|y| (k * 32..k * 32 + 32).any(|x| img.get_pixel(x, y).0 == [255, 255, 255]));
        assert!(white, "panel {k} has a label");
    }
    let _ = std::fs::remove_dir_all(&d);
}

#[test]
fn without_a_vulkan_driver_renders_on_the_cpu_or_says_how_to_get_one() {
    let d = temp_dir("nogpu");
    let cbox = common::asset("cornell-box.gltf");
    let out = d.join("a.png");
    let no_driver = [("VK_DRIVER_FILES", "/nonexistent.json"), ("VK_ICD_FILENAMES", "/nonexistent.json")];
    let args =
        ["render", cbox.to_str().unwrap(), "-o", out.to_str().unwrap(), "--width", "8", "--height", "8", "--spp", "1"];
    let r = veach(&args, &no_driver);
    let stderr = String::from_utf8_lossy(&r.stderr);
    assert!(r.status.success(), "{stderr}");
    // The default engine is the faster one: no driver is no reason to suggest installing one.
    assert!(stderr.contains("CPU backend") && stderr.contains("no GPU adapter"), "{stderr}");
    assert!(!stderr.contains("apt-get"), "{stderr}");
    assert!(out.exists());

    let mut explicit = args.to_vec();
    explicit.extend(["--backend", "gpu"]);
    assert_user_error(&veach(&explicit, &no_driver), "apt-get install mesa-vulkan-drivers");
    let _ = std::fs::remove_dir_all(&d);
}

/// `--backend auto` (the default) runs the GPU engine on a hardware adapter and the CPU
/// engine on a software one (lavapipe here) or with none, says why in `--stats-json`, and
/// says so in one line when it picks the CPU; `--backend gpu` still runs the kernel.
#[test]
fn the_default_backend_is_the_faster_engine() {
    let d = temp_dir("auto");
    let cbox = common::asset("cornell-box.gltf");
    let stats = d.join("stats.json");
    let run = |extra: &[&str]| {
        let out = d.join("a.png");
        let mut args = render_args(&cbox, &out, "8", "1");
        args.extend(["--stats-json", stats.to_str().unwrap()]);
        args.extend(extra);
        let r = veach(&args, &[]);
        let stderr = String::from_utf8_lossy(&r.stderr).to_string();
        assert!(r.status.success(), "{stderr}");
        let s: serde_json::Value = serde_json::from_slice(&std::fs::read(&stats).unwrap()).unwrap();
        (s, stderr)
    };
    let (s, stderr) = run(&[]);
    let reason = s["backend_reason"].as_str().unwrap_or_default().to_string();
    assert_eq!(run(&["--backend", "auto"]).0["backend"], s["backend"], "auto is the default");
    match veach::gpu::adapter_info() {
        Ok(info) if info.device_type == wgpu::DeviceType::Cpu => {
            assert_eq!(s["backend"], "cpu", "{reason}");
            assert!(reason.contains("software") && reason.contains(&info.name), "{reason}");
            assert!(stderr.contains("rendering on the CPU backend") && stderr.contains("--backend gpu"), "{stderr}");
            let (forced, _) = run(&["--backend", "gpu"]);
            assert_eq!(
                (forced["backend"].as_str(), forced["backend_reason"].as_str()),
                (Some("gpu"), Some("requested"))
            );
        }
        Ok(info) => {
            assert_eq!(s["backend"], "gpu", "{reason}");
            assert!(reason.contains(&info.name), "{reason}");
        }
        Err(_) => {
            assert_eq!(s["backend"], "cpu");
            assert!(reason.contains("no GPU adapter"), "{reason}");
        }
    }
    let _ = std::fs::remove_dir_all(&d);
}

/// `--time` renders until the budget is spent: fewer samples than the `--spp` cap, a valid
/// image that says how many it reached, exit 0; resuming it under a new budget goes on.
#[test]
fn a_time_budget_stops_early_with_a_valid_image_that_resumes() {
    let d = temp_dir("time");
    let cbox = common::asset("cornell-box.gltf");
    let (exr, resumed, stats) = (d.join("a.exr"), d.join("b.exr"), d.join("stats.json"));
    let cap = 1_000_000u32;
    let cap_s = cap.to_string();
    let run = |args: &[&str]| {
        let r = veach(args, &[]);
        let stderr = String::from_utf8_lossy(&r.stderr).to_string();
        assert_eq!(r.status.code(), Some(0), "{stderr}");
        let s: serde_json::Value = serde_json::from_slice(&std::fs::read(&stats).unwrap()).unwrap();
        (s, stderr)
    };
    let mut args = render_args(&cbox, &exr, "16", &cap_s);
    args.extend(["--time", "0.5", "--backend", "cpu", "--stats-json", stats.to_str().unwrap()]);
    let (s, stderr) = run(&args);
    let spp = s["spp"].as_u64().unwrap() as u32;
    assert!(spp >= 1 && spp < cap, "{s}");
    assert_eq!((s["stopped_by"].as_str(), s["interrupted"].as_bool()), (Some("time"), Some(false)), "{s}");
    assert_eq!(s["spp_target"], cap);
    assert!(stderr.contains(&format!("{spp} spp (the time budget")), "{stderr}");
    let (film, job) = veach::output::read_film(&exr).expect("a valid EXR");
    assert_eq!((film.samples(), job.spp()), (spp, cap));
    assert!(film.to_rgb32f().iter().all(|v| v.is_finite() && *v >= 0.0));
    assert!(film.to_rgb32f().iter().any(|v| *v > 0.0), "the image is lit");

    let (s, _) = run(&[
        "render",
        "--resume",
        exr.to_str().unwrap(),
        "-o",
        resumed.to_str().unwrap(),
        "--time",
        "0.3",
        "--backend",
        "cpu",
        "--stats-json",
        stats.to_str().unwrap(),
    ]);
    let (film, _) = veach::output::read_film(&resumed).expect("a valid EXR");
    assert!(film.samples() > spp && film.samples() < cap, "{} after {spp}", film.samples());
    assert_eq!(s["spp"], film.samples());
    let _ = std::fs::remove_dir_all(&d);
}

/// Firefly clamping is biased on purpose: the EXR's job (what resume and merge read) and
/// --stats-json say so, and a limit that is not a positive number is refused in one line.
#[test]
fn clamping_is_recorded_in_the_exr_and_the_stats() {
    let d = temp_dir("clamp");
    let cbox = common::asset("cornell-box.gltf");
    let (exr, stats) = (d.join("a.exr"), d.join("stats.json"));
    let mut args = render_args(&cbox, &exr, "8", "2");
    args.extend(["--backend", "cpu", "--stats-json", stats.to_str().unwrap()]);
    for bad in ["0", "-1", "inf", "x"] {
        let mut a = args.clone();
        a.extend(["--clamp-direct", bad]);
        assert_user_error(&veach(&a, &[]), "--clamp-direct");
    }
    args.extend(["--clamp-direct", "4", "--clamp-indirect", "1.5"]);
    let r = veach(&args, &[]);
    assert!(r.status.success(), "{}", String::from_utf8_lossy(&r.stderr));
    let s: serde_json::Value = serde_json::from_slice(&std::fs::read(&stats).unwrap()).unwrap();
    assert_eq!(
        (s["biased"].as_bool(), s["clamp_direct"].as_f64(), s["clamp_indirect"].as_f64()),
        (Some(true), Some(4.0), Some(1.5))
    );
    let (_, job) = veach::output::read_film(&exr).expect("a veach EXR");
    assert_eq!((job.settings.clamp_direct, job.settings.clamp_indirect), (Some(4.0), Some(1.5)));
    let _ = std::fs::remove_dir_all(&d);
}

#[test]
fn reference_records_convergence_and_plots_it() {
    let d = temp_dir("convergence");
    let cbox = common::asset("cornell-box.gltf");
    // Mitsuba's Cornell box at depth 8 (tests/data), the render at the same size.
    let reference = common::root().join("tests/data/cbox_d8_64.exr");
    let mut stats = Vec::new();
    for strategy in ["mis-power", "bsdf"] {
        let json = d.join(format!("{strategy}.json"));
        let out = veach(
            &[
                "render",
                cbox.to_str().unwrap(),
                "--backend",
                "cpu",
                "--width",
                "64",
                "--height",
                "64",
                "--spp",
                "32",
                "--strategy",
                strategy,
                "--reference",
                reference.to_str().unwrap(),
                "--stats-json",
                json.to_str().unwrap(),
                "-o",
                d.join(format!("{strategy}.exr")).to_str().unwrap(),
            ],
            &[],
        );
        assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
        let v: serde_json::Value = serde_json::from_slice(&std::fs::read(&json).unwrap()).unwrap();
        let series = v["convergence"].as_array().expect("convergence series");
        let spp: Vec<u64> = series.iter().map(|p| p["spp"].as_u64().unwrap()).collect();
        assert_eq!(spp, [1, 2, 4, 8, 16, 32]);
        let rmse: Vec<f64> = series.iter().map(|p| p["rmse"].as_f64().unwrap()).collect();
        let seconds: Vec<f64> = series.iter().map(|p| p["seconds"].as_f64().unwrap()).collect();
        assert!(seconds.windows(2).all(|w| w[1] >= w[0]), "{seconds:?}");
        // Noise dominates: 32× the samples must cut the error by well over half (1/√32 ≈ 0.18).
        assert!(rmse[5] < 0.6 * rmse[0], "{strategy}: {rmse:?}");
        stats.push(json);
    }
    // MIS beats BSDF sampling on the same samples.
    let last = |p: &PathBuf| {
        let v: serde_json::Value = serde_json::from_slice(&std::fs::read(p).unwrap()).unwrap();
        v["convergence"].as_array().unwrap().last().unwrap()["rmse"].as_f64().unwrap()
    };
    assert!(last(&stats[0]) < last(&stats[1]), "MIS {} vs BSDF {}", last(&stats[0]), last(&stats[1]));

    let plot = d.join("plot.png");
    let args: Vec<&str> = ["plot-convergence", stats[0].to_str().unwrap(), stats[1].to_str().unwrap(), "-o"]
        .into_iter()
        .chain([plot.to_str().unwrap()])
        .collect();
    let out = veach(&args, &[]);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let img = image::open(&plot).unwrap().to_rgb8();
    assert_eq!(img.dimensions(), (900, 560));
    // Both series are drawn in their colours.
    for colour in [[31u8, 119, 180], [214, 39, 40]] {
        assert!(img.pixels().filter(|p| p.0 == colour).count() > 200, "series {colour:?} missing");
    }

    // A stats file without a series, and a reference of the wrong size: one line, exit 2.
    let bare = d.join("bare.json");
    std::fs::write(&bare, b"{}").unwrap();
    assert_user_error(
        &veach(&["plot-convergence", bare.to_str().unwrap(), "-o", plot.to_str().unwrap()], &[]),
        "bare.json",
    );
    let out = veach(
        &[
            "render",
            cbox.to_str().unwrap(),
            "--backend",
            "cpu",
            "--width",
            "32",
            "--height",
            "32",
            "--spp",
            "1",
            "--reference",
            reference.to_str().unwrap(),
            "-o",
            d.join("x.png").to_str().unwrap(),
        ],
        &[],
    );
    assert_user_error(&out, "cbox_d8_64.exr");
    let _ = std::fs::remove_dir_all(&d);
}

/// A smoke test of the benchmark's report (its numbers are timings and are not judged here),
/// on the CPU and, `with_gpu`, on the GPU too.
fn bench_report(with_gpu: bool) {
    let d = temp_dir(if with_gpu { "bench-gpu" } else { "bench" });
    let json = d.join("bench.json");
    let mut args = vec![
        "bench",
        "--width",
        "16",
        "--height",
        "16",
        "--spp",
        "1",
        "--large-grid",
        "1",
        "--tree-emitters",
        "5000",
        "--backend",
        "cpu",
    ];
    if with_gpu {
        args.extend(["--backend", "gpu"]);
    }
    args.extend(["--json", json.to_str().expect("utf8")]);
    let out = veach(&args, &[]);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let report: serde_json::Value = serde_json::from_slice(&std::fs::read(&json).expect("json")).expect("valid json");
    let scenes = report["scenes"].as_array().expect("scenes");
    assert_eq!(scenes.len(), 4);
    let tree = &report["light_tree_scale"];
    assert_eq!(tree["emitters"], 5000);
    // The 4-wide tree: the root, then groups of four records; one emitter per leaf, and at
    // most every node of the binary tree (2n − 1) in each group's slots.
    let nodes = tree["nodes"].as_u64().expect("nodes");
    assert_eq!((nodes - 1) % 4, 0, "root + groups of four: {tree}");
    assert!(nodes > 5000 && nodes <= 4 * 9999, "{tree}");
    // The binary tree's 13 ..= 32 levels, halved.
    assert!(tree["depth"].as_u64().is_some_and(|d| (7..=16).contains(&d)), "{tree}");
    for sc in scenes {
        // Each backend with each light sampler.
        assert_eq!(sc["renders"].as_array().expect("renders").len(), if with_gpu { 6 } else { 3 });
        assert!(sc["light_tree_emitters"].as_u64().is_some_and(|n| n > 0), "{sc}");
        let kinds = |key: &str| -> Vec<(String, f64)> {
            sc[key]
                .as_array()
                .expect("rays")
                .iter()
                .map(|r| (r["kind"].as_str().unwrap_or("").to_string(), r["rays"].as_f64().unwrap_or(0.0)))
                .collect()
        };
        let cpu = kinds("rays");
        assert_eq!(cpu.iter().map(|k| k.0.as_str()).collect::<Vec<_>>(), ["primary", "shadow", "diffuse"]);
        if with_gpu {
            let gpu = kinds("gpu_rays");
            assert_eq!(gpu.len(), 3, "{sc}");
            // 16 passes of sample 0's 16×16 primary rays: the CPU's rays, 16 times (the twins'
            // traversal may disagree on a ray grazing an edge).
            assert_eq!(gpu[0].1, 16.0 * 256.0);
            for k in 1..3 {
                let (g, c) = (gpu[k].1, 16.0 * cpu[k].1);
                assert!(g > 0.0 && (g - c).abs() <= 0.01 * c + 16.0, "{} rays: GPU {g}, CPU × 16 {c}", gpu[k].0);
            }
        }
    }
}

#[test]
fn bench_reports_renders_and_ray_rates_per_backend() {
    bench_report(false);
}

#[test]
#[cfg_attr(veach_no_gpu, ignore = "needs a GPU adapter (no Vulkan driver on this machine)")]
fn bench_reports_renders_and_ray_rates_per_backend_on_the_gpu() {
    if common::gpu("bench_reports_renders_and_ray_rates_per_backend_on_the_gpu").is_none() {
        return;
    }
    bench_report(true);
}

/// `--noise-threshold`: the stats report the mean spp and the converged fraction, the EXR a
/// `samples` layer; a render stopped by its time budget resumes to the very bytes of an
/// uninterrupted one; every pixel converged ends the render early; adaptive parts do not merge.
#[test]
fn adaptive_renders_report_their_samples_resume_exactly_and_refuse_to_merge() {
    let d = temp_dir("adaptive");
    let glass = common::asset("cornell-glass.gltf");
    let (whole, part, resumed, stats) =
        (d.join("whole.exr"), d.join("part.exr"), d.join("resumed.exr"), d.join("s.json"));
    let stats_s = stats.to_str().unwrap();
    let read_stats = || -> serde_json::Value { serde_json::from_slice(&std::fs::read(&stats).unwrap()).unwrap() };
    let adaptive = ["--noise-threshold", "0.1", "--backend", "cpu", "--stats-json", stats_s];

    let mut args = render_args(&glass, &whole, "48", "256");
    args.extend(adaptive);
    common::cli::ok(veach(&args, &[]));
    let s = read_stats();
    let (mean, converged) = (s["mean_spp"].as_f64().unwrap(), s["converged_fraction"].as_f64().unwrap());
    assert!(mean < 200.0 && (0.1..0.99).contains(&converged), "{s}");
    assert_eq!((s["spp"].as_u64(), s["stopped_by"].as_str()), (Some(256), Some("samples")), "{s}");
    let (film, job) = veach::output::read_film(&whole).expect("a valid EXR");
    assert_eq!(job.settings.noise_threshold, Some(0.1));
    assert!((film.mean_spp() - mean).abs() < 1e-9);
    let image = exr::prelude::read_all_flat_layers_from_file(&whole).expect("exr");
    let samples = image.layer_data[0].channel_data.list.iter().find(|c| c.name.to_string() == "samples.Y");
    let samples = samples.expect("a samples layer").sample_data.values_as_f32().collect::<Vec<f32>>();
    assert_eq!(samples, (0..film.pixel_count()).map(|i| film.taken(i) as f32).collect::<Vec<_>>());

    // Stopped early by time, then resumed: the same bytes as the uninterrupted render.
    let mut args = render_args(&glass, &part, "48", "256");
    args.extend(adaptive);
    args.extend(["--time", "0.15"]);
    common::cli::ok(veach(&args, &[]));
    assert_eq!(read_stats()["stopped_by"].as_str(), Some("time"), "the budget must stop this render early");
    common::cli::ok(veach(
        &["render", "--resume", part.to_str().unwrap(), "-o", resumed.to_str().unwrap(), "--backend", "cpu"],
        &[],
    ));
    assert!(std::fs::read(&whole).unwrap() == std::fs::read(&resumed).unwrap(), "the resumed render differs");

    // A threshold every pixel meets: all stop at the first test, and the render ends there.
    let mut args = render_args(&glass, &part, "16", "1000");
    args.extend(["--noise-threshold", "1000", "--min-samples", "24", "--backend", "cpu", "--stats-json", stats_s]);
    common::cli::ok(veach(&args, &[]));
    let s = read_stats();
    assert_eq!(
        (s["spp"].as_u64(), s["stopped_by"].as_str(), s["mean_spp"].as_f64()),
        (Some(24), Some("converged"), Some(24.0)),
        "{s}"
    );

    let merged = d.join("merged.exr");
    assert_user_error(
        &veach(&["merge", whole.to_str().unwrap(), resumed.to_str().unwrap(), "-o", merged.to_str().unwrap()], &[]),
        "adaptive",
    );
    assert!(!merged.exists());
    let out = d.join("x.png");
    let mut args = render_args(&glass, &out, "16", "4");
    args.extend(["--noise-threshold", "-1"]);
    assert_user_error(&veach(&args, &[]), "noise-threshold");
    let mut args = render_args(&glass, &out, "16", "4");
    args.extend(["--min-samples", "8"]);
    assert_user_error(&veach(&args, &[]), "noise-threshold");
}

/// `--stats-json` and `veach info` report the texture atlas: the box's 211² logo is kept at
/// its size on one 256² page.
#[test]
fn texture_memory_is_reported() {
    let d = temp_dir("texture-stats");
    let scene = common::root().join("tests/data/web/box-textured.webp.glb");
    let (out, stats) = (d.join("box.png"), d.join("stats.json"));
    let (out_s, stats_s) = (out.to_str().unwrap(), stats.to_str().unwrap());
    let args = ["render", scene.to_str().unwrap(), "-o", out_s, "--width", "16", "--height", "16", "--spp", "1"];
    let r = veach(&[&args[..], &["--backend", "cpu", "--stats-json", stats_s]].concat(), &[]);
    assert!(r.status.success(), "{}", String::from_utf8_lossy(&r.stderr));
    let s: serde_json::Value = serde_json::from_slice(&std::fs::read(&stats).unwrap()).unwrap();
    assert_eq!((s["texture_pages"].as_u64(), s["texture_page_side"].as_u64()), (Some(1), Some(256)), "{s}");
    assert_eq!(s["texture_bytes"].as_u64(), Some(256 * 256 * 4));
    assert_eq!(s["textures_shrunk"].as_u64(), Some(0));
    let occupancy = s["texture_occupancy"].as_f64().unwrap();
    assert!((occupancy - 211.0 * 211.0 / 65536.0).abs() < 1e-9, "{occupancy}");
    let info = veach(&["info", scene.to_str().unwrap()], &[]);
    let text = String::from_utf8_lossy(&info.stdout);
    assert!(text.contains("texture atlas: 1 page(s) of 256²"), "{text}");
    let _ = std::fs::remove_dir_all(&d);
}

/// `--light-sampler ris` is part of the render: `--stats-json` shows it, the EXR keeps it (a
/// resumed render goes on with it), and merge refuses a part rendered with the tree.
#[test]
fn the_resampling_light_sampler_is_saved_resumed_and_checked_by_merge() {
    let d = temp_dir("ris");
    let veach_scene = common::asset("veach-mis.gltf");
    let (a, b, resumed, stats) = (d.join("a.exr"), d.join("b.exr"), d.join("r.exr"), d.join("stats.json"));
    let stats_s = stats.to_str().unwrap();
    // A time-budgeted render (stopped early), then resumed for more samples.
    let mut args = render_args(&veach_scene, &resumed, "16", "1000000");
    args.extend(["--light-sampler", "ris", "--time", "0.3", "--backend", "cpu", "--stats-json", stats_s]);
    let r = veach(&args, &[]);
    assert_eq!(r.status.code(), Some(0), "{}", String::from_utf8_lossy(&r.stderr));
    let s: serde_json::Value = serde_json::from_slice(&std::fs::read(&stats).unwrap()).unwrap();
    assert_eq!(s["light_sampler"], "ris", "{s}");
    let (film, job) = veach::output::read_film(&resumed).expect("a valid EXR");
    assert_eq!(job.settings.light_sampler, veach::LightSampler::Ris);
    let before = film.samples();
    let r = veach(
        &[
            "render",
            "--resume",
            resumed.to_str().unwrap(),
            "-o",
            resumed.to_str().unwrap(),
            "--time",
            "0.2",
            "--backend",
            "cpu",
        ],
        &[],
    );
    assert_eq!(r.status.code(), Some(0), "{}", String::from_utf8_lossy(&r.stderr));
    let (film, job) = veach::output::read_film(&resumed).expect("a valid EXR");
    assert!(film.samples() > before, "{} after {before}", film.samples());
    assert_eq!(job.settings.light_sampler, veach::LightSampler::Ris);

    // Parts of one render must agree on the light sampler.
    let mut args = render_args(&veach_scene, &a, "16", "8");
    args.extend(["--light-sampler", "ris", "--sample-range", "0..4", "--backend", "cpu"]);
    assert_eq!(veach(&args, &[]).status.code(), Some(0));
    let mut args = render_args(&veach_scene, &b, "16", "8");
    args.extend(["--light-sampler", "tree", "--sample-range", "4..8", "--backend", "cpu"]);
    assert_eq!(veach(&args, &[]).status.code(), Some(0));
    let merged = d.join("merged.exr");
    assert_user_error(
        &veach(&["merge", a.to_str().unwrap(), b.to_str().unwrap(), "-o", merged.to_str().unwrap()], &[]),
        "light sampler",
    );
    assert!(!merged.exists());
    let _ = std::fs::remove_dir_all(&d);
}
