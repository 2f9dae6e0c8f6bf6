//! The scene's cell test for the quadtree scheduler: which objects, leaves and perturbations of
//! the scene a cell's ray bundle may meet (box versus bundle), and the work list it yields — the
//! one list both backends render from (fray-trace casts each tile's pixels with the items'
//! [`ActiveSet`]s; fray-gpu uploads the same arrays and dispatches a workgroup per item).
//!
//! Every test is conservative against the per-ray tests of the ray caster (a box the bundle
//! misses is missed by every ray of the cell, with a margin), so casting a tile's pixels with its
//! [`ActiveSet`]s gives exactly the image of casting with everything.

use crate::{PrimitiveKind, Scene};
use fray_core::Aabb;
use fray_geometry::ActiveSet;
use fray_quadtree::{Candidates, QuadtreeConfig, RayBundle, WorkList, build_parallel};

/// The boxes the cell test needs, gathered once per frame.
struct ObjectBoxes {
    solid: Aabb,
    leaves: Vec<Aabb>,
    /// Per object-wide perturbation: its support box (`None`: unbounded, always kept). The whole
    /// box, not its part inside the leaf's box: a perturbation is dropped only where it is zero
    /// all along the tile's rays, so normals evaluated with the subset are exact too.
    perturbations: Vec<Option<Aabb>>,
}

fn object_boxes(scene: &Scene) -> Vec<ObjectBoxes> {
    scene
        .objects
        .iter()
        .map(|o| {
            let mut perturbations = Vec::new();
            for leaf in o.solid.leaves() {
                for p in leaf.perturbations() {
                    perturbations.push(p.support_bounds());
                }
            }
            ObjectBoxes {
                solid: o.solid.bounds(),
                leaves: o.solid.leaves().iter().map(|l| l.bounds()).collect(),
                perturbations,
            }
        })
        .collect()
}

/// A terrain's box and its coarse max columns (level [`Terrain::coarsest_stop_level`], at most
/// 8 × 8 columns: each column is a cell's map rectangle from the base up to the pyramid's maximum
/// over it). Every hit — the exact surface, and the max-column tops a LOD search (bias or pixel
/// footprint) stops at, which lie in the columns of any coarser level — is in one of the columns,
/// so a bundle that misses all of them misses the terrain.
///
/// [`Terrain::coarsest_stop_level`]: fray_terrain::Terrain::coarsest_stop_level
struct TerrainBoxes {
    bounds: Aabb,
    columns: Vec<Aabb>,
}

fn terrain_boxes(scene: &Scene) -> Vec<TerrainBoxes> {
    scene
        .terrains
        .iter()
        .map(|t| {
            let t = &t.terrain;
            let level = t.coarsest_stop_level();
            let side = 1usize << level;
            let columns = (0..side * side)
                .filter_map(|k| t.column_bounds(level, k % side, k / side))
                .collect();
            TerrainBoxes {
                bounds: t.bounds(),
                columns,
            }
        })
        .collect()
}

/// The quadtree work list the backends render from when culling: tiles of at most
/// `cell_size` pixels with their candidate objects, active leaves and perturbations.
///
/// Candidates carry their primitive kind ([`crate::PrimitiveId::of_candidate`]): free forms (with their
/// active leaves and perturbations) first, in scene order, then terrains (no leaves, no
/// perturbations), then meshes (no leaves, no perturbations). A cell keeps a terrain when its
/// bundle meets the terrain's box and one of its coarse max columns, a mesh when it meets the
/// instance's world box.
pub fn work_list(scene: &Scene, cell_size: u32) -> Result<WorkList, fray_quadtree::QuadtreeError> {
    work_list_within(scene, &QuadtreeConfig::new(cell_size))
}

/// [`work_list`] with the quadtree's configuration: cell size and memory budget (a list that
/// could outgrow the budget is refused before it is built).
pub fn work_list_within(
    scene: &Scene,
    config: &QuadtreeConfig,
) -> Result<WorkList, fray_quadtree::QuadtreeError> {
    work_list_view(scene, &scene.camera, (scene.width, scene.height), config)
}

