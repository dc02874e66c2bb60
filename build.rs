//! Tells the tests whether this machine can have a GPU adapter at all, so that tests needing
//! one are reported as ignored ("needs a GPU adapter") in cargo's summary instead of passing
//! without running. Linux: a Vulkan loader and an installed ICD; macOS (Metal) and Windows
//! (DX12) always have a backend. Installing a driver later re-runs this probe.

fn main() {
    println!("cargo::rustc-check-cfg=cfg(veach_no_gpu)");
    println!("cargo::rerun-if-env-changed=VK_ICD_FILENAMES");
    println!("cargo::rerun-if-env-changed=VK_DRIVER_FILES");
    let icd_dirs = ["/usr/share/vulkan/icd.d", "/etc/vulkan/icd.d", "/usr/local/share/vulkan/icd.d"];
    for d in icd_dirs {
        watch(std::path::Path::new(d));
    }
    // Installing a driver through the package manager also writes its database: one file,
    // so a single timestamp to compare, on Debian and its kin.
    watch_file(std::path::Path::new("/var/lib/dpkg/status"));
    // CI requires the GPU tests to run (and fail without an adapter), never to be ignored.
    println!("cargo::rerun-if-env-changed=VEACH_REQUIRE_GPU");
    let required = std::env::var("VEACH_REQUIRE_GPU").is_ok_and(|v| v == "1");
    let target = std::env::var("CARGO_CFG_TARGET_OS").unwrap_or_default();
    if target != "linux" || required {
        return;
    }
    let env_icd = std::env::var_os("VK_ICD_FILENAMES").or_else(|| std::env::var_os("VK_DRIVER_FILES")).is_some();
    let icd = env_icd
        || icd_dirs.iter().any(|d| {
            std::fs::read_dir(d)
                .is_ok_and(|entries| entries.flatten().any(|e| e.path().extension().is_some_and(|x| x == "json")))
        });
    let loader = ["/usr/lib/x86_64-linux-gnu", "/usr/lib/aarch64-linux-gnu", "/usr/lib64", "/usr/lib", "/lib64"]
        .iter()
        .any(|d| std::path::Path::new(d).join("libvulkan.so.1").exists());
    if !(icd && loader) {
        println!("cargo::rustc-cfg=veach_no_gpu");
    }
}

/// Re-probe when `dir` changes. Cargo re-runs a build script on every build when a watched path
/// does not exist, so a missing directory is watched through its nearest existing ancestor
/// (creating it changes that ancestor) — unless that ancestor is a top-level system directory
/// (/, /etc, /usr, /usr/share, /usr/local, /usr/local/share), which cargo would scan whole and
/// which changes for unrelated reasons; the package database covers those.
fn watch(dir: &std::path::Path) {
    let too_wide = ["/", "/etc", "/usr", "/usr/share", "/usr/local", "/usr/local/share"];
    let mut p = Some(dir);
    while let Some(d) = p {
        if d.exists() {
            if d == dir || !too_wide.iter().any(|w| d == std::path::Path::new(w)) {
                println!("cargo::rerun-if-changed={}", d.display());
            }
            return;
        }
        p = d.parent();
    }
}

fn watch_file(file: &std::path::Path) {
    if file.is_file() {
        println!("cargo::rerun-if-changed={}", file.display());
    }
}
