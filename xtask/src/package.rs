//! `cargo xtask package`: packages every library crate as crates.io would receive it and checks
//! that each `.crate` holds what its sources embed.
//!
//! The library crates are the workspace members with a `lib` target that may be published
//! (`cargo metadata`). All of them are packaged in one `cargo package --no-verify` call, which
//! orders them by their dependencies and resolves each one's fray dependencies through a local
//! overlay of the ones packaged before it, so nothing has to be on crates.io. `--offline`: the
//! crates.io index cache that building the workspace filled is enough, and nothing is fetched.
//! Then, per crate, `cargo package --list` names the archive's files; every
//! `include_str!`/`include_bytes!` in an archived `.rs` file must name a file in the archive
//! (a path out of the crate's folder, such as `../../../shaders/x.wgsl`, is a failure), what a
//! build script reads (its `cargo:rerun-if-changed=` files and folders) must be in it too, and the
//! README and both licence texts must be there.

use serde::Deserialize;
use std::collections::BTreeSet;
use std::path::{Component, Path, PathBuf};
use std::process::Command;
use std::time::Instant;

/// The files every packaged library must carry.
const REQUIRED_FILES: [&str; 3] = ["README.md", "LICENSE-MIT", "LICENSE-APACHE"];

/// The part of `cargo metadata --no-deps` this task reads.
#[derive(Debug, Deserialize)]
struct Metadata {
    packages: Vec<Package>,
}

#[derive(Debug, Deserialize)]
struct Package {
    name: String,
    manifest_path: PathBuf,
    /// `None`: any registry; `[]`: `publish = false`.
    publish: Option<Vec<String>>,
    targets: Vec<Target>,
}

#[derive(Debug, Deserialize)]
struct Target {
    kind: Vec<String>,
}

/// A library crate to package: its name and folder.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Library {
    pub name: String,
    pub dir: PathBuf,
}

/// Packages every library crate and checks each archive; returns whether every check passed
/// (the report is printed as it goes).
pub fn run() -> Result<bool, String> {
    let start = Instant::now();
    let root = crate::workspace::root();
    let libraries = libraries(&cargo(
        &root,
        &["metadata", "--format-version", "1", "--no-deps"],
    )?)?;
    let mut args = vec!["package", "--no-verify", "--allow-dirty", "--offline"];
    for lib in &libraries {
        args.extend(["-p", lib.name.as_str()]);
    }
    cargo(&root, &args)?;
    let mut ok = true;
    for lib in &libraries {
        let listing = cargo(
            &root,
            &[
                "package",
                "--list",
                "--allow-dirty",
                "--offline",
                "-p",
                &lib.name,
            ],
        )?;
        let files: Vec<String> = listing.lines().map(str::to_owned).collect();
        let read = |path: &str| {
            std::fs::read_to_string(lib.dir.join(path))
                .map_err(|e| format!("cannot read {}: {e}", lib.dir.join(path).display()))
        };
        let (includes, problems) = check_archive(&files, read)?;
        if problems.is_empty() {
            println!(
                "{}: {} files; {includes} embedded files and build-script inputs, all in the archive",
                lib.name,
                files.len()
            );
        } else {
            ok = false;
            for p in &problems {
                println!("{}: {p}", lib.name);
            }
        }
    }
    println!(
        "packaged {} library crates in {:.1} s (target/package/*.crate)",
        libraries.len(),
        start.elapsed().as_secs_f64()
    );
    Ok(ok)
}

/// Runs cargo (the one running this task, else `cargo` on the path) in `dir`; its stdout, or
/// an error with its stderr.
fn cargo(dir: &Path, args: &[&str]) -> Result<String, String> {
    let program = std::env::var_os("CARGO").unwrap_or_else(|| "cargo".into());
    let out = Command::new(&program)
        .args(args)
        .current_dir(dir)
        .output()
        .map_err(|e| format!("cannot run {}: {e}", program.to_string_lossy()))?;
    if !out.status.success() {
        return Err(format!(
            "`cargo {}` failed ({}):\n{}\n(offline, cargo reads the crates.io index cache that a build \
             fills: build the workspace once first)",
            args.join(" "),
            out.status,
            String::from_utf8_lossy(&out.stderr).trim_end()
        ));
    }
    String::from_utf8(out.stdout).map_err(|e| format!("`cargo {}`: {e}", args.join(" ")))
}

/// The publishable library crates in `cargo metadata` JSON, by name.
pub fn libraries(metadata_json: &str) -> Result<Vec<Library>, String> {
    let metadata: Metadata =
        serde_json::from_str(metadata_json).map_err(|e| format!("cargo metadata: {e}"))?;
    let mut libraries: Vec<Library> = metadata
        .packages
        .into_iter()
        .filter(|p| {
            p.publish
                .as_ref()
                .is_none_or(|registries| !registries.is_empty())
        })
        .filter(|p| p.targets.iter().any(|t| t.kind.iter().any(|k| k == "lib")))
        .map(|p| Library {
            dir: p
                .manifest_path
                .parent()
                .map(Path::to_path_buf)
                .unwrap_or_default(),
            name: p.name,
        })
        .collect();
    libraries.sort_by(|a, b| a.name.cmp(&b.name));
    if libraries.is_empty() {
        return Err("cargo metadata lists no publishable library crate".into());
    }
    Ok(libraries)
}

