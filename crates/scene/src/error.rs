//! Scene file errors: each names the file, and where one applies the line, column and field.

use std::path::PathBuf;

/// Why a scene file cannot be loaded. Displays as `file:line:column: field: message`.
#[derive(Debug, thiserror::Error)]
pub enum SceneError {
    /// The file is missing or unreadable.
    #[error("{}: cannot read the scene file: {source}", path.display())]
    Io {
        path: PathBuf,
        source: std::io::Error,
    },
    /// The text is not well-formed RON.
    #[error("{file}:{line}:{column}: syntax error: {message}")]
    Syntax {
        file: String,
        line: usize,
        column: usize,
        message: String,
    },
    /// The text is RON but not a valid scene: an unknown or missing field, a wrong type, a value
    /// out of range, an unknown material, an unbounded object, a degenerate camera…
    #[error("{file}:{line}:{column}: {field}: {message}")]
    Invalid {
        file: String,
        line: usize,
        column: usize,
        /// The path of the offending field, like `objects[1].shape.perturbations[0].quadric.radius`.
        field: String,
        message: String,
    },
    /// A time of the scene's animation at which it cannot be built (e.g. the camera's look-at
    /// point meets its eye between two keys).
    #[error("{what} at time {time} s: {message}")]
    Animation {
        time: f64,
        what: String,
        message: String,
    },
    /// `--camera NAME` names no camera of the scene.
    #[error("no camera named {name:?}: {known}")]
    NoSuchCamera { name: String, known: String },
}

impl SceneError {
    /// The 1-based line the error points at (`None` for I/O errors).
    pub fn line(&self) -> Option<usize> {
        match self {
            SceneError::Io { .. }
            | SceneError::Animation { .. }
            | SceneError::NoSuchCamera { .. } => None,
            SceneError::Syntax { line, .. } | SceneError::Invalid { line, .. } => Some(*line),
        }
    }

    /// The 1-based column (in characters) the error points at (`None` for I/O errors).
    pub fn column(&self) -> Option<usize> {
        match self {
            SceneError::Io { .. }
            | SceneError::Animation { .. }
            | SceneError::NoSuchCamera { .. } => None,
            SceneError::Syntax { column, .. } | SceneError::Invalid { column, .. } => Some(*column),
        }
    }

    /// The path of the offending field, for [`SceneError::Invalid`].
    pub fn field(&self) -> Option<&str> {
        match self {
            SceneError::Invalid { field, .. } => Some(field),
            _ => None,
        }
    }
}
