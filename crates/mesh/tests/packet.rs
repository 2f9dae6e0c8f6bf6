//! The packet path against the f64 reference, bit for bit: coherent tiles of pinhole views and
//! random incoherent rays on the bunny and the Boeing, rays aimed at vertices and edge midpoints
//! (axis-aligned ones too, lying in box faces), rays from inside, ranges cut short at the
//! reference's own hits, degenerate directions, the empty mesh, the bunny 10⁶ from the origin;
//! and the tie rule (smallest triangle index) in the reference against a brute force.

use fray_core::{Interval, MemoryBudget, Pinhole, Projector, Ray};
use fray_mesh::triangle::{RayFrame, intersect};
use fray_mesh::{LANES, MeshBvh, MeshHit, PacketBvh, TriangleMesh};
use glam::DVec3;
use proptest::prelude::*;
use std::path::Path;
use std::sync::OnceLock;

fn load(name: &str) -> TriangleMesh {
    let path = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../data/meshes")
        .join(name);
    TriangleMesh::load_obj(&path, &MemoryBudget::default()).unwrap_or_else(|e| panic!("{e}"))
}

fn bunny() -> &'static PacketBvh {
    static B: OnceLock<PacketBvh> = OnceLock::new();
    B.get_or_init(|| PacketBvh::new(MeshBvh::build(load("bunny00.obj"))))
}

fn boeing() -> &'static PacketBvh {
    static B: OnceLock<PacketBvh> = OnceLock::new();
    B.get_or_init(|| PacketBvh::new(MeshBvh::build(load("boeing.obj"))))
}

/// The bunny moved by (10⁶, −10⁶, 10⁶).
fn far_bunny() -> &'static PacketBvh {
    static B: OnceLock<PacketBvh> = OnceLock::new();
    B.get_or_init(|| {
        let m = load("bunny00.obj");
        let offset = DVec3::new(1e6, -1e6, 1e6);
        let moved = TriangleMesh::new(
            m.positions.iter().map(|p| *p + offset).collect(),
            m.triangles,
        )
        .unwrap();
        PacketBvh::new(MeshBvh::build(moved))
    })
}

/// Checks the packet path against the reference for `rays` over `ranges`; returns the number
/// of nearest hits.
fn check(bvh: &PacketBvh, rays: &[Ray], ranges: &[Interval]) -> usize {
    let mut hits = vec![None; rays.len()];
    bvh.nearest_hits(rays, ranges, &mut hits);
    let mut occluded = vec![false; rays.len()];
    bvh.any_hits(rays, ranges, &mut occluded);
    let reference = bvh.reference();
    for (i, (ray, range)) in rays.iter().zip(ranges).enumerate() {
        let want = reference.nearest_hit(ray, *range);
        assert!(
            same(hits[i], want),
            "ray {i} {ray:?} over {range:?}: packet {:?}, reference {want:?}",
            hits[i]
        );
        assert_eq!(
            occluded[i],
            reference.any_hit(ray, *range),
            "any hit, ray {i} {ray:?} over {range:?}"
        );
        assert_eq!(occluded[i], want.is_some(), "ray {i}: any hit vs nearest");
    }
    hits.iter().filter(|h| h.is_some()).count()
}

/// Bit-for-bit equality (so that `-0.0` and `0.0` differ, and NaN would be caught).
fn same(a: Option<MeshHit>, b: Option<MeshHit>) -> bool {
    match (a, b) {
        (None, None) => true,
        (Some(a), Some(b)) => {
            a.t.to_bits() == b.t.to_bits()
                && a.triangle == b.triangle
                && a.barycentric.map(f64::to_bits) == b.barycentric.map(f64::to_bits)
        }
        _ => false,
    }
}

