//! fray-mesh's textures: the mip chain's build for the brick photograph (512², grey) and the
//! cat (451 × 300, RGB: odd sizes, three taps per axis), and lookups per second on one thread —
//! nearest and bilinear at the base level, trilinear at a footprint's level, and a triplanar
//! mapping's three blended trilinear lookups — at 2¹⁶ scattered uvs (a cache-unfriendly order,
//! as secondary rays give).

use criterion::{Criterion, Throughput, criterion_group, criterion_main};
use fray_core::MemoryBudget;
use fray_mesh::texture::{Encoding, Mapping, Texture, Triplanar, Wrap};
use glam::{DVec2, DVec3};
use std::hint::black_box;

fn load(name: &str) -> Texture {
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../data/textures")
        .join(name);
    Texture::load(&path, Encoding::Srgb, &MemoryBudget::default()).expect("the texture loads")
}

/// splitmix64 in [0, 1).
fn uniforms(n: usize, seed: u64) -> Vec<f64> {
    let mut s = seed;
    (0..n)
        .map(|_| {
            s = s.wrapping_add(0x9E37_79B9_7F4A_7C15);
            let mut z = s;
            z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
            z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
            ((z ^ (z >> 31)) >> 11) as f64 / (1u64 << 53) as f64
        })
        .collect()
}

fn bench(c: &mut Criterion) {
    let brick = load("brick.png");
    let cat = load("chelsea.png");
    let mut group = c.benchmark_group("texture");
    group.sample_size(20);
    for (name, t) in [("brick 512² grey", &brick), ("cat 451×300 RGB", &cat)] {
        let base = t.level(0).data().to_vec();
        let (w, h, ch) = (t.width(), t.height(), t.channels());
        group.bench_function(format!("mip chain {name}"), |b| {
            b.iter(|| {
                Texture::from_texels(
                    w,
                    h,
                    ch,
                    black_box(base.clone()),
                    &MemoryBudget::unlimited(),
                )
            })
        });
    }
    let n = 1 << 16;
    let r = uniforms(3 * n, 1);
    let uvs: Vec<DVec2> = (0..n)
        .map(|i| DVec2::new(4.0 * r[3 * i] - 2.0, 4.0 * r[3 * i + 1] - 2.0))
        .collect();
    // Footprints from 1/4 to 64 texels.
    let widths: Vec<f64> = (0..n)
        .map(|i| 2f64.powf(8.0 * r[3 * i + 2] - 2.0) / 451.0)
        .collect();
    group.throughput(Throughput::Elements(n as u64));
    group.bench_function("nearest (cat)", |b| {
        b.iter(|| {
            uvs.iter()
                .map(|&uv| cat.nearest(0, uv, Wrap::REPEAT).x)
                .sum::<f32>()
        })
    });
    group.bench_function("bilinear (cat)", |b| {
        b.iter(|| {
            uvs.iter()
                .map(|&uv| cat.bilinear(0, uv, Wrap::REPEAT).x)
                .sum::<f32>()
        })
    });
    group.bench_function("trilinear from a footprint (cat)", |b| {
        b.iter(|| {
            uvs.iter()
                .zip(&widths)
                .map(|(&uv, &w)| cat.sample(uv, w, Wrap::REPEAT).x)
                .sum::<f32>()
        })
    });
    let triplanar = Mapping::Triplanar(Triplanar::new(DVec3::ZERO, 0.5, 4.0).expect("triplanar"));
    let points: Vec<(DVec3, DVec3)> = (0..n)
        .map(|i| {
            let p = DVec3::new(r[3 * i], r[3 * i + 1], r[3 * i + 2]) * 10.0;
            (p, (p - DVec3::splat(5.0)).normalize_or_zero())
        })
        .collect();
    group.bench_function("triplanar, 3 trilinear lookups (cat)", |b| {
        b.iter(|| {
            points
                .iter()
                .zip(&widths)
                .map(|(&(p, nrm), &w)| triplanar.project(p, nrm).sample(&cat, w, Wrap::REPEAT).x)
                .sum::<f32>()
        })
    });
    group.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
