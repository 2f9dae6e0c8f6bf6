//! Packet traversal of a [`MeshBvh`]: many rays at once (a renderer's tile), the same answers as
//! [`MeshBvh::nearest_hit`] and [`MeshBvh::any_hit`] bit for bit, found faster.
//!
//! Rays go through in packets of [`LANES`] consecutive rays, traversing one BVH2 (the
//! reference's topology) together with a shared stack whose entries carry the mask of lanes
//! still in them. A box is first judged for the whole packet by interval bounds over its lanes
//! (all in, all out), then, if undecided, lane by lane in chunks of 8 (chunks with no lane left
//! skipped). Everything that only *decides what to look at* is f32 and conservative;
//! everything that *answers* is the reference's f64 code:
//!
//! - Boxes are the reference's f64 boxes relative to the mesh's centre, rounded outward to f32.
//!   Each lane's origin is rounded outward too (two copies, one per box side) and its inverse
//!   direction shrunk toward zero for near planes and grown for far planes by more than every
//!   f32 and f64 rounding in between, so a lane enters every box the f64 slab lets it enter.
//!   The cull against the lane's best hit uses the major-axis entry alone, like the reference.
//! - Triangles are pre-tested in f32 by Plücker coordinates relative to the mesh's centre
//!   (`d·n + m·e` per edge, proportional to the watertight test's edge functions), rejected only
//!   when two edges have opposite signs beyond an error bound that covers both f32 rounding and
//!   the f64 watertight test's own; what survives (the real hits and rays within ~1e-7 of an
//!   edge) is decided by [`crate::triangle::intersect`] itself, and a leaf's hit counts only when
//!   the f64 slab reaches that leaf, as in the reference.
//! - A camera's packet (one origin for every lane) subtracts the origin once per box plane, not
//!   once per lane, and pre-tests triangles by `d·(n + o × e)` with the sum made once per packet.
//! - The exact test is [`crate::triangle::intersect`]'s arithmetic, op for op, with what can be
//!   shared made once: lanes whose frames share their axes get their shears in one pass over
//!   the packet, lanes that share one origin get each triangle's corners relative to it once
//!   per triangle, and a lane divides out its barycentric weights only for its final hit.
//! - The f32 lane tests run as `wide::f32x8` vectors (SSE2 pairs on the default target), whose
//!   `minps`/`maxps` are the scalar `min`/`max` lane by lane and whose `move_mask` gathers a
//!   comparison into bits; written as scalar loops, the compiler vectorised them across the
//!   wrong dimension and gathered bits one by one (1.2× faster primary rays as vectors).
//! - Lanes the f32 bounds cannot cover (a direction component that is zero or below ~3e-39, a
//!   range that starts below 0, non-finite values) are answered by the reference itself.

// Lane loops index several arrays by the lane (structure of arrays): that is what vectorises.
#![allow(clippy::needless_range_loop)]

use crate::bvh::{Slab, is_better};
use crate::triangle::{RayFrame, UnresolvedHit, intersect_relative};
use crate::{MeshBvh, MeshHit, TriangleMesh};
use fray_core::{Interval, Ray};
use glam::DVec3;
use std::sync::Arc;
use wide::{CmpEq, CmpGt, CmpLe, CmpLt, f32x8};

/// Rays per packet: consecutive rays of a call are traversed together, so neighbouring pixels
/// (an 8×8 block: 64 consecutive rays of a tile in Morton order) should be consecutive.
pub const LANES: usize = 64;

/// Fewer rays than this go to the reference one by one: setting a packet up costs more than
/// it saves for them (the answers are the same either way).
const MIN_PACKET: usize = 4;

/// A set of lanes, one bit each.
type Mask = u64;

/// Lanes tested together (one AVX register of f32, two SSE ones); chunks with no lane left in a
/// packet's mask are skipped.
const CHUNK: usize = 8;
const CHUNK_MASK: Mask = (1 << CHUNK) - 1;
const NCHUNK: usize = LANES / CHUNK;
const LANES_MASK: Mask = if LANES == Mask::BITS as usize {
    Mask::MAX
} else {
    (1 << LANES) - 1
};
/// One chunk's values of one quantity.
type V = [f32; CHUNK];

/// The f32 unit roundoff.
const U32: f64 = f32::EPSILON as f64 * 0.5;
/// An absolute slack above the spacing of subnormal f32s.
const TINY: f64 = 1e-42;
/// The f64 unit roundoff.
const U64: f64 = f64::EPSILON * 0.5;
/// How much a lane's inverse direction is shrunk (near planes) or grown (far planes): more than
/// the f32 subtraction, product and rounding of the inverse (3 · 2⁻²⁴) plus the f64 slab's own
/// rounding and its widening (`1 + 2γ₃`).
const KAPPA: f64 = 1.0 / (1u64 << 20) as f64;

/// An f32 node: the f64 box rounded outward, relative to the mesh's centre.
#[derive(Clone, Copy, Debug)]
struct FNode {
    min: [f32; 3],
    max: [f32; 3],
    first: u32,
    count: u32,
}

/// A triangle's f32 Plücker data for the pre-test, edges in the watertight test's order
/// (`u`: b→c, `v`: c→a, `w`: a→b): `n = Q × P`, `e = Q − P` relative to the mesh's centre, and
/// their 1-norms for the error bound.
#[derive(Clone, Copy, Debug)]
struct FTri {
    n: [[f32; 3]; 3],
    e: [[f32; 3]; 3],
    n1: [f32; 3],
    e1: [f32; 3],
}

/// A [`MeshBvh`] with f32 copies of its boxes and triangle data for packet traversal; answers
/// exactly what the reference answers (see the module's notes).
#[derive(Clone, Debug)]
pub struct PacketBvh {
    reference: Arc<MeshBvh>,
    centre: DVec3,
    /// The largest `|v − centre|∞` over the vertices (rounded up).
    radius: f64,
    nodes: Vec<FNode>,
    /// The reference's f64 boxes, by node: a hit counts only in a leaf the f64 slab reaches.
    boxes: Vec<[DVec3; 2]>,
    /// By position in leaf order.
    tris: Vec<FTri>,
    corners: Vec<[DVec3; 3]>,
    order: Vec<u32>,
}

/// One chunk as a vector (`wide`: SSE2 pairs by default, one AVX register where the target has
/// it). Its `fast_max(a, b)` and `fast_min(a, b)` are `maxps` and `minps`: exactly [`max`]
/// and [`min`] below, lane by lane; `move_mask` gathers a comparison's lanes as bits in one
/// instruction per 4 lanes (the scalar gathering took a tenth of the traversal).
#[inline(always)]
fn lanes(v: &V) -> f32x8 {
    f32x8::from(*v)
}

/// A lane array as one flat array of [`LANES`].
#[inline(always)]
fn flat(v: &mut [V; NCHUNK]) -> &mut [f32; LANES] {
    v.as_flattened_mut()
        .try_into()
        .expect("NCHUNK · CHUNK = LANES")
}

#[inline(always)]
fn splat(x: f32) -> f32x8 {
    f32x8::splat(x)
}

