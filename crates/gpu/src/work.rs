//! The quadtree work list as the free-form pass uploads it: work items (tiles of at most
//! [`TILE`]² pixels, one workgroup each), their candidate objects with active leaves and
//! perturbations, and each candidate's pruned CSG program. With culling it is the list
//! `fray_scene::work_list` builds — the one fray-trace renders from; without, every tile of the
//! image grid with every object and all of its parts (the same arithmetic, nothing skipped).
//!
//! `WorkItem` and `Candidate` are fray-quadtree's `#[repr(C)]` Pod structs, uploaded as they
//! are; their WGSL mirrors are generated from [`WGSL_STRUCTS`], which a test checks against the
//! Rust layouts (and fray-gpu's naga test against the compiled module).

use fray_geometry::ActiveSet;
use fray_geometry::gpu_layout::{GpuSolids, WgslStruct, program_word};
#[cfg(test)]
use fray_geometry::gpu_layout::{OP_BITS, OP_LEAF};
use fray_quadtree::{Candidate, QuadtreeError, QuadtreeStats, WorkItem};
use fray_scene::{PrimitiveKind, Scene};

/// Side of a work item's tile in pixels, and of the workgroup that renders it.
pub const TILE: u32 = 8;

/// The upload-ready work list of one frame.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct GpuWork {
    /// Tiles sorted by first row (stably), so the items of a band of rows are one run.
    pub items: Vec<WorkItem>,
    pub candidates: Vec<Candidate>,
    /// Active leaves of the candidates (solid-local indices, increasing per candidate).
    pub leaves: Vec<u32>,
    /// Active perturbations of the candidates (object-wide indices, increasing per candidate).
    pub perturbations: Vec<u32>,
    /// Per candidate: `[first word, length]` of its program in [`GpuWork::program`].
    pub programs: Vec<[u32; 2]>,
    /// The solids' full programs (as [`GpuSolids`] lays them out, so `GpuSolid::info` still
    /// indexes them) followed by the candidates' pruned programs.
    pub program: Vec<u32>,
    /// The scheduler's counts when culling; `None` for the plain grid.
    pub stats: Option<QuadtreeStats>,
}

impl GpuWork {
    /// The culled work list of `scene` (`solids`: the scene's objects flattened in order). Free
    /// forms are listed with their pruned programs; a terrain the scheduler lists (id past the
    /// objects) stays in the list with an empty program, and the shader casts the terrain only
    /// on the pixels of items that list it, as fray-trace does. Items left with no candidate are
    /// dropped, and the stats count the items this pass runs.
    pub fn culled(scene: &Scene, solids: &GpuSolids) -> Result<Self, QuadtreeError> {
        let list = fray_scene::work_list(scene, TILE)?;
        let mut work = Self {
            program: solids.program.clone(),
            stats: Some(list.stats),
            ..Self::default()
        };
        let mut active = ActiveSet::new();
        for item in &list.items {
            let candidate_start = work.candidates.len() as u32;
            for c in list.candidates_of(item) {
                if c.kind == PrimitiveKind::Terrain.code() {
                    work.push_terrain(c.object);
                    continue;
                }
                let (Some(object), Some(flat)) = (
                    scene.objects.get(c.object as usize),
                    solids.solids.get(c.object as usize),
                ) else {
                    continue;
                };
                let (leaves, perturbations) =
                    (c.leaves(&list.leaves), c.perturbations(&list.perturbations));
                if !active.set(&object.solid, leaves, perturbations) {
                    continue;
                }
                let start = work.program.len() as u32;
                work.program.extend(
                    active
                        .program()
                        .iter()
                        .map(|&op| program_word(op, flat.info[0])),
                );
                work.programs
                    .push([start, work.program.len() as u32 - start]);
                work.candidates.push(Candidate {
                    leaf_start: work.leaves.len() as u32,
                    perturbation_start: work.perturbations.len() as u32,
                    ..*c
                });
                work.leaves.extend_from_slice(leaves);
                work.perturbations.extend_from_slice(perturbations);
            }
            let candidate_count = work.candidates.len() as u32 - candidate_start;
            if candidate_count > 0 {
                work.items.push(WorkItem {
                    candidate_start,
                    candidate_count,
                    ..*item
                });
            }
        }
        work.items.sort_by_key(|it| it.y0);
        if let Some(stats) = work.stats.as_mut() {
            stats.items = work.items.len() as u64;
        }
        Ok(work)
    }

