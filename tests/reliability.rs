//! Work is never lost and splits merge exactly: sample ranges and tiles merged equal the
//! uninterrupted render byte for byte; an interrupted render keeps its samples and resumes
//! to the same bytes; non-finite samples are dropped and counted; limits fail early.

mod common;

use glam::Vec3;
use std::path::{Path, PathBuf};
use std::process::{Command, Output, Stdio};

fn veach(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_veach")).args(args).output().expect("run veach")
}

fn ok(out: Output) -> Output {
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    out
}

fn temp_dir(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("veach-rel-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).expect("temp dir");
    d
}

fn s(p: &Path) -> &str {
    p.to_str().expect("utf-8 path")
}

/// Whether the GPU tests here have an adapter (`veach` opens its own; bit-exactness on one
/// adapter is the claim).
fn has_gpu(test: &str) -> bool {
    common::gpu(test).is_some()
}

/// Sample ranges and tiles rendered with `--backend b` merge into the bytes of one render.
fn merges_into_the_same_bytes(b: &str) {
    let d = temp_dir(&format!("merge-{b}"));
    let scene = common::asset("cornell-box.gltf");
    let base = ["--width", "40", "--height", "30", "--backend", b];
    let render = |out: &Path, extra: &[&str]| {
        let mut args = vec!["render", s(&scene), "-o", s(out)];
        args.extend(base);
        args.extend(extra);
        ok(veach(&args));
    };
    render(&d.join("full.exr"), &["--spp", "12"]);
    render(&d.join("full.png"), &["--spp", "12"]);
    render(&d.join("a.exr"), &["--sample-range", "0..5"]);
    render(&d.join("b.exr"), &["--sample-range", "5..12"]);
    render(&d.join("top.exr"), &["--spp", "12", "--tile", "0,0,40,13"]);
    render(&d.join("bottom-left.exr"), &["--spp", "12", "--tile", "0,13,25,17"]);
    render(&d.join("bottom-right.exr"), &["--spp", "12", "--tile", "25,13,15,17"]);
    ok(veach(&["merge", s(&d.join("b.exr")), s(&d.join("a.exr")), "-o", s(&d.join("ranges.exr"))]));
    ok(veach(&["merge", s(&d.join("a.exr")), s(&d.join("b.exr")), "-o", s(&d.join("ranges.png"))]));
    ok(veach(&[
        "merge",
        s(&d.join("bottom-right.exr")),
        s(&d.join("top.exr")),
        s(&d.join("bottom-left.exr")),
        "-o",
        s(&d.join("tiles.exr")),
    ]));
    let read = |n: &str| std::fs::read(d.join(n)).expect(n);
    assert!(read("full.exr") == read("ranges.exr"), "sample ranges merge to the same EXR bytes");
    assert!(read("full.png") == read("ranges.png"), "and the same PNG bytes");
    assert!(read("full.exr") == read("tiles.exr"), "tiles merge to the same EXR bytes");
    // Overlapping parts are refused.
    let again = veach(&["merge", s(&d.join("a.exr")), s(&d.join("a.exr")), "-o", s(&d.join("x.exr"))]);
    assert_eq!(again.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&again.stderr).contains("overlap"));
    // So are parts made with another sample generator: the merged file could not say how it
    // was made, nor be resumed.
    render(&d.join("c.exr"), &["--sample-range", "5..12", "--sampler", "independent"]);
    let mixed = veach(&["merge", s(&d.join("a.exr")), s(&d.join("c.exr")), "-o", s(&d.join("y.exr"))]);
    assert_eq!(mixed.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&mixed.stderr).contains("sampler"));
    let _ = std::fs::remove_dir_all(&d);
}

#[test]
fn sample_ranges_and_tiles_merge_into_the_same_bytes() {
    merges_into_the_same_bytes("cpu");
}

#[test]
#[cfg_attr(veach_no_gpu, ignore = "needs a GPU adapter (no Vulkan driver on this machine)")]
fn sample_ranges_and_tiles_merge_into_the_same_bytes_on_the_gpu() {
    if has_gpu("sample_ranges_and_tiles_merge_into_the_same_bytes_on_the_gpu") {
        merges_into_the_same_bytes("gpu");
    }
}

