//! A mesh's BVH: the topology from a binned SAH build whose work is bounded whatever the
//! triangles (`bvh_build`: BVH2, built from the triangles' boxes rounded to f32, at most
//! [`MAX_DEPTH`](crate::MAX_DEPTH) deep), its boxes refitted in f64 around the f64 triangles
//! (so they bound them exactly, whatever the rounding), traversed here nearest child first with
//! a conservative slab test (Ize 2013: the far distance widened by `1 + 2γ₃`, so rounding never
//! drops a box a ray touches). Nearest hit for camera and secondary rays, any hit for shadow
//! rays.

use crate::TriangleMesh;
use crate::bvh_build::{self, BuildPreset, PrimBox};
use crate::triangle::{RayFrame, intersect};
use fray_core::{Aabb, Interval, Ray};
use glam::DVec3;

/// A node: its f64 box; a leaf's triangles are `order[first..first + count]`, an inner node's
/// children are nodes `first` and `first + 1`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct Node {
    pub(crate) min: DVec3,
    pub(crate) max: DVec3,
    pub(crate) first: u32,
    /// 0 for an inner node.
    pub(crate) count: u32,
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
    /// How long the topology build took.
    build_time: std::time::Duration,
}

/// `1 + 2γ₃` with `γₙ = nε/(1 − nε)` for f64 (Pharr, Jakob and Humphreys, §6.8).
const SLAB_WIDEN: f64 = 1.0 + 2.0 * (3.0 * f64::EPSILON * 0.5) / (1.0 - 3.0 * f64::EPSILON * 0.5);

impl MeshBvh {
    /// Builds the BVH of `mesh` (a binned SAH build, `O(n · MAX_DEPTH)` for any triangles: see
    /// [`MeshBvh::build_bytes`] for its memory). The topology is built from
    /// the corners relative to [`topology_anchor`] (the difference in f64, then rounded to
    /// f32), so a mesh far from the origin gets the tree it would get at the origin rather than
    /// one over f32 corners that have collapsed onto a coarse grid; the boxes are refitted in
    /// f64 around the absolute f64 corners either way.
    ///
    /// # Panics
    /// If the mesh has more than [`MAX_TRIANGLES`](crate::MAX_TRIANGLES) triangles, which only a
    /// mesh whose fields were filled by hand can have: [`TriangleMesh::new`] and the OBJ loader
    /// refuse it.
    pub fn build(mesh: TriangleMesh) -> Self {
        Self::build_with(mesh, BuildPreset::default())
    }

