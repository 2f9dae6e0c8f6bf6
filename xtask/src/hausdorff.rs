//! The two-sided Hausdorff distance between a triangle mesh and the surface `F = 0` of a solid,
//! by sampling both sides: (a) mesh → surface, points on every triangle, each one's distance to
//! the surface bounded *from above* by the nearest hit of rays cast from it; (b) surface → mesh,
//! points *on* the surface (every crossing of a sphere of directions × a grid of parallel rays),
//! each one's distance to the mesh exact (`triangle_grid`).
//!
//! Why (a) is a bound: a ray from `p` that first reaches the boundary of the solid at `t` has
//! found a surface point at distance `t`, and `p`'s distance to the surface is the least over all
//! surface points, so it is at most `t` along any ray. The caster's hit is at most `ε` past the
//! first crossing and earlier only by the rounding of the inputs (docs/accuracy.md's contract), so
//! the bound holds to that rounding. A point inside the solid casts the solid's complement (where
//! it ends); one whose ray leaves the solid's box first has the box's exit, where the solid ends,
//! as its hit. The rays go along `±∇F` and `±` the triangle's normal; by the triangle inequality
//! a corner `v`'s bound plus `|p − v|` bounds `p`'s too; and the samples that decide the maximum
//! and the 99th percentile cast [`REFINE_DIRECTIONS`] more rays each (`refine_top`), since `∇F`
//! of the deciding leaf need not point at the nearest surface (thin edges, creases).
//!
//! The maxima are over finitely many samples, so each side's maximum approaches the true
//! supremum from below as the sampling gets denser: (b)'s by at most the largest distance from a
//! surface point to its nearest sample (the distance to the mesh is 1-Lipschitz).

use crate::triangle_grid::TriangleGrid;
use fray_core::{Interval, Ray};
use fray_geometry::{CastStats, PolygonMesh, RayCaster, Solid};
use glam::DVec3;
use std::collections::HashSet;
use std::time::{Duration, Instant};

/// How densely to sample each side.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Sampling {
    /// Random barycentric points per triangle, besides its vertices, edge midpoints and centroid.
    pub random_per_triangle: u32,
    /// The random points' seed (the same points whatever the thread count).
    pub seed: u64,
    /// Directions (a Fibonacci sphere) from which parallel rays cross the solid.
    pub directions: u32,
    /// Rays across the solid's bounding sphere per direction, per side of the square grid.
    pub rays_across: u32,
    /// The caster's accuracy, a share of the solid's box diagonal.
    pub eps_share: f64,
    /// Worker threads.
    pub threads: usize,
}

/// One side's figures over its samples, in world units.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Side {
    pub samples: usize,
    pub max: f64,
    /// The 99th percentile (nearest rank).
    pub p99: f64,
    /// Where the largest is (the sample's point).
    pub worst: DVec3,
    /// What measuring the samples took.
    pub time: Duration,
}

impl Side {
    /// The figures of `distances` (reordered) at `points` (in the same order), measured in
    /// `time`.
    pub fn of(distances: &mut [f64], points: &[DVec3], time: Duration) -> Self {
        let worst = (0..distances.len())
            .max_by(|&i, &j| distances[i].total_cmp(&distances[j]))
            .and_then(|i| points.get(i).copied())
            .unwrap_or_default();
        if distances.is_empty() {
            return Self {
                time,
                ..Self::default()
            };
        }
        distances.sort_unstable_by(f64::total_cmp);
        let rank = ((distances.len() as f64 * 0.99).ceil() as usize).clamp(1, distances.len());
        Self {
            samples: distances.len(),
            max: distances[distances.len() - 1],
            p99: distances[rank - 1],
            worst,
            time,
        }
    }
}

/// Both sides of the measure.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Hausdorff {
    /// (a): the distance of points on the mesh to the surface (upper bounds per sample).
    pub mesh_to_surface: Side,
    /// (b): the distance of points on the surface to the mesh (exact per sample).
    pub surface_to_mesh: Side,
}

