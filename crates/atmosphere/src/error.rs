//! The errors of `fray-atmosphere`: a parameter out of its range, a table past its budget or
//! its work cap.

/// What can go wrong when an atmosphere is built.
#[derive(Debug, thiserror::Error, PartialEq)]
pub enum AtmosphereError {
    /// A parameter is outside its range (or not finite).
    #[error("{field}: {reason}, got {value}")]
    Invalid {
        field: &'static str,
        value: f64,
        reason: &'static str,
    },
    /// A table would take more march steps to fill than its cap.
    #[error("{field}: {what} takes {work} march steps, over the cap of {limit}")]
    Work {
        field: &'static str,
        what: String,
        work: u64,
        limit: u64,
    },
    /// A table would exceed the memory budget.
    #[error(transparent)]
    Budget(#[from] fray_core::BudgetError),
}

impl AtmosphereError {
    /// `field` must be finite and satisfy `ok`, else [`AtmosphereError::Invalid`] with `reason`.
    pub(crate) fn check(
        field: &'static str,
        value: f64,
        ok: bool,
        reason: &'static str,
    ) -> Result<(), Self> {
        if value.is_finite() && ok {
            Ok(())
        } else {
            Err(Self::Invalid {
                field,
                value,
                reason,
            })
        }
    }
}
