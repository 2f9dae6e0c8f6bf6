//! Errors raised when building geometry from user input.

/// Why a shape cannot be built.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum GeometryError {
    #[error(
        "the object is unbounded: its base quadric or a perturbation with a positive form factor is not an ellipsoid, so give it `bounds`"
    )]
    Unbounded,
    #[error("`{field}` must be finite")]
    NotFinite { field: &'static str },
    #[error("`bounds` must be a finite, non-empty box (min ≤ max on every axis)")]
    InvalidBounds,
    #[error(
        "a clipping box cannot be {how}: only a move that keeps boxes axis-aligned (a translation, or \
         a scale) keeps the object's shape"
    )]
    ClipNotMovable { how: &'static str },
    #[error("the transform is singular or not finite")]
    SingularTransform,
    #[error("a {op} needs at least {min} operands, got {got}")]
    TooFewOperands {
        op: &'static str,
        min: usize,
        got: usize,
    },
}
