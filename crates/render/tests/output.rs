//! Round trips of `fray_render::output`: PNG 8/16-bit, EXR channels, and its errors.

use fray_core::glam::Vec3;
use fray_core::{Frame, Image, RenderStats, ToneMap, linear_to_srgb};
use fray_render::output::{
    BitDepth, OutputError, PngOptions, read_png_rgb8, srgb8, write_exr, write_image, write_png,
};
use std::path::PathBuf;

/// A fresh path under cargo's per-test-crate scratch directory.
fn scratch(name: &str) -> PathBuf {
    let dir = PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join("fray-render-output");
    std::fs::create_dir_all(&dir).expect("scratch dir");
    let path = dir.join(name);
    let _ = std::fs::remove_file(&path);
    path
}

/// Linear values chosen to exercise black, the 0.5 anchor, white, clipping, negatives and
/// the linear toe of the sRGB curve.
const VALUES: [f32; 6] = [0.0, 0.5, 1.0, 2.5, -0.25, 0.002];

/// A 3 × 2 frame: pixel i has colour (v_i, v_{i+1}, v_{i+2}) (cyclic), depth i+1 except
/// pixel 4, which missed (depth +∞, normal zero).
fn synthetic_frame() -> Frame {
    let (w, h) = (3, 2);
    let n = VALUES.len();
    let colour = (0..n)
        .map(|i| Vec3::new(VALUES[i], VALUES[(i + 1) % n], VALUES[(i + 2) % n]))
        .collect();
    let depth = (0..n)
        .map(|i| {
            if i == 4 {
                f64::INFINITY
            } else {
                i as f64 + 1.25
            }
        })
        .collect();
    let normals = (0..n)
        .map(|i| {
            if i == 4 {
                Vec3::ZERO
            } else {
                Vec3::new(i as f32, 1.0, -2.0).normalize()
            }
        })
        .collect();
    Frame {
        colour: Image::from_pixels(w, h, colour).unwrap(),
        depth: Image::from_pixels(w, h, depth).unwrap(),
        normals: Image::from_pixels(w, h, normals).unwrap(),
        stats: RenderStats::default(),
    }
}

fn expected(v: f32, options: &PngOptions, max: f32) -> f32 {
    (linear_to_srgb(options.tone_map.apply(v, options.exposure)) * max).round()
}

#[test]
fn png_8_bit_round_trip() {
    let frame = synthetic_frame();
    let options = PngOptions::default();
    let path = scratch("eight.png");
    write_png(&frame, &path, &options).unwrap();

    let read = image::open(&path).unwrap();
    assert_eq!(read.color(), image::ColorType::Rgb8);
    let read = read.to_rgb8();
    assert_eq!(read.dimensions(), (3, 2));
    for (i, (p, c)) in read.pixels().zip(frame.colour.pixels()).enumerate() {
        let want = c.to_array().map(|v| expected(v, &options, 255.0) as u8);
        assert_eq!(p.0, want, "pixel {i}");
    }
    // Known values: linear 0.5 → sRGB 188; 0 → 0; 1 and above → 255; negative → 0.
    assert_eq!(read.get_pixel(0, 0).0, [0, 188, 255]);
    assert_eq!(read.get_pixel(1, 0).0, [188, 255, 255]);
    assert_eq!(read.get_pixel(0, 1).0, [255, 0, 7]); // (2.5, -0.25, 0.002): linear toe

    // `srgb8` is exactly what was written, and `read_png_rgb8` reads it back.
    let ours = read_png_rgb8(&path).unwrap();
    assert_eq!(ours, srgb8(&frame, &options));
    assert_eq!(*ours.get(1, 0), [188, 255, 255]);
}

#[test]
fn png_16_bit_round_trip_with_reinhard_and_exposure() {
    let frame = synthetic_frame();
    let options = PngOptions {
        bit_depth: BitDepth::Sixteen,
        tone_map: ToneMap::Reinhard,
        exposure: 2.0,
    };
    let path = scratch("sixteen.png");
    write_png(&frame, &path, &options).unwrap();

    let read = image::open(&path).unwrap();
    assert_eq!(read.color(), image::ColorType::Rgb16);
    let read = read.to_rgb16();
    for (i, (p, c)) in read.pixels().zip(frame.colour.pixels()).enumerate() {
        let want = c.to_array().map(|v| expected(v, &options, 65535.0) as u16);
        assert_eq!(p.0, want, "pixel {i}");
    }
    // Reinhard at exposure 2: 0.5 → 1/2 → sRGB 0.735357 → 48192 of 65535.
    assert_eq!(read.get_pixel(0, 0).0[1], 48192);
}

#[test]
fn png_16_bit_clamp_known_value() {
    let frame = synthetic_frame();
    let options = PngOptions {
        bit_depth: BitDepth::Sixteen,
        ..PngOptions::default()
    };
    let path = scratch("sixteen-clamp.png");
    write_image(&frame, &path, &options).unwrap();
    let read = image::open(&path).unwrap().to_rgb16();
    assert_eq!(read.get_pixel(0, 0).0, [0, 48192, 65535]);
}

