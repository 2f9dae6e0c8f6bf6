//! Clouds in scene files: a layer and a volume resolved with their defaults, every bad value
//! reported at its file, line and field, unreadable volumes named with their path and reason,
//! a grid past the memory budget refused before it is made, and a march or a bake past its cap
//! (`fray_clouds::cost`) refused at load, at its field.

fn err(src: &str) -> String {
    match fray_scene::parse(src, "s.ron") {
        Ok(_) => panic!("expected an error for {src}"),
        Err(e) => e.to_string(),
    }
}

const LAYER: &str = "(clouds: (region: (min: (-100, 10, -100), max: (100, 40, 100)), density: Layer((resolution: (8, 4, 8)))))";

#[test]
fn a_layer_takes_its_defaults_and_sets_the_feature() {
    let s = fray_scene::parse(LAYER, "s.ron").unwrap();
    assert!(s.features.clouds && s.features.names().contains(&"clouds"));
    let c = s.clouds.unwrap();
    assert_eq!(c.volume.grid.size(), [8, 4, 8]);
    assert_eq!(c.volume.region.min, [-100.0, 10.0, -100.0]);
    // Extinction at density 1 = scattering + absorption; albedo their ratio.
    assert!((c.volume.scale - 0.0202).abs() < 1e-15);
    assert!((c.albedo - 0.02 / 0.0202).abs() < 1e-15);
    // The default step: the smallest side / 32.
    assert_eq!(c.march.step, 30.0 / 32.0);
    assert_eq!(c.march.sun_steps, 6);
    assert_eq!(c.skip_block, Some(4));
    assert!(c.volume.skip.is_some() && c.jitter);
    assert!(c.describe().contains("8×4×8"), "{}", c.describe());
    let none = fray_scene::parse("()", "s.ron").unwrap();
    assert!(none.clouds.is_none() && !none.features.clouds);
    // Worley billows mixed in change the layer; none leaves it Perlin's alone.
    let dense = LAYER.replace("(8, 4, 8)", "(16, 8, 16), coverage: 0.8");
    let perlin = fray_scene::parse(&dense, "s.ron").unwrap().clouds.unwrap();
    let zero = fray_scene::parse(&dense.replace("0.8", "0.8, worley: 0"), "s.ron").unwrap();
    assert_eq!(zero.clouds.unwrap().volume.grid, perlin.volume.grid);
    let mixed = fray_scene::parse(&dense.replace("0.8", "0.8, worley: 0.5"), "s.ron").unwrap();
    assert_ne!(mixed.clouds.unwrap().volume.grid, perlin.volume.grid);
    // Skipping off.
    let off = LAYER.replace("density:", "skip_block: 0, density:");
    let c = fray_scene::parse(&off, "s.ron").unwrap().clouds.unwrap();
    assert!(c.volume.skip.is_none() && c.skip_block.is_none());
}

#[test]
fn the_bake_reports_its_progress() {
    let reports = std::sync::Mutex::new(Vec::new());
    let progress = |what: &str, done: usize, total: usize| {
        reports.lock().unwrap().push((what.to_owned(), done, total));
    };
    let options = fray_scene::BuildOptions {
        progress: Some(&progress),
        ..Default::default()
    };
    fray_scene::parse_with(LAYER, "s.ron", &options).unwrap();
    let mut reports = reports.into_inner().unwrap();
    reports.sort();
    let expected: Vec<_> = (1..=8)
        .map(|k| ("baking clouds".to_owned(), k, 8))
        .collect();
    assert_eq!(reports, expected);
}

