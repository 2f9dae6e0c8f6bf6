//! Textures against known answers: the uv convention on known 2 × 2 and 4 × 3 images (nearest,
//! bilinear, every wrap mode at and past the edges), the mip chain's sizes and its mean (the box
//! filter conserves it to 1e-6 on power-of-two and odd sizes), PNG and OpenEXR loading (sRGB to
//! linear against the formula, round trips, real photographs) and their errors (each names the
//! path and the reason), the projected mappings at known points and on degenerate input
//! (property-tested: finite, weights summing to 1), the colour ramps and the drape.

use fray_core::MemoryBudget;
use fray_mesh::MeshError;
use fray_mesh::texture::{
    Channels, Cylindrical, Drape, Encoding, Filter, Footprint, Mapping, Planar, Ramp, Spherical,
    TerrainRamp, Texture, TextureError, Triplanar, Wrap, WrapMode, level_sizes,
};
use glam::{DVec2, DVec3, Vec3, Vec4};
use proptest::prelude::*;
use std::path::{Path, PathBuf};

fn dir(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("fray-mesh-texture-{}-{name}", std::process::id()));
    std::fs::create_dir_all(&d).unwrap();
    d
}

fn data(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../data/textures")
        .join(name)
}

/// A `w × h` RGB texture whose texel `(i, j)` is `(i, j, 10 i + j)`.
fn indexed(w: u32, h: u32) -> Texture {
    let mut d = Vec::new();
    for j in 0..h {
        for i in 0..w {
            d.extend([i as f32, j as f32, (10 * i + j) as f32]);
        }
    }
    Texture::from_rgb(w, h, d).unwrap()
}

fn texel(i: u32, j: u32) -> Vec4 {
    Vec4::new(i as f32, j as f32, (10 * i + j) as f32, 1.0)
}

/// The uv of texel `(i, j)`'s centre in a `w × h` image.
fn centre(i: u32, j: u32, w: u32, h: u32) -> DVec2 {
    DVec2::new(
        (f64::from(i) + 0.5) / f64::from(w),
        1.0 - (f64::from(j) + 0.5) / f64::from(h),
    )
}

/// The convention: uv (0.25, 0.75) of a 2 × 2 image is the top-left texel (row 0, column 0),
/// (0.75, 0.25) the bottom-right; uv (0, 0) is the bottom-left corner. Exact.
#[test]
fn uv_origin_is_bottom_left_and_row_0_is_the_top() {
    let t = indexed(2, 2);
    let w = Wrap::CLAMP;
    for f in [Texture::nearest, Texture::bilinear] {
        assert_eq!(f(&t, 0, DVec2::new(0.25, 0.75), w), texel(0, 0));
        assert_eq!(f(&t, 0, DVec2::new(0.75, 0.75), w), texel(1, 0));
        assert_eq!(f(&t, 0, DVec2::new(0.25, 0.25), w), texel(0, 1));
        assert_eq!(f(&t, 0, DVec2::new(0.75, 0.25), w), texel(1, 1));
    }
    // The corners of the uv square, clamped: the corner texels.
    assert_eq!(t.nearest(0, DVec2::ZERO, w), texel(0, 1));
    assert_eq!(t.bilinear(0, DVec2::new(0.0, 1.0), w), texel(0, 0));
    assert_eq!(t.bilinear(0, DVec2::new(1.0, 0.0), w), texel(1, 1));
    // The centre of the image: the mean of the four.
    assert_eq!(
        t.bilinear(0, DVec2::splat(0.5), w),
        (texel(0, 0) + texel(1, 0) + texel(0, 1) + texel(1, 1)) / 4.0
    );
}

/// On a 4 × 3 image (non-dyadic rows), nearest anywhere in a texel and bilinear at every texel
/// centre return that texel exactly; bilinear halfway between two centres is their mean
/// (to f32 rounding, 1e-6).
#[test]
fn texel_centres_read_their_texel_exactly() {
    let (w, h) = (4, 3);
    let t = indexed(w, h);
    for j in 0..h {
        for i in 0..w {
            let c = centre(i, j, w, h);
            for wrap in [Wrap::REPEAT, Wrap::CLAMP, Wrap::MIRROR] {
                assert_eq!(t.bilinear(0, c, wrap), texel(i, j), "({i}, {j}) {wrap:?}");
                for d in [-0.49, 0.0, 0.49] {
                    let p = c + DVec2::new(d / f64::from(w), -d / f64::from(h));
                    assert_eq!(t.nearest(0, p, wrap), texel(i, j), "({i}, {j}) {d}");
                }
            }
            // Trilinear at level 0 is the bilinear.
            assert_eq!(t.trilinear(c, 0.0, Wrap::REPEAT), texel(i, j));
        }
    }
    let mid = (centre(1, 2, w, h) + centre(2, 2, w, h)) / 2.0;
    let got = t.bilinear(0, mid, Wrap::CLAMP);
    assert!(
        (got - (texel(1, 2) + texel(2, 2)) / 2.0)
            .abs()
            .max_element()
            < 1e-6
    );
}

