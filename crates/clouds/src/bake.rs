//! Baking a cloud field into a density grid over a box: each sample the field's density at its
//! cell centre (so the grid's trilinear samples reproduce the field at the centres exactly), slice
//! by slice with a progress report, checked against its work cap and the memory budget first.

use crate::shape::{CloudField, Envelope};
use crate::{CloudsError, DensityGrid};
use fray_core::MemoryBudget;

/// The world box `[min, max]` a grid covers.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Region {
    pub min: [f64; 3],
    pub max: [f64; 3],
}

impl Region {
    /// The world position of the centre of cell `(i, j, k)` of a grid of `size`.
    pub fn cell_centre(&self, size: [usize; 3], ijk: [usize; 3]) -> [f64; 3] {
        std::array::from_fn(|a| {
            self.min[a] + (self.max[a] - self.min[a]) * (ijk[a] as f64 + 0.5) / size[a] as f64
        })
    }
}

/// Bakes `field` inside `envelope` over `region` into a grid of `size`, z slices in parallel;
/// `progress(done, total)` after each slice (from the thread that finished it). Refused before
/// anything is allocated past [`crate::cost::MAX_BAKE_WORK`] (the field's and the envelope's
/// cost per cell times the cells) or the budget.
pub fn bake(
    field: &CloudField,
    envelope: &dyn Envelope,
    region: Region,
    size: [usize; 3],
    budget: &MemoryBudget,
    progress: impl Fn(usize, usize) + Sync,
) -> Result<DensityGrid, CloudsError> {
    crate::cost::check_bake(field, envelope.cost(), size)?;
    DensityGrid::from_fn_parallel(
        size,
        budget,
        |i, j, k| field.density(region.cell_centre(size, [i, j, k]), envelope) as f32,
        |done| progress(done, size[2]),
    )
}
