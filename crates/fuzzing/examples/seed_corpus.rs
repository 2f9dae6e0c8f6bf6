//! Writes the seed corpus, `fuzz/corpus/<target>/`, from the repository's `data/`: small crops of
//! its height map, textures, meshes and CT volume in every format and variant the loaders read,
//! and its scenes with their assets swapped for those crops (cloud grids shrunk), as scene
//! bundles. Run from anywhere: `cargo run -p fray-fuzzing --example seed_corpus`. It replaces
//! the files it writes and leaves `fuzz/regressions/` alone.

use exr::prelude as x;
use fray_fuzzing::{Bundle, MAIN_FILE, Target};
use image::{DynamicImage, ImageFormat};
use std::path::{Path, PathBuf};

fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../..")
}

fn main() {
    let data = root().join("data");
    let dem = image::open(data.join("terrain/jacksboro_fault_dem.png")).expect("the DEM");
    let brick = image::open(data.join("textures/brick.png")).expect("brick.png");
    let chelsea = image::open(data.join("textures/chelsea.png")).expect("chelsea.png");
    // A 16 × 12 crop of the DEM across the fault (raw 16-bit metres).
    let dem = dem.crop_imm(190, 160, 16, 12).into_luma16();
    let heights: Vec<f32> = dem.pixels().map(|p| f32::from(p.0[0])).collect();
    let (dw, dh) = (16usize, 12usize);

    let mut corpus = Corpus::default();

    // Height maps: PNG 16- and 8-bit grey.
    let dem_png = png(&DynamicImage::ImageLuma16(dem.clone()));
    corpus.add(Target::HeightmapPng, "dem16.png", dem_png.clone());
    let dem8 = DynamicImage::ImageLuma16(dem.clone())
        .crop_imm(0, 0, 6, 5)
        .into_luma8();
    corpus.add(
        Target::HeightmapPng,
        "dem8.png",
        png(&DynamicImage::ImageLuma8(dem8)),
    );
    let tiny = DynamicImage::ImageLuma16(dem.clone()).crop_imm(4, 4, 2, 2);
    corpus.add(Target::HeightmapPng, "dem16_2x2.png", png(&tiny));

    // Height maps: OpenEXR, one channel in each compression, f16 and f32, lines and tiles.
    use x::Compression as C;
    let z = |name: &str, half: bool| channel(name, &heights, half);
    let dem_exr = exr((dw, dh), C::Uncompressed, None, vec![z("Z", false)]);
    corpus.add(Target::HeightmapExr, "z_f32_raw.exr", dem_exr.clone());
    corpus.add(
        Target::HeightmapExr,
        "z_f32_zip16.exr",
        exr((dw, dh), C::ZIP16, None, vec![z("Z", false)]),
    );
    corpus.add(
        Target::HeightmapExr,
        "y_f16_zip1.exr",
        exr((dw, dh), C::ZIP1, None, vec![z("Y", true)]),
    );
    corpus.add(
        Target::HeightmapExr,
        "h_f32_piz.exr",
        exr((dw, dh), C::PIZ, None, vec![z("height", false)]),
    );
    corpus.add(
        Target::HeightmapExr,
        "z_f32_pxr24.exr",
        exr((dw, dh), C::PXR24, None, vec![z("Z", false)]),
    );
    corpus.add(
        Target::HeightmapExr,
        "z_f16_b44_tiles.exr",
        exr((dw, dh), C::B44, Some(8), vec![z("Z", true)]),
    );
    corpus.add(
        Target::HeightmapExr,
        "rgb_f32_rle_tiles.exr",
        exr(
            (dw, dh),
            C::RLE,
            Some(4),
            vec![z("R", false), z("G", false), z("B", false)],
        ),
    );

    // Height maps: .npy in each element type, version 1.0 and 2.0 headers.
    let bytes =
        |v: &[f32], f: fn(f32) -> Vec<u8>| v.iter().flat_map(|&h| f(h)).collect::<Vec<u8>>();
    let dem_npy = fray_terrain::npy::encode(
        "<f4",
        dh,
        dw,
        &bytes(&heights, |h| h.to_le_bytes().to_vec()),
    );
    corpus.add(Target::HeightmapNpy, "dem_f4.npy", dem_npy.clone());
    let small: Vec<f32> = heights[..20].to_vec();
    let i2 = bytes(&small, |h| (h as i16).to_le_bytes().to_vec());
    corpus.add(
        Target::HeightmapNpy,
        "dem_i2.npy",
        fray_terrain::npy::encode("<i2", 4, 5, &i2),
    );
    let u2 = bytes(&small[..12], |h| (h as u16).to_le_bytes().to_vec());
    corpus.add(
        Target::HeightmapNpy,
        "dem_u2.npy",
        fray_terrain::npy::encode("<u2", 3, 4, &u2),
    );
    let f8 = bytes(&small[..9], |h| f64::from(h).to_le_bytes().to_vec());
    let f8_v1 = fray_terrain::npy::encode("<f8", 3, 3, &f8);
    corpus.add(Target::HeightmapNpy, "dem_f8.npy", f8_v1.clone());
    corpus.add(Target::HeightmapNpy, "dem_f8_v2.npy", npy_v2(&f8_v1));

    // Meshes: cuts of the bunny (positions only), the polygonised turboprop (with normals) and
    // the Boeing; a quad and negative indices; UVs.
    let bunny = cut_obj(&data.join("meshes/bunny00.obj"), 24);
    corpus.add(Target::Obj, "bunny_cut.obj", bunny.clone().into_bytes());
    let turboprop = cut_obj(&data.join("meshes/turboprop_polygonised.obj"), 12);
    corpus.add(
        Target::Obj,
        "turboprop_cut.obj",
        turboprop.clone().into_bytes(),
    );
    let boeing = cut_obj(&data.join("meshes/boeing.obj"), 16);
    corpus.add(Target::Obj, "boeing_cut.obj", boeing.clone().into_bytes());
    corpus.add(
        Target::Obj,
        "bunny_negative_quads.obj",
        negative_quads(&bunny).into_bytes(),
    );
    corpus.add(
        Target::Obj,
        "turboprop_uvs.obj",
        with_uvs(&turboprop).into_bytes(),
    );

    // Volumes: a 4 × 4 × 4 crop of the CT skull, little-endian, and 3 × 2 × 2 big-endian.
    let skull = std::fs::read(data.join("volumes/skull_2.9.inr")).expect("the skull");
    let voxel = |x: usize, y: usize, z: usize| {
        let at = 256 + 4 * (x + 64 * (y + 64 * z));
        f32::from_le_bytes([skull[at], skull[at + 1], skull[at + 2], skull[at + 3]])
    };
    let crop = |n: [usize; 3], from: [usize; 3]| {
        let mut v = Vec::new();
        for z in 0..n[2] {
            for y in 0..n[1] {
                for x in 0..n[0] {
                    v.push(voxel(from[0] + x, from[1] + y, from[2] + z));
                }
            }
        }
        v
    };
    let skull_inr = inr([4, 4, 4], &crop([4, 4, 4], [30, 30, 30]), false);
    corpus.add(Target::Inr, "skull_4.inr", skull_inr.clone());
    corpus.add(
        Target::Inr,
        "skull_3x2x2_be.inr",
        inr([3, 2, 2], &crop([3, 2, 2], [20, 32, 28]), true),
    );

    // Textures: PNG grey, grey + alpha, RGB, RGBA, 8 and 16 bits.
    let brick8 = brick.crop_imm(100, 100, 8, 8);
    let cat8 = chelsea.crop_imm(200, 120, 8, 8);
    let brick_png = png(&DynamicImage::ImageLuma8(brick8.to_luma8()));
    corpus.add(Target::TexturePng, "brick_l8.png", brick_png.clone());
    corpus.add(
        Target::TexturePng,
        "brick_la8.png",
        png(&DynamicImage::ImageLumaA8(brick8.to_luma_alpha8())),
    );
    corpus.add(
        Target::TexturePng,
        "brick_l16.png",
        png(&DynamicImage::ImageLuma16(brick8.to_luma16())),
    );
    corpus.add(
        Target::TexturePng,
        "chelsea_rgb8.png",
        png(&DynamicImage::ImageRgb8(cat8.to_rgb8())),
    );
    corpus.add(
        Target::TexturePng,
        "chelsea_rgba8_5x3.png",
        png(&DynamicImage::ImageRgba8(
            cat8.crop_imm(0, 0, 5, 3).to_rgba8(),
        )),
    );
    corpus.add(
        Target::TexturePng,
        "chelsea_rgb16.png",
        png(&DynamicImage::ImageRgb16(cat8.to_rgb16())),
    );

    // Textures: OpenEXR RGB, RGBA, Y and one unnamed channel.
    let rgb = cat8.to_rgb32f();
    let plane = |c: usize| -> Vec<f32> { rgb.pixels().map(|p| p.0[c]).collect() };
    let (r, g, b) = (plane(0), plane(1), plane(2));
    let alpha: Vec<f32> = (0..64).map(|i| i as f32 / 63.0).collect();
    let cat_exr = exr(
        (8, 8),
        C::ZIP1,
        None,
        vec![
            channel("R", &r, true),
            channel("G", &g, true),
            channel("B", &b, true),
        ],
    );
    corpus.add(
        Target::TextureExr,
        "chelsea_rgb_f16_zip1.exr",
        cat_exr.clone(),
    );
    corpus.add(
        Target::TextureExr,
        "chelsea_rgba_f32_piz_tiles.exr",
        exr(
            (8, 8),
            C::PIZ,
            Some(4),
            vec![
                channel("R", &r, false),
                channel("G", &g, false),
                channel("B", &b, false),
                channel("A", &alpha, false),
            ],
        ),
    );
    let grey: Vec<f32> = brick8.to_luma32f().pixels().map(|p| p.0[0]).collect();
    corpus.add(
        Target::TextureExr,
        "brick_y_f32_raw.exr",
        exr(
            (8, 8),
            C::Uncompressed,
            None,
            vec![channel("Y", &grey, false)],
        ),
    );
    corpus.add(
        Target::TextureExr,
        "brick_l_f16_rle.exr",
        exr((8, 8), C::RLE, None, vec![channel("L", &grey, true)]),
    );

    // Scenes: every data scene with its assets swapped for the crops above.
    let assets: [(&str, &str, &[u8]); 7] = [
        ("../terrain/jacksboro_fault_dem.png", "dem.png", &dem_png),
        ("../meshes/bunny00.obj", "bunny.obj", bunny.as_bytes()),
        (
            "../meshes/turboprop_polygonised.obj",
            "turboprop.obj",
            turboprop.as_bytes(),
        ),
        ("../meshes/boeing.obj", "boeing.obj", boeing.as_bytes()),
        ("../volumes/skull_2.9.inr", "skull.inr", &skull_inr),
        ("../textures/brick.png", "brick.png", &brick_png),
        ("\"turboprop.ron\"", "turboprop.ron", &[]),
    ];
    let turboprop_ron = std::fs::read(data.join("scenes/turboprop.ron")).expect("turboprop.ron");
    let mut scenes: Vec<_> = std::fs::read_dir(data.join("scenes"))
        .expect("data/scenes")
        .map(|e| e.expect("an entry").path())
        .filter(|p| p.extension().is_some_and(|e| e == "ron"))
        .collect();
    scenes.sort();
    for path in &scenes {
        let mut text = std::fs::read_to_string(path).expect("a scene");
        // Cloud layers baked at a few cells, so a scene input loads in milliseconds.
        let shrunk = [
            ("(192, 24, 192)", "(12, 3, 12)"),
            ("(128, 96, 128)", "(8, 6, 8)"),
        ];
        for (big, small) in shrunk {
            text = text.replace(
                &format!("resolution: {big}"),
                &format!("resolution: {small}"),
            );
        }
        // A cut at 800 m leaves no cell of the crop: cut at its median instead.
        let mut sorted = heights.clone();
        sorted.sort_by(f32::total_cmp);
        text = text.replace(
            "threshold: 800",
            &format!("threshold: {}", sorted[sorted.len() / 2]),
        );
        let grids = text.matches("resolution: (").count();
        let small = shrunk
            .iter()
            .map(|(_, s)| text.matches(&format!("resolution: {s}")).count());
        assert_eq!(
            grids,
            small.sum::<usize>(),
            "{}: a grid left unshrunk",
            path.display()
        );
        let mut files = Vec::new();
        for (from, to, bytes) in assets {
            if !text.contains(from) {
                continue;
            }
            if to == "turboprop.ron" {
                files.push((to.to_owned(), turboprop_ron.clone()));
            } else {
                text = text.replace(from, to);
                files.push((to.to_owned(), bytes.to_vec()));
            }
        }
        assert!(
            !text.contains("../"),
            "{}: an asset left outside the bundle",
            path.display()
        );
        files.insert(0, (MAIN_FILE.to_owned(), text.into_bytes()));
        let name = path.file_name().and_then(|n| n.to_str()).expect("a name");
        corpus.add(Target::Scene, name, Bundle { files }.join());
    }
    // The height map in the other two formats, and two levels of includes.
    let terrain =
        std::fs::read_to_string(data.join("scenes/terrain_high.ron")).expect("terrain_high");
    for (file, bytes) in [("dem.exr", dem_exr), ("dem.npy", dem_npy)] {
        let text = terrain.replace("../terrain/jacksboro_fault_dem.png", file);
        let files = vec![
            (MAIN_FILE.to_owned(), text.into_bytes()),
            (file.to_owned(), bytes),
        ];
        corpus.add(
            Target::Scene,
            &format!("terrain_high_{}.ron", &file[4..]),
            Bundle { files }.join(),
        );
    }
    let nested = vec![
        (
            MAIN_FILE.to_owned(),
            b"Scene(\n  include: [\"parts.ron\"],\n  image: (width: 64, height: 48),\n  camera: Pinhole(eye: (0, 1, -4), look_at: (0, 0, 0), up: (0, 1, 0), fov_y: 40),\n  lights: [ Sun(direction: (0, 1, -1), irradiance: (3, 3, 3)) ],\n)\n".to_vec(),
        ),
        (
            "parts.ron".to_owned(),
            b"Scene(\n  include: [\"bunny.ron\"],\n  materials: { \"red\": (diffuse: (0.8, 0.1, 0.1)) },\n  objects: [ (name: \"ball\", material: \"red\", shape: Sphere(center: (1, 0, 0), radius: 0.5)) ],\n)\n".to_vec(),
        ),
        (
            "bunny.ron".to_owned(),
            b"Scene(\n  materials: { \"clay\": (diffuse: (0.7, 0.6, 0.5)) },\n  objects: [ (name: \"bunny\", material: \"clay\", shape: Mesh(path: \"bunny.obj\")) ],\n)\n".to_vec(),
        ),
        ("bunny.obj".to_owned(), bunny.into_bytes()),
    ];
    corpus.add(
        Target::Scene,
        "nested_includes.ron",
        Bundle { files: nested }.join(),
    );
    corpus.write();
}

