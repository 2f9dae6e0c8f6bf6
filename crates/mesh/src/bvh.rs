//! A mesh's BVH: the topology from `obvhs`'s SAH builder (BVH2, built from the triangles rounded
//! to f32), its boxes refitted in f64 around the f64 triangles (so they bound them exactly,
//! whatever the rounding), traversed here nearest child first with a conservative slab test
//! (Ize 2013: the far distance widened by `1 + 2γ₃`, so rounding never drops a box a ray
//! touches). Nearest hit for camera and secondary rays, any hit for shadow rays.

use crate::TriangleMesh;
use crate::triangle::{RayFrame, intersect};
use fray_core::{Aabb, Interval, Ray};
use glam::DVec3;

/// A node: its f64 box; a leaf's triangles are `order[first..first + count]`, an inner node's
/// children are nodes `first` and `first + 1`.
#[derive(Clone, Copy, Debug, PartialEq)]
struct Node {
    min: DVec3,
    max: DVec3,
    first: u32,
    /// 0 for an inner node.
    count: u32,
}

/// The nearest hit on a mesh.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct MeshHit {
    pub t: f64,
    pub triangle: u32,
    /// The barycentric weights of the triangle's three corners at the hit.
    pub barycentric: [f64; 3],
}

/// A triangle mesh with its BVH.
#[derive(Clone, Debug)]
pub struct MeshBvh {
    mesh: TriangleMesh,
    nodes: Vec<Node>,
    /// Triangle indices in leaf order.
    order: Vec<u32>,
    /// How long the `obvhs` build took.
    build_time: std::time::Duration,
}

/// `1 + 2γ₃` with `γₙ = nε/(1 − nε)` for f64 (Pharr, Jakob and Humphreys, §6.8).
const SLAB_WIDEN: f64 = 1.0 + 2.0 * (3.0 * f64::EPSILON * 0.5) / (1.0 - 3.0 * f64::EPSILON * 0.5);

impl MeshBvh {
    /// Builds the BVH of `mesh` (obvhs's medium-quality SAH build).
    pub fn build(mesh: TriangleMesh) -> Self {
        let tris: Vec<obvhs::triangle::Triangle> = (0..mesh.triangles.len())
            .map(|i| {
                let [a, b, c] = mesh.corners(i).map(|p| p.as_vec3().into());
                obvhs::triangle::Triangle {
                    v0: a,
                    v1: b,
                    v2: c,
                }
            })
            .collect();
        let mut build_time = std::time::Duration::ZERO;
        let (mut nodes, order) = if tris.is_empty() {
            (Vec::new(), Vec::new())
        } else {
            let bvh = obvhs::bvh2::builder::build_bvh2_from_tris(
                &tris,
                obvhs::BvhBuildParams::medium_build(),
                &mut build_time,
            );
            let nodes = bvh
                .nodes
                .iter()
                .map(|n| Node {
                    min: DVec3::ZERO,
                    max: DVec3::ZERO,
                    first: n.first_index,
                    count: n.prim_count,
                })
                .collect();
            (nodes, bvh.primitive_indices.clone())
        };
        if !nodes.is_empty() {
            refit(&mut nodes, &order, &mesh, 0);
        }
        Self {
            mesh,
            nodes,
            order,
            build_time,
        }
    }

    /// The mesh.
    pub fn mesh(&self) -> &TriangleMesh {
        &self.mesh
    }

    /// How long `obvhs` took to build the topology (the refit not included).
    pub fn build_time(&self) -> std::time::Duration {
        self.build_time
    }

    /// The number of BVH nodes.
    pub fn node_count(&self) -> usize {
        self.nodes.len()
    }

    /// The box around the mesh.
    pub fn bounds(&self) -> Aabb {
        self.nodes
            .first()
            .map_or(Aabb::EMPTY, |n| Aabb::new(n.min, n.max))
    }

    /// The nearest hit of `ray` with `t` in `range` (open at both ends).
    pub fn nearest_hit(&self, ray: &Ray, range: Interval) -> Option<MeshHit> {
        let mut best: Option<MeshHit> = None;
        let mut hi = range.hi;
        self.traverse(ray, range.lo, &mut hi, |frame, triangle, lo, hi| {
            let hit = intersect(
                frame,
                self.mesh.corners(triangle as usize),
                Interval::new(lo, *hi),
            )?;
            *hi = hit.t;
            best = Some(MeshHit {
                t: hit.t,
                triangle,
                barycentric: hit.barycentric,
            });
            Some(false)
        });
        best
    }

    /// Whether `ray` hits anything with `t` in `range` (open): the shadow-ray query, which stops
    /// at the first hit it finds.
    pub fn any_hit(&self, ray: &Ray, range: Interval) -> bool {
        let mut hi = range.hi;
        let mut found = false;
        self.traverse(ray, range.lo, &mut hi, |frame, triangle, lo, hi| {
            intersect(
                frame,
                self.mesh.corners(triangle as usize),
                Interval::new(lo, *hi),
            )?;
            found = true;
            Some(true)
        });
        found
    }

