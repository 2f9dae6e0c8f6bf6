//! The subdivision: split the image rectangle into a quadtree, ask the caller's conservative test
//! which candidates each cell's ray bundle may meet, drop cells with none, emit leaf cells — on one
//! thread (`build`) or with the subtrees on the rayon pool (`build_parallel`, the same list).

use crate::{Candidate, Candidates, PixelCoverage, QuadtreeError, RayBundle, WorkItem, WorkList};
use fray_core::{MemoryBudget, Projector};

/// How far to subdivide.
#[derive(Clone, Debug)]
pub struct QuadtreeConfig {
    /// Cells no wider and no taller than this (pixels) are not split further: they become work
    /// items.
    pub cell_size: u32,
    /// The most the work list may take. Checked before the build against its largest possible
    /// size — every grid cell of `cell_size` a work item holding all of the root's candidates
    /// and index lists (the cell test only ever keeps a subset of its parent's) — so a build
    /// that could exceed it is refused instead of growing without a bound.
    pub memory_budget: MemoryBudget,
    /// Which points of its pixels a cell's rays pass through: the centres (one ray per pixel),
    /// or anywhere (anti-aliasing samples).
    pub coverage: PixelCoverage,
}

impl QuadtreeConfig {
    /// Cells of at most `cell_size` pixels, rays through the pixel centres, the default memory
    /// budget.
    pub fn new(cell_size: u32) -> Self {
        Self {
            cell_size,
            memory_budget: MemoryBudget::default(),
            coverage: PixelCoverage::Centres,
        }
    }

    /// The largest work list a build over a `width × height` image can make from `root`:
    /// one item per grid cell, each with every root candidate and index.
    pub fn largest_work_list_bytes(&self, (width, height): (u32, u32), root: &Candidates) -> u64 {
        let cell = u64::from(self.cell_size.max(1));
        let cells = u64::from(width).div_ceil(cell) * u64::from(height).div_ceil(cell);
        let per_item = std::mem::size_of::<WorkItem>() as u64
            + std::mem::size_of::<Candidate>() as u64 * root.candidates.len() as u64
            + 4 * (root.leaves.len() + root.perturbations.len()) as u64;
        cells.saturating_mul(per_item)
    }
}

impl Default for QuadtreeConfig {
    fn default() -> Self {
        Self::new(8)
    }
}

/// Builds the work list of a `width × height` image seen through `projector`.
///
/// `root` lists every candidate for the whole image. For each cell, `test(bundle, parent, out)`
/// gets the cell's [`RayBundle`] and the candidates that survived in the parent cell, and writes
/// into `out` (cleared) those that rays of the bundle *may* meet, with their leaves and
/// perturbations; it must be conservative: dropping something a ray of the cell can hit changes
/// the image. Cells left with no candidate are culled with all their children.
pub fn build<F>(
    projector: &Projector,
    (width, height): (u32, u32),
    config: &QuadtreeConfig,
    root: &Candidates,
    mut test: F,
) -> Result<WorkList, QuadtreeError>
where
    F: FnMut(&RayBundle, &Candidates, &mut Candidates),
{
    check(config, width, height, root)?;
    let mut out = WorkList::default();
    let mut scratch: Vec<Candidates> = Vec::new();
    let mut state = State {
        projector,
        size: (width, height),
        cell_size: config.cell_size,
        coverage: config.coverage,
        test: &mut test,
        out: &mut out,
        scratch: &mut scratch,
        frontier: None,
    };
    state.visit((0, 0, width, height), root, 0);
    Ok(out)
}

