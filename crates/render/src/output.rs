//! Writing frames as PNG (sRGB, 8/16-bit) and EXR (linear float with depth).
//!
//! * **PNG** — RGB, 8 or 16 bits per channel: linear radiance is tone mapped
//!   ([`ToneMap::apply`] with the exposure), sRGB-encoded ([`linear_to_srgb`]) and rounded to
//!   the nearest code value. No alpha, no colour profile chunk (PNG's default is sRGB).
//! * **EXR** — one single-part, scan-line, ZIP-compressed (lossless) image with `f32` channels
//!   following the OpenEXR naming conventions that compositors (Nuke, Blender, DJV, tev)
//!   understand:
//!   - `R`, `G`, `B`: linear radiance, untouched by tone mapping or exposure;
//!   - `Z`: depth, the distance from the ray's origin along the ray in world units, `+∞`
//!     where nothing was hit;
//!   - `N.X`, `N.Y`, `N.Z`: the unit world-space normal (layer `N`, channels `X`/`Y`/`Z`,
//!     the `layer.channel` convention), zero where nothing was hit.
//!
//! Every function returns an [`OutputError`] naming the path and the reason; none panics.

use exr::prelude::{
    AnyChannel, AnyChannels, Encoding, FlatSamples, Image as ExrImage, Layer, LayerAttributes,
    SmallVec, Text, WritableImage,
};
use fray_core::{Frame, Image, ToneMap, linear_to_srgb};
use std::path::{Path, PathBuf};

/// Bits per channel of a written PNG.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum BitDepth {
    #[default]
    Eight,
    Sixteen,
}

/// How linear radiance becomes PNG code values.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PngOptions {
    pub bit_depth: BitDepth,
    pub tone_map: ToneMap,
    /// Multiplies radiance before tone mapping.
    pub exposure: f32,
}

impl Default for PngOptions {
    /// 8-bit, [`ToneMap::Clamp`], exposure 1.
    fn default() -> Self {
        Self {
            bit_depth: BitDepth::Eight,
            tone_map: ToneMap::Clamp,
            exposure: 1.0,
        }
    }
}

/// The extensions [`write_image`] understands.
pub const SUPPORTED_EXTENSIONS: &[&str] = &["png", "exr"];

/// Why an image could not be written or read.
#[derive(Debug, thiserror::Error)]
pub enum OutputError {
    #[error("{}: unsupported image extension (supported: .{})", path.display(), SUPPORTED_EXTENSIONS.join(", ."))]
    UnsupportedExtension { path: PathBuf },
    #[error("{}: the frame is empty ({width} × {height})", path.display())]
    EmptyFrame {
        path: PathBuf,
        width: u32,
        height: u32,
    },
    #[error("{}: the frame's colour, depth and normal images differ in size", path.display())]
    InconsistentFrame { path: PathBuf },
    #[error("cannot write PNG {}: {source}", path.display())]
    WritePng {
        path: PathBuf,
        #[source]
        source: image::ImageError,
    },
    #[error("cannot write EXR {}: {source}", path.display())]
    WriteExr {
        path: PathBuf,
        #[source]
        source: exr::error::Error,
    },
    #[error("cannot read PNG {}: {source}", path.display())]
    ReadPng {
        path: PathBuf,
        #[source]
        source: image::ImageError,
    },
}

/// Writes `frame` as a PNG or EXR, chosen by the extension of `path` (case-insensitive).
/// `options` apply to PNG only; EXR is always linear.
pub fn write_image(frame: &Frame, path: &Path, options: &PngOptions) -> Result<(), OutputError> {
    match check_extension(path)? {
        ImageFormat::Png => write_png(frame, path, options),
        ImageFormat::Exr => write_exr(frame, path),
    }
}

/// The formats [`write_image`] writes.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ImageFormat {
    Png,
    Exr,
}

/// The format [`write_image`] would choose for `path` (by its extension, case-insensitive), or
/// [`OutputError::UnsupportedExtension`]: callers check it before rendering, so a typo in the
/// output name costs nothing.
pub fn check_extension(path: &Path) -> Result<ImageFormat, OutputError> {
    let ext = path
        .extension()
        .and_then(|e| e.to_str())
        .map(str::to_ascii_lowercase);
    match ext.as_deref() {
        Some("png") => Ok(ImageFormat::Png),
        Some("exr") => Ok(ImageFormat::Exr),
        _ => Err(OutputError::UnsupportedExtension {
            path: path.to_path_buf(),
        }),
    }
}

/// One linear channel value as a display value in `[0, 1]`: tone mapped, then sRGB-encoded.
fn encode(value: f32, options: &PngOptions) -> f32 {
    linear_to_srgb(options.tone_map.apply(value, options.exposure))
}

/// The 8-bit sRGB image that [`write_png`] writes at [`BitDepth::Eight`] (its bit depth is
/// ignored here).
pub fn srgb8(frame: &Frame, options: &PngOptions) -> Image<[u8; 3]> {
    frame.colour.map(|c| {
        c.to_array()
            .map(|v| (encode(v, options) * 255.0).round() as u8)
    })
}

