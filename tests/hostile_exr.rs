//! Hostile and damaged EXR parts for `veach merge` and `--resume`, and hostile flags: every
//! input gives a result or one clear error (exit 2), never a panic, a hang or a silently
//! mixed image. A mutation test feeds thousands of damaged headers and metadata to the
//! library's read, merge and resume paths.

mod common;

use common::rng::Lcg;

use common::cli::{assert_user_error, ok, s, temp_dir, veach};
use serde_json::Value;
use std::path::{Path, PathBuf};

/// A 16×16 two-sample part of the Cornell box on the CPU engine, with extra flags.
fn part(dir: &Path, name: &str, extra: &[&str]) -> PathBuf {
    let out = dir.join(name);
    let scene = common::asset("cornell-box.gltf");
    let mut args = vec!["render", s(&scene), "-o", s(&out), "--width", "16", "--height", "16", "--backend", "cpu"];
    args.extend_from_slice(extra);
    ok(veach(&args, &[]));
    out
}

/// The veach metadata JSON of an EXR written by veach: (start of the text, its length field
/// offset, the JSON).
fn metadata(bytes: &[u8]) -> (usize, usize, Value) {
    let key = b"veach\0string\0";
    let at = bytes.windows(key.len()).position(|w| w == key).expect("veach attribute") + key.len();
    let len = i32::from_le_bytes(bytes[at..at + 4].try_into().unwrap()) as usize;
    let json = serde_json::from_slice(&bytes[at + 4..at + 4 + len]).expect("metadata JSON");
    (at + 4, at, json)
}

/// The EXR with its metadata replaced by `json` (the attribute's size updated).
fn with_metadata(bytes: &[u8], json: &Value) -> Vec<u8> {
    let (start, size_at, _) = metadata(bytes);
    let old_len = i32::from_le_bytes(bytes[size_at..size_at + 4].try_into().unwrap()) as usize;
    let text = serde_json::to_vec(json).unwrap();
    let mut out = bytes[..size_at].to_vec();
    out.extend((text.len() as i32).to_le_bytes());
    out.extend(&text);
    out.extend(&bytes[start + old_len..]);
    // The offset table after the header moves with it: chunk offsets are absolute.
    let shift = text.len() as i64 - old_len as i64;
    fix_offsets(&mut out, start + text.len(), shift);
    out
}

/// Shifts the scan-line offset table that follows the header (the header ends with a 0 byte).
fn fix_offsets(bytes: &mut [u8], after: usize, shift: i64) {
    let Some(end) = find_header_end(bytes, after) else { return };
    let mut at = end;
    while at + 8 <= bytes.len() {
        let v = i64::from_le_bytes(bytes[at..at + 8].try_into().unwrap());
        // The table holds increasing offsets into the file; it ends where the first chunk starts.
        if v <= 0 || v as usize > bytes.len() + shift.unsigned_abs() as usize + 16 {
            break;
        }
        let first_chunk = (v + shift) as usize;
        bytes[at..at + 8].copy_from_slice(&(v + shift).to_le_bytes());
        at += 8;
        if at >= first_chunk {
            break;
        }
    }
}

/// The byte after the header's terminating 0 (attributes are name\0type\0size value).
fn find_header_end(bytes: &[u8], from: usize) -> Option<usize> {
    let mut at = from;
    loop {
        if *bytes.get(at)? == 0 {
            return Some(at + 1);
        }
        let name_end = at + bytes[at..].iter().position(|&b| b == 0)?;
        let type_end = name_end + 1 + bytes[name_end + 1..].iter().position(|&b| b == 0)?;
        let size = i32::from_le_bytes(bytes.get(type_end + 1..type_end + 5)?.try_into().ok()?) as usize;
        at = type_end + 5 + size;
    }
}

#[test]
fn damaged_metadata_is_refused_with_one_line() {
    let d = temp_dir("hostile-exr");
    let base = std::fs::read(part(d.path(), "base.exr", &["--spp", "2"])).unwrap();
    let (_, _, job) = metadata(&base);
    // Sanity: the unmodified rewrite still merges.
    let same = d.path().join("same.exr");
    std::fs::write(&same, with_metadata(&base, &job)).unwrap();
    ok(veach(&["merge", s(&same), "-o", s(&d.path().join("same-out.exr"))], &[]));
    let cases: &[(&str, Value, &str)] = &[
        ("/job/width", Value::from(4_000_000_000u64), "image size"),
        ("/job/height", Value::from(0), "image size"),
        ("/job/tile", serde_json::json!({"x": 30, "y": 0, "width": 20, "height": 16}), "does not fit"),
        ("/job/tile", serde_json::json!({"x": 4294967295u32, "y": 0, "width": 1, "height": 1}), "does not fit"),
        ("/job/sample_end", Value::from(0), "sample range"),
        ("/job/aperture", Value::from(-1.0), "aperture"),
        ("/job/focus_distance", Value::from(-5.0), "focus distance"),
        ("/job/env_strength", Value::from(-2.0), "environment strength"),
        ("/job/width", Value::from(32), "film is 16x16"),
        ("/job/sample_end", Value::from(1), "sample counts"),
    ];
    for (pointer, value, needle) in cases {
        let mut j = job.clone();
        *j.pointer_mut(pointer).unwrap_or_else(|| panic!("{pointer}")) = value.clone();
        let bad = d.path().join("bad.exr");
        std::fs::write(&bad, with_metadata(&base, &j)).unwrap();
        let out = d.path().join("out.exr");
        assert_user_error(&veach(&["merge", s(&bad), "-o", s(&out)], &[]), needle);
        assert_user_error(&veach(&["render", "--resume", s(&bad), "-o", s(&out)], &[]), needle);
        assert!(!out.exists(), "{pointer}: no output on error");
    }
}

