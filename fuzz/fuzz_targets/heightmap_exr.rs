//! cargo-fuzz target `heightmap_exr`: `fray_fuzzing::heightmap_exr` on each input.
#![no_main]

libfuzzer_sys::fuzz_target!(|data: &[u8]| {
    let _ = fray_fuzzing::heightmap_exr(data);
});