impl Hausdorff {
    /// `max(max_a, max_b)`.
    pub fn two_sided(&self) -> f64 {
        self.mesh_to_surface.max.max(self.surface_to_mesh.max)
    }
}

/// The surface `F = 0` of one solid, as the caster sees it.
#[derive(Debug)]
pub struct Surface<'a> {
    solid: &'a Solid,
    complement: Solid,
    eps: f64,
}

impl<'a> Surface<'a> {
    /// The boundary of `solid`, cast to `eps_share` of its box's diagonal.
    pub fn new(solid: &'a Solid, eps_share: f64) -> Self {
        Self {
            solid,
            complement: solid.complement(),
            eps: eps_share * solid.bounds().diagonal(),
        }
    }

    /// The caster's accuracy in world units.
    #[cfg(test)]
    pub fn eps(&self) -> f64 {
        self.eps
    }

    /// An upper bound on the distance from `p` to the surface: the nearest hit of rays from `p`
    /// along `±∇F` (normalised) and `±normal` (the mesh's), first within `reach`, then, where
    /// none hits there, over the whole box and also along the 26 directions to a cube's
    /// neighbours. `+∞` if no ray finds the surface.
    pub fn distance_bound(
        &self,
        caster: &mut RayCaster,
        p: DVec3,
        normal: DVec3,
        reach: f64,
    ) -> f64 {
        let (f, g) = self.solid.eval_with_gradient(p);
        if f == 0.0 {
            return 0.0;
        }
        let gradient = g.try_normalize().unwrap_or(normal);
        let main = [gradient, -gradient, normal, -normal];
        let near = self.nearest_hit(caster, p, f > 0.0, main, reach);
        if near.is_finite() {
            return near;
        }
        let neighbours = (0..27).filter(|&i| i != 13).map(|i| {
            DVec3::new(
                f64::from(i % 3) - 1.0,
                f64::from(i / 3 % 3) - 1.0,
                f64::from(i / 9) - 1.0,
            )
        });
        self.nearest_hit(
            caster,
            p,
            f > 0.0,
            main.into_iter().chain(neighbours),
            f64::INFINITY,
        )
    }

    /// `bound` (an upper bound on `p`'s distance to the surface) lowered to the nearest hit of
    /// rays from `p` along `directions` within it.
    pub fn refine(
        &self,
        caster: &mut RayCaster,
        p: DVec3,
        directions: &[DVec3],
        bound: f64,
    ) -> f64 {
        let (f, _) = self.solid.eval_with_gradient(p);
        if f == 0.0 {
            return 0.0;
        }
        self.nearest_hit(caster, p, f > 0.0, directions.iter().copied(), bound)
            .min(bound)
    }

    /// The nearest first hit of the rays from `p` along `directions` within `reach`: of the
    /// solid's boundary from outside it, of its complement from `inside` — where a ray that
    /// leaves the solid's box without meeting the complement crosses the boundary at the box's
    /// exit. Each ray looks only nearer than the best hit so far; `+∞` if none hits.
    fn nearest_hit(
        &self,
        caster: &mut RayCaster,
        p: DVec3,
        inside: bool,
        directions: impl IntoIterator<Item = DVec3>,
        reach: f64,
    ) -> f64 {
        let target = if inside { &self.complement } else { self.solid };
        let mut stats = CastStats::default();
        let mut best = f64::INFINITY;
        for d in directions {
            let Some(ray) = Ray::new(p, d) else { continue };
            let range = Interval::new(0.0, best.min(reach));
            let hit = caster
                .cast(target, &ray, range, self.eps, &mut stats)
                .or_else(|| {
                    let exit = self.solid.bounds().clip_ray(&ray, range)?.hi;
                    (inside && exit < range.hi).then_some(exit)
                });
            if let Some(t) = hit {
                best = best.min(t);
            }
        }
        best
    }

