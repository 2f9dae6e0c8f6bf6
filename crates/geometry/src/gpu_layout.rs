//! GPU parameter structs of free-form solids: plain `#[repr(C)]` (bytemuck) mirrors of quadrics,
//! perturbations, leaves, the postfix CSG program and solids, in f32 and **relative to a
//! reference point** (the GPU backend's anchor), each declared once with
//! [`fray_core::gpu_struct!`], which generates its WGSL twin from the same field list.
//!
//! Positions are made relative in f64 before they are rounded to f32 (a quadric's coefficients
//! are about its own origin, so only origins and boxes move), which keeps far-from-origin scenes
//! as accurate on the GPU as scenes at the origin. Boxes are rounded outward.

use crate::{CsgOp, Quadric, Solid};
use fray_core::Aabb;
use fray_core::gpu_struct::GpuStruct;
use glam::DVec3;

/// Op codes of the flat postfix program, in the low two bits of each word; a leaf's index (into
/// the whole leaf array) sits in the upper 30 bits.
pub const OP_LEAF: u32 = 0;
pub const OP_MAX: u32 = 1;
pub const OP_MIN: u32 = 2;
pub const OP_NEG: u32 = 3;
/// Bits of a program word that hold the op code.
pub const OP_BITS: u32 = 2;

fray_core::gpu_struct! {
    /// A quadric relative to the reference point: `origin.xyz` (w unused) and the ten
    /// coefficients `c0 = (A11, A22, A33, A12)`, `c1 = (A13, A23, A14, A24)`, `c2 = (A34, A44, –, –)`.
    pub struct GpuQuadric {
        pub origin: [f32; 4],
        pub c0: [f32; 4],
        pub c1: [f32; 4],
        pub c2: [f32; 4],
    }
}

fray_core::gpu_struct! {
    /// A perturbation `f · Q³` where `Q > 0`.
    pub struct GpuPerturbation {
        pub quadric: GpuQuadric,
        /// The form factor `f`.
        pub form_factor: f32,
        pub pad: f32,
        pub pad2: [f32; 2],
    }
}

fray_core::gpu_struct! {
    /// A CSG leaf (free form): base quadric, box (relative), whether the box clips it, its
    /// perturbations `[first_perturbation, end_perturbation)` and the caller's tag (e.g. its
    /// material).
    pub struct GpuLeaf {
        pub base: GpuQuadric,
        pub box_min: [f32; 4],
        pub box_max: [f32; 4],
        /// 1 if the box clips the leaf's shape, else 0.
        pub clips: u32,
        pub first_perturbation: u32,
        pub end_perturbation: u32,
        pub material: u32,
    }
}

fray_core::gpu_struct! {
    /// A solid: its box (relative), its leaves `[first_leaf, first_leaf + leaf_count)` and its
    /// program `[first_word, first_word + word_count)` of the program array; where the solid's
    /// complement is needed (rays travelling inside a transmissive solid look for where it
    /// ends), that program negated at `[complement_word, complement_word + word_count + 1)`
    /// (0: none — a complement always follows the solids' own programs).
    pub struct GpuSolid {
        pub box_min: [f32; 4],
        pub box_max: [f32; 4],
        pub first_leaf: u32,
        pub leaf_count: u32,
        pub first_word: u32,
        pub word_count: u32,
        pub complement_word: u32,
        pub pad: u32,
        pub pad2: [u32; 2],
    }
}

/// All solids of a scene flattened into upload-ready arrays.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct GpuSolids {
    pub reference: DVec3,
    pub solids: Vec<GpuSolid>,
    pub leaves: Vec<GpuLeaf>,
    pub perturbations: Vec<GpuPerturbation>,
    pub program: Vec<u32>,
    /// Largest leaf count of one solid.
    pub max_leaves: u32,
    /// Largest perturbation count of one solid.
    pub max_perturbations: u32,
    /// Largest CSG stack depth of one solid.
    pub max_stack: u32,
}

/// `(v, w)` rounded to f32: the packing of every `vec4<f32>` field the GPU structs share.
pub fn vec4(v: DVec3, w: f64) -> [f32; 4] {
    [v.x as f32, v.y as f32, v.z as f32, w as f32]
}