/// [`build`] on the current rayon pool: the same work list, item for item and index for index.
///
/// The cells above a few levels are tested in order on this thread; the subtrees below them
/// are built in parallel, each with its own test from `make_test` (so tests may keep scratch
/// space), and joined in depth-first order.
pub fn build_parallel<M, F>(
    projector: &Projector,
    (width, height): (u32, u32),
    config: &QuadtreeConfig,
    root: &Candidates,
    make_test: M,
) -> Result<WorkList, QuadtreeError>
where
    M: Fn() -> F + Sync,
    F: FnMut(&RayBundle, &Candidates, &mut Candidates),
{
    use rayon::prelude::*;
    check(config, width, height, root)?;
    // Enough subtrees to keep every thread busy when some are culled early: 4^depth ≥ 8 × threads.
    let threads = rayon::current_num_threads().max(1);
    let mut frontier = 0usize;
    while 4usize.pow(frontier as u32) < 8 * threads && frontier < 8 {
        frontier += 1;
    }
    // The top levels: their stats go into `top`, their leaves and subtrees into `tasks`.
    let mut top = WorkList::default();
    let mut tasks: Vec<Task> = Vec::new();
    let mut test = make_test();
    let mut state = State {
        projector,
        size: (width, height),
        cell_size: config.cell_size,
        coverage: config.coverage,
        test: &mut test,
        out: &mut top,
        scratch: &mut Vec::new(),
        frontier: Some((frontier, &mut tasks)),
    };
    state.visit((0, 0, width, height), root, 0);
    let parts: Vec<WorkList> = tasks
        .into_par_iter()
        .map_init(
            || (make_test(), Vec::new()),
            |(test, scratch), task| {
                let mut out = WorkList::default();
                match task {
                    Task::Emit(cell, candidates) => out.push(cell, &candidates),
                    Task::Subtree(cell, parent, depth) => {
                        let mut state = State {
                            projector,
                            size: (width, height),
                            cell_size: config.cell_size,
                            coverage: config.coverage,
                            test,
                            out: &mut out,
                            scratch,
                            frontier: None,
                        };
                        state.visit(cell, &parent, depth);
                    }
                }
                out
            },
        )
        .collect();
    let mut out = WorkList {
        stats: top.stats,
        ..WorkList::default()
    };
    for part in parts {
        out.append(part);
    }
    Ok(out)
}

/// The configuration, image size and memory errors both builds report.
fn check(
    config: &QuadtreeConfig,
    width: u32,
    height: u32,
    root: &Candidates,
) -> Result<(), QuadtreeError> {
    if config.cell_size == 0 {
        return Err(QuadtreeError::ZeroCellSize);
    }
    if width == 0 || height == 0 {
        return Err(QuadtreeError::EmptyImage(width, height));
    }
    config.memory_budget.check(
        format!(
            "the quadtree work list ({width} × {height} pixels in cells of {}, {} candidates at most per cell)",
            config.cell_size,
            root.candidates.len()
        ),
        config.largest_work_list_bytes((width, height), root),
    )?;
    Ok(())
}

/// A cell `(x0, y0, x1, y1)` in pixels.
type Cell = (u32, u32, u32, u32);

/// A piece of the parallel build, in depth-first order: a leaf cell found above the frontier
/// (emitted as is) or a subtree at it (cell, its parent's candidates, depth).
enum Task {
    Emit(Cell, Candidates),
    Subtree(Cell, Candidates, usize),
}

/// The up to four children of `cell` in visiting order, or `None` when it is no larger than the
/// cell size (a leaf). Splits at a multiple of the cell size so leaf tiles align to a grid.
fn children((x0, y0, x1, y1): Cell, cell_size: u32) -> Option<[Option<Cell>; 4]> {
    let (w, h) = (x1 - x0, y1 - y0);
    let split_x = w > cell_size;
    let split_y = h > cell_size;
    if !split_x && !split_y {
        return None;
    }
    let xm = if split_x {
        x0 + half_aligned(w, cell_size)
    } else {
        x1
    };
    let ym = if split_y {
        y0 + half_aligned(h, cell_size)
    } else {
        y1
    };
    let mut out = [None; 4];
    let mut k = 0;
    for (cy0, cy1) in [(y0, ym), (ym, y1)] {
        for (cx0, cx1) in [(x0, xm), (xm, x1)] {
            if cx0 < cx1 && cy0 < cy1 {
                out[k] = Some((cx0, cy0, cx1, cy1));
                k += 1;
            }
        }
    }
    Some(out)
}

struct State<'a, F> {
    projector: &'a Projector,
    size: (u32, u32),
    cell_size: u32,
    coverage: PixelCoverage,
    test: &'a mut F,
    out: &'a mut WorkList,
    /// One candidate list per depth, reused.
    scratch: &'a mut Vec<Candidates>,
    /// For the top of [`build_parallel`]: the depth at which subtrees are left as tasks, and
    /// the task list, which also takes the leaf cells found above it (in order).
    frontier: Option<(usize, &'a mut Vec<Task>)>,
}

