//! The bounded, seeded run every kind's stress test goes through: proptest draws one scene per
//! case (a `TestRunner` with a fixed seed per test, so CI feeds the same inputs every time), the
//! case casts a batch of rays at it, and a tally per ray family counts what was checked.
//!
//! `FRAY_STRESS_SCALE` multiplies the number of cases (a longer run: `FRAY_STRESS_SCALE=10`);
//! `FRAY_STRESS_SEED` (a number) changes every test's seed, to explore beyond the fixed run.

use proptest::strategy::Strategy;
use proptest::test_runner::{Config, RngAlgorithm, TestCaseError, TestRng, TestRunner};
use std::sync::Mutex;

/// The multiplier on every test's case count (`FRAY_STRESS_SCALE`, default 1).
pub fn scale() -> f64 {
    std::env::var("FRAY_STRESS_SCALE")
        .ok()
        .and_then(|s| s.parse::<f64>().ok())
        .filter(|s| s.is_finite() && *s > 0.0)
        .unwrap_or(1.0)
}

/// `cases` scaled by [`scale`]: the cases a test runs.
pub fn cases(cases: u32) -> u64 {
    (f64::from(cases) * scale()).ceil() as u64
}

/// A fixed 32-byte seed from the test's name (FNV-1a), changed by `FRAY_STRESS_SEED`.
fn seed(name: &str) -> [u8; 32] {
    let extra = std::env::var("FRAY_STRESS_SEED")
        .ok()
        .and_then(|s| s.parse::<u64>().ok())
        .unwrap_or(0);
    let mut h: u64 = 0xcbf2_9ce4_8422_2325 ^ extra;
    let mut out = [0u8; 32];
    for (k, chunk) in out.chunks_mut(8).enumerate() {
        for b in name.bytes().chain([k as u8]) {
            h = (h ^ u64::from(b)).wrapping_mul(0x0100_0000_01b3);
        }
        chunk.copy_from_slice(&h.to_le_bytes());
    }
    out
}

/// Runs `cases × scale()` cases of `test` on values of `strategy`, seeded from `name`; panics
/// with proptest's (lightly shrunk) failing case.
pub fn run<S: Strategy>(
    name: &str,
    cases: u32,
    strategy: S,
    test: impl Fn(S::Value) -> Result<(), TestCaseError>,
) {
    let cases = u32::try_from(self::cases(cases)).unwrap_or(u32::MAX);
    let config = Config {
        cases,
        failure_persistence: None,
        // A failing case is a whole scene and its batch of rays: shrinking it far costs minutes.
        max_shrink_iters: 8,
        ..Config::default()
    };
    let mut runner = TestRunner::new_with_rng(
        config,
        TestRng::from_seed(RngAlgorithm::ChaCha, &seed(name)),
    );
    if let Err(e) = runner.run(&strategy, test) {
        panic!("{name}: {e}");
    }
}

/// What one family of rays saw: how many were cast, how many hit, and the largest of a
/// measured figure (a test says which: an early hit's distance, an error against a reference).
#[derive(Clone, Copy, Debug, Default)]
pub struct Family {
    pub rays: u64,
    pub hits: u64,
    /// Hits a test flags (each test says what: e.g. allowed only by rounding).
    pub flagged: u64,
    /// Flagged hits with no reference point near them.
    pub phantom: u64,
    /// Rays where the kind missed what the reference says it must find, in a regime the test
    /// states as a finding (not counted: a failure).
    pub missed: u64,
    pub worst: f64,
}

impl Family {
    /// Adds `other`'s counts and keeps the larger worst figure.
    pub fn merge(&mut self, other: &Family) {
        self.rays += other.rays;
        self.hits += other.hits;
        self.flagged += other.flagged;
        self.phantom += other.phantom;
        self.missed += other.missed;
        self.worst = self.worst.max(other.worst);
    }

    /// Counts one ray, a hit or not.
    pub fn count(&mut self, hit: bool) {
        self.rays += 1;
        self.hits += u64::from(hit);
    }
}

/// The tally of one test: a [`Family`] per named family, merged from its cases.
#[derive(Debug)]
pub struct Tally {
    name: &'static str,
    names: &'static [&'static str],
    worst_is: &'static str,
    families: Mutex<Vec<Family>>,
}

impl Tally {
    pub fn new(name: &'static str, names: &'static [&'static str], worst_is: &'static str) -> Self {
        Self {
            name,
            names,
            worst_is,
            families: Mutex::new(vec![Family::default(); names.len()]),
        }
    }

    /// Adds one case's families.
    pub fn add(&self, case: &[Family]) {
        let mut all = self.families.lock().expect("no test panicked holding it");
        for (a, c) in all.iter_mut().zip(case) {
            a.merge(c);
        }
    }

    /// Prints the tally (`--nocapture` shows it) and returns the rays cast in all.
    pub fn report(&self) -> u64 {
        let all = self.families.lock().expect("no test panicked holding it");
        let total: u64 = all.iter().map(|f| f.rays).sum();
        println!("{}: {total} rays; worst = {}", self.name, self.worst_is);
        for (n, f) in self.names.iter().zip(all.iter()) {
            println!(
                "  {n:<18} {:>9} rays {:>9} hits {:>7} flagged {:>7} phantom {:>5} missed  worst {:.3e}",
                f.rays, f.hits, f.flagged, f.phantom, f.missed, f.worst
            );
        }
        total
    }
}
