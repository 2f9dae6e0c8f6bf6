//! Loading textures: PNG (8 or 16 bits; grey, grey + alpha, RGB, RGBA; palettes expanded) and
//! OpenEXR (the first layer's `R G B [A]`, `Y [A]` or single channel, as `f32`). The size comes
//! from the header and is checked — against [`MAX_SIDE`](super::MAX_SIDE), then against a
//! [`MemoryBudget`] for everything a load holds at its peak (the file's bytes, the decoded
//! image, the whole mip chain) — before any texel is decoded. Errors name the path and the
//! reason.
//!
//! PNG colour channels are **sRGB-decoded** to linear by default (IEC 61966-2-1, in f64 before
//! rounding to `f32`; gamma and ICC chunks are not read); [`Encoding::Linear`] takes the
//! values as they are, scaled to `[0, 1]`, for data that is not colour — normal, roughness or
//! height maps. Alpha is always linear. OpenEXR holds linear values by definition: they are
//! taken as they are (any finite value, negative included), whatever the encoding asked.

use super::texels::check_size;
use super::{Channels, Texture, TextureError};
use exr::prelude as x;
use fray_core::MemoryBudget;
use fray_core::input::{InputError, checked_file_size, read_file};
use image::ImageDecoder;
use std::path::Path;

/// How a PNG's colour channels are read.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum Encoding {
    /// sRGB-encoded colour (photographs, albedo maps): decoded to linear.
    #[default]
    Srgb,
    /// Linear data (normal, roughness, height maps): `value / max` as it is.
    Linear,
}

/// The sRGB decoding of `c ∈ [0, 1]` to linear, in f64.
pub fn srgb_to_linear(c: f64) -> f64 {
    if c <= 0.040_45 {
        c / 12.92
    } else {
        ((c + 0.055) / 1.055).powf(2.4)
    }
}

impl Texture {
    /// Loads the PNG or OpenEXR file at `path` (by its extension, case-insensitive) with its
    /// mip chain, within `budget`; PNG colour decoded by `encoding`.
    pub fn load(
        path: &Path,
        encoding: Encoding,
        budget: &MemoryBudget,
    ) -> Result<Self, TextureError> {
        let ext = path
            .extension()
            .and_then(|e| e.to_str())
            .map(str::to_ascii_lowercase);
        match ext.as_deref() {
            Some("png") => load_png(path, encoding, budget),
            Some("exr") => load_exr(path, budget),
            _ => Err(TextureError::UnsupportedExtension {
                path: path.to_owned(),
            }),
        }
    }
}

fn format(path: &Path) -> impl Fn(String) -> TextureError + '_ {
    move |reason| TextureError::Format {
        path: path.to_owned(),
        reason,
    }
}

fn over(path: &Path, budget: &MemoryBudget, what: String, bytes: u64) -> Result<(), TextureError> {
    budget.check(what, bytes).map_err(budget_error(path))
}

fn budget_error(path: &Path) -> impl Fn(fray_core::BudgetError) -> TextureError + '_ {
    move |source| TextureError::Budget {
        path: Some(path.to_owned()),
        source,
    }
}

/// A file that could not be read (or is not a regular file, or is larger than what is left of
/// the budget), naming its path.
fn input(path: &Path) -> impl Fn(InputError) -> TextureError + '_ {
    move |e| match e {
        InputError::Budget(source) => budget_error(path)(source),
        other => TextureError::Io {
            path: path.to_owned(),
            reason: other.to_string(),
        },
    }
}

/// Charges the texture's mip chain to the render's account: it lives as long as the scene.
fn charge_chain(
    path: &Path,
    budget: &MemoryBudget,
    (w, h, channels): (u32, u32, Channels),
) -> Result<(), TextureError> {
    budget
        .charge(
            format!("textures' mip chains (the {w} × {h} {})", path.display()),
            Texture::chain_bytes(w, h, channels),
        )
        .map_err(budget_error(path))
}

