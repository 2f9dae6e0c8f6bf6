//! cargo-fuzz target `heightmap_png`: `fray_fuzzing::heightmap_png` on each input.
#![no_main]

libfuzzer_sys::fuzz_target!(|data: &[u8]| {
    let _ = fray_fuzzing::heightmap_png(data);
});