/// The lanes where `m` (a comparison's result) is set, as bits.
#[inline(always)]
fn mask_bits(m: f32x8) -> Mask {
    Mask::from(m.move_mask() as u32 & CHUNK_MASK as u32)
}

/// The larger of two numbers that are never NaN here (one compare and select: `maxps`).
#[inline(always)]
fn max(a: f32, b: f32) -> f32 {
    if a > b { a } else { b }
}

/// The smaller of two numbers that are never NaN here.
#[inline(always)]
fn min(a: f32, b: f32) -> f32 {
    if a < b { a } else { b }
}

/// The bits of `b` (lane `j` → bit `j`): the bools as bytes, gathered by one multiplication
/// (each byte's low bit lands in the top byte), which compiles to a compare, packs and a
/// multiply instead of a shift and an or per lane.
#[inline(always)]
fn bitmask(b: [bool; CHUNK]) -> Mask {
    let mut bytes = [0u8; 8];
    for j in 0..CHUNK {
        bytes[j] = u8::from(b[j]);
    }
    ((u64::from_le_bytes(bytes).wrapping_mul(0x0102_0408_1020_4080)) >> 56) as Mask
}

/// 0 for a finite `x`, NaN for an infinite or NaN one (branch-free, so lane loops vectorise).
#[inline(always)]
fn zero_if_finite(x: f32) -> f32 {
    x * 0.0
}

/// The least and largest of a lane array (lane-innermost: it vectorises).
#[inline(always)]
fn range(v: &[V; NCHUNK]) -> [f32; 2] {
    let (mut a, mut b) = (v[0], v[0]);
    for c in 1..NCHUNK {
        for j in 0..CHUNK {
            a[j] = min(a[j], v[c][j]);
            b[j] = max(b[j], v[c][j]);
        }
    }
    let (mut lo, mut hi) = (a[0], b[0]);
    for j in 1..CHUNK {
        lo = min(lo, a[j]);
        hi = max(hi, b[j]);
    }
    [lo, hi]
}

/// The largest magnitude in a lane array of f64.
#[inline(always)]
fn largest(v: &[f64; LANES]) -> f64 {
    let mut a = [0.0f64; CHUNK];
    for c in 0..NCHUNK {
        for j in 0..CHUNK {
            let x = v[c * CHUNK + j].abs();
            a[j] = if x > a[j] { x } else { a[j] };
        }
    }
    a.into_iter().fold(0.0, |m, x| if x > m { x } else { m })
}

/// `x` rounded to an f32 no greater than it.
fn down(x: f64) -> f32 {
    let f = x as f32;
    if f64::from(f) > x { f.next_down() } else { f }
}

/// `x` rounded to an f32 no less than it.
fn up(x: f64) -> f32 {
    let f = x as f32;
    if f64::from(f) < x { f.next_up() } else { f }
}

fn f32s(v: DVec3) -> [f32; 3] {
    [v.x as f32, v.y as f32, v.z as f32]
}

/// The 1-norm of `v`, rounded up to f32 with room for the f64 sums' rounding.
fn norm1_up(v: DVec3) -> f32 {
    up((v.x.abs() + v.y.abs() + v.z.abs()) * (1.0 + 8.0 * U64))
}

impl PacketBvh {
    /// The packet data of `bvh`, which it keeps as its reference.
    pub fn new(bvh: MeshBvh) -> Self {
        Self::shared(Arc::new(bvh))
    }

    /// The packet data of a shared `bvh` (the one a scene's [`crate::Instance`]s hold), which it
    /// keeps as its reference: the mesh and its f64 BVH are not copied.
    pub fn shared(bvh: Arc<MeshBvh>) -> Self {
        let centre = if bvh.node_count() == 0 {
            DVec3::ZERO
        } else {
            bvh.bounds().center()
        };
        let mesh: &TriangleMesh = bvh.mesh();
        let radius = mesh
            .positions
            .iter()
            .map(|p| (*p - centre).abs().max_element())
            .fold(0.0, f64::max)
            * (1.0 + 4.0 * U64);
        // The f64 difference `p − centre` is within one rounding of the exact one: widen it by
        // that before rounding outward.
        let lower = |x: f64| down(x - x.abs() * (2.0 * U64));
        let upper = |x: f64| up(x + x.abs() * (2.0 * U64));
        let nodes = bvh
            .raw_nodes()
            .iter()
            .map(|n| {
                let (lo, hi) = (n.min - centre, n.max - centre);
                FNode {
                    min: [lower(lo.x), lower(lo.y), lower(lo.z)],
                    max: [upper(hi.x), upper(hi.y), upper(hi.z)],
                    first: n.first,
                    count: n.count,
                }
            })
            .collect();
        let boxes = bvh.raw_nodes().iter().map(|n| [n.min, n.max]).collect();
        let order = bvh.order().to_vec();
        let corners: Vec<[DVec3; 3]> = order.iter().map(|&t| mesh.corners(t as usize)).collect();
        let tris = corners
            .iter()
            .map(|c| {
                let [a, b, c] = c.map(|p| p - centre);
                let edges = [(c, b), (a, c), (b, a)];
                let n = edges.map(|(q, p)| q.cross(p));
                let e = edges.map(|(q, p)| q - p);
                FTri {
                    n: n.map(f32s),
                    e: e.map(f32s),
                    n1: n.map(norm1_up),
                    e1: e.map(norm1_up),
                }
            })
            .collect();
        Self {
            reference: bvh,
            centre,
            radius,
            nodes,
            boxes,
            tris,
            corners,
            order,
        }
    }

    /// The reference this answers like.
    pub fn reference(&self) -> &MeshBvh {
        &self.reference
    }

    /// The reference, shared.
    pub fn shared_reference(&self) -> &Arc<MeshBvh> {
        &self.reference
    }

    /// The bytes [`PacketBvh::shared`] allocates for `bvh` beside it (its f32 nodes, f64
    /// boxes, f32 triangle data, f64 corners and leaf order), for a memory-budget check before
    /// building.
    pub fn bytes_for(bvh: &MeshBvh) -> u64 {
        let nodes = bvh.node_count() as u64;
        let triangles = bvh.leaf_order().len() as u64;
        let per_node = std::mem::size_of::<FNode>() + std::mem::size_of::<[DVec3; 2]>();
        let per_triangle = std::mem::size_of::<FTri>()
            + std::mem::size_of::<[DVec3; 3]>()
            + std::mem::size_of::<u32>();
        nodes.saturating_mul(per_node as u64) + triangles.saturating_mul(per_triangle as u64)
    }

    /// `hits[i]` = [`MeshBvh::nearest_hit`]`(rays[i], ranges[i])`, bit for bit, for any rays;
    /// fastest when consecutive rays are coherent (see [`LANES`]).
    ///
    /// # Panics
    /// If the three slices differ in length.
    pub fn nearest_hits(&self, rays: &[Ray], ranges: &[Interval], hits: &mut [Option<MeshHit>]) {
        assert!(
            rays.len() == ranges.len() && rays.len() == hits.len(),
            "nearest_hits: {} rays, {} ranges, {} hits",
            rays.len(),
            ranges.len(),
            hits.len()
        );
        if rays.len() < MIN_PACKET {
            for ((ray, range), hit) in rays.iter().zip(ranges).zip(hits) {
                *hit = self.reference.nearest_hit(ray, *range);
            }
            return;
        }
        let mut stack = Vec::with_capacity(64);
        let mut packet = Packet::empty();
        for ((rays, ranges), hits) in rays
            .chunks(LANES)
            .zip(ranges.chunks(LANES))
            .zip(hits.chunks_mut(LANES))
        {
            self.nearest_packet(rays, ranges, hits, &mut stack, &mut packet);
        }
    }

