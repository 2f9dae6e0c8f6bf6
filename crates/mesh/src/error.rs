//! The errors of `fray-mesh`: an unreadable or malformed OBJ file (path, line where one applies,
//! reason), one with more triangles than a mesh may have, a mesh whose indices or values are
//! bad, a mesh past its memory budget, a texture that cannot be loaded.

use std::path::PathBuf;

/// What can go wrong when a mesh is made or loaded.
#[derive(Debug, thiserror::Error)]
pub enum MeshError {
    /// The file is missing or unreadable.
    #[error("{}: cannot read the mesh: {reason}", path.display())]
    Io { path: PathBuf, reason: String },
    /// A line of an OBJ file is malformed.
    #[error("{}:{line}: {reason}", path.display())]
    Obj {
        path: PathBuf,
        line: usize,
        reason: String,
    },
    /// The file's faces make more triangles than a mesh may have ([`crate::MAX_TRIANGLES`]).
    #[error(
        "{}: its faces make {triangles} triangles, more than the {limit} a mesh may have",
        path.display()
    )]
    TooManyTriangles {
        path: PathBuf,
        triangles: u64,
        limit: u64,
    },
    /// The file parsed but holds no usable mesh (no triangles, or `tobj` refused it).
    #[error("{}: {reason}", path.display())]
    Invalid { path: PathBuf, reason: String },
    /// A mesh built in memory is inconsistent.
    #[error("{0}")]
    Mesh(String),
    #[error(transparent)]
    Budget(#[from] fray_core::BudgetError),
    /// A texture that cannot be loaded or made (its path and the reason).
    #[error(transparent)]
    Texture(#[from] crate::texture::TextureError),
}
