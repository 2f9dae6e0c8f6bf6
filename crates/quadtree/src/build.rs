//! The subdivision: split the image rectangle into a quadtree, ask the caller's conservative test
//! which candidates each cell's ray bundle may meet, drop cells with none, emit leaf cells.

use crate::{Candidates, QuadtreeError, RayBundle, WorkList};
use fray_core::Projector;

/// How far to subdivide.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct QuadtreeConfig {
    /// Cells no wider and no taller than this (pixels) are not split further: they become work
    /// items.
    pub cell_size: u32,
}

impl Default for QuadtreeConfig {
    fn default() -> Self {
        Self { cell_size: 8 }
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
    if config.cell_size == 0 {
        return Err(QuadtreeError::ZeroCellSize);
    }
    if width == 0 || height == 0 {
        return Err(QuadtreeError::EmptyImage(width, height));
    }
    let mut out = WorkList::default();
    let mut scratch: Vec<Candidates> = Vec::new();
    let mut state = State {
        projector,
        size: (width, height),
        cell_size: config.cell_size,
        test: &mut test,
        out: &mut out,
        scratch: &mut scratch,
    };
    state.visit((0, 0, width, height), root, 0);
    Ok(out)
}

struct State<'a, F> {
    projector: &'a Projector,
    size: (u32, u32),
    cell_size: u32,
    test: &'a mut F,
    out: &'a mut WorkList,
    /// One candidate list per depth, reused.
    scratch: &'a mut Vec<Candidates>,
}

impl<F> State<'_, F>
where
    F: FnMut(&RayBundle, &Candidates, &mut Candidates),
{
    fn visit(&mut self, cell: (u32, u32, u32, u32), parent: &Candidates, depth: usize) {
        let (x0, y0, x1, y1) = cell;
        self.out.stats.cells_visited += 1;
        let bundle = RayBundle::of_cell(self.projector, self.size, cell);
        if self.scratch.len() <= depth {
            self.scratch.resize_with(depth + 1, Candidates::new);
        }
        let mut mine = std::mem::take(&mut self.scratch[depth]);
        mine.clear();
        (self.test)(&bundle, parent, &mut mine);
        if mine.is_empty() {
            self.out.stats.cells_culled += 1;
        } else {
            let (w, h) = (x1 - x0, y1 - y0);
            let split_x = w > self.cell_size;
            let split_y = h > self.cell_size;
            if !split_x && !split_y {
                self.out.push(cell, &mine);
            } else {
                // Split at a multiple of the cell size so leaf tiles align to a grid.
                let xm = if split_x {
                    x0 + half_aligned(w, self.cell_size)
                } else {
                    x1
                };
                let ym = if split_y {
                    y0 + half_aligned(h, self.cell_size)
                } else {
                    y1
                };
                for (cy0, cy1) in [(y0, ym), (ym, y1)] {
                    for (cx0, cx1) in [(x0, xm), (xm, x1)] {
                        if cx0 < cx1 && cy0 < cy1 {
                            self.visit((cx0, cy0, cx1, cy1), &mine, depth + 1);
                        }
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
        c.begin(0, 0.0, f64::INFINITY);
        c
    }

    #[test]
    fn keeping_everything_tiles_the_image_exactly_once() {
        for (w, h, cell) in [(100, 37, 8), (1, 1, 8), (64, 64, 16), (33, 90, 5)] {
            let list = build(
                &camera(),
                (w, h),
                &QuadtreeConfig { cell_size: cell },
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

    #[test]
    fn culled_cells_produce_no_items_and_bad_configs_are_errors() {
        let list = build(
            &camera(),
            (64, 64),
            &QuadtreeConfig { cell_size: 8 },
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
            &QuadtreeConfig { cell_size: 0 },
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
}