    /// `occluded[i]` = [`MeshBvh::any_hit`]`(rays[i], ranges[i])` for any rays (shadow rays).
    ///
    /// # Panics
    /// If the three slices differ in length.
    pub fn any_hits(&self, rays: &[Ray], ranges: &[Interval], occluded: &mut [bool]) {
        assert!(
            rays.len() == ranges.len() && rays.len() == occluded.len(),
            "any_hits: {} rays, {} ranges, {} results",
            rays.len(),
            ranges.len(),
            occluded.len()
        );
        if rays.len() < MIN_PACKET {
            for ((ray, range), o) in rays.iter().zip(ranges).zip(occluded) {
                *o = self.reference.any_hit(ray, *range);
            }
            return;
        }
        let mut stack = Vec::with_capacity(64);
        let mut packet = Packet::empty();
        for ((rays, ranges), out) in rays
            .chunks(LANES)
            .zip(ranges.chunks(LANES))
            .zip(occluded.chunks_mut(LANES))
        {
            self.any_packet(rays, ranges, out, &mut stack, &mut packet);
        }
    }

    fn nearest_packet(
        &self,
        rays: &[Ray],
        ranges: &[Interval],
        hits: &mut [Option<MeshHit>],
        stack: &mut Vec<(u32, Mask)>,
        p: &mut Packet,
    ) {
        if rays.len() < MIN_PACKET {
            for ((ray, range), hit) in rays.iter().zip(ranges).zip(hits) {
                *hit = self.reference.nearest_hit(ray, *range);
            }
            return;
        }
        p.load(self, rays, ranges);
        for (l, hit) in hits.iter_mut().enumerate() {
            *hit = None;
            if p.valid & (1 << l) == 0 {
                *hit = self.reference.nearest_hit(&rays[l], ranges[l]);
            }
        }
        if p.valid == 0 {
            return;
        }
        let mut best_tri = [u32::MAX; LANES];
        let mut best_t = [f64::INFINITY; LANES];
        let mut best_hit: [Option<UnresolvedHit>; LANES] = [None; LANES];
        stack.clear();
        stack.push((0, p.valid));
        while let Some((index, mask)) = stack.pop() {
            let node = &self.nodes[index as usize];
            let mask = p.enters(node, mask, true);
            if mask == 0 {
                continue;
            }
            if node.count == 0 {
                self.push_children(p, node, mask, stack);
                continue;
            }
            let (first, count) = (node.first as usize, node.count as usize);
            for pos in first..first + count {
                let mut candidates = p.may_hit(&self.tris[pos], mask);
                if candidates == 0 {
                    continue;
                }
                let corners = self.corners[pos];
                let relative = p.relative(corners);
                while candidates != 0 {
                    let l = candidates.trailing_zeros() as usize;
                    candidates &= candidates - 1;
                    // A camera's packet: one origin, one frame's axes (inlined: the common case).
                    let h = match (p.axes, relative) {
                        (Some(axes), Some(relative)) => {
                            let shear = [p.shear[0][l], p.shear[1][l], p.shear[2][l]];
                            intersect_relative(axes, shear, relative, ranges[l])
                        }
                        _ => p.hit(l, &rays[l], corners, relative, ranges[l]),
                    };
                    let Some(h) = h else {
                        continue;
                    };
                    let triangle = self.order[pos];
                    let best = (best_tri[l] != u32::MAX).then_some(best_tri[l]);
                    if is_better(h.t, triangle, best_t[l], best)
                        && p.reaches(l, &rays[l], ranges[l], &self.boxes, index)
                    {
                        best_t[l] = h.t;
                        best_tri[l] = triangle;
                        best_hit[l] = Some(h);
                        p.set_best(l, h.t);
                    }
                }
            }
        }
        for (l, hit) in hits.iter_mut().enumerate() {
            if p.valid & (1 << l) != 0
                && let Some(h) = best_hit[l]
            {
                *hit = Some(MeshHit {
                    t: best_t[l],
                    triangle: best_tri[l],
                    barycentric: h.resolve().barycentric,
                });
            }
        }
    }

    fn any_packet(
        &self,
        rays: &[Ray],
        ranges: &[Interval],
        out: &mut [bool],
        stack: &mut Vec<(u32, Mask)>,
        p: &mut Packet,
    ) {
        if rays.len() < MIN_PACKET {
            for ((ray, range), o) in rays.iter().zip(ranges).zip(out) {
                *o = self.reference.any_hit(ray, *range);
            }
            return;
        }
        p.load(self, rays, ranges);
        for (l, o) in out.iter_mut().enumerate() {
            *o = p.valid & (1 << l) == 0 && self.reference.any_hit(&rays[l], ranges[l]);
        }
        let mut active = p.valid;
        stack.clear();
        if active != 0 {
            stack.push((0, active));
        }
        while let Some((index, mask)) = stack.pop() {
            let node = &self.nodes[index as usize];
            let mask = mask & active;
            if mask == 0 {
                continue;
            }
            let mut mask = p.enters(node, mask, false);
            if mask == 0 {
                continue;
            }
            if node.count == 0 {
                self.push_children(p, node, mask, stack);
                continue;
            }
            let (first, count) = (node.first as usize, node.count as usize);
            for pos in first..first + count {
                let mut candidates = p.may_hit(&self.tris[pos], mask);
                let corners = self.corners[pos];
                let relative = if candidates == 0 {
                    None
                } else {
                    p.relative(corners)
                };
                while candidates != 0 {
                    let l = candidates.trailing_zeros() as usize;
                    candidates &= candidates - 1;
                    if p.hit(l, &rays[l], corners, relative, ranges[l]).is_some()
                        && p.reaches(l, &rays[l], ranges[l], &self.boxes, index)
                    {
                        out[l] = true;
                        mask &= !(1 << l);
                        active &= !(1 << l);
                    }
                }
                if mask == 0 {
                    break;
                }
            }
            if active == 0 {
                return;
            }
        }
    }

    /// Pushes an inner node's children, the one nearer along the packet's mean direction last
    /// (popped first).
    #[inline]
    fn push_children(&self, p: &Packet, node: &FNode, mask: Mask, stack: &mut Vec<(u32, Mask)>) {
        let (a, b) = (node.first, node.first + 1);
        let (na, nb) = (&self.nodes[a as usize], &self.nodes[b as usize]);
        let mut s = 0.0;
        for k in 0..3 {
            s += (na.min[k] + na.max[k] - nb.min[k] - nb.max[k]) * p.mean_dir[k];
        }
        if s <= 0.0 {
            stack.extend([(b, mask), (a, mask)]);
        } else {
            stack.extend([(a, mask), (b, mask)]);
        }
    }
}

