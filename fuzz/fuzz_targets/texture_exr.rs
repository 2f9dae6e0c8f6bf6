//! cargo-fuzz target `texture_exr`: `fray_fuzzing::texture_exr` on each input.
#![no_main]

libfuzzer_sys::fuzz_target!(|data: &[u8]| {
    let _ = fray_fuzzing::texture_exr(data);
});
