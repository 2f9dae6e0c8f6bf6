//! How far the method's fog light (eq. 15, the sun through the whole layer at every point) is
//! from exact single scattering (the sun's path from each point to the top), printed as
//! Markdown tables for `docs/atmosphere.md`: `cargo run --release -p fray-atmosphere --example
//! method_vs_exact`.
//!
//! The observer is at the layer's top looking down at the ground (an object at the base), as in
//! the method's figure. For the homogeneous slab the ratio depends only on the optical thickness
//! `B·H` and the two angles, so one table per thickness covers every height and extinction. The
//! ratio is of the sun's in-scattered radiance (ambient light scatters the same in both); the
//! transmittance is the same in both. Each exact value is checked against the quadrature
//! reference before it is printed.

use fray_atmosphere::reference::single_scattering;
use fray_atmosphere::{FogLayer, FogLighting, FogModel, Phase, Sunlight};
use fray_core::{Interval, Ray};
use glam::DVec3;

fn main() {
    let views = [1.0, 2.0, 5.0, 10.0, 20.0, 45.0, 90.0];
    let suns = [2.0, 5.0, 10.0, 20.0, 45.0, 90.0];
    let height = 100.0;
    let mut worst_check = 0.0f64;
    for thickness in [0.1, 1.0, 10.0] {
        let fog = FogLayer {
            top: height,
            extinction: thickness / height,
            phase: Phase::Isotropic,
            ..FogLayer::default()
        };
        println!(
            "\n**B·H = {thickness}** (method ÷ exact; rows: sun elevation β, columns: view angle α below the horizon)\n"
        );
        print!("| β \\ α |");
        for v in views {
            print!(" {v}° |");
        }
        println!();
        print!("|---|");
        for _ in views {
            print!("---|");
        }
        println!();
        for sun in suns {
            let b = f64::to_radians(sun);
            let light = FogLighting {
                suns: vec![Sunlight {
                    direction: DVec3::new(0.0, b.sin(), b.cos()),
                    irradiance: DVec3::ONE,
                }],
                ambient: DVec3::ZERO,
            };
            print!("| {sun}° |");
            for view in views {
                let a = f64::to_radians(view);
                let ray = Ray::new(
                    DVec3::new(0.0, height, 0.0),
                    DVec3::new(a.cos(), -a.sin(), 0.0),
                )
                .expect("a unit direction");
                let range = Interval::new(0.0, height / a.sin());
                let exact = fog.terms(&ray, range, &light, FogModel::Exact).in_scatter.x;
                let method = fog
                    .terms(&ray, range, &light, FogModel::Method)
                    .in_scatter
                    .x;
                let reference = single_scattering(&fog, &ray, range, &light).in_scatter.x;
                worst_check = worst_check.max((exact / reference - 1.0).abs());
                let ratio = method / exact;
                if ratio >= 0.01 {
                    print!(" {ratio:.3} |");
                } else {
                    print!(" {ratio:.1e} |");
                }
            }
            println!();
        }
    }
    println!(
        "\n(exact against the quadrature reference over these cases: worst relative difference {worst_check:.1e})"
    );
}