    /// Every crossing of the surface by the rays of [`Sampling::directions`] directions, each a
    /// square grid of [`Sampling::rays_across`]² parallel rays over the solid's bounding sphere,
    /// from outside it: entries (the solid's first point past the last exit) and exits (its
    /// complement's), each on the surface to the caster's `ε`. At most 64 crossings a ray.
    pub fn samples(&self, sampling: &Sampling) -> Vec<DVec3> {
        let b = self.solid.bounds();
        let (centre, radius) = (b.center(), 0.5 * b.diagonal() * 1.001 + self.eps);
        let n = sampling.rays_across.max(1);
        let tasks: Vec<(u32, u32)> = (0..sampling.directions)
            .flat_map(|d| (0..n).map(move |row| (d, row)))
            .collect();
        let step = 10.0 * self.eps;
        parallel_map(
            &tasks,
            sampling.threads,
            |&(d, row), out: &mut Vec<DVec3>| {
                let mut caster = RayCaster::new();
                let mut stats = CastStats::default();
                let dir = fibonacci_direction(d, sampling.directions);
                let u = dir.any_orthonormal_vector();
                let v = dir.cross(u);
                let y = -radius + (f64::from(row) + 0.5) * 2.0 * radius / f64::from(n);
                for col in 0..n {
                    let x = -radius + (f64::from(col) + 0.5) * 2.0 * radius / f64::from(n);
                    let origin = centre + u * x + v * y - dir * radius;
                    let Some(ray) = Ray::new(origin, dir) else {
                        continue;
                    };
                    let end = 2.0 * radius;
                    let mut t = 0.0;
                    for crossing in 0..64 {
                        let (target, inside) = if crossing % 2 == 0 {
                            (self.solid, false)
                        } else {
                            (&self.complement, true)
                        };
                        let range = Interval::new(t, end);
                        let hit = caster
                            .cast(target, &ray, range, self.eps, &mut stats)
                            .or_else(|| {
                                let exit = b.clip_ray(&ray, range)?.hi;
                                (inside && exit < end).then_some(exit)
                            });
                        let Some(hit) = hit else { break };
                        out.push(ray.at(hit));
                        t = hit + step;
                        if t >= end {
                            break;
                        }
                    }
                }
            },
        )
    }
}

/// Direction `i` of `n` spread evenly over the unit sphere (the Fibonacci lattice).
pub fn fibonacci_direction(i: u32, n: u32) -> DVec3 {
    let golden = std::f64::consts::PI * (3.0 - 5f64.sqrt());
    let z = 1.0 - (f64::from(i) + 0.5) * 2.0 / f64::from(n.max(1));
    let r = (1.0 - z * z).max(0.0).sqrt();
    let phi = golden * f64::from(i);
    DVec3::new(r * phi.cos(), z, r * phi.sin())
}

/// A point on the mesh to measure: its triangle's corners (a vertex's own index three times)
/// and the triangle's unit normal (a vertex's: the mesh's normal there).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct MeshSample {
    pub point: DVec3,
    pub normal: DVec3,
    pub corners: [u32; 3],
}