    /// [`MeshBvh::build`] with the build's effort chosen: the same guarantees and the same hits
    /// for every preset, a different tree (build time against traversal speed).
    ///
    /// # Panics
    /// As [`MeshBvh::build`].
    pub fn build_with(mesh: TriangleMesh, preset: BuildPreset) -> Self {
        let anchor = topology_anchor(&mesh);
        let boxes: Vec<PrimBox> = (0..mesh.triangles.len())
            .map(|i| PrimBox::around(i as u32, mesh.corners(i).map(|p| p - anchor)))
            .collect();
        let start = std::time::Instant::now();
        let (mut nodes, order) = bvh_build::build(boxes, preset);
        let build_time = start.elapsed();
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

    /// The bytes a BVH of `triangles` triangles holds beside its mesh, at most: `2n − 1` nodes
    /// and the leaf order (a tree with fuller leaves has fewer nodes: [`MeshBvh::bytes`]).
    pub fn bytes_for(triangles: usize) -> u64 {
        bvh_build::tree_bytes(triangles)
    }

    /// The bytes [`MeshBvh::build`] allocates for a mesh of `triangles` triangles at its peak,
    /// beside the mesh it is given: the triangles' f32 boxes (dropped before the refit) and the
    /// tree at its largest ([`MeshBvh::bytes_for`]) — and that again while the nodes' unused
    /// room is given back.
    pub fn build_bytes(triangles: usize) -> u64 {
        let boxes = (triangles as u64).saturating_mul(std::mem::size_of::<PrimBox>() as u64);
        boxes.saturating_add(Self::bytes_for(triangles).saturating_mul(2))
    }

    /// The bytes this BVH holds beside its mesh (its nodes and leaf order).
    pub fn bytes(&self) -> u64 {
        (self.nodes.len() * std::mem::size_of::<Node>() + self.order.len() * 4) as u64
    }

    /// The mesh.
    pub fn mesh(&self) -> &TriangleMesh {
        &self.mesh
    }

    /// How long the topology build took (the boxes' f32 rounding and the f64 refit not
    /// included).
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
    ///
    /// What it returns is defined without reference to the traversal order, so that any other
    /// traversal (the packet path, [`crate::PacketBvh`]) can return the same bits: among the
    /// triangles of the leaves whose boxes the ray enters within `range` (the conservative slab
    /// of Ize's slab), those that [`intersect`] hits over the whole of `range`, the one of
    /// smallest `t`, and of those the smallest triangle index (two triangles through a shared
    /// edge can meet the ray at the same `t`). Subtrees are skipped only when no triangle in
    /// them can compute a `t` at or below the best so far, judged along the ray's major axis
    /// alone: the computed `t` of a triangle is a convex combination of its corners' major-axis
    /// distances, whereas a grazing ray's computed `t` may fall well before the box's entry on
    /// another axis.
    pub fn nearest_hit(&self, ray: &Ray, range: Interval) -> Option<MeshHit> {
        if self.nodes.is_empty()
            || matches!(
                range.lo.partial_cmp(&range.hi),
                None | Some(std::cmp::Ordering::Greater)
            )
        {
            return None;
        }
        let frame = RayFrame::new(ray);
        let slab = Slab::new(ray, range);
        let mut best: Option<MeshHit> = None;
        let mut best_t = f64::INFINITY;
        let mut stack: Vec<(u32, f64)> = Vec::with_capacity(64);
        if let Some((_, bound)) = slab.test(self.nodes[0].min, self.nodes[0].max) {
            stack.push((0, bound));
        }
        while let Some((index, bound)) = stack.pop() {
            if bound > best_t {
                continue;
            }
            let node = &self.nodes[index as usize];
            if node.count > 0 {
                let (first, count) = (node.first as usize, node.count as usize);
                for &triangle in &self.order[first..first + count] {
                    let Some(hit) = intersect(&frame, self.mesh.corners(triangle as usize), range)
                    else {
                        continue;
                    };
                    if is_better(hit.t, triangle, best_t, best.map(|b| b.triangle)) {
                        best_t = hit.t;
                        best = Some(MeshHit {
                            t: hit.t,
                            triangle,
                            barycentric: hit.barycentric,
                        });
                    }
                }
                continue;
            }
            let (left, right) = (node.first, node.first + 1);
            let l = &self.nodes[left as usize];
            let r = &self.nodes[right as usize];
            let a = slab.test(l.min, l.max);
            let b = slab.test(r.min, r.max);
            match (a, b) {
                (Some((ea, ba)), Some((eb, bb))) => {
                    // The nearer child is popped first.
                    if ea <= eb {
                        stack.extend([(right, bb), (left, ba)]);
                    } else {
                        stack.extend([(left, ba), (right, bb)]);
                    }
                }
                (Some((_, ba)), None) => stack.push((left, ba)),
                (None, Some((_, bb))) => stack.push((right, bb)),
                (None, None) => {}
            }
        }
        best
    }

    /// Whether `ray` hits anything with `t` in `range` (open): the shadow-ray query, which stops
    /// at the first hit it finds. True exactly when the triangles [`MeshBvh::nearest_hit`]
    /// chooses among are not none, whatever the order.
    pub fn any_hit(&self, ray: &Ray, range: Interval) -> bool {
        if self.nodes.is_empty()
            || matches!(
                range.lo.partial_cmp(&range.hi),
                None | Some(std::cmp::Ordering::Greater)
            )
        {
            return false;
        }
        let frame = RayFrame::new(ray);
        let slab = Slab::new(ray, range);
        let mut stack: Vec<u32> = Vec::with_capacity(64);
        if slab.test(self.nodes[0].min, self.nodes[0].max).is_some() {
            stack.push(0);
        }
        while let Some(index) = stack.pop() {
            let node = &self.nodes[index as usize];
            if node.count > 0 {
                let (first, count) = (node.first as usize, node.count as usize);
                if self.order[first..first + count].iter().any(|&triangle| {
                    intersect(&frame, self.mesh.corners(triangle as usize), range).is_some()
                }) {
                    return true;
                }
                continue;
            }
            // The nearer child first: a hit, if any, is found sooner.
            let (left, right) = (node.first, node.first + 1);
            let l = &self.nodes[left as usize];
            let r = &self.nodes[right as usize];
            match (slab.test(l.min, l.max), slab.test(r.min, r.max)) {
                (Some((ea, _)), Some((eb, _))) => {
                    if ea <= eb {
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
        false
    }

    /// The nodes, for the packet path (which copies their topology).
    pub(crate) fn raw_nodes(&self) -> &[Node] {
        &self.nodes
    }

    /// The triangle indices in leaf order.
    pub(crate) fn order(&self) -> &[u32] {
        &self.order
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

/// The point [`MeshBvh::build`] subtracts from the corners before rounding them to f32 for the
/// topology build: the origin when the mesh's box lies within its own size of it — f32 corners
/// then keep all but about one bit of their precision relative to the mesh's size, and meshes
/// near the origin keep exactly the tree they always had —, else the box's centre (a mesh
/// 10⁵ sizes away would otherwise lose 17 bits: its BVH degenerates, too deep for the GPU).
/// The box is over the vertices triangles use; an empty mesh's anchor is the origin.
pub(crate) fn topology_anchor(mesh: &TriangleMesh) -> DVec3 {
    let (mut lo, mut hi) = (DVec3::INFINITY, DVec3::NEG_INFINITY);
    for t in &mesh.triangles {
        for &v in t {
            let p = mesh.positions[v as usize];
            lo = lo.min(p);
            hi = hi.max(p);
        }
    }
    if !(lo.is_finite() && hi.is_finite()) {
        return DVec3::ZERO;
    }
    let centre = (lo + hi) * 0.5;
    let size = (hi - lo).max_element();
    if centre.abs().max_element() <= size {
        DVec3::ZERO
    } else {
        centre
    }
}

/// Whether a hit at `t` on `triangle` beats the best so far (`best_t`, `best`): nearer, or as
/// near with a smaller triangle index — the tie rule both traversals share.
#[inline]
pub(crate) fn is_better(t: f64, triangle: u32, best_t: f64, best: Option<u32>) -> bool {
    t < best_t || (t == best_t && best.is_some_and(|b| triangle < b))
}

/// `1 − 2⁻⁵⁰`: a computed triangle `t` is at least `(1 − 6u)` times its corners' least
/// major-axis distance (u = 2⁻⁵³: three products, two sums and a quotient of non-negative
/// terms), and `fl(x · (1 − 2⁻⁵⁰)) ≤ x (1 − 6u)`.
const BOUND_SHRINK: f64 = 1.0 - 1.0 / (1u64 << 50) as f64;

/// The axis of `d`'s largest component, as [`RayFrame::new`] chooses it (ties to the first).
#[inline]
pub(crate) fn major_axis(d: DVec3) -> usize {
    let a = d.abs();
    if a.x >= a.y && a.x >= a.z {
        0
    } else if a.y >= a.z {
        1
    } else {
        2
    }
}

/// A ray's box test in f64 (Ize's conservative slab over a range), the one both traversals
/// judge reachability by.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Slab {
    pub(crate) origin: DVec3,
    pub(crate) inv: DVec3,
    /// The ray's major axis (the watertight test's `kz`).
    pub(crate) kz: usize,
    pub(crate) lo: f64,
    pub(crate) hi: f64,
}

impl Slab {
    pub(crate) fn new(ray: &Ray, range: Interval) -> Self {
        Self {
            origin: ray.origin,
            inv: ray.dir.recip(),
            kz: major_axis(ray.dir),
            lo: range.lo,
            hi: range.hi,
        }
    }

    /// For a box the ray enters within the range: the entry (to order children by) and a lower
    /// bound on the `t` that [`intersect`] computes for any triangle inside the box (from the
    /// major axis alone; `−∞` when the box reaches behind the origin on that axis).
    #[inline]
    pub(crate) fn test(&self, min: DVec3, max: DVec3) -> Option<(f64, f64)> {
        // Arrays, not `DVec3`'s `Index` (a `match` per access); the same products.
        let t0 = ((min - self.origin) * self.inv).to_array();
        let t1 = ((max - self.origin) * self.inv).to_array();
        let (mut enter, mut leave) = (self.lo, self.hi);
        for a in 0..3 {
            let (x, y) = (t0[a], t1[a]);
            // NaN (0 · ∞: a ray parallel to the slab, in the plane of one of its faces) means
            // the ray is inside that (closed) slab all along: the axis does not constrain.
            // Selects, not branches (`|`, not `||`).
            let constrains = !(x.is_nan() | y.is_nan());
            let (near, far) = if x < y { (x, y) } else { (y, x) };
            enter = if constrains { enter.max(near) } else { enter };
            leave = if constrains {
                leave.min(far * SLAB_WIDEN)
            } else {
                leave
            };
        }
        // The major axis's direction component is not 0: no NaN there.
        let (x, y) = (t0[self.kz], t1[self.kz]);
        let near = if x < y { x } else { y };
        let bound = if near > 0.0 {
            near * BOUND_SHRINK
        } else {
            f64::NEG_INFINITY
        };
        (enter <= leave).then_some((enter, bound))
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
