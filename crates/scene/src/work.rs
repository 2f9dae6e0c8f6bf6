//! The scene's cell test for the quadtree scheduler: which objects, leaves and perturbations of
//! the scene a cell's ray bundle may meet (box versus bundle), and the work list it yields — the
//! one list both backends render from (fray-trace casts each tile's pixels with the items'
//! [`ActiveSet`]s; fray-gpu uploads the same arrays and dispatches a workgroup per item). Each
//! kind's part of the test is its own (`crate::kinds`); this file walks the kinds.
//!
//! Every test is conservative against the per-ray tests of the ray caster (a box the bundle
//! misses is missed by every ray of the cell, with a margin), so casting a tile's pixels with its
//! [`ActiveSet`]s gives exactly the image of casting with everything.
//!
//! [`ActiveSet`]: fray_geometry::ActiveSet

use crate::{PrimitiveKind, Scene};
use fray_quadtree::{Candidates, QuadtreeConfig, RayBundle, WorkList, build_parallel};

/// The quadtree work list the backends render from when culling: tiles of at most
/// `cell_size` pixels with their candidate objects, active leaves and perturbations.
///
/// Candidates carry their primitive kind ([`crate::PrimitiveId::of_candidate`]), kind by kind
/// in [`PrimitiveKind::ALL`] order, each kind's in scene order; free forms carry their active
/// leaves and perturbations too. A cell keeps a candidate where its kind's own test — boxes
/// against the bundle, conservative against the kind's per-ray tests — says the bundle may meet
/// it.
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
    // Each kind's boxes, gathered once, indexed by the kind's code.
    let kinds: Vec<Box<dyn crate::kinds::Culling + '_>> = (0..)
        .map_while(PrimitiveKind::from_code)
        .map(|kind| crate::kinds::of(kind).culling(scene))
        .collect();
    let mut root = Candidates::new();
    for kind in PrimitiveKind::ALL {
        kinds[kind.code() as usize].roots(&mut root);
    }
    // One test per worker of the parallel build_parallel, each with its own scratch.
    let make_test = || {
        let mut tests: Vec<_> = kinds.iter().map(|k| k.cell_test()).collect();
        move |bundle: &RayBundle, parent: &Candidates, out: &mut Candidates| {
            for c in &parent.candidates {
                if let Some(test) = tests.get_mut(c.kind as usize) {
                    test(bundle, c, parent, out);
                }
            }
        }
    };
    build_parallel(camera, size, config, &root, make_test)
}