/// The points of (a): every vertex and every edge's midpoint once, and each triangle's centroid
/// and `random` barycentric points (uniform over it; a splitmix64 stream seeded by `seed` and
/// the triangle's index).
pub fn mesh_samples(mesh: &PolygonMesh, random: u32, seed: u64) -> Vec<MeshSample> {
    let p = |i: u32| mesh.positions[i as usize];
    let mut out = Vec::new();
    let mut used = vec![false; mesh.positions.len()];
    let mut edges = HashSet::new();
    for (index, t) in mesh.triangles.iter().enumerate() {
        let [a, b, c] = t.map(p);
        let normal = (b - a).cross(c - a).try_normalize().unwrap_or(DVec3::Y);
        let sample = |point: DVec3| MeshSample {
            point,
            normal,
            corners: *t,
        };
        for (k, &v) in t.iter().enumerate() {
            if !std::mem::replace(&mut used[v as usize], true) {
                out.push(MeshSample {
                    point: p(v),
                    normal: mesh.normals.get(v as usize).copied().unwrap_or(normal),
                    corners: [v; 3],
                });
            }
            let w = t[(k + 1) % 3];
            if edges.insert((v.min(w), v.max(w))) {
                out.push(sample(0.5 * (p(v) + p(w))));
            }
        }
        out.push(sample((a + b + c) / 3.0));
        let mut state = seed ^ (index as u64).wrapping_mul(0x9e37_79b9_7f4a_7c15);
        for _ in 0..random {
            let (mut r, mut s) = (unit(&mut state), unit(&mut state));
            if r + s > 1.0 {
                (r, s) = (1.0 - r, 1.0 - s);
            }
            out.push(sample(a + (b - a) * r + (c - a) * s));
        }
    }
    out
}

/// The next number of a splitmix64 stream, in `[0, 1)`.
fn unit(state: &mut u64) -> f64 {
    *state = state.wrapping_add(0x9e37_79b9_7f4a_7c15);
    let mut z = *state;
    z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
    ((z ^ (z >> 31)) >> 11) as f64 / (1u64 << 53) as f64
}

/// The mean edge length of `mesh`'s triangles (0 for none).
pub fn mean_edge(mesh: &PolygonMesh) -> f64 {
    let sum: f64 = mesh
        .triangles
        .iter()
        .map(|t| {
            let [a, b, c] = t.map(|i| mesh.positions[i as usize]);
            (b - a).length() + (c - b).length() + (a - c).length()
        })
        .sum();
    sum / (3 * mesh.triangles.len()).max(1) as f64
}

/// (a)'s distances and their samples' points, in sample order: each sample's bound is the least
/// of [`Surface::distance_bound`] (rays first reaching four mean edges) and, by the triangle
/// inequality, `|p − v| + bound(v)` over its triangle's corners `v` (each vertex's own bound from
/// its rays); then the largest are refined ([`refine_top`]).
pub fn mesh_to_surface(
    surface: &Surface<'_>,
    mesh: &PolygonMesh,
    sampling: &Sampling,
) -> (Vec<f64>, Vec<DVec3>) {
    let samples = mesh_samples(mesh, sampling.random_per_triangle, sampling.seed);
    let reach = 4.0 * mean_edge(mesh);
    let mut vertex = vec![f64::INFINITY; mesh.positions.len()];
    let vertices: Vec<&MeshSample> = samples
        .iter()
        .filter(|s| s.corners[0] == s.corners[1])
        .collect();
    let chunks: Vec<&[&MeshSample]> = vertices.chunks(4096).collect();
    let bounds = parallel_map(&chunks, sampling.threads, |chunk, out: &mut Vec<f64>| {
        let mut caster = RayCaster::new();
        out.extend(
            chunk
                .iter()
                .map(|s| surface.distance_bound(&mut caster, s.point, s.normal, reach)),
        );
    });
    for (s, b) in vertices.iter().zip(bounds) {
        vertex[s.corners[0] as usize] = b;
    }
    let chunks: Vec<&[MeshSample]> = samples.chunks(4096).collect();
    let distances = parallel_map(&chunks, sampling.threads, |chunk, out: &mut Vec<f64>| {
        let mut caster = RayCaster::new();
        out.extend(chunk.iter().map(|s| {
            let [a, b, c] = s.corners;
            if a == b {
                return vertex[a as usize];
            }
            let by_corner = [a, b, c]
                .map(|v| (s.point - mesh.positions[v as usize]).length() + vertex[v as usize])
                .into_iter()
                .fold(f64::INFINITY, f64::min);
            surface
                .distance_bound(&mut caster, s.point, s.normal, reach)
                .min(by_corner)
        }));
    });
    let distances = refine_top(surface, &samples, distances, sampling.threads);
    (distances, samples.iter().map(|s| s.point).collect())
}

