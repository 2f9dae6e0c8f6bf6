//! The BVH's topology: a top-down binned SAH build (Wald 2007) over the triangles' boxes, with
//! its work bounded whatever the triangles are — duplicates, slivers, fans, degenerate triangles
//! or centroids all in one point. Each level of the tree costs work linear in the triangles, and
//! the depth is capped at [`MAX_DEPTH`]: a node that could not otherwise reach leaves of at most
//! [`MAX_LEAF`] triangles within the cap, or whose centroids no plane separates, is split at its
//! object median, which halves it. The build is therefore `O(n · MAX_DEPTH)` (`O(n log n)` with a
//! constant that does not grow with the input) and every tree fits the GPU's traversal stack.
//!
//! (obvhs's PLOC builder, used before, merges mutually nearest neighbours in Morton order; on
//! boxes that are equal or nested along that order — copies of one triangle, or a fan of
//! triangles sharing a vertex — only one pair per chain agrees in each pass, so it made `n / 2`
//! passes of `O(n)`: 9 904 passes for a 10⁵-triangle disc fan, 31 s.)

use crate::bvh::Node;
use glam::{DVec3, Vec3};

/// Triangles per leaf at most: what obvhs's medium build allowed, and what the packet
/// traversal's leaves were tuned on.
pub const MAX_LEAF: usize = 8;

/// The deepest a tree may be (edges from the root to a leaf): the GPU traversal's stack holds
/// `MAX_DEPTH + 1` entries ([`crate::gpu_layout::MESH_STACK`]), so every tree this builds can be
/// drawn there. Median splits reach leaves of [`MAX_LEAF`] within 29 levels for any `u32` count
/// of triangles, which leaves the SAH at least 34 levels of its own choosing (the bunny's tree is
/// far shallower).
pub const MAX_DEPTH: u32 = crate::gpu_layout::MESH_STACK - 1;

/// The most bins a preset bins into (the bin arrays' size).
const MAX_BINS: usize = 64;

/// How much work the build spends on the tree's quality: the SAH over more candidate planes, or
/// none at all. Every preset builds a tree with the same guarantees (leaves of at most
/// [`MAX_LEAF`], at most [`MAX_DEPTH`] deep, `O(n · MAX_DEPTH)` work) and every traversal of any
/// of them returns the same hits (the answer is defined by the triangles, not the tree); they
/// differ only in build time and traversal speed (`cargo xtask bench bvh`).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum BuildPreset {
    /// Object-median splits along the centres' longest axis, no SAH: the cheapest build.
    Median,
    /// The SAH over 4 bins per axis (3 candidate planes).
    Fast,
    /// The SAH over 16 bins per axis: the bunny's tree traverses no measurably slower than with
    /// 32, and builds faster. The default.
    #[default]
    Medium,
    /// The SAH over [`MAX_BINS`] (64) bins per axis.
    Slow,
}

impl BuildPreset {
    /// Every preset, cheapest build first.
    pub const ALL: [Self; 4] = [Self::Median, Self::Fast, Self::Medium, Self::Slow];

    /// Bins per axis of the SAH (`None`: median splits only).
    fn bins(self) -> Option<usize> {
        match self {
            Self::Median => None,
            Self::Fast => Some(4),
            Self::Medium => Some(16),
            Self::Slow => Some(MAX_BINS),
        }
    }

    /// The preset's name in lower case (`median`, `fast`, `medium`, `slow`).
    pub fn name(self) -> &'static str {
        match self {
            Self::Median => "median",
            Self::Fast => "fast",
            Self::Medium => "medium",
            Self::Slow => "slow",
        }
    }
}

/// The SAH's cost of visiting a node, in units of one ray–triangle test: a leaf is kept when
/// splitting it would not save this much. 3, as obvhs's medium build collapsed its leaves with,
/// gives the bunny as many nodes as before (34 715; obvhs 34 807), so the packet data and the
/// GPU's arrays keep their size; 1 and 2 made 2.5× and 1.5× the nodes for no traversal speed
/// that the (noisy) machine could show.
const TRAVERSAL_COST: f64 = 3.0;

/// The most triangles [`build`] accepts: node indices are `u32`, and a tree of `n` triangles
/// may have `2n − 1` nodes.
pub const MAX_TRIANGLES: usize = (u32::MAX / 2) as usize;

/// A triangle's box in f32, relative to the build's anchor, and its index: the build reorders
/// these in place (each node's triangles contiguous), so it reads them in order.
#[derive(Clone, Copy, Debug)]
pub(crate) struct PrimBox {
    lo: Vec3,
    hi: Vec3,
    triangle: u32,
}

impl PrimBox {
    /// The box of `triangle` around its three corners (relative to the anchor), each
    /// coordinate rounded to f32 and clamped to the finite f32 range (the SAH needs only an
    /// approximate box: the tree's own boxes are refitted in f64 afterwards).
    pub(crate) fn around(triangle: u32, corners: [DVec3; 3]) -> Self {
        let f = |p: DVec3| {
            let c = p.clamp(
                DVec3::splat(-f32::MAX as f64),
                DVec3::splat(f32::MAX as f64),
            );
            // NaN (only from a hand-made mesh: loaders refuse it) becomes 0, not a NaN box.
            Vec3::new(c.x as f32, c.y as f32, c.z as f32).map(|x| if x.is_nan() { 0.0 } else { x })
        };
        let [a, b, c] = corners.map(f);
        Self {
            lo: a.min(b).min(c),
            hi: a.max(b).max(c),
            triangle,
        }
    }