/// A pinhole view's rays, tile by tile (`tile`² pixels, Morton order inside a tile, as a
/// renderer hands them over), with `t > 0`.
fn tiles(bvh: &MeshBvh, eye_offset: DVec3, side: u32, tile: u32) -> Vec<Ray> {
    let b = bvh.bounds();
    let eye = b.center() + eye_offset * b.diagonal();
    let camera =
        Projector::Pinhole(Pinhole::new(eye, b.center(), DVec3::Y, 0.5, 0.01).expect("camera"));
    let mut rays = Vec::new();
    for ty in (0..side).step_by(tile as usize) {
        for tx in (0..side).step_by(tile as usize) {
            for i in 0..tile * tile {
                let (mut x, mut y) = (0, 0);
                for bit in 0..8 {
                    x |= ((i >> (2 * bit)) & 1) << bit;
                    y |= ((i >> (2 * bit + 1)) & 1) << bit;
                }
                if let Some(c) = camera.pixel_ray(tx + x, ty + y, side, side) {
                    rays.push(c.ray);
                }
            }
        }
    }
    rays
}

const ALL: Interval = Interval {
    lo: 0.0,
    hi: f64::INFINITY,
};

#[test]
fn coherent_tiles_match_the_reference_on_the_bunny_the_boeing_and_far_from_the_origin() {
    for (name, bvh) in [
        ("bunny", bunny()),
        ("boeing", boeing()),
        ("far bunny", far_bunny()),
    ] {
        for (offset, tile) in [
            (DVec3::new(0.0, 0.0, -1.2), 16),
            (DVec3::new(0.9, 0.4, 0.8), 8),
            (DVec3::new(-0.3, -1.1, 0.2), 32),
        ] {
            let rays = tiles(bvh.reference(), offset, 128, tile);
            let ranges = vec![ALL; rays.len()];
            let hits = check(bvh, &rays, &ranges);
            assert!(hits > rays.len() / 10, "{name}: {hits} hits");
        }
    }
}

#[test]
fn shadow_rays_from_hit_points_match_the_reference() {
    for bvh in [bunny(), boeing()] {
        let rays = tiles(bvh.reference(), DVec3::new(0.0, 0.2, -1.2), 96, 16);
        let mut hits = vec![None; rays.len()];
        bvh.nearest_hits(&rays, &vec![ALL; rays.len()], &mut hits);
        let b = bvh.reference().bounds();
        let light = b.center() + DVec3::new(1.0, 2.0, -1.5) * b.diagonal();
        let (mut shadow, mut ranges) = (Vec::new(), Vec::new());
        for (ray, hit) in rays.iter().zip(&hits) {
            if let Some(h) = hit {
                let p = ray.at(h.t);
                let to = light - p;
                shadow.push(Ray::new(p, to).unwrap());
                // From the surface itself (t = 0 excluded): the hit triangle is not met again.
                ranges.push(Interval::new(0.0, to.length()));
            }
        }
        check(bvh, &shadow, &ranges);
    }
}

/// Shadow rays from the mesh's own vertices and edge midpoints toward a point light (lines that
/// all pass through one point, tested as lines through it: the pre-test's tightest cases are
/// rays through shared edges and vertices), over ranges from 0 and from just past the surface.
#[test]
fn shadow_rays_from_vertices_and_edges_toward_a_point_light_match_the_reference() {
    for bvh in [bunny(), boeing()] {
        let m = bvh.reference().mesh();
        let b = bvh.reference().bounds();
        let light = b.center() + DVec3::new(-0.8, 1.7, 1.2) * b.diagonal();
        let (mut rays, mut ranges) = (Vec::new(), Vec::new());
        for t in m.triangles.iter().step_by(5) {
            let p = t.map(|v| m.positions[v as usize]);
            for from in [p[0], (p[0] + p[1]) * 0.5, (p[0] + p[1] + p[2]) / 3.0] {
                let to = light - from;
                rays.extend(Ray::new(from, to));
                ranges.push(Interval::new(0.0, to.length()));
                rays.extend(Ray::new(from, to));
                ranges.push(Interval::new(1e-9 * b.diagonal(), to.length()));
            }
        }
        check(bvh, &rays, &ranges);
    }
}