#[test]
fn an_envelope_confines_the_layer() {
    // The whole layer is cloud (coverage 1, no threshold) except outside the envelope.
    let full = "(clouds: (region: (min: (-100, 0, -100), max: (100, 100, 100)), density: Layer((resolution: (16, 16, 16), coverage: 1, threshold: 0, profile: Custom(base_ramp: 0, top_start: 1), envelope_fade: 0ENVELOPE))))";
    let open = fray_scene::parse(&full.replace("ENVELOPE", ""), "s.ron").unwrap();
    let ball = fray_scene::parse(
        &full.replace(
            "ENVELOPE",
            ", envelope: Sphere(center: (0, 50, 0), radius: 30)",
        ),
        "s.ron",
    )
    .unwrap();
    let (open, ball) = (open.clouds.unwrap(), ball.clouds.unwrap());
    let size = [16, 16, 16];
    let region = ball.volume.region;
    let (mut inside, mut outside) = (0, 0);
    for k in 0..16 {
        for j in 0..16 {
            for i in 0..16 {
                let p = region.cell_centre(size, [i, j, k]);
                let r = ((p[0]).powi(2) + (p[1] - 50.0).powi(2) + p[2].powi(2)).sqrt();
                let unit = [
                    (i as f64 + 0.5) / 16.0,
                    (j as f64 + 0.5) / 16.0,
                    (k as f64 + 0.5) / 16.0,
                ];
                let (b, o) = (ball.volume.grid.sample(unit), open.volume.grid.sample(unit));
                if r > 30.0 {
                    assert_eq!(b, 0.0, "outside the envelope at {p:?}");
                    outside += 1;
                } else {
                    assert_eq!(b, o, "inside the envelope at {p:?}");
                    inside += usize::from(o > 0.0);
                }
            }
        }
    }
    assert!(
        inside > 50 && outside > 1000,
        "{inside} inside, {outside} outside"
    );
    // The envelope draws nothing and adds no features.
    let s = fray_scene::parse(
        &full.replace(
            "ENVELOPE",
            ", envelope: Union([Sphere(radius: 3), Sphere(center: (5, 0, 0), radius: 3)])",
        ),
        "s.ron",
    )
    .unwrap();
    assert!(s.objects.is_empty() && !s.features.csg && !s.features.free_forms);
}

#[test]
fn bad_cloud_values_name_file_line_and_field() {
    let bad = |from: &str, to: &str| err(&LAYER.replace(from, to));
    assert!(
        bad("max: (100, 40, 100)", "max: (100, 10, 100)")
            .contains("clouds.region: must have a positive size on every axis")
    );
    assert!(bad("density:", "scattering: -1, density:").contains("clouds.scattering: must be ≥ 0"));
    assert!(
        bad("density:", "sun_steps: 0, density:")
            .contains("clouds.sun_steps: must be a whole number in 1..=256")
    );
    assert!(bad("density:", "step: 0, density:").contains("clouds.step: must be > 0"));
    assert!(bad("density:", "min_transmittance: 1, density:").contains("clouds.min_transmittance"));
    assert!(bad("density:", "skip_block: 2.5, density:").contains("clouds.skip_block"));
    assert!(
        bad("density:", "phase: (g: 1), density:").contains("clouds.phase.g: must be in (−1, 1)")
    );
    assert!(
        bad("(8, 4, 8)", "(8, 0, 8)")
            .contains("clouds.density.resolution[1]: must be a whole number in 1..=1024")
    );
    assert!(
        bad("(8, 4, 8))", "(8, 4, 8), coverage: 2)")
            .contains("clouds.density.coverage: must be in [0, 1]")
    );
    assert!(bad("(8, 4, 8))", "(8, 4, 8), octaves: 0)").contains("clouds.density.octaves"));
    assert!(
        bad("(8, 4, 8))", "(8, 4, 8), worley: 1.5)")
            .contains("clouds.density.worley: must be in [0, 1]")
    );
    assert!(bad("(8, 4, 8))", "(8, 4, 8), threshold: 1)").contains("clouds.density.threshold"));
    assert!(
        bad(
            "(8, 4, 8))",
            "(8, 4, 8), profile: Custom(base_ramp: 0.5, top_start: 0.2))"
        )
        .contains("clouds.density.profile.top_start: must be ≥ base_ramp")
    );
    assert!(
        bad("(8, 4, 8))", "(8, 4, 8), envelope: Sphere(radius: -1))")
            .contains("clouds.density.envelope")
    );
    // The line is the field's.
    let e = err(
        "(clouds: (region: (min: (0, 0, 0), max: (1, 1, 1)),\n  density: Layer((\n    coverage: 3))))",
    );
    assert!(e.starts_with("s.ron:3:"), "{e}");
}

