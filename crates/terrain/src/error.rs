//! Terrain errors: a bad height-map file names its path and the reason; bad parameters name the
//! parameter; an allocation over the memory budget names what, how much, the limit and the path.

use fray_core::BudgetError;
use std::path::PathBuf;

/// Why a height map or a terrain cannot be built.
#[derive(Debug, thiserror::Error)]
pub enum TerrainError {
    /// The file is missing or unreadable.
    #[error("{}: cannot read the height map: {source}", path.display())]
    Io {
        path: PathBuf,
        source: std::io::Error,
    },
    /// The file was read but its contents are not a usable height map (wrong format, wrong
    /// channel count or sample type, truncated data, a malformed header…).
    #[error("{}: {reason}", path.display())]
    Format { path: PathBuf, reason: String },
    /// The file name has no extension fray reads (`.png`, `.exr`, `.npy`).
    #[error("{}: unsupported height-map format (expected .png, .exr or .npy)", path.display())]
    UnsupportedExtension { path: PathBuf },
    /// Fewer than 2 × 2 samples: there is no cell to interpolate.
    #[error("height map of {width} × {height} samples: at least 2 × 2 are needed")]
    TooSmall { width: usize, height: usize },
    /// More samples than [`crate::MAX_SIDE`] per side or [`crate::MAX_SAMPLES`] in all.
    #[error(
        "height map of {width} × {height} samples is too large (at most {} per side and {} in all)",
        crate::MAX_SIDE,
        crate::MAX_SAMPLES
    )]
    TooLarge { width: usize, height: usize },
    /// The sample array does not hold `width × height` values.
    #[error("expected {expected} samples ({width} × {height}), got {got}")]
    WrongLength {
        width: usize,
        height: usize,
        expected: usize,
        got: usize,
    },
    /// A sample is NaN or infinite (use the threshold to cut parts out).
    #[error("sample ({column}, {row}) is not finite: {value}")]
    NonFinite {
        column: usize,
        row: usize,
        value: f64,
    },
    /// No cell has all four corners at or above the threshold: nothing would be drawn.
    #[error("no cell has all four samples at or above the threshold {threshold}")]
    NoSurface { threshold: f64 },
    /// A placement or option value is out of range.
    #[error("{name}: {message}")]
    Parameter { name: &'static str, message: String },
    /// An allocation that grows with the input (the file's bytes, the decoded image, the `f32`
    /// samples, the pyramids) would exceed the memory budget; estimated before it is made.
    /// `path` is the height map's file, when it came from one.
    #[error("{}{source}", path.as_ref().map(|p| format!("{}: ", p.display())).unwrap_or_default())]
    Budget {
        path: Option<PathBuf>,
        source: BudgetError,
    },
    /// A fixed-step march would take more than [`crate::MAX_MARCH_STEPS`] steps.
    #[error(
        "a march of {length} in steps of {step} takes {steps:.3e} steps, over the cap of {}",
        crate::MAX_MARCH_STEPS
    )]
    MarchSteps { length: f64, step: f64, steps: f64 },
    /// Reading the file failed with a path attached (wraps the other variants).
    #[error("{}: {source}", path.display())]
    File {
        path: PathBuf,
        source: Box<TerrainError>,
    },
}
