//! Loading height maps from 16-bit PNG, EXR and `.npy` files, and the errors for unreadable,
//! empty, wrong-format, non-finite and absurd-size inputs (each names the path and the reason;
//! none panics).

use fray_terrain::{Heightmap, TerrainError};
use std::path::{Path, PathBuf};

fn dir(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!(
        "fray-terrain-loaders-{}-{name}",
        std::process::id()
    ));
    std::fs::create_dir_all(&d).unwrap();
    d
}

fn err_text(path: &Path) -> String {
    let e = Heightmap::load(path).unwrap_err();
    let text = e.to_string();
    assert!(
        text.contains(&path.display().to_string()),
        "no path in: {text}"
    );
    text
}

#[test]
fn sixteen_bit_png_loads_exactly_row_0_first() {
    let d = dir("png");
    let path = d.join("map.png");
    let values: Vec<u16> = (0..12).map(|k| k * 5000 + 7).collect();
    let img = image::ImageBuffer::<image::Luma<u16>, _>::from_raw(4, 3, values.clone()).unwrap();
    img.save(&path).unwrap();
    let m = Heightmap::load(&path).unwrap();
    assert_eq!((m.width(), m.height()), (4, 3));
    assert_eq!(m.at(1, 2), f32::from(values[9]));
    assert_eq!(m.at(3, 0), f32::from(values[3]));
}

#[test]
fn the_real_dem_loads_with_its_documented_size_and_range() {
    let path =
        Path::new(env!("CARGO_MANIFEST_DIR")).join("../../data/terrain/jacksboro_fault_dem.png");
    let m = Heightmap::load(&path).unwrap();
    assert_eq!((m.width(), m.height()), (403, 344));
    let (lo, hi) = m
        .samples()
        .iter()
        .fold((f32::MAX, f32::MIN), |(a, b), &s| (a.min(s), b.max(s)));
    assert_eq!((lo, hi), (236.0, 1076.0));
}

#[test]
fn npy_loads_every_accepted_dtype_and_names_the_rest() {
    let d = dir("npy");
    let path = d.join("a.npy");
    let data: Vec<u8> = [1i16, -2, 3, 4, 5, 6]
        .iter()
        .flat_map(|v| v.to_le_bytes())
        .collect();
    std::fs::write(&path, fray_terrain::npy::encode("<i2", 2, 3, &data)).unwrap();
    let m = Heightmap::load(&path).unwrap();
    assert_eq!(
        (m.width(), m.height(), m.at(1, 0), m.at(0, 1)),
        (3, 2, -2.0, 4.0)
    );
    let data: Vec<u8> = [0.5f64, 1.5, 2.5, 3.5]
        .iter()
        .flat_map(|v| v.to_le_bytes())
        .collect();
    std::fs::write(&path, fray_terrain::npy::encode("<f8", 2, 2, &data)).unwrap();
    assert_eq!(Heightmap::load(&path).unwrap().at(1, 1), 3.5);
    std::fs::write(&path, fray_terrain::npy::encode("<c8", 2, 2, &[0; 32])).unwrap();
    assert!(err_text(&path).contains("unsupported .npy dtype '<c8'"));
    // NaN in the data: the sample is named.
    let data: Vec<u8> = [0.0f32, f32::NAN, 1.0, 2.0]
        .iter()
        .flat_map(|v| v.to_le_bytes())
        .collect();
    std::fs::write(&path, fray_terrain::npy::encode("<f4", 2, 2, &data)).unwrap();
    assert!(err_text(&path).contains("sample (1, 0) is not finite"));
}

#[test]
fn exr_single_channel_f32_loads() {
    use exr::prelude::*;
    let d = dir("exr");
    let path = d.join("h.exr");
    let channel = SpecificChannels::build()
        .with_channel("Z")
        .with_pixel_fn(|p: Vec2<usize>| (p.x() as f32 * 0.25 + p.y() as f32 * 10.0,));
    Image::from_channels((5, 4), channel)
        .write()
        .to_file(&path)
        .unwrap();
    let m = Heightmap::load(&path).unwrap();
    assert_eq!((m.width(), m.height()), (5, 4));
    assert_eq!(m.at(2, 3), 30.5);
}

#[test]
fn unreadable_empty_wrong_format_and_absurd_inputs_are_clear_errors() {
    let d = dir("errors");
    // Missing file: an I/O error, for each format.
    for ext in ["png", "exr", "npy"] {
        let missing = d.join(format!("missing.{ext}"));
        let e = Heightmap::load(&missing).unwrap_err();
        assert!(matches!(e, TerrainError::Io { .. }), "{ext}: {e}");
    }
    // Empty files.
    for ext in ["png", "exr", "npy"] {
        let empty = d.join(format!("empty.{ext}"));
        std::fs::write(&empty, b"").unwrap();
        err_text(&empty);
    }
    // Text pretending to be each format.
    for ext in ["png", "exr", "npy"] {
        let junk = d.join(format!("junk.{ext}"));
        std::fs::write(&junk, b"this is not a height map at all").unwrap();
        err_text(&junk);
    }
    // An RGB PNG: greyscale is needed.
    let rgb = d.join("rgb.png");
    image::RgbImage::new(4, 4).save(&rgb).unwrap();
    assert!(err_text(&rgb).contains("greyscale"));
    // A 1-pixel-wide PNG: too small to have a cell.
    let thin = d.join("thin.png");
    image::GrayImage::new(1, 7).save(&thin).unwrap();
    assert!(err_text(&thin).contains("at least 2 × 2"));
    // An absurd .npy shape is refused from the header alone (no 10¹⁰-sample allocation).
    let huge = d.join("huge.npy");
    std::fs::write(
        &huge,
        fray_terrain::npy::encode("<f4", 100000, 100000, &[0; 64]),
    )
    .unwrap();
    assert!(err_text(&huge).contains("too large"));
    // An unknown extension.
    let tiff = d.join("map.tiff");
    std::fs::write(&tiff, b"II*\0").unwrap();
    assert!(matches!(
        Heightmap::load(&tiff),
        Err(TerrainError::UnsupportedExtension { .. })
    ));
    // Truncated PNG: the header promises more than the file holds.
    let good = d.join("good.png");
    image::GrayImage::new(64, 64).save(&good).unwrap();
    let bytes = std::fs::read(&good).unwrap();
    let cut = d.join("cut.png");
    std::fs::write(&cut, &bytes[..bytes.len() / 2]).unwrap();
    err_text(&cut);
}