/// Rays aimed exactly at vertices and edge midpoints, from outside and from inside, and the
/// axis-aligned rays through vertices (zero direction components; rays lying in box faces).
#[test]
fn rays_through_vertices_and_edges_match_the_reference() {
    for bvh in [bunny(), boeing()] {
        let m = bvh.reference().mesh();
        let b = bvh.reference().bounds();
        let (c, r) = (b.center(), b.diagonal());
        let mut rays = Vec::new();
        for (k, t) in m.triangles.iter().enumerate().step_by(7) {
            let p = t.map(|v| m.positions[v as usize]);
            for target in [p[0], (p[0] + p[1]) * 0.5, (p[1] + p[2]) * 0.5] {
                let o = match k % 3 {
                    0 => c + DVec3::new(0.3, 0.9, -1.0) * r,
                    1 => c,
                    _ => target + DVec3::new(0.0, 0.0, -r),
                };
                rays.extend(Ray::new(o, target - o));
            }
            for axis in [DVec3::X, DVec3::NEG_Y, DVec3::Z] {
                rays.extend(Ray::new(p[0] - axis * r, axis));
            }
        }
        let ranges = vec![ALL; rays.len()];
        let hits = check(bvh, &rays, &ranges);
        assert!(hits > rays.len() / 2, "{hits} of {}", rays.len());
        // The same targets from one camera (the one-origin path), in packets.
        for eye in [c + DVec3::new(0.2, 0.4, -1.1) * r, c] {
            let rays: Vec<Ray> = m
                .triangles
                .iter()
                .step_by(3)
                .flat_map(|t| {
                    let p = t.map(|v| m.positions[v as usize]);
                    [p[0], (p[0] + p[1]) * 0.5, (p[1] + p[2]) * 0.5]
                })
                .filter_map(|target| Ray::new(eye, target - eye))
                .collect();
            check(bvh, &rays, &vec![ALL; rays.len()]);
        }
    }
}

/// Ranges that end at, just past and just before the reference's own hit, and that start at it
/// (stepping from hit to hit along the ray).
#[test]
fn ranges_cut_short_match_the_reference() {
    let bvh = bunny();
    let rays = tiles(bvh.reference(), DVec3::new(0.5, 0.3, -1.0), 64, 8);
    let (mut all_rays, mut ranges) = (Vec::new(), Vec::new());
    for ray in &rays {
        let mut lo = 0.0;
        for _ in 0..4 {
            let Some(h) = bvh
                .reference()
                .nearest_hit(ray, Interval::new(lo, f64::INFINITY))
            else {
                break;
            };
            for range in [
                Interval::new(lo, h.t),
                Interval::new(lo, h.t.next_up()),
                Interval::new(lo, h.t.next_down()),
                Interval::new(h.t, f64::INFINITY),
                Interval::new(h.t.next_down(), h.t * 2.0),
            ] {
                all_rays.push(*ray);
                ranges.push(range);
            }
            lo = h.t;
        }
    }
    assert!(all_rays.len() > 10_000);
    check(bvh, &all_rays, &ranges);
}

/// Directions with zero and tiny components, origins on the mesh's box faces, negative and empty
/// ranges, the empty mesh: all answered like the reference, none panics.
#[test]
fn degenerate_rays_and_the_empty_mesh_match_the_reference() {
    let bvh = bunny();
    let b = bvh.reference().bounds();
    let c = b.center();
    let mut rays = Vec::new();
    for dir in [
        DVec3::X,
        DVec3::NEG_X,
        DVec3::Y,
        DVec3::NEG_Z,
        DVec3::new(1.0, 1.0, 0.0),
        DVec3::new(0.0, -1.0, 1.0),
        DVec3::new(1e-300, 0.0, 1.0),
        DVec3::new(-1e-40, 1e-30, 1.0),
        DVec3::new(1.0, 1e-200, -1e-20),
    ] {
        for o in [
            c,
            DVec3::new(b.min.x, c.y, c.z),
            DVec3::new(c.x, b.max.y, c.z),
            b.min,
            c - dir * b.diagonal(),
        ] {
            rays.extend(Ray::new(o, dir));
        }
    }
    // Non-unit directions are rays too (`t` in units of their length).
    rays.push(Ray {
        origin: c - DVec3::Z,
        dir: DVec3::new(0.0, 0.0, 3.0),
    });
    let n = rays.len();
    for range in [
        ALL,
        Interval::new(-1.0, 1.0),
        Interval::new(0.05, 0.1),
        Interval::new(1.0, 1.0),
        Interval { lo: 2.0, hi: 1.0 },
        Interval::new(f64::INFINITY, f64::INFINITY),
    ] {
        check(bvh, &rays, &vec![range; n]);
    }

    let empty = PacketBvh::new(MeshBvh::build(TriangleMesh::new(vec![], vec![]).unwrap()));
    let mut hits = vec![None; n];
    empty.nearest_hits(&rays, &vec![ALL; n], &mut hits);
    assert!(hits.iter().all(Option::is_none));
    check(&empty, &rays, &vec![ALL; n]);
}

