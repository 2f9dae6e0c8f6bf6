//! Embeds every WGSL file of `shaders/` (a link to the repository's): writes the table
//! `fray_gpu::shader::SHADER_FILES` includes — each file's name and text as a raw string — so a
//! new shader file is embedded by being there.

use std::fmt::Write as _;
use std::path::PathBuf;

fn main() {
    let manifest = PathBuf::from(std::env::var_os("CARGO_MANIFEST_DIR").expect("set by cargo"));
    let dir = manifest.join("shaders");
    // A directory: cargo reruns this when any file in it changes, is added or removed.
    println!("cargo:rerun-if-changed=shaders");
    let mut names: Vec<String> = std::fs::read_dir(&dir)
        .unwrap_or_else(|e| panic!("{}: {e}", dir.display()))
        .filter_map(|entry| entry.ok()?.file_name().into_string().ok())
        .filter(|name| name.ends_with(".wgsl"))
        .collect();
    names.sort();
    let mut table = format!(
        "/// Every shader file with its name, embedded at build time from `shaders/` (by `build.rs`).\n\
         pub const SHADER_FILES: [(&str, &str); {}] = [\n",
        names.len()
    );
    for name in &names {
        let path = dir.join(name);
        let text =
            std::fs::read_to_string(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
        // A raw string whose closing quote and hashes the text does not hold.
        let hashes = (1..)
            .map(|n| "#".repeat(n))
            .find(|h| !text.contains(&format!("\"{h}")))
            .expect("some run of hashes is not in the text");
        writeln!(table, "    ({name:?}, r{hashes}\"{text}\"{hashes}),")
            .expect("writing to a string");
    }
    table.push_str("];\n");
    let out = PathBuf::from(std::env::var_os("OUT_DIR").expect("set by cargo"));
    std::fs::write(out.join("shader_files.rs"), table).expect("OUT_DIR is writable");
}