#[test]
fn exr_round_trip_keeps_linear_colour_depth_and_normals() {
    let frame = synthetic_frame();
    let path = scratch("frame.exr");
    write_image(&frame, &path, &PngOptions::default()).unwrap();

    let image = exr::prelude::read_first_flat_layer_from_file(&path).unwrap();
    let layer = &image.layer_data;
    assert_eq!(
        (layer.size.width(), layer.size.height()),
        (3, 2),
        "layer size"
    );
    let channel = |name: &str| -> Vec<f32> {
        let c = layer
            .channel_data
            .list
            .iter()
            .find(|c| c.name == *name)
            .unwrap_or_else(|| panic!("channel {name} missing"));
        match &c.sample_data {
            exr::prelude::FlatSamples::F32(v) => v.clone(),
            other => panic!("channel {name} is not f32: {other:?}"),
        }
    };
    let names: Vec<String> = layer
        .channel_data
        .list
        .iter()
        .map(|c| c.name.to_string())
        .collect();
    assert_eq!(names, ["B", "G", "N.X", "N.Y", "N.Z", "R", "Z"]);

    let (r, g, b) = (channel("R"), channel("G"), channel("B"));
    let z = channel("Z");
    let (nx, ny, nz) = (channel("N.X"), channel("N.Y"), channel("N.Z"));
    for i in 0..6 {
        let c = frame.colour.pixels()[i];
        // Linear and untouched: negative and > 1 values survive.
        assert_eq!([r[i], g[i], b[i]], c.to_array(), "colour {i}");
        let n = frame.normals.pixels()[i];
        assert_eq!([nx[i], ny[i], nz[i]], n.to_array(), "normal {i}");
        assert_eq!(z[i], frame.depth.pixels()[i] as f32, "depth {i}");
    }
    assert_eq!(z[4], f32::INFINITY);
    assert_eq!([nx[4], ny[4], nz[4]], [0.0; 3]);
    assert_eq!(z[0], 1.25);
}

#[test]
fn unknown_extension_is_an_error_naming_path_and_supported_extensions() {
    let frame = synthetic_frame();
    for name in ["frame.jpg", "frame"] {
        let path = scratch(name);
        let err = write_image(&frame, &path, &PngOptions::default()).unwrap_err();
        assert!(
            matches!(err, OutputError::UnsupportedExtension { .. }),
            "{err:?}"
        );
        let msg = err.to_string();
        assert!(msg.contains(&path.display().to_string()), "{msg}");
        assert!(msg.contains(".png") && msg.contains(".exr"), "{msg}");
        assert!(!path.exists());
    }
    // Extensions are matched case-insensitively.
    write_image(&frame, &scratch("upper.PNG"), &PngOptions::default()).unwrap();
}

#[test]
fn unwritable_paths_are_errors_naming_the_path() {
    let frame = synthetic_frame();
    let dir = scratch("no-such-dir");
    for name in ["x.png", "x.exr"] {
        let path = dir.join("deeper").join(name);
        let err = write_image(&frame, &path, &PngOptions::default()).unwrap_err();
        let msg = err.to_string();
        assert!(msg.contains(&path.display().to_string()), "{msg}");
    }
    let png16 = PngOptions {
        bit_depth: BitDepth::Sixteen,
        ..PngOptions::default()
    };
    let path = dir.join("deeper").join("y.png");
    assert!(write_png(&frame, &path, &png16).is_err());
}

#[test]
fn reading_a_missing_or_bad_png_is_an_error() {
    let missing = scratch("missing.png");
    let err = read_png_rgb8(&missing).unwrap_err();
    assert!(
        err.to_string().contains(&missing.display().to_string()),
        "{err}"
    );

    let garbage = scratch("garbage.png");
    std::fs::write(&garbage, b"not a png").unwrap();
    assert!(matches!(
        read_png_rgb8(&garbage),
        Err(OutputError::ReadPng { .. })
    ));
}

#[test]
fn empty_and_inconsistent_frames_are_errors() {
    let empty = Frame {
        colour: Image::from_pixels(0, 0, vec![]).unwrap(),
        depth: Image::from_pixels(0, 0, vec![]).unwrap(),
        normals: Image::from_pixels(0, 0, vec![]).unwrap(),
        stats: RenderStats::default(),
    };
    for name in ["e.png", "e.exr"] {
        let err = write_image(&empty, &scratch(name), &PngOptions::default()).unwrap_err();
        assert!(matches!(err, OutputError::EmptyFrame { .. }), "{err:?}");
    }
    let mut odd = synthetic_frame();
    odd.depth = Image::filled(1, 1, 1.0);
    let err = write_exr(&odd, &scratch("odd.exr")).unwrap_err();
    assert!(
        matches!(err, OutputError::InconsistentFrame { .. }),
        "{err:?}"
    );
}
