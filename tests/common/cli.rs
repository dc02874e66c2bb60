//! Running the `veach` binary in tests, in temporary directories removed afterwards.

use std::path::Path;
use std::process::{Command, Output};

/// Runs `veach` with `args` (and extra environment variables).
pub fn veach(args: &[&str], envs: &[(&str, &str)]) -> Output {
    let mut cmd = Command::new(env!("CARGO_BIN_EXE_veach"));
    cmd.args(args);
    for (k, v) in envs {
        cmd.env(k, v);
    }
    cmd.output().expect("run veach")
}

/// Asserts success and returns the output.
pub fn ok(out: Output) -> Output {
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    out
}

/// Asserts a user error: exit 2, one line on stderr naming `needle`, no panic.
pub fn assert_user_error(out: &Output, needle: &str) {
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "expected exit 2 for '{needle}', got {:?}: {err}", out.status);
    assert!(!err.contains("internal error") && !err.contains("panicked"), "{err}");
    assert!(err.contains(needle), "expected '{needle}' in: {err}");
    let lines: Vec<&str> = err.lines().filter(|l| !l.trim().is_empty()).collect();
    assert!(lines.len() <= 2, "more than one line (and clap's usage hint): {err}");
}

/// A temporary directory, removed when dropped (a failing test too).
pub fn temp_dir(name: &str) -> tempfile::TempDir {
    tempfile::Builder::new().prefix(&format!("veach-{name}-")).tempdir().expect("temp dir")
}

pub fn s(p: &Path) -> &str {
    p.to_str().expect("utf-8 path")
}
