//! Moving a solid (`Solid::moved`, what an animated object is at a time): the moved solid at the
//! moved point equals the original at the point, the boxes follow, a clipping box turned with its
//! object becomes the intersection with its six moved faces.

use fray_core::Aabb;
use fray_geometry::{FreeForm, Perturbation, Quadric, Shape, Solid};
use glam::{DAffine3, DQuat, DVec3};

/// A wing-like union with a bump and a dent, minus a sphere: every CSG operator.
fn solid() -> Solid {
    let body = FreeForm::new(
        Quadric::ellipsoid(DVec3::ZERO, DVec3::new(3.0, 0.6, 0.5)),
        vec![
            Perturbation::new(
                1.5,
                Quadric::ellipsoid(DVec3::new(1.0, 0.3, 0.0), DVec3::new(0.8, 0.5, 0.4)),
            ),
            Perturbation::new(
                -0.7,
                Quadric::ellipsoid(DVec3::new(-2.0, 0.0, 0.0), DVec3::splat(0.5)),
            ),
        ],
        None,
    )
    .unwrap();
    let wing = FreeForm::new(
        Quadric::ellipsoid(DVec3::new(0.5, 0.2, 0.0), DVec3::new(0.9, 0.1, 4.0)),
        vec![],
        None,
    )
    .unwrap();
    let hole = FreeForm::new(
        Quadric::sphere(DVec3::new(2.5, 0.0, 0.0), 0.4),
        vec![],
        None,
    )
    .unwrap();
    Solid::new(Shape::Difference(
        Box::new(Shape::Union(vec![
            Shape::FreeForm(body),
            Shape::FreeForm(wing),
        ])),
        Box::new(Shape::FreeForm(hole)),
    ))
    .unwrap()
}

fn motion() -> DAffine3 {
    DAffine3::from_scale_rotation_translation(
        DVec3::splat(1.0),
        DQuat::from_euler(glam::EulerRot::YXZ, 0.7, -0.3, 0.2),
        DVec3::new(120.0, -40.0, 3.5),
    )
}

/// The moved solid's value at `t(p)` is the original's at `p`: the polynomial is substituted
/// exactly, so the two agree to rounding (relative 1e-12 of the terms' size) at points inside,
/// outside and on the surface's neighbourhood. The original is evaluated at the untransformed
/// point, a path that shares no arithmetic with the moved coefficients.
#[test]
fn a_moved_solid_at_the_moved_point_has_the_original_value() {
    let (solid, t) = (solid(), motion());
    let (moved, origins) = solid.moved(&t).unwrap();
    assert_eq!(origins, [0, 1, 2], "no clipping box: one leaf per leaf");
    let mut state = 0x2545_f491_u64;
    let mut next = || {
        state = state
            .wrapping_mul(6_364_136_223_846_793_005)
            .wrapping_add(1);
        (state >> 11) as f64 / (1u64 << 53) as f64
    };
    let mut checked = 0;
    for _ in 0..20_000 {
        let p = DVec3::new(8.0 * next() - 4.0, 2.0 * next() - 1.0, 10.0 * next() - 5.0);
        let (a, b) = (solid.eval(p), moved.eval(t.transform_point3(p)));
        // The terms reach |F| + a few units at these points: rounding of a 4×4 substitution.
        let scale = 1.0 + a.abs();
        assert!(
            (a - b).abs() <= 1e-12 * scale * 64.0,
            "at {p}: {a} before, {b} moved"
        );
        checked += 1;
    }
    assert_eq!(checked, 20_000);
    // The box holds the moved shape: every moved point inside the solid is inside the new box.
    let b = moved.bounds();
    for _ in 0..20_000 {
        let p = DVec3::new(8.0 * next() - 4.0, 2.0 * next() - 1.0, 10.0 * next() - 5.0);
        if solid.eval(p) >= 0.0 {
            assert!(
                b.contains(t.transform_point3(p)),
                "{p} inside, outside {b:?}"
            );
        }
    }
}