#[test]
fn parts_of_other_renders_are_refused() {
    let d = temp_dir("hostile-merge");
    let a = part(d.path(), "a.exr", &["--sample-range", "0..2"]);
    let out = d.path().join("out.exr");
    for (flags, needle) in [
        (&["--env-color", "0.5,0.5,0.5"][..], "environment color"),
        (&["--env-strength", "2"][..], "environment strength"),
        (&["--aperture", "0.05"][..], "aperture"),
        (&["--aperture", "0.05", "--focus-distance", "3"][..], "aperture"),
        (&["--seed", "3"][..], "seed"),
        (&["--sampler", "independent"][..], "sampler"),
        (&["--max-depth", "3"][..], "max depth"),
    ] {
        let mut f = vec!["--sample-range", "2..4"];
        f.extend_from_slice(flags);
        let b = part(d.path(), "b.exr", &f);
        assert_user_error(&veach(&["merge", s(&a), s(&b), "-o", s(&out)], &[]), needle);
    }
    // Overlapping samples in the same pixels are refused too.
    let c = part(d.path(), "c.exr", &["--sample-range", "1..3"]);
    assert_user_error(&veach(&["merge", s(&a), s(&c), "-o", s(&out)], &[]), "overlap");
    // A gap in the samples: merged as 0..6, a resume would take samples 4 and 5 twice.
    let gap = part(d.path(), "gap.exr", &["--sample-range", "4..6"]);
    assert_user_error(&veach(&["merge", s(&a), s(&gap), "-o", s(&out)], &[]), "gap");
    // Tiles whose samples differ, and tiles that half overlap.
    let left = part(d.path(), "left.exr", &["--sample-range", "0..2", "--tile", "0,0,8,16"]);
    let right = part(d.path(), "right.exr", &["--sample-range", "0..4", "--tile", "8,0,8,16"]);
    assert_user_error(&veach(&["merge", s(&left), s(&right), "-o", s(&out)], &[]), "same samples");
    let shifted = part(d.path(), "shifted.exr", &["--sample-range", "2..4", "--tile", "4,0,8,16"]);
    assert_user_error(&veach(&["merge", s(&left), s(&shifted), "-o", s(&out)], &[]), "same tile");
    // Tiles by sample ranges, in any order, merge into the whole render.
    let right2 = part(d.path(), "right2.exr", &["--sample-range", "2..4", "--tile", "8,0,8,16"]);
    let left2 = part(d.path(), "left2.exr", &["--sample-range", "2..4", "--tile", "0,0,8,16"]);
    let right3 = part(d.path(), "right3.exr", &["--sample-range", "0..2", "--tile", "8,0,8,16"]);
    ok(veach(&["merge", s(&right2), s(&left), s(&right3), s(&left2), "-o", s(&out)], &[]));
    let (film, job) = veach::output::read_film(&out).unwrap();
    assert_eq!((film.samples(), job.sample_start, job.sample_end), (4, 0, 4));
    let whole = part(d.path(), "whole.exr", &["--spp", "4"]);
    let (reference, _) = veach::output::read_film(&whole).unwrap();
    let exact = |f: &veach::Film| -> Vec<u32> {
        (0..f.pixel_count()).flat_map(|i| f.data[i * 12..i * 12 + 8].to_vec()).collect()
    };
    assert!(exact(&film) == exact(&reference), "tiles x ranges = the whole render");
}

