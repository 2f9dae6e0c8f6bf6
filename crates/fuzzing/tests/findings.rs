//! What fuzzing found, each finding's input (`fuzz/regressions/`) with the refusal it now gets.
//! `tests/bounded.rs` replays them all for panics and time; this checks the message too, where
//! it does not depend on the build profile.

use fray_fuzzing::{Outcome, Target};
use std::path::Path;

fn regression(target: Target, file: &str) -> Vec<u8> {
    let path = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../fuzz/regressions")
        .join(target.name())
        .join(file);
    std::fs::read(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display()))
}

fn refusal(target: Target, file: &str) -> String {
    match target.run(&regression(target, file)) {
        Outcome::Refused(why) => why,
        Outcome::Accepted => panic!("{file} is accepted by {}", target.name()),
    }
}

/// A PLTE chunk of 59 bytes (not a multiple of 3): png 0.18.1 indexes past the palette while it
/// expands it and panics — in every build profile. Height maps and textures alike now refuse the
/// file, naming the decoder.
#[test]
fn a_palette_of_59_bytes_is_refused_not_a_panic() {
    for target in [Target::HeightmapPng, Target::TexturePng] {
        let why = refusal(target, "palette_59_bytes.png");
        assert!(
            why.contains("the PNG decoder failed on this file")
                && why.contains("out of range for slice"),
            "{}: {why}",
            target.name()
        );
    }
}