/// Whether the valid lanes' directions share a sign on an axis.
#[derive(Clone, Copy, Debug, PartialEq)]
enum Sign {
    Positive,
    Negative,
    Mixed,
}

/// One packet's lanes in structure-of-arrays form for the f32 tests, with each lane's f64
/// frame and slab for the exact ones.
struct Packet {
    /// Lanes the f32 tests cover (the others are answered by the reference).
    valid: Mask,
    /// Origins relative to the centre, rounded up (used with box minima) and down (maxima).
    oa: [[V; NCHUNK]; 3],
    ob: [[V; NCHUNK]; 3],
    /// Inverse directions scaled for the minimum and the maximum planes (see [`KAPPA`]).
    imin: [[V; NCHUNK]; 3],
    imax: [[V; NCHUNK]; 3],
    lo: [V; NCHUNK],
    hi: [V; NCHUNK],
    /// The best hit so far, rounded up, on the lane's major axis; `+∞` on the others and
    /// before a hit.
    bound: [[V; NCHUNK]; 3],
    /// Directions and moments `d × o` (relative to the centre) for the triangle pre-test.
    d: [[V; NCHUNK]; 3],
    m: [[V; NCHUNK]; 3],
    /// The pre-test's error bound is `alpha·|n|₁ + beta·|e|₁ + gamma` per edge.
    alpha: f32,
    beta: f32,
    gamma: f32,
    mean_dir: [f32; 3],
    /// Per axis, whether every valid lane's direction is positive, negative, or neither.
    sign: [Sign; 3],
    /// The valid lanes' major axis when they share one.
    major: Option<usize>,
    /// Whether the valid lanes share one origin (a camera's packet): then `oa` and `ob` are
    /// the same in every lane and the box test subtracts once per plane, not once per lane.
    shared: bool,
    /// The shared `oa` and `ob` per axis.
    shared_o: [[f32; 2]; 3],
    /// The shared origin relative to the centre (rounded to nearest), and the pre-test's
    /// `|e|₁` coefficient that goes with it.
    shared_origin: [f32; 3],
    shared_beta: f32,
    /// Each lane's f64 frame, made when first needed (most lanes need it once at most: a
    /// candidate) where the lanes' frames do not share their axes.
    frames: [Option<RayFrame>; LANES],
    /// Each lane's f64 inverse direction, per axis (its slab's: `Slab::new` computes the same
    /// quotients).
    inv: [[f64; LANES]; 3],
    /// Where every valid lane has the same frame axes `[kx, ky, kz]` (one major axis, one sign
    /// on it): the axes, and `shear` holds each lane's frame shear, made for all lanes at once.
    axes: Option<[usize; 3]>,
    shear: [[f64; LANES]; 3],
    /// Every valid lane's origin, where they share it bit for bit (a camera's packet).
    origin: Option<DVec3>,
    /// Valid lanes with no hit yet: while there are some, the largest best-hit bound is `+∞`.
    unhit: Mask,
    /// Each lane's major axis.
    kz: [u8; LANES],
    /// Interval bounds over the lanes, to decide a box for all of them at once.
    whole: Whole,
}

/// The packet's lanes as intervals (Wald, Boulos and Shirley 2007's interval test): each
/// lane's f32 values lie inside, and rounding is monotone, so a box the intervals' entry and
/// exit bounds put outside (inside) every lane's f32 test is outside (inside) each of them.
#[derive(Clone, Copy, Debug)]
struct Whole {
    /// Whether the bounds apply: every axis's directions share a sign and some lane is valid.
    usable: bool,
    /// Per axis, the lanes' range of `oa`, `ob`, `imin` and `imax` (lowest, highest).
    oa: [[f32; 2]; 3],
    ob: [[f32; 2]; 3],
    imin: [[f32; 2]; 3],
    imax: [[f32; 2]; 3],
    lo: [f32; 2],
    hi: [f32; 2],
    /// The shared major axis (for the nearest hit's cull), when there is one.
    major: Option<usize>,
    /// Whether the lanes share one origin (`oa` and `ob` are then points).
    shared: bool,
    bound_min: f32,
    bound_max: f32,
}

/// The range of `(x − o) · i` over `x − o ∈ [x − o_hi, x − o_lo]` and `i ∈ i`, as f32 computes
/// it lane by lane (the extremes of a product over a box are at its corners).
#[inline(always)]
fn product_range(x: f32, o: [f32; 2], i: [f32; 2]) -> [f32; 2] {
    let (a, b) = (x - o[1], x - o[0]);
    let p = [a * i[0], a * i[1], b * i[0], b * i[1]];
    [
        min(min(p[0], p[1]), min(p[2], p[3])),
        max(max(p[0], p[1]), max(p[2], p[3])),
    ]
}

/// The range of `a · i` over `i ∈ i` (one origin: `a` is the same in every lane).
#[inline(always)]
fn scaled_range(a: f32, i: [f32; 2]) -> [f32; 2] {
    let (p, q) = (a * i[0], a * i[1]);
    [min(p, q), max(p, q)]
}

impl Whole {
    /// Every lane in, every lane out, or undecided.
    #[inline(always)]
    fn decide(&self, node: &FNode, nearest: bool) -> Option<bool> {
        if !self.usable {
            return None;
        }
        // Entry and exit bounds: `[lowest, highest]` over the lanes.
        let (mut enter, mut leave) = (self.lo, self.hi);
        let mut major = [f32::NEG_INFINITY, f32::INFINITY];
        for k in 0..3 {
            let (t0, t1) = if self.shared {
                (
                    scaled_range(node.min[k] - self.oa[k][0], self.imin[k]),
                    scaled_range(node.max[k] - self.ob[k][0], self.imax[k]),
                )
            } else {
                (
                    product_range(node.min[k], self.oa[k], self.imin[k]),
                    product_range(node.max[k], self.ob[k], self.imax[k]),
                )
            };
            // `usable` means one sign per axis: a positive direction enters at the minimum.
            let (near, far) = if self.imin[k][0] > 0.0 {
                (t0, t1)
            } else {
                (t1, t0)
            };
            enter = [max(enter[0], near[0]), max(enter[1], near[1])];
            leave = [min(leave[0], far[0]), min(leave[1], far[1])];
            if self.major == Some(k) {
                major = near;
            }
        }
        let tiny = f32::MIN_POSITIVE;
        if enter[0] > leave[1] + tiny || (nearest && major[0] > self.bound_max) {
            return Some(false);
        }
        let major_in = !nearest || (self.major.is_some() && major[1] <= self.bound_min);
        (enter[1] <= leave[0] + tiny && major_in).then_some(true)
    }
}

