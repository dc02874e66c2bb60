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
        println!("cargo::rerun-if-changed={d}");
    }
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
