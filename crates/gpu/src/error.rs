//! Why the GPU backend could not render.

/// Errors of the GPU backend. A missing adapter or a lost device is something the facade can
/// answer by falling back to the CPU; the others are bugs or bad settings.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum GpuError {
    #[error("no GPU adapter found: {0}")]
    NoAdapter(String),
    #[error("could not open the GPU device: {0}")]
    Device(String),
    #[error("the GPU device was lost: {0}")]
    DeviceLost(String),
    #[error("building the {pass} pipeline failed: {reason}")]
    Pipeline { pass: &'static str, reason: String },
    #[error("the {pass} pass failed on the GPU: {reason}")]
    Dispatch { pass: &'static str, reason: String },
    #[error("building the work list failed: {0}")]
    WorkList(String),
    #[error("epsilon must be finite and > 0, got {0}")]
    BadEpsilon(f64),
    #[error(
        "rows {start}..{end} are not a band of the {height}-row image that starts and ends on \
         the {tile}-pixel tiles (or ends at the image's foot)"
    )]
    BadRows {
        start: u32,
        end: u32,
        height: u32,
        tile: u32,
    },
    #[error("image size must be at least 1 × 1, got {0} × {1}")]
    EmptyImage(u32, u32),
    /// The scene uses a feature this backend does not draw yet (`Auto` renders it on the CPU).
    #[error("the GPU backend does not draw {feature} yet; render this scene with the CPU backend")]
    Unsupported { feature: &'static str },
    #[error(transparent)]
    Budget(fray_core::BudgetError),
    /// Meshes that cannot be laid out for the GPU (an instance naming no mesh, a transform that
    /// is not invertible, coordinates past f32).
    #[error("the meshes cannot be uploaded to the GPU: {0}")]
    Mesh(String),
    /// The scene needs more of something than the GPU backend (or this device) allows.
    #[error(
        "too large for the GPU: {what} — the scene needs {}, the GPU backend allows at most {} \
         here; the CPU backend has no such limit (`--backend auto` falls back to it, \
         `--backend cpu` uses it)",
        grouped(*.needed),
        grouped(*.limit)
    )]
    TooLarge {
        what: &'static str,
        needed: u64,
        limit: u64,
    },
}

impl GpuError {
    /// Whether the GPU itself is missing or gone (the facade may fall back to the CPU).
    pub fn is_unavailable(&self) -> bool {
        matches!(
            self,
            GpuError::NoAdapter(_) | GpuError::Device(_) | GpuError::DeviceLost(_)
        )
    }
}

/// `n` with its digits in groups of three, e.g. `201 523 200`.
fn grouped(n: u64) -> String {
    let digits = n.to_string();
    let mut out = String::with_capacity(digits.len() + digits.len() / 3);
    for (i, c) in digits.chars().enumerate() {
        if i > 0 && (digits.len() - i).is_multiple_of(3) {
            out.push(' ');
        }
        out.push(c);
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn too_large_reads_in_plain_words() {
        assert_eq!(grouped(0), "0");
        assert_eq!(grouped(999), "999");
        assert_eq!(grouped(1000), "1 000");
        assert_eq!(grouped(201_523_200), "201 523 200");
        let e = GpuError::TooLarge {
            what: "the rays in flight for one row of tiles, in bytes",
            needed: 201_523_200,
            limit: 134_217_728,
        };
        assert_eq!(
            e.to_string(),
            "too large for the GPU: the rays in flight for one row of tiles, in bytes — the scene \
             needs 201 523 200, the GPU backend allows at most 134 217 728 here; the CPU backend \
             has no such limit (`--backend auto` falls back to it, `--backend cpu` uses it)"
        );
    }
}
