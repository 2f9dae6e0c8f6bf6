//! The errors of `fray-clouds`: a bad grid size, a grid past its budget, an unreadable volume.

use std::path::PathBuf;

/// What can go wrong when a density grid is made or loaded.
#[derive(Debug, thiserror::Error)]
pub enum CloudsError {
    /// A grid side is zero or its cell count overflows.
    #[error("a density grid needs every side ≥ 1, got {0} × {1} × {2}")]
    BadSize(u64, u64, u64),
    #[error(transparent)]
    Budget(#[from] fray_core::BudgetError),
    /// A volume file is missing, unreadable or malformed.
    #[error("{}: {reason}", path.display())]
    Volume { path: PathBuf, reason: String },
}
