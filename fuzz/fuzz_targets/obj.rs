//! cargo-fuzz target `obj`: `fray_fuzzing::obj` on each input.
#![no_main]

libfuzzer_sys::fuzz_target!(|data: &[u8]| {
    let _ = fray_fuzzing::obj(data);
});
