//! Every query takes one straight segment and a parameter range, so that a curved ray (a
//! polyline, later) can be cast segment by segment: a camera ray cut into consecutive ranges
//! finds, in the first range with a hit, the hit of the whole range — the same primitive and
//! part, `t` within the search's tolerance — both on the same ray and with each piece as its own
//! ray starting where the piece starts; transmittance over the whole range is the product over
//! the pieces. On every data scene (free forms, CSG, terrains).

mod common;

use fray_core::{Interval, Ray};
use fray_scene::PrimitiveKind;
use fray_trace::{TraceContext, TraceSettings, nearest_hit, transmittance};

/// The cut points of `[t_near, ∞)` into pieces: three finite breaks spread over the scene's
/// depth, so that some pieces end before a hit, some contain it and one is unbounded.
fn breaks(t_near: f64, far: f64) -> Vec<f64> {
    let span = (far - t_near).max(1e-9);
    let mut b = vec![t_near];
    b.extend([0.29, 0.53, 0.81].map(|f| t_near + f * span));
    b.push(f64::INFINITY);
    b
}

/// The first `t` in `[lo, hi]` where `value(t) ≥ 0` (inside), by steps of ε/8 and then
/// bisection to ε/1000; `None` if there is none on the steps.
fn first_inside(value: impl Fn(f64) -> f64, lo: f64, hi: f64, eps: f64) -> Option<f64> {
    let step = eps / 8.0;
    let mut prev = lo;
    let mut t = lo;
    while t <= hi {
        if value(t) >= 0.0 {
            let (mut a, mut b) = (prev, t);
            if a == b {
                return Some(t);
            }
            while b - a > eps / 1000.0 {
                let m = 0.5 * (a + b);
                if value(m) >= 0.0 { b = m } else { a = m }
            }
            return Some(b);
        }
        prev = t;
        t += step;
    }
    None
}

#[test]
fn a_ray_cast_in_pieces_finds_the_hit_of_the_whole_range() {
    let mut ctx = TraceContext::default();
    let mut compared = 0usize;
    let mut split_hits = 0usize;
    let mut widely_apart = 0usize;
    for path in common::data_scenes() {
        let what = path.display().to_string();
        let mut s = common::load_at_height(&path, 24);
        for t in &mut s.terrains {
            t.lod = fray_scene::TerrainLod::Exact;
        }
        let eps = TraceSettings::for_scene(&s).epsilon;
        // How deep the scene reaches from the camera: the farthest hit of any pixel.
        let mut far = 0.0f64;
        let mut rays = Vec::new();
        for y in 0..s.height {
            for x in 0..s.width {
                let Some(c) = s.camera.pixel_ray(x, y, s.width, s.height) else {
                    continue;
                };
                let whole = Interval::new(c.t_near, f64::INFINITY);
                let hit = nearest_hit(&s, &mut ctx, &c.ray, whole, eps);
                if let Some(h) = &hit {
                    far = far.max(h.t);
                }
                rays.push((x, y, c, hit));
            }
        }
        for (x, y, c, whole_hit) in rays {
            let cuts = breaks(c.t_near, far * 1.1);
            // The same ray, range by range.
            let mut piecewise = None;
            for w in cuts.windows(2) {
                let piece = Interval::new(w[0], w[1]);
                if let Some(h) = nearest_hit(&s, &mut ctx, &c.ray, piece, eps) {
                    assert!(
                        piece.contains(h.t),
                        "{what} ({x}, {y}): {} outside {w:?}",
                        h.t
                    );
                    if h.t > w[0] && w[0] > c.t_near {
                        split_hits += 1;
                    }
                    piecewise = Some(h);
                    break;
                }
            }
            // Each piece its own ray, from where the piece starts.
            let mut moved = None;
            for w in cuts.windows(2) {
                let start = c.ray.at(w[0]);
                let ray = Ray::new(start, c.ray.dir).expect("unit direction");
                let len = w[1] - w[0];
                if let Some(h) = nearest_hit(&s, &mut ctx, &ray, Interval::new(0.0, len), eps) {
                    assert!(
                        h.t <= len,
                        "{what} ({x}, {y}): {} past the piece's {len}",
                        h.t
                    );
                    moved = Some((w[0], h));
                    break;
                }
            }
            let at = format!("{what}: pixel ({x}, {y})");
            match (&whole_hit, &piecewise, &moved) {
                (None, None, None) => {}
                (Some(a), Some(b), Some((t0, m))) => {
                    assert_eq!(a.primitive, b.primitive, "{at}: primitive, same ray");
                    assert_eq!(a.primitive, m.primitive, "{at}: primitive, moved ray");
                    // The moved ray's origin is the rounded point at `t0`: its rounding adds
                    // to its `t`.
                    let rounding = 4.0 * f64::EPSILON * (c.ray.origin.abs().max_element() + t0);
                    let answers = [a.t, b.t, t0 + m.t];
                    let (lo, hi) = answers
                        .iter()
                        .fold((f64::INFINITY, 0.0f64), |(l, h), &t| (l.min(t), h.max(t)));
                    compared += 1;
                    if hi - lo <= eps + rounding {
                        continue;
                    }
                    // They differ by more than ε. Terrains are cast exactly per cell: they may
                    // not. A free form's answers each lie in [t* − ρ, t* + ε] (docs/accuracy.md:
                    // ρ the earliness the rounding of the solid explains), so they may differ by
                    // ε + ρ; check the one-sided bound t ≤ t* + ε against t* found by a fine
                    // scan of the solid's value along the ray (f64, a different method).
                    assert_eq!(
                        a.primitive.kind,
                        PrimitiveKind::FreeForm,
                        "{at}: {answers:?}"
                    );
                    let solid = &s.objects[a.primitive.index as usize].solid;
                    let t_star = first_inside(|t| solid.eval(c.ray.at(t)), lo, hi + 1e4 * eps, eps)
                        .unwrap_or_else(|| panic!("{at}: no inside point after {answers:?}"));
                    for t in answers {
                        assert!(
                            t <= t_star + eps + rounding,
                            "{at}: {t} later than t* {t_star} + ε ({answers:?})"
                        );
                    }
                    widely_apart += 1;
                }
                _ => panic!(
                    "{at}: hit or miss differs: whole {:?}, pieces {:?}, moved {:?}",
                    whole_hit.as_ref().map(|h| h.t),
                    piecewise.as_ref().map(|h| h.t),
                    moved.as_ref().map(|(t0, h)| t0 + h.t)
                ),
            }
            // Transmittance: opaque kinds block in exactly the pieces that hold a hit.
            let through_whole = transmittance(
                &s,
                &mut ctx,
                &c.ray,
                Interval::new(c.t_near, far * 1.1),
                eps,
            );
            let mut through_pieces = fray_core::Rgb::ONE;
            for w in cuts.windows(2) {
                let hi = w[1].min(far * 1.1);
                if hi > w[0] {
                    through_pieces *=
                        transmittance(&s, &mut ctx, &c.ray, Interval::new(w[0], hi), eps);
                }
            }
            assert_eq!(through_whole, through_pieces, "{at}: transmittance");
        }
    }
    // The test means something: many hits compared, some of them in a piece that starts later.
    assert!(compared > 500, "only {compared} hits compared");
    assert!(split_hits > 50, "only {split_hits} hits in later pieces");
    eprintln!(
        "{compared} hits compared, {split_hits} in later pieces, {widely_apart} more than ε apart (checked against t*)"
    );
}
