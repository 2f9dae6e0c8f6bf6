//! Packet traversal of a [`MeshBvh`]: many rays at once (a renderer's tile), the same answers as
//! [`MeshBvh::nearest_hit`] and [`MeshBvh::any_hit`] bit for bit, found faster.
//!
//! Rays go through in packets of [`LANES`] consecutive rays, traversing one BVH2 (the
//! reference's topology) together with a shared stack whose entries carry the mask of lanes
//! still in them. Everything that only *decides what to look at* is f32 and conservative;
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
//! - Lanes the f32 bounds cannot cover (a direction component that is zero or below ~3e-39, a
//!   range that starts below 0, non-finite values) are answered by the reference itself.

use crate::bvh::{Slab, is_better};
use crate::triangle::{RayFrame, intersect};
use crate::{MeshBvh, MeshHit, TriangleMesh};
use fray_core::{Interval, Ray};
use glam::DVec3;

/// Rays per packet: consecutive rays of a call are traversed together, so neighbouring pixels
/// (a 4×2 block in Morton order) should be consecutive.
pub const LANES: usize = 8;

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
    reference: MeshBvh,
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
            .nodes()
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
        let boxes = bvh.nodes().iter().map(|n| [n.min, n.max]).collect();
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
        let mut stack = Vec::with_capacity(64);
        for ((rays, ranges), hits) in rays
            .chunks(LANES)
            .zip(ranges.chunks(LANES))
            .zip(hits.chunks_mut(LANES))
        {
            self.nearest_packet(rays, ranges, hits, &mut stack);
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
        let mut stack = Vec::with_capacity(64);
        for ((rays, ranges), out) in rays
            .chunks(LANES)
            .zip(ranges.chunks(LANES))
            .zip(occluded.chunks_mut(LANES))
        {
            self.any_packet(rays, ranges, out, &mut stack);
        }
    }

    fn nearest_packet(
        &self,
        rays: &[Ray],
        ranges: &[Interval],
        hits: &mut [Option<MeshHit>],
        stack: &mut Vec<(u32, u32)>,
    ) {
        let mut p = Packet::new(self, rays, ranges);
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
        let mut bary = [[0.0; 3]; LANES];
        stack.clear();
        stack.push((0, p.valid));
        while let Some((index, mask)) = stack.pop() {
            let node = &self.nodes[index as usize];
            let mask = mask & p.enters(node, true);
            if mask == 0 {
                continue;
            }
            if node.count == 0 {
                self.push_children(&p, node, mask, stack);
                continue;
            }
            let (first, count) = (node.first as usize, node.count as usize);
            for pos in first..first + count {
                let mut candidates = mask & p.may_hit(&self.tris[pos]);
                while candidates != 0 {
                    let l = candidates.trailing_zeros() as usize;
                    candidates &= candidates - 1;
                    let Some(h) = intersect(&p.frames[l], self.corners[pos], ranges[l]) else {
                        continue;
                    };
                    let triangle = self.order[pos];
                    let best = (best_tri[l] != u32::MAX).then_some(best_tri[l]);
                    if is_better(h.t, triangle, best_t[l], best) && p.reaches(l, &self.boxes, index)
                    {
                        best_t[l] = h.t;
                        best_tri[l] = triangle;
                        bary[l] = h.barycentric;
                        p.set_best(l, h.t);
                    }
                }
            }
        }
        for (l, hit) in hits.iter_mut().enumerate() {
            if p.valid & (1 << l) != 0 && best_tri[l] != u32::MAX {
                *hit = Some(MeshHit {
                    t: best_t[l],
                    triangle: best_tri[l],
                    barycentric: bary[l],
                });
            }
        }
    }

    fn any_packet(
        &self,
        rays: &[Ray],
        ranges: &[Interval],
        out: &mut [bool],
        stack: &mut Vec<(u32, u32)>,
    ) {
        let p = Packet::new(self, rays, ranges);
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
            let mut mask = mask & p.enters(node, false);
            if mask == 0 {
                continue;
            }
            if node.count == 0 {
                self.push_children(&p, node, mask, stack);
                continue;
            }
            let (first, count) = (node.first as usize, node.count as usize);
            for pos in first..first + count {
                let mut candidates = mask & p.may_hit(&self.tris[pos]);
                while candidates != 0 {
                    let l = candidates.trailing_zeros() as usize;
                    candidates &= candidates - 1;
                    if intersect(&p.frames[l], self.corners[pos], ranges[l]).is_some()
                        && p.reaches(l, &self.boxes, index)
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
    fn push_children(&self, p: &Packet, node: &FNode, mask: u32, stack: &mut Vec<(u32, u32)>) {
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
    valid: u32,
    /// Origins relative to the centre, rounded up (used with box minima) and down (maxima).
    oa: [[f32; LANES]; 3],
    ob: [[f32; LANES]; 3],
    /// Inverse directions scaled for the minimum and the maximum planes (see [`KAPPA`]).
    imin: [[f32; LANES]; 3],
    imax: [[f32; LANES]; 3],
    lo: [f32; LANES],
    hi: [f32; LANES],
    /// The best hit so far, rounded up, on the lane's major axis; `+∞` on the others and
    /// before a hit.
    bound: [[f32; LANES]; 3],
    /// Directions and moments `d × o` (relative to the centre) for the triangle pre-test.
    d: [[f32; LANES]; 3],
    m: [[f32; LANES]; 3],
    /// The pre-test's error bound is `alpha·|n|₁ + beta·|e|₁ + gamma` per edge.
    alpha: f32,
    beta: f32,
    gamma: f32,
    mean_dir: [f32; 3],
    /// Per axis, whether every valid lane's direction is positive, negative, or neither.
    sign: [Sign; 3],
    frames: [RayFrame; LANES],
    slabs: [Slab; LANES],
}

impl Packet {
    fn new(bvh: &PacketBvh, rays: &[Ray], ranges: &[Interval]) -> Self {
        let unit = Ray {
            origin: DVec3::ZERO,
            dir: DVec3::Z,
        };
        let mut p = Packet {
            valid: 0,
            oa: [[0.0; LANES]; 3],
            ob: [[0.0; LANES]; 3],
            imin: [[0.0; LANES]; 3],
            imax: [[0.0; LANES]; 3],
            // A lane that is not valid never enters a box.
            lo: [f32::INFINITY; LANES],
            hi: [f32::NEG_INFINITY; LANES],
            bound: [[f32::INFINITY; LANES]; 3],
            d: [[0.0; LANES]; 3],
            m: [[0.0; LANES]; 3],
            alpha: 0.0,
            beta: 0.0,
            gamma: 0.0,
            mean_dir: [0.0; 3],
            sign: [Sign::Mixed; 3],
            frames: [RayFrame::new(&unit); LANES],
            slabs: [Slab::new(&unit, Interval::new(0.0, 0.0)); LANES],
        };
        if bvh.nodes.is_empty() {
            return p;
        }
        let (mut d_max, mut m_max, mut r_max) = (0.0f64, 0.0f64, 0.0f64);
        let mut mean = DVec3::ZERO;
        let (mut positive, mut negative) = ([true; 3], [true; 3]);
        for (l, (ray, range)) in rays.iter().zip(ranges).enumerate() {
            // Negative starts would need the bounds' other sign cases; NaN fails too.
            if !(range.lo >= 0.0 && range.lo <= range.hi && range.lo.is_finite())
                || !(ray.origin.is_finite() && ray.dir.is_finite())
            {
                continue;
            }
            let o = ray.origin - bvh.centre;
            let inv = ray.dir.recip();
            let m = ray.dir.cross(o);
            let mut ok = true;
            for k in 0..3 {
                // `o − centre` is within one f64 rounding of the exact difference; one f32
                // rounding to nearest is within 2⁻²⁴ of what it rounds (and `TINY` covers
                // subnormal spacing).
                let slack = o[k].abs() * (2.0 * U64 + 2.0 * U32) + TINY;
                p.oa[k][l] = (o[k] + slack) as f32;
                p.ob[k][l] = (o[k] - slack) as f32;
                let shrunk = (inv[k] * (1.0 - KAPPA - 2.0 * U32)) as f32;
                let grown = (inv[k] * (1.0 + KAPPA + 2.0 * U32)) as f32;
                ok &= inv[k].is_finite() && grown.is_finite() && p.oa[k][l].is_finite();
                ok &= p.ob[k][l].is_finite();
                // A positive component meets the minimum plane first, a negative one the
                // maximum.
                (p.imin[k][l], p.imax[k][l]) = if inv[k] > 0.0 {
                    (shrunk, grown)
                } else {
                    (grown, shrunk)
                };
                p.d[k][l] = ray.dir[k] as f32;
                p.m[k][l] = m[k] as f32;
                ok &= p.m[k][l].is_finite();
            }
            if !ok {
                // Back to a lane that never enters a box.
                for k in 0..3 {
                    p.imin[k][l] = 0.0;
                    p.imax[k][l] = 0.0;
                }
                continue;
            }
            p.valid |= 1 << l;
            p.lo[l] = (range.lo * (1.0 - 2.0 * U32) - TINY) as f32;
            p.hi[l] = (range.hi * (1.0 + 2.0 * U32) + TINY) as f32;
            p.slabs[l] = Slab::new(ray, *range);
            p.frames[l] = RayFrame::new(ray);
            d_max = d_max.max(ray.dir.abs().max_element());
            m_max = m_max.max(m.abs().max_element());
            r_max = r_max.max(o.abs().max_element());
            mean += ray.dir;
            for k in 0..3 {
                positive[k] &= inv[k] > 0.0;
                negative[k] &= inv[k] < 0.0;
            }
        }
        for k in 0..3 {
            p.sign[k] = match (positive[k], negative[k]) {
                (true, false) => Sign::Positive,
                (false, true) => Sign::Negative,
                _ => Sign::Mixed,
            };
        }
        // f32 pre-test error (the inputs' rounding to f32, the two dot products and their sum:
        // under 7·2⁻²⁴ of |d|∞|n|₁ + |m|∞|e|₁) and the f64 watertight test's own error with the
        // rounding of the mesh-centred f64 inputs (under 256·2⁻⁵³·(R + r)²|d|∞).
        p.alpha = up(8.0 * U32 * d_max);
        p.beta = up(8.0 * U32 * m_max * (1.0 + 8.0 * U64));
        let reach = (bvh.radius + r_max) * (1.0 + 8.0 * U64);
        p.gamma = up(256.0 * U64 * reach * reach * d_max);
        p.mean_dir = f32s(mean);
        p
    }

    /// The lanes whose ray enters `node`'s f32 box within their range (and, for the nearest
    /// hit, whose major-axis entry is not past their best hit): every lane the f64 slab lets in.
    /// Written lane-innermost so that it compiles to vector code over the lanes; on an axis
    /// where every lane's direction has one sign the near and far planes are known up front.
    #[inline(always)]
    fn enters(&self, node: &FNode, nearest: bool) -> u32 {
        let mut enter = self.lo;
        let mut leave = self.hi;
        // The largest `near − bound` over the axes: positive when the major-axis entry is past
        // the best hit (`bound` is `+∞` on the other axes, so they never count).
        let mut excess = [f32::NEG_INFINITY; LANES];
        for k in 0..3 {
            let (lo, hi) = (node.min[k], node.max[k]);
            match self.sign[k] {
                Sign::Mixed => {
                    for l in 0..LANES {
                        let t0 = (lo - self.oa[k][l]) * self.imin[k][l];
                        let t1 = (hi - self.ob[k][l]) * self.imax[k][l];
                        let near = min(t0, t1);
                        enter[l] = max(enter[l], near);
                        leave[l] = min(leave[l], max(t0, t1));
                        excess[l] = max(excess[l], near - self.bound[k][l]);
                    }
                }
                Sign::Positive => {
                    for l in 0..LANES {
                        let near = (lo - self.oa[k][l]) * self.imin[k][l];
                        let far = (hi - self.ob[k][l]) * self.imax[k][l];
                        enter[l] = max(enter[l], near);
                        leave[l] = min(leave[l], far);
                        excess[l] = max(excess[l], near - self.bound[k][l]);
                    }
                }
                Sign::Negative => {
                    for l in 0..LANES {
                        let far = (lo - self.oa[k][l]) * self.imin[k][l];
                        let near = (hi - self.ob[k][l]) * self.imax[k][l];
                        enter[l] = max(enter[l], near);
                        leave[l] = min(leave[l], far);
                        excess[l] = max(excess[l], near - self.bound[k][l]);
                    }
                }
            }
        }
        let mut bits = 0u32;
        for l in 0..LANES {
            // `MIN_POSITIVE`: an underflowed product may be off by a subnormal's spacing. A
            // difference of two floats is ≤ 0 exactly when the first is not the larger.
            let mut gap = enter[l] - (leave[l] + f32::MIN_POSITIVE);
            if nearest {
                gap = max(gap, excess[l]);
            }
            bits |= u32::from(gap <= 0.0) << l;
        }
        bits
    }

    /// The lanes whose ray may hit `tri`: not those where two edge functions have opposite
    /// signs beyond the error bound.
    #[inline(always)]
    fn may_hit(&self, tri: &FTri) -> u32 {
        // The least `s + bound` (negative: an edge certainly negative) and the largest
        // `s − bound` (positive: one certainly positive).
        let mut low = [f32::INFINITY; LANES];
        let mut high = [f32::NEG_INFINITY; LANES];
        for k in 0..3 {
            let (n, e) = (tri.n[k], tri.e[k]);
            let bound = self.alpha * tri.n1[k] + self.beta * tri.e1[k] + self.gamma;
            for l in 0..LANES {
                let dn = self.d[0][l] * n[0] + self.d[1][l] * n[1] + self.d[2][l] * n[2];
                let me = self.m[0][l] * e[0] + self.m[1][l] * e[1] + self.m[2][l] * e[2];
                let s = dn + me;
                low[l] = min(low[l], s + bound);
                high[l] = max(high[l], s - bound);
            }
        }
        let (mut negative, mut positive) = (0u32, 0u32);
        for l in 0..LANES {
            negative |= u32::from(low[l] < 0.0) << l;
        }
        for l in 0..LANES {
            positive |= u32::from(high[l] > 0.0) << l;
        }
        !(negative & positive)
    }

    /// Records lane `l`'s new best hit for the major-axis cull.
    fn set_best(&mut self, l: usize, t: f64) {
        self.bound[self.slabs[l].kz][l] = up(t);
    }

    /// Whether the f64 slab of lane `l` reaches node `index` (a hit in its leaf counts).
    fn reaches(&self, l: usize, boxes: &[[DVec3; 2]], index: u32) -> bool {
        let [min, max] = boxes[index as usize];
        self.slabs[l].test(min, max).is_some()
    }
}
