//! Density grids and volumes: trilinear sampling hits the samples at cell centres and is linear
//! between them; the max grid bounds every trilinear sample in its block (checked by brute force
//! at random points); the real CT scan loads with its documented size and range; bad files name
//! their path and reason; grids past the budget are refused before they are made.

use fray_clouds::{CloudsError, DensityGrid, inr};
use fray_core::MemoryBudget;
use std::path::Path;

fn lcg(seed: u64) -> impl FnMut() -> f64 {
    let mut state = seed;
    move || {
        state = state
            .wrapping_mul(6_364_136_223_846_793_005)
            .wrapping_add(1_442_695_040_888_963_407);
        (state >> 11) as f64 / (1u64 << 53) as f64
    }
}

#[test]
fn trilinear_sampling_interpolates_the_cell_centres() {
    let budget = MemoryBudget::default();
    // A linear field is reproduced exactly inside the centres' hull.
    let grid =
        DensityGrid::from_fn([8, 6, 4], &budget, |i, j, k| (i + 2 * j + 3 * k) as f32).unwrap();
    let mut next = lcg(3);
    for _ in 0..1000 {
        let p = [
            (0.5 + next() * 7.0) / 8.0,
            (0.5 + next() * 5.0) / 6.0,
            (0.5 + next() * 3.0) / 4.0,
        ];
        let expected = (p[0] * 8.0 - 0.5) + 2.0 * (p[1] * 6.0 - 0.5) + 3.0 * (p[2] * 4.0 - 0.5);
        assert!((grid.sample(p) - expected).abs() < 1e-12, "{p:?}");
    }
    // At a cell centre it is the sample; outside the cube it is clamped to the edge.
    assert_eq!(
        grid.sample([2.5 / 8.0, 1.5 / 6.0, 0.5 / 4.0]),
        f64::from(grid.get(2, 1, 0))
    );
    assert_eq!(grid.sample([-3.0, -1.0, -5.0]), 0.0);
    assert_eq!(grid.sample([9.0, 9.0, 9.0]), f64::from(grid.get(7, 5, 3)));
}

#[test]
fn the_max_grid_bounds_every_sample_in_its_block() {
    let budget = MemoryBudget::default();
    let mut next = lcg(11);
    // Sparse blobs: most blocks empty, a few dense.
    let grid = DensityGrid::from_fn([37, 29, 23], &budget, |_, _, _| {
        let r = next();
        if r > 0.97 { (r * 10.0) as f32 } else { 0.0 }
    })
    .unwrap();
    let mut sample = lcg(12);
    for block in [1, 4, 8] {
        let max = grid.max_grid(block);
        let mut empty = 0;
        for _ in 0..50_000 {
            let p = [
                sample() * 1.2 - 0.1,
                sample() * 1.2 - 0.1,
                sample() * 1.2 - 0.1,
            ];
            let value = grid.sample(p);
            let bound = f64::from(max.bound_at(p));
            assert!(value <= bound, "block {block}: {value} > {bound} at {p:?}");
            if bound == 0.0 {
                empty += 1;
            }
        }
        if block == 1 {
            // Most of this sparse grid is provably empty at the finest blocks.
            assert!(empty > 10_000, "{empty}");
        }
    }
}

#[test]
fn the_ct_scan_loads_with_its_documented_size_and_range() {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../data/volumes/skull_2.9.inr");
    let volume = inr::load(&path, &MemoryBudget::default()).unwrap();
    assert_eq!(volume.grid.size(), [64, 64, 64]);
    assert_eq!(volume.voxel_size, [3.943050, 3.943050, 3.650790]);
    let (lo, hi) = volume
        .grid
        .data()
        .iter()
        .fold((f32::INFINITY, f32::NEG_INFINITY), |(a, b), &v| {
            (a.min(v), b.max(v))
        });
    assert!(lo >= 0.0 && (5.0..5.5).contains(&hi), "{lo} … {hi}");
    // A budget below the file's 1 MiB refuses it before reading it; one that holds the file
    // but not the file and its voxels together refuses the voxels. Both name the file.
    for small in [MemoryBudget::new(1 << 19), MemoryBudget::new(3 << 19)] {
        let e = inr::load(&path, &small);
        let text = format!("{:?}", e.as_ref().err());
        assert!(matches!(e, Err(CloudsError::Budget(_))), "{text}");
        assert!(text.contains("skull_2.9.inr"), "{text}");
    }
}

#[test]
fn bad_volume_files_name_their_path_and_reason() {
    let dir = std::env::temp_dir().join(format!("fray-inr-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let budget = MemoryBudget::default();
    let write = |name: &str, bytes: &[u8]| {
        let p = dir.join(name);
        std::fs::write(&p, bytes).unwrap();
        p
    };
    let header = |fields: &str| {
        let mut h = format!("#INRIMAGE-4#{{\n{fields}\n").into_bytes();
        h.resize(252, b'\n');
        h.extend_from_slice(b"##}\n");
        h
    };
    let cases: Vec<(std::path::PathBuf, &str)> = vec![
        (dir.join("missing.inr"), "cannot read the file"),
        (write("png.inr", b"\x89PNG...."), "not an INRIMAGE-4 file"),
        (write("open.inr", b"#INRIMAGE-4#{\nXDIM=2\n"), "never ends"),
        (
            write(
                "bytes.inr",
                &header("XDIM=2\nYDIM=2\nZDIM=2\nTYPE=unsigned fixed\nPIXSIZE=8 bits"),
            ),
            "only TYPE=float",
        ),
        (
            write(
                "short.inr",
                &header("XDIM=2\nYDIM=2\nZDIM=2\nTYPE=float\nPIXSIZE=32 bits\nCPU=decm"),
            ),
            "truncated",
        ),
        (
            write("nodim.inr", &header("TYPE=float\nPIXSIZE=32 bits")),
            "XDIM, YDIM and ZDIM",
        ),
        (
            write("word.inr", &header("XDIM=two")),
            "XDIM: not a whole number",
        ),
    ];
    for (path, reason) in cases {
        let e = inr::load(&path, &budget).unwrap_err().to_string();
        assert!(
            e.contains(&path.display().to_string()) && e.contains(reason),
            "{e}"
        );
    }
    // A big-endian file reads the same values.
    let mut big = header("XDIM=2\nYDIM=1\nZDIM=1\nTYPE=float\nPIXSIZE=32 bits\nCPU=sun");
    big.extend_from_slice(&1.5f32.to_be_bytes());
    big.extend_from_slice(&(-2.0f32).to_be_bytes());
    let v = inr::load(&write("big.inr", &big), &budget).unwrap();
    assert_eq!(v.grid.data(), &[1.5, -2.0]);
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn grids_past_the_budget_or_empty_are_refused() {
    let small = MemoryBudget::new(1000);
    assert!(matches!(
        DensityGrid::from_fn([64, 64, 64], &small, |_, _, _| 0.0),
        Err(CloudsError::Budget(_))
    ));
    assert!(matches!(
        DensityGrid::from_fn([0, 4, 4], &MemoryBudget::default(), |_, _, _| 0.0),
        Err(CloudsError::BadSize(0, 4, 4))
    ));
}