/// A damaged EXR's job may name any path as its scene: a device or a pipe is refused, never
/// read forever.
#[test]
#[cfg(unix)]
fn a_resumed_job_naming_a_device_is_refused() {
    let d = temp_dir("hostile-scene");
    let base = std::fs::read(part(d.path(), "base.exr", &["--spp", "2"])).unwrap();
    let (_, _, mut job) = metadata(&base);
    let fifo = d.path().join("fifo");
    let made = std::process::Command::new("mkfifo").arg(&fifo).status().is_ok_and(|s| s.success());
    let mut devices = vec!["/dev/zero".to_string()];
    if made {
        devices.push(fifo.display().to_string());
    }
    for device in devices {
        *job.pointer_mut("/job/scene").unwrap() = Value::from(device.clone());
        let bad = d.path().join("bad.exr");
        std::fs::write(&bad, with_metadata(&base, &job)).unwrap();
        let out = d.path().join("out.exr");
        assert_user_error(&veach(&["render", "--resume", s(&bad), "-o", s(&out)], &[]), "not a regular file");
    }
}

#[test]
fn hostile_flags_exit_2() {
    let d = temp_dir("hostile-flags");
    let scene = common::asset("cornell-box.gltf");
    let out = d.path().join("o.png");
    let base = ["render", s(&scene), "-o", s(&out), "--height", "8", "--spp", "1"];
    for (flags, needle) in [
        (&["--tile", "4294967295,0,1,1"][..], "does not fit"),
        (&["--tile", "0,4294967295,1,4294967295"][..], "does not fit"),
        (&["--width", "4294967295"][..], "image size"),
        (&["--width", "0"][..], "image size"),
        (&["--sample-range", "4294967294..4294967295"][..], ""),
        (&["--aperture", "-1"][..], "aperture"),
        (&["--aperture", "nan"][..], "aperture"),
        (&["--focus-distance", "-5"][..], "focus-distance"),
        (&["--focus-distance", "inf"][..], "focus-distance"),
        (&["--exposure", "nan"][..], "exposure"),
        (&["--checkpoint-every", "-1"][..], "checkpoint-every"),
        (&["--env-strength", "-1"][..], "env-strength"),
    ] {
        let mut args = base.to_vec();
        if !flags.contains(&"--width") {
            args.extend_from_slice(&["--width", "8"]);
        }
        args.extend_from_slice(flags);
        let o = veach(&args, &[]);
        if needle.is_empty() {
            // The last samples of the u32 range render (no overflow).
            ok(o);
            continue;
        }
        assert_user_error(&o, needle);
    }
    let saved = part(d.path(), "saved.exr", &["--spp", "2"]);
    // Flags at their default values too: a saved render made with other values would
    // silently ignore them.
    for flags in [
        &["--spp", "8"][..],
        &["--width", "32"],
        &["--env-color", "1,1,1"],
        &["--tile", "0,0,4,4"],
        &["--seed", "2"],
        &["--light-sampler", "tree"],
        &["--env-strength", "1"],
        &["--aperture", "0"],
        &["--aov", "depth"],
    ] {
        let mut args = vec!["render", "--resume", s(&saved), "-o", s(&out)];
        args.extend_from_slice(flags);
        let o = veach(&args, &[]);
        assert_eq!(o.status.code(), Some(2), "--resume with {flags:?}: {}", String::from_utf8_lossy(&o.stderr));
    }
}

/// Numbers a mutation puts into the metadata: edges of every integer and float range.
const EXTREMES: &[f64] = &[
    0.0,
    -0.0,
    1.0,
    -1.0,
    15.0,
    16.0,
    17.0,
    255.0,
    65536.0,
    2147483647.0,
    2147483648.0,
    4294967295.0,
    4294967296.0,
    1e30,
    -1e30,
    1e-45,
    0.5,
    3.0,
];

fn numeric_paths(v: &Value, path: String, out: &mut Vec<String>) {
    match v {
        Value::Object(m) => m.iter().for_each(|(k, x)| numeric_paths(x, format!("{path}/{k}"), out)),
        Value::Array(a) => a.iter().enumerate().for_each(|(i, x)| numeric_paths(x, format!("{path}/{i}"), out)),
        Value::Number(_) | Value::Null => out.push(path),
        _ => {}
    }
}

