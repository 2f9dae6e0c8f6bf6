//! The flat, GPU-uploadable work list: work items (tiles), their candidates, and index arrays.
//!
//! Everything is plain `#[repr(C)]` u32/f32 (`bytemuck::Pod`), so the arrays upload as they are;
//! the structs are declared with `fray_core::gpu_struct!`, which generates their WGSL twins.
//! The scheduler does not know what a candidate *is*: it is a caller-given `(kind, object)` id
//! with two caller-given index lists, called `leaves` and `perturbations` after their use in fray
//! (the leaves of a CSG solid that may matter in the tile and the perturbations that may matter
//! there; fray's kinds are its primitive kinds — free form, terrain — and `object` the index
//! within the kind).

fray_core::gpu_struct! {
    /// A tile of the image `[x0, x1) × [y0, y1)` and its candidates
    /// `candidates[start..start+count]`.
    pub struct WorkItem {
        pub x0: u32,
        pub y0: u32,
        pub x1: u32,
        pub y1: u32,
        pub candidate_start: u32,
        pub candidate_count: u32,
        /// A conservative range of ray parameters where the candidates can be (hull over them).
        pub t_min: f32,
        pub t_max: f32,
    }
}

fray_core::gpu_struct! {
    /// One object that may be hit in a tile, with the index ranges of its active leaves and
    /// perturbations in [`WorkList::leaves`] and [`WorkList::perturbations`].
    pub struct Candidate {
        /// The caller's kind of object (fray: its primitive kind).
        pub kind: u32,
        /// The object's index (fray: within its kind).
        pub object: u32,
        pub leaf_start: u32,
        pub leaf_count: u32,
        pub perturbation_start: u32,
        pub perturbation_count: u32,
        /// Conservative range of ray parameters where this object can be, for the tile's rays.
        pub t_min: f32,
        pub t_max: f32,
    }
}

impl Candidate {
    /// A candidate for `object` of `kind` with no leaves or perturbations yet, whose lists will
    /// start at `leaf_start` and `perturbation_start` in their index arrays, and whose rays can
    /// meet it for `t ∈ [t_min, t_max]` (rounded outward to f32).
    pub fn new(
        kind: u32,
        object: u32,
        leaf_start: u32,
        perturbation_start: u32,
        t_min: f64,
        t_max: f64,
    ) -> Self {
        Self {
            kind,
            object,
            leaf_start,
            leaf_count: 0,
            perturbation_start,
            perturbation_count: 0,
            t_min: round_down(t_min),
            t_max: round_up(t_max),
        }
    }

    pub fn leaves<'a>(&self, leaves: &'a [u32]) -> &'a [u32] {
        let s = self.leaf_start as usize;
        leaves.get(s..s + self.leaf_count as usize).unwrap_or(&[])
    }

    pub fn perturbations<'a>(&self, perturbations: &'a [u32]) -> &'a [u32] {
        let s = self.perturbation_start as usize;
        perturbations
            .get(s..s + self.perturbation_count as usize)
            .unwrap_or(&[])
    }
}

/// The candidates of one cell, in the same flat layout (what the cell test reads and writes).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Candidates {
    pub candidates: Vec<Candidate>,
    pub leaves: Vec<u32>,
    pub perturbations: Vec<u32>,
}

impl Candidates {
    pub fn new() -> Self {
        Self::default()
    }

    pub fn clear(&mut self) {
        self.candidates.clear();
        self.leaves.clear();
        self.perturbations.clear();
    }

    pub fn is_empty(&self) -> bool {
        self.candidates.is_empty()
    }

    pub fn len(&self) -> usize {
        self.candidates.len()
    }

    /// Starts a candidate for `object` of `kind` whose rays can meet it for `t ∈ [t_min, t_max]`;
    /// the following [`Candidates::push_leaf`] / [`Candidates::push_perturbation`] calls fill it.
    pub fn begin(&mut self, kind: u32, object: u32, t_min: f64, t_max: f64) {
        let (leaf_start, perturbation_start) = (self.leaves.len(), self.perturbations.len());
        self.candidates.push(Candidate::new(
            kind,
            object,
            leaf_start as u32,
            perturbation_start as u32,
            t_min,
            t_max,
        ));
    }

