//! cargo-fuzz target `texture_png`: `fray_fuzzing::texture_png` on each input.
#![no_main]

libfuzzer_sys::fuzz_target!(|data: &[u8]| {
    let _ = fray_fuzzing::texture_png(data);
});