impl<F> State<'_, F>
where
    F: FnMut(&RayBundle, &Candidates, &mut Candidates),
{
    fn visit(&mut self, cell: Cell, parent: &Candidates, depth: usize) {
        if let Some((frontier, tasks)) = &mut self.frontier
            && depth == *frontier
        {
            tasks.push(Task::Subtree(cell, parent.clone(), depth));
            return;
        }
        self.out.stats.cells_visited += 1;
        let bundle = RayBundle::covering(self.projector, self.size, cell, self.coverage);
        if self.scratch.len() <= depth {
            self.scratch.resize_with(depth + 1, Candidates::new);
        }
        let mut mine = std::mem::take(&mut self.scratch[depth]);
        mine.clear();
        (self.test)(&bundle, parent, &mut mine);
        if mine.is_empty() {
            self.out.stats.cells_culled += 1;
        } else {
            match (children(cell, self.cell_size), &mut self.frontier) {
                (None, None) => self.out.push(cell, &mine),
                (None, Some((_, tasks))) => tasks.push(Task::Emit(cell, mine.clone())),
                (Some(children), _) => {
                    for child in children.into_iter().flatten() {
                        self.visit(child, &mine, depth + 1);
                    }
                }
            }
        }
        self.scratch[depth] = mine;
    }
}

/// About half of `len`, rounded up to a multiple of `cell` (so `0 < result < len` for
/// `len > cell`).
fn half_aligned(len: u32, cell: u32) -> u32 {
    let cells = len.div_ceil(cell);
    (cells.div_ceil(2) * cell).min(len - 1).max(1)
}

#[cfg(test)]
mod tests {
    use super::*;
    use fray_core::Pinhole;
    use glam::DVec3;

    fn camera() -> Projector {
        Projector::Pinhole(
            Pinhole::new(DVec3::new(0.0, 0.0, -5.0), DVec3::ZERO, DVec3::Y, 1.0, 0.1).unwrap(),
        )
    }

    fn everything() -> Candidates {
        let mut c = Candidates::new();
        c.begin(0, 0, 0.0, f64::INFINITY);
        c
    }

    #[test]
    fn keeping_everything_tiles_the_image_exactly_once() {
        for (w, h, cell) in [(100, 37, 8), (1, 1, 8), (64, 64, 16), (33, 90, 5)] {
            let list = build(
                &camera(),
                (w, h),
                &QuadtreeConfig::new(cell),
                &everything(),
                |_, parent, out| out.clone_from(parent),
            )
            .unwrap();
            let mut covered = vec![0u8; (w * h) as usize];
            for it in &list.items {
                assert!(it.x1 - it.x0 <= cell && it.y1 - it.y0 <= cell);
                for y in it.y0..it.y1 {
                    for x in it.x0..it.x1 {
                        covered[(y * w + x) as usize] += 1;
                    }
                }
            }
            assert!(covered.iter().all(|&c| c == 1));
            assert_eq!(list.stats.items as usize, list.items.len());
            assert_eq!(list.stats.cells_culled, 0);
        }
    }

    /// A deterministic, uneven culling test: keeps each parent candidate whose hash with the
    /// cell is not 0 mod 5 (and leaves and perturbations likewise), so subtrees differ.
    fn patchy(b: &RayBundle, parent: &Candidates, out: &mut Candidates) {
        let h = |k: u32| (b.x0.wrapping_mul(73) ^ b.y0.wrapping_mul(151) ^ k.wrapping_mul(31)) % 5;
        for c in &parent.candidates {
            if h(c.object) == 0 && b.x1 - b.x0 < 40 {
                continue;
            }
            out.begin(
                c.kind,
                c.object,
                f64::from(c.t_min) + 0.5,
                f64::from(c.t_max),
            );
            for &l in c.leaves(&parent.leaves) {
                if h(l + 7) != 0 {
                    out.push_leaf(l);
                }
            }
            for &p in c.perturbations(&parent.perturbations) {
                if h(p + 13) != 1 {
                    out.push_perturbation(p);
                }
            }
        }
    }

