//! Per-tile shadow-ray culling: for each light, the objects that the shadow rays of a tile's
//! hit points may meet, from the box of the rays' origins. Conservative (an object left out is
//! missed by every such ray, with a margin for rounding), so testing only the kept objects
//! answers every shadow ray exactly as testing all of them: `occluded` is an "any".

use fray_core::{Aabb, Interval, Ray};
use fray_scene::{Light, Scene};
use glam::DVec3;

/// Rounding margin relative to the coordinates involved: far above f64 error in the box tests,
/// far below anything that changes which objects are kept.
const RELATIVE_MARGIN: f64 = 1e-9;

/// The objects each light's shadow rays may meet, for shadow rays leaving points inside
/// `origins` (the box of the tile's shadow-ray origins; `None`: the tile casts none).
/// `reach` bounds how far an origin lies from its surface point (the offset along the
/// normal), which moves a point light's rays' ends by as much. Indexed like `scene.lights`.
pub(crate) fn occluders(scene: &Scene, origins: Option<Aabb>, reach: f64) -> Vec<Vec<u32>> {
    let Some(origins) = origins else {
        return vec![Vec::new(); scene.lights.len()];
    };
    let scale = origins.min.abs().max(origins.max.abs()).max_element();
    let centre = origins.center();
    let half = 0.5 * (origins.max - origins.min);
    scene
        .lights
        .iter()
        .map(|light| {
            let keep = |bounds: &Aabb| -> bool {
                if bounds.is_empty() {
                    return false;
                }
                let margin = RELATIVE_MARGIN
                    * (scale + bounds.min.abs().max(bounds.max.abs()).max_element())
                    + reach;
                match *light {
                    // Parallel rays from the origin box: one ray from its centre against the
                    // object's box grown by the origin box's half extents (Minkowski sum).
                    Light::Sun { direction, .. } => {
                        let grown =
                            Aabb::new(bounds.min - half, bounds.max + half).expanded(margin);
                        Ray::new(centre, direction).is_none_or(|ray| {
                            grown
                                .clip_ray(&ray, Interval::new(0.0, f64::INFINITY))
                                .is_some()
                        })
                    }
                    // Segments from the origin box to the light lie in the box of both.
                    Light::Point { position, .. } => {
                        let hull = origins
                            .union(&Aabb::new(position, position))
                            .expanded(margin);
                        !hull.intersection(bounds).is_empty()
                    }
                }
            };
            (0..scene.objects.len() as u32)
                .filter(|&k| keep(&scene.objects[k as usize].solid.bounds()))
                .collect()
        })
        .collect()
}

/// The box of `points`, `None` for none.
pub(crate) fn bounding_box(points: impl Iterator<Item = DVec3>) -> Option<Aabb> {
    points.fold(None, |acc, p| {
        let point = Aabb::new(p, p);
        Some(acc.map_or(point, |b: Aabb| b.union(&point)))
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use fray_core::{Interval as I, Ray as R};

    fn scene() -> Scene {
        let path = concat!(env!("CARGO_MANIFEST_DIR"), "/../../data/scenes/csg.ron");
        fray_scene::load(std::path::Path::new(path)).unwrap()
    }

    /// Every shadow ray from random origins in a box toward each light that hits an object
    /// (cast exactly) hits one that the culling kept.
    #[test]
    fn culled_objects_are_missed_by_every_shadow_ray() {
        let mut s = scene();
        s.lights.push(Light::Point {
            position: DVec3::new(0.5, 4.0, -1.0),
            intensity: fray_core::Rgb::ONE,
        });
        let mut state = 0x2545_f491_4f6c_dd1du64;
        let mut next = || {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            (state >> 11) as f64 / (1u64 << 53) as f64
        };
        let mut kept_fewer = false;
        for _ in 0..300 {
            let c = DVec3::new(next() * 10.0 - 5.0, next() * 2.5, next() * 10.0 - 5.0);
            let h = DVec3::new(next(), next() * 0.3, next()) * 0.4;
            let origins = Aabb::new(c - h, c + h);
            let lists = occluders(&s, Some(origins), 0.0);
            for (light, kept) in s.lights.iter().zip(&lists) {
                kept_fewer |= kept.len() < s.objects.len();
                for _ in 0..20 {
                    let o = origins.min
                        + (origins.max - origins.min) * DVec3::new(next(), next(), next());
                    let (dir, range) = match *light {
                        Light::Sun { direction, .. } => (direction, I::new(0.0, f64::INFINITY)),
                        Light::Point { position, .. } => (
                            (position - o).normalize(),
                            I::new(0.0, (position - o).length()),
                        ),
                    };
                    let ray = R::new(o, dir).unwrap();
                    for (k, object) in s.objects.iter().enumerate() {
                        if object.solid.cast(&ray, range, 1e-9).is_some() {
                            assert!(kept.contains(&(k as u32)), "object {k} hit but culled");
                        }
                    }
                }
            }
        }
        assert!(kept_fewer, "the test never culled anything");
        assert!(occluders(&s, None, 0.0).iter().all(Vec::is_empty));
    }
}