#[test]
fn a_grid_past_the_budget_is_refused_before_it_is_made() {
    let src = LAYER.replace("(8, 4, 8)", "(512, 256, 512)");
    let options = fray_scene::BuildOptions::within(fray_core::MemoryBudget::new(64 << 20));
    let e = fray_scene::parse_with(&src, "s.ron", &options)
        .unwrap_err()
        .to_string();
    // 256 MiB of f32 over a 64 MiB budget, named with its size and at the resolution field.
    assert!(
        e.contains("clouds.density.resolution") && e.contains("512 × 256 × 512 density grid"),
        "{e}"
    );
}

#[test]
fn volumes_load_and_bad_files_name_their_path_and_reason() {
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../data/volumes");
    let src = |path: &str, extra: &str| {
        format!(
            "(clouds: (region: (min: (-1, -1, -1), max: (1, 1, 1)), density: Volume(path: \"{path}\"{extra})))"
        )
    };
    let skull = dir.join("skull_2.9.inr").display().to_string();
    let s = fray_scene::parse(&src(&skull, ""), "s.ron").unwrap();
    let c = s.clouds.unwrap();
    assert_eq!(c.volume.grid.size(), [64, 64, 64]);
    let max = |c: &fray_scene::Clouds| c.volume.grid.data().iter().copied().fold(0.0f32, f32::max);
    assert!((max(&c) - 5.43).abs() < 0.01, "{}", max(&c));
    // The threshold keeps the excess above it.
    let cut = fray_scene::parse(&src(&skull, ", threshold: 2.9, scale: 2"), "s.ron").unwrap();
    let cut = cut.clouds.unwrap();
    assert!((max(&cut) - (max(&c) - 2.9)).abs() < 1e-5);
    assert_eq!(cut.volume.scale, 2.0 * c.volume.scale);
    let zeros = |c: &fray_scene::Clouds| c.volume.grid.data().iter().filter(|v| **v == 0.0).count();
    assert!(zeros(&cut) > zeros(&c));
    // A missing file: its path and the reason, at the field.
    let e = err(&src("no/such/volume.inr", ""));
    assert!(
        e.contains("clouds.density.path") && e.contains("volume.inr") && e.contains("cannot read"),
        "{e}"
    );
    // Not an INRIMAGE file.
    let scene = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("Cargo.toml");
    let e = err(&src(&scene.display().to_string(), ""));
    assert!(
        e.contains("Cargo.toml") && e.contains("clouds.density.path"),
        "{e}"
    );
}

#[test]
fn a_march_past_its_cap_is_refused_at_load_at_its_field() {
    // The bound: (⌈diagonal / step⌉) × (1 + sun_steps) ≤ MAX_RAY_SAMPLES = 65 536 density
    // samples per view ray. A step of 1e-7 in a unit box: 17 320 509 view steps.
    let unit = |extra: &str| {
        format!(
            "(clouds: (region: (min: (0, 0, 0), max: (1, 1, 1)),\n  {extra}\n  density: Layer((resolution: (4, 4, 4)))))"
        )
    };
    let e = err(&unit("step: 1e-7,"));
    assert!(
        e.starts_with("s.ron:2:3: clouds.step: ")
            && e.contains("17320509 view steps, each with 6 sun steps")
            && e.contains("over the cap of 65536"),
        "{e}"
    );
    // 20 000 view steps would fit with one sun step each, not with 6: the sun steps are named.
    let e = err(&unit("step: 8.660254037844386e-5, sun_steps: 6,"));
    assert!(
        e.starts_with("s.ron:2:") && e.contains("clouds.sun_steps: "),
        "{e}"
    );
    // A region of ±1e300 across and 1 high: the default step (1/32) takes 9e301 steps.
    let e = err(
        "(clouds: (region: (min: (-1e300, 0, -1e300), max: (1e300, 1, 1e300)), density: Layer((resolution: (4, 4, 4)))))",
    );
    assert!(
        e.contains("clouds.step: ")
            && e.contains("9.051e301 view steps")
            && e.contains("(the default step: the region's smallest side / 32)"),
        "{e}"
    );
    // The cap is checked before a volume is read, too.
    let e = err(
        "(clouds: (region: (min: (0, 0, 0), max: (1, 1, 1)), step: 1e-7, density: Volume(path: \"no/such.inr\")))",
    );
    assert!(
        e.contains("clouds.step: ") && e.contains("over the cap"),
        "{e}"
    );
}

