//! Meshes that used to stop fray-mesh (issue 22) now end in seconds: a face of 3·10⁷ corners is
//! refused by the memory budget before `tobj` or the BVH allocate (its triangles were not
//! counted, and the BVH build's allocation failed: a panic); copies of one triangle and fans of
//! slivers sharing a vertex — on which the old builder took quadratic time — build within
//! [`MAX_DEPTH`] levels and answer as a brute force does; empty and degenerate-only meshes answer
//! without a panic.

use fray_core::{Interval, MemoryBudget, Ray};
use fray_mesh::gpu_layout::{GpuMeshes, MeshLayoutError};
use fray_mesh::triangle::{RayFrame, intersect};
use fray_mesh::{BuildPreset, MAX_DEPTH, MAX_LEAF, MeshBvh, MeshError, PacketBvh, TriangleMesh};
use glam::{DAffine3, DVec3};
use std::time::{Duration, Instant};

use fray_test_support::Rng;

const ALL: Interval = Interval {
    lo: 0.0,
    hi: f64::INFINITY,
};

/// Far above the builds measured (≤ 1 s for 10⁶ triangles in the test profile) and far below
/// the old builder's quadratic times (30 s for 2·10⁴ copies, over 300 s for 5·10⁴): a build
/// slower than this has lost its bound, on a machine however loaded.
const BUILD_LIMIT: Duration = Duration::from_secs(60);

fn build_within_the_bounds(name: &str, mesh: TriangleMesh) -> MeshBvh {
    build_with_within_the_bounds(name, mesh, BuildPreset::default())
}

fn build_with_within_the_bounds(name: &str, mesh: TriangleMesh, preset: BuildPreset) -> MeshBvh {
    let n = mesh.triangles.len();
    let start = Instant::now();
    let bvh = MeshBvh::build_with(mesh, preset);
    let took = start.elapsed();
    println!(
        "{name}: {n} triangles built in {took:.2?}: {} nodes, depth {}",
        bvh.node_count(),
        bvh.max_depth()
    );
    assert!(took < BUILD_LIMIT, "{name}: {took:?}");
    assert!(bvh.max_depth() <= MAX_DEPTH, "{name}: {}", bvh.max_depth());
    assert!(bvh.bytes() <= MeshBvh::bytes_for(n), "{name}");
    // Every triangle in exactly one leaf of at most MAX_LEAF.
    let mut seen = vec![false; n];
    for node in bvh.nodes().filter(|n| n.is_leaf()) {
        assert!(
            node.count as usize <= MAX_LEAF,
            "{name}: leaf of {}",
            node.count
        );
        for &t in &bvh.leaf_order()[node.first as usize..(node.first + node.count) as usize] {
            assert!(
                !std::mem::replace(&mut seen[t as usize], true),
                "{name}: {t} twice"
            );
        }
    }
    assert!(seen.iter().all(|&s| s), "{name}: a triangle in no leaf");
    bvh
}

/// The BVH's and the packet path's nearest hit against the least `(t, triangle index)` over
/// every triangle, on `rays`; returns how many hit.
fn agrees_with_brute_force(name: &str, bvh: MeshBvh, rays: &[Ray]) -> usize {
    let m = bvh.mesh().clone();
    let packets = PacketBvh::new(bvh);
    let mut from_packets = vec![None; rays.len()];
    packets.nearest_hits(rays, &vec![ALL; rays.len()], &mut from_packets);
    let mut hits = 0;
    for (ray, packet_hit) in rays.iter().zip(&from_packets) {
        let frame = RayFrame::new(ray);
        let brute = (0..m.triangles.len())
            .filter_map(|i| intersect(&frame, m.corners(i), ALL).map(|h| (h.t, i as u32)))
            .min_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)));
        let got = packets
            .reference()
            .nearest_hit(ray, ALL)
            .map(|h| (h.t, h.triangle));
        assert_eq!(got, brute, "{name}: {ray:?}");
        assert_eq!(
            packet_hit.map(|h| (h.t, h.triangle)),
            brute,
            "{name}: packets"
        );
        assert_eq!(packets.reference().any_hit(ray, ALL), brute.is_some());
        hits += usize::from(brute.is_some());
    }
    hits
}

