//! Criterion benchmark of the scheduler alone: the work list of a 1024² view of the turboprop
//! (data/scenes/turboprop.ron), with a box test per object, CSG leaf and perturbation; built
//! sequentially (`build`) and on a 2-thread pool (`build_parallel`, the same list).

use criterion::{Criterion, criterion_group, criterion_main};
use fray_core::Aabb;
use fray_quadtree::{Candidates, QuadtreeConfig, RayBundle, build, build_parallel};
use std::hint::black_box;
use std::path::Path;

/// An object's box, its leaves' boxes, and every perturbation's (leaf, support box).
type ObjectBoxes = (Aabb, Vec<Aabb>, Vec<(u32, Aabb)>);

fn turboprop_work_list(c: &mut Criterion) {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../data/scenes/turboprop.ron");
    let scene = fray_scene::load(&path).unwrap_or_else(|e| panic!("{e}"));
    // Per object: its box, its leaves' boxes, and every perturbation's (leaf, support box).
    let objects: Vec<ObjectBoxes> = scene
        .objects
        .iter()
        .map(|o| {
            let leaves = o.solid.leaves().iter().map(|l| l.bounds()).collect();
            let perts = o
                .solid
                .leaves()
                .iter()
                .enumerate()
                .flat_map(|(i, l)| {
                    l.perturbations()
                        .iter()
                        .map(move |p| (i as u32, p.support_bounds().unwrap_or(l.bounds())))
                })
                .collect();
            (o.solid.bounds(), leaves, perts)
        })
        .collect();
    let mut root = Candidates::new();
    for (i, (_, leaves, perts)) in objects.iter().enumerate() {
        root.begin(0, i as u32, 0.0, f64::INFINITY);
        (0..leaves.len() as u32).for_each(|l| root.push_leaf(l));
        (0..perts.len() as u32).for_each(|p| root.push_perturbation(p));
    }
    let test = |b: &RayBundle, parent: &Candidates, out: &mut Candidates| {
        for c in &parent.candidates {
            let (solid, leaves, perts) = &objects[c.object as usize];
            let Some(t) = b.box_range(solid) else {
                continue;
            };
            out.begin(c.kind, c.object, t.lo, t.hi);
            for &l in c.leaves(&parent.leaves) {
                if b.box_range(&leaves[l as usize]).is_some() {
                    out.push_leaf(l);
                }
            }
            for &p in c.perturbations(&parent.perturbations) {
                if b.box_range(&perts[p as usize].1).is_some() {
                    out.push_perturbation(p);
                }
            }
        }
    };
    let mut group = c.benchmark_group("quadtree");
    for cell in [8u32, 16] {
        group.bench_function(format!("turboprop_1024x1024_cell{cell}"), |bench| {
            bench.iter(|| {
                let list = build(
                    &scene.camera,
                    (1024, 1024),
                    &QuadtreeConfig::new(cell),
                    &root,
                    test,
                );
                black_box(list.map(|l| l.items.len()))
            })
        });
    }
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(2)
        .build()
        .expect("a 2-thread pool");
    for cell in [8u32, 16] {
        group.bench_function(
            format!("turboprop_1024x1024_cell{cell}_parallel_2threads"),
            |bench| {
                bench.iter(|| {
                    let list = pool.install(|| {
                        build_parallel(
                            &scene.camera,
                            (1024, 1024),
                            &QuadtreeConfig::new(cell),
                            &root,
                            || test,
                        )
                    });
                    black_box(list.map(|l| l.items.len()))
                })
            },
        );
    }
    group.finish();
}

criterion_group!(benches, turboprop_work_list);
criterion_main!(benches);