/// Wrap modes at and past the edges of the 4 × 3 image: repeat reads `uv + (1, −2)` as `uv`
/// and blends the two edge columns at `u = 0`; clamp extends the edge texels; mirror reads
/// `−u` as `u` and `1 + u` as `1 − u`; modes apply per axis.
#[test]
fn wrap_modes_at_and_past_the_edges() {
    let (w, h) = (4u32, 3u32);
    let t = indexed(w, h);
    let row1 = |i: u32| texel(i, 1);
    let v1 = centre(0, 1, w, h).y;
    let at = |u: f64, wrap: Wrap| t.bilinear(0, DVec2::new(u, v1), wrap);
    let near = |a: Vec4, b: Vec4| (a - b).abs().max_element() < 1e-5;
    // Repeat.
    for i in 0..w {
        let c = centre(i, 1, w, h);
        assert_eq!(
            t.nearest(0, c + DVec2::new(1.0, -2.0), Wrap::REPEAT),
            row1(i)
        );
        assert!(near(
            t.bilinear(0, c + DVec2::new(-3.0, 5.0), Wrap::REPEAT),
            row1(i)
        ));
    }
    assert!(near(at(0.0, Wrap::REPEAT), (row1(0) + row1(3)) / 2.0));
    assert!(near(at(1.0, Wrap::REPEAT), (row1(0) + row1(3)) / 2.0));
    // Clamp: the edge column at and past the edge.
    for u in [0.0, -0.3, -7.0] {
        assert_eq!(at(u, Wrap::CLAMP), row1(0));
    }
    for u in [1.0, 1.7, 1e9] {
        assert_eq!(at(u, Wrap::CLAMP), row1(3));
    }
    // Mirror: the edge texel is its own neighbour; −u reads u, 1 + u reads 1 − u.
    assert_eq!(at(0.0, Wrap::MIRROR), row1(0));
    assert_eq!(at(1.0, Wrap::MIRROR), row1(3));
    for u in [0.1, 0.3, 0.55, 0.8] {
        assert!(near(at(-u, Wrap::MIRROR), at(u, Wrap::MIRROR)), "{u}");
        assert!(
            near(at(1.0 + u, Wrap::MIRROR), at(1.0 - u, Wrap::MIRROR)),
            "{u}"
        );
        assert!(near(at(2.0 + u, Wrap::MIRROR), at(u, Wrap::MIRROR)), "{u}");
    }
    // Per axis: u repeats, v clamps (above the top: row 0).
    let mixed = Wrap {
        u: WrapMode::Repeat,
        v: WrapMode::Clamp,
    };
    assert_eq!(t.nearest(0, DVec2::new(1.125, 3.0), mixed), texel(0, 0));
    assert_eq!(t.nearest(0, DVec2::new(-0.125, -3.0), mixed), texel(3, 2));
    // Non-finite or huge coordinates: finite texels, no panic.
    for uv in [
        DVec2::NAN,
        DVec2::splat(f64::INFINITY),
        DVec2::splat(-1e300),
    ] {
        for wrap in [Wrap::REPEAT, Wrap::CLAMP, Wrap::MIRROR] {
            assert!(t.bilinear(0, uv, wrap).is_finite());
            assert!(t.trilinear(uv, f64::NAN, wrap).is_finite());
        }
    }
}

use fray_test_support::Rng;

/// Level sizes are `⌈w/2⌉ × ⌈h/2⌉` down to 1 × 1, and every level's mean is the base mean to
/// 1e-6 (values in [0, 1]), for power-of-two, odd, thin and photo-like sizes.
#[test]
fn mip_levels_halve_and_keep_the_mean() {
    let mut rng = Rng(7);
    for (w, h) in [
        (8u32, 8u32),
        (16, 4),
        (5, 3),
        (7, 1),
        (1, 9),
        (33, 17),
        (451, 300),
    ] {
        for channels in [Channels::Grey, Channels::Rgba] {
            let n = channels.count();
            let texels: Vec<f32> = (0..w as usize * h as usize * n)
                .map(|_| rng.unit() as f32)
                .collect();
            let t = Texture::from_texels(w, h, channels, texels, &MemoryBudget::default()).unwrap();
            let sizes: Vec<(u32, u32)> =
                t.levels().iter().map(|l| (l.width(), l.height())).collect();
            assert_eq!(sizes, level_sizes(w, h));
            for pair in sizes.windows(2) {
                assert_eq!(pair[1], (pair[0].0.div_ceil(2), pair[0].1.div_ceil(2)));
            }
            assert_eq!(*sizes.last().unwrap(), (1, 1));
            let base = t.level(0).mean();
            for (k, l) in t.levels().iter().enumerate() {
                let m = l.mean();
                for c in 0..4 {
                    assert!(
                        (m[c] - base[c]).abs() < 1e-6,
                        "{w} × {h} level {k} channel {c}: {} vs {}",
                        m[c],
                        base[c]
                    );
                }
            }
        }
    }
    assert_eq!(level_sizes(5, 3), vec![(5, 3), (3, 2), (2, 1), (1, 1)]);
}

