//! What the end-to-end suites share: running the `fray` binary and a fresh scratch folder.

use std::path::PathBuf;
use std::process::{Command, Output};

/// Runs the `fray` binary with `args` in the repository's root, without the memory-budget
/// variable of the caller's environment.
pub fn fray(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_fray"))
        .args(args)
        .env_remove("FRAY_MEMORY_BUDGET")
        .current_dir(env!("CARGO_MANIFEST_DIR"))
        .output()
        .expect("the fray binary runs")
}

/// An empty folder `fray-<suite>-<pid>-<name>` in the system's temporary folder.
pub fn temp_dir(suite: &str, name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("fray-{suite}-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).expect("temp dir");
    dir
}