/// Ties: every triangle doubled (the copies far apart in index), so each hit has a twin at the
/// same `t`; both paths pick the smaller index, as a brute force over every triangle does.
#[test]
fn ties_go_to_the_smallest_triangle_index() {
    let m = load("boeing.obj");
    let n = m.triangles.len() as u32;
    let mut triangles = m.triangles.clone();
    // The copy of triangle i is triangle n + i, the same corners in the same order, so the same
    // `t` to the bit (rotating the corners would change the rounding).
    triangles.extend(m.triangles.iter().copied());
    let doubled = TriangleMesh::new(m.positions.clone(), triangles).unwrap();
    let bvh = PacketBvh::new(MeshBvh::build(doubled));
    let rays = tiles(bvh.reference(), DVec3::new(0.4, 0.5, -0.9), 64, 16);
    let ranges = vec![ALL; rays.len()];
    let hits = check(&bvh, &rays, &ranges);
    assert!(hits > 300, "{hits}");
    let mesh = bvh.reference().mesh();
    for ray in rays.iter().step_by(5) {
        let frame = RayFrame::new(ray);
        let brute = (0..mesh.triangles.len())
            .filter_map(|i| intersect(&frame, mesh.corners(i), ALL).map(|h| (h.t, i as u32)))
            .min_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)));
        let got = bvh
            .reference()
            .nearest_hit(ray, ALL)
            .map(|h| (h.t, h.triangle));
        assert_eq!(got, brute);
        if let Some((_, t)) = got {
            assert!(t < n, "the twin {t} won");
        }
    }
}

/// A flat grid of unit squares (two triangles each) in z = 1 and rays along +z through its
/// vertices and edges: a ray with zero x and y components lies in the planes of leaf boxes'
/// faces, and must still hit.
#[test]
fn axis_aligned_rays_in_box_faces_hit_a_grid() {
    let n = 24;
    let mut positions = Vec::new();
    for y in 0..=n {
        for x in 0..=n {
            positions.push(DVec3::new(f64::from(x), f64::from(y), 1.0));
        }
    }
    let mut triangles = Vec::new();
    let v = |x: u32, y: u32| y * (n + 1) + x;
    for y in 0..n {
        for x in 0..n {
            triangles.push([v(x, y), v(x + 1, y), v(x + 1, y + 1)]);
            triangles.push([v(x, y), v(x + 1, y + 1), v(x, y + 1)]);
        }
    }
    let bvh = PacketBvh::new(MeshBvh::build(
        TriangleMesh::new(positions, triangles).unwrap(),
    ));
    let mut rays = Vec::new();
    for y in 0..=2 * n {
        for x in 0..=2 * n {
            let o = DVec3::new(f64::from(x) * 0.5, f64::from(y) * 0.5, 0.0);
            rays.extend(Ray::new(o, DVec3::Z));
            rays.extend(Ray::new(o + DVec3::new(0.0, 0.0, 2.0), DVec3::NEG_Z));
        }
    }
    let ranges = vec![ALL; rays.len()];
    let hits = check(&bvh, &rays, &ranges);
    assert_eq!(hits, rays.len(), "a ray along a grid line went through");
}

