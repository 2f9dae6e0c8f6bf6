//! cargo-fuzz target `heightmap_npy`: `fray_fuzzing::heightmap_npy` on each input.
#![no_main]

libfuzzer_sys::fuzz_target!(|data: &[u8]| {
    let _ = fray_fuzzing::heightmap_npy(data);
});