/// The odd-size filter's weights: a row `a b c` becomes `(2a + b)/3, (b + 2c)/3`, then their
/// mean; a constant image stays constant at every level.
#[test]
fn odd_sides_split_the_middle_texel() {
    let t = Texture::from_texels(
        3,
        1,
        Channels::Grey,
        vec![0.0, 3.0, 6.0],
        &MemoryBudget::default(),
    )
    .unwrap();
    assert_eq!(t.level(1).data(), &[1.0, 5.0]);
    assert_eq!(t.level(2).data(), &[3.0]);
    let c = Texture::from_rgb(13, 7, vec![0.3; 13 * 7 * 3]).unwrap();
    for l in c.levels() {
        assert!(l.data().iter().all(|&v| (v - 0.3).abs() < 1e-7));
    }
}

/// The level of detail is `log₂` of the footprint in base texels, clamped; trilinear blends
/// the two levels around it; the 1 × 1 level is the mean.
#[test]
fn level_of_detail_and_trilinear_blend() {
    let t = indexed(16, 16);
    assert_eq!(t.level_count(), 5);
    assert_eq!(t.level_of_detail(0.5), 0.0);
    assert_eq!(t.level_of_detail(4.0), 2.0);
    assert_eq!(t.level_of_detail(1e9), 4.0);
    assert_eq!(t.level_of_detail(f64::INFINITY), 4.0);
    assert_eq!(t.level_of_detail(f64::NAN), 0.0);
    let uv = DVec2::new(0.3, 0.6);
    let (a, b) = (
        t.bilinear(1, uv, Wrap::REPEAT),
        t.bilinear(2, uv, Wrap::REPEAT),
    );
    let mid = t.trilinear(uv, 1.25, Wrap::REPEAT);
    assert!((mid - a.lerp(b, 0.25)).abs().max_element() < 1e-5);
    // A footprint of 4 texels (uv width 4/16) reads level 2.
    assert_eq!(
        t.sample(uv, 4.0 / 16.0, Wrap::REPEAT),
        t.bilinear(2, uv, Wrap::REPEAT)
    );
    let mean = t.level(4).texel(0, 0);
    assert_eq!(t.sample(uv, 1e6, Wrap::REPEAT), mean);
    assert!((mean - Vec4::new(7.5, 7.5, 82.5, 1.0)).abs().max_element() < 1e-4);
    assert_eq!(
        t.filtered(uv, 1e6, Wrap::REPEAT, Filter::Nearest),
        t.nearest(0, uv, Wrap::REPEAT)
    );
}

/// `from_texels` refuses zero sizes, wrong lengths, non-finite values and a chain over the
/// budget, each saying why.
#[test]
fn texels_in_memory_are_checked() {
    let e = Texture::from_rgb(0, 3, vec![]).unwrap_err();
    assert!(matches!(e, TextureError::Size { .. }), "{e}");
    assert!(e.to_string().contains("0 × 3"), "{e}");
    let e = Texture::from_rgb(2, 2, vec![0.0; 11]).unwrap_err();
    assert!(e.to_string().contains("needs 12 values, got 11"), "{e}");
    let mut d = vec![0.0; 12];
    d[7] = f32::NAN;
    let e = Texture::from_rgb(2, 2, d).unwrap_err();
    assert!(
        e.to_string()
            .contains("texel (0, 1) channel 1 is not finite"),
        "{e}"
    );
    let e = Texture::from_texels(
        64,
        64,
        Channels::Rgb,
        vec![0.0; 64 * 64 * 3],
        &MemoryBudget::new(1000),
    )
    .unwrap_err();
    assert!(matches!(e, TextureError::Budget { .. }), "{e}");
    assert!(e.to_string().contains("mip chain"), "{e}");
    // 64² + 32² + … + 1 = 5461 texels of 3 f32.
    assert_eq!(Texture::chain_bytes(64, 64, Channels::Rgb), 5461 * 12);
}

fn err_text(path: &Path, budget: &MemoryBudget) -> (TextureError, String) {
    let e = Texture::load(path, Encoding::Srgb, budget).unwrap_err();
    let text = e.to_string();
    assert!(
        text.contains(&path.display().to_string()),
        "no path in: {text}"
    );
    (e, text)
}

/// The sRGB decoding, written out here from IEC 61966-2-1.
fn srgb(c8: u8) -> f64 {
    let c = f64::from(c8) / 255.0;
    if c <= 0.04045 {
        c / 12.92
    } else {
        ((c + 0.055) / 1.055).powf(2.4)
    }
}

