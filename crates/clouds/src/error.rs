//! The errors of `fray-clouds`: a bad grid size, a grid past its budget, an unreadable volume, a
//! march or a bake past its cap.

use std::path::PathBuf;

/// What can go wrong when a density grid is made or loaded.
#[derive(Debug, thiserror::Error)]
pub enum CloudsError {
    /// A grid side is zero or its cell count overflows.
    #[error("a density grid needs every side ≥ 1, got {0} × {1} × {2}")]
    BadSize(u64, u64, u64),
    #[error(transparent)]
    Budget(#[from] fray_core::BudgetError),
    /// A view ray's march would take more density samples than [`crate::cost::MAX_RAY_SAMPLES`].
    #[error(
        "a march across the region's diagonal {} in steps of {} takes {} view steps, each with {sun_steps} sun steps: {} density samples per ray, over the cap of {limit}",
        crate::cost::length(*diagonal),
        crate::cost::length(*step),
        crate::cost::count(*view_steps),
        crate::cost::count(*samples)
    )]
    MarchSamples {
        diagonal: f64,
        step: f64,
        view_steps: f64,
        sun_steps: u32,
        samples: f64,
        limit: u64,
    },
    /// A bake would do more work than [`crate::cost::MAX_BAKE_WORK`].
    #[error(
        "baking {} × {} × {} cells at a cost of {per_cell} each is {} units of work, over the cap of {limit} (fewer cells or octaves)",
        size[0], size[1], size[2], crate::cost::count(*work)
    )]
    BakeWork {
        size: [u64; 3],
        per_cell: u64,
        work: f64,
        limit: u64,
    },
    /// A volume file is missing, unreadable or malformed.
    #[error("{}: {reason}", path.display())]
    Volume { path: PathBuf, reason: String },
}