    /// Visits the triangles of the leaves whose boxes `ray` enters within `[lo, hi]`, nearer
    /// child first; `visit` may shrink `hi` and returns `Some(true)` to stop.
    fn traverse(
        &self,
        ray: &Ray,
        lo: f64,
        hi: &mut f64,
        mut visit: impl FnMut(&RayFrame, u32, f64, &mut f64) -> Option<bool>,
    ) {
        if self.nodes.is_empty()
            || matches!(lo.partial_cmp(hi), None | Some(std::cmp::Ordering::Greater))
        {
            return;
        }
        let frame = RayFrame::new(ray);
        let inv = ray.dir.recip();
        let slab = |n: &Node, hi: f64| -> Option<f64> {
            let t0 = (n.min - ray.origin) * inv;
            let t1 = (n.max - ray.origin) * inv;
            // NaN (0 · ∞: a ray in a slab's plane) counts as inside that slab.
            let near = t0.min(t1);
            let far = t0.max(t1);
            let (mut enter, mut leave) = (lo, hi);
            for a in 0..3 {
                if !near[a].is_nan() {
                    enter = enter.max(near[a]);
                }
                if !far[a].is_nan() {
                    leave = leave.min(far[a] * SLAB_WIDEN);
                }
            }
            (enter <= leave).then_some(enter)
        };
        let mut stack: Vec<u32> = Vec::with_capacity(64);
        if slab(&self.nodes[0], *hi).is_none() {
            return;
        }
        stack.push(0);
        while let Some(index) = stack.pop() {
            let node = &self.nodes[index as usize];
            if node.count > 0 {
                let (first, count) = (node.first as usize, node.count as usize);
                for &triangle in &self.order[first..first + count] {
                    if visit(&frame, triangle, lo, hi) == Some(true) {
                        return;
                    }
                }
                continue;
            }
            let (left, right) = (node.first, node.first + 1);
            let a = slab(&self.nodes[left as usize], *hi);
            let b = slab(&self.nodes[right as usize], *hi);
            match (a, b) {
                (Some(ta), Some(tb)) => {
                    // The nearer child is popped first.
                    if ta <= tb {
                        stack.extend([right, left]);
                    } else {
                        stack.extend([left, right]);
                    }
                }
                (Some(_), None) => stack.push(left),
                (None, Some(_)) => stack.push(right),
                (None, None) => {}
            }
        }
    }

    /// The nodes in index order, read-only (for flattening the BVH: `gpu_layout`): node 0 is
    /// the root; an inner node's children are nodes `first` and `first + 1`, a leaf's
    /// triangles `leaf_order()[first..first + count]`.
    pub fn nodes(&self) -> impl ExactSizeIterator<Item = crate::BvhNode> + '_ {
        self.nodes.iter().map(|n| crate::BvhNode {
            min: n.min,
            max: n.max,
            first: n.first,
            count: n.count,
        })
    }

    /// The triangle indices in leaf order (what a leaf's `first..first + count` indexes).
    pub fn leaf_order(&self) -> &[u32] {
        &self.order
    }

    /// The number of edges on the longest root-to-leaf path: 0 for a single leaf (or no
    /// nodes). A traversal that pushes both children of each inner node needs a stack of
    /// `max_depth() + 1` entries.
    pub fn max_depth(&self) -> u32 {
        let mut deepest = 0;
        let mut pending: Vec<(u32, u32)> = Vec::with_capacity(64);
        if !self.nodes.is_empty() {
            pending.push((0, 0));
        }
        while let Some((index, depth)) = pending.pop() {
            deepest = deepest.max(depth);
            let node = &self.nodes[index as usize];
            if node.count == 0 {
                pending.extend([(node.first, depth + 1), (node.first + 1, depth + 1)]);
            }
        }
        deepest
    }
}

/// Sets the f64 boxes of the subtree at `index` from its triangles' corners.
fn refit(nodes: &mut [Node], order: &[u32], mesh: &TriangleMesh, index: usize) -> (DVec3, DVec3) {
    let node = nodes[index];
    let (min, max) = if node.count > 0 {
        let (first, count) = (node.first as usize, node.count as usize);
        order[first..first + count].iter().fold(
            (DVec3::INFINITY, DVec3::NEG_INFINITY),
            |(lo, hi), &t| {
                let [a, b, c] = mesh.corners(t as usize);
                (lo.min(a).min(b).min(c), hi.max(a).max(b).max(c))
            },
        )
    } else {
        let (a0, a1) = refit(nodes, order, mesh, node.first as usize);
        let (b0, b1) = refit(nodes, order, mesh, node.first as usize + 1);
        (a0.min(b0), a1.max(b1))
    };
    nodes[index].min = min;
    nodes[index].max = max;
    (min, max)
}