/// 8-bit sRGB PNG values decode to the formula's linear values (to f32 rounding, 6e-8
/// relative), alpha stays linear, `Encoding::Linear` gives `value / 255`, 16-bit values
/// `value / 65535`; row 0 of the file is the top row (v = 1).
#[test]
fn png_values_decode_to_linear() {
    let d = dir("png");
    let path = d.join("rgba.png");
    let values: [u8; 16] = [
        0, 1, 10, 128, 11, 50, 200, 64, 255, 254, 3, 255, 100, 20, 30, 0,
    ];
    image::RgbaImage::from_raw(2, 2, values.to_vec())
        .unwrap()
        .save(&path)
        .unwrap();
    let t = Texture::load(&path, Encoding::Srgb, &MemoryBudget::default()).unwrap();
    assert_eq!(
        (t.width(), t.height(), t.channels()),
        (2, 2, Channels::Rgba)
    );
    let base = t.level(0).data();
    for (k, (&got, &raw)) in base.iter().zip(&values).enumerate() {
        let want = if k % 4 == 3 {
            f64::from(raw) / 255.0
        } else {
            srgb(raw)
        };
        assert!(
            (f64::from(got) - want).abs() <= 6e-8 * want.max(1e-3),
            "value {k}: {got} vs {want}"
        );
    }
    // Texel (1, 0) — top right — at uv (0.75, 0.75).
    let tr = t.nearest(0, DVec2::new(0.75, 0.75), Wrap::CLAMP);
    assert_eq!(tr.to_array(), [base[4], base[5], base[6], base[7]]);
    let lin = Texture::load(&path, Encoding::Linear, &MemoryBudget::default()).unwrap();
    for (&got, &raw) in lin.level(0).data().iter().zip(&values) {
        assert_eq!(got, f32::from(raw) / 255.0);
    }
    // 16-bit grey.
    let p16 = d.join("grey16.png");
    let v16: Vec<u16> = vec![0, 1000, 40000, 65535, 7, 32768];
    image::ImageBuffer::<image::Luma<u16>, _>::from_raw(3, 2, v16.clone())
        .unwrap()
        .save(&p16)
        .unwrap();
    let g = Texture::load(&p16, Encoding::Linear, &MemoryBudget::default()).unwrap();
    assert_eq!(
        (g.channels(), g.width(), g.height()),
        (Channels::Grey, 3, 2)
    );
    for (&got, &raw) in g.level(0).data().iter().zip(&v16) {
        assert_eq!(got, (f64::from(raw) / 65535.0) as f32);
    }
    let s = Texture::load(&p16, Encoding::Srgb, &MemoryBudget::default()).unwrap();
    let want = fray_mesh::texture::srgb_to_linear(40000.0 / 65535.0) as f32;
    assert_eq!(s.level(0).data()[2], want);
    // Grey reads as grey RGB with alpha 1.
    assert_eq!(
        g.nearest(0, centre(0, 1, 3, 2), Wrap::CLAMP),
        Vec4::new(1.0, 1.0, 1.0, 1.0)
    );
}

/// An OpenEXR file of RGBA f32 (negative and large values included) loads bit for bit, row 0
/// at the top; an RGB-only and a Y-only file load as RGB and grey.
#[test]
fn exr_round_trips() {
    use exr::prelude::*;
    let d = dir("exr");
    let path = d.join("rgba.exr");
    let (w, h) = (5usize, 3usize);
    let value = |x: usize, y: usize, c: usize| {
        (x as f32 - 2.0) * 0.75 + y as f32 * 100.0 + c as f32 * 0.125
    };
    let channels = SpecificChannels::rgba(|p: Vec2<usize>| {
        (
            value(p.x(), p.y(), 0),
            value(p.x(), p.y(), 1),
            value(p.x(), p.y(), 2),
            value(p.x(), p.y(), 3),
        )
    });
    Image::from_channels((w, h), channels)
        .write()
        .to_file(&path)
        .unwrap();
    let t = Texture::load(&path, crate::Encoding::Srgb, &MemoryBudget::default()).unwrap();
    assert_eq!(
        (t.width(), t.height(), t.channels()),
        (5, 3, Channels::Rgba)
    );
    for y in 0..h {
        for x in 0..w {
            let got = t.level(0).texel(x as u32, y as u32);
            let want = Vec4::from_array([0, 1, 2, 3].map(|c| value(x, y, c)));
            assert_eq!(got, want, "({x}, {y})");
            assert_eq!(
                t.bilinear(0, centre(x as u32, y as u32, 5, 3), Wrap::CLAMP),
                want
            );
        }
    }
    let rgb = d.join("rgb.exr");
    let channels = SpecificChannels::rgb(|p: Vec2<usize>| (p.x() as f32, p.y() as f32, 0.5f32));
    Image::from_channels((4, 2), channels)
        .write()
        .to_file(&rgb)
        .unwrap();
    let t = Texture::load(&rgb, crate::Encoding::Linear, &MemoryBudget::default()).unwrap();
    assert_eq!(t.channels(), Channels::Rgb);
    assert_eq!(t.level(0).texel(3, 1), Vec4::new(3.0, 1.0, 0.5, 1.0));
    let grey = d.join("y.exr");
    let channels = SpecificChannels::build()
        .with_channel("Y")
        .with_pixel_fn(|p: Vec2<usize>| (p.x() as f32 * 2.0,));
    Image::from_channels((3, 3), channels)
        .write()
        .to_file(&grey)
        .unwrap();
    let t = Texture::load(&grey, crate::Encoding::Srgb, &MemoryBudget::default()).unwrap();
    assert_eq!(t.channels(), Channels::Grey);
    assert_eq!(t.level(0).texel(2, 0), Vec4::new(4.0, 4.0, 4.0, 1.0));
}