impl Packet {
    /// A packet with no valid lane, to [`Packet::load`] into (it is large: one per call, not
    /// one per packet).
    fn empty() -> Self {
        Packet {
            valid: 0,
            oa: [[[0.0; CHUNK]; NCHUNK]; 3],
            ob: [[[0.0; CHUNK]; NCHUNK]; 3],
            imin: [[[0.0; CHUNK]; NCHUNK]; 3],
            imax: [[[0.0; CHUNK]; NCHUNK]; 3],
            // A lane that is not valid never enters a box.
            lo: [[f32::INFINITY; CHUNK]; NCHUNK],
            hi: [[f32::NEG_INFINITY; CHUNK]; NCHUNK],
            bound: [[[f32::INFINITY; CHUNK]; NCHUNK]; 3],
            d: [[[0.0; CHUNK]; NCHUNK]; 3],
            m: [[[0.0; CHUNK]; NCHUNK]; 3],
            alpha: 0.0,
            beta: 0.0,
            gamma: 0.0,
            mean_dir: [0.0; 3],
            sign: [Sign::Mixed; 3],
            major: None,
            shared: false,
            shared_o: [[0.0; 2]; 3],
            shared_origin: [0.0; 3],
            shared_beta: 0.0,
            frames: [None; LANES],
            inv: [[0.0; LANES]; 3],
            axes: None,
            origin: None,
            shear: [[0.0; LANES]; 3],
            unhit: 0,
            kz: [0; LANES],
            whole: Whole {
                usable: false,
                oa: [[0.0; 2]; 3],
                ob: [[0.0; 2]; 3],
                imin: [[0.0; 2]; 3],
                imax: [[0.0; 2]; 3],
                lo: [0.0; 2],
                hi: [0.0; 2],
                major: None,
                shared: false,
                bound_min: f32::INFINITY,
                bound_max: f32::INFINITY,
            },
        }
    }

