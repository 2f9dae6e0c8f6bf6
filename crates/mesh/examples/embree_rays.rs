//! Writes the mesh benchmark's rays (`benches/bunny_view`) for the Embree comparison,
//! `benches/embree/embree_bench.c` (docs/mesh-bench.md): the same primary and shadow rays, so
//! that both ray casters answer exactly the same queries.
//!
//! `cargo run --release -p fray-mesh --example embree_rays -- OUT.bin`
//!
//! The file is little-endian: a `u64` count of primary rays, then per ray `origin, dir` as six
//! f32 (its range is `[0, ∞)`); a `u64` count of shadow rays, then per ray
//! `origin, dir, lo, hi` as eight f32.

#[path = "../benches/bunny_view/mod.rs"]
mod bunny_view;

use fray_core::Interval;
use fray_mesh::{MeshBvh, PacketBvh};
use std::io::Write;

fn main() -> std::io::Result<()> {
    let Some(out) = std::env::args_os().nth(1) else {
        eprintln!("usage: embree_rays OUT.bin");
        std::process::exit(2);
    };
    let bvh = MeshBvh::build(bunny_view::bunny());
    let rays = bunny_view::primary_rays(&bvh);
    let all = vec![Interval::new(0.0, f64::INFINITY); rays.len()];
    let mut hits = vec![None; rays.len()];
    PacketBvh::new(bvh.clone()).nearest_hits(&rays, &all, &mut hits);
    let (shadow, ranges) = bunny_view::shadow_rays(&bvh, &rays, &hits);
    let mut bytes = Vec::with_capacity(16 + rays.len() * 24 + shadow.len() * 32);
    let mut put = |x: f64| bytes.extend_from_slice(&(x as f32).to_le_bytes());
    let count = |n: usize| (n as u64).to_le_bytes();
    let mut file = std::io::BufWriter::new(std::fs::File::create(&out)?);
    for r in &rays {
        for x in r.origin.to_array().into_iter().chain(r.dir.to_array()) {
            put(x);
        }
    }
    file.write_all(&count(rays.len()))?;
    file.write_all(&bytes)?;
    bytes.clear();
    let mut put = |x: f64| bytes.extend_from_slice(&(x as f32).to_le_bytes());
    for (r, range) in shadow.iter().zip(&ranges) {
        for x in r.origin.to_array().into_iter().chain(r.dir.to_array()) {
            put(x);
        }
        put(range.lo);
        put(range.hi);
    }
    file.write_all(&count(shadow.len()))?;
    file.write_all(&bytes)?;
    file.flush()?;
    let hit = hits.iter().filter(|h| h.is_some()).count();
    eprintln!(
        "{} primary rays ({hit} hit the bunny here), {} shadow rays → {}",
        rays.len(),
        shadow.len(),
        std::path::Path::new(&out).display()
    );
    Ok(())
}
