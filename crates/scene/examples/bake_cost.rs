//! What a cloud layer's bake costs per cell, by octaves, Worley billows and envelope terms: the
//! measurements behind `fray_clouds::cost` (`WORLEY_OCTAVE_COST`) and `ENVELOPE_TERMS_PER_OCTAVE`.
//! `cargo run --profile test -p fray-scene --example bake_cost -- [SIDE]` bakes each case at
//! SIDE³ cells (default 64) three times and prints the median per cell, on all cores.

fn main() {
    let side: usize = match std::env::args().nth(1).map(|s| s.parse()) {
        None => 64,
        Some(Ok(n)) if n > 0 => n,
        Some(_) => {
            eprintln!("usage: bake_cost [SIDE ≥ 1]");
            std::process::exit(2);
        }
    };
    // Spheres holding the whole region, so every cell pays for its noise and its depth query.
    let envelope = |terms: usize| {
        let spheres: Vec<String> = (0..terms)
            .map(|k| format!("Sphere(center: ({}, 50, 0), radius: 1000)", k * 3))
            .collect();
        match terms {
            1 => format!("envelope: {}", spheres[0]),
            _ => format!("envelope: Union([{}])", spheres.join(", ")),
        }
    };
    // One ellipsoid holding the region, with small perturbations inside it.
    let perturbed = |terms: usize| {
        let bumps: Vec<String> = (0..terms)
            .map(|k| {
                format!(
                    "(form_factor: 1.0, quadric: Sphere(center: ({}, 50, 0), radius: 10))",
                    k * 3
                )
            })
            .collect();
        format!(
            "octaves: 1, envelope: FreeForm(base: Ellipsoid(center: (0, 50, 0), radii: (1000, \
             1000, 1000)), perturbations: [{}])",
            bumps.join(", ")
        )
    };
    let cases = [
        ("1 octave", "octaves: 1".to_owned()),
        ("5 octaves", "octaves: 5".to_owned()),
        ("12 octaves", "octaves: 12".to_owned()),
        ("1 octave, Worley", "octaves: 1, worley: 0.5".to_owned()),
        ("3 octaves, Worley", "octaves: 3, worley: 0.5".to_owned()),
        ("1 octave, 1 leaf", format!("octaves: 1, {}", envelope(1))),
        (
            "1 octave, 40 leaves",
            format!("octaves: 1, {}", envelope(40)),
        ),
        ("1 octave, 40 perturbations", perturbed(40)),
    ];
    for (name, fields) in cases {
        let src = format!(
            "(clouds: (region: (min: (-100, 0, -100), max: (100, 100, 100)), density: \
             Layer((resolution: ({side}, {side}, {side}), coverage: 0.6, {fields}))))"
        );
        let mut times: Vec<f64> = (0..3)
            .map(|_| match fray_scene::parse(&src, "bake_cost.ron") {
                Ok(scene) => match scene.clouds.map(|c| c.source.clone()) {
                    Some(fray_scene::CloudSource::Layer { bake }) => bake.as_secs_f64(),
                    _ => f64::NAN,
                },
                Err(e) => {
                    eprintln!("{name}: {e}");
                    std::process::exit(1);
                }
            })
            .collect();
        times.sort_by(f64::total_cmp);
        let cells = (side * side * side) as f64;
        println!(
            "{name:>20}: median {:.3} s, {:.1} ns per cell",
            times[1],
            times[1] / cells * 1e9
        );
    }
}
