//! Loading height maps from files: 16-bit (or 8-bit) greyscale PNG, OpenEXR (one `f32`/`f16`
//! channel, or the `R` / `Y` / `Z` channel of several) and NumPy `.npy` (see [`crate::npy`]
//! for the accepted subset). Sizes are checked from the header before the samples are decoded,
//! so an absurd file is refused without allocating for it: first against the format limits
//! ([`crate::MAX_SIDE`], [`crate::MAX_SAMPLES`]), then against a [`MemoryBudget`] — the file's
//! bytes, the decoded image and the `f32` samples, which are alive together while a map loads.

use crate::heightmap::check_size;
use crate::{Heightmap, TerrainError, npy};
use exr::prelude as x;
use fray_core::MemoryBudget;
use fray_core::input::{InputError, checked_file_size, read_file};
use image::ImageDecoder;
use std::path::Path;

impl Heightmap {
    /// Loads the height map at `path`, by its extension (`.png`, `.exr`, `.npy`,
    /// case-insensitive), within the default memory budget ([`MemoryBudget::default`]: 4 GiB or
    /// `FRAY_MEMORY_BUDGET`). PNG values are the 8/16-bit integers (e.g. metres); EXR and `.npy`
    /// values are taken as they are. Errors name the path and the reason.
    pub fn load(path: &Path) -> Result<Self, TerrainError> {
        Self::load_within(path, &MemoryBudget::default())
    }

    /// [`Heightmap::load`] within `budget`: the memory a load holds at its peak — the file's
    /// bytes (PNG, `.npy`), the decoded image (PNG, every channel of an EXR layer) and the `f32`
    /// samples — is estimated from the header and refused over the budget
    /// ([`TerrainError::Budget`], naming the path) before it is allocated.
    pub fn load_within(path: &Path, budget: &MemoryBudget) -> Result<Self, TerrainError> {
        let ext = path
            .extension()
            .and_then(|e| e.to_str())
            .map(str::to_ascii_lowercase);
        let format = |reason: String| TerrainError::Format {
            path: path.to_owned(),
            reason,
        };
        let with_path = |e: TerrainError| match e {
            e @ (TerrainError::Io { .. }
            | TerrainError::Format { .. }
            | TerrainError::Budget { .. }) => e,
            other => TerrainError::File {
                path: path.to_owned(),
                source: Box::new(other),
            },
        };
        let over_budget = |source| TerrainError::Budget {
            path: Some(path.to_owned()),
            source,
        };
        let over = |what: String, bytes: u64| budget.check(what, bytes).map_err(over_budget);
        // The samples live as long as the terrain: charged to the render's account.
        let charge_samples = |w: usize, h: usize| {
            budget
                .charge(
                    "height maps' f32 samples",
                    (w as u64).saturating_mul(h as u64).saturating_mul(4),
                )
                .map_err(over_budget)
        };
        // Only a regular file, no larger than what is left of the budget.
        let input = |e: InputError| match e {
            InputError::Budget(source) => over_budget(source),
            InputError::Io(source) => TerrainError::Io {
                path: path.to_owned(),
                source,
            },
            other => TerrainError::Io {
                path: path.to_owned(),
                source: std::io::Error::other(other.to_string()),
            },
        };
        // The file's bytes, read whole (PNG, .npy).
        let read = || read_file(path, budget).map_err(input);
        let check = |w: usize, h: usize| check_size(w, h).map_err(|e| e.to_string());
        let samples_bytes = |w: usize, h: usize| (w as u64).saturating_mul(h as u64) * 4;
        let (width, height, samples) = match ext.as_deref() {
            Some("png") => {
                let bytes = read()?;
                let decoder = fray_core::contain_panic("the PNG decoder", || {
                    image::codecs::png::PngDecoder::new(std::io::Cursor::new(&bytes))
                })
                .map_err(format)?
                .map_err(|e| format(format!("not a readable PNG: {e}")))?;
                let (w, h) = decoder.dimensions();
                let (w, h) = (w as usize, h as usize);
                check(w, h).map_err(format)?;
                let peak = (bytes.len() as u64)
                    .saturating_add(decoder.total_bytes())
                    .saturating_add(samples_bytes(w, h));
                over(
                    format!(
                        "decoding the {w} × {h} PNG height map (the file, the decoded image and \
                         the f32 samples together)"
                    ),
                    peak,
                )?;
                charge_samples(w, h)?;
                let image = fray_core::contain_panic("the PNG decoder", || {
                    image::DynamicImage::from_decoder(decoder)
                })
                .map_err(format)?
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
                // exr opens the file itself: report a missing file, a device or a FIFO, or one
                // larger than the budget left, before it does.
                checked_file_size(path, budget).map_err(input)?;
                let meta = exr::meta::MetaData::read_from_file(path, false)
                    .map_err(|e| format(format!("not a readable OpenEXR file: {e}")))?;
                let header = meta
                    .headers
                    .first()
                    .ok_or_else(|| format("the OpenEXR file has no layer".into()))?;
                let (w, h) = (header.layer_size.x(), header.layer_size.y());
                check(w, h).map_err(format)?;
                // The first layer is decoded whole, every channel, before one is taken.
                let decoded = (w as u64)
                    .saturating_mul(h as u64)
                    .saturating_mul(header.channels.bytes_per_pixel as u64);
                over(
                    format!(
                        "decoding the {w} × {h} OpenEXR height map ({} channels, then the f32 \
                         samples)",
                        header.channels.list.len()
                    ),
                    decoded.saturating_add(samples_bytes(w, h)),
                )?;
                charge_samples(w, h)?;
                let image = read_exr(path).map_err(format)?;
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
                let header = npy::parse_header(&bytes).map_err(format)?;
                let (w, h) = (header.columns, header.rows);
                check(w, h).map_err(format)?;
                over(
                    format!(
                        "decoding the {w} × {h} .npy height map (the file and the f32 samples \
                         together)"
                    ),
                    (bytes.len() as u64).saturating_add(samples_bytes(w, h)),
                )?;
                charge_samples(w, h)?;
                let a = npy::decode(&bytes, &header).map_err(format)?;
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

/// The first layer of the OpenEXR file at `path`, every channel, decoded on this thread (a panic
/// of the decoder on a malformed block — on a worker thread it would abort the process — is
/// caught and named).
fn read_exr(path: &Path) -> Result<x::Image<x::Layer<x::AnyChannels<x::FlatSamples>>>, String> {
    use x::{ReadChannels, ReadLayers};
    let read = x::read()
        .no_deep_data()
        .largest_resolution_level()
        .all_channels()
        .first_valid_layer()
        .all_attributes()
        .non_parallel();
    fray_core::contain_panic("the OpenEXR decoder", || read.from_file(path))?
        .map_err(|e| format!("cannot decode the OpenEXR file: {e}"))
}
