//! cargo-fuzz target `scene`: `fray_fuzzing::scene` on each input.
#![no_main]

libfuzzer_sys::fuzz_target!(|data: &[u8]| {
    let _ = fray_fuzzing::scene(data);
});