/// The seeds to write, by target.
#[derive(Default)]
struct Corpus {
    files: Vec<(Target, String, Vec<u8>)>,
}

impl Corpus {
    fn add(&mut self, target: Target, name: &str, bytes: Vec<u8>) {
        self.files.push((target, name.to_owned(), bytes));
    }

    fn write(&self) {
        for target in Target::ALL {
            let dir = root().join("fuzz/corpus").join(target.name());
            let _ = std::fs::remove_dir_all(&dir);
            std::fs::create_dir_all(&dir).expect("the corpus folder");
        }
        for (target, name, bytes) in &self.files {
            let path = root().join("fuzz/corpus").join(target.name()).join(name);
            std::fs::write(&path, bytes).expect("a seed");
            println!(
                "{:>6} bytes  fuzz/corpus/{}/{name}",
                bytes.len(),
                target.name()
            );
        }
    }
}

fn png(image: &DynamicImage) -> Vec<u8> {
    let mut out = std::io::Cursor::new(Vec::new());
    image
        .write_to(&mut out, ImageFormat::Png)
        .expect("PNG encoding");
    out.into_inner()
}

fn channel(name: &str, values: &[f32], half: bool) -> x::AnyChannel<x::FlatSamples> {
    let samples = if half {
        x::FlatSamples::F16(values.iter().map(|&v| x::f16::from_f32(v)).collect())
    } else {
        x::FlatSamples::F32(values.to_vec())
    };
    x::AnyChannel::new(name, samples)
}