    #[test]
    fn the_parallel_build_makes_the_sequential_list() {
        let mut root = Candidates::new();
        for object in 0..6 {
            root.begin(0, object, 0.0, 100.0);
            for l in 0..3 {
                root.push_leaf(l);
            }
            for p in 0..4 {
                root.push_perturbation(p);
            }
        }
        for threads in [1, 3, 16] {
            let pool = rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .build()
                .unwrap();
            for (w, h, cell) in [
                (300, 200, 8),
                (64, 64, 16),
                (7, 5, 8),
                (1, 1, 1),
                (1000, 3, 4),
            ] {
                let config = QuadtreeConfig::new(cell);
                let sequential = build(&camera(), (w, h), &config, &root, patchy).unwrap();
                let parallel = pool
                    .install(|| build_parallel(&camera(), (w, h), &config, &root, || patchy))
                    .unwrap();
                assert_eq!(
                    parallel, sequential,
                    "{w}×{h} cell {cell}, {threads} threads"
                );
            }
        }
        let zero = QuadtreeConfig::new(0);
        let e = build_parallel(&camera(), (4, 4), &zero, &root, || patchy);
        assert_eq!(e, Err(QuadtreeError::ZeroCellSize));
        let e = build_parallel(&camera(), (0, 4), &QuadtreeConfig::default(), &root, || {
            patchy
        });
        assert_eq!(e, Err(QuadtreeError::EmptyImage(0, 4)));
    }

    #[test]
    fn culled_cells_produce_no_items_and_bad_configs_are_errors() {
        let list = build(
            &camera(),
            (64, 64),
            &QuadtreeConfig::new(8),
            &everything(),
            |b, parent, out| {
                if b.x0 < 32 {
                    out.clone_from(parent);
                }
            },
        )
        .unwrap();
        assert!(list.items.iter().all(|i| i.x1 <= 32));
        assert_eq!(list.items.len(), 32);
        assert!(list.stats.cells_culled > 0);
        let e = build(
            &camera(),
            (4, 4),
            &QuadtreeConfig::new(0),
            &everything(),
            |_, _, _| {},
        );
        assert_eq!(e, Err(QuadtreeError::ZeroCellSize));
        let e = build(
            &camera(),
            (0, 4),
            &QuadtreeConfig::default(),
            &everything(),
            |_, _, _| {},
        );
        assert_eq!(e, Err(QuadtreeError::EmptyImage(0, 4)));
    }

    /// A work list that could outgrow its budget is refused before the build, naming it; one
    /// within is built, and its real size is within the estimate.
    #[test]
    fn a_work_list_over_its_budget_is_refused_before_it_is_built() {
        let mut root = Candidates::new();
        for object in 0..3 {
            root.begin(0, object, 0.0, f64::INFINITY);
            root.push_leaf(0);
            root.push_perturbation(object);
        }
        let keep_all =
            |_: &RayBundle, parent: &Candidates, out: &mut Candidates| out.clone_from(parent);
        let mut config = QuadtreeConfig::new(8);
        let largest = config.largest_work_list_bytes((64, 48), &root);
        // 8 × 6 cells of (32 + 3 × 32 + 4 × 6) bytes.
        assert_eq!(largest, 48 * (32 + 96 + 24));
        config.memory_budget = MemoryBudget::new(largest);
        let list = build(&camera(), (64, 48), &config, &root, keep_all).unwrap();
        let bytes = list.items.len() * 32
            + list.candidates.len() * 32
            + 4 * (list.leaves.len() + list.perturbations.len());
        assert_eq!(
            bytes as u64, largest,
            "keeping everything reaches the estimate"
        );
        config.memory_budget = MemoryBudget::new(largest - 1);
        for e in [
            build(&camera(), (64, 48), &config, &root, keep_all).unwrap_err(),
            build_parallel(&camera(), (64, 48), &config, &root, || keep_all).unwrap_err(),
        ] {
            let QuadtreeError::Budget(b) = &e else {
                panic!("expected a budget error, got {e}");
            };
            assert_eq!((b.needed, b.limit), (largest, largest - 1));
            assert!(e.to_string().contains("quadtree work list"), "{e}");
        }
    }
}