/// [`work_list_within`] for a view of the scene other than its own: `camera` at `size` (a
/// resident GPU scene seen from a moved camera).
pub fn work_list_view(
    scene: &Scene,
    camera: &fray_core::Projector,
    size: (u32, u32),
    config: &QuadtreeConfig,
) -> Result<WorkList, fray_quadtree::QuadtreeError> {
    let boxes = object_boxes(scene);
    let terrains = terrain_boxes(scene);
    let (free_form, terrain) = (
        PrimitiveKind::FreeForm.code(),
        PrimitiveKind::Terrain.code(),
    );
    let mut root = Candidates::new();
    for (i, (object, b)) in scene.objects.iter().zip(&boxes).enumerate() {
        root.begin(free_form, i as u32, 0.0, f64::INFINITY);
        for l in 0..b.leaves.len() as u32 {
            root.push_leaf(l);
        }
        // Every perturbation, zero form factors included (the caster skips those per ray; the
        // normals sum them like the full evaluation does).
        for k in 0..object.solid.perturbation_count() as u32 {
            root.push_perturbation(k);
        }
    }
    for k in 0..terrains.len() {
        root.begin(terrain, k as u32, 0.0, f64::INFINITY);
    }
    let mesh = PrimitiveKind::Mesh.code();
    let mesh_boxes: Vec<Aabb> = scene.meshes.iter().map(|m| m.instance.bounds()).collect();
    for k in 0..mesh_boxes.len() {
        root.begin(mesh, k as u32, 0.0, f64::INFINITY);
    }
    // One test per worker of the parallel build_parallel, each with its own scratch set.
    let make_test =
        || {
            let mut active = ActiveSet::new();
            let boxes = &boxes;
            let terrains = &terrains;
            let mesh_boxes = &mesh_boxes;
            move |bundle: &RayBundle, parent: &Candidates, out: &mut Candidates| {
                for c in &parent.candidates {
                    if c.kind == mesh {
                        // The instance's world box (it holds every triangle, with a margin).
                        if let Some(range) = mesh_boxes
                            .get(c.object as usize)
                            .and_then(|b| bundle.box_range(b))
                        {
                            out.begin(mesh, c.object, range.lo, range.hi);
                        }
                        continue;
                    }
                    if c.kind == terrain {
                        let Some(t) = terrains.get(c.object as usize) else {
                            continue;
                        };
                        if bundle.box_range(&t.bounds).is_some() {
                            let hull = t.columns.iter().filter_map(|b| bundle.box_range(b)).reduce(
                                |a, b| fray_core::Interval::new(a.lo.min(b.lo), a.hi.max(b.hi)),
                            );
                            if let Some(range) = hull {
                                out.begin(terrain, c.object, range.lo, range.hi);
                            }
                        }
                        continue;
                    }
                    let Some(b) = boxes.get(c.object as usize) else {
                        continue;
                    };
                    let Some(t) = bundle.box_range(&b.solid) else {
                        continue;
                    };
                    out.begin(free_form, c.object, t.lo, t.hi);
                    for &l in c.leaves(&parent.leaves) {
                        if bundle.box_range(&b.leaves[l as usize]).is_some() {
                            out.push_leaf(l);
                        }
                    }
                    for &p in c.perturbations(&parent.perturbations) {
                        if b.perturbations[p as usize]
                            .is_none_or(|pb| bundle.box_range(&pb).is_some())
                        {
                            out.push_perturbation(p);
                        }
                    }
                    let solid = &scene.objects[c.object as usize].solid;
                    let (leaves, perts) = out
                        .candidates
                        .last()
                        .map(|last| {
                            (
                                last.leaves(&out.leaves),
                                last.perturbations(&out.perturbations),
                            )
                        })
                        .unwrap_or((&[], &[]));
                    if !active.set(solid, leaves, perts) {
                        out.cancel();
                    }
                }
            }
        };
    build_parallel(camera, size, config, &root, make_test)
}