#[test]
fn mutated_parts_never_panic() {
    let d = temp_dir("mutated-exr");
    let base = std::fs::read(part(d.path(), "base.exr", &["--spp", "2", "--tile", "0,0,16,8"])).unwrap();
    let (_, _, job) = metadata(&base);
    let mut paths = Vec::new();
    numeric_paths(&job, String::new(), &mut paths);
    paths.extend(["/job/tile".into(), "/job/focus_distance".into(), "/job/env_color".into()]);
    let loaded = veach::load(&common::asset("cornell-box.gltf"), None).unwrap();
    let packed = veach::PackedScene::new(&loaded.scene);
    // VEACH_MUTATION_SEED replays another sequence (the inputs also depend on the base file,
    // whose metadata names a temporary directory).
    let seed = std::env::var("VEACH_MUTATION_SEED").ok().and_then(|s| s.parse().ok()).unwrap_or(7);
    let mut rng = Lcg(seed);
    let (mut refused, mut accepted) = (0, 0);
    let file = d.path().join("m.exr");
    let t0 = std::time::Instant::now();
    for k in 0..2400 {
        let bytes = match k % 4 {
            // The image's data or display window set to extremes (a decoder must not allocate
            // what the header claims).
            3 => {
                let mut b = base.clone();
                let key: &[u8] = if rng.below(2) == 0 { b"dataWindow\0box2i\0" } else { b"displayWindow\0box2i\0" };
                if let Some(at) = b.windows(key.len()).position(|w| w == key) {
                    let field = at + key.len() + 4 + 4 * rng.below(4);
                    let v = [i32::MAX, i32::MIN, 1 << 20, -1, 0, 100_000][rng.below(6)];
                    b[field..field + 4].copy_from_slice(&v.to_le_bytes());
                }
                b
            }
            // A numeric metadata field set to an extreme value (or a tile of extremes).
            0 | 1 => {
                let mut j = job.clone();
                let p = &paths[rng.below(paths.len())];
                let x = |r: &mut Lcg| Value::from(EXTREMES[r.below(EXTREMES.len())]);
                let v = if p.ends_with("/tile") {
                    serde_json::json!({"x": x(&mut rng), "y": x(&mut rng), "width": x(&mut rng), "height": x(&mut rng)})
                } else {
                    x(&mut rng)
                };
                if let Some(slot) = j.pointer_mut(p) {
                    *slot = v;
                }
                with_metadata(&base, &j)
            }
            // Random bytes of the file changed, or the file cut short.
            _ => {
                let mut b = base.clone();
                if rng.below(4) == 0 {
                    b.truncate(rng.below(b.len()));
                } else {
                    for _ in 0..1 + rng.below(4) {
                        let i = rng.below(b.len());
                        b[i] = rng.next() as u8;
                    }
                }
                b
            }
        };
        std::fs::write(&file, &bytes).unwrap();
        let result = std::panic::catch_unwind(|| {
            let (film, job) = veach::output::read_film(&file)?;
            let part = veach::Part { film: film.clone(), job: job.clone(), path: file.clone() };
            veach::merge(std::slice::from_ref(&part))?;
            // Resume: the saved settings over the scene, the film set into the renderer.
            let mut r = veach::Renderer::new(packed.clone(), &loaded.camera, &job.settings, veach::Backend::Cpu)?;
            r.set_film(&film)?;
            Ok::<(), veach::Error>(())
        });
        match result {
            Ok(Ok(())) => accepted += 1,
            Ok(Err(e)) => {
                let m = e.to_string();
                assert!(!m.contains('\n') && !m.is_empty(), "multi-line error: {m}");
                refused += 1;
            }
            Err(_) => panic!("mutation {k} panicked; input kept at {}", {
                let keep = std::env::temp_dir().join(format!("veach-panic-{k}.exr"));
                std::fs::write(&keep, &bytes).unwrap();
                keep.display().to_string()
            }),
        }
        assert!(t0.elapsed().as_secs() < 120, "the mutation test took too long at input {k}");
    }
    eprintln!("mutated parts: {accepted} accepted, {refused} refused");
    assert!(refused > 500 && accepted > 50, "{accepted} accepted, {refused} refused");
}

/// Every extreme value in every field of both windows, each on its own: the decoder sizes its
/// buffers from the header, so a header claiming billions of pixels must be refused before any
/// allocation (a failed allocation aborts the process, which no `catch_unwind` can catch).
#[test]
fn extreme_windows_are_refused_before_allocation() {
    let d = temp_dir("window-exr");
    let base = std::fs::read(part(d.path(), "base.exr", &["--spp", "1"])).unwrap();
    let file = d.path().join("w.exr");
    let mut refused = 0;
    for key in [&b"dataWindow\0box2i\0"[..], &b"displayWindow\0box2i\0"[..]] {
        let at = base.windows(key.len()).position(|w| w == key).expect("window attribute") + key.len() + 4;
        for field in 0..4 {
            for v in [i32::MAX, i32::MIN, 3 << 28, -(3 << 28), 1 << 20, -1, 100_000] {
                let mut b = base.clone();
                b[at + 4 * field..at + 4 * field + 4].copy_from_slice(&v.to_le_bytes());
                std::fs::write(&file, &b).unwrap();
                match std::panic::catch_unwind(|| veach::output::read_film(&file)) {
                    Ok(Ok(_)) => {}
                    Ok(Err(e)) => {
                        assert!(!e.to_string().contains('\n'), "multi-line error: {e}");
                        refused += 1;
                    }
                    Err(_) => panic!("window field {field} = {v} panicked"),
                }
            }
        }
    }
    // Every data-window change breaks the film's size or the chunk table.
    assert!(refused >= 24, "only {refused} of 56 extreme windows refused");
}