/// Random rays: origins in and around the box, directions anywhere (a few axis-aligned),
/// ranges from 0 or cut, in packets of random size.
fn random_rays(seed: u64, count: usize, bvh: &MeshBvh) -> (Vec<Ray>, Vec<Interval>) {
    let mut s = seed;
    let mut next = move || {
        s = s.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = s;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        ((z ^ (z >> 31)) >> 11) as f64 / (1u64 << 53) as f64
    };
    let b = bvh.bounds();
    let (mut rays, mut ranges) = (Vec::new(), Vec::new());
    while rays.len() < count {
        let o = b.center() + (DVec3::new(next(), next(), next()) - 0.5) * 2.0 * b.diagonal();
        let mut d = DVec3::new(next(), next(), next()) - 0.5;
        if next() < 0.1 {
            d = DVec3::ZERO;
            d[(next() * 3.0) as usize % 3] = if next() < 0.5 { 1.0 } else { -1.0 };
        } else if next() < 0.5 {
            // Aimed into the box: most of these hit.
            d = b.min + (b.max - b.min) * DVec3::new(next(), next(), next()) - o;
        }
        let Some(ray) = Ray::new(o, d) else { continue };
        let range = if next() < 0.7 {
            ALL
        } else {
            Interval::new(next() * b.diagonal(), next() * 3.0 * b.diagonal())
        };
        rays.push(ray);
        ranges.push(range);
    }
    (rays, ranges)
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(24))]

    #[test]
    fn random_incoherent_rays_match_the_reference(seed in any::<u64>(), count in 1..3 * LANES) {
        for bvh in [bunny(), boeing(), far_bunny()] {
            let (rays, ranges) = random_rays(seed, count * 8, bvh.reference());
            check(bvh, &rays, &ranges);
        }
    }

    /// One origin per packet (a camera's packets take their own path), directions anywhere.
    #[test]
    fn random_rays_from_one_origin_match_the_reference(seed in any::<u64>(), count in 1..3 * LANES) {
        for bvh in [bunny(), boeing(), far_bunny()] {
            let (mut rays, ranges) = random_rays(seed, count * 4, bvh.reference());
            let origin = rays[0].origin;
            for (i, ray) in rays.iter_mut().enumerate() {
                // Every packet but a few lanes of the last shares `origin`.
                if i + 3 < count * 4 {
                    ray.origin = origin;
                }
            }
            check(bvh, &rays, &ranges);
        }
    }
}