fn load_png(
    path: &Path,
    encoding: Encoding,
    budget: &MemoryBudget,
) -> Result<Texture, TextureError> {
    let format = format(path);
    let bytes = read_file(path, budget).map_err(input(path))?;
    let decoder = fray_core::contain_panic("the PNG decoder", || {
        image::codecs::png::PngDecoder::new(std::io::Cursor::new(&bytes))
    })
    .map_err(&format)?
    .map_err(|e| format(format!("not a readable PNG: {e}")))?;
    let (w, h) = decoder.dimensions();
    check_size(Some(path), u64::from(w), u64::from(h))?;
    let channels = match decoder.color_type().channel_count() {
        1 => Channels::Grey,
        2 => Channels::GreyAlpha,
        3 => Channels::Rgb,
        _ => Channels::Rgba,
    };
    let peak = (bytes.len() as u64)
        .saturating_add(decoder.total_bytes())
        .saturating_add(Texture::chain_bytes(w, h, channels));
    over(
        path,
        budget,
        format!(
            "decoding the {w} × {h} PNG texture (the file, the decoded image and the f32 mip \
             chain together)"
        ),
        peak,
    )?;
    charge_chain(path, budget, (w, h, channels))?;
    let image = fray_core::contain_panic("the PNG decoder", || {
        image::DynamicImage::from_decoder(decoder)
    })
    .map_err(&format)?
    .map_err(|e| format(format!("cannot decode the PNG: {e}")))?;
    drop(bytes);
    let n = channels.count();
    let alpha = channels.has_alpha();
    // Channel k of a texel is colour unless it is the last one of an image with alpha.
    let is_colour = |i: usize| encoding == Encoding::Srgb && !(alpha && i % n == n - 1);
    let data: Vec<f32> = match image {
        image::DynamicImage::ImageLuma8(i) => decode8(i.into_raw(), is_colour),
        image::DynamicImage::ImageLumaA8(i) => decode8(i.into_raw(), is_colour),
        image::DynamicImage::ImageRgb8(i) => decode8(i.into_raw(), is_colour),
        image::DynamicImage::ImageRgba8(i) => decode8(i.into_raw(), is_colour),
        image::DynamicImage::ImageLuma16(i) => decode16(i.into_raw(), is_colour),
        image::DynamicImage::ImageLumaA16(i) => decode16(i.into_raw(), is_colour),
        image::DynamicImage::ImageRgb16(i) => decode16(i.into_raw(), is_colour),
        image::DynamicImage::ImageRgba16(i) => decode16(i.into_raw(), is_colour),
        other => {
            return Err(format(format!(
                "an 8- or 16-bit PNG is needed, this one decodes as {:?}",
                other.color()
            )));
        }
    };
    if data.len() != w as usize * h as usize * n {
        return Err(format(format!(
            "the PNG decoded to {} values, not {w} × {h} × {n}",
            data.len()
        )));
    }
    Ok(Texture::build(w, h, channels, data))
}

fn decode8(raw: Vec<u8>, is_colour: impl Fn(usize) -> bool) -> Vec<f32> {
    let table: Vec<f32> = (0..=255u8)
        .map(|v| srgb_to_linear(f64::from(v) / 255.0) as f32)
        .collect();
    raw.into_iter()
        .enumerate()
        .map(|(i, v)| {
            if is_colour(i) {
                table[usize::from(v)]
            } else {
                f32::from(v) / 255.0
            }
        })
        .collect()
}

fn decode16(raw: Vec<u16>, is_colour: impl Fn(usize) -> bool) -> Vec<f32> {
    raw.into_iter()
        .enumerate()
        .map(|(i, v)| {
            let c = f64::from(v) / 65535.0;
            (if is_colour(i) { srgb_to_linear(c) } else { c }) as f32
        })
        .collect()
}

