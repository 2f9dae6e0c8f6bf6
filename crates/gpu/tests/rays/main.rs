//! One ray-by-ray suite, written once and run by both backends (as fidget runs one suite against
//! every evaluator): each backend ([`Backend`]: [`cpu::Cpu`], the f64 model crates;
//! [`gpu::Gpu`], the batch kernels of `fray_gpu::testing`) answers the same rays, for every kind
//! and every medium. Two sorts of check:
//! - **reference** checks (`free_forms`, `meshes`, `terrains`, `fog`, `sky`, `clouds`; trials
//!   `cpu::*` and `gpu::*`): each backend's answer against an **independent reference**, not
//!   against the other backend;
//! - **parity** checks (each module's `parity`; trials `parity::*`): the CPU and the GPU on the same rays,
//!   compared with GPU-vs-CPU bounds — the f32 arithmetic's, tighter than any independent
//!   reference allows (stated as such in each module) — on the harder cases: rays from inside
//!   the closed bunny, mirrored and far instances, barycentrics, shading normals and uvs, walls,
//!   starts and levels of detail of terrains, cell-edge normals, every fog model and phase with
//!   every term, the sky's tables and background, the clouds' in-scatter, density and jitter.
//!
//! Free forms: each answer (nearest hit, its normal, the any-hit answer over the same range)
//! against the solids' own function `F` (`Solid::eval`, inside where
//! `F ≥ 0`) sampled in f64 along the ray (2048 samples per box diagonal of each solid), every sign
//! change refined by bisection to 1e-12 — no interval bound, closed form or search of either
//! caster. (The CPU caster's full contract, every span at least `ε` thick found, is proven
//! against a double-double reference in `fray-geometry`'s accuracy tests.)
//!
//! A backend states its bounds ([`free_forms::Bounds`]): `depth(t)`, how far its hit may be from
//! where the reference's first inside span begins, and `sliver(t)`, the thickness of a span it
//! may step over (the CPU's contract: every span at least `ε` long is found; the GPU's leaves
//! are not widened by their f32 rounding, so grazing rays may miss a span a few `ε_gpu` thick).
//! The checks, per ray:
//! - **hit**: no reference span at least `sliver` thick (and not grazed) begins more than
//!   `depth / |cos θ|` before it, and the point is within `depth / |cos θ|` of an inside point
//!   (a reference span, or `F ≥ 0` at one of 64 points around it: the reference's sampling may
//!   step over a sliver the backend found);
//! - **miss**: every reference span is thinner than `sliver` or entered at a grazing angle
//!   (`|cos θ| < 0.05` to the surface: a ray that runs just inside a surface for a long way);
//! - **normal**: within `normal` of the reference's (`Solid::surface_at` at the reference hit),
//!   where both points have the same deciding leaf and the surface is not grazed;
//! - **any hit**: true wherever the nearest hit is outside a grazed span, and wherever a span the
//!   backend must find lies on the range.
//!
//! Meshes: each backend's nearest hit and geometric normal against a brute force over every
//! triangle of every instance in world space (f64 Möller–Trumbore: no BVH, and not the
//! watertight test either backend uses), on camera rays of the mesh data scenes
//! (`mesh_bunny_freeform.ron`, `mesh_aircraft_pair.ron`) and from a camera 10³ back: the depth
//! across the triangle's plane within `depth · scale`, the normal within `normal`, a hit/miss or
//! triangle difference only within `edge · scale` of an edge (`scale`: the lengths f32 positions
//! are rounded relative to — [`meshes::parity`]'s bounds on the GPU).
//!
//! Terrains: each backend's exact hit and normal on the DEM scenes (`terrain_low.ron`,
//! `terrain_high.ron`: from 1.25 km and from 66 km up) and from a camera 10⁴ back, against the
//! map's interpolated height (`Terrain::surface`) sampled at an eighth of a cell along the ray
//! and bisected, and its central differences for the normal (away from cell edges, where the
//! bilinear patches' normals jump): a hit within `depth(t) / |cos θ|` of where the ray goes
//! under, or within `depth(t)` above a ridge it skims; a miss only of a span shorter than 50
//! depth bounds.
//!
//! Media: each backend's transmittances (its terms' and its segment's) and optical depth of the
//! fog data scenes' layers against a composite Simpson quadrature of the extinction (4096
//! intervals), from the scenes' cameras, from inside the layer and from its top, over a fan of
//! elevations (the horizontal exactly) and ranges of 1 m to 20 km or unbounded: 810 rays. The sky's aerial perspective (transmittance,
//! in-scatter) and transmittance to the sun against its adaptive-quadrature reference, from the
//! sky scenes' cameras and 10 km above them: 240 rays. The clouds' march transmittance and
//! optical depth against the volume's density integrated at a 64th of the step: 534 rays of the
//! cloud scenes, from inside the cloud among them.
//!
//! Cases: camera rays of the free-form data scenes (`csg.ron`, `turboprop.ron`), grazing rays
//! (along the tangent plane at each hit, just outside the surface), and far rays (the camera
//! rays started 10⁴ back along themselves: long `t`, f32 positions far from the reference on the
//! GPU). The case counts are printed. The GPU runs in f32 relative to the camera
//! (`fray_gpu::testing::FreeFormBatch`), the CPU in f64 (`fray_geometry::RayCaster`).
//!
//! Parity cases (ray counts the same as the files they replace): terrains 146 724 rays in 14
//! comparisons, meshes 827 030 rays in 22 (236 522 from inside the closed bunny), fog 64 800
//! rays, sky 25 872 queries, clouds 31 392 rays; each module states its bounds and what it
//! measured.
//!
//! Uses the libtest-mimic harness: the GPU's trials (`gpu::*`, `parity::*`) are ignored without an
//! adapter and a failure under `FRAY_REQUIRE_GPU=1`; the CPU's (`cpu::*`) and the acceptance
//! rules' unit tests (`edge::*`) always run.

