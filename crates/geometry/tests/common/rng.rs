//! The tests' and benchmarks' random stream: `fray-test-support`'s (SplitMix64, the same numbers
//! on every machine).

pub use fray_test_support::Rng;