/// CRC-32 (IEEE) for forging PNG chunks.
fn crc32(bytes: &[u8]) -> u32 {
    let mut c = 0xFFFF_FFFFu32;
    for &b in bytes {
        c ^= u32::from(b);
        for _ in 0..8 {
            c = if c & 1 != 0 {
                0xEDB8_8320 ^ (c >> 1)
            } else {
                c >> 1
            };
        }
    }
    !c
}

/// A PNG whose header claims `w × h` RGB texels, with a token IDAT: enough for the header to
/// be read, nothing like the data.
fn forged_png(w: u32, h: u32) -> Vec<u8> {
    let mut out = vec![0x89, b'P', b'N', b'G', 0x0D, 0x0A, 0x1A, 0x0A];
    let mut chunk = |kind: &[u8; 4], body: &[u8]| {
        out.extend((body.len() as u32).to_be_bytes());
        let mut typed = kind.to_vec();
        typed.extend(body);
        out.extend(&typed);
        out.extend(crc32(&typed).to_be_bytes());
    };
    let mut ihdr = Vec::new();
    ihdr.extend(w.to_be_bytes());
    ihdr.extend(h.to_be_bytes());
    ihdr.extend([8, 2, 0, 0, 0]);
    chunk(b"IHDR", &ihdr);
    chunk(b"IDAT", &[0x78, 0x9C, 0x03, 0x00, 0x00, 0x00, 0x00, 0x01]);
    chunk(b"IEND", &[]);
    out
}

/// Errors name the path and the reason: a missing file, a file that is not an image (text,
/// empty), an unknown extension, a header past the size limit or the budget (refused from the
/// header alone: no 50 GB allocation), an EXR over the budget; a mesh error wraps them.
#[test]
fn load_errors_name_the_path_and_the_reason() {
    let d = dir("errors");
    let budget = MemoryBudget::default();
    for ext in ["png", "exr"] {
        let missing = d.join(format!("missing.{ext}"));
        let (e, _) = err_text(&missing, &budget);
        assert!(matches!(e, TextureError::Io { .. }), "{ext}: {e}");
        for (name, bytes) in [
            ("junk", &b"this is not an image at all"[..]),
            ("empty", b""),
        ] {
            let p = d.join(format!("{name}.{ext}"));
            std::fs::write(&p, bytes).unwrap();
            let (e, text) = err_text(&p, &budget);
            assert!(matches!(e, TextureError::Format { .. }), "{ext}: {e}");
            assert!(text.contains("not a readable"), "{text}");
        }
    }
    let tiff = d.join("a.tiff");
    std::fs::write(&tiff, b"II*\0").unwrap();
    let (e, _) = err_text(&tiff, &budget);
    assert!(matches!(e, TextureError::UnsupportedExtension { .. }));
    // Past MAX_SIDE per side.
    let wide = d.join("wide.png");
    std::fs::write(&wide, forged_png(100_000, 2)).unwrap();
    let (e, text) = err_text(&wide, &budget);
    assert!(matches!(e, TextureError::Size { .. }), "{text}");
    assert!(text.contains("100000 × 2"), "{text}");
    // 60000² RGB: within the side limit, 57 GB of chain: over the 4 GiB default budget.
    let huge = d.join("huge.png");
    std::fs::write(&huge, forged_png(60_000, 60_000)).unwrap();
    let (e, text) = err_text(&huge, &MemoryBudget::new(4 << 30));
    assert!(matches!(e, TextureError::Budget { .. }), "{text}");
    assert!(
        text.contains("60000 × 60000") && text.contains("mip chain"),
        "{text}"
    );
    // A real PNG and an EXR under a tiny budget.
    let small = d.join("small.png");
    image::RgbImage::new(32, 32).save(&small).unwrap();
    let (e, _) = err_text(&small, &MemoryBudget::new(2000));
    assert!(matches!(e, TextureError::Budget { .. }));
    let exr_path = d.join("small.exr");
    {
        use exr::prelude::*;
        let channels = SpecificChannels::rgb(|_p: Vec2<usize>| (0.0f32, 0.0f32, 0.0f32));
        Image::from_channels((32, 32), channels)
            .write()
            .to_file(&exr_path)
            .unwrap();
    }
    let (e, text) = err_text(&exr_path, &MemoryBudget::new(2000));
    assert!(matches!(e, TextureError::Budget { .. }), "{text}");
    assert!(text.contains("OpenEXR"), "{text}");
    // A mesh error carries the texture's.
    let m: MeshError = Texture::load(&d.join("missing.png"), Encoding::Srgb, &budget)
        .unwrap_err()
        .into();
    assert!(m.to_string().contains("missing.png"), "{m}");
}