/// The program word of `op` for a solid whose leaves start at `first_leaf` in the leaf array
/// (a leaf's index is global there). Also encodes pruned programs ([`crate::ActiveSet::program`]).
pub fn program_word(op: CsgOp, first_leaf: u32) -> u32 {
    match op {
        CsgOp::Leaf(i) => ((first_leaf + i) << OP_BITS) | OP_LEAF,
        CsgOp::Max => OP_MAX,
        CsgOp::Min => OP_MIN,
        CsgOp::Neg => OP_NEG,
    }
}

/// Rounds `b` to f32 outward, relative to `reference`, so the f32 box still holds the f64 one.
fn box_relative(b: &Aabb, reference: DVec3) -> ([f32; 4], [f32; 4]) {
    let lo = b.min - reference;
    let hi = b.max - reference;
    let down = |x: f64| {
        let f = x as f32;
        if f64::from(f) > x { f.next_down() } else { f }
    };
    let up = |x: f64| {
        let f = x as f32;
        if f64::from(f) < x { f.next_up() } else { f }
    };
    (
        [down(lo.x), down(lo.y), down(lo.z), 0.0],
        [up(hi.x), up(hi.y), up(hi.z), 0.0],
    )
}

impl GpuQuadric {
    /// `q` with its origin taken relative to `reference` (in f64, then rounded).
    pub fn new(q: &Quadric, reference: DVec3) -> Self {
        let c = q.coefficients.map(|c| c as f32);
        Self {
            origin: vec4(q.origin - reference, 0.0),
            c0: [c[0], c[1], c[2], c[3]],
            c1: [c[4], c[5], c[6], c[7]],
            c2: [c[8], c[9], 0.0, 0.0],
        }
    }
}

impl GpuSolids {
    /// An empty set of solids relative to `reference`.
    pub fn new(reference: DVec3) -> Self {
        Self {
            reference,
            ..Self::default()
        }
    }

    /// Appends `solid`; `tag(leaf)` fills each leaf's `info.w` (e.g. its material index).
    pub fn push(&mut self, solid: &Solid, tag: impl Fn(usize) -> u32) {
        let first_leaf = self.leaves.len() as u32;
        let first_word = self.program.len() as u32;
        let mut perturbations = 0u32;
        for (i, leaf) in solid.leaves().iter().enumerate() {
            let start = self.perturbations.len() as u32;
            for p in leaf.perturbations() {
                self.perturbations.push(GpuPerturbation {
                    quadric: GpuQuadric::new(&p.quadric, self.reference),
                    form_factor: p.form_factor as f32,
                    ..GpuPerturbation::default()
                });
            }
            let end = self.perturbations.len() as u32;
            perturbations += end - start;
            let (box_min, box_max) = box_relative(&leaf.bounds(), self.reference);
            self.leaves.push(GpuLeaf {
                base: GpuQuadric::new(leaf.base(), self.reference),
                box_min,
                box_max,
                clips: u32::from(leaf.clips()),
                first_perturbation: start,
                end_perturbation: end,
                material: tag(i),
            });
        }
        self.program.extend(
            solid
                .program()
                .iter()
                .map(|&op| program_word(op, first_leaf)),
        );
        let (box_min, box_max) = box_relative(&solid.bounds(), self.reference);
        self.solids.push(GpuSolid {
            box_min,
            box_max,
            first_leaf,
            leaf_count: solid.leaves().len() as u32,
            first_word,
            word_count: solid.program().len() as u32,
            ..GpuSolid::default()
        });
        self.max_leaves = self.max_leaves.max(solid.leaves().len() as u32);
        self.max_perturbations = self.max_perturbations.max(perturbations);
        self.max_stack = self.max_stack.max(solid.max_stack() as u32);
    }

    /// Appends the complement of solid `index` (already pushed) to the program array — its
    /// program followed by a negation, `Solid::complement`'s program — and records where.
    /// Call after every solid is pushed, so that a complement never starts at word 0.
    pub fn push_complement(&mut self, index: usize) {
        let Some(solid) = self.solids.get(index).copied() else {
            return;
        };
        let (first, count) = (solid.first_word as usize, solid.word_count as usize);
        let start = self.program.len() as u32;
        self.program.extend_from_within(first..first + count);
        self.program.push(OP_NEG);
        self.solids[index].complement_word = start;
    }
}

