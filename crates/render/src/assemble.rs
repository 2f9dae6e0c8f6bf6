//! Tiles back into an image: PNG bands rendered apart (`RenderOptions::tile`) stacked in order.

use crate::output::OutputError;
use std::path::{Path, PathBuf};

/// Why tiles could not be assembled.
#[derive(Debug, thiserror::Error)]
pub enum AssembleError {
    #[error(transparent)]
    Read(#[from] OutputError),
    #[error(
        "{}: {what} {got}, but the first tile ({}) has {want}: tiles of one image share their \
         width and pixel format",
        path.display(),
        first.display()
    )]
    Mismatch {
        path: PathBuf,
        first: PathBuf,
        what: &'static str,
        got: String,
        want: String,
    },
    #[error("{} rows in all: more than an image side may have (16384)", rows)]
    TooTall { rows: u64 },
    #[error("cannot write PNG {}: {source}", path.display())]
    Write {
        path: PathBuf,
        #[source]
        source: image::ImageError,
    },
}

/// Reads the PNG tiles `tiles` (tile 0 first), checks they share a width and a pixel format
/// (8- or 16-bit RGB, as `fray render` writes them) and writes them one under the other to
/// `output`: the bytes of each row as its tile holds them, so the whole image is the tiles'
/// pixels exactly.
pub fn assemble_png_tiles(tiles: &[PathBuf], output: &Path) -> Result<(), AssembleError> {
    let mut first: Option<(PathBuf, u32, image::ColorType)> = None;
    let mut bytes: Vec<u8> = Vec::new();
    let mut rows = 0u64;
    for path in tiles {
        let image = read(path)?;
        let (width, height, colour) = (image.width(), image.height(), image.color());
        match &first {
            None => first = Some((path.clone(), width, colour)),
            Some((first, w, c)) => {
                let mismatch = |what, got: String, want: String| AssembleError::Mismatch {
                    path: path.clone(),
                    first: first.clone(),
                    what,
                    got,
                    want,
                };
                if width != *w {
                    return Err(mismatch("width", width.to_string(), w.to_string()));
                }
                if colour != *c {
                    return Err(mismatch(
                        "pixel format",
                        format!("{colour:?}"),
                        format!("{c:?}"),
                    ));
                }
            }
        }
        rows += u64::from(height);
        if rows > 16384 {
            return Err(AssembleError::TooTall { rows });
        }
        bytes.extend_from_slice(image.as_bytes());
    }
    let Some((_, width, colour)) = first else {
        return Ok(());
    };
    image::save_buffer_with_format(
        output,
        &bytes,
        width,
        rows as u32,
        image::ExtendedColorType::from(colour),
        image::ImageFormat::Png,
    )
    .map_err(|source| AssembleError::Write {
        path: output.to_path_buf(),
        source,
    })
}

fn read(path: &Path) -> Result<image::DynamicImage, OutputError> {
    let wrap = |source| OutputError::ReadPng {
        path: path.to_path_buf(),
        source,
    };
    image::ImageReader::open(path)
        .map_err(|e| wrap(image::ImageError::IoError(e)))?
        .with_guessed_format()
        .map_err(|e| wrap(image::ImageError::IoError(e)))?
        .decode()
        .map_err(wrap)
}