/// A real photograph: the cat loads as 451 × 300 RGB with 10 levels; its top-left and
/// bottom-right pixels (by the decoder) are read at uv (0, 1) and (1, 0) of the convention,
/// sRGB-decoded; the odd-sized chain keeps its mean to 1e-6. The bricks: 512² grey.
#[test]
fn real_photographs_load_upright() {
    let path = data("chelsea.png");
    let t = Texture::load(&path, Encoding::Srgb, &MemoryBudget::default()).unwrap();
    assert_eq!(
        (t.width(), t.height(), t.channels()),
        (451, 300, Channels::Rgb)
    );
    assert_eq!(t.level_count(), 10);
    let raw = image::open(&path).unwrap().to_rgb8();
    let decoded = |x: u32, y: u32| {
        let p = raw.get_pixel(x, y).0;
        Vec4::new(srgb(p[0]) as f32, srgb(p[1]) as f32, srgb(p[2]) as f32, 1.0)
    };
    let eps = 1e-9;
    let near = |a: Vec4, b: Vec4| (a - b).abs().max_element() < 1e-6;
    assert!(near(
        t.nearest(0, DVec2::new(eps, 1.0 - eps), Wrap::CLAMP),
        decoded(0, 0)
    ));
    assert!(near(
        t.nearest(0, DVec2::new(1.0 - eps, eps), Wrap::CLAMP),
        decoded(450, 299)
    ));
    assert!(near(
        t.bilinear(0, centre(200, 100, 451, 300), Wrap::CLAMP),
        decoded(200, 100)
    ));
    let base = t.level(0).mean();
    for l in t.levels() {
        let m = l.mean();
        assert!(
            (0..3).all(|c| (m[c] - base[c]).abs() < 1e-6),
            "{m:?} vs {base:?}"
        );
    }
    let b = Texture::load(&data("brick.png"), Encoding::Srgb, &MemoryBudget::default()).unwrap();
    assert_eq!(
        (b.width(), b.height(), b.channels(), b.level_count()),
        (512, 512, Channels::Grey, 10)
    );
}

/// Planar, spherical and cylindrical mappings at known points, with their scales.
#[test]
fn mappings_map_known_points() {
    let planar = Planar::new(
        DVec3::new(1.0, 0.0, 0.0),
        DVec3::X,
        DVec3::Y,
        DVec2::new(0.5, 2.0),
    )
    .unwrap();
    let m = Mapping::Planar(planar);
    let p = m.project(DVec3::new(3.0, 0.25, 9.0), DVec3::Z);
    assert_eq!(p.main_uv(), DVec2::new(1.0, 0.5));
    assert_eq!(p.uv_per_world, 2.0);
    assert_eq!(p.weight, [1.0, 0.0, 0.0]);

    let s =
        Mapping::Spherical(Spherical::new(DVec3::ZERO, DVec3::Y, DVec3::X, DVec2::ONE).unwrap());
    let uv = |m: &Mapping, p: DVec3| m.project(p, DVec3::ZERO).main_uv();
    let close = |a: DVec2, b: DVec2| (a - b).length() < 1e-12;
    assert!(close(uv(&s, DVec3::X * 2.0), DVec2::new(0.0, 0.5)));
    // East of the seam (pole × seam = −z) is a quarter turn: u = 0.25.
    assert!(close(uv(&s, -DVec3::Z), DVec2::new(0.25, 0.5)));
    assert!(close(uv(&s, -DVec3::X), DVec2::new(0.5, 0.5)));
    assert!(close(uv(&s, DVec3::Z), DVec2::new(0.75, 0.5)));
    assert!(close(uv(&s, DVec3::Y * 3.0), DVec2::new(0.0, 1.0)));
    assert!(close(uv(&s, -DVec3::Y), DVec2::new(0.0, 0.0)));
    let on_equator = s.project(DVec3::X * 2.0, DVec3::X);
    assert!((on_equator.uv_per_world - 1.0 / (2.0 * std::f64::consts::PI)).abs() < 1e-15);

    let c = Mapping::Cylindrical(
        Cylindrical::new(DVec3::new(0.0, 1.0, 0.0), DVec3::Y, DVec3::X, 2.0, 0.5).unwrap(),
    );
    assert!(close(
        uv(&c, DVec3::new(3.0, 5.0, 0.0)),
        DVec2::new(0.0, 2.0)
    ));
    assert!(close(
        uv(&c, DVec3::new(0.0, 1.0, -2.0)),
        DVec2::new(0.5, 0.0)
    ));
    let at = c.project(DVec3::new(0.0, 0.0, 4.0), DVec3::Z);
    assert!((at.uv_per_world - 0.5).abs() < 1e-15); // max(0.5, 2/(2π·4))
}