    /// Sets the lanes to `rays` over `ranges` (at most [`LANES`]): a scalar pass that checks
    /// and stages each ray in f64, then passes over all lanes at once (they vectorise), then
    /// the bounds over the valid lanes.
    fn load(&mut self, bvh: &PacketBvh, rays: &[Ray], ranges: &[Interval]) {
        let p = self;
        let empty = [f32::INFINITY, f32::NEG_INFINITY];
        p.valid = 0;
        p.major = None;
        p.shared = false;
        p.whole = Whole {
            usable: false,
            oa: [empty; 3],
            ob: [empty; 3],
            imin: [empty; 3],
            imax: [empty; 3],
            lo: empty,
            hi: empty,
            major: None,
            shared: false,
            bound_min: f32::INFINITY,
            bound_max: f32::INFINITY,
        };
        p.lo = [[f32::INFINITY; CHUNK]; NCHUNK];
        p.hi = [[f32::NEG_INFINITY; CHUNK]; NCHUNK];
        p.bound = [[[f32::INFINITY; CHUNK]; NCHUNK]; 3];
        if bvh.nodes.is_empty() {
            return;
        }
        // Staging in f64: origins relative to the centre, directions, ranges, copied as they
        // are; lanes past the rays get values that fail the checks below.
        let n = rays.len().min(LANES);
        let mut o = [[0.0f64; LANES]; 3];
        let mut d = [[1.0f64; LANES]; 3];
        let mut lo = [f64::NAN; LANES];
        let mut hi = [0.0f64; LANES];
        p.axes = None;
        p.origin = None;
        for l in 0..LANES {
            p.frames[l] = None;
        }
        for l in 0..n {
            let (ray, range) = (&rays[l], &ranges[l]);
            let rel = (ray.origin - bvh.centre).to_array();
            let dir = ray.dir.to_array();
            for k in 0..3 {
                o[k][l] = rel[k];
                d[k][l] = dir[k];
            }
            (lo[l], hi[l]) = (range.lo, range.hi);
        }
        // Which lanes the bounds cover: finite origins and directions, a range from a finite
        // `lo ≥ 0` (negative starts would need the bounds' other sign cases) to `hi ≥ lo`;
        // NaN anywhere fails. And each lane's major axis, as `RayFrame::new` picks it.
        let mut staged: Mask = 0;
        let mut kz = [0u8; LANES];
        for l in 0..LANES {
            let mut z = 0.0f64;
            for k in 0..3 {
                z += o[k][l] * 0.0 + d[k][l] * 0.0;
            }
            let covered = lo[l] >= 0.0 && lo[l] <= hi[l] && lo[l] * 0.0 == 0.0 && z == 0.0;
            staged |= Mask::from(covered) << l;
            let (x, y, w) = (d[0][l].abs(), d[1][l].abs(), d[2][l].abs());
            kz[l] = if x >= y && x >= w {
                0
            } else if y >= w {
                1
            } else {
                2
            };
        }
        p.kz = kz;
        let mut majors = [false; 3];
        // Whether every staged lane has the first one's origin (bit for bit).
        let mut shared = staged != 0;
        if shared {
            let first = staged.trailing_zeros() as usize;
            for k in 0..3 {
                let o0 = o[k][first].to_bits();
                let mut differ = 0u64;
                for l in 0..LANES {
                    let on = (staged >> l) & 1;
                    differ |= (o[k][l].to_bits() ^ o0) * on;
                }
                shared &= differ == 0;
            }
            for l in (0..LANES).filter(|l| (staged >> l) & 1 != 0) {
                majors[usize::from(kz[l])] = true;
            }
        }
        // Per axis over all lanes: outward origins, inverse directions shrunk and grown (see
        // `KAPPA`), the f32 directions; `bad` turns NaN where an f32 value is not finite.
        // Flat loops over the lanes (the loop vectoriser's form; nested chunk loops went to
        // the SLP vectoriser, which shuffled).
        let mut bad = [[0.0f32; CHUNK]; NCHUNK];
        for k in 0..3 {
            let bad = flat(&mut bad);
            let (oa, ob) = (flat(&mut p.oa[k]), flat(&mut p.ob[k]));
            let (imin, imax) = (flat(&mut p.imin[k]), flat(&mut p.imax[k]));
            let (d32, inverse) = (flat(&mut p.d[k]), &mut p.inv[k]);
            for l in 0..LANES {
                // `o − centre` is within one f64 rounding of the exact difference; one f32
                // rounding to nearest is within 2⁻²⁴ of what it rounds (and `TINY` covers
                // subnormal spacing).
                let ok = o[k][l];
                let slack = ok.abs() * (2.0 * U64 + 2.0 * U32) + TINY;
                oa[l] = (ok + slack) as f32;
                ob[l] = (ok - slack) as f32;
                let inv = 1.0 / d[k][l];
                inverse[l] = inv;
                let shrunk = (inv * (1.0 - KAPPA - 2.0 * U32)) as f32;
                let grown = (inv * (1.0 + KAPPA + 2.0 * U32)) as f32;
                // A positive component meets the minimum plane first, a negative one the
                // maximum.
                let positive = inv > 0.0;
                imin[l] = if positive { shrunk } else { grown };
                imax[l] = if positive { grown } else { shrunk };
                // An infinite inverse (a zero component) rounds to an infinite `grown`.
                bad[l] += zero_if_finite(oa[l]) + zero_if_finite(ob[l]) + zero_if_finite(grown);
                d32[l] = d[k][l] as f32;
            }
        }
        // Moments `d × o` for the triangle pre-test (not needed with one origin).
        let mut m_max = [0.0f64; LANES];
        for k in (0..3).filter(|_| !shared) {
            let (a, b) = ((k + 1) % 3, (k + 2) % 3);
            for c in 0..NCHUNK {
                for j in 0..CHUNK {
                    let l = c * CHUNK + j;
                    let m = d[a][l] * o[b][l] - d[b][l] * o[a][l];
                    let m32 = m as f32;
                    bad[c][j] += zero_if_finite(m32);
                    p.m[k][c][j] = m32;
                    m_max[l] = if m.abs() > m_max[l] {
                        m.abs()
                    } else {
                        m_max[l]
                    };
                }
            }
        }
        // A chunk's finite lanes as bits.
        let mut finite: Mask = 0;
        for c in 0..NCHUNK {
            finite |= mask_bits(lanes(&bad[c]).cmp_eq(splat(0.0))) << (c * CHUNK);
        }
        let valid = staged & finite;
        p.valid = valid;
        if valid == 0 {
            return;
        }
        let is_valid = |l: usize| valid & (1 << l) != 0;
        let first = valid.trailing_zeros() as usize;
        let (c0, j0) = (first / CHUNK, first % CHUNK);
        // Lanes that are not valid take the first valid lane's values, so that bounds over all
        // lanes are bounds over the valid ones (their `lo`/`hi` keep them out of every box).
        for l in (0..LANES).filter(|&l| !is_valid(l)) {
            let (c, j) = (l / CHUNK, l % CHUNK);
            for k in 0..3 {
                p.oa[k][c][j] = p.oa[k][c0][j0];
                p.ob[k][c][j] = p.ob[k][c0][j0];
                p.imin[k][c][j] = p.imin[k][c0][j0];
                p.imax[k][c][j] = p.imax[k][c0][j0];
                p.d[k][c][j] = p.d[k][c0][j0];
                p.m[k][c][j] = p.m[k][c0][j0];
                o[k][l] = o[k][first];
                d[k][l] = d[k][first];
            }
            m_max[l] = m_max[first];
            (lo[l], hi[l]) = (lo[first], hi[first]);
        }
        let (mut whole_lo, mut whole_hi) = ([[0.0; CHUNK]; NCHUNK], [[0.0; CHUNK]; NCHUNK]);
        {
            let (wlo, whi) = (flat(&mut whole_lo), flat(&mut whole_hi));
            let (plo, phi) = (flat(&mut p.lo), flat(&mut p.hi));
            for l in 0..LANES {
                wlo[l] = (lo[l] * (1.0 - 2.0 * U32) - TINY) as f32;
                whi[l] = (hi[l] * (1.0 + 2.0 * U32) + TINY) as f32;
                // Lanes that are not valid keep an empty range (they never enter a box).
                let on = (valid >> l) & 1 != 0;
                plo[l] = if on { wlo[l] } else { f32::INFINITY };
                phi[l] = if on { whi[l] } else { f32::NEG_INFINITY };
            }
        }
        let (mut d_max, mut r_max) = (0.0f64, 0.0f64);
        let mut mean = [0.0f32; 3];
        for k in 0..3 {
            d_max = d_max.max(largest(&d[k]));
            r_max = r_max.max(largest(&o[k]));
            // Only orders children: lane-wise sums (a sequential sum was a chain of 64 adds).
            let mut sum = splat(0.0);
            for c in 0..NCHUNK {
                sum += lanes(&p.d[k][c]);
            }
            mean[k] = sum.reduce_add();
            let w = &mut p.whole;
            w.oa[k] = range(&p.oa[k]);
            w.ob[k] = range(&p.ob[k]);
            w.imin[k] = range(&p.imin[k]);
            w.imax[k] = range(&p.imax[k]);
            // `imin` is positive exactly for a positive direction.
            p.sign[k] = match (w.imin[k][0] > 0.0, w.imin[k][1] < 0.0) {
                (true, _) => Sign::Positive,
                (_, true) => Sign::Negative,
                _ => Sign::Mixed,
            };
        }
        let mm_max = largest(&m_max);
        p.whole.lo = range(&whole_lo);
        p.whole.hi = range(&whole_hi);
        p.shared = shared;
        let (c, j) = (first / CHUNK, first % CHUNK);
        p.shared_o = std::array::from_fn(|k| [p.oa[k][c][j], p.ob[k][c][j]]);
        if majors.iter().filter(|m| **m).count() == 1 {
            p.major = majors.iter().position(|m| *m);
        }
        // f32 pre-test error (the inputs' rounding to f32, the two dot products and their sum:
        // under 7·2⁻²⁴ of |d|∞|n|₁ + |m|∞|e|₁) and the f64 watertight test's own error with the
        // rounding of the mesh-centred f64 inputs (under 256·2⁻⁵³·(R + r)²|d|∞).
        p.alpha = up(8.0 * U32 * d_max);
        p.beta = up(8.0 * U32 * mm_max * (1.0 + 8.0 * U64));
        p.shared_origin = std::array::from_fn(|k| o[k][first] as f32);
        p.shared_beta = up(24.0 * U32 * d_max * r_max * (1.0 + 8.0 * U64));
        let reach = (bvh.radius + r_max) * (1.0 + 8.0 * U64);
        p.gamma = up(256.0 * U64 * reach * reach * d_max);
        p.mean_dir = mean;
        let w = &mut p.whole;
        w.usable = p.sign.iter().all(|s| *s != Sign::Mixed);
        w.major = p.major;
        w.shared = p.shared;
        w.bound_min = f32::INFINITY;
        w.bound_max = f32::INFINITY;
        p.unhit = valid;
        // One frame's axes for every valid lane: each lane's shear now, as `RayFrame::new`
        // computes it (the same quotients), for all lanes at once.
        let origin = rays[first].origin.to_array().map(f64::to_bits);
        let one_origin =
            (0..n).all(|l| !is_valid(l) || rays[l].origin.to_array().map(f64::to_bits) == origin);
        if one_origin {
            p.origin = Some(rays[first].origin);
        }
        if let Some(kz) = p.major
            && p.sign[kz] != Sign::Mixed
        {
            let (mut kx, mut ky) = ((kz + 1) % 3, (kz + 2) % 3);
            if p.sign[kz] == Sign::Negative {
                std::mem::swap(&mut kx, &mut ky);
            }
            for l in 0..LANES {
                p.shear[0][l] = d[kx][l] / d[kz][l];
                p.shear[1][l] = d[ky][l] / d[kz][l];
                p.shear[2][l] = p.inv[kz][l];
            }
            p.axes = Some([kx, ky, kz]);
        }
        if valid != LANES_MASK {
            // See `set_best`: lanes that are not valid do not hold the largest bound up.
            for k in 0..3 {
                for l in (0..LANES).filter(|&l| !is_valid(l)) {
                    p.bound[k][l / CHUNK][l % CHUNK] = f32::NEG_INFINITY;
                }
            }
        }
    }

