//! fray's fuzz targets, defined once: one function per parser, each taking the fuzzer's bytes as
//! a file (or, for scenes, a bundle of files) written into a scratch folder and loaded through the
//! same public entry point the renderer uses, under a small memory budget
//! ([`FUZZ_BUDGET_BYTES`]) so that a huge declared size is refused rather than allocated.
//!
//! The cargo-fuzz targets in `fuzz/fuzz_targets/` call these functions; so does the bounded run
//! on stable (`tests/bounded.rs`), which feeds each target its seed corpus (`fuzz/corpus/`), the
//! inputs fuzzing once broke (`fuzz/regressions/`) and a fixed number of deterministic mutations.
//! A body returns normally for every input, accepted or refused; it panics only when a loader
//! does or when an accepted result breaks what the loader promises (its size limits, the
//! budget). `docs/fuzzing.md` says how to run them.

mod bundle;
mod png_crc;
mod scratch;

pub use bundle::{Bundle, MAIN_FILE, SEPARATOR};
pub use png_crc::fix_png_crcs;

use fray_core::MemoryBudget;
use fray_mesh::texture::{self, Encoding};
use fray_mesh::{Texture, TriangleMesh};
use fray_terrain::Heightmap;
use scratch::Scratch;

/// The memory budget every target loads under: 256 MiB. Far below the fuzzer's 2 GiB RSS limit
/// (`-rss_limit_mb=2048`), so an input whose declared size passes the budget is a finding —
/// not an out-of-memory abort — and far above what any seed needs (the largest holds a few KB).
pub const FUZZ_BUDGET_BYTES: u64 = 256 << 20;

/// What a loader made of an input (the fuzzer ignores it; the stable run checks that every seed
/// is accepted, so the corpus reaches past the first refusal).
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum Outcome {
    /// Loaded.
    Accepted,
    /// Refused, with the loader's message.
    Refused(String),
}

/// One fuzz target: a parser and the file name its input is written to.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Target {
    /// A scene and the files it includes or names (`fray_scene::load_with`), as a [`Bundle`].
    Scene,
    /// A PNG height map (`Heightmap::load_within`), its chunks' CRCs fixed first.
    HeightmapPng,
    /// An OpenEXR height map (`Heightmap::load_within`).
    HeightmapExr,
    /// A NumPy `.npy` height map (`Heightmap::load_within`).
    HeightmapNpy,
    /// An OBJ mesh (`TriangleMesh::load_obj`).
    Obj,
    /// An INRIMAGE-4 volume (`fray_clouds::inr::load`).
    Inr,
    /// A PNG texture (`Texture::load`, sRGB), its chunks' CRCs fixed first.
    TexturePng,
    /// An OpenEXR texture (`Texture::load`).
    TextureExr,
}

impl Target {
    /// Every target, in the order the docs list them.
    pub const ALL: [Target; 8] = [
        Target::Scene,
        Target::HeightmapPng,
        Target::HeightmapExr,
        Target::HeightmapNpy,
        Target::Obj,
        Target::Inr,
        Target::TexturePng,
        Target::TextureExr,
    ];

    /// The target's name: its cargo-fuzz target and its folders under `fuzz/corpus/` and
    /// `fuzz/regressions/`.
    pub fn name(self) -> &'static str {
        match self {
            Target::Scene => "scene",
            Target::HeightmapPng => "heightmap_png",
            Target::HeightmapExr => "heightmap_exr",
            Target::HeightmapNpy => "heightmap_npy",
            Target::Obj => "obj",
            Target::Inr => "inr",
            Target::TexturePng => "texture_png",
            Target::TextureExr => "texture_exr",
        }
    }

    /// Runs the target's body on `data`.
    pub fn run(self, data: &[u8]) -> Outcome {
        match self {
            Target::Scene => scene(data),
            Target::HeightmapPng => heightmap_png(data),
            Target::HeightmapExr => heightmap_exr(data),
            Target::HeightmapNpy => heightmap_npy(data),
            Target::Obj => obj(data),
            Target::Inr => inr(data),
            Target::TexturePng => texture_png(data),
            Target::TextureExr => texture_exr(data),
        }
    }
}

/// A scene bundle ([`Bundle`]: the main file and the files it includes or names) written into a
/// scratch folder and loaded by `fray_scene::load_with` under the fuzz budget.
pub fn scene(data: &[u8]) -> Outcome {
    let bundle = Bundle::split(data);
    let scratch = Scratch::new();
    for (name, bytes) in &bundle.files {
        scratch.write(name, bytes);
    }
    let budget = MemoryBudget::new(FUZZ_BUDGET_BYTES);
    let options = fray_scene::BuildOptions::within(budget.clone());
    let outcome = match fray_scene::load_with(&scratch.path(MAIN_FILE), &options) {
        Ok(scene) => {
            assert!(scene.width >= 1 && scene.width <= fray_scene::MAX_IMAGE_SIDE);
            assert!(scene.height >= 1 && scene.height <= fray_scene::MAX_IMAGE_SIDE);
            Outcome::Accepted
        }
        Err(e) => refused(&e),
    };
    within_budget(&budget);
    outcome
}

