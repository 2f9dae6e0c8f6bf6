//! The caps on what a cloud costs, checked before anything runs: a view ray's march takes at most
//! `MAX_RAY_SAMPLES` density samples (view steps across the region's diagonal × (1 + sun
//! steps)), a bake at most `MAX_BAKE_WORK` units (cells × cost per cell); refusals name the
//! cost and the cap and come before any allocation.

use fray_clouds::bake::{Region, bake};
use fray_clouds::cost::{
    MAX_BAKE_WORK, MAX_RAY_SAMPLES, MarchCost, WORLEY_OCTAVE_COST, check_bake,
};
use fray_clouds::fractal::Fractal;
use fray_clouds::march::MarchSettings;
use fray_clouds::{CloudField, CloudsError, Unbounded};
use fray_core::MemoryBudget;

const UNIT: Region = Region {
    min: [0.0; 3],
    max: [1.0; 3],
};

fn settings(step: f64, sun_steps: u32) -> MarchSettings {
    MarchSettings {
        step,
        sun_steps,
        ..MarchSettings::default()
    }
}

#[test]
fn a_march_costs_its_diagonal_over_its_step_times_one_plus_its_sun_steps() {
    // √3 / 0.01 = 173.2: 174 view steps, each with 6 sun steps.
    assert_eq!(
        settings(0.01, 6).cost(&UNIT).unwrap(),
        MarchCost {
            view_steps: 174,
            samples: 174 * 7
        }
    );
    // A step longer than the box is one step.
    assert_eq!(settings(10.0, 0).cost(&UNIT).unwrap().samples, 1);
    // The cap itself passes, one view step more does not: 2¹⁶ = 8192 × (1 + 7).
    let edge = Region {
        min: [0.0; 3],
        max: [8192.0, 0.0, 0.0],
    };
    assert_eq!(
        settings(1.0, 7).cost(&edge).unwrap().samples,
        MAX_RAY_SAMPLES
    );
    let past = Region {
        max: [8192.5, 0.0, 0.0],
        ..edge
    };
    assert!(matches!(
        settings(1.0, 7).cost(&past),
        Err(CloudsError::MarchSamples {
            samples, limit, ..
        }) if samples == 8193.0 * 8.0 && limit == MAX_RAY_SAMPLES
    ));
}

#[test]
fn a_march_past_its_cap_is_refused_naming_its_steps_and_the_cap() {
    // The reproducers: a step of 1e-7 in a unit box (1.7e7 view steps), a region of
    // ±1e300 (its diagonal computed without overflow) at a step of 1.
    let e = settings(1e-7, 6).cost(&UNIT).unwrap_err().to_string();
    assert!(
        e.contains(
            "takes 17320509 view steps, each with 6 sun steps: 121243563 density samples per ray, over the cap of 65536"
        ),
        "{e}"
    );
    let huge = Region {
        min: [-1e300; 3],
        max: [1e300; 3],
    };
    assert!((huge.diagonal() / (2e300 * 3f64.sqrt()) - 1.0).abs() < 1e-15);
    let e = settings(1.0, 6).cost(&huge).unwrap_err().to_string();
    assert!(
        e.contains("diagonal 3.464e300 in steps of 1 takes 3.464e300 view steps"),
        "{e}"
    );
    // A step that is not a finite number > 0 is no march either.
    for step in [0.0, -1.0, f64::NAN] {
        assert!(settings(step, 6).cost(&UNIT).is_err(), "step {step}");
    }
}

#[test]
fn a_bake_costs_its_cells_times_octaves_and_worley() {
    let field = |octaves, worley| CloudField {
        noise: Fractal {
            octaves,
            ..Fractal::default()
        },
        worley,
        ..CloudField::default()
    };
    // One for the cell, one per octave, WORLEY_OCTAVE_COST per Worley octave (at most 3).
    assert_eq!(field(5, 0.0).cell_cost(), 6);
    assert_eq!(field(5, 0.5).cell_cost(), 6 + 3 * WORLEY_OCTAVE_COST);
    assert_eq!(field(2, 0.5).cell_cost(), 3 + 2 * WORLEY_OCTAVE_COST);
    assert_eq!(
        check_bake(&field(5, 0.0), 2, [10, 20, 30]).ok(),
        Some(6000 * 8)
    );
    // 512³ cells of 8 units is the cap exactly; one cell more is past it.
    assert_eq!(
        check_bake(&field(7, 0.0), 0, [512, 512, 512]).ok(),
        Some(MAX_BAKE_WORK)
    );
    assert!(check_bake(&field(7, 0.0), 0, [512, 512, 513]).is_err());
    // No overflow, whatever the sizes.
    assert!(check_bake(&field(12, 1.0), u64::MAX, [usize::MAX; 3]).is_err());
}

#[test]
fn a_1024_cubed_bake_is_refused_before_its_grid_is_allocated() {
    // 2³⁰ cells of at least 2 units each: twice the cap even at one octave; refused before
    // the 4 GiB grid exists, whatever the budget.
    let field = CloudField {
        noise: Fractal {
            octaves: 1,
            ..Fractal::default()
        },
        ..CloudField::default()
    };
    let region = Region {
        min: [-4000.0, field.base, -4000.0],
        max: [4000.0, field.top, 4000.0],
    };
    let e = bake(
        &field,
        &Unbounded,
        region,
        [1024; 3],
        &MemoryBudget::unlimited(),
        |_, _| panic!("nothing is baked"),
    )
    .unwrap_err();
    assert!(
        matches!(
            e,
            CloudsError::BakeWork {
                per_cell: 2,
                limit: MAX_BAKE_WORK,
                ..
            }
        ),
        "{e}"
    );
    assert!(
        e.to_string().contains(
            "baking 1024 × 1024 × 1024 cells at a cost of 2 each is 2147483648 units of work, over the cap of 1073741824"
        ),
        "{e}"
    );
}