fn load_exr(path: &Path, budget: &MemoryBudget) -> Result<Texture, TextureError> {
    let format = format(path);
    // exr opens the file itself: report a missing file, a device or a FIFO, or one larger than
    // the budget left, before it does.
    checked_file_size(path, budget).map_err(input(path))?;
    let meta = exr::meta::MetaData::read_from_file(path, false)
        .map_err(|e| format(format!("not a readable OpenEXR file: {e}")))?;
    let header = meta
        .headers
        .first()
        .ok_or_else(|| format("the OpenEXR file has no layer".into()))?;
    let (w, h) = (header.layer_size.x() as u64, header.layer_size.y() as u64);
    check_size(Some(path), w, h)?;
    let (w, h) = (w as u32, h as u32);
    let names: Vec<String> = header
        .channels
        .list
        .iter()
        .map(|c| c.name.to_string())
        .collect();
    let (channels, picked) = pick_exr_channels(&names).ok_or_else(|| {
        format(format!(
            "the OpenEXR layer's channels {names:?} hold no colour: R, G, B [A], Y [A] or a \
             single channel is needed"
        ))
    })?;
    // The first layer is decoded whole, every channel, before the texture's are taken.
    let decoded = u64::from(w)
        .saturating_mul(u64::from(h))
        .saturating_mul(header.channels.bytes_per_pixel as u64);
    over(
        path,
        budget,
        format!(
            "decoding the {w} × {h} OpenEXR texture ({} channels, then the f32 mip chain)",
            names.len()
        ),
        decoded.saturating_add(Texture::chain_bytes(w, h, channels)),
    )?;
    charge_chain(path, budget, (w, h, channels))?;
    let image = read_exr(path).map_err(&format)?;
    let layer = image.layer_data;
    if (layer.size.x(), layer.size.y()) != (w as usize, h as usize) {
        return Err(format(
            "the OpenEXR layer's size differs from its header".into(),
        ));
    }
    let list = &layer.channel_data.list;
    let columns: Vec<Vec<f32>> = picked
        .iter()
        .map(|name| {
            list.iter()
                .find(|c| c.name.to_string() == *name)
                .map(|c| c.sample_data.values_as_f32().collect::<Vec<f32>>())
                .ok_or_else(|| format(format!("the OpenEXR layer lost its channel {name}")))
        })
        .collect::<Result<_, _>>()?;
    let texels = w as usize * h as usize;
    if columns.iter().any(|c| c.len() != texels) {
        return Err(format(format!(
            "an OpenEXR channel does not hold {w} × {h} samples"
        )));
    }
    let mut data = Vec::with_capacity(texels * picked.len());
    for t in 0..texels {
        for (k, c) in columns.iter().enumerate() {
            let v = c[t];
            if !v.is_finite() {
                return Err(format(format!(
                    "texel ({}, {}) channel {} is not finite: {v}",
                    t % w as usize,
                    t / w as usize,
                    picked[k]
                )));
            }
            data.push(v);
        }
    }
    Ok(Texture::build(w, h, channels, data))
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

/// The channels a texture takes from an OpenEXR layer's names, in texel order.
fn pick_exr_channels(names: &[String]) -> Option<(Channels, Vec<String>)> {
    let has = |n: &str| names.iter().any(|m| m == n);
    let list = |v: &[&str]| v.iter().map(|s| (*s).to_owned()).collect();
    if has("R") && has("G") && has("B") {
        Some(if has("A") {
            (Channels::Rgba, list(&["R", "G", "B", "A"]))
        } else {
            (Channels::Rgb, list(&["R", "G", "B"]))
        })
    } else if has("Y") {
        Some(if has("A") {
            (Channels::GreyAlpha, list(&["Y", "A"]))
        } else {
            (Channels::Grey, list(&["Y"]))
        })
    } else if names.len() == 1 {
        Some((Channels::Grey, names.to_vec()))
    } else {
        None
    }
}