    pub fn push_leaf(&mut self, leaf: u32) {
        self.leaves.push(leaf);
        if let Some(c) = self.candidates.last_mut() {
            c.leaf_count += 1;
        }
    }

    pub fn push_perturbation(&mut self, perturbation: u32) {
        self.perturbations.push(perturbation);
        if let Some(c) = self.candidates.last_mut() {
            c.perturbation_count += 1;
        }
    }

    /// Drops the candidate begun last (the test found it cannot be hit after all).
    pub fn cancel(&mut self) {
        if let Some(c) = self.candidates.pop() {
            self.leaves.truncate(c.leaf_start as usize);
            self.perturbations.truncate(c.perturbation_start as usize);
        }
    }
}

/// An f32 not above `x` (`−∞` stays, NaN becomes 0).
fn round_down(x: f64) -> f32 {
    if x.is_nan() {
        return 0.0;
    }
    let f = x as f32;
    if f64::from(f) > x { f.next_down() } else { f }
}

/// An f32 not below `x` (NaN becomes +∞).
fn round_up(x: f64) -> f32 {
    if x.is_nan() {
        return f32::INFINITY;
    }
    let f = x as f32;
    if f64::from(f) < x { f.next_up() } else { f }
}

/// What the scheduler did.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct QuadtreeStats {
    /// Cells whose bundle was tested.
    pub cells_visited: u64,
    /// Cells dropped because no candidate survived.
    pub cells_culled: u64,
    /// Work items produced (leaf cells with candidates).
    pub items: u64,
}

/// The scheduler's output: tiles with candidates, in a flat form ready to upload.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct WorkList {
    pub items: Vec<WorkItem>,
    pub candidates: Vec<Candidate>,
    pub leaves: Vec<u32>,
    pub perturbations: Vec<u32>,
    pub stats: QuadtreeStats,
}

impl WorkList {
    /// The candidates of `item`.
    pub fn candidates_of(&self, item: &WorkItem) -> &[Candidate] {
        let s = item.candidate_start as usize;
        self.candidates
            .get(s..s + item.candidate_count as usize)
            .unwrap_or(&[])
    }

    /// Appends a tile with the cell's candidates (index ranges rebased into this list).
    /// Appends `other`'s items after this list's, rebasing its candidate, leaf and perturbation
    /// indices, and adds its stats: the list one sequential build over both parts would make.
    pub(crate) fn append(&mut self, other: WorkList) {
        let (candidate_base, leaf_base, pert_base) = (
            self.candidates.len() as u32,
            self.leaves.len() as u32,
            self.perturbations.len() as u32,
        );
        self.items.extend(other.items.iter().map(|it| WorkItem {
            candidate_start: it.candidate_start + candidate_base,
            ..*it
        }));
        self.candidates
            .extend(other.candidates.iter().map(|c| Candidate {
                leaf_start: c.leaf_start + leaf_base,
                perturbation_start: c.perturbation_start + pert_base,
                ..*c
            }));
        self.leaves.extend_from_slice(&other.leaves);
        self.perturbations.extend_from_slice(&other.perturbations);
        self.stats.cells_visited += other.stats.cells_visited;
        self.stats.cells_culled += other.stats.cells_culled;
        self.stats.items += other.stats.items;
    }

    pub(crate) fn push(&mut self, (x0, y0, x1, y1): (u32, u32, u32, u32), cell: &Candidates) {
        let (leaf_base, pert_base) = (self.leaves.len() as u32, self.perturbations.len() as u32);
        let mut t_min = f32::INFINITY;
        let mut t_max = f32::NEG_INFINITY;
        let candidate_start = self.candidates.len() as u32;
        for c in &cell.candidates {
            t_min = t_min.min(c.t_min);
            t_max = t_max.max(c.t_max);
            self.candidates.push(Candidate {
                leaf_start: c.leaf_start + leaf_base,
                perturbation_start: c.perturbation_start + pert_base,
                ..*c
            });
        }
        self.leaves.extend_from_slice(&cell.leaves);
        self.perturbations.extend_from_slice(&cell.perturbations);
        self.items.push(WorkItem {
            x0,
            y0,
            x1,
            y1,
            candidate_start,
            candidate_count: cell.candidates.len() as u32,
            t_min,
            t_max,
        });
        self.stats.items += 1;
    }
}
