//! cargo-fuzz target `inr`: `fray_fuzzing::inr` on each input.
#![no_main]

libfuzzer_sys::fuzz_target!(|data: &[u8]| {
    let _ = fray_fuzzing::inr(data);
});
