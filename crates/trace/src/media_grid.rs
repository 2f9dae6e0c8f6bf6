//! The method's "per vertex" evaluation of the media (docs/methods.md §5): their terms computed on a grid
//! of pixels `spacing` apart (the centre rays of pixels `(i·s, j·s)` and of the last row and
//! column, cast to their own nearest hit) and interpolated bilinearly in between — depth-aware:
//! a ray whose four nodes are not all hits (or all misses, for a miss), or whose depth differs by
//! more than [`DEPTH_TOLERANCE`] (relative) from the nodes' interpolated depth (interpolated as
//! `1/depth`, which is linear across the screen on a plane), or by more than
//! [`OPTICAL_TOLERANCE`] of a node's optical depth from that node's depth (the air seen from
//! 66 km: the last kilometre before the ground holds much of the haze), or whose nodes' terms
//! spread by more than [`TERMS_TOLERANCE`] (the fog's top seen edge-on), is evaluated exactly
//! instead, so media do not bleed across silhouettes.

use crate::hit::nearest_pending;
use crate::media::{Media, MediaTerms};
use crate::primitive::TraceContext;
use fray_core::{BudgetError, Interval, MemoryBudget, Ray};
use fray_scene::Scene;
use rayon::prelude::*;

/// The largest relative difference between a ray's depth and its grid nodes' interpolated depth
/// that still interpolates.
pub const DEPTH_TOLERANCE: f64 = 0.02;

/// The largest spread of a cell's four nodes' terms that still interpolates: of their
/// transmittances (absolute) and of their in-scattered radiance (relative to the largest).
pub const TERMS_TOLERANCE: f64 = 0.05;

/// The largest optical depth between a ray's depth and a node's (the media's extinction at the
/// node's end times the depth difference), relative to the node's own optical depth, that still
/// interpolates.
pub const OPTICAL_TOLERANCE: f64 = 0.05;

/// One grid node: its centre ray's depth (`∞`: a miss), the media's terms along it, its optical
/// depth (the largest channel's) and the media's extinction at its end.
#[derive(Clone, Copy, Debug)]
struct Node {
    depth: f64,
    terms: MediaTerms,
    optical_depth: f64,
    end_extinction: f64,
}

/// The media's terms on a grid of pixels, for one frame.
#[derive(Clone, Debug)]
pub struct MediaGrid {
    spacing: u32,
    /// Pixel columns and rows of the nodes (multiples of `spacing`, then the last pixel).
    columns: Vec<u32>,
    rows: Vec<u32>,
    nodes: Vec<Node>,
}

/// The node positions along a side of `n` pixels: `0, s, 2s, …` and `n − 1`.
fn positions(n: u32, spacing: u32) -> Vec<u32> {
    let mut p: Vec<u32> = (0..n).step_by(spacing as usize).collect();
    if p.last() != Some(&(n - 1)) {
        p.push(n - 1);
    }
    p
}

impl MediaGrid {
    /// Casts every node's centre ray (in parallel; the caller's thread pool) and evaluates the
    /// media along it. The nodes are checked against `budget` first.
    pub fn build(
        scene: &Scene,
        media: &Media,
        spacing: u32,
        epsilon: f64,
        budget: &MemoryBudget,
    ) -> Result<Self, BudgetError> {
        let (columns, rows) = (
            positions(scene.width, spacing.max(1)),
            positions(scene.height, spacing.max(1)),
        );
        let count = columns.len() as u64 * rows.len() as u64;
        budget.check_elements(
            format!("the media grid's {count} nodes"),
            count,
            std::mem::size_of::<Node>() as u64,
        )?;
        let footprint = scene.camera.pixel_footprint(scene.width, scene.height);
        let nodes = rows
            .par_iter()
            .map_init(TraceContext::default, |ctx, &py| {
                columns
                    .iter()
                    .map(|&px| {
                        let Some(c) = scene.camera.pixel_ray(px, py, scene.width, scene.height)
                        else {
                            return Node {
                                depth: f64::INFINITY,
                                terms: MediaTerms::CLEAR,
                                optical_depth: 0.0,
                                end_extinction: 0.0,
                            };
                        };
                        let range = Interval::new(c.t_near, f64::INFINITY);
                        let depth = nearest_pending(
                            scene, ctx, &c.ray, range, epsilon, None, footprint, None,
                        )
                        .map_or(f64::INFINITY, |h| h.hit.t);
                        let terms = media.terms(&c.ray, Interval::new(c.t_near, depth));
                        let end_extinction = if depth.is_finite() {
                            media.extinction_at(&c.ray, depth)
                        } else {
                            0.0
                        };
                        Node {
                            depth,
                            terms,
                            optical_depth: -terms.transmittance.min_element().ln(),
                            end_extinction,
                        }
                    })
                    .collect::<Vec<_>>()
            })
            .flatten()
            .collect();
        Ok(Self {
            spacing,
            columns,
            rows,
            nodes,
        })
    }

    /// The grid spacing in pixels.
    pub fn spacing(&self) -> u32 {
        self.spacing
    }

    /// How many nodes the grid has.
    pub fn len(&self) -> usize {
        self.nodes.len()
    }