/// Directions along which [`refine_top`] casts.
pub const REFINE_DIRECTIONS: u32 = 128;

/// Tightens the bounds that decide the maximum and the 99th percentile: the samples with the
/// largest bounds (2 % of them, then twice as many while needed) cast [`REFINE_DIRECTIONS`]
/// more rays each ([`Surface::refine`]), until every sample left unrefined is below the 99th
/// percentile of the whole — so that refining it could change neither figure. The maximum and
/// the percentile are then those of every sample refined.
pub fn refine_top(
    surface: &Surface<'_>,
    samples: &[MeshSample],
    mut distances: Vec<f64>,
    threads: usize,
) -> Vec<f64> {
    let n = distances.len();
    let mut order: Vec<usize> = (0..n).collect();
    order.sort_unstable_by(|&i, &j| distances[j].total_cmp(&distances[i]).then(i.cmp(&j)));
    let directions: Vec<DVec3> = (0..REFINE_DIRECTIONS)
        .map(|k| fibonacci_direction(k, REFINE_DIRECTIONS))
        .collect();
    let (mut done, mut want) = (0, n.div_ceil(50));
    while done < n {
        let batch = &order[done..want.min(n)];
        let chunks: Vec<&[usize]> = batch.chunks(256).collect();
        let refined = parallel_map(&chunks, threads, |chunk, out: &mut Vec<f64>| {
            let mut caster = RayCaster::new();
            out.extend(chunk.iter().map(|&i| {
                surface.refine(&mut caster, samples[i].point, &directions, distances[i])
            }));
        });
        for (&i, d) in batch.iter().zip(refined) {
            distances[i] = d;
        }
        done = want.min(n);
        want = 2 * done;
        let Some(&next) = order.get(done) else { break };
        let mut copy = distances.clone();
        let rank = ((n as f64 * 0.99).ceil() as usize).clamp(1, n);
        let (_, p99, _) = copy.select_nth_unstable_by(rank - 1, f64::total_cmp);
        if distances[next] < *p99 {
            break;
        }
    }
    distances
}

/// (b)'s distances: each surface sample's exact distance to the mesh.
pub fn surface_to_mesh(points: &[DVec3], grid: &TriangleGrid<'_>, threads: usize) -> Vec<f64> {
    let chunks: Vec<&[DVec3]> = points.chunks(4096).collect();
    parallel_map(&chunks, threads, |chunk, out: &mut Vec<f64>| {
        out.extend(chunk.iter().map(|&p| grid.distance(p)));
    })
}

/// Both sides for `mesh` against `solid`'s surface.
/// Both sides for `mesh` against `surface`, whose samples ([`Surface::samples`], which do not
/// depend on the mesh) are `points`; each side timed.
pub fn measure(
    surface: &Surface<'_>,
    points: &[DVec3],
    mesh: &PolygonMesh,
    sampling: &Sampling,
) -> Hausdorff {
    let start = Instant::now();
    let (mut a, on_mesh) = mesh_to_surface(surface, mesh, sampling);
    let a_time = start.elapsed();
    let start = Instant::now();
    let grid = TriangleGrid::new(&mesh.positions, &mesh.triangles);
    let mut b = surface_to_mesh(points, &grid, sampling.threads);
    let b_time = start.elapsed();
    Hausdorff {
        mesh_to_surface: Side::of(&mut a, &on_mesh, a_time),
        surface_to_mesh: Side::of(&mut b, points, b_time),
    }
}

