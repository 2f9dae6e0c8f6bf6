//! The quadtree work list as the GPU reads it: work items (tiles of at most [`TILE`]² pixels,
//! one workgroup each), their candidates of every primitive kind, and one index array behind the
//! scene's CSG programs in `indices` — the candidates' active leaves, active perturbations,
//! (first word, length) program pairs and pruned programs. With culling it is the list
//! `fray_scene::work_list` builds — the one fray-trace renders from; without, every tile of the
//! image grid with every primitive and all of its parts (the same arithmetic, nothing skipped).
//!
//! `WorkItem` and `Candidate` are fray-quadtree's `gpu_struct!`s, uploaded as they are.

use fray_geometry::ActiveSet;
use fray_geometry::gpu_layout::{GpuSolids, program_word};
use fray_quadtree::{
    Candidate, PixelCoverage, QuadtreeConfig, QuadtreeError, QuadtreeStats, WorkItem,
};
use fray_scene::{PrimitiveKind, Scene};

/// Side of a work item's tile in pixels, and of the workgroup that renders it.
pub const TILE: u32 = 8;

/// The upload-ready work list of one frame.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct GpuWork {
    /// Tiles sorted by first row (stably), so the items of a band of rows are one run.
    pub items: Vec<WorkItem>,
    /// Candidates; a free form's `leaf_start`/`perturbation_start` index [`GpuWork::indices`]
    /// as the GPU sees it (after the scene's programs).
    pub candidates: Vec<Candidate>,
    /// The index words that follow the scene's programs in the GPU's `indices` array: active
    /// leaves (solid-local, increasing per candidate), active perturbations (object-wide,
    /// increasing), the candidates' `(first word, length)` program pairs (at
    /// [`GpuWork::programs_base`], two words per candidate) and their pruned programs.
    pub indices: Vec<u32>,
    /// Where the candidates' program pairs start in the GPU's `indices` array.
    pub programs_base: u32,
    /// The scheduler's counts when culling; `None` for the plain grid.
    pub stats: Option<QuadtreeStats>,
}

/// One candidate's parts before the index arrays are laid out.
struct Listed {
    candidate: Candidate,
    leaves: Vec<u32>,
    perturbations: Vec<u32>,
    /// A pruned program (its words), or the solid's whole program `(first word, length)`.
    program: Program,
}

enum Program {
    Pruned(Vec<u32>),
    Whole(u32, u32),
    None,
}