/// The identity moves nothing: the same values everywhere, the same box.
#[test]
fn the_identity_moves_nothing() {
    let solid = solid();
    let (same, _) = solid.moved(&DAffine3::IDENTITY).unwrap();
    assert_eq!(same.bounds(), solid.bounds());
    for p in [
        DVec3::ZERO,
        DVec3::new(1.0, 0.3, 0.2),
        DVec3::new(2.5, 0.0, 0.1),
    ] {
        assert_eq!(same.eval(p), solid.eval(p));
    }
}

/// A clipping box follows a translation and a scale as a box; turned, it becomes the
/// intersection with its six moved faces (seven leaves from one, each from leaf 0): the moved
/// solid is inside exactly where the original is, at points away from the surface by more than
/// rounding (the values differ in size outside the box: `−∞` there before, a face's distance
/// after).
#[test]
fn a_clipping_box_translates_as_a_box_and_turns_as_its_faces() {
    let plane = FreeForm::new(
        Quadric::half_space(DVec3::ZERO, DVec3::Y),
        vec![Perturbation::new(
            0.5,
            Quadric::sphere(DVec3::new(0.3, 0.0, 0.2), 0.5),
        )],
        Some(Aabb::new(DVec3::splat(-1.0), DVec3::new(1.0, 0.0, 1.0))),
    )
    .unwrap();
    let solid = Solid::from_free_form(plane);
    let shift = DAffine3::from_translation(DVec3::new(5.0, 1.0, -2.0));
    let (moved, origins) = solid.moved(&shift).unwrap();
    assert_eq!(origins, [0]);
    assert_eq!(
        moved.bounds(),
        Aabb::new(DVec3::new(4.0, 0.0, -3.0), DVec3::new(6.0, 1.0, -1.0))
    );
    for p in [DVec3::new(0.5, -0.5, 0.5), DVec3::new(1.5, -0.5, 0.0)] {
        assert_eq!(moved.eval(shift.transform_point3(p)), solid.eval(p));
    }
    let t = motion();
    let (turned, origins) = solid.moved(&t).unwrap();
    assert_eq!(origins, [0; 7]);
    assert_eq!(turned.leaves().len(), 7);
    let mut state = 0x9e37_79b9_u64;
    let mut next = || {
        state = state
            .wrapping_mul(6_364_136_223_846_793_005)
            .wrapping_add(1);
        (state >> 11) as f64 / (1u64 << 53) as f64
    };
    let (mut inside, mut outside) = (0, 0);
    for _ in 0..50_000 {
        let p = DVec3::new(3.0 * next() - 1.5, 3.0 * next() - 2.0, 3.0 * next() - 1.5);
        let (a, b) = (solid.eval(p), turned.eval(t.transform_point3(p)));
        // Away from the surface: F′ and every face farther than rounding from zero.
        let (lo, hi) = (DVec3::splat(-1.0), DVec3::new(1.0, 0.0, 1.0));
        let face = (p - lo).min(hi - p).abs().min_element();
        let unclipped = solid.leaves()[0].eval_unclipped(p);
        if face < 1e-9 || unclipped.abs() < 1e-9 {
            continue;
        }
        assert_eq!(a >= 0.0, b >= 0.0, "at {p}: {a} before, {b} turned");
        if a >= 0.0 {
            inside += 1;
        } else {
            outside += 1;
        }
    }
    assert!(
        inside > 5_000 && outside > 5_000,
        "{inside} inside, {outside} outside"
    );
    // The moved box holds the turned shape.
    let b = turned.bounds();
    for _ in 0..20_000 {
        let p = DVec3::new(3.0 * next() - 1.5, 3.0 * next() - 2.0, 3.0 * next() - 1.5);
        if solid.eval(p) >= 0.0 {
            assert!(
                b.contains(t.transform_point3(p)),
                "{p} inside, outside {b:?}"
            );
        }
    }
}
