//! The errors of textures: an unreadable or unusable image file names its path and the reason
//! (missing, not an image, zero size, too large, over the memory budget); texels or parameters
//! built in memory name what is wrong.

use fray_core::BudgetError;
use std::path::PathBuf;

/// Why a texture, a mapping or a ramp cannot be made.
#[derive(Debug, thiserror::Error)]
pub enum TextureError {
    /// The file is missing or unreadable.
    #[error("{}: cannot read the texture: {reason}", path.display())]
    Io {
        /// The file.
        path: PathBuf,
        /// What the system said.
        reason: String,
    },
    /// The file was read but is not an image fray can use (not a PNG / OpenEXR file, a
    /// truncated one, no colour channel, a non-finite texel…).
    #[error("{}: {reason}", path.display())]
    Format {
        /// The file.
        path: PathBuf,
        /// What is wrong with it.
        reason: String,
    },
    /// The file name has no extension fray reads as a texture.
    #[error("{}: unsupported texture format (expected .png or .exr)", path.display())]
    UnsupportedExtension {
        /// The file.
        path: PathBuf,
    },
    /// A width or a height of zero, or past [`crate::texture::MAX_SIDE`].
    #[error(
        "{}a texture of {width} × {height} texels: each side must be 1 to {}",
        path.as_ref().map(|p| format!("{}: ", p.display())).unwrap_or_default(),
        crate::texture::MAX_SIDE
    )]
    Size {
        /// The file, when the texture came from one.
        path: Option<PathBuf>,
        /// The width asked for, in texels.
        width: u64,
        /// The height asked for, in texels.
        height: u64,
    },
    /// The texels given in memory are not `width × height × channels` finite values.
    #[error("{0}")]
    Texels(String),
    /// The mip chain (with what a load holds at its peak) would exceed the memory budget;
    /// estimated from the header, before anything is decoded.
    #[error("{}{source}", path.as_ref().map(|p| format!("{}: ", p.display())).unwrap_or_default())]
    Budget {
        /// The file, when the texture came from one.
        path: Option<PathBuf>,
        /// What, how much and the limit.
        source: BudgetError,
    },
    /// A mapping's or a ramp's parameter is out of range (not finite, zero, parallel axes,
    /// unsorted stops…).
    #[error("{name}: {message}")]
    Parameter {
        /// The parameter, as a scene file would name it (`u_axis`, `scale.y`, `ramp`…).
        name: &'static str,
        /// What is wrong with its value.
        message: String,
    },
}