/// Triplanar: the face of each axis is upright and unmirrored, a normal along an axis takes
/// that face alone, weights sum to 1 and follow `|n|^sharpness`.
#[test]
fn triplanar_faces_and_weights() {
    let t = Triplanar::new(DVec3::ZERO, 0.5, 4.0).unwrap();
    let m = Mapping::Triplanar(t);
    let p = DVec3::new(2.0, 4.0, 6.0);
    let cases = [
        (DVec3::X, 0, DVec2::new(-3.0, 2.0)),
        (-DVec3::X, 0, DVec2::new(3.0, 2.0)),
        (DVec3::Y, 1, DVec2::new(1.0, -3.0)),
        (-DVec3::Y, 1, DVec2::new(1.0, 3.0)),
        (DVec3::Z, 2, DVec2::new(1.0, 2.0)),
        (-DVec3::Z, 2, DVec2::new(-1.0, 2.0)),
    ];
    for (n, k, want) in cases {
        let q = m.project(p, n);
        assert_eq!(q.weight[k], 1.0, "{n}");
        assert_eq!(q.uv[k], want, "{n}");
        assert_eq!(q.main_uv(), want);
    }
    let w = t.weights(DVec3::new(1.0, 2.0, 0.0));
    assert!((w[0] - 1.0 / 17.0).abs() < 1e-15 && (w[1] - 16.0 / 17.0).abs() < 1e-15);
    assert_eq!(t.weights(DVec3::ZERO), [1.0 / 3.0; 3]);
    let sharp = Triplanar::new(DVec3::ZERO, 1.0, 1e6).unwrap();
    assert_eq!(sharp.weights(DVec3::new(0.6, 0.8, 0.0)), [0.0, 1.0, 0.0]);
    // A constant texture reads the same through the blend.
    let tex = Texture::from_rgb(4, 4, vec![0.25; 48]).unwrap();
    let c = m.project(p, DVec3::ONE).sample(&tex, 0.01, Wrap::REPEAT);
    assert!((c - Vec4::new(0.25, 0.25, 0.25, 1.0)).abs().max_element() < 1e-6);
}

/// Degenerate input gives stated finite answers: a zero normal, the sphere's centre and
/// poles, the cylinder's axis; bad parameters are refused naming the field.
#[test]
fn degenerate_input_is_finite_and_bad_parameters_are_named() {
    let s = Spherical::new(DVec3::ONE, DVec3::Y, DVec3::X, DVec2::ONE).unwrap();
    let at_centre = s.project(DVec3::ONE);
    assert_eq!(at_centre.main_uv(), DVec2::new(0.0, 0.5));
    assert_eq!(at_centre.uv_per_world, f64::MAX);
    let pole = s.project(DVec3::new(1.0, 3.0, 1.0));
    assert!(pole.main_uv().is_finite() && pole.uv_per_world == f64::MAX);
    let c = Cylindrical::new(DVec3::ZERO, DVec3::Y, DVec3::X, 1.0, 1.0).unwrap();
    let on_axis = c.project(DVec3::new(0.0, 2.0, 0.0));
    assert_eq!(on_axis.main_uv(), DVec2::new(0.0, 2.0));
    assert_eq!(on_axis.uv_per_world, f64::MAX);
    // The footprint of an infinite scale is finite, and reads the coarsest level.
    let width = Footprint::default().uv_width(0.01, 1.0, f64::MAX);
    assert!(width.is_finite());
    let tex = indexed(8, 8);
    assert_eq!(
        tex.sample(DVec2::ZERO, width, Wrap::REPEAT),
        tex.level(3).texel(0, 0)
    );

    let named = |e: TextureError, field: &str| {
        let text = e.to_string();
        assert!(text.starts_with(field), "{text}");
    };
    named(
        Planar::new(DVec3::ZERO, DVec3::X, DVec3::X * 2.0, DVec2::ONE).unwrap_err(),
        "v_axis",
    );
    named(
        Planar::new(DVec3::ZERO, DVec3::ZERO, DVec3::Y, DVec2::ONE).unwrap_err(),
        "u_axis",
    );
    named(
        Planar::new(DVec3::NAN, DVec3::X, DVec3::Y, DVec2::ONE).unwrap_err(),
        "origin",
    );
    named(
        Planar::new(DVec3::ZERO, DVec3::X, DVec3::Y, DVec2::new(1.0, 0.0)).unwrap_err(),
        "scale.y",
    );
    named(
        Spherical::new(DVec3::ZERO, DVec3::Y, -DVec3::Y, DVec2::ONE).unwrap_err(),
        "seam",
    );
    named(
        Cylindrical::new(DVec3::ZERO, DVec3::Y, DVec3::X, -1.0, 1.0).unwrap_err(),
        "repeat_u",
    );
    named(
        Triplanar::new(DVec3::ZERO, 1.0, f64::NAN).unwrap_err(),
        "sharpness",
    );
    named(
        Triplanar::new(DVec3::ZERO, f64::INFINITY, 1.0).unwrap_err(),
        "scale",
    );
}

fn any_vec(range: f64) -> impl Strategy<Value = DVec3> {
    prop_oneof![
        3 => (-range..range, -range..range, -range..range).prop_map(|(x, y, z)| DVec3::new(x, y, z)),
        1 => Just(DVec3::ZERO),
        1 => (-range..range).prop_map(|y| DVec3::new(0.0, y, 0.0)),
    ]
}

