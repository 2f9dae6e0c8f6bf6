//! The free-form kernel's frame counters: one Rust table of slots, from which the shader
//! prelude's constants are generated and the read-back words are decoded, so the WGSL and the
//! Rust side cannot drift apart.
//!
//! Each pixel adds to a workgroup sum (`group_counts[COUNT_…]`); one invocation per workgroup
//! adds the sums to the frame's counter buffer (`counters[WORD_…]`). Hits and shadow rays take
//! one 32-bit word each; the evaluation and terrain counters, which can pass 2³² in a frame, a
//! pair of words (low, high) that the kernel carries into.

/// A counter the kernel sums, in the order of its workgroup slots.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Counter {
    Hits,
    ShadowRays,
    BoundEvaluations,
    PointEvaluations,
    TerrainRays,
    TerrainSegments,
    TerrainCells,
    TerrainStops,
    TerrainStopLevels,
    /// The cloud march's density samples of camera rays (the media pass).
    CloudSamples,
    /// Camera rays cast at a mesh instance: one per ray and instance searched (the mesh
    /// intersection pass; fray-trace's `mesh_rays`).
    MeshRays,
    /// Whitted's reflected and refracted rays traced (fray-trace's `secondary_rays`).
    SecondaryRays,
    /// Secondary rays that found the band's queue full (the frame is rendered again in
    /// smaller bands; 0 in a frame that is kept).
    QueueOverflows,
}

/// Every counter, in workgroup-slot order.
pub const ALL: [Counter; 13] = [
    Counter::Hits,
    Counter::ShadowRays,
    Counter::BoundEvaluations,
    Counter::PointEvaluations,
    Counter::TerrainRays,
    Counter::TerrainSegments,
    Counter::TerrainCells,
    Counter::TerrainStops,
    Counter::TerrainStopLevels,
    Counter::CloudSamples,
    Counter::MeshRays,
    Counter::SecondaryRays,
    Counter::QueueOverflows,
];

/// 32-bit words of the counters proper.
pub const COUNTER_WORDS: usize = 23;

/// Whitted's queue state, in words after the counters (one band's; reset per band): the next
/// free queue slot, the level being processed, the current dispatch's range of slots, and per
/// level its range of slots in `paths`.
pub const QUEUE_TOP: usize = COUNTER_WORDS;
pub const QUEUE_DEPTH: usize = QUEUE_TOP + 1;
pub const QUEUE_CURRENT_START: usize = QUEUE_TOP + 2;
pub const QUEUE_CURRENT_COUNT: usize = QUEUE_TOP + 3;
/// `LEVEL_START + d`, `LEVEL_END + d` for levels `d = 0..=MAX_DEPTH` (0: the camera rays).
pub const LEVEL_START: usize = QUEUE_TOP + 4;
pub const LEVEL_END: usize = LEVEL_START + fray_scene::MAX_DEPTH as usize + 1;
/// Words of the queue state.
pub const QUEUE_WORDS: usize = LEVEL_END + fray_scene::MAX_DEPTH as usize + 1 - QUEUE_TOP;

/// 32-bit words in the frame's counter buffer: the counters, then the queue state.
pub const WORDS: usize = COUNTER_WORDS + QUEUE_WORDS;

impl Counter {
    /// Its slot in the workgroup sums.
    pub const fn slot(self) -> u32 {
        self as u32
    }

    /// Whether it is a 64-bit pair of words.
    pub const fn wide(self) -> bool {
        !matches!(
            self,
            Counter::Hits | Counter::ShadowRays | Counter::QueueOverflows
        )
    }

    /// Its (first) word in the frame's counter buffer.
    pub const fn word(self) -> u32 {
        match self {
            Counter::Hits => 0,
            Counter::ShadowRays => 1,
            Counter::QueueOverflows => COUNTER_WORDS as u32 - 1,
            // The pairs follow the two single words, in slot order.
            wide => 2 + 2 * (wide as u32 - 2),
        }
    }

