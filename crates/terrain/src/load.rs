//! Loading height maps from files: 16-bit (or 8-bit) greyscale PNG, OpenEXR (one `f32`/`f16`
//! channel, or the `R` / `Y` / `Z` channel of several) and NumPy `.npy` (see [`crate::npy`]
//! for the accepted subset). Sizes are checked from the header before the samples are decoded,
//! so an absurd file is refused without allocating for it.

use crate::heightmap::check_size;
use crate::{Heightmap, TerrainError, npy};
use image::ImageDecoder;
use std::path::Path;

impl Heightmap {
    /// Loads the height map at `path`, by its extension (`.png`, `.exr`, `.npy`,
    /// case-insensitive). PNG values are the 8/16-bit integers (e.g. metres); EXR and `.npy`
    /// values are taken as they are. Errors name the path and the reason.
    pub fn load(path: &Path) -> Result<Self, TerrainError> {
        let ext = path
            .extension()
            .and_then(|e| e.to_str())
            .map(str::to_ascii_lowercase);
        let format = |reason: String| TerrainError::Format {
            path: path.to_owned(),
            reason,
        };
        let with_path = |e: TerrainError| match e {
            e @ (TerrainError::Io { .. } | TerrainError::Format { .. }) => e,
            other => TerrainError::File {
                path: path.to_owned(),
                source: Box::new(other),
            },
        };
        let read = || {
            std::fs::read(path).map_err(|source| TerrainError::Io {
                path: path.to_owned(),
                source,
            })
        };
        let check = |w: usize, h: usize| check_size(w, h).map_err(|e| e.to_string());
        let (width, height, samples) = match ext.as_deref() {
            Some("png") => {
                let bytes = read()?;
                let decoder = image::codecs::png::PngDecoder::new(std::io::Cursor::new(&bytes))
                    .map_err(|e| format(format!("not a readable PNG: {e}")))?;
                let (w, h) = decoder.dimensions();
                let (w, h) = (w as usize, h as usize);
                check(w, h).map_err(format)?;
                let image = image::DynamicImage::from_decoder(decoder)
                    .map_err(|e| format(format!("cannot decode the PNG: {e}")))?;
                let samples: Vec<f32> = match image {
                    image::DynamicImage::ImageLuma16(g) => {
                        g.into_raw().into_iter().map(f32::from).collect()
                    }
                    image::DynamicImage::ImageLuma8(g) => {
                        g.into_raw().into_iter().map(f32::from).collect()
                    }
                    other => {
                        return Err(format(format!(
                            "a greyscale PNG (8 or 16 bits, no alpha) is needed, this one is {:?}",
                            other.color()
                        )));
                    }
                };
                (w, h, samples)
            }
            Some("exr") => {
                // exr opens the file itself: report a missing file as an I/O error first.
                std::fs::metadata(path).map_err(|source| TerrainError::Io {
                    path: path.to_owned(),
                    source,
                })?;
                let meta = exr::meta::MetaData::read_from_file(path, false)
                    .map_err(|e| format(format!("not a readable OpenEXR file: {e}")))?;
                let header = meta
                    .headers
                    .first()
                    .ok_or_else(|| format("the OpenEXR file has no layer".into()))?;
                check(header.layer_size.x(), header.layer_size.y()).map_err(format)?;
                let image = exr::prelude::read_first_flat_layer_from_file(path)
                    .map_err(|e| format(format!("cannot decode the OpenEXR file: {e}")))?;
                let layer = image.layer_data;
                let (w, h) = (layer.size.x(), layer.size.y());
                check(w, h).map_err(format)?;
                let channels = &layer.channel_data.list;
                let channel = if channels.len() == 1 {
                    channels.first()
                } else {
                    ["R", "Y", "Z"]
                        .iter()
                        .find_map(|name| channels.iter().find(|c| c.name.to_string() == *name))
                };
                let channel = channel.ok_or_else(|| {
                    format(format!(
                        "the OpenEXR layer has {} channels and none named R, Y or Z",
                        channels.len()
                    ))
                })?;
                let samples: Vec<f32> = channel.sample_data.values_as_f32().collect();
                (w, h, samples)
            }
            Some("npy") => {
                let bytes = read()?;
                let a = npy::parse(&bytes, check).map_err(format)?;
                (a.columns, a.rows, a.values)
            }
            _ => {
                return Err(TerrainError::UnsupportedExtension {
                    path: path.to_owned(),
                });
            }
        };
        Heightmap::from_samples(width, height, samples).map_err(with_path)
    }
}