proptest! {
    /// Every mapping gives finite uvs, non-negative weights summing to 1 (1e-12) and a finite
    /// positive scale on any finite point and normal — zero normals, centres and axes included.
    #[test]
    fn mappings_are_finite_everywhere(
        p in any_vec(1e6),
        n in any_vec(10.0),
        axis in any_vec(1.0).prop_filter("non-zero", |a| a.length() > 1e-3),
        sharpness in 0.0..64.0f64,
    ) {
        let mut maps = vec![Mapping::Triplanar(Triplanar::new(DVec3::ZERO, 0.37, sharpness).unwrap())];
        let seam = if axis.normalize().dot(DVec3::X).abs() < 0.9 { DVec3::X } else { DVec3::Z };
        maps.push(Mapping::Spherical(Spherical::new(DVec3::ZERO, axis, seam, DVec2::new(2.0, 1.0)).unwrap()));
        maps.push(Mapping::Cylindrical(Cylindrical::new(DVec3::ZERO, axis, seam, 3.0, 0.1).unwrap()));
        maps.push(Mapping::Planar(Planar::new(DVec3::ONE, axis, seam, DVec2::splat(0.2)).unwrap()));
        for m in &maps {
            let q = m.project(p, n);
            prop_assert!(q.uv.iter().all(|uv| uv.is_finite()), "{m:?} {q:?}");
            prop_assert!(q.weight.iter().all(|&w| (0.0..=1.0).contains(&w)), "{q:?}");
            prop_assert!((q.weight.iter().sum::<f64>() - 1.0).abs() < 1e-12, "{q:?}");
            prop_assert!(q.uv_per_world.is_finite() && q.uv_per_world > 0.0, "{q:?}");
            let w = Footprint::default().uv_width(1e-3, n.normalize_or_zero().y, q.uv_per_world);
            prop_assert!(w.is_finite() && w >= 0.0);
        }
    }
}

/// Ramps: validated stops (sorted, finite, non-empty), linear between, constant past the ends,
/// a step at equal keys; the terrain ramp lays the slope colour over the height colour by its
/// alpha.
#[test]
fn ramps_interpolate_and_validate() {
    let (a, b, c) = (
        Vec4::new(0.0, 0.0, 1.0, 1.0),
        Vec4::new(0.0, 1.0, 0.0, 1.0),
        Vec4::ONE,
    );
    let r = Ramp::new(vec![(0.0, a), (10.0, b), (10.0, c), (20.0, c)]).unwrap();
    assert_eq!(r.at(-5.0), a);
    assert_eq!(r.at(5.0), a.lerp(b, 0.5));
    assert_eq!(r.at(9.999), a.lerp(b, 0.9999));
    assert_eq!(r.at(10.0), c);
    assert_eq!(r.at(1e9), c);
    assert_eq!(r.at(f64::NAN), a);
    assert_eq!(r.stops().count(), 4);
    for (stops, says) in [
        (vec![], "at least one"),
        (vec![(1.0, a), (0.0, b)], "sorted"),
        (vec![(f64::NAN, a)], "not finite"),
        (vec![(0.0, Vec4::splat(f32::INFINITY))], "colour"),
    ] {
        let e = Ramp::new(stops).unwrap_err().to_string();
        assert!(e.starts_with("ramp") && e.contains(says), "{e}");
    }
    let rock = Vec4::new(0.5, 0.5, 0.5, 0.0);
    let terrain = TerrainRamp {
        height: Ramp::new(vec![(0.0, a), (100.0, b)]).unwrap(),
        slope: Some(
            Ramp::new(vec![
                (30f64.to_radians(), rock),
                (45f64.to_radians(), rock.with_w(1.0)),
            ])
            .unwrap(),
        ),
    };
    assert_eq!(terrain.colour(50.0, DVec3::Y), Vec3::new(0.0, 0.5, 0.5));
    let steep = DVec3::new(1.0, 1.0, 0.0); // 45°
    assert!(
        (terrain.colour(50.0, steep) - Vec3::splat(0.5))
            .abs()
            .max_element()
            < 1e-6
    );
    assert!((TerrainRamp::slope_of(steep, DVec3::Y) - std::f64::consts::FRAC_PI_4).abs() < 1e-15);
    assert_eq!(TerrainRamp::slope_of(DVec3::ZERO, DVec3::Y), 0.0);
    assert_eq!(TerrainRamp::slope_of(DVec3::splat(f64::NAN), DVec3::Y), 0.0);
}

/// The drape: an image of the map's size puts texel `(i, j)` exactly on sample `(i, j)`
/// (bilinear, clamp); past the map's edge the edge texels; the scale is 1 / the shorter side.
#[test]
fn a_drape_lines_up_with_the_map() {
    let (cols, rows) = (5, 3);
    let image = indexed(cols, rows);
    let drape = Drape::new(cols, rows).unwrap();
    for j in 0..rows {
        for i in 0..cols {
            let uv = drape.uv(f64::from(i), f64::from(j));
            assert_eq!(image.bilinear(0, uv, Drape::WRAP), texel(i, j));
        }
    }
    assert_eq!(
        image.bilinear(0, drape.uv(-3.0, 7.0), Drape::WRAP),
        texel(0, 2)
    );
    assert_eq!(drape.uv_per_map_unit(), 1.0 / 3.0);
    assert!(Drape::new(0, 3).is_err());
}