#[test]
fn sigint_keeps_the_work_and_resume_finishes_it_exactly() {
    let d = temp_dir("resume");
    let scene = common::asset("cornell-box.gltf");
    let (out, ck, stats) = (d.join("out.exr"), d.join("ck.exr"), d.join("stats.json"));
    let args = ["--width", "48", "--height", "48", "--spp", "3000", "--backend", "cpu", "--seed", "5"];
    let mut cmd = Command::new(env!("CARGO_BIN_EXE_veach"));
    cmd.args(["render", s(&scene), "-o", s(&out), "--checkpoint", s(&ck), "--checkpoint-every", "0"])
        .args(["--stats-json", s(&stats)])
        .args(args)
        .stderr(Stdio::piped());
    let child = cmd.spawn().expect("spawn");
    // Interrupt once the first checkpoint shows work under way.
    let t = std::time::Instant::now();
    while !ck.exists() && t.elapsed().as_secs() < 60 {
        std::thread::sleep(std::time::Duration::from_millis(20));
    }
    let kill = Command::new("kill").args(["-INT", &child.id().to_string()]).status().expect("kill");
    assert!(kill.success());
    let result = child.wait_with_output().expect("wait");
    let stderr = String::from_utf8_lossy(&result.stderr);
    assert_eq!(result.status.code(), Some(130), "{stderr}");
    assert!(stderr.contains("interrupted"), "{stderr}");
    // The image of the samples so far is valid, with their count in the stats and the EXR.
    let (film, job) = veach::output::read_film(&out).expect("a valid EXR");
    let done = film.samples();
    assert!(done > 0 && done < 3000, "{done} samples");
    assert_eq!(job.sample_end, 3000);
    let st: serde_json::Value = serde_json::from_slice(&std::fs::read(&stats).unwrap()).unwrap();
    assert_eq!(st["spp"], done);
    assert_eq!(st["interrupted"], true);
    assert!((0..film.pixel_count()).all(|i| film.mean(i).is_finite()));
    // Resume to the target, then compare with a render that was never interrupted.
    let resumed = d.join("resumed.exr");
    ok(veach(&["render", "--resume", s(&ck), "-o", s(&resumed), "--backend", "cpu"]));
    let straight = d.join("straight.exr");
    let mut full = vec!["render", s(&scene), "-o", s(&straight)];
    full.extend(args);
    ok(veach(&full));
    assert!(std::fs::read(&resumed).unwrap() == std::fs::read(&straight).unwrap(), "resumed = uninterrupted");
    let _ = std::fs::remove_dir_all(&d);
}

fn non_finite_samples_are_dropped_and_counted_on(backend: veach::Backend) {
    // A material that produces NaN (the loader would sanitise it; inject it after loading).
    let (mut scene, camera) = common::load_pair(&common::asset("cornell-box.gltf"), None).unwrap();
    scene.materials[0].base_color = Vec3::new(f32::NAN, 0.5, 0.5);
    let packed = veach::packed::PackedScene::new(&scene);
    let mut r = veach::Renderer::new(packed, &camera, &common::settings(24, 8, 0), backend).unwrap();
    r.render_samples(0, 8).unwrap();
    let film = r.film().unwrap();
    assert!(film.nonfinite_samples() > 0, "{backend:?}: NaN paths are counted");
    assert!((0..film.pixel_count()).all(|i| film.mean(i).is_finite()), "{backend:?}: the image stays finite");
    assert_eq!(film.samples(), 8);
}

#[test]
fn non_finite_samples_are_dropped_and_counted() {
    non_finite_samples_are_dropped_and_counted_on(veach::Backend::Cpu);
}

#[test]
#[cfg_attr(veach_no_gpu, ignore = "needs a GPU adapter (no Vulkan driver on this machine)")]
fn non_finite_samples_are_dropped_and_counted_on_the_gpu() {
    if has_gpu("non_finite_samples_are_dropped_and_counted_on_the_gpu") {
        non_finite_samples_are_dropped_and_counted_on(veach::Backend::Gpu);
    }
}

/// A film too large for memory fails with `--backend b` before any work, naming the limit.
fn limits_fail_early_on(b: &str) {
    let scene = common::asset("cornell-box.gltf");
    let d = temp_dir(&format!("limits-{b}"));
    let out = d.join("big.png");
    let r = veach(&["render", s(&scene), "-o", s(&out), "--width", "16384", "--height", "16384", "--backend", b]);
    let stderr = String::from_utf8_lossy(&r.stderr);
    assert_eq!(r.status.code(), Some(2), "{stderr}");
    assert!(stderr.contains("16384") && stderr.contains("bytes"), "{stderr}");
    assert!(!out.exists());
    let _ = std::fs::remove_dir_all(&d);
}

#[test]
fn limits_fail_early_naming_the_limit() {
    limits_fail_early_on("cpu");
    let scene = common::asset("cornell-box.gltf");
    let d = temp_dir("limits");
    let out = d.join("big.png");
    let r = veach(&["render", s(&scene), "-o", s(&out), "--width", "100000", "--height", "8"]);
    assert_eq!(r.status.code(), Some(2));
    let _ = std::fs::remove_dir_all(&d);
}

#[test]
#[cfg_attr(veach_no_gpu, ignore = "needs a GPU adapter (no Vulkan driver on this machine)")]
fn limits_fail_early_naming_the_limit_on_the_gpu() {
    if has_gpu("limits_fail_early_naming_the_limit_on_the_gpu") {
        limits_fail_early_on("gpu");
    }
}
