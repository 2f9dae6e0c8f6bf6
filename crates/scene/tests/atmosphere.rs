//! The atmosphere in scene files: fog resolved with its defaults, every bad value reported at
//! its file, line and field; `include` brings in another file's materials and objects.

use fray_atmosphere::{FogModel, Phase};

fn err(src: &str) -> String {
    match fray_scene::parse(src, "s.ron") {
        Ok(_) => panic!("expected an error for {src}"),
        Err(e) => e.to_string(),
    }
}

#[test]
fn fog_defaults_and_features() {
    let s = fray_scene::parse("(atmosphere: (fog: (top: 50)))", "s.ron").unwrap();
    let fog = s.atmosphere.fog.unwrap();
    assert_eq!((fog.layer.base, fog.layer.top), (0.0, 50.0));
    assert_eq!(fog.layer.extinction, 1e-3);
    assert_eq!(fog.layer.phase, Phase::HenyeyGreenstein { g: 0.76 });
    assert_eq!(fog.model, FogModel::Exact);
    assert!(s.features.fog && s.features.names().contains(&"fog"));
    let s = fray_scene::parse(
        "(atmosphere: (grid: 8, fog: (top: 5, base: -5, falloff: 20, phase: Printed(g: 0.5), model: Method)))",
        "s.ron",
    )
    .unwrap();
    assert_eq!(s.atmosphere.grid, Some(8));
    let fog = s.atmosphere.fog.unwrap();
    assert_eq!(fog.layer.falloff, Some(20.0));
    assert_eq!(fog.model, FogModel::Method);
    let none = fray_scene::parse("()", "s.ron").unwrap();
    assert!(none.atmosphere.is_empty() && !none.features.fog);
}

#[test]
fn bad_fog_values_name_file_line_and_field() {
    assert_eq!(
        err("(atmosphere: (\n fog: (top: -1)))"),
        "s.ron:2:8: atmosphere.fog.top: must be above base (0), got -1"
    );
    assert!(
        err("(atmosphere: (fog: (top: 1, extinction: -2)))")
            .contains("atmosphere.fog.extinction: must be ≥ 0")
    );
    assert!(
        err("(atmosphere: (fog: (top: 1, albedo: (1, 2, 0))))")
            .contains("atmosphere.fog.albedo: must be in [0, 1]")
    );
    assert!(err("(atmosphere: (fog: (top: 1, falloff: 0)))").contains("atmosphere.fog.falloff"));
    assert!(
        err("(atmosphere: (fog: (top: 1, phase: HenyeyGreenstein(g: 1))))")
            .contains("atmosphere.fog.phase.g: must be in (−1, 1)")
    );
    assert!(err("(atmosphere: (grid: 1.5))").contains("atmosphere.grid: must be a whole number"));
    assert!(err("(atmosphere: (fog: (top: 1, modle: Exact)))").contains("unknown field `modle`"));
}

#[test]
fn include_brings_materials_and_objects_and_reports_problems() {
    let dir = std::env::temp_dir().join(format!("fray-include-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let part = dir.join("part.ron");
    std::fs::write(
        &part,
        r#"(materials: { "red": (diffuse: (0.8, 0.1, 0.1)) },
            objects: [(name: "ball", material: "red", shape: Sphere(radius: 1))])"#,
    )
    .unwrap();
    let main = dir.join("main.ron");
    std::fs::write(
        &main,
        r#"(include: ["part.ron"], objects: [(shape: Sphere(center: (3, 0, 0), radius: 1))])"#,
    )
    .unwrap();
    let s = fray_scene::load(&main).unwrap();
    assert_eq!(s.objects.len(), 2);
    assert_eq!(s.objects[1].name, "ball");
    assert_eq!(
        s.materials[s.objects[1].leaf_materials[0] as usize].name,
        "red"
    );
    // A missing file, a clash and a cycle are errors at the include.
    std::fs::write(&main, "(include: [\"nope.ron\"])").unwrap();
    let e = fray_scene::load(&main).unwrap_err().to_string();
    assert!(
        e.contains("include[0]: cannot read") && e.contains("nope.ron"),
        "{e}"
    );
    std::fs::write(
        &main,
        r#"(include: ["part.ron"], materials: { "red": (diffuse: (0.1, 0.1, 0.8)) })"#,
    )
    .unwrap();
    let e = fray_scene::load(&main).unwrap_err().to_string();
    assert!(e.contains("material `red` is defined differently"), "{e}");
    std::fs::write(&main, r#"(include: ["main.ron"])"#).unwrap();
    let e = fray_scene::load(&main).unwrap_err().to_string();
    assert!(e.contains("nest deeper than"), "{e}");
    // An error inside the included file names that file.
    std::fs::write(&part, "(objects: [(shape: Sphere(radius: -1))])").unwrap();
    std::fs::write(&main, r#"(include: ["part.ron"])"#).unwrap();
    let e = fray_scene::load(&main).unwrap_err().to_string();
    assert!(
        e.contains("part.ron:1:") && e.contains("radius: must be > 0"),
        "{e}"
    );
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn a_sky_takes_the_first_sun_and_checks_its_fields() {
    let s = fray_scene::parse(
        "(lights: [Point(position: (0, 5, 0)), Sun(direction: (0, 1, 1), irradiance: (9, 9, 9))],\n\
         atmosphere: (sky: (haze: 4, ozone: false, steps: 8, ground_elevation: -20)))",
        "s.ron",
    )
    .unwrap();
    let sky = s.atmosphere.sky.as_ref().unwrap();
    assert_eq!(sky.sun_light, Some(1));
    assert_eq!(sky.steps, 8);
    let model = sky.sky.model();
    assert_eq!(model.ground_elevation, -20.0);
    assert_eq!(model.ozone_absorption, glam::DVec3::ZERO);
    let earth = fray_atmosphere::sky::SkyModel::earth();
    assert_eq!(model.mie_scattering, 4.0 * earth.mie_scattering);
    assert!((sky.sky.sun().direction.y - 0.5f64.sqrt()).abs() < 1e-15);
    assert!(s.features.sky && s.features.names().contains(&"sky"));
    assert!(
        err("(atmosphere: (sky: (steps: 0)))")
            .contains("atmosphere.sky.steps: must be a whole number")
    );
    assert!(err("(atmosphere: (sky: (haze: -1)))").contains("atmosphere.sky.haze: must be ≥ 0"));
    // No sun: a dark sky, still valid.
    let s = fray_scene::parse("(atmosphere: (sky: ()))", "s.ron").unwrap();
    assert_eq!(s.atmosphere.sky.unwrap().sun_light, None);
}