/// An OpenEXR file of one layer: `tile` = `Some(side)` for tiles, else scan lines.
fn exr(
    size: (usize, usize),
    compression: x::Compression,
    tile: Option<usize>,
    channels: Vec<x::AnyChannel<x::FlatSamples>>,
) -> Vec<u8> {
    use x::WritableImage;
    let encoding = x::Encoding {
        compression,
        blocks: tile.map_or(x::Blocks::ScanLines, |s| x::Blocks::Tiles(x::Vec2(s, s))),
        line_order: x::LineOrder::Increasing,
    };
    let channels = x::AnyChannels::sort(x::SmallVec::from_vec(channels));
    let layer = x::Layer::new(size, x::LayerAttributes::default(), encoding, channels);
    let mut out = std::io::Cursor::new(Vec::new());
    x::Image::from_layer(layer)
        .write()
        .to_buffered(&mut out)
        .expect("OpenEXR encoding");
    out.into_inner()
}

/// A version 1.0 `.npy` file rewritten with a version 2.0 header (a `u32` header length).
fn npy_v2(v1: &[u8]) -> Vec<u8> {
    let len = u16::from_le_bytes([v1[8], v1[9]]);
    let mut out = b"\x93NUMPY\x02\x00".to_vec();
    out.extend_from_slice(&u32::from(len).to_le_bytes());
    out.extend_from_slice(&v1[10..]);
    out
}