/// An instance's tile of world rays through its packets (`Instance::nearest_hits`, as the CPU
/// frame loop casts them) against its ray-by-ray `nearest_hit`, bit for bit: rotated, scaled
/// and mirrored placements, a pinhole's rows in the order a tile lists them (packets that do
/// not start on a row and a last one cut short), and ranges that start past the eye and end
/// at infinity, at the ray's own hit (open: excluded), between, or before the mesh.
#[test]
fn instances_cast_tiles_through_packets_as_ray_by_ray() {
    use fray_mesh::Instance;
    use glam::{DAffine3, DQuat};
    use std::sync::Arc;
    let packets = Arc::new(PacketBvh::new(MeshBvh::build(load("bunny00.obj"))));
    let placements = [
        DAffine3::IDENTITY,
        DAffine3::from_scale_rotation_translation(
            DVec3::splat(0.7),
            DQuat::from_rotation_y(0.6) * DQuat::from_rotation_x(-0.3),
            DVec3::new(3.0, -1.0, 2.0),
        ),
        DAffine3::from_scale_rotation_translation(
            DVec3::new(-1.3, 0.9, 1.1),
            DQuat::from_rotation_z(0.2),
            DVec3::new(-2.0, 0.5, 1e3),
        ),
    ];
    let mut local = Vec::new();
    for to_world in placements {
        let (mut found, mut shadowed) = (0, 0);
        let instance = Instance::with_packets(packets.clone(), to_world).unwrap();
        assert!(instance.packets().is_some());
        let b = instance.bounds();
        let eye = b.center() + DVec3::new(0.3, 0.2, -1.5) * b.diagonal();
        let camera =
            Projector::Pinhole(Pinhole::new(eye, b.center(), DVec3::Y, 0.6, 0.01).expect("camera"));
        let (side, tile) = (60, 13);
        for ty in (0..side).step_by(tile) {
            for tx in (0..side).step_by(tile) {
                let mut rays = Vec::new();
                let mut near = Vec::new();
                for y in ty..(ty + tile).min(side) {
                    for x in tx..(tx + tile).min(side) {
                        if let Some(c) =
                            camera.pixel_ray(x as u32, y as u32, side as u32, side as u32)
                        {
                            rays.push(c.ray);
                            near.push(c.t_near);
                        }
                    }
                }
                let mut ranges: Vec<Interval> = near
                    .iter()
                    .map(|&lo| Interval::new(lo, f64::INFINITY))
                    .collect();
                // The range's end: by lane, infinity, the ray's own hit, half way to it, or
                // before the mesh altogether.
                for (k, (ray, range)) in rays.iter().zip(&mut ranges).enumerate() {
                    if let Some(h) = instance.nearest_hit(ray, *range) {
                        found += 1;
                        range.hi = match k % 4 {
                            0 => f64::INFINITY,
                            1 => h.t,
                            2 => 0.5 * (range.lo + h.t),
                            _ => range.lo * 1.01,
                        };
                    }
                }
                let mut hits = vec![None; rays.len()];
                instance.nearest_hits(&rays, &ranges, &mut hits, &mut local);
                let plain = Instance::new(instance.mesh.clone(), to_world).unwrap();
                let mut plain_hits = vec![None; rays.len()];
                plain.nearest_hits(&rays, &ranges, &mut plain_hits, &mut local);
                for (k, (ray, range)) in rays.iter().zip(&ranges).enumerate() {
                    let want = instance.nearest_hit(ray, *range);
                    assert!(
                        same(hits[k], want) && same(plain_hits[k], want),
                        "{to_world:?}, tile ({tx}, {ty}), ray {k} over {range:?}: packets {:?}, \
                         ray by ray {:?}, reference {want:?}",
                        hits[k],
                        plain_hits[k]
                    );
                }
                // Any hits over the same ranges, and shadow rays toward a sun from the hits
                // over the whole range (parallel rays from scattered origins, as the frame
                // loop casts them): `Instance::any_hits` against `any_hit`.
                let mut shadow_rays = rays.clone();
                let mut shadow_ranges = ranges.clone();
                let sun = DVec3::new(0.3, 0.8, -0.5).normalize();
                for (ray, range) in rays.iter().zip(&near) {
                    let whole = Interval::new(*range, f64::INFINITY);
                    if let Some(h) = instance.nearest_hit(ray, whole) {
                        shadow_rays.push(Ray::new(ray.at(h.t), sun).unwrap());
                        shadow_ranges.push(Interval::new(1e-9 * b.diagonal(), f64::INFINITY));
                    }
                }
                let mut occluded = vec![false; shadow_rays.len()];
                instance.any_hits(&shadow_rays, &shadow_ranges, &mut occluded, &mut local);
                let mut plain_occluded = vec![false; shadow_rays.len()];
                plain.any_hits(
                    &shadow_rays,
                    &shadow_ranges,
                    &mut plain_occluded,
                    &mut local,
                );
                for (k, (ray, range)) in shadow_rays.iter().zip(&shadow_ranges).enumerate() {
                    let want = instance.any_hit(ray, *range);
                    shadowed += usize::from(want && k >= rays.len());
                    assert!(
                        occluded[k] == want && plain_occluded[k] == want,
                        "{to_world:?}, tile ({tx}, {ty}), any-hit ray {k} over {range:?}: \
                         packets {}, ray by ray {}, reference {want}",
                        occluded[k],
                        plain_occluded[k]
                    );
                }
            }
        }
        // Rays that hit over the whole range (before it was cut), and shadowed hits.
        assert!(found > 300, "{to_world:?}: {found} hits");
        assert!(shadowed > 30, "{to_world:?}: {shadowed} shadowed hits");
    }
}