/// The WGSL source of the geometry structs and op-code constants, generated from Rust.
pub fn wgsl_declarations() -> String {
    let mut s = String::from("// Generated by fray_geometry::gpu_layout — do not edit.\n");
    for (name, value) in [
        ("OP_LEAF", OP_LEAF),
        ("OP_MAX", OP_MAX),
        ("OP_MIN", OP_MIN),
        ("OP_NEG", OP_NEG),
        ("OP_BITS", OP_BITS),
    ] {
        s.push_str(&format!("const {name}: u32 = {value}u;\n"));
    }
    for declaration in [
        GpuQuadric::declaration(),
        GpuPerturbation::declaration(),
        GpuLeaf::declaration(),
        GpuSolid::declaration(),
    ] {
        s.push_str(&declaration);
    }
    s
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::{FreeForm, Perturbation, Shape};

    #[test]
    fn wgsl_layouts_match_rust_layouts() {
        GpuQuadric::check_layout().unwrap();
        GpuPerturbation::check_layout().unwrap();
        GpuLeaf::check_layout().unwrap();
        GpuSolid::check_layout().unwrap();
        let text = wgsl_declarations();
        assert!(text.contains("struct GpuLeaf {") && text.contains("const OP_NEG: u32 = 3u;"));
        assert!(text.contains("    first_perturbation: u32,\n"));
    }

    /// A complement is the solid's program negated, after every solid's own program, at the
    /// word its solid records (0 for solids without one).
    #[test]
    fn complements_follow_the_programs_negated() {
        let sphere = |c: DVec3| {
            Solid::new(Shape::FreeForm(
                FreeForm::new(Quadric::sphere(c, 1.0), vec![], None).unwrap(),
            ))
            .unwrap()
        };
        let mut g = GpuSolids::new(DVec3::ZERO);
        g.push(&sphere(DVec3::ZERO), |_| 0);
        g.push(&sphere(DVec3::X * 3.0), |_| 0);
        let own = g.program.clone();
        g.push_complement(1);
        let s = g.solids[1];
        assert_eq!(g.solids[0].complement_word, 0);
        assert_eq!(s.complement_word as usize, own.len());
        let (first, count) = (s.first_word as usize, s.word_count as usize);
        assert_eq!(&g.program[..own.len()], &own[..]);
        assert_eq!(
            &g.program[own.len()..own.len() + count],
            &own[first..first + count]
        );
        assert_eq!(g.program[own.len() + count], OP_NEG);
        assert_eq!(g.program.len(), own.len() + count + 1);
        g.push_complement(7);
        assert_eq!(
            g.program.len(),
            own.len() + count + 1,
            "no such solid: nothing"
        );
    }

    #[test]
    fn solids_flatten_relative_to_the_reference() {
        let far = DVec3::new(1e6, -2e6, 3e6);
        let a = FreeForm::new(
            Quadric::sphere(far, 1.0),
            vec![Perturbation::new(0.5, Quadric::sphere(far + DVec3::X, 0.5))],
            None,
        )
        .unwrap();
        let b = FreeForm::new(Quadric::sphere(far + DVec3::Y, 1.0), vec![], None).unwrap();
        let solid = Solid::new(Shape::Difference(
            Box::new(Shape::FreeForm(a)),
            Box::new(Shape::FreeForm(b)),
        ))
        .unwrap();
        let mut g = GpuSolids::new(far - DVec3::Z * 5.0);
        g.push(&solid, |i| 10 + i as u32);
        assert_eq!(g.solids.len(), 1);
        assert_eq!(g.leaves.len(), 2);
        assert_eq!(g.perturbations.len(), 1);
        assert_eq!(g.leaves[0].base.origin, [0.0, 0.0, 5.0, 0.0]);
        assert_eq!(g.leaves[1].base.origin, [0.0, 1.0, 5.0, 0.0]);
        let l = g.leaves[1];
        assert_eq!(
            (
                l.clips,
                l.first_perturbation,
                l.end_perturbation,
                l.material
            ),
            (0, 1, 1, 11)
        );
        assert_eq!(
            g.program,
            vec![OP_LEAF, (1 << OP_BITS) | OP_LEAF, OP_NEG, OP_MIN]
        );
        let so = g.solids[0];
        assert_eq!(
            (so.first_leaf, so.leaf_count, so.first_word, so.word_count),
            (0, 2, 0, 4)
        );
        assert_eq!((g.max_leaves, g.max_perturbations, g.max_stack), (2, 1, 2));
        // The f32 box holds the f64 one.
        let b = solid.bounds();
        assert!(f64::from(g.solids[0].box_min[0]) <= b.min.x - g.reference.x);
        assert!(f64::from(g.solids[0].box_max[2]) >= b.max.z - g.reference.z);
    }
}