#[path = "../common/mod.rs"]
mod common;

mod backend;
mod cases;
mod clouds;
mod cpu;
mod fog;
mod free_forms;
mod gpu;
mod meshes;
mod sky;
mod terrains;

/// A backend of the suite: its name and what it answers for every kind and medium (each
/// declares its own: [`free_forms::FreeFormBackend`], …).
pub trait Backend:
    backend::Named
    + free_forms::FreeFormBackend
    + meshes::MeshBackend
    + terrains::TerrainBackend
    + fog::FogBackend
    + sky::SkyBackend
    + clouds::CloudBackend
{
}

impl Backend for cpu::Cpu {}
impl Backend for gpu::Gpu {}

/// A reference check: every case of a kind or medium through one backend.
type Suite = fn(&dyn Backend);

/// The reference checks of every kind and medium, by name.
const REFERENCE: [(&str, Suite); 6] = [
    ("free_forms", free_forms::suite),
    ("meshes", meshes::suite),
    ("terrains", terrains::suite),
    ("fog", fog::suite),
    ("sky", sky::suite),
    ("clouds", clouds::suite),
];

/// The parity checks (the CPU and the GPU on the same rays), the heaviest first.
const PARITY: [(&str, fn()); 16] = [
    (
        "parity::mesh::no_ray_escapes_the_closed_bunny",
        meshes::parity::no_ray_escapes_the_closed_bunny,
    ),
    (
        "parity::mesh::bunny_camera_and_random_rays",
        meshes::parity::bunny_camera_and_random_rays,
    ),
    (
        "parity::mesh::boeing_camera_and_random_rays",
        meshes::parity::boeing_camera_and_random_rays,
    ),
    (
        "parity::mesh::instances_rotated_scaled_translated",
        meshes::parity::instances_rotated_scaled_translated,
    ),
    (
        "parity::mesh::a_mesh_far_from_the_origin",
        meshes::parity::a_mesh_far_from_the_origin,
    ),
    (
        "parity::mesh::uvs_are_interpolated_like_the_cpu",
        meshes::parity::uvs_are_interpolated_like_the_cpu,
    ),
    (
        "parity::mesh::rebased_instances_hit_the_same",
        meshes::parity::rebased_instances_hit_the_same,
    ),
    (
        "parity::terrain::pixel_lod_views",
        terrains::parity::pixel_lod_views,
    ),
    (
        "parity::terrain::walls_and_starts_match_the_cpu",
        terrains::parity::walls_and_starts_match_the_cpu,
    ),
    (
        "parity::terrain::a_long_thin_map_on_the_gpu",
        terrains::parity::a_long_thin_map_on_the_gpu,
    ),
    (
        "parity::terrain::low_view_bilinear_and_bicubic",
        terrains::parity::low_view_bilinear_and_bicubic,
    ),
    (
        "parity::terrain::high_view_bilinear_and_lod",
        terrains::parity::high_view_bilinear_and_lod,
    ),
    (
        "parity::terrain::high_view_bicubic",
        terrains::parity::high_view_bicubic,
    ),
    ("parity::fog", fog::parity::fog_matches_the_cpu),
    ("parity::sky", sky::parity::sky_matches_the_cpu),
    ("parity::clouds", clouds::parity::clouds_match_the_cpu),
];

/// GPU checks of the batch kernels themselves.
const GPU_ONLY: [(&str, fn()); 1] = [(
    "gpu::clouds_grids_past_the_device_limit_are_refused",
    clouds::parity::grids_past_the_device_limit_are_refused,
)];

/// The acceptance rules' unit tests: no adapter needed.
const EDGE: [(&str, fn()); 4] = [
    (
        "edge::terrain_neighbour_normal_accepted_only_within_tolerance",
        terrains::parity::edge_neighbour_normal_accepted_only_within_tolerance,
    ),
    (
        "edge::terrain_corner_and_cut_out_cells",
        terrains::parity::edge_corner_and_cut_out_cells,
    ),
    (
        "edge::terrain_on_the_dem_from_terrain_high",
        terrains::parity::edge_on_the_dem_from_terrain_high,
    ),
    (
        "edge::mesh_distance_is_from_the_line_to_the_nearest_segment",
        meshes::parity::edge_distance_is_from_the_line_to_the_nearest_segment,
    ),
];

fn main() {
    let named = |name: &str, test: fn()| -> common::Test { (name.to_owned(), Box::new(test)) };
    let mut gpu_tests: Vec<common::Test> = PARITY
        .iter()
        .chain(&GPU_ONLY)
        .map(|&(name, test)| named(name, test))
        .collect();
    let mut host_tests: Vec<common::Test> = EDGE.iter().map(|&(n, t)| named(n, t)).collect();
    for &(name, suite) in &REFERENCE {
        gpu_tests.push((format!("gpu::{name}"), Box::new(move || suite(gpu::gpu()))));
        host_tests.push((format!("cpu::{name}"), Box::new(move || suite(&cpu::Cpu))));
    }
    common::run_tests(gpu_tests, host_tests)
}