/// A PNG height map (chunk CRCs fixed by [`fix_png_crcs`], so mutations reach the decoder).
pub fn heightmap_png(data: &[u8]) -> Outcome {
    heightmap("map.png", &fix_png_crcs(data))
}

/// An OpenEXR height map.
pub fn heightmap_exr(data: &[u8]) -> Outcome {
    heightmap("map.exr", data)
}

/// A NumPy `.npy` height map.
pub fn heightmap_npy(data: &[u8]) -> Outcome {
    heightmap("map.npy", data)
}

fn heightmap(file: &str, data: &[u8]) -> Outcome {
    let scratch = Scratch::new();
    let path = scratch.write(file, data);
    let budget = MemoryBudget::new(FUZZ_BUDGET_BYTES);
    let outcome = match Heightmap::load_within(&path, &budget) {
        Ok(map) => {
            let (w, h) = (map.width(), map.height());
            assert!((2..=fray_terrain::MAX_SIDE).contains(&w), "width {w}");
            assert!((2..=fray_terrain::MAX_SIDE).contains(&h), "height {h}");
            assert!(w * h <= fray_terrain::MAX_SAMPLES);
            assert_eq!(map.samples().len(), w * h);
            assert!(map.samples().iter().all(|s| s.is_finite()));
            Outcome::Accepted
        }
        Err(e) => refused(&e),
    };
    within_budget(&budget);
    outcome
}

/// An OBJ mesh.
pub fn obj(data: &[u8]) -> Outcome {
    let scratch = Scratch::new();
    let path = scratch.write("mesh.obj", data);
    let budget = MemoryBudget::new(FUZZ_BUDGET_BYTES);
    let outcome = match TriangleMesh::load_obj(&path, &budget) {
        Ok(mesh) => {
            let n = mesh.positions.len();
            assert!(!mesh.triangles.is_empty());
            assert!(mesh.triangles.iter().flatten().all(|&i| (i as usize) < n));
            assert!(mesh.normals.len() == n);
            Outcome::Accepted
        }
        Err(e) => refused(&e),
    };
    within_budget(&budget);
    outcome
}

/// An INRIMAGE-4 volume.
pub fn inr(data: &[u8]) -> Outcome {
    let scratch = Scratch::new();
    let path = scratch.write("volume.inr", data);
    let budget = MemoryBudget::new(FUZZ_BUDGET_BYTES);
    let outcome = match fray_clouds::inr::load(&path, &budget) {
        Ok(volume) => {
            assert!(volume.voxel_size.iter().all(|v| v.is_finite() && *v > 0.0));
            Outcome::Accepted
        }
        Err(e) => refused(&e),
    };
    within_budget(&budget);
    outcome
}

/// A PNG texture, sRGB-decoded (chunk CRCs fixed by [`fix_png_crcs`]).
pub fn texture_png(data: &[u8]) -> Outcome {
    texture_file("texture.png", &fix_png_crcs(data))
}

/// An OpenEXR texture.
pub fn texture_exr(data: &[u8]) -> Outcome {
    texture_file("texture.exr", data)
}

fn texture_file(file: &str, data: &[u8]) -> Outcome {
    let scratch = Scratch::new();
    let path = scratch.write(file, data);
    let budget = MemoryBudget::new(FUZZ_BUDGET_BYTES);
    let outcome = match Texture::load(&path, Encoding::Srgb, &budget) {
        Ok(t) => {
            let max = texture::MAX_SIDE;
            assert!(t.width() >= 1 && t.width() <= max, "width {}", t.width());
            assert!(
                t.height() >= 1 && t.height() <= max,
                "height {}",
                t.height()
            );
            let last = t.level(t.level_count() - 1);
            assert_eq!(
                (last.width(), last.height()),
                (1, 1),
                "the mip chain ends at 1 × 1"
            );
            Outcome::Accepted
        }
        Err(e) => refused(&e),
    };
    within_budget(&budget);
    outcome
}

/// A refusal must say why: its message is formatted (as the CLI would) and not empty.
fn refused(e: &dyn std::error::Error) -> Outcome {
    let message = e.to_string();
    assert!(!message.is_empty(), "an error without a message");
    Outcome::Refused(message)
}

/// Whatever a load charged for good stays within the limit.
fn within_budget(budget: &MemoryBudget) {
    assert!(
        budget.charged() <= budget.bytes(),
        "charged {} over the limit {}",
        budget.charged(),
        budget.bytes()
    );
}
