//! The bounded fuzz run on stable, part of `cargo test --workspace`: each target is fed its seed
//! corpus (`fuzz/corpus/<target>/`, every seed must load), every input fuzzing once broke
//! (`fuzz/regressions/<target>/`) and a fixed number ([`mutations`]) of deterministic mutations
//! of its seeds (proptest with a fixed seed, so every run feeds the same inputs). It fails on a
//! panic and on any input that takes longer than [`INPUT_TIME_BOUND`]; the failing input is
//! saved under `target/tmp/fuzz-failures/<target>/` and its path printed, ready for
//! `fuzz/regressions/`.

mod mutation;

use fray_fuzzing::{Outcome, Target};
use mutation::Mutation;
use proptest::test_runner::{Config, RngAlgorithm, TestCaseError, TestRng, TestRunner};
use std::path::{Path, PathBuf};
use std::sync::mpsc;
use std::time::{Duration, Instant};

/// The most one input may take: 5 s. Issue 22 asks every input to end "in seconds"; the slowest
/// seed (a scene with its included turboprop and a baked cloud layer) takes well under 0.1 s in
/// the test profile, so 5 s is a hang, not a slow machine.
const INPUT_TIME_BOUND: Duration = Duration::from_secs(5);

/// Mutated inputs per target: 8000 of a file (0.25–0.4 ms each in the test profile, on 2 cores
/// shared with the other targets), 2400 of a scene bundle (1.3–1.5 ms each: the largest inputs,
/// several files, whole scenes built) — 2 to 4 s per target.
fn mutations(target: Target) -> u32 {
    match target {
        Target::Scene => 2400,
        _ => 8000,
    }
}

/// The mutation stream's seed: fixed, so the run is the same on every machine.
const SEED: [u8; 32] = *b"fray: bounded fuzz run, seed #1.";

#[test]
fn scene() {
    bounded_run(Target::Scene);
}

#[test]
fn heightmap_png() {
    bounded_run(Target::HeightmapPng);
}

#[test]
fn heightmap_exr() {
    bounded_run(Target::HeightmapExr);
}

#[test]
fn heightmap_npy() {
    bounded_run(Target::HeightmapNpy);
}

#[test]
fn obj() {
    bounded_run(Target::Obj);
}

#[test]
fn inr() {
    bounded_run(Target::Inr);
}

#[test]
fn texture_png() {
    bounded_run(Target::TexturePng);
}

#[test]
fn texture_exr() {
    bounded_run(Target::TextureExr);
}

fn bounded_run(target: Target) {
    let started = Instant::now();
    let seeds = files(target, "corpus");
    assert!(!seeds.is_empty(), "{}: no seed corpus", target.name());
    let mut slowest = Duration::ZERO;
    for (path, bytes) in &seeds {
        match bounded(target, bytes.clone()) {
            Ok((Outcome::Accepted, took)) => slowest = slowest.max(took),
            Ok((Outcome::Refused(why), _)) => {
                panic!("the seed {} is refused: {why}", path.display())
            }
            Err(why) => panic!("the seed {}: {why}", path.display()),
        }
    }
    let regressions = files(target, "regressions");
    for (path, bytes) in &regressions {
        match bounded(target, bytes.clone()) {
            Ok((_, took)) => slowest = slowest.max(took),
            Err(why) => panic!("the regression {}: {why}", path.display()),
        }
    }
    let seeds: Vec<Vec<u8>> = seeds.into_iter().map(|(_, bytes)| bytes).collect();
    let slowest = std::cell::Cell::new(slowest);
    let config = Config {
        cases: mutations(target),
        failure_persistence: None,
        max_shrink_iters: 256,
        ..Config::default()
    };
    let mut runner =
        TestRunner::new_with_rng(config, TestRng::from_seed(RngAlgorithm::ChaCha, &SEED));
    let strategy = (
        0..seeds.len(),
        proptest::collection::vec(Mutation::strategy(), 1..=4),
    );
    let result = runner.run(&strategy, |(seed, mutations)| {
        let mut input = seeds[seed].clone();
        for m in &mutations {
            m.apply(&mut input, &seeds);
        }
        match bounded(target, input.clone()) {
            Ok((_, took)) => {
                slowest.set(slowest.get().max(took));
                Ok(())
            }
            Err(why) => {
                let saved = save_failure(target, &input);
                Err(TestCaseError::fail(format!(
                    "{why}; the input is saved as {}",
                    saved.display()
                )))
            }
        }
    });
    if let Err(e) = result {
        panic!("{}: {e}", target.name());
    }
    eprintln!(
        "{}: {} seeds, {} regressions, {} mutations in {:.2} s; slowest input {:.3} s",
        target.name(),
        seeds.len(),
        regressions.len(),
        mutations(target),
        started.elapsed().as_secs_f64(),
        slowest.get().as_secs_f64()
    );
}

/// Runs the target on `input` on its own thread: its outcome and time, or why it failed — a
/// panic's message, or that it ran past [`INPUT_TIME_BOUND`] (the thread is left to finish).
fn bounded(target: Target, input: Vec<u8>) -> Result<(Outcome, Duration), String> {
    let (send, receive) = mpsc::channel();
    let started = Instant::now();
    std::thread::Builder::new()
        .name(format!("fuzz-{}", target.name()))
        .spawn(move || {
            let outcome = std::panic::catch_unwind(|| target.run(&input));
            let _ = send.send(outcome);
        })
        .map_err(|e| format!("cannot start a thread: {e}"))?;
    match receive.recv_timeout(INPUT_TIME_BOUND) {
        Ok(Ok(outcome)) => Ok((outcome, started.elapsed())),
        Ok(Err(panic)) => {
            let message = panic
                .downcast_ref::<String>()
                .cloned()
                .or_else(|| panic.downcast_ref::<&str>().map(|s| (*s).to_owned()))
                .unwrap_or_else(|| "a panic without a message".to_owned());
            Err(format!("panicked: {message}"))
        }
        Err(_) => Err(format!("ran longer than {INPUT_TIME_BOUND:?}")),
    }
}

/// The files of `fuzz/<kind>/<target>/` (none if the folder does not exist), by name.
fn files(target: Target, kind: &str) -> Vec<(PathBuf, Vec<u8>)> {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../fuzz")
        .join(kind)
        .join(target.name());
    let Ok(entries) = std::fs::read_dir(&dir) else {
        return Vec::new();
    };
    let mut paths: Vec<PathBuf> = entries
        .map(|e| e.expect("a folder entry").path())
        .filter(|p| p.is_file())
        .collect();
    paths.sort();
    paths
        .into_iter()
        .map(|p| {
            let bytes = std::fs::read(&p).unwrap_or_else(|e| panic!("{}: {e}", p.display()));
            (p, bytes)
        })
        .collect()
}

/// Saves a failing input under the target folder's `fuzz-failures/<target>/`, named by its
/// FNV-1a hash; returns its path.
fn save_failure(target: Target, input: &[u8]) -> PathBuf {
    let hash = input.iter().fold(0xcbf2_9ce4_8422_2325u64, |h, &b| {
        (h ^ u64::from(b)).wrapping_mul(0x100_0000_01b3)
    });
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR"))
        .join("fuzz-failures")
        .join(target.name());
    let path = dir.join(format!("{hash:016x}"));
    if let Err(e) = std::fs::create_dir_all(&dir).and_then(|()| std::fs::write(&path, input)) {
        eprintln!("cannot save the failing input as {}: {e}", path.display());
    }
    path
}