    /// Every [`TILE`]-sized tile of the image with every object and all of its parts.
    pub fn everything(scene: &Scene, solids: &GpuSolids) -> Self {
        let mut work = Self {
            program: solids.program.clone(),
            ..Self::default()
        };
        for (i, (object, flat)) in scene.objects.iter().zip(&solids.solids).enumerate() {
            let leaves = object.solid.leaves().len() as u32;
            let perturbations = object.solid.perturbation_count() as u32;
            let (leaf_start, perturbation_start) = (work.leaves.len(), work.perturbations.len());
            work.candidates.push(Candidate {
                leaf_count: leaves,
                perturbation_count: perturbations,
                ..Candidate::new(
                    PrimitiveKind::FreeForm.code(),
                    i as u32,
                    leaf_start as u32,
                    perturbation_start as u32,
                    0.0,
                    f64::INFINITY,
                )
            });
            work.leaves.extend(0..leaves);
            work.perturbations.extend(0..perturbations);
            work.programs.push([flat.info[2], flat.info[3]]);
        }
        for k in 0..scene.terrains.len() {
            work.push_terrain(k as u32);
        }
        if work.candidates.is_empty() {
            return work;
        }
        for y0 in (0..scene.height).step_by(TILE as usize) {
            for x0 in (0..scene.width).step_by(TILE as usize) {
                work.items.push(WorkItem {
                    x0,
                    y0,
                    x1: (x0 + TILE).min(scene.width),
                    y1: (y0 + TILE).min(scene.height),
                    candidate_start: 0,
                    candidate_count: work.candidates.len() as u32,
                    t_min: 0.0,
                    t_max: f32::INFINITY,
                });
            }
        }
        work
    }

    /// Lists terrain `index`: no leaves, no perturbations, an empty program.
    fn push_terrain(&mut self, index: u32) {
        let (leaf_start, perturbation_start) = (self.leaves.len(), self.perturbations.len());
        self.candidates.push(Candidate::new(
            PrimitiveKind::Terrain.code(),
            index,
            leaf_start as u32,
            perturbation_start as u32,
            0.0,
            f64::INFINITY,
        ));
        self.programs.push([0, 0]);
    }

    /// The items whose tiles start in rows `[y0, y1)` (a run: items are sorted by first row).
    pub fn band(&self, y0: u32, y1: u32) -> &[WorkItem] {
        let a = self.items.partition_point(|it| it.y0 < y0);
        let b = self.items.partition_point(|it| it.y0 < y1);
        &self.items[a..b.max(a)]
    }
}

/// WGSL mirrors of fray-quadtree's `WorkItem` and `Candidate` (all fields 4-byte scalars, so
/// WGSL packs them back to back as `#[repr(C)]` does).
pub const WGSL_STRUCTS: [WgslStruct; 2] = [
    WgslStruct {
        name: "WorkItem",
        fields: &[
            ("x0", "u32"),
            ("y0", "u32"),
            ("x1", "u32"),
            ("y1", "u32"),
            ("candidate_start", "u32"),
            ("candidate_count", "u32"),
            ("t_min", "f32"),
            ("t_max", "f32"),
        ],
    },
    WgslStruct {
        name: "Candidate",
        fields: &[
            ("kind", "u32"),
            ("object", "u32"),
            ("leaf_start", "u32"),
            ("leaf_count", "u32"),
            ("perturbation_start", "u32"),
            ("perturbation_count", "u32"),
            ("t_min", "f32"),
            ("t_max", "f32"),
        ],
    },
];

#[cfg(test)]
mod tests {
    use super::*;
    use std::mem::{offset_of, size_of};

    #[test]
    fn wgsl_tables_match_rust_layouts() {
        let rust = [
            (
                size_of::<WorkItem>(),
                vec![
                    offset_of!(WorkItem, x0),
                    offset_of!(WorkItem, y0),
                    offset_of!(WorkItem, x1),
                    offset_of!(WorkItem, y1),
                    offset_of!(WorkItem, candidate_start),
                    offset_of!(WorkItem, candidate_count),
                    offset_of!(WorkItem, t_min),
                    offset_of!(WorkItem, t_max),
                ],
            ),
            (
                size_of::<Candidate>(),
                vec![
                    offset_of!(Candidate, kind),
                    offset_of!(Candidate, object),
                    offset_of!(Candidate, leaf_start),
                    offset_of!(Candidate, leaf_count),
                    offset_of!(Candidate, perturbation_start),
                    offset_of!(Candidate, perturbation_count),
                    offset_of!(Candidate, t_min),
                    offset_of!(Candidate, t_max),
                ],
            ),
        ];
        for (st, (size, offsets)) in WGSL_STRUCTS.iter().zip(rust) {
            assert_eq!(st.layout(|_| 4), (offsets, size), "{}", st.name);
        }
    }

