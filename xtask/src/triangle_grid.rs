//! The exact distance from a point to a triangle mesh: the closest point on one triangle
//! (Ericson's Voronoi-region walk, *Real-Time Collision Detection* §5.1.5) and a uniform grid of
//! cells over the triangles, searched in rings of cells around the point until no unvisited cell
//! can hold a nearer triangle.

use glam::DVec3;

/// The point of triangle `abc` (solid, not just its edges) nearest to `p`.
pub fn closest_point_on_triangle(p: DVec3, a: DVec3, b: DVec3, c: DVec3) -> DVec3 {
    let (ab, ac, ap) = (b - a, c - a, p - a);
    let (d1, d2) = (ab.dot(ap), ac.dot(ap));
    if d1 <= 0.0 && d2 <= 0.0 {
        return a;
    }
    let bp = p - b;
    let (d3, d4) = (ab.dot(bp), ac.dot(bp));
    if d3 >= 0.0 && d4 <= d3 {
        return b;
    }
    let vc = d1 * d4 - d3 * d2;
    if vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0 {
        return a + ab * (d1 / (d1 - d3));
    }
    let cp = p - c;
    let (d5, d6) = (ab.dot(cp), ac.dot(cp));
    if d6 >= 0.0 && d5 <= d6 {
        return c;
    }
    let vb = d5 * d2 - d1 * d6;
    if vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0 {
        return a + ac * (d2 / (d2 - d6));
    }
    let va = d3 * d6 - d5 * d4;
    if va <= 0.0 && (d4 - d3) >= 0.0 && (d5 - d6) >= 0.0 {
        return b + (c - b) * ((d4 - d3) / ((d4 - d3) + (d5 - d6)));
    }
    let denom = va + vb + vc;
    if denom.abs() <= f64::MIN_POSITIVE {
        // A degenerate triangle (a segment or a point) whose regions above all failed by
        // rounding: its nearest vertex is within its size of the answer; take the nearest
        // point of its three edges instead, which is exact for a segment.
        return [(a, b), (b, c), (c, a)]
            .into_iter()
            .map(|(u, v)| closest_point_on_segment(p, u, v))
            .min_by(|x, y| {
                (*x - p)
                    .length_squared()
                    .total_cmp(&(*y - p).length_squared())
            })
            .unwrap_or(a);
    }
    let (v, w) = (vb / denom, vc / denom);
    a + ab * v + ac * w
}

/// The point of segment `uv` nearest to `p`.
fn closest_point_on_segment(p: DVec3, u: DVec3, v: DVec3) -> DVec3 {
    let d = v - u;
    let len2 = d.length_squared();
    if len2 == 0.0 {
        return u;
    }
    u + d * ((p - u).dot(d) / len2).clamp(0.0, 1.0)
}

/// The distance from `p` to triangle `abc`.
#[cfg(test)]
pub fn point_triangle_distance(p: DVec3, [a, b, c]: [DVec3; 3]) -> f64 {
    (closest_point_on_triangle(p, a, b, c) - p).length()
}

/// A uniform grid of cubic cells over a mesh's box; each cell lists the triangles whose boxes
/// overlap it (compressed rows: `starts[cell]..starts[cell + 1]` of `items`).
#[derive(Debug)]
pub struct TriangleGrid<'a> {
    positions: &'a [DVec3],
    triangles: &'a [[u32; 3]],
    origin: DVec3,
    cell: f64,
    dims: [usize; 3],
    starts: Vec<u32>,
    items: Vec<u32>,
}

/// Cells per triangle at most (the grid's size is bounded by the mesh's, whatever its shape).
const CELLS_PER_TRIANGLE: f64 = 8.0;

