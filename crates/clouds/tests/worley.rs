//! Worley's cellular noise against brute force: `F1` equals the nearest of every feature point
//! within 4 cells (9³ cells), at random points, negative and far coordinates included; feature
//! points lie in their cells; billows stay in `[0, 1]` and are deterministic.

use fray_clouds::worley::{billows, f1, feature_point};

/// A small deterministic generator (splitmix64) for test points.
fn points(n: usize, scale: f64) -> Vec<[f64; 3]> {
    let mut s = 0x9E37_79B9_7F4A_7C15u64;
    let mut next = || {
        s = s.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = s;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        ((z ^ (z >> 31)) >> 11) as f64 / (1u64 << 53) as f64
    };
    (0..n)
        .map(|_| [0; 3].map(|_| (next() * 2.0 - 1.0) * scale))
        .collect()
}

#[test]
fn f1_is_the_nearest_feature_point() {
    let mut worst = 0.0f64;
    let mut far_searches = 0;
    for scale in [3.0, 40.0, 1e4] {
        for p in points(3000, scale) {
            let cell = p.map(|v| v.floor() as i64);
            let mut best = f64::INFINITY;
            for dk in -4..=4 {
                for dj in -4..=4 {
                    for di in -4..=4 {
                        let q = feature_point(cell[0] + di, cell[1] + dj, cell[2] + dk);
                        let d =
                            ((q[0] - p[0]).powi(2) + (q[1] - p[1]).powi(2) + (q[2] - p[2]).powi(2))
                                .sqrt();
                        best = best.min(d);
                    }
                }
            }
            let got = f1(p[0], p[1], p[2]);
            worst = worst.max((got - best).abs());
            far_searches += usize::from(got > 1.0);
        }
    }
    assert!(worst <= 1e-12, "worst |F1 − brute force| = {worst}");
    println!("F1 against brute force: worst {worst:e}; {far_searches} points had F1 > 1");
}

#[test]
fn feature_points_lie_in_their_cells_and_billows_in_unit_range() {
    for (i, j, k) in [(0, 0, 0), (-1, 5, -300), (255, 256, 257), (-12345, 0, 99)] {
        let q = feature_point(i, j, k);
        for (v, c) in q.iter().zip([i, j, k]) {
            assert!(
                *v > c as f64 && *v < c as f64 + 1.0,
                "{q:?} not in cell {i} {j} {k}"
            );
        }
        // Perlin's period: the cell 256 over has the same offset.
        let r = feature_point(i + 256, j, k);
        assert_eq!(r[0] - q[0], 256.0);
    }
    for p in points(2000, 50.0) {
        let b = billows(p[0], p[1], p[2], 3, 2.0, 0.5);
        assert!((0.0..=1.0).contains(&b));
        assert_eq!(b, billows(p[0], p[1], p[2], 3, 2.0, 0.5));
    }
    // On a feature point F1 is 0 and its billow 1.
    let q = feature_point(7, -3, 2);
    assert_eq!(f1(q[0], q[1], q[2]), 0.0);
}