/// Checks one archive's file list: `read` gives an archived file's text. Returns how many
/// include targets and build-script inputs were found and what is wrong (nothing: the archive
/// is whole).
pub fn check_archive(
    files: &[String],
    read: impl Fn(&str) -> Result<String, String>,
) -> Result<(usize, Vec<String>), String> {
    let archived: BTreeSet<&str> = files.iter().map(String::as_str).collect();
    let mut problems = Vec::new();
    for required in REQUIRED_FILES {
        if !archived.contains(required) {
            problems.push(format!("{required} is not in the archive"));
        }
    }
    let mut count = 0;
    for file in files.iter().filter(|f| f.ends_with(".rs")) {
        let source = read(file)?;
        for target in include_targets(&source) {
            count += 1;
            let target = target.map_err(|e| format!("{file}: {e}"))?;
            match resolve(file, &target) {
                Some(path) if archived.contains(path.as_str()) => {}
                Some(path) => problems.push(format!(
                    "{file} includes \"{target}\" = {path}, which is not in the archive"
                )),
                None => problems.push(format!(
                    "{file} includes \"{target}\", which is outside the crate's folder"
                )),
            }
        }
    }
    if archived.contains("build.rs") {
        let source = read("build.rs")?;
        for input in build_inputs(&source) {
            count += 1;
            let prefix = format!("{input}/");
            if !archived
                .iter()
                .any(|f| *f == input || f.starts_with(&prefix))
            {
                problems.push(format!(
                    "build.rs reads {input}, which is not in the archive"
                ));
            }
        }
    }
    Ok((count, problems))
}

/// What a build script reads, as it tells cargo: every `cargo:rerun-if-changed=<path>` (a file,
/// or a folder it reads files of), relative to the crate's folder.
pub fn build_inputs(source: &str) -> Vec<String> {
    source
        .match_indices("rerun-if-changed=")
        .map(|(at, key)| {
            source[at + key.len()..]
                .chars()
                .take_while(|c| *c != '"' && !c.is_whitespace())
                .collect::<String>()
        })
        .filter(|path| !path.is_empty())
        .collect()
}

/// The string literal of every `include_str!(…)`/`include_bytes!(…)` in `source`, in order; an
/// argument that is not a plain or raw string literal is an error (it cannot be checked).
pub fn include_targets(source: &str) -> Vec<Result<String, String>> {
    let mut found = Vec::new();
    for mac in ["include_str!", "include_bytes!"] {
        for (at, _) in source.match_indices(mac) {
            let rest = source[at + mac.len()..].trim_start();
            let Some(arg) = rest.strip_prefix('(') else {
                continue;
            };
            found.push((
                at,
                literal(arg.trim_start()).ok_or_else(|| {
                    let shown: String = arg.chars().take(40).collect();
                    format!("{mac}({shown}…: not a string literal, cannot be checked")
                }),
            ));
        }
    }
    found.sort_by_key(|(at, _)| *at);
    found.into_iter().map(|(_, target)| target).collect()
}

/// The value of the string literal `text` starts with: `"…"` without escapes, or `r"…"`,
/// `r#"…"#`.
fn literal(text: &str) -> Option<String> {
    if let Some(body) = text.strip_prefix('"') {
        let end = body.find('"')?;
        let value = &body[..end];
        return (!value.contains('\\')).then(|| value.to_owned());
    }
    let raw = text.strip_prefix('r')?;
    let hashes = raw.len() - raw.trim_start_matches('#').len();
    let body = raw[hashes..].strip_prefix('"')?;
    let close = format!("\"{}", "#".repeat(hashes));
    body.find(&close).map(|end| body[..end].to_owned())
}