    /// The centre (halves first: no overflow however far apart the corners).
    #[inline]
    fn centre(&self) -> Vec3 {
        self.lo * 0.5 + self.hi * 0.5
    }
}

/// A box being grown, in f32 (min and max only: no rounding).
#[derive(Clone, Copy, Debug)]
struct Bounds {
    lo: Vec3,
    hi: Vec3,
}

impl Bounds {
    const EMPTY: Self = Self {
        lo: Vec3::INFINITY,
        hi: Vec3::NEG_INFINITY,
    };

    #[inline]
    fn grow(&mut self, lo: Vec3, hi: Vec3) {
        self.lo = self.lo.min(lo);
        self.hi = self.hi.max(hi);
    }

    fn union(self, o: Self) -> Self {
        Self {
            lo: self.lo.min(o.lo),
            hi: self.hi.max(o.hi),
        }
    }

    /// Half the surface area, in f64 (0 for an empty box).
    fn half_area(&self) -> f64 {
        if self.lo.cmpgt(self.hi).any() {
            return 0.0;
        }
        let e = self.hi.as_dvec3() - self.lo.as_dvec3();
        e.x * e.y + e.y * e.z + e.z * e.x
    }
}

/// One bin of one axis: the box of its triangles and how many.
#[derive(Clone, Copy, Debug)]
struct Bin {
    bounds: Bounds,
    count: u32,
}

/// A split of a node's triangles: those whose centre's bin along `axis` is below `bin` go left.
#[derive(Clone, Copy, Debug)]
struct Split {
    axis: usize,
    bin: usize,
    /// `A_L N_L + A_R N_R`.
    cost: f64,
}

/// Levels of median splits from `n` triangles down to leaves of at most [`MAX_LEAF`]:
/// `⌈log₂ ⌈n / MAX_LEAF⌉⌉`.
fn median_levels(n: usize) -> u32 {
    n.div_ceil(MAX_LEAF)
        .max(1)
        .next_power_of_two()
        .trailing_zeros()
}

/// The bytes of a tree of `triangles` triangles at most: the nodes (at most `2n − 1`) and the
/// leaf order.
pub(crate) fn tree_bytes(triangles: usize) -> u64 {
    let n = triangles as u64;
    (2 * n).saturating_sub(1) * std::mem::size_of::<Node>() as u64
        + n * std::mem::size_of::<u32>() as u64
}

/// The topology over `boxes` (one per triangle): the nodes (boxes left zero for the caller's
/// refit; node 0 the root, an inner node's children at `first` and `first + 1`, a leaf's
/// triangles `order[first..first + count]`) and the leaf order. Empty for no triangles.
///
/// # Panics
/// If there are more than [`MAX_TRIANGLES`] boxes (the loaders and [`crate::TriangleMesh`]'s
/// constructors refuse such meshes).
pub(crate) fn build(mut boxes: Vec<PrimBox>, preset: BuildPreset) -> (Vec<Node>, Vec<u32>) {
    let n = boxes.len();
    assert!(
        n <= MAX_TRIANGLES,
        "{n} triangles: a BVH holds at most {MAX_TRIANGLES}"
    );
    if n == 0 {
        return (Vec::new(), Vec::new());
    }
    let mut nodes: Vec<Node> = Vec::with_capacity(2 * n - 1);
    let leaf = |first: usize, count: usize| Node {
        min: DVec3::ZERO,
        max: DVec3::ZERO,
        first: first as u32,
        count: count as u32,
    };
    nodes.push(leaf(0, n));
    let bin_count = preset.bins();
    let mut bins = [[Bin {
        bounds: Bounds::EMPTY,
        count: 0,
    }; MAX_BINS]; 3];
    // (node, first triangle, triangles, depth)
    let mut pending: Vec<(usize, usize, usize, u32)> = vec![(0, 0, n, 0)];
    while let Some((index, start, count, depth)) = pending.pop() {
        if count == 1 || depth >= MAX_DEPTH {
            continue; // A leaf already.
        }
        let range = &mut boxes[start..start + count];
        let (mut bounds, mut centres) = (Bounds::EMPTY, Bounds::EMPTY);
        for b in range.iter() {
            bounds.grow(b.lo, b.hi);
            let c = b.centre();
            centres.grow(c, c);
        }
        // Room for the SAH's own choice: after this split, medians must still reach the leaves
        // within MAX_DEPTH (`depth + median_levels(count) ≤ MAX_DEPTH` holds here).
        let sah_allowed = depth + 1 + median_levels(count) <= MAX_DEPTH;
        let axes = Axes::of(centres, bin_count.unwrap_or(1));
        let split = match bin_count {
            Some(_) if sah_allowed => best_split(range, &axes, &mut bins),
            _ => None,
        };
        let parent_area = bounds.half_area();
        let left_count = match split {
            // Leaf when it costs no more than the split (cost in units of a triangle test).
            Some(s)
                if count <= MAX_LEAF
                    && count as f64 * parent_area <= TRAVERSAL_COST * parent_area + s.cost =>
            {
                continue;
            }
            Some(s) => partition(range, s, &axes),
            None if count <= MAX_LEAF => continue,
            None => median(range, &axes),
        };
        let first = nodes.len();
        nodes.push(leaf(start, left_count));
        nodes.push(leaf(start + left_count, count - left_count));
        nodes[index].first = first as u32;
        nodes[index].count = 0;
        pending.push((first + 1, start + left_count, count - left_count, depth + 1));
        pending.push((first, start, left_count, depth + 1));
    }
    nodes.shrink_to_fit();
    let order = boxes.iter().map(|b| b.triangle).collect();
    (nodes, order)
}