/// The first `faces` faces of an OBJ file with the vertices (and normals, where a face names
/// them as `v//vn`) they use, renumbered from 1.
fn cut_obj(path: &Path, faces: usize) -> String {
    let text = std::fs::read_to_string(path).expect("an OBJ file");
    let (mut v, mut vn) = (Vec::new(), Vec::new());
    let mut f = Vec::new();
    for line in text.lines() {
        match line.split_whitespace().next() {
            Some("v") => v.push(line),
            Some("vn") => vn.push(line),
            Some("f") if f.len() < faces => f.push(line),
            _ => {}
        }
    }
    let mut used: Vec<usize> = Vec::new();
    let mut out_faces = Vec::new();
    for line in f {
        let mut corners = Vec::new();
        for corner in line.split_whitespace().skip(1) {
            let i: usize = corner
                .split('/')
                .next()
                .and_then(|i| i.parse().ok())
                .expect("an index");
            let k = used.iter().position(|&u| u == i).unwrap_or_else(|| {
                used.push(i);
                used.len() - 1
            }) + 1;
            corners.push(if corner.contains("//") {
                format!("{k}//{k}")
            } else {
                k.to_string()
            });
        }
        out_faces.push(format!("f {}", corners.join(" ")));
    }
    let name = path.file_name().and_then(|n| n.to_str()).expect("a name");
    let mut out = format!("# the first {faces} faces of data/meshes/{name}\n");
    for &i in &used {
        out.push_str(v[i - 1]);
        out.push('\n');
    }
    if !vn.is_empty() {
        for &i in &used {
            out.push_str(vn[i - 1]);
            out.push('\n');
        }
    }
    out.push_str(&out_faces.join("\n"));
    out.push('\n');
    out
}

