//! `Scene::switched` (the viewer's fog, sky, clouds and reflections toggles): a scene with a part
//! switched off renders the bytes of the same file without that part, and computes nothing of it.

use fray_render::{Backend, RenderOptions, Renderer};
use fray_scene::{Scene, Switches};

/// A mirror ball and a glass ball on a floor, under a sun, in fog, under a sky, below a small
/// cloud layer; each part a placeholder so that it can be left out of the file.
const TEMPLATE: &str = r#"Scene(
  image: (width: 48, height: 32),
  camera: Pinhole(eye: (0, 1.2, -6), look_at: (0, 0.6, 0), fov_y: 50),
  background: (0.3, 0.4, 0.6),
  lights: [Sun(direction: (0.4, 1, -0.5), irradiance: (3, 3, 3))],
  materials: {
    "floor": (diffuse: (0.5, 0.45, 0.4)),
    "mirror": (diffuse: (0.02, 0.02, 0.02), reflect: (0.9, 0.9, 0.9)),
    "glass": (diffuse: (0, 0, 0), transmit: (0.95, 0.95, 0.95), ior: 1.5, fresnel: true),
  },
  atmosphere: (FOG SKY),
  CLOUDS
  objects: [
    (material: "floor", shape: FreeForm(base: HalfSpace(point: (0, 0, 0), normal: (0, 1, 0)), bounds: (min: (-8, -0.1, -8), max: (8, 0, 8)))),
    (material: "mirror", shape: Sphere(center: (-0.8, 0.6, 0), radius: 0.6)),
    (material: "glass", shape: Sphere(center: (0.8, 0.6, 0), radius: 0.6)),
  ],
  settings: (max_depth: DEPTH),
)"#;

const FOG: &str = "fog: (base: 0, top: 0.8, extinction: 0.3, albedo: (0.9, 0.9, 0.9)),";
const SKY: &str = "sky: (ground_elevation: 0),";
const CLOUDS: &str = "clouds: (region: (min: (-6, 3, -6), max: (6, 4, 6)), density: Layer((resolution: (16, 4, 16), feature_size: 3, octaves: 2, seed: 3, coverage: 0.6, threshold: 0.05)), scattering: 1, step: 0.2, sun_steps: 2),";

fn scene(on: Switches) -> Scene {
    let source = TEMPLATE
        .replace("FOG", if on.fog { FOG } else { "" })
        .replace("SKY", if on.sky { SKY } else { "" })
        .replace("CLOUDS", if on.clouds { CLOUDS } else { "" })
        .replace("DEPTH", if on.reflections { "6" } else { "0" });
    fray_scene::parse(&source, "switches.ron").unwrap()
}

fn render(scene: &Scene) -> fray_core::Frame {
    Renderer::new(RenderOptions {
        backend: Backend::Cpu,
        threads: Some(2),
        ..RenderOptions::default()
    })
    .render(scene)
    .unwrap()
}

#[test]
fn a_part_switched_off_renders_the_file_without_it_and_computes_none_of_it() {
    let full = scene(Switches::ALL_ON);
    let everything = render(&full);
    for (part, off) in [
        (
            "fog",
            Switches {
                fog: false,
                ..Switches::ALL_ON
            },
        ),
        (
            "sky",
            Switches {
                sky: false,
                ..Switches::ALL_ON
            },
        ),
        (
            "clouds",
            Switches {
                clouds: false,
                ..Switches::ALL_ON
            },
        ),
        (
            "reflections",
            Switches {
                reflections: false,
                ..Switches::ALL_ON
            },
        ),
    ] {
        let switched = render(&full.switched(off));
        let without = render(&scene(off));
        assert_eq!(
            switched.colour.pixels(),
            without.colour.pixels(),
            "{part} switched off"
        );
        assert_ne!(
            switched.colour.pixels(),
            everything.colour.pixels(),
            "switching {part} off changed nothing: the test scene does not show it"
        );
        let ran = &switched.stats.passes;
        match part {
            "fog" => assert!(!ran.iter().any(|p| p.contains("fog")), "{ran:?}"),
            "sky" => assert!(!ran.iter().any(|p| p.contains("sky")), "{ran:?}"),
            "clouds" => assert_eq!(switched.stats.cloud_samples, 0),
            _ => assert_eq!(switched.stats.secondary_rays, 0),
        }
    }
    // The full scene computed each part (the checks above are not vacuous).
    assert!(everything.stats.cloud_samples > 0);
    assert!(everything.stats.secondary_rays > 0);
    let ran = &everything.stats.passes;
    assert!(ran.iter().any(|p| p.contains("fog")), "{ran:?}");
    assert!(ran.iter().any(|p| p.contains("sky")), "{ran:?}");
}
