//! Property: the max pyramid never drops a segment that holds a hit. On random maps (random
//! sizes, not powers of two, random thresholds cutting holes) and random rays, the pyramid
//! search finds exactly the brute-force hit over every cell (bilinear: the same `t` bit for bit;
//! bicubic: within the root tolerance), and never a hit where brute force finds none.

mod common;

use common::Rng;
use fray_core::{Interval, Ray};
use fray_terrain::{Heightmap, Interpolation, Placement, Terrain, TerrainOptions};
use glam::{DVec2, DVec3};
use proptest::prelude::*;

fn build(w: usize, h: usize, seed: u64, threshold: f32, bicubic: bool) -> Option<Terrain> {
    let mut rng = Rng(seed);
    let amp = rng.range(0.1, 30.0) as f32;
    let samples = (0..w * h).map(|_| (rng.unit() as f32) * amp).collect();
    let map = Heightmap::from_samples(w, h, samples).ok()?;
    let map = map.with_threshold(threshold * amp).ok()?;
    let placement = Placement::new(DVec3::new(-3.0, 1.0, 2.0), DVec2::new(0.8, 1.7), 0.3).ok()?;
    let options = TerrainOptions {
        interpolation: if bicubic {
            Interpolation::Bicubic
        } else {
            Interpolation::Bilinear
        },
        ..TerrainOptions::default()
    };
    Terrain::new(map, placement, options).ok()
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 512, ..ProptestConfig::default() })]

    #[test]
    fn pyramid_never_drops_a_hit(
        w in 2usize..40, h in 2usize..40, seed in any::<u64>(),
        threshold in prop_oneof![Just(-1.0f32), 0.0f32..0.5],
        bicubic in any::<bool>(),
        rays in proptest::collection::vec(
            (0.0f64..1.0, 0.0f64..1.0, 0.0f64..1.0, -1.0f64..1.0, -1.0f64..0.2, -1.0f64..1.0, 0.0f64..40.0),
            40,
        ),
    ) {
        let Some(t) = build(w, h, seed, threshold, bicubic) else { return Ok(()) };
        let (lo, hi) = t.map_box();
        let eps = 1e-9;
        for (a, b, c, dx, dy, dz, back) in rays {
            let target = t.placement().to_world(lo + (hi - lo) * DVec3::new(a, b, c));
            let Some(ray) = Ray::new(target - DVec3::new(dx, dy, dz) * back, DVec3::new(dx, dy, dz)) else {
                continue;
            };
            let range = Interval::new(0.0, f64::INFINITY);
            let got = t.cast(&ray, range, eps).map(|h| h.t);
            let want = t.cast_brute_force(&ray, range, eps).map(|h| h.t);
            match (got, want) {
                (Some(g), Some(w)) if bicubic => prop_assert!((g - w).abs() <= 2.0 * eps, "{g} vs {w}"),
                (g, w) => prop_assert_eq!(g, w),
            }
        }
    }
}