    /// Whether the grid has no nodes (never, for an image of at least one pixel).
    pub fn is_empty(&self) -> bool {
        self.nodes.is_empty()
    }

    /// The media's terms for the camera ray through image point `(x, y)` (pixel units, centres
    /// at `+0.5`) over `range` (`range.hi`: its depth, `∞` for a miss): interpolated from the
    /// four nodes around it if their depths agree with the ray's, else `None`.
    pub fn interpolate(&self, x: f64, y: f64, range: Interval) -> Option<MediaTerms> {
        let (i, fx) = locate(&self.columns, x - 0.5);
        let (j, fy) = locate(&self.rows, y - 0.5);
        let n = self.columns.len();
        let i1 = (i + 1).min(n - 1);
        let j1 = (j + 1).min(self.rows.len() - 1);
        let corners = [
            (self.nodes[j * n + i], (1.0 - fx) * (1.0 - fy)),
            (self.nodes[j * n + i1], fx * (1.0 - fy)),
            (self.nodes[j1 * n + i], (1.0 - fx) * fy),
            (self.nodes[j1 * n + i1], fx * fy),
        ];
        // Misses interpolate only between misses, hits between hits whose inverse depths
        // (linear across the screen on a plane, jumping at a silhouette) interpolate to the
        // ray's own.
        let depth = range.hi;
        let miss = depth == f64::INFINITY;
        if !corners
            .iter()
            .all(|(node, _)| (node.depth == f64::INFINITY) == miss)
        {
            return None;
        }
        if !miss {
            let inverse: f64 = corners.iter().map(|(node, w)| w / node.depth).sum();
            if (inverse * depth - 1.0).abs() > DEPTH_TOLERANCE {
                return None;
            }
            let optically_close = |node: &Node| {
                (depth - node.depth).abs() * node.end_extinction
                    <= OPTICAL_TOLERANCE * node.optical_depth
            };
            if !corners.iter().all(|(node, _)| optically_close(node)) {
                return None;
            }
        }
        // Only where the terms themselves are smooth: a cell across the fog's top seen edge-on
        // (transmittance from 1 to 0 between two misses) is evaluated exactly.
        let spread = |f: &dyn Fn(&MediaTerms) -> glam::DVec3| {
            let values = corners.map(|(node, _)| f(&node.terms));
            let (lo, hi) = values.iter().fold((values[0], values[0]), |(lo, hi), v| {
                (lo.min(*v), hi.max(*v))
            });
            ((hi - lo).max_element(), hi.max_element())
        };
        let (t_spread, _) = spread(&|t| t.transmittance);
        let (l_spread, l_max) = spread(&|t| t.in_scatter);
        if t_spread > TERMS_TOLERANCE || l_spread > TERMS_TOLERANCE * l_max {
            return None;
        }
        let mut terms = MediaTerms {
            transmittance: glam::DVec3::ZERO,
            in_scatter: glam::DVec3::ZERO,
        };
        for (node, w) in corners {
            terms.transmittance += node.terms.transmittance * w;
            terms.in_scatter += node.terms.in_scatter * w;
        }
        Some(terms)
    }
}

/// The interval of `positions` holding `x` and the fraction of the way across it (clamped to
/// the ends).
fn locate(positions: &[u32], x: f64) -> (usize, f64) {
    let k = positions.partition_point(|&p| f64::from(p) <= x);
    let i = k.saturating_sub(1).min(positions.len().saturating_sub(2));
    let (a, b) = (
        f64::from(positions[i]),
        f64::from(*positions.get(i + 1).unwrap_or(&positions[i])),
    );
    let f = if b > a {
        ((x - a) / (b - a)).clamp(0.0, 1.0)
    } else {
        0.0
    };
    (i, f)
}

/// The media's terms for a camera ray through image point `(x, y)`: from `grid` where it
/// interpolates, else exact; counts which in `ctx`.
#[inline]
pub(crate) fn camera_terms(
    media: &Media,
    grid: Option<&MediaGrid>,
    ctx: &mut TraceContext,
    (x, y): (f64, f64),
    ray: &Ray,
    range: Interval,
) -> MediaTerms {
    if let Some(grid) = grid {
        if let Some(terms) = grid.interpolate(x, y, range) {
            ctx.counts.media_interpolated += 1;
            return terms;
        }
        ctx.counts.media_exact += 1;
    }
    let jitter = media.camera_jitter((x, y));
    media.terms_jittered(ray, range, jitter, &mut ctx.counts.cloud_samples)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn node_positions_cover_the_image_and_locate_inverts_them() {
        assert_eq!(positions(17, 8), [0, 8, 16]);
        assert_eq!(positions(18, 8), [0, 8, 16, 17]);
        assert_eq!(positions(1, 8), [0]);
        let p = positions(18, 8);
        assert_eq!(locate(&p, 0.0), (0, 0.0));
        assert_eq!(locate(&p, 4.0), (0, 0.5));
        assert_eq!(locate(&p, 16.5), (2, 0.5));
        assert_eq!(locate(&p, 17.0), (2, 1.0));
        assert_eq!(locate(&[0], 0.0), (0, 0.0));
    }
}