#[test]
fn a_bake_past_its_work_cap_is_refused_at_load_before_its_grid_is_made() {
    // The 1024³ grid (4 GiB: it fits a 4 GiB budget exactly) of 5 octaves: 6 units a
    // cell, 6 × 2³⁰ against MAX_BAKE_WORK = 2³⁰. Refused at the resolution, whatever the
    // budget, before the grid exists.
    let src = LAYER.replace("(8, 4, 8)", "(1024, 1024, 1024)");
    let options = fray_scene::BuildOptions::within(fray_core::MemoryBudget::unlimited());
    let e = fray_scene::parse_with(&src, "s.ron", &options)
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("clouds.density.resolution: baking 1024 × 1024 × 1024 cells at a cost of 6 each is 6442450944 units of work, over the cap of 1073741824"),
        "{e}"
    );
    // An envelope's leaves and perturbations add to each cell's cost (one unit per 2 terms):
    // 448³ cells of 6 + 12 = 18 units are past the cap, 6 units alone are not.
    let big = LAYER.replace("(8, 4, 8)", "(448, 448, 448)");
    let solid = "Union([Sphere(radius: 1), Sphere(radius: 2), Sphere(radius: 3), Sphere(radius: 4), Sphere(radius: 5), Sphere(radius: 6), Sphere(radius: 7), Sphere(radius: 8), Sphere(radius: 9), Sphere(radius: 10), Sphere(radius: 11), Sphere(radius: 12), Sphere(radius: 13), Sphere(radius: 14), Sphere(radius: 15), Sphere(radius: 16), Sphere(radius: 17), Sphere(radius: 18), Sphere(radius: 19), Sphere(radius: 20), Sphere(radius: 21), Sphere(radius: 22), Sphere(radius: 23), Sphere(radius: 24)])";
    let with_envelope = big.replace(
        "(448, 448, 448))",
        &format!("(448, 448, 448), envelope: {solid})"),
    );
    let e = fray_scene::parse_with(&with_envelope, "s.ron", &options)
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("clouds.density.resolution: baking 448 × 448 × 448 cells at a cost of 18 each"),
        "{e}"
    );
    // Without the envelope the same layer (5 octaves: 6 units a cell) is within the cap.
    let field = fray_clouds::CloudField::default();
    assert_eq!(field.cell_cost(), 6);
    assert!(fray_clouds::cost::check_bake(&field, 0, [448; 3]).is_ok());
}

#[test]
fn every_cloud_data_scene_is_well_within_the_caps() {
    // The caps are generous: each data scene's march takes at most 1/9 of MAX_RAY_SAMPLES per
    // view ray (the skull, the largest, 7 125), and each loads (its bake within MAX_BAKE_WORK).
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../data/scenes");
    let mut clouds = 0;
    for entry in std::fs::read_dir(&dir).unwrap() {
        let path = entry.unwrap().path();
        let text = std::fs::read_to_string(&path).unwrap();
        if path.extension().is_none_or(|e| e != "ron") || !text.contains("clouds:") {
            continue;
        }
        let scene = fray_scene::load(&path).unwrap_or_else(|e| panic!("{e}"));
        let c = scene.clouds.expect("a cloud scene");
        let cost = c.march.cost(&c.volume.region).unwrap();
        assert!(
            cost.samples * 9 <= fray_clouds::cost::MAX_RAY_SAMPLES,
            "{}: {cost:?}",
            path.display()
        );
        clouds += 1;
    }
    assert_eq!(clouds, 5);
}