/// `target` as the archive names it, relative to the crate's folder, for an include in `file`
/// (both with `/`); `None` when it leaves the folder or is absolute.
fn resolve(file: &str, target: &str) -> Option<String> {
    let base = Path::new(file).parent().unwrap_or(Path::new(""));
    let mut parts: Vec<String> = Vec::new();
    for component in base.join(target).components() {
        match component {
            Component::Normal(part) => parts.push(part.to_str()?.to_owned()),
            Component::CurDir => {}
            Component::ParentDir => {
                parts.pop()?;
            }
            Component::RootDir | Component::Prefix(_) => return None,
        }
    }
    Some(parts.join("/"))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn files(names: &[&str]) -> Vec<String> {
        names.iter().map(|n| n.to_string()).collect()
    }

    const HEADER: [&str; 3] = ["README.md", "LICENSE-MIT", "LICENSE-APACHE"];

    #[test]
    fn finds_every_include_with_plain_and_raw_literals() {
        let source = r####"
            #![doc = include_str!("../README.md")]
            const A: &str = include_str!( "../shaders/a.wgsl" );
            const B: &[u8] = include_bytes!(r#"data/b.bin"#);
            const C: &str = include_str!(concat!("x", "y"));
        "####;
        let found = include_targets(source);
        assert_eq!(found.len(), 4);
        assert_eq!(found[0], Ok("../README.md".to_owned()));
        assert_eq!(found[1], Ok("../shaders/a.wgsl".to_owned()));
        assert_eq!(found[2], Ok("data/b.bin".to_owned()));
        assert!(
            found[3]
                .as_ref()
                .unwrap_err()
                .contains("not a string literal")
        );
    }

    #[test]
    fn an_archive_holding_every_target_passes() {
        let mut names = files(&["src/lib.rs", "src/shader.rs", "shaders/a.wgsl"]);
        names.extend(files(&HEADER));
        let read = |f: &str| {
            Ok(match f {
                "src/lib.rs" => r#"#![doc = include_str!("../README.md")]"#.to_owned(),
                _ => r#"const A: &str = include_str!("../shaders/./a.wgsl");"#.to_owned(),
            })
        };
        assert_eq!(check_archive(&names, read), Ok((2, vec![])));
    }

    #[test]
    fn a_target_outside_the_folder_or_missing_from_the_archive_fails() {
        let mut names = files(&["src/shader.rs"]);
        names.extend(files(&HEADER));
        let read =
            |_: &str| {
                Ok(r#"include_str!("../../../shaders/a.wgsl"); include_str!("../shaders/b.wgsl");"#
                .to_owned())
            };
        let (count, problems) = check_archive(&names, read).unwrap();
        assert_eq!(count, 2);
        assert_eq!(problems.len(), 2, "{problems:?}");
        assert!(
            problems[0].contains("outside the crate's folder"),
            "{problems:?}"
        );
        assert!(problems[1].contains("shaders/b.wgsl, which is not in the archive"));
    }

    #[test]
    fn a_missing_readme_or_licence_fails_and_an_uncheckable_include_is_an_error() {
        let names = files(&["src/lib.rs", "README.md"]);
        let (_, problems) = check_archive(&names, |_| Ok(String::new())).unwrap();
        assert_eq!(problems.len(), 2, "{problems:?}");
        assert!(problems.iter().all(|p| p.contains("LICENSE-")));
        let uncheckable = check_archive(&names, |_| Ok("include_bytes!(PATH)".to_owned()));
        assert!(uncheckable.unwrap_err().contains("src/lib.rs"));
    }

    /// A build script's inputs must be archived: a folder by any file under it.
    #[test]
    fn a_build_script_s_inputs_must_be_in_the_archive() {
        let script = r#"fn main() { println!("cargo:rerun-if-changed=shaders"); }"#;
        assert_eq!(build_inputs(script), ["shaders"]);
        let read = |f: &str| {
            Ok(match f {
                "build.rs" => script.to_owned(),
                _ => String::new(),
            })
        };
        let mut archive = files(&["build.rs", "shaders/a.wgsl"]);
        archive.extend(files(&HEADER));
        let (_, problems) = check_archive(&archive, read).unwrap();
        assert!(problems.is_empty(), "{problems:?}");
        archive.retain(|f| !f.starts_with("shaders/"));
        archive.push("shaders.wgsl".to_owned());
        let (_, problems) = check_archive(&archive, read).unwrap();
        assert_eq!(
            problems,
            ["build.rs reads shaders, which is not in the archive"]
        );
    }

    #[test]
    fn libraries_are_the_publishable_crates_with_a_lib_target() {
        let json = r#"{"packages": [
            {"name": "b-lib", "manifest_path": "/w/crates/b/Cargo.toml", "publish": null,
             "targets": [{"kind": ["lib"]}, {"kind": ["test"]}]},
            {"name": "a-lib", "manifest_path": "/w/crates/a/Cargo.toml", "publish": null,
             "targets": [{"kind": ["lib"]}]},
            {"name": "internal", "manifest_path": "/w/crates/i/Cargo.toml", "publish": [],
             "targets": [{"kind": ["lib"]}]},
            {"name": "cli", "manifest_path": "/w/Cargo.toml", "publish": null,
             "targets": [{"kind": ["bin"]}]}
        ]}"#;
        let libs = libraries(json).unwrap();
        let names: Vec<&str> = libs.iter().map(|l| l.name.as_str()).collect();
        assert_eq!(names, ["a-lib", "b-lib"]);
        assert_eq!(libs[0].dir, Path::new("/w/crates/a"));
        assert!(libraries(r#"{"packages": []}"#).is_err());
    }
}