/// A node's centres, binned: `bins` equal bins per axis over their extent.
#[derive(Clone, Copy, Debug)]
struct Axes {
    bins: usize,
    lo: Vec3,
    /// `bins / extent` per axis (from f64: no overflow), 0 for an axis along which every
    /// centre is the same.
    scale: Vec3,
    /// The extent, to choose the median's axis.
    extent: DVec3,
}

impl Axes {
    fn of(centres: Bounds, bins: usize) -> Self {
        let extent = centres.hi.as_dvec3() - centres.lo.as_dvec3();
        let scale = extent.map(|e| if e > 0.0 { bins as f64 / e } else { 0.0 });
        Self {
            bins,
            lo: centres.lo,
            scale: scale.as_vec3(),
            extent,
        }
    }

    /// The bin of `b`'s centre along `axis`.
    #[inline]
    fn bin(&self, b: &PrimBox, axis: usize) -> usize {
        // `as` saturates (an overflow to ∞ lands in the last bin, NaN in the first); the
        // clamp catches the top edge.
        (((b.centre()[axis] - self.lo[axis]) * self.scale[axis]) as usize).min(self.bins - 1)
    }
}

/// The cheapest SAH split of `range` over every axis's bin boundaries (`None` when no boundary
/// has triangles on both sides: every centre in one bin on every axis).
fn best_split(range: &[PrimBox], axes: &Axes, bins: &mut [[Bin; MAX_BINS]; 3]) -> Option<Split> {
    let (scale, count) = (axes.scale, axes.bins);
    for axis_bins in bins.iter_mut() {
        axis_bins[..count].fill(Bin {
            bounds: Bounds::EMPTY,
            count: 0,
        });
    }
    for b in range {
        for axis in 0..3 {
            if scale[axis] > 0.0 {
                let bin = &mut bins[axis][axes.bin(b, axis)];
                bin.bounds.grow(b.lo, b.hi);
                bin.count += 1;
            }
        }
    }
    let mut best: Option<Split> = None;
    for (axis, axis_bins) in bins.iter().enumerate() {
        if scale[axis] == 0.0 {
            continue;
        }
        // Right-to-left: the count and cost of the right side of each boundary.
        let mut right = [(0u64, 0.0f64); MAX_BINS];
        let (mut acc, mut n) = (Bounds::EMPTY, 0u64);
        for k in (1..count).rev() {
            acc = acc.union(axis_bins[k].bounds);
            n += u64::from(axis_bins[k].count);
            right[k] = (n, acc.half_area() * n as f64);
        }
        let (mut acc, mut n) = (Bounds::EMPTY, 0u64);
        for k in 1..count {
            acc = acc.union(axis_bins[k - 1].bounds);
            n += u64::from(axis_bins[k - 1].count);
            let (n_right, right_cost) = right[k];
            let cost = acc.half_area() * n as f64 + right_cost;
            if n > 0 && n_right > 0 && best.is_none_or(|b| cost < b.cost) {
                best = Some(Split { axis, bin: k, cost });
            }
        }
    }
    best
}

/// Puts the triangles of `range` that `split` sends left first; returns how many.
fn partition(range: &mut [PrimBox], split: Split, axes: &Axes) -> usize {
    let left = |b: &PrimBox| axes.bin(b, split.axis) < split.bin;
    let (mut i, mut j) = (0, range.len());
    while i < j {
        if left(&range[i]) {
            i += 1;
        } else {
            j -= 1;
            range.swap(i, j);
        }
    }
    i
}

/// Splits `range` in halves at the median centre along the axis of the centres' largest extent
/// (ties by triangle index, so equal centres are split too); returns the left half's size.
fn median(range: &mut [PrimBox], axes: &Axes) -> usize {
    let e = axes.extent;
    let axis = if e.x >= e.y && e.x >= e.z {
        0
    } else if e.y >= e.z {
        1
    } else {
        2
    };
    let mid = range.len() / 2;
    // Linear in the worst case (Rust's selection falls back to median of medians).
    range.select_nth_unstable_by(mid, |a, b| {
        (a.centre()[axis].total_cmp(&b.centre()[axis])).then(a.triangle.cmp(&b.triangle))
    });
    mid
}
