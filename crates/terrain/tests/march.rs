//! The fixed-step march (the baseline the pyramid search is measured against): it finds the
//! brute-force hit to within a step, and a march of more than `MAX_MARCH_STEPS` steps across the
//! terrain's box is refused at once, naming its steps and the cap.

mod common;

use common::rough_map;
use fray_core::{Interval, Ray};
use fray_terrain::{MAX_MARCH_STEPS, Placement, Terrain, TerrainError, TerrainOptions};
use glam::{DVec2, DVec3};

fn terrain() -> Terrain {
    let placement = Placement::new(DVec3::ZERO, DVec2::new(1.0, 1.0), 0.5).unwrap();
    Terrain::new(rough_map(33, 29, 7), placement, TerrainOptions::default()).unwrap()
}

/// A ray from above one side of the box down through its centre.
fn ray(t: &Terrain) -> Ray {
    let (lo, hi) = t.map_box();
    let centre = t.placement().to_world(0.5 * (lo + hi));
    let eye = centre + DVec3::new(-10.0, 30.0, -7.0);
    Ray::new(eye, centre - eye).unwrap()
}

#[test]
fn the_march_finds_the_hit_to_within_its_step() {
    let t = terrain();
    let ray = ray(&t);
    let all = Interval::new(0.0, f64::INFINITY);
    let exact = t
        .cast_brute_force(&ray, all, 1e-9)
        .expect("the ray meets the map")
        .t;
    let step = 0.01;
    let marched = t.march(&ray, all, step).unwrap().expect("a hit");
    assert!((marched - exact).abs() <= step, "{marched} vs {exact}");
}

#[test]
fn a_march_past_its_cap_is_refused_naming_its_steps() {
    // The bound: ⌈length in the box / step⌉ ≤ MAX_MARCH_STEPS = 2²⁴. A step of 1e-9 across a
    // box tens of units long would take ~1e10 steps (minutes): refused before the first.
    let t = terrain();
    let ray = ray(&t);
    let all = Interval::new(0.0, f64::INFINITY);
    let e = t.march(&ray, all, 1e-9).unwrap_err();
    let TerrainError::MarchSteps { length, steps, .. } = e else {
        panic!("expected MarchSteps, got {e}");
    };
    assert!(steps > MAX_MARCH_STEPS as f64 && steps == (length / 1e-9).ceil());
    assert!(
        e.to_string()
            .contains(&format!("over the cap of {MAX_MARCH_STEPS}")),
        "{e}"
    );
    // The same ray at the step that takes exactly the cap is marched.
    let at_cap = length / MAX_MARCH_STEPS as f64;
    assert!(t.march(&ray, all, at_cap * (1.0 + 1e-12)).is_ok());
}