impl<'a> TriangleGrid<'a> {
    /// The grid over `triangles` (indices into `positions`): cells about twice the mean edge
    /// long, or larger so that there are at most two cells per triangle.
    pub fn new(positions: &'a [DVec3], triangles: &'a [[u32; 3]]) -> Self {
        let corners = |t: &[u32; 3]| t.map(|i| positions[i as usize]);
        let (mut lo, mut hi) = (DVec3::INFINITY, DVec3::NEG_INFINITY);
        let mut edges = 0.0;
        for t in triangles {
            let [a, b, c] = corners(t);
            lo = lo.min(a.min(b).min(c));
            hi = hi.max(a.max(b).max(c));
            edges += (b - a).length() + (c - b).length() + (a - c).length();
        }
        if triangles.is_empty() {
            (lo, hi) = (DVec3::ZERO, DVec3::ZERO);
        }
        let extent = (hi - lo).max(DVec3::splat(1e-12));
        let mean_edge = edges / (3.0 * triangles.len().max(1) as f64);
        let volume = extent.x * extent.y * extent.z;
        let by_count = (volume / (CELLS_PER_TRIANGLE * triangles.len().max(1) as f64)).cbrt();
        let cell = mean_edge.max(by_count).max(extent.max_element() * 1e-9);
        let dims = ((extent / cell).floor().as_uvec3() + glam::UVec3::ONE)
            .to_array()
            .map(|d| d as usize);
        let cells = dims[0] * dims[1] * dims[2];
        let mut grid = Self {
            positions,
            triangles,
            origin: lo,
            cell,
            dims,
            starts: vec![0; cells + 1],
            items: Vec::new(),
        };
        // Count, prefix-sum, fill.
        for t in triangles {
            for id in grid.cells_of(t) {
                grid.starts[id + 1] += 1;
            }
        }
        for i in 0..cells {
            grid.starts[i + 1] += grid.starts[i];
        }
        let mut next = grid.starts.clone();
        grid.items = vec![0; grid.starts[cells] as usize];
        for (index, t) in triangles.iter().enumerate() {
            for id in grid.cells_of(t) {
                grid.items[next[id] as usize] = index as u32;
                next[id] += 1;
            }
        }
        grid
    }

    fn id(&self, [i, j, k]: [usize; 3]) -> usize {
        (k * self.dims[1] + j) * self.dims[0] + i
    }

    /// The cell holding `p`, clamped to the grid.
    fn cell_of(&self, p: DVec3) -> [usize; 3] {
        let q = (p - self.origin) / self.cell;
        std::array::from_fn(|a| {
            let x = q[a].floor();
            if x.is_nan() || x < 0.0 {
                0
            } else {
                (x as usize).min(self.dims[a] - 1)
            }
        })
    }

    /// The ids of the cells a triangle's box overlaps.
    fn cells_of(&self, t: &[u32; 3]) -> impl Iterator<Item = usize> + use<> {
        let [a, b, c] = t.map(|i| self.positions[i as usize]);
        let (c0, c1) = (self.cell_of(a.min(b).min(c)), self.cell_of(a.max(b).max(c)));
        let (nx, ny) = (self.dims[0], self.dims[1]);
        (c0[2]..=c1[2]).flat_map(move |k| {
            (c0[1]..=c1[1]).flat_map(move |j| (c0[0]..=c1[0]).map(move |i| (k * ny + j) * nx + i))
        })
    }

    /// The distance from `p` to the nearest triangle, exactly (each triangle's distance from
    /// [`point_triangle_distance`]); `+∞` for a mesh without triangles.
    ///
    /// Rings of cells at Chebyshev index distance `r = 0, 1, …` from `p`'s cell (clamped to the
    /// grid) are searched in turn; a cell at distance `r + 1` or more lies at least `r` cells
    /// from `p` along one axis (also for a point outside the grid: clamping it onto the grid
    /// moves it toward every cell), so the search stops once the best distance is at most
    /// `r · cell`.
    pub fn distance(&self, p: DVec3) -> f64 {
        let c = self.cell_of(p);
        let mut best2 = f64::INFINITY;
        let reach = self.dims.iter().copied().max().unwrap_or(0);
        for r in 0..=reach {
            self.visit_ring(c, r, |index| {
                let t = self.triangles[index as usize].map(|i| self.positions[i as usize]);
                let d = closest_point_on_triangle(p, t[0], t[1], t[2]) - p;
                best2 = best2.min(d.length_squared());
            });
            let bound = r as f64 * self.cell;
            if best2 <= bound * bound {
                break;
            }
        }
        best2.sqrt()
    }