/// `f` over `items` on `threads` workers, each item's outputs in item order (the same result
/// whatever the thread count).
fn parallel_map<T: Sync, U: Send>(
    items: &[T],
    threads: usize,
    f: impl Fn(&T, &mut Vec<U>) + Sync,
) -> Vec<U> {
    let threads = threads.clamp(1, items.len().max(1));
    let next = std::sync::atomic::AtomicUsize::new(0);
    let mut parts: Vec<(usize, Vec<U>)> = std::thread::scope(|scope| {
        let workers: Vec<_> = (0..threads)
            .map(|_| {
                scope.spawn(|| {
                    let mut done = Vec::new();
                    loop {
                        let i = next.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
                        let Some(item) = items.get(i) else { break };
                        let mut out = Vec::new();
                        f(item, &mut out);
                        done.push((i, out));
                    }
                    done
                })
            })
            .collect();
        workers
            .into_iter()
            .flat_map(|w| w.join().unwrap_or_default())
            .collect()
    });
    parts.sort_unstable_by_key(|(i, _)| *i);
    parts.into_iter().flat_map(|(_, out)| out).collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::triangle_grid::point_triangle_distance;
    use fray_core::MemoryBudget;
    use fray_geometry::{FreeForm, Quadric, Shape};

    const C: DVec3 = DVec3::new(0.3, -0.2, 0.1);
    const R: f64 = 1.0;

    fn sphere() -> Solid {
        Solid::new(Shape::FreeForm(
            FreeForm::new(Quadric::sphere(C, R), vec![], None).unwrap(),
        ))
        .unwrap()
    }

    fn sampling() -> Sampling {
        Sampling {
            random_per_triangle: 4,
            seed: 1,
            directions: 24,
            rays_across: 40,
            eps_share: 1e-9,
            threads: 2,
        }
    }

    /// A unit sphere polygonised coarsely (10 cells across): every mesh sample's bound is its
    /// exact distance to the sphere, `R − |p − c|`, to the caster's ε (the mesh is inscribed, so
    /// inside the ball, and `±∇F` is radial, the direction of the nearest surface point) and
    /// never below it; vertices are on it; the
    /// true supremum over the triangles is `R − dist(c, T)` — the sagitta `R(1 − cos θ)` of the
    /// triangle's circumcircle where the circumcentre lies in the triangle, less elsewhere — and
    /// the samples' maximum is at most that and close to it.
    #[test]
    fn mesh_to_surface_on_a_sphere_is_the_sagitta() {
        let s = sphere();
        let mesh =
            fray_geometry::polygonise(&[&s], s.bounds(), 10, &MemoryBudget::default()).unwrap();
        let surface = Surface::new(&s, sampling().eps_share);
        let mut caster = RayCaster::new();
        let samples = mesh_samples(&mesh, 4, 1);
        let reach = 4.0 * mean_edge(&mesh);
        let mut max = 0.0f64;
        for sample in &samples {
            let d = surface.distance_bound(&mut caster, sample.point, sample.normal, reach);
            let exact = R - (sample.point - C).length();
            // A bound (never below, up to rounding), late by at most the caster's ε.
            assert!(
                d >= exact - 1e-12 && d <= exact + surface.eps(),
                "{}: {d} vs {exact}",
                sample.point
            );
            max = max.max(d);
        }
        for p in &mesh.positions {
            // On the sphere but for the root's tolerance (vertices are held 10⁻⁶ of an edge
            // off its ends).
            let exact = ((*p - C).length() - R).abs();
            let d = surface.distance_bound(&mut caster, *p, DVec3::Y, reach);
            assert!(
                exact < 1e-6 && d >= exact - 1e-12 && d <= exact + surface.eps(),
                "{d}"
            );
        }
        let mut sup = 0.0f64;
        let mut sagitta_max = 0.0f64;
        for t in &mesh.triangles {
            let corners = t.map(|i| mesh.positions[i as usize]);
            let here = R - point_triangle_distance(C, corners);
            sup = sup.max(here);
            let [a, b, c] = corners;
            // The circumradius and the sagitta of the cap it cuts from the sphere.
            let rho = (b - a).length() * (c - b).length() * (a - c).length()
                / (2.0 * (b - a).cross(c - a).length());
            let sagitta = R * (1.0 - (rho / R).min(1.0).asin().cos());
            assert!(here <= sagitta + 1e-6, "{here} > {sagitta}");
            sagitta_max = sagitta_max.max(sagitta);
        }
        assert!(max <= sup + surface.eps(), "{max} > {sup}");
        assert!(max >= 0.8 * sup, "{max} ≪ {sup}");
        // h = 0.2: the chords are about a cell long, the sagitta about h²/8R.
        assert!(sup > 0.002 && sup < 0.05, "{sup}");
        assert!(sup <= sagitta_max + 1e-9);
        // The whole measure agrees (the corners' triangle inequality never undercuts the radial
        // ray on a sphere).
        let h = measure(&surface, &[], &mesh, &sampling());
        assert!((h.mesh_to_surface.max - max).abs() < 1e-12);
        assert_eq!(h.mesh_to_surface.samples, samples.len());
        assert!(((h.mesh_to_surface.worst - C).length() - (R - max)).abs() < 1e-9);
    }

    /// Surface samples lie on the sphere to ε (entries and exits: two per ray that meets it);
    /// each one's distance to the inscribed mesh is at most the mesh side's supremum (the mesh
    /// point on the same radius is that close) and the largest is comparable to it; the
    /// two-sided figure is the larger side.
    #[test]
    fn surface_to_mesh_on_a_sphere_is_bounded_by_the_sagitta() {
        let s = sphere();
        let mesh =
            fray_geometry::polygonise(&[&s], s.bounds(), 10, &MemoryBudget::default()).unwrap();
        let surface = Surface::new(&s, sampling().eps_share);
        let points = surface.samples(&sampling());
        assert!(points.len() > 1000, "{}", points.len());
        for p in &points {
            assert!(
                ((*p - C).length() - R).abs() < 20.0 * surface.eps() + 1e-12,
                "{p}"
            );
        }
        // Rays through the sphere's disc (π/4 of the square's) cross it twice.
        let rays = 24.0 * 40.0 * 40.0;
        let expected = 2.0 * rays * std::f64::consts::FRAC_PI_4 / 1.001f64.powi(2) / 3.0;
        assert!((points.len() as f64 - expected).abs() < 0.05 * expected);
        let sup = mesh
            .triangles
            .iter()
            .map(|t| R - point_triangle_distance(C, t.map(|i| mesh.positions[i as usize])))
            .fold(0.0, f64::max);
        let grid = TriangleGrid::new(&mesh.positions, &mesh.triangles);
        let d = surface_to_mesh(&points, &grid, 2);
        let max = d.iter().copied().fold(0.0, f64::max);
        assert!(max <= sup + 1e-9, "{max} > {sup}");
        assert!(max >= 0.5 * sup, "{max} ≪ {sup}");
        let h = measure(&surface, &points, &mesh, &sampling());
        assert_eq!(h.surface_to_mesh.max, max);
        assert_eq!(
            h.two_sided(),
            h.mesh_to_surface.max.max(h.surface_to_mesh.max)
        );
        assert!(h.surface_to_mesh.p99 <= max && h.surface_to_mesh.p99 > 0.0);
    }

    /// Percentiles by nearest rank; the same points whatever the thread count.
    #[test]
    fn sides_rank_and_threads_do_not_matter() {
        let mut d: Vec<f64> = (1..=200).rev().map(f64::from).collect();
        let at: Vec<DVec3> = d.iter().map(|&x| DVec3::X * x).collect();
        let side = Side::of(&mut d, &at, Duration::ZERO);
        assert_eq!((side.samples, side.max, side.p99), (200, 200.0, 198.0));
        assert_eq!(side.worst, DVec3::X * 200.0);
        assert_eq!(Side::of(&mut [], &[], Duration::ZERO), Side::default());
        let s = sphere();
        let surface = Surface::new(&s, 1e-9);
        let one = Sampling {
            threads: 1,
            ..sampling()
        };
        let three = Sampling {
            threads: 3,
            ..sampling()
        };
        assert_eq!(surface.samples(&one), surface.samples(&three));
    }
}