    /// The suffix of its WGSL constants (`COUNT_…`, `WORD_…`).
    const fn wgsl_name(self) -> &'static str {
        match self {
            Counter::Hits => "HITS",
            Counter::ShadowRays => "SHADOW_RAYS",
            Counter::BoundEvaluations => "BOUND_EVALUATIONS",
            Counter::PointEvaluations => "POINT_EVALUATIONS",
            Counter::TerrainRays => "TERRAIN_RAYS",
            Counter::TerrainSegments => "TERRAIN_SEGMENTS",
            Counter::TerrainCells => "TERRAIN_CELLS",
            Counter::TerrainStops => "TERRAIN_STOPS",
            Counter::TerrainStopLevels => "TERRAIN_STOP_LEVELS",
            Counter::CloudSamples => "CLOUD_SAMPLES",
            Counter::MeshRays => "MESH_RAYS",
            Counter::SecondaryRays => "SECONDARY_RAYS",
            Counter::QueueOverflows => "QUEUE_OVERFLOWS",
        }
    }

    /// Its value in the read-back buffer `words` (0 if the buffer is too short).
    pub fn read(self, words: &[u32]) -> u64 {
        let at = |k: u32| words.get(k as usize).copied().map_or(0, u64::from);
        if self.wide() {
            at(self.word()) | (at(self.word() + 1) << 32)
        } else {
            at(self.word())
        }
    }
}

/// The WGSL constants of the layout: `COUNT_<NAME>` (workgroup slot) and `WORD_<NAME>` (buffer
/// word) per counter, `GROUP_COUNTERS` and `COUNTER_WORDS`.
pub fn wgsl_constants() -> Vec<(String, u32)> {
    let mut c: Vec<(String, u32)> = ALL
        .iter()
        .flat_map(|&k| {
            [
                (format!("COUNT_{}", k.wgsl_name()), k.slot()),
                (format!("WORD_{}", k.wgsl_name()), k.word()),
            ]
        })
        .collect();
    c.push(("GROUP_COUNTERS".into(), ALL.len() as u32));
    c.push(("COUNTER_WORDS".into(), WORDS as u32));
    for (name, word) in [
        ("WORD_QUEUE_TOP", QUEUE_TOP),
        ("WORD_QUEUE_DEPTH", QUEUE_DEPTH),
        ("WORD_QUEUE_CURRENT_START", QUEUE_CURRENT_START),
        ("WORD_QUEUE_CURRENT_COUNT", QUEUE_CURRENT_COUNT),
        ("WORD_LEVEL_START", LEVEL_START),
        ("WORD_LEVEL_END", LEVEL_END),
    ] {
        c.push((name.into(), word as u32));
    }
    c
}

/// The WGSL tables `flush_counts` (counters.wgsl) walks: per workgroup slot, its first word
/// (`COUNTER_WORD`) and whether it is a 64-bit pair (`COUNTER_WIDE`).
pub fn wgsl_tables() -> String {
    let words: Vec<String> = ALL.iter().map(|c| format!("{}u", c.word())).collect();
    let wide: Vec<String> = ALL.iter().map(|c| c.wide().to_string()).collect();
    format!(
        "const COUNTER_WORD: array<u32, {n}> = array<u32, {n}>({});\nconst COUNTER_WIDE: array<bool, {n}> = array<bool, {n}>({});\n",
        words.join(", "),
        wide.join(", "),
        n = ALL.len()
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn slots_are_in_order_and_words_tile_the_buffer_without_overlap() {
        let mut used = [false; COUNTER_WORDS];
        for (k, c) in ALL.iter().enumerate() {
            assert_eq!(c.slot() as usize, k);
            let n = if c.wide() { 2 } else { 1 };
            for w in c.word()..c.word() + n {
                let w = w as usize;
                assert!(w < COUNTER_WORDS, "{c:?} past the counters");
                assert!(!used[w], "{c:?} overlaps");
                used[w] = true;
            }
        }
        assert!(used.iter().all(|&u| u), "every word is a counter's");
        // The queue state follows, its level tables one word per level each.
        assert_eq!(QUEUE_TOP, COUNTER_WORDS);
        assert_eq!(LEVEL_END - LEVEL_START, fray_scene::MAX_DEPTH as usize + 1);
        assert_eq!(COUNTER_WORDS + QUEUE_WORDS, WORDS);
        assert_eq!(LEVEL_END + fray_scene::MAX_DEPTH as usize + 1, WORDS);
    }

    #[test]
    fn wide_counters_read_as_pairs() {
        let mut words = [0u32; WORDS];
        words[Counter::Hits.word() as usize] = 7;
        let w = Counter::PointEvaluations.word() as usize;
        (words[w], words[w + 1]) = (5, 2);
        assert_eq!(Counter::Hits.read(&words), 7);
        assert_eq!(Counter::PointEvaluations.read(&words), (2u64 << 32) | 5);
        assert_eq!(Counter::TerrainStops.read(&words[..3]), 0);
    }
}