    /// Calls `f` with every triangle listed in the cells at Chebyshev distance exactly `r` from
    /// cell `c` (those inside the grid); a triangle in several cells comes several times.
    fn visit_ring(&self, c: [usize; 3], r: usize, mut f: impl FnMut(u32)) {
        let r = r as isize;
        let range = |a: usize| {
            let lo = (c[a] as isize - r).max(0);
            let hi = (c[a] as isize + r).min(self.dims[a] as isize - 1);
            (lo, hi)
        };
        let ((i0, i1), (j0, j1), (k0, k1)) = (range(0), range(1), range(2));
        let ci = c.map(|x| x as isize);
        for k in k0..=k1 {
            let k_on = (k - ci[2]).abs() == r;
            for j in j0..=j1 {
                let jk_on = k_on || (j - ci[1]).abs() == r;
                // On the ring's face in j or k: the whole row; else only its two ends.
                let row: &[isize] = &[ci[0] - r, ci[0] + r];
                let mut visit = |i: isize| {
                    if i >= i0 && i <= i1 {
                        let id = self.id([i as usize, j as usize, k as usize]);
                        for &t in
                            &self.items[self.starts[id] as usize..self.starts[id + 1] as usize]
                        {
                            f(t);
                        }
                    }
                };
                if jk_on {
                    (i0..=i1).for_each(&mut visit);
                } else if r == 0 {
                    visit(ci[0]);
                } else {
                    row.iter().copied().for_each(&mut visit);
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A splitmix64 stream mapped to `[0, 1)`.
    fn uniform(state: &mut u64) -> f64 {
        *state = state.wrapping_add(0x9e37_79b9_7f4a_7c15);
        let mut z = *state;
        z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
        (z ^ (z >> 31)) as f64 / 2f64.powi(64)
    }

    fn point(state: &mut u64, scale: f64) -> DVec3 {
        DVec3::new(
            uniform(state) - 0.5,
            uniform(state) - 0.5,
            uniform(state) - 0.5,
        ) * scale
    }

    /// The exact distance is never above any point of the triangle's (a dense barycentric
    /// grid: an upper bound) and is within the grid's spacing of the best of them; the closest
    /// point lies on the triangle (its barycentric coordinates are in [0, 1]).
    #[test]
    fn point_triangle_distance_matches_brute_force() {
        let mut s = 7;
        const N: usize = 200;
        for case in 0..300 {
            let tri = [point(&mut s, 2.0), point(&mut s, 2.0), point(&mut s, 2.0)];
            // A few near-degenerate triangles too: a sliver and a near-segment.
            let tri = match case % 10 {
                8 => [
                    tri[0],
                    tri[1],
                    tri[0] + (tri[1] - tri[0]) * 0.5 + DVec3::splat(1e-9),
                ],
                9 => [tri[0], tri[0] + DVec3::splat(1e-13), tri[2]],
                _ => tri,
            };
            let p = point(&mut s, 4.0);
            let exact = point_triangle_distance(p, tri);
            let mut brute = f64::INFINITY;
            for i in 0..=N {
                for j in 0..=N - i {
                    let (u, v) = (i as f64 / N as f64, j as f64 / N as f64);
                    let q = tri[0] + (tri[1] - tri[0]) * u + (tri[2] - tri[0]) * v;
                    brute = brute.min((q - p).length());
                }
            }
            let longest = (tri[1] - tri[0])
                .length()
                .max((tri[2] - tri[1]).length())
                .max((tri[0] - tri[2]).length());
            assert!(exact <= brute + 1e-12, "case {case}: {exact} > {brute}");
            assert!(
                brute - exact <= longest / N as f64,
                "case {case}: {exact} vs {brute}"
            );
        }
    }

    /// The grid's answer is the minimum over every triangle, bit for bit, for points near the
    /// mesh, far from it and outside its box.
    #[test]
    fn the_grid_finds_the_nearest_triangle() {
        let mut s = 11;
        let positions: Vec<DVec3> = (0..600).map(|_| point(&mut s, 3.0)).collect();
        // Small triangles around random centres, as a surface mesh's are.
        let triangles: Vec<[u32; 3]> = (0..200).map(|t| [3 * t, 3 * t + 1, 3 * t + 2]).collect();
        let positions: Vec<DVec3> = positions
            .chunks(3)
            .flat_map(|c| {
                let centre = c[0];
                [centre, centre + c[1] * 0.05, centre + c[2] * 0.05]
            })
            .collect();
        let grid = TriangleGrid::new(&positions, &triangles);
        for scale in [1.0, 3.0, 20.0] {
            for _ in 0..300 {
                let p = point(&mut s, scale);
                let brute = triangles
                    .iter()
                    .map(|t| point_triangle_distance(p, t.map(|i| positions[i as usize])))
                    .fold(f64::INFINITY, f64::min);
                assert_eq!(grid.distance(p), brute, "{p}");
            }
        }
        assert_eq!(
            TriangleGrid::new(&[], &[]).distance(DVec3::ONE),
            f64::INFINITY
        );
    }
}