    /// Which of the lanes in `mask` enter `node`'s f32 box within their range (and, for the
    /// nearest hit, whose major-axis entry is not past their best hit): every lane the f64
    /// slab lets in. Lanes go [`CHUNK`] at a time, lane-innermost so that each chunk compiles
    /// to vector code, and chunks with no lane in `mask` are skipped.
    #[inline(always)]
    fn enters(&self, node: &FNode, mask: Mask, nearest: bool) -> Mask {
        match self.whole.decide(node, nearest) {
            Some(true) => return mask,
            Some(false) => return 0,
            None => {}
        }
        if self.whole.usable {
            return self.enters_signed(node, mask, nearest);
        }
        let mut bits: Mask = 0;
        for c in 0..LANES / CHUNK {
            let base = c * CHUNK;
            if (mask >> base) & CHUNK_MASK != 0 {
                bits |= self.enters_chunk(node, c, nearest) << base;
            }
        }
        bits & mask
    }

    /// [`Packet::enters`]'s lane tests where every axis's directions share a sign (the near plane of
    /// each axis is known for the whole packet), written lane-outermost with the three axes
    /// inside: that form vectorises across the lanes (axes-outermost, the compiler vectorised
    /// across the axes and shuffled: twice the instructions).
    #[inline(always)]
    fn enters_signed(&self, node: &FNode, mask: Mask, nearest: bool) -> Mask {
        // Per axis: the near and far planes with the origins and inverses that go with them.
        let mut planes = [[0.0f32; 2]; 3];
        let mut origins: [[&[V; NCHUNK]; 2]; 3] = [[&self.oa[0]; 2]; 3];
        let mut inverses: [[&[V; NCHUNK]; 2]; 3] = [[&self.imin[0]; 2]; 3];
        for k in 0..3 {
            let lo = (node.min[k], &self.oa[k], &self.imin[k], self.shared_o[k][0]);
            let hi = (node.max[k], &self.ob[k], &self.imax[k], self.shared_o[k][1]);
            let (n, f) = if self.sign[k] == Sign::Positive {
                (lo, hi)
            } else {
                (hi, lo)
            };
            // One origin: the plane minus the origin once (as `enters_chunk` does).
            let (np, fp) = if self.shared {
                (n.0 - n.3, f.0 - f.3)
            } else {
                (n.0, f.0)
            };
            planes[k] = [np, fp];
            origins[k] = [n.1, f.1];
            inverses[k] = [n.2, f.2];
        }
        // The major-axis cull: the shared major axis, every axis without one (3), or none (4).
        let cull = match (nearest, self.major) {
            (false, _) => 4,
            (true, Some(m)) => m,
            (true, None) => 3,
        };
        let mut bits: Mask = 0;
        for c in 0..NCHUNK {
            let base = c * CHUNK;
            if (mask >> base) & CHUNK_MASK != 0 {
                bits |= if self.shared {
                    self.enters_lanes::<true>(c, &planes, &origins, &inverses, cull)
                } else {
                    self.enters_lanes::<false>(c, &planes, &origins, &inverses, cull)
                } << base;
            }
        }
        bits & mask
    }

    #[inline(always)]
    fn enters_lanes<const SHARED: bool>(
        &self,
        c: usize,
        planes: &[[f32; 2]; 3],
        origins: &[[&[V; NCHUNK]; 2]; 3],
        inverses: &[[&[V; NCHUNK]; 2]; 3],
        cull: usize,
    ) -> Mask {
        let (mut enter, mut leave) = (lanes(&self.lo[c]), lanes(&self.hi[c]));
        let mut excess = splat(f32::NEG_INFINITY);
        for k in 0..3 {
            let [np, fp] = planes[k];
            let (ni, fi) = (lanes(&inverses[k][0][c]), lanes(&inverses[k][1][c]));
            let (near, far) = if SHARED {
                (splat(np) * ni, splat(fp) * fi)
            } else {
                (
                    (splat(np) - lanes(&origins[k][0][c])) * ni,
                    (splat(fp) - lanes(&origins[k][1][c])) * fi,
                )
            };
            enter = enter.fast_max(near);
            leave = leave.fast_min(far);
            if cull == k || cull == 3 {
                excess = excess.fast_max(near - lanes(&self.bound[k][c]));
            }
        }
        let gap = (enter - (leave + splat(f32::MIN_POSITIVE))).fast_max(excess);
        mask_bits(gap.cmp_le(splat(0.0)))
    }

    #[inline(always)]
    fn enters_chunk(&self, node: &FNode, c: usize, nearest: bool) -> Mask {
        let mut enter = self.lo[c];
        let mut leave = self.hi[c];
        // `near − bound` on the major axis: positive when the entry is past the best hit.
        let mut excess = [f32::NEG_INFINITY; CHUNK];
        for k in 0..3 {
            let (lo, hi) = (node.min[k], node.max[k]);
            let (oa, ob) = (&self.oa[k][c], &self.ob[k][c]);
            let (ia, ib) = (&self.imin[k][c], &self.imax[k][c]);
            let mut t0 = [0.0f32; CHUNK];
            let mut t1 = [0.0f32; CHUNK];
            if self.shared {
                // The same subtraction as below, done once.
                let (a, b) = (lo - self.shared_o[k][0], hi - self.shared_o[k][1]);
                for j in 0..CHUNK {
                    t0[j] = a * ia[j];
                    t1[j] = b * ib[j];
                }
            } else {
                for j in 0..CHUNK {
                    t0[j] = (lo - oa[j]) * ia[j];
                    t1[j] = (hi - ob[j]) * ib[j];
                }
            }
            // On an axis where every lane's direction has one sign, the near plane is known
            // up front.
            let (near, far) = match self.sign[k] {
                Sign::Positive => (t0, t1),
                Sign::Negative => (t1, t0),
                Sign::Mixed => {
                    let mut near = [0.0f32; CHUNK];
                    let mut far = [0.0f32; CHUNK];
                    for j in 0..CHUNK {
                        near[j] = min(t0[j], t1[j]);
                        far[j] = max(t0[j], t1[j]);
                    }
                    (near, far)
                }
            };
            for j in 0..CHUNK {
                enter[j] = max(enter[j], near[j]);
                leave[j] = min(leave[j], far[j]);
            }
            if nearest && self.major.is_none_or(|m| m == k) {
                let bound = &self.bound[k][c];
                for j in 0..CHUNK {
                    excess[j] = max(excess[j], near[j] - bound[j]);
                }
            }
        }
        let mut inside = [false; CHUNK];
        for j in 0..CHUNK {
            // `MIN_POSITIVE`: an underflowed product may be off by a subnormal's spacing. A
            // difference of two floats is ≤ 0 exactly when the first is not the larger.
            let gap = max(enter[j] - (leave[j] + f32::MIN_POSITIVE), excess[j]);
            inside[j] = gap <= 0.0;
        }
        bitmask(inside)
    }

    /// Which of the lanes in `mask` may hit `tri`: not those where two edge functions have
    /// opposite signs beyond the error bound.
    #[inline(always)]
    fn may_hit(&self, tri: &FTri, mask: Mask) -> Mask {
        if self.shared {
            return self.may_hit_shared(tri, mask);
        }
        let bound: [f32; 3] =
            std::array::from_fn(|k| self.alpha * tri.n1[k] + self.beta * tri.e1[k] + self.gamma);
        let mut bits: Mask = 0;
        for c in 0..LANES / CHUNK {
            let base = c * CHUNK;
            if (mask >> base) & CHUNK_MASK != 0 {
                bits |= self.may_hit_chunk(tri, &bound, c) << base;
            }
        }
        bits & mask
    }

