//! Property: updating a pyramid (and a terrain's heights) only where they changed gives the same
//! bits as building it again. Random maps (sizes not powers of two, long thin ones, holes of
//! `−∞` cells, thresholds), random changed rectangles (empty, one cell, the whole map, reaching
//! past it): [`Pyramid::update_max`] / [`Pyramid::update_min`] against [`Pyramid::max_of`] /
//! [`Pyramid::min_of`] of the new cells, and [`Terrain::with_heights`] against [`Terrain::new`]
//! of the new map — pyramids, min pyramid and height range, bilinear and bicubic.

mod common;

use common::Rng;
use fray_terrain::{Heightmap, Interpolation, Placement, Pyramid, Region, Terrain, TerrainOptions};
use glam::{DVec2, DVec3};
use proptest::prelude::*;

fn bits(p: &Pyramid) -> Vec<u32> {
    p.values().iter().map(|v| v.to_bits()).collect()
}

/// A rectangle of a `columns × rows` grid from four fractions, sometimes reaching past it.
fn rect(columns: usize, rows: usize, f: [f64; 4]) -> Region {
    let (x0, y0) = (
        (f[0] * columns as f64) as usize,
        (f[1] * rows as f64) as usize,
    );
    let (x1, y1) = (
        x0 + (f[2] * (columns + 2) as f64) as usize,
        y0 + (f[3] * (rows + 2) as f64) as usize,
    );
    Region::new(x0, y0, x1, y1)
}

fn cell(rng: &mut Rng, holes: f64) -> f32 {
    if rng.unit() < holes {
        f32::NEG_INFINITY
    } else {
        (rng.range(-50.0, 50.0) as f32).round() // ties between cells are common
    }
}

fn placement() -> Placement {
    Placement::new(DVec3::new(1.0, -2.0, 3.0), DVec2::new(0.7, 1.3), 0.4).unwrap()
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 400, ..ProptestConfig::default() })]

    #[test]
    fn an_updated_pyramid_is_a_rebuilt_one(
        columns in 1usize..80, rows in 1usize..80, seed in any::<u64>(),
        holes in prop_oneof![Just(0.0), 0.0..0.5],
        f in proptest::array::uniform4(0.0f64..1.0),
        thin in any::<bool>(),
    ) {
        let rows = if thin { 1 } else { rows };
        let mut rng = Rng(seed);
        let old: Vec<f32> = (0..columns * rows).map(|_| cell(&mut rng, holes)).collect();
        let changed = rect(columns, rows, f);
        let mut new = old.clone();
        let inside = changed.clamped(columns, rows);
        for j in inside.y0..inside.y1 {
            for i in inside.x0..inside.x1 {
                new[j * columns + i] = cell(&mut rng, holes);
            }
        }
        let mut max = Pyramid::max_of(columns, rows, &old);
        max.update_max(changed, |i, j| new[j * columns + i]);
        prop_assert_eq!(bits(&max), bits(&Pyramid::max_of(columns, rows, &new)));
        let mut min = Pyramid::min_of(columns, rows, &old);
        min.update_min(changed, |i, j| new[j * columns + i]);
        prop_assert_eq!(bits(&min), bits(&Pyramid::min_of(columns, rows, &new)));
    }

    #[test]
    fn a_terrain_with_new_heights_is_the_terrain_built_from_them(
        w in 2usize..48, h in 2usize..48, seed in any::<u64>(),
        f in proptest::array::uniform4(0.0f64..1.0),
        bicubic in any::<bool>(), threshold in proptest::option::of(-20.0f32..10.0),
        offset in prop_oneof![Just(0.0f32), Just(60.0f32)],
    ) {
        let mut rng = Rng(seed);
        let samples: Vec<f32> = (0..w * h).map(|_| rng.range(-30.0, 30.0) as f32 + offset).collect();
        let map = Heightmap::from_samples(w, h, samples).unwrap();
        let map = match threshold {
            Some(t) => map.with_threshold(t).unwrap(),
            None => map,
        };
        let options = TerrainOptions {
            interpolation: if bicubic { Interpolation::Bicubic } else { Interpolation::Bilinear },
            lod_bias: 0,
            min_pyramid: true,
        };
        let Ok(base) = Terrain::new(map.clone(), placement(), options) else {
            return Ok(()); // nothing solid to start from
        };
        let changed = rect(w, h, f);
        let moved = map
            .with_region(changed, |_, _, s| s + rng.range(-40.0, 40.0) as f32)
            .unwrap();
        let rebuilt = Terrain::new(moved.clone(), placement(), options);
        let updated = base.with_heights(moved, changed);
        match (updated, rebuilt) {
            (Ok(u), Ok(r)) => {
                prop_assert_eq!(bits(u.max_pyramid()), bits(r.max_pyramid()));
                prop_assert_eq!(bits(u.min_pyramid().unwrap()), bits(r.min_pyramid().unwrap()));
                prop_assert_eq!(u.height_range(), r.height_range());
                prop_assert_eq!(u.map(), r.map());
            }
            (Err(u), Err(r)) => prop_assert_eq!(u.to_string(), r.to_string()),
            (u, r) => prop_assert!(false, "update {:?} against build {:?}", u.is_ok(), r.is_ok()),
        }
    }
}

#[test]
fn a_map_of_another_size_is_refused() {
    let map = Heightmap::from_fn(4, 4, |i, j| (i * j) as f32).unwrap();
    let t = Terrain::new(map, placement(), TerrainOptions::default()).unwrap();
    let other = Heightmap::from_fn(5, 4, |_, _| 1.0).unwrap();
    let e = t.with_heights(other, Region::all(5, 4)).unwrap_err();
    assert!(
        e.to_string()
            .contains("a 5 × 4 map cannot replace the terrain's 4 × 4"),
        "{e}"
    );
}