/// The 16-bit sRGB image that [`write_png`] writes at [`BitDepth::Sixteen`].
fn srgb16(frame: &Frame, options: &PngOptions) -> Image<[u16; 3]> {
    frame.colour.map(|c| {
        c.to_array()
            .map(|v| (encode(v, options) * 65535.0).round() as u16)
    })
}

fn check_not_empty(frame: &Frame, path: &Path) -> Result<(), OutputError> {
    let (width, height) = (frame.colour.width(), frame.colour.height());
    if width == 0 || height == 0 {
        return Err(OutputError::EmptyFrame {
            path: path.to_path_buf(),
            width,
            height,
        });
    }
    Ok(())
}

/// Writes the frame's colour as an sRGB PNG (RGB, 8 or 16 bits per channel).
pub fn write_png(frame: &Frame, path: &Path, options: &PngOptions) -> Result<(), OutputError> {
    check_not_empty(frame, path)?;
    let (w, h) = (frame.colour.width(), frame.colour.height());
    let wrap = |source| OutputError::WritePng {
        path: path.to_path_buf(),
        source,
    };
    match options.bit_depth {
        BitDepth::Eight => {
            let data = srgb8(frame, options).into_pixels().concat();
            image::save_buffer_with_format(
                path,
                &data,
                w,
                h,
                image::ExtendedColorType::Rgb8,
                image::ImageFormat::Png,
            )
            .map_err(wrap)
        }
        BitDepth::Sixteen => {
            let data = srgb16(frame, options).into_pixels().concat();
            let buffer = image::ImageBuffer::<image::Rgb<u16>, Vec<u16>>::from_raw(w, h, data)
                .ok_or_else(|| OutputError::InconsistentFrame {
                    path: path.to_path_buf(),
                })?;
            buffer
                .save_with_format(path, image::ImageFormat::Png)
                .map_err(wrap)
        }
    }
}

/// Writes the frame as a linear EXR: `R`, `G`, `B`, depth `Z` (+∞ where no hit) and normals
/// `N.X`, `N.Y`, `N.Z`, all `f32` (see the module documentation).
pub fn write_exr(frame: &Frame, path: &Path) -> Result<(), OutputError> {
    check_not_empty(frame, path)?;
    let size = (frame.colour.width(), frame.colour.height());
    if (frame.depth.width(), frame.depth.height()) != size
        || (frame.normals.width(), frame.normals.height()) != size
    {
        return Err(OutputError::InconsistentFrame {
            path: path.to_path_buf(),
        });
    }
    let colour = frame.colour.pixels();
    let normals = frame.normals.pixels();
    let channel = |name: &str, values: Vec<f32>| AnyChannel::new(name, FlatSamples::F32(values));
    let list: SmallVec<[AnyChannel<FlatSamples>; 4]> = SmallVec::from_vec(vec![
        channel("R", colour.iter().map(|c| c.x).collect()),
        channel("G", colour.iter().map(|c| c.y).collect()),
        channel("B", colour.iter().map(|c| c.z).collect()),
        channel(
            "Z",
            frame.depth.pixels().iter().map(|&d| d as f32).collect(),
        ),
        channel("N.X", normals.iter().map(|n| n.x).collect()),
        channel("N.Y", normals.iter().map(|n| n.y).collect()),
        channel("N.Z", normals.iter().map(|n| n.z).collect()),
    ]);
    let attributes = LayerAttributes {
        comments: Some(Text::from(
            "fray: linear RGB radiance; Z = distance along the ray (inf = no hit); \
             N = world-space unit normal",
        )),
        software_name: Some(Text::from("fray")),
        ..LayerAttributes::default()
    };
    let layer = Layer::new(
        (size.0 as usize, size.1 as usize),
        attributes,
        Encoding::SMALL_LOSSLESS,
        AnyChannels::sort(list),
    );
    ExrImage::from_layer(layer)
        .write()
        .to_file(path)
        .map_err(|source| OutputError::WriteExr {
            path: path.to_path_buf(),
            source,
        })
}

/// Reads a PNG as 8-bit RGB (other layouts are converted: alpha dropped, 16-bit rounded).
pub fn read_png_rgb8(path: &Path) -> Result<Image<[u8; 3]>, OutputError> {
    let wrap = |source| OutputError::ReadPng {
        path: path.to_path_buf(),
        source,
    };
    let reader = image::ImageReader::open(path)
        .map_err(|e| wrap(image::ImageError::IoError(e)))?
        .with_guessed_format()
        .map_err(|e| wrap(image::ImageError::IoError(e)))?;
    let rgb = reader.decode().map_err(wrap)?.to_rgb8();
    let (w, h) = rgb.dimensions();
    let pixels = rgb.pixels().map(|p| p.0).collect();
    // The count is right by construction; `None` cannot happen, but we never panic.
    Image::from_pixels(w, h, pixels).ok_or_else(|| {
        wrap(image::ImageError::Limits(
            image::error::LimitError::from_kind(image::error::LimitErrorKind::DimensionError),
        ))
    })
}
