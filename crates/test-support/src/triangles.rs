//! Triangle references the mesh tests of two crates share: the f64 Möller–Trumbore line–triangle
//! test — the brute force the suites check both backends' watertight tests and BVHs against —
//! and the closed cube `[−1, 1]³` their stress cases use.

use glam::DVec3;

/// Where the line `origin + t·dir` meets the triangle `c` (f64 Möller–Trumbore, barycentric
/// coordinates `u, v ≥ 0`, `u + v ≤ 1`): its `t`, whatever its sign; `None` for a line parallel
/// to the triangle's plane (or a degenerate triangle) and a line that passes it by.
pub fn moller_trumbore(origin: DVec3, dir: DVec3, c: &[DVec3; 3]) -> Option<f64> {
    let (e1, e2) = (c[1] - c[0], c[2] - c[0]);
    let p = dir.cross(e2);
    let det = e1.dot(p);
    if det == 0.0 {
        return None;
    }
    let s = origin - c[0];
    let u = s.dot(p) / det;
    let q = s.cross(e1);
    let v = dir.dot(q) / det;
    let t = e2.dot(q) / det;
    // Written as the rejection, so a NaN coordinate rejects nothing, as the suites always had it.
    (!(u < 0.0 || v < 0.0 || u + v > 1.0)).then_some(t)
}

/// The distance from `p` to the nearest of the triangle `c`'s three edges (as segments; a
/// zero-length edge is its point).
pub fn edge_distance(c: &[DVec3; 3], p: DVec3) -> f64 {
    (0..3)
        .map(|k| {
            let (a, b) = (c[k], c[(k + 1) % 3]);
            let ab = b - a;
            let s = ((p - a).dot(ab) / ab.length_squared().max(f64::MIN_POSITIVE)).clamp(0.0, 1.0);
            (p - (a + ab * s)).length()
        })
        .fold(f64::INFINITY, f64::min)
}

/// The brute force's nearest hit of the line `origin + t·dir` over `triangles`, `t` accepted by
/// `in_range`, each triangle by [`moller_trumbore`] (the earlier triangle on a tie): `(t, the
/// hit's distance to that triangle's nearest edge, |cos θ| between the line and its normal)`.
pub fn nearest_hit(
    origin: DVec3,
    dir: DVec3,
    triangles: impl IntoIterator<Item = [DVec3; 3]>,
    in_range: impl Fn(f64) -> bool,
) -> Option<(f64, f64, f64)> {
    let mut best: Option<(f64, f64, f64)> = None;
    for c in triangles {
        let Some(t) = moller_trumbore(origin, dir, &c) else {
            continue;
        };
        if !in_range(t) || best.is_some_and(|b| b.0 <= t) {
            continue;
        }
        let normal = (c[1] - c[0]).cross(c[2] - c[0]).normalize_or_zero();
        best = Some((
            t,
            edge_distance(&c, origin + dir * t),
            normal.dot(dir).abs(),
        ));
    }
    best
}

/// The cube `[−1, 1]³`: its 8 corners (corner `k` at `±1` by bits 0, 1, 2 of `k` for x, y, z)
/// and its 12 triangles, wound outward.
pub fn cube() -> (Vec<DVec3>, Vec<[u32; 3]>) {
    let sign = |bit: bool| if bit { 1.0 } else { -1.0 };
    let corners = (0..8)
        .map(|k| DVec3::new(sign(k & 1 != 0), sign(k & 2 != 0), sign(k & 4 != 0)))
        .collect();
    let faces = [
        [0, 2, 3, 1],
        [4, 5, 7, 6],
        [0, 1, 5, 4],
        [2, 6, 7, 3],
        [0, 4, 6, 2],
        [1, 3, 7, 5],
    ];
    let triangles = faces
        .iter()
        .flat_map(|f| [[f[0], f[1], f[2]], [f[0], f[2], f[3]]])
        .collect();
    (corners, triangles)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_line_meets_a_triangle_inside_and_misses_it_outside() {
        let c = [DVec3::ZERO, DVec3::X, DVec3::Y];
        let hit = moller_trumbore(DVec3::new(0.25, 0.25, 2.0), -DVec3::Z, &c);
        assert_eq!(hit, Some(2.0));
        // Behind the origin: the line still meets it, at a negative t.
        assert_eq!(
            moller_trumbore(DVec3::new(0.25, 0.25, -1.0), -DVec3::Z, &c),
            Some(-1.0)
        );
        assert_eq!(
            moller_trumbore(DVec3::new(0.75, 0.75, 2.0), -DVec3::Z, &c),
            None
        );
        assert_eq!(
            moller_trumbore(DVec3::new(0.25, 0.25, 2.0), DVec3::X, &c),
            None
        );
    }

    #[test]
    fn edge_distances_are_to_the_segments() {
        let c = [DVec3::ZERO, DVec3::X, DVec3::Y];
        assert_eq!(edge_distance(&c, DVec3::new(0.5, 0.1, 0.0)), 0.1);
        // Past the end of the edge along x: to its end point, not its line.
        assert_eq!(edge_distance(&c, DVec3::new(2.0, 0.0, 0.0)), 1.0);
        let point = [DVec3::ONE; 3];
        assert_eq!(edge_distance(&point, DVec3::new(1.0, 1.0, 3.0)), 2.0);
    }

    #[test]
    fn the_cube_is_closed_and_wound_outward() {
        let (p, tris) = cube();
        assert_eq!((p.len(), tris.len()), (8, 12));
        for t in &tris {
            let [a, b, c] = t.map(|i| p[i as usize]);
            let normal = (b - a).cross(c - a);
            let centre = (a + b + c) / 3.0;
            assert!(normal.dot(centre) > 0.0, "{t:?} faces inward");
        }
        // Every edge is shared by exactly two triangles, in opposite directions.
        let mut edges = std::collections::HashMap::new();
        for t in &tris {
            for k in 0..3 {
                *edges.entry((t[k], t[(k + 1) % 3])).or_insert(0) += 1;
            }
        }
        assert!(
            edges
                .iter()
                .all(|(&(a, b), &n)| n == 1 && edges.get(&(b, a)) == Some(&1))
        );
    }
}