    fn scene() -> Scene {
        fray_scene::parse(
            r#"Scene(
                image: (width: 37, height: 21),
                camera: Pinhole(eye: (0, 0, -6), look_at: (0, 0, 0), fov_y: 40),
                objects: [
                    (shape: Difference(Sphere(center: (-1, 0, 0), radius: 0.6),
                                       Sphere(center: (-0.6, 0, -0.4), radius: 0.3))),
                    (shape: FreeForm(base: Sphere(center: (1.2, 0, 0), radius: 0.5),
                        perturbations: [(form_factor: 2, quadric: Sphere(center: (1.5, 0.3, -0.3), radius: 0.3))])),
                ],
            )"#,
            "work.ron",
        )
        .unwrap()
    }

    fn flat(scene: &Scene) -> GpuSolids {
        let mut solids = GpuSolids::new(glam::DVec3::ZERO);
        for o in &scene.objects {
            solids.push(&o.solid, |_| 0);
        }
        solids
    }

    #[test]
    fn the_plain_grid_tiles_the_image_once_with_every_part() {
        let s = scene();
        let solids = flat(&s);
        let w = GpuWork::everything(&s, &solids);
        assert_eq!(w.items.len(), 5 * 3);
        let covered: u32 = w.items.iter().map(|i| (i.x1 - i.x0) * (i.y1 - i.y0)).sum();
        assert_eq!(covered, 37 * 21);
        assert_eq!(w.candidates.len(), 2);
        assert_eq!(w.leaves, [0, 1, 0]);
        assert_eq!(w.perturbations, [0]);
        assert_eq!(w.programs, [[0, 4], [4, 1]]);
        assert_eq!(w.program, solids.program);
        assert!(w.stats.is_none());
        assert_eq!(w.band(8, 16).len(), 5);
        assert!(w.band(21, 24).is_empty());
    }

    #[test]
    fn the_culled_list_prunes_programs_and_sorts_items_by_row() {
        let s = scene();
        let solids = flat(&s);
        let w = GpuWork::culled(&s, &solids).unwrap();
        let stats = w.stats.unwrap();
        assert_eq!(stats.items as usize, w.items.len());
        assert!(stats.cells_culled > 0 && w.items.len() < 15);
        assert!(w.items.windows(2).all(|p| p[0].y0 <= p[1].y0));
        assert_eq!(w.programs.len(), w.candidates.len());
        for (c, &[start, len]) in w.candidates.iter().zip(&w.programs) {
            assert!(len >= 1 && (start + len) as usize <= w.program.len());
            assert!(start as usize >= solids.program.len());
            // Leaf words of the pruned program name active leaves of the candidate's own solid.
            let first = solids.solids[c.object as usize].info[0];
            for &word in &w.program[start as usize..(start + len) as usize] {
                if word & ((1 << OP_BITS) - 1) == OP_LEAF {
                    let leaf = (word >> OP_BITS) - first;
                    assert!(c.leaves(&w.leaves).contains(&leaf));
                }
            }
        }
        // Every band's items start in the band.
        let band = w.band(8, 16);
        assert!(band.iter().all(|i| (8..16).contains(&i.y0)));
    }

    #[test]
    fn terrain_candidates_reach_the_gpu_where_listed() {
        // The scheduler's list names the terrain (its kind) where it may be hit: the
        // pass keeps it there, with an empty program, and the same items.
        let path = concat!(
            env!("CARGO_MANIFEST_DIR"),
            "/../../data/scenes/terrain_low.ron"
        );
        let mut s = fray_scene::load(std::path::Path::new(path)).unwrap();
        (s.width, s.height) = (64, 36);
        let list = fray_scene::work_list(&s, TILE).unwrap();
        let w = GpuWork::culled(&s, &flat(&s)).unwrap();
        assert_eq!(w.candidates.len(), w.programs.len());
        let terrain = PrimitiveKind::Terrain.code();
        let listed = |cands: &[Candidate]| cands.iter().any(|c| c.kind == terrain);
        let kept: Vec<&WorkItem> = list
            .items
            .iter()
            .filter(|it| !list.candidates_of(it).is_empty())
            .collect();
        assert_eq!(w.items.len(), kept.len());
        let mut by_tile = w.items.clone();
        by_tile.sort_by_key(|it| (it.y0, it.x0));
        let mut expected = kept.clone();
        expected.sort_by_key(|it| (it.y0, it.x0));
        for (g, c) in by_tile.iter().zip(expected) {
            assert_eq!((g.x0, g.y0), (c.x0, c.y0));
            let gpu = &w.candidates[g.candidate_start as usize..][..g.candidate_count as usize];
            assert_eq!(listed(gpu), listed(list.candidates_of(c)));
            let range =
                g.candidate_start as usize..(g.candidate_start + g.candidate_count) as usize;
            for k in range.filter(|&k| w.candidates[k].kind == terrain) {
                assert_eq!(w.programs[k], [0, 0]);
            }
        }
        // Some tiles list the terrain alone.
        assert!(w.items.iter().any(|i| {
            let c = &w.candidates[i.candidate_start as usize..][..i.candidate_count as usize];
            c.len() == 1 && c[0].kind == terrain
        }));
        assert_eq!(w.stats.unwrap().items as usize, w.items.len());
        // Without culling every tile lists every object and the terrain.
        let all = GpuWork::everything(&s, &flat(&s));
        assert!(
            all.items
                .iter()
                .all(|i| i.candidate_count as usize == s.objects.len() + 1)
        );
    }
}
