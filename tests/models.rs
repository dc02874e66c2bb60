//! Every third-party model in ../shared/models loads (or is refused with a one-line error
//! naming the extensions it requires) and renders with finite, plausible pixels on both
//! engines: 0 non-finite samples. The folder is not part of the repository: without it these
//! tests report themselves skipped, unless VEACH_REQUIRE_MODELS=1 (CI), where that fails.

mod common;

use std::path::PathBuf;
use veach::Settings;

fn models_dir() -> Option<PathBuf> {
    let d = common::root().join("../shared/models");
    if d.is_dir() {
        Some(d)
    } else {
        if std::env::var("VEACH_REQUIRE_MODELS").as_deref() == Ok("1") {
            panic!("VEACH_REQUIRE_MODELS=1 but {} is absent", d.display());
        }
        eprintln!("SKIPPED: {} is absent (third-party models are not in the repository)", d.display());
        None
    }
}

/// Every .gltf/.glb one level below `dir`.
fn model_files(dir: &std::path::Path) -> Vec<PathBuf> {
    let mut files = Vec::new();
    for entry in std::fs::read_dir(dir).unwrap().flatten() {
        if entry.path().is_dir() {
            for f in std::fs::read_dir(entry.path()).unwrap().flatten() {
                let p = f.path();
                if matches!(p.extension().and_then(|e| e.to_str()), Some("gltf" | "glb")) {
                    files.push(p);
                }
            }
        }
    }
    files.sort();
    files
}

#[test]
fn every_shared_model_renders_finite_and_plausible() {
    let Some(dir) = models_dir() else { return };
    let files = model_files(&dir);
    assert!(files.len() >= 8, "expected the shared models, found {files:?}");
    let ctx = common::gpu("every_shared_model_renders_finite_and_plausible");
    let mut refused = Vec::new();
    for path in files {
        let loaded = match veach::load(&path, None) {
            Ok(l) => l,
            // Support for these extensions is tracked in its own issues; refusing them with
            // a clear message is the behaviour until then.
            Err(e) if e.to_string().contains("requires glTF extensions veach does not support") => {
                assert!(!e.to_string().contains('\n'), "{e}");
                refused.push(format!("{e}"));
                continue;
            }
            Err(e) => panic!("{e}"),
        };
        for w in &loaded.warnings {
            eprintln!("{}: warning: {w}", path.display());
        }
        let packed = veach::packed::PackedScene::new(&loaded.scene);
        // A white sky, so that models without lights are seen.
        let settings =
            Settings { width: 64, height: 64, max_depth: 6, env_color: Some([1.0; 3]), ..Settings::default() };
        for ctx in [None, ctx.clone()].into_iter().enumerate().filter(|(k, c)| *k == 0 || c.is_some()).map(|(_, c)| c) {
            let engine = if ctx.is_some() { "gpu" } else { "cpu" };
            let mut r = common::renderer(packed.clone(), &loaded.camera, &settings, ctx).unwrap();
            r.render_samples(0, 4).unwrap();
            let film = r.film().unwrap();
            let n = film.pixel_count();
            let mean: f32 = (0..n).map(|i| veach::packed::luminance(film.mean(i))).sum::<f32>() / n as f32;
            let blown = (0..n).filter(|&i| film.mean(i).max_element() > 100.0).count();
            eprintln!(
                "{} ({engine}): {} triangles, {} textures, mean {mean:.3}, {} non-finite",
                path.display(),
                loaded.scene.triangles.len(),
                loaded.scene.textures.len(),
                film.nonfinite_samples()
            );
            assert_eq!(film.nonfinite_samples(), 0, "{} ({engine}): non-finite samples", path.display());
            assert!(mean > 0.02 && mean < 20.0, "{} ({engine}): implausible image mean {mean}", path.display());
            assert!(blown * 100 < n, "{} ({engine}): {blown} of {n} pixels above 100", path.display());
        }
    }
    eprintln!("refused (unsupported required extensions): {}", refused.len());
    for r in &refused {
        eprintln!("  {r}");
    }
}

#[test]
fn emissive_strength_doubles_per_step() {
    let Some(dir) = models_dir() else { return };
    let (scene, _) = common::load_pair(&dir.join("EmissiveStrengthTest/EmissiveStrengthTest.glb"), None).unwrap();
    let mut radiance: Vec<f32> =
        scene.materials.iter().filter(|m| m.is_emissive()).map(|m| m.emission.max_element()).collect();
    radiance.sort_by(f32::total_cmp);
    radiance.dedup();
    assert_eq!(radiance.len(), 5, "{radiance:?}");
    for w in radiance.windows(2) {
        assert!((w[1] / w[0] - 2.0).abs() < 1e-4, "{radiance:?}");
    }
}

#[test]
fn flight_helmet_keeps_its_textures_and_mirrored_tangents() {
    let Some(dir) = models_dir() else { return };
    let (scene, _) = common::load_pair(&dir.join("FlightHelmet/FlightHelmet.gltf"), None).unwrap();
    assert_eq!(scene.textures.len(), 15);
    assert!(scene.materials.iter().any(|m| m.normal_texture.is_some()));
    let mirrored = scene.triangles.iter().filter(|t| t.tangents[0].w < 0.0).count();
    let tangent = scene.triangles.iter().filter(|t| t.tangents[0].w != 0.0).count();
    eprintln!("FlightHelmet: {tangent} triangles with tangents, {mirrored} mirrored");
    assert!(mirrored > 0 && mirrored < tangent);
}