/// Pairs of triangles as quads (`f a b c d`), indices counted from the end (`-1` the last).
fn negative_quads(obj: &str) -> String {
    let count = obj.lines().filter(|l| l.starts_with("v ")).count() as i64;
    let faces: Vec<Vec<i64>> = obj
        .lines()
        .filter(|l| l.starts_with("f "))
        .map(|l| {
            l.split_whitespace()
                .skip(1)
                .map(|i| i.parse().expect("an index"))
                .collect()
        })
        .collect();
    let mut out: String = obj
        .lines()
        .filter(|l| !l.starts_with("f "))
        .map(|l| format!("{l}\n"))
        .collect();
    for pair in faces.chunks(2) {
        let mut corners = pair[0].clone();
        if let Some(next) = pair.get(1) {
            corners.push(next[2]);
        }
        let negative: Vec<String> = corners
            .iter()
            .map(|i| (i - count - 1).to_string())
            .collect();
        out.push_str(&format!("f {}\n", negative.join(" ")));
    }
    out
}

/// Texture coordinates from the positions' x and z, every corner `v/vt/vn`.
fn with_uvs(obj: &str) -> String {
    let mut out = String::new();
    for line in obj.lines() {
        if let Some(rest) = line.strip_prefix("v ") {
            let p: Vec<&str> = rest.split_whitespace().collect();
            out.push_str(&format!("{line}\nvt {} {}\n", p[0], p[2]));
        } else if let Some(rest) = line.strip_prefix("f ") {
            let corners: Vec<String> = rest
                .split_whitespace()
                .map(|c| c.replace("//", &format!("/{}/", c.split('/').next().unwrap_or("1"))))
                .collect();
            out.push_str(&format!("f {}\n", corners.join(" ")));
        } else {
            out.push_str(line);
            out.push('\n');
        }
    }
    out
}

/// An INRIMAGE-4 file: the header padded to 256 bytes, then the voxels.
fn inr(size: [usize; 3], voxels: &[f32], big_endian: bool) -> Vec<u8> {
    let cpu = if big_endian { "sun" } else { "decm" };
    let mut header = format!(
        "#INRIMAGE-4#{{\nXDIM={}\nYDIM={}\nZDIM={}\nVDIM=1\nTYPE=float\nPIXSIZE=32 bits\nCPU={cpu}\nVX=3.943050\nVY=3.943050\nVZ=3.650790\n",
        size[0], size[1], size[2]
    )
    .into_bytes();
    header.resize(256 - 4, b'\n');
    header.extend_from_slice(b"##}\n");
    for v in voxels {
        header.extend_from_slice(&if big_endian {
            v.to_be_bytes()
        } else {
            v.to_le_bytes()
        });
    }
    header
}
