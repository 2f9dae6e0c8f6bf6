//! Why the scheduler refused a request.

/// Invalid scheduler input.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
pub enum QuadtreeError {
    #[error("quadtree cell size must be at least 1 pixel")]
    ZeroCellSize,
    #[error("image size must be at least 1 × 1, got {0} × {1}")]
    EmptyImage(u32, u32),
    #[error(transparent)]
    Budget(#[from] fray_core::BudgetError),
}