/// Rays from above toward random points of the box `lo..hi` in the plane `z = 0`, slightly
/// oblique, from one origin (a camera) and from scattered ones.
fn rays_down(rng: &mut Rng, lo: DVec3, hi: DVec3, count: usize) -> Vec<Ray> {
    let eye = DVec3::new(0.3, -0.2, 5.0);
    (0..count)
        .map(|i| {
            let target = lo + (hi - lo) * DVec3::new(rng.unit(), rng.unit(), 0.0);
            let origin = if i % 2 == 0 {
                eye
            } else {
                target + DVec3::new(rng.unit() - 0.5, rng.unit() - 0.5, 2.0)
            };
            Ray::new(origin, target - origin).unwrap()
        })
        .collect()
}

/// The face: `f 1 2 3 4 1 2 3 4 …` with 3·10⁷ corners (a 60 MB file) makes
/// 29 999 998 triangles; under a 64 MiB budget it is refused before `tobj` reads it, by an
/// error naming the file, what was to be made, how much it needs and the limit.
#[test]
fn a_face_of_thirty_million_corners_is_refused_by_the_budget() {
    let dir = std::env::temp_dir().join(format!("fray-mesh-robust-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join("huge_face.obj");
    let corners = 30_000_000;
    let mut text = String::with_capacity(2 * corners + 64);
    text.push_str("v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nf");
    for i in 0..corners {
        text.push_str([" 1", " 2", " 3", " 4"][i % 4]);
    }
    text.push('\n');
    std::fs::write(&path, &text).unwrap();
    drop(text);
    // `tobj` reads `l` lines as faces (3 corners or more become triangles): they are checked
    // and counted as faces are, a bad index refused at its line before tobj sees it.
    let bad = dir.join("line.obj");
    std::fs::write(
        &bad,
        "v 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nl 1/-9223372036854775807 2 3\n",
    )
    .unwrap();
    let e = TriangleMesh::load_obj(&bad, &MemoryBudget::default()).unwrap_err();
    assert!(
        matches!(&e, MeshError::Obj { line: 5, .. })
            && e.to_string().contains("texture coordinate"),
        "{e}"
    );
    let limit = 64 << 20;
    let start = Instant::now();
    let e = TriangleMesh::load_obj(&path, &MemoryBudget::new(limit)).unwrap_err();
    println!("refused in {:.2?}: {e}", start.elapsed());
    let MeshError::Budget(b) = &e else {
        panic!("not a budget refusal: {e}")
    };
    assert_eq!(b.limit, limit);
    // Its 29 999 998 triangles alone take more than 16 bytes each in tobj and in the mesh.
    assert!(b.needed > 16 * 29_999_998, "{}", b.needed);
    let message = e.to_string();
    for part in [
        path.display().to_string(),
        "29999998 triangles".into(),
        format!("{} bytes", b.needed),
        "64.0 MiB".into(),
    ] {
        assert!(message.contains(&part), "{part:?} not in {message}");
    }
    std::fs::remove_dir_all(&dir).ok();
}

/// 5·10⁴ copies of one triangle (30 s for 2·10⁴ before, over 300 s for 5·10⁴): every centre
/// is the same point, so no SAH plane separates them and the builder halves them by index —
/// depth ⌈log₂(5·10⁴ / 8)⌉ = 13. Every ray through the triangle meets all the copies at one `t`,
/// and the answer is the smallest index.
#[test]
fn fifty_thousand_copies_of_one_triangle_build_and_answer_as_a_brute_force() {
    let n = 50_000;
    let mesh = TriangleMesh::new(
        vec![
            DVec3::new(0.0, 0.0, 0.0),
            DVec3::new(1.0, 0.0, 0.0),
            DVec3::new(0.0, 1.0, 0.0),
        ],
        vec![[0, 1, 2]; n],
    )
    .unwrap();
    let bvh = build_within_the_bounds("copies", mesh);
    assert_eq!(bvh.max_depth(), 13);
    let rays = rays_down(&mut Rng(5), DVec3::splat(-0.2), DVec3::splat(1.2), 200);
    let hits = agrees_with_brute_force("copies", bvh, &rays);
    assert!(hits > 50, "{hits} of 200 rays hit");
}

/// A disc of 10⁶ slivers round one vertex (a fan: 10⁵ of them took the old builder 31 s, its
/// Morton-order neighbours' boxes nested), and a fan of 10⁵ slivers whose far ends lie on a
/// short segment, so that each triangle's box holds the one before it.
#[test]
fn fans_of_slivers_sharing_a_vertex_build_and_answer_as_a_brute_force() {
    let fan = |far: Vec<DVec3>| {
        let n = far.len() as u32 - 1;
        let mut positions = vec![DVec3::ZERO];
        positions.extend(far);
        TriangleMesh::new(positions, (1..=n).map(|i| [0, i, i + 1]).collect()).unwrap()
    };
    let n = 1_000_000;
    let disc = fan((0..=n)
        .map(|i| {
            let a = i as f64 / n as f64 * std::f64::consts::TAU;
            DVec3::new(a.cos(), a.sin(), 0.0)
        })
        .collect());
    let bvh = build_within_the_bounds("disc fan", disc);
    let rays = rays_down(&mut Rng(7), DVec3::splat(-1.1), DVec3::splat(1.1), 100);
    let hits = agrees_with_brute_force("disc fan", bvh, &rays);
    assert!(hits > 50, "{hits} of 100 rays hit");

    let n = 100_000;
    let nested = fan((0..=n)
        .map(|i| DVec3::new(1.0, 1e-3 * i as f64 / n as f64, 0.0))
        .collect());
    let bvh = build_within_the_bounds("nested fan", nested);
    let rays = rays_down(
        &mut Rng(9),
        DVec3::new(-0.1, -1e-4, 0.0),
        DVec3::new(1.1, 1.1e-3, 0.0),
        200,
    );
    let hits = agrees_with_brute_force("nested fan", bvh, &rays);
    assert!(hits > 50, "{hits} of 200 rays hit");
}

/// No triangles, or only degenerate ones (zero area: a repeated corner, collinear corners, all
/// corners at one point, a huge finite coordinate): the BVH, the packet path, an instance and
/// the GPU layout answer without a panic, as the brute force does (nothing to hit, or the
/// degenerate triangles' own answers).
#[test]
fn empty_and_degenerate_only_meshes_answer_without_a_panic() {
    let empty = MeshBvh::build(TriangleMesh::new(Vec::new(), Vec::new()).unwrap());
    assert_eq!((empty.node_count(), empty.max_depth()), (0, 0));
    assert!(
        empty
            .nearest_hit(&Ray::new(DVec3::ZERO, DVec3::Z).unwrap(), ALL)
            .is_none()
    );
    let p = PacketBvh::new(empty.clone());
    let rays = vec![Ray::new(DVec3::ZERO, DVec3::Z).unwrap(); 8];
    let mut hits = vec![None; 8];
    p.nearest_hits(&rays, &[ALL; 8], &mut hits);
    assert!(hits.iter().all(Option::is_none));
    let instances = [(0, DAffine3::IDENTITY)];
    assert!(GpuMeshes::build(&[&empty], &instances, DVec3::ZERO, &MemoryBudget::default()).is_ok());

    let big = 1e300;
    let positions = vec![
        DVec3::ZERO,
        DVec3::X,
        DVec3::new(2.0, 0.0, 0.0),
        DVec3::new(0.5, 0.5, 0.5),
        DVec3::new(big, -big, big),
    ];
    let triangles = vec![
        [0, 0, 1],
        [0, 1, 2],
        [3, 3, 3],
        [4, 4, 0],
        [1, 1, 1],
        [2, 1, 0],
        [4, 4, 4],
    ];
    let triangles: Vec<[u32; 3]> = triangles.into_iter().cycle().take(7 * 100).collect();
    let degenerate = TriangleMesh::new(positions, triangles).unwrap();
    let bvh = build_within_the_bounds("degenerate", degenerate);
    let mut rng = Rng(13);
    let rays: Vec<Ray> = (0..200)
        .map(|i| {
            // Along the segment's line, through its corners, and at random.
            let (o, d) = match i % 4 {
                0 => (DVec3::new(-1.0, 0.0, 0.0), DVec3::X),
                1 => (DVec3::new(0.5, 0.5, 2.0), DVec3::NEG_Z),
                2 => (DVec3::new(1.0, 0.0, 1.0), DVec3::NEG_Z),
                _ => (
                    DVec3::new(rng.unit(), rng.unit(), rng.unit()) * 4.0 - 2.0,
                    DVec3::new(rng.unit(), rng.unit(), rng.unit()) - 0.5,
                ),
            };
            Ray::new(o, d).unwrap()
        })
        .collect();
    agrees_with_brute_force("degenerate", bvh.clone(), &rays);
    // The GPU's f32 cannot hold 10³⁰⁰: a refusal, not a panic.
    let e = GpuMeshes::build(&[&bvh], &instances, DVec3::ZERO, &MemoryBudget::default());
    assert!(
        matches!(e, Err(MeshLayoutError::OutOfRange { .. })),
        "{e:?}"
    );
}

/// Every build preset keeps the bounds (leaves, depth, memory) and the answers: on the boeing
/// part (2 564 triangles) from rays all round it, on 10⁴ copies of one triangle (no plane
/// separates them) and on a fan of 10⁴ nested slivers. The presets differ in the tree (the
/// median build's differs from the SAH's), never in a hit.
#[test]
fn every_build_preset_keeps_the_bounds_and_the_brute_forces_answers() {
    let path =
        std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../data/meshes/boeing.obj");
    let boeing = TriangleMesh::load_obj(&path, &MemoryBudget::default()).unwrap();
    let copies = TriangleMesh::new(
        vec![DVec3::ZERO, DVec3::X, DVec3::Y],
        vec![[0, 1, 2]; 10_000],
    )
    .unwrap();
    let n = 10_000u32;
    let mut positions = vec![DVec3::ZERO];
    positions.extend((0..=n).map(|i| DVec3::new(1.0, 1e-3 * f64::from(i) / f64::from(n), 0.0)));
    let nested = TriangleMesh::new(positions, (1..=n).map(|i| [0, i, i + 1]).collect()).unwrap();
    let mut rng = Rng(11);
    let b = boeing.bounds();
    let all_round: Vec<Ray> = (0..1500)
        .map(|_| {
            let o = b.center() + rng.direction() * b.diagonal() * (0.1 + rng.unit());
            let toward = b.min + (b.max - b.min) * DVec3::new(rng.unit(), rng.unit(), rng.unit());
            Ray::new(o, toward - o).unwrap()
        })
        .collect();
    let down = rays_down(&mut rng, DVec3::splat(-0.2), DVec3::splat(1.2), 200);
    let mut orders = Vec::new();
    for preset in BuildPreset::ALL {
        let name = preset.name();
        let bvh = build_with_within_the_bounds(name, boeing.clone(), preset);
        orders.push(bvh.leaf_order().to_vec());
        let hits = agrees_with_brute_force(name, bvh, &all_round);
        assert!(hits > 200, "{name}: {hits} of 1500 rays hit");
        let bvh = build_with_within_the_bounds(name, copies.clone(), preset);
        assert!(
            agrees_with_brute_force(name, bvh, &down) > 20,
            "{name}: copies"
        );
        let bvh = build_with_within_the_bounds(name, nested.clone(), preset);
        agrees_with_brute_force(name, bvh, &down);
    }
    // The presets build different trees (else the sweep would compare one tree with itself).
    for (i, a) in orders.iter().enumerate() {
        for b in &orders[i + 1..] {
            assert_ne!(a, b, "two presets built the same tree");
        }
    }
}