impl GpuWork {
    /// The culled work list of `scene` seen by `camera` at `width × height` (`solids`: the
    /// scene's objects flattened in order, whose programs precede the work list in `indices`). Free forms are listed with their pruned programs;
    /// terrains and meshes with none, and their passes cast them only on the pixels of items
    /// that list them, as fray-trace does. Items left with no candidate are dropped.
    pub fn culled(
        scene: &Scene,
        (camera, width, height): (&fray_core::Projector, u32, u32),
        solids: &GpuSolids,
        config: &QuadtreeConfig,
    ) -> Result<Self, QuadtreeError> {
        let list = fray_scene::work_list_view(scene, camera, (width, height), config)?;
        let mut items = Vec::new();
        let mut listed = Vec::new();
        let mut active = ActiveSet::new();
        for item in &list.items {
            let candidate_start = listed.len() as u32;
            for c in list.candidates_of(item) {
                // Kinds other than free forms have no program: their passes cast the candidate.
                if c.kind != PrimitiveKind::FreeForm.code() {
                    listed.push(Listed {
                        candidate: *c,
                        leaves: Vec::new(),
                        perturbations: Vec::new(),
                        program: Program::None,
                    });
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
                let words = active
                    .program()
                    .iter()
                    .map(|&op| program_word(op, flat.first_leaf))
                    .collect();
                listed.push(Listed {
                    candidate: *c,
                    leaves: leaves.to_vec(),
                    perturbations: perturbations.to_vec(),
                    program: Program::Pruned(words),
                });
            }
            let candidate_count = listed.len() as u32 - candidate_start;
            if candidate_count > 0 {
                items.push(WorkItem {
                    candidate_start,
                    candidate_count,
                    ..*item
                });
            }
        }
        items.sort_by_key(|it| it.y0);
        let mut stats = list.stats;
        stats.items = items.len() as u64;
        Ok(Self::laid_out(
            items,
            listed,
            solids.program.len() as u32,
            Some(stats),
        ))
    }

    /// Every [`TILE`]-sized tile of the image with every primitive and all of its parts.
    pub fn everything(scene: &Scene, solids: &GpuSolids, (width, height): (u32, u32)) -> Self {
        let mut listed = Vec::new();
        for (i, (object, flat)) in scene.objects.iter().zip(&solids.solids).enumerate() {
            let leaves = object.solid.leaves().len() as u32;
            let perturbations = object.solid.perturbation_count() as u32;
            listed.push(Listed {
                candidate: Candidate::new(
                    PrimitiveKind::FreeForm.code(),
                    i as u32,
                    0,
                    0,
                    0.0,
                    f64::INFINITY,
                ),
                leaves: (0..leaves).collect(),
                perturbations: (0..perturbations).collect(),
                program: Program::Whole(flat.first_word, flat.word_count),
            });
        }
        let others = PrimitiveKind::ALL
            .into_iter()
            .filter(|k| *k != PrimitiveKind::FreeForm);
        for kind in others {
            for k in 0..scene.count(kind) {
                listed.push(Listed {
                    candidate: Candidate::new(kind.code(), k as u32, 0, 0, 0.0, f64::INFINITY),
                    leaves: Vec::new(),
                    perturbations: Vec::new(),
                    program: Program::None,
                });
            }
        }
        let mut items = Vec::new();
        if !listed.is_empty() {
            for y0 in (0..height).step_by(TILE as usize) {
                for x0 in (0..width).step_by(TILE as usize) {
                    items.push(WorkItem {
                        x0,
                        y0,
                        x1: (x0 + TILE).min(width),
                        y1: (y0 + TILE).min(height),
                        candidate_start: 0,
                        candidate_count: listed.len() as u32,
                        t_min: 0.0,
                        t_max: f32::INFINITY,
                    });
                }
            }
        }
        Self::laid_out(items, listed, solids.program.len() as u32, None)
    }

    /// The candidates and the index words of `listed`, the index arrays starting at word
    /// `base` of the GPU's `indices`.
    fn laid_out(
        items: Vec<WorkItem>,
        listed: Vec<Listed>,
        base: u32,
        stats: Option<QuadtreeStats>,
    ) -> Self {
        let leaves: usize = listed.iter().map(|l| l.leaves.len()).sum();
        let perturbations: usize = listed.iter().map(|l| l.perturbations.len()).sum();
        let programs_base = base + (leaves + perturbations) as u32;
        let mut pruned_base = programs_base + 2 * listed.len() as u32;
        let (mut leaf_words, mut pert_words) = (Vec::new(), Vec::new());
        let (mut pairs, mut pruned) = (Vec::new(), Vec::new());
        let mut candidates = Vec::with_capacity(listed.len());
        for l in listed {
            candidates.push(Candidate {
                leaf_start: base + leaf_words.len() as u32,
                leaf_count: l.leaves.len() as u32,
                perturbation_start: base + (leaves + pert_words.len()) as u32,
                perturbation_count: l.perturbations.len() as u32,
                ..l.candidate
            });
            leaf_words.extend_from_slice(&l.leaves);
            pert_words.extend_from_slice(&l.perturbations);
            match l.program {
                Program::Pruned(words) => {
                    pairs.extend([pruned_base, words.len() as u32]);
                    pruned_base += words.len() as u32;
                    pruned.extend(words);
                }
                Program::Whole(first, len) => pairs.extend([first, len]),
                Program::None => pairs.extend([0, 0]),
            }
        }
        let mut indices = leaf_words;
        indices.extend(pert_words);
        indices.extend(pairs);
        indices.extend(pruned);
        Self {
            items,
            candidates,
            indices,
            programs_base,
            stats,
        }
    }

    /// The items whose tiles start in rows `[y0, y1)` (a run: items are sorted by first row).
    pub fn band(&self, y0: u32, y1: u32) -> &[WorkItem] {
        let a = self.items.partition_point(|it| it.y0 < y0);
        let b = self.items.partition_point(|it| it.y0 < y1);
        &self.items[a..b.max(a)]
    }

    /// Bytes this list uploads.
    pub fn bytes(&self) -> u64 {
        (std::mem::size_of_val(self.items.as_slice())
            + std::mem::size_of_val(self.candidates.as_slice())
            + 4 * self.indices.len()) as u64
    }
}

/// The quadtree configuration of a GPU frame: [`TILE`]-sized cells, bundles over whole pixels
/// when anti-aliasing samples lie anywhere in them, the settings' memory budget.
pub fn quadtree_config(samples: u32, budget: fray_core::MemoryBudget) -> QuadtreeConfig {
    QuadtreeConfig {
        cell_size: TILE,
        memory_budget: budget,
        coverage: if samples > 1 {
            PixelCoverage::Area
        } else {
            PixelCoverage::Centres
        },
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use fray_geometry::gpu_layout::{OP_BITS, OP_LEAF};

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

    fn flat(s: &Scene) -> GpuSolids {
        let mut solids = GpuSolids::new(glam::DVec3::ZERO);
        for o in &s.objects {
            solids.push(&o.solid, |_| 0);
        }
        solids
    }

    /// `s`'s free forms flattened and its culled work list at the scene's own camera.
    fn culled(s: &Scene) -> (GpuSolids, GpuWork) {
        let solids = flat(s);
        let w = GpuWork::culled(
            s,
            (&s.camera, s.width, s.height),
            &solids,
            &QuadtreeConfig::new(TILE),
        )
        .unwrap();
        (solids, w)
    }

    /// Reads word `k` of the GPU's `indices` (scene programs, then the work list's words).
    fn word(solids: &GpuSolids, w: &GpuWork, k: u32) -> u32 {
        let head = solids.program.len() as u32;
        if k < head {
            solids.program[k as usize]
        } else {
            w.indices[(k - head) as usize]
        }
    }

    #[test]
    fn culled_items_keep_the_schedulers_tiles_and_index_the_gpu_array() {
        let s = scene();
        let (solids, w) = culled(&s);
        assert!(!w.items.is_empty() && w.stats.is_some());
        assert!(w.items.windows(2).all(|p| p[0].y0 <= p[1].y0));
        for (c_index, c) in w.candidates.iter().enumerate() {
            let at = w.programs_base + 2 * c_index as u32;
            let (start, len) = (word(&solids, &w, at), word(&solids, &w, at + 1));
            assert!(len >= 1);
            let first = solids.solids[c.object as usize].first_leaf;
            let leaves: Vec<u32> = (0..c.leaf_count)
                .map(|k| word(&solids, &w, c.leaf_start + k))
                .collect();
            for k in start..start + len {
                let op = word(&solids, &w, k);
                if op & ((1 << OP_BITS) - 1) == OP_LEAF {
                    assert!(leaves.contains(&((op >> OP_BITS) - first)));
                }
            }
        }
        let band = w.band(8, 16);
        assert!(band.iter().all(|i| (8..16).contains(&i.y0)));
        // Without culling: every tile, every object, whole programs.
        let all = GpuWork::everything(&s, &solids, (37, 21));
        assert_eq!(all.items.len(), 5 * 3);
        let at = all.programs_base + 2;
        assert_eq!(
            (word(&solids, &all, at), word(&solids, &all, at + 1)),
            (solids.solids[1].first_word, solids.solids[1].word_count)
        );
    }

    #[test]
    fn terrain_candidates_reach_the_gpu_where_listed() {
        let path = concat!(
            env!("CARGO_MANIFEST_DIR"),
            "/../../data/scenes/terrain_low.ron"
        );
        let mut s = fray_scene::load(std::path::Path::new(path)).unwrap();
        (s.width, s.height) = (64, 36);
        let list = fray_scene::work_list(&s, TILE).unwrap();
        let (solids, w) = culled(&s);
        let terrain = PrimitiveKind::Terrain.code();
        let kept = list
            .items
            .iter()
            .filter(|it| !list.candidates_of(it).is_empty())
            .count();
        assert_eq!(w.items.len(), kept);
        assert!(w.items.iter().any(|i| {
            let c = &w.candidates[i.candidate_start as usize..][..i.candidate_count as usize];
            c.len() == 1 && c[0].kind == terrain
        }));
        for (k, c) in w.candidates.iter().enumerate() {
            if c.kind == terrain {
                let at = w.programs_base + 2 * k as u32;
                assert_eq!((word(&solids, &w, at), word(&solids, &w, at + 1)), (0, 0));
            }
        }
    }

    /// Mesh candidates (one instance each) reach the GPU as the scheduler lists them — not
    /// taken for free forms of the same index —, with no program; without culling every item
    /// lists every instance after the free forms.
    #[test]
    fn mesh_candidates_reach_the_gpu_where_listed() {
        let bunny = concat!(env!("CARGO_MANIFEST_DIR"), "/../../data/meshes/bunny00.obj");
        let text = format!(
            "Scene(image: (width: 64, height: 40), \
             camera: Pinhole(eye: (0, 0.5, -4), look_at: (0, 0, 0)), \
             objects: [(shape: Sphere(center: (1.2, 0, 0), radius: 0.4)), \
                       (shape: Mesh(path: {bunny:?}, transform: (translate: (-0.8, 0, 0)))), \
                       (shape: Mesh(path: {bunny:?}, transform: (translate: (0.2, 0, 1))))])"
        );
        let s = fray_scene::parse(&text, "meshes.ron").unwrap();
        assert_eq!((s.objects.len(), s.meshes.len()), (1, 2));
        let (solids, w) = culled(&s);
        let mesh = PrimitiveKind::Mesh.code();
        let listed: Vec<u32> = w
            .candidates
            .iter()
            .filter(|c| c.kind == mesh)
            .map(|c| c.object)
            .collect();
        assert!(listed.contains(&0) && listed.contains(&1), "{listed:?}");
        for (k, c) in w.candidates.iter().enumerate() {
            if c.kind == mesh {
                let at = w.programs_base + 2 * k as u32;
                assert_eq!((word(&solids, &w, at), word(&solids, &w, at + 1)), (0, 0));
                assert_eq!((c.leaf_count, c.perturbation_count), (0, 0));
            }
        }
        // Some tile sees a mesh and no free form.
        assert!(w.items.iter().any(|i| {
            let c = &w.candidates[i.candidate_start as usize..][..i.candidate_count as usize];
            c.iter().all(|c| c.kind == mesh)
        }));
        let all = GpuWork::everything(&s, &solids, (s.width, s.height));
        let kinds: Vec<(u32, u32)> = all.candidates.iter().map(|c| (c.kind, c.object)).collect();
        assert_eq!(
            kinds,
            vec![(PrimitiveKind::FreeForm.code(), 0), (mesh, 0), (mesh, 1)]
        );
    }
}