    /// [`Packet::may_hit`] for lanes that share one origin `o`: `d·n + (d × o)·e` is
    /// `d·(n + o × e)`, and `n + o × e` is computed once for the packet. In f32, with the
    /// rounding of `o`, `n`, `e` and `d`, the cross product, the sum and the dot product, the
    /// result is within 2⁻²⁴·(6|n|₁ + 20|o|∞|e|₁)·|d|∞ of `d·n + (d × o)·e`, which `alpha` and
    /// `shared_beta` cover (8 and 24).
    #[inline(always)]
    fn may_hit_shared(&self, tri: &FTri, mask: Mask) -> Mask {
        let o = self.shared_origin;
        let normals: [[f32; 3]; 3] = std::array::from_fn(|k| {
            let (n, e) = (tri.n[k], tri.e[k]);
            [
                n[0] + (o[1] * e[2] - o[2] * e[1]),
                n[1] + (o[2] * e[0] - o[0] * e[2]),
                n[2] + (o[0] * e[1] - o[1] * e[0]),
            ]
        });
        let bound: [f32; 3] = std::array::from_fn(|k| {
            self.alpha * tri.n1[k] + self.shared_beta * tri.e1[k] + self.gamma
        });
        let mut bits: Mask = 0;
        for c in 0..LANES / CHUNK {
            let base = c * CHUNK;
            if (mask >> base) & CHUNK_MASK != 0 {
                let (d0, d1, d2) = (
                    lanes(&self.d[0][c]),
                    lanes(&self.d[1][c]),
                    lanes(&self.d[2][c]),
                );
                let (mut low, mut high) = (splat(f32::INFINITY), splat(f32::NEG_INFINITY));
                for k in 0..3 {
                    let (n, b) = (normals[k], splat(bound[k]));
                    let s = d0 * splat(n[0]) + d1 * splat(n[1]) + d2 * splat(n[2]);
                    low = low.fast_min(s + b);
                    high = high.fast_max(s - b);
                }
                let reject = low.cmp_lt(splat(0.0)) & high.cmp_gt(splat(0.0));
                bits |= (!mask_bits(reject) & CHUNK_MASK) << base;
            }
        }
        bits & mask
    }

    #[inline(always)]
    fn may_hit_chunk(&self, tri: &FTri, bound: &[f32; 3], c: usize) -> Mask {
        // The least `s + bound` (negative: an edge certainly negative) and the largest
        // `s − bound` (positive: one certainly positive).
        let (d, m) = (&self.d, &self.m);
        let (d0, d1, d2) = (lanes(&d[0][c]), lanes(&d[1][c]), lanes(&d[2][c]));
        let (m0, m1, m2) = (lanes(&m[0][c]), lanes(&m[1][c]), lanes(&m[2][c]));
        let (mut low, mut high) = (splat(f32::INFINITY), splat(f32::NEG_INFINITY));
        for k in 0..3 {
            let (n, e, b) = (tri.n[k], tri.e[k], splat(bound[k]));
            let dn = d0 * splat(n[0]) + d1 * splat(n[1]) + d2 * splat(n[2]);
            let me = m0 * splat(e[0]) + m1 * splat(e[1]) + m2 * splat(e[2]);
            let s = dn + me;
            low = low.fast_min(s + b);
            high = high.fast_max(s - b);
        }
        let reject = low.cmp_lt(splat(0.0)) & high.cmp_gt(splat(0.0));
        !mask_bits(reject) & CHUNK_MASK
    }

    /// Records lane `l`'s new best hit for the major-axis cull.
    fn set_best(&mut self, l: usize, t: f64) {
        let kz = usize::from(self.kz[l]);
        self.bound[kz][l / CHUNK][l % CHUNK] = up(t);
        self.unhit &= !(1 << l);
        if self.major == Some(kz) && self.unhit != 0 {
            // A lane with no hit holds the largest bound at `+∞`.
            self.whole.bound_min = min(self.whole.bound_min, up(t));
        } else if self.major == Some(kz) {
            // Bounds only fall: the least is the last least or this one. Lanes that are not
            // valid hold `−∞` here (they never enter a box anyway), so the row's largest is the
            // valid lanes' largest.
            self.whole.bound_min = min(self.whole.bound_min, up(t));
            // Lane-wise over the chunks first (it vectorises: a sequential fold of 64 selects
            // was an eighth of the primary rays' time), then across one chunk.
            self.whole.bound_max = range(&self.bound[kz])[1];
        }
    }

    /// Whether the f64 slab of lane `l` (`ray` over `range`) reaches node `index` (a hit in its
    /// leaf counts).
    fn reaches(
        &self,
        l: usize,
        ray: &Ray,
        range: Interval,
        boxes: &[[DVec3; 2]],
        index: u32,
    ) -> bool {
        let [min, max] = boxes[index as usize];
        let slab = Slab {
            origin: ray.origin,
            inv: DVec3::new(self.inv[0][l], self.inv[1][l], self.inv[2][l]),
            kz: usize::from(self.kz[l]),
            lo: range.lo,
            hi: range.hi,
        };
        slab.test(min, max).is_some()
    }

    /// A triangle's corners relative to the packet's one origin, once for all its lanes.
    #[inline(always)]
    fn relative(&self, corners: [DVec3; 3]) -> Option<[[f64; 3]; 3]> {
        self.origin.map(|o| corners.map(|c| (c - o).to_array()))
    }

    /// Lane `l`'s (`ray`'s) hit on the triangle with `corners`: [`intersect`]'s answer, from
    /// the packet's shears and `relative` corners where it has them.
    #[inline(always)]
    fn hit(
        &mut self,
        l: usize,
        ray: &Ray,
        corners: [DVec3; 3],
        relative: Option<[[f64; 3]; 3]>,
        range: Interval,
    ) -> Option<UnresolvedHit> {
        let Some(axes) = self.axes else {
            return self.frame_hit(l, ray, corners, range);
        };
        let shear = [self.shear[0][l], self.shear[1][l], self.shear[2][l]];
        let relative = relative.unwrap_or_else(|| corners.map(|c| (c - ray.origin).to_array()));
        intersect_relative(axes, shear, relative, range)
    }

    /// Lane `l`'s (`ray`'s) hit on the triangle with `corners` by its own frame.
    fn frame_hit(
        &mut self,
        l: usize,
        ray: &Ray,
        corners: [DVec3; 3],
        range: Interval,
    ) -> Option<UnresolvedHit> {
        let frame = self.frame(l, ray);
        let relative = corners.map(|c| (c - frame.origin()).to_array());
        intersect_relative(frame.axes(), frame.shear(), relative, range)
    }

    /// Lane `l`'s (`ray`'s) watertight frame.
    fn frame(&mut self, l: usize, ray: &Ray) -> &RayFrame {
        self.frames[l].get_or_insert_with(|| RayFrame::new(ray))
    }
}
