//! Mesh objects and Whitted materials in scene files: meshes load once per file (objects naming
//! the same file are instances of one BVH), placed by their transform; the feature set lists
//! meshes, reflection and transmission only for materials a primitive uses; and every bad value
//! or asset is a located error naming the field, the file, its line and the reason.

use std::path::PathBuf;
use std::sync::Arc;

fn scenes() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../data/scenes")
}

fn parse(src: &str) -> Result<fray_scene::Scene, String> {
    // Relative paths resolve against the (virtual) scene file's folder.
    let file = scenes().join("inline.ron");
    fray_scene::parse(src, &file.display().to_string()).map_err(|e| e.to_string())
}

#[test]
fn meshes_load_once_per_file_and_are_placed_by_their_transform() {
    let s = parse(
        "(materials: { \"glass\": (transmit: (0.9, 0.9, 0.9), ior: 1.5), \"unused\": (reflect: (1, 1, 1)) },
          objects: [
            (name: \"a\", material: \"glass\", shape: Mesh(path: \"../meshes/bunny00.obj\")),
            (name: \"b\", shape: Mesh(path: \"../meshes/../meshes/bunny00.obj\",
               transform: (scale: (2, 2, 2), translate: (10, 0, 0)), smooth: false)),
          ])",
    )
    .unwrap();
    assert_eq!(s.meshes.len(), 2);
    let (a, b) = (&s.meshes[0], &s.meshes[1]);
    assert!(Arc::ptr_eq(&a.instance.mesh, &b.instance.mesh), "one BVH");
    assert_eq!(a.instance.mesh.mesh().triangles.len(), 75_408);
    assert_eq!((a.material, b.material), (1, 0));
    assert!(a.smooth && !b.smooth);
    let (ba, bb) = (a.instance.bounds(), b.instance.bounds());
    assert!(((bb.center() - ba.center() * 2.0) - glam::DVec3::new(10.0, 0.0, 0.0)).length() < 1e-9);
    assert!((bb.diagonal() - 2.0 * ba.diagonal()).abs() < 1e-9);
    assert!(s.bounds().contains(bb.max) && s.bounds().contains(ba.min));
    let f = s.features;
    assert!(f.meshes && f.transmission && !f.reflection, "{f:?}");
    assert!(f.names().contains(&"meshes") && f.names().contains(&"transmission"));
    assert_eq!(
        s.primitives().map(|p| p.to_string()).collect::<Vec<_>>(),
        ["mesh 0", "mesh 1"]
    );
    assert_eq!(
        s.material_of(fray_scene::PrimitiveId::mesh(0), 123),
        Some(1)
    );
}

#[test]
fn whitted_materials_and_settings_resolve_with_defaults() {
    let s = parse(
        "(materials: { \"m\": (reflect: (0.5, 0.5, 0.5)), \"g\": (transmit: (1, 1, 1), fresnel: true) },
          objects: [(material: \"m\", shape: Sphere(radius: 1)), (material: \"g\", shape: Sphere(center: (3, 0, 0), radius: 1))],
          settings: (max_depth: 9, min_contribution: 0.01, max_secondary_rays: 100))",
    )
    .unwrap();
    let named = |n: &str| s.materials.iter().find(|m| m.name == n).unwrap();
    let (m, g) = (named("m"), named("g"));
    assert_eq!(m.reflect, fray_core::Rgb::splat(0.5));
    assert!(m.reflects() && !m.transmits());
    assert!(
        g.transmits() && g.reflects(),
        "Fresnel reflects what it transmits"
    );
    assert_eq!((g.ior, g.fresnel), (1.5, true));
    assert_eq!(
        (
            s.settings.max_depth,
            s.settings.min_contribution,
            s.settings.max_secondary_rays
        ),
        (9, 0.01, 100)
    );
    // Depth 9 would allow 2¹⁰ − 2 = 1022 rays per camera ray: the budget is the bound.
    assert_eq!(s.settings.secondary_rays_per_camera_ray(), 100);
    assert!(s.features.reflection && s.features.transmission);
    let d = parse("(objects: [(shape: Sphere(radius: 1))])").unwrap();
    assert_eq!(
        (
            d.settings.max_depth,
            d.settings.min_contribution,
            d.settings.max_secondary_rays
        ),
        (5, 1e-3, fray_scene::DEFAULT_MAX_SECONDARY_RAYS)
    );
    // Depth 5's full tree, 2⁶ − 2 = 62 rays, is within the default budget: the depth bounds.
    assert_eq!(d.settings.secondary_rays_per_camera_ray(), 62);
    let deep = parse("(settings: (max_depth: 64))").unwrap();
    assert_eq!(
        deep.settings.secondary_rays_per_camera_ray(),
        fray_scene::DEFAULT_MAX_SECONDARY_RAYS
    );
    assert!(!d.features.reflection && !d.features.transmission && !d.features.meshes);
}

#[test]
fn bad_meshes_and_whitted_values_are_located_errors() {
    let e = parse("(objects: [\n (shape: Mesh(path: \"nowhere.obj\")),\n])").unwrap_err();
    assert!(
        e.contains(":2:")
            && e.contains("objects[0].shape.path:")
            && e.contains("nowhere.obj")
            && e.contains("cannot read"),
        "{e}"
    );
    // A malformed OBJ: its path and line.
    let dir = std::env::temp_dir().join(format!("fray-scene-meshes-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let bad = dir.join("bad.obj");
    std::fs::write(&bad, "v 0 0 0\nv 1 0 0\nv 0 x 0\nf 1 2 3\n").unwrap();
    let e = parse(&format!(
        "(objects: [\n (shape: Mesh(path: {:?})),\n])",
        bad.display().to_string()
    ))
    .unwrap_err();
    assert!(
        e.contains("objects[0].shape.path:") && e.contains("bad.obj:3"),
        "{e}"
    );
    std::fs::remove_dir_all(&dir).ok();
    let e = parse(
        "(objects: [\n (shape: Mesh(path: \"../meshes/boeing.obj\", transform: (scale: (1, 0, 1)))),\n])",
    )
    .unwrap_err();
    assert!(e.contains("objects[0].shape.transform.scale:"), "{e}");
    let e = parse(
        "(objects: [\n (shape: Union([Sphere(radius: 1), Mesh(path: \"../meshes/boeing.obj\")])),\n])",
    )
    .unwrap_err();
    assert!(
        e.contains("a Mesh can only be an object's whole shape"),
        "{e}"
    );
    let e = parse("(materials: {\n \"g\": (ior: 0.5) })").unwrap_err();
    assert!(
        e.contains(":2:") && e.contains("materials.g.ior: must be in [1, 10]"),
        "{e}"
    );
    let e = parse("(materials: {\n \"g\": (reflect: (1.5, 0, 0)) })").unwrap_err();
    assert!(e.contains("materials.g.reflect:"), "{e}");
    let e = parse("(materials: {\n \"g\": (transmit: (0, -1, 0)) })").unwrap_err();
    assert!(e.contains("materials.g.transmit:"), "{e}");
    let e = parse("(settings: (max_depth: 2.5))").unwrap_err();
    assert!(
        e.contains("settings.max_depth: must be a whole number in 0..=64"),
        "{e}"
    );
    let e = parse("(settings: (max_depth: 65))").unwrap_err();
    assert!(e.contains("settings.max_depth"), "{e}");
    let e = parse("(settings: (min_contribution: 1))").unwrap_err();
    assert!(
        e.contains("settings.min_contribution: must be in [0, 1)"),
        "{e}"
    );
    for bad in ["-1", "2.5", "65537", "1e30"] {
        let e = parse(&format!("(settings: (\n max_secondary_rays: {bad}))")).unwrap_err();
        assert!(
            e.contains(":2:")
                && e.contains("settings.max_secondary_rays: must be a whole number in 0..=65536"),
            "{bad}: {e}"
        );
    }
    let most = parse("(settings: (max_secondary_rays: 65536))").unwrap();
    assert_eq!(
        most.settings.max_secondary_rays,
        fray_scene::MAX_SECONDARY_RAYS
    );
}

/// A mesh over the memory budget is refused before it is read into memory.
#[test]
fn a_mesh_over_the_budget_is_refused() {
    let options = fray_scene::BuildOptions {
        budget: fray_core::MemoryBudget::new(1 << 20),
        ..Default::default()
    };
    let file = scenes().join("inline.ron");
    let e = fray_scene::parse_with(
        "(objects: [(shape: Mesh(path: \"../meshes/bunny00.obj\"))])",
        &file.display().to_string(),
        &options,
    )
    .unwrap_err()
    .to_string();
    assert!(
        e.contains("objects[0].shape.path:") && e.contains("bunny00.obj"),
        "{e}"
    );
}

/// A mesh's BVH build is reserved on the scene's memory account before it starts, and the tree
/// and its packet data are charged to it for as long as the scene lives: the bunny's are in the
/// ledger at their exact sizes; a face of 2·10⁵ corners over 4 vertices loads within 32 MiB
/// (its load is bounded by ≈ 20 MB) but its BVH's build, ≈ 51 MB at its largest for 199 998
/// triangles, does not fit, and is refused at the `path` field.
#[test]
fn a_mesh_bvh_is_reserved_before_its_build_and_charged_to_the_scene() {
    let file = scenes().join("inline.ron");
    let options = fray_scene::BuildOptions {
        budget: fray_core::MemoryBudget::new(1 << 30),
        ..Default::default()
    };
    let s = fray_scene::parse_with(
        "(objects: [(shape: Mesh(path: \"../meshes/bunny00.obj\"))])",
        &file.display().to_string(),
        &options,
    )
    .unwrap();
    let bvh = &s.meshes[0].instance.mesh;
    let charged = |what: &str| {
        s.budget
            .ledger()
            .into_iter()
            .find(|(w, _)| w.starts_with(what) && w.contains("bunny00.obj (75408 triangles)"))
            .unwrap_or_else(|| panic!("{what} not in {:?}", s.budget.ledger()))
            .1
    };
    assert_eq!(charged("the BVH of the mesh"), bvh.bytes());
    // The mesh itself: its triangles (12 bytes each) and its vertices' positions and normals
    // (24 bytes each; the bunny has no UVs).
    let mesh = s
        .budget
        .ledger()
        .into_iter()
        .find(|(w, _)| w.starts_with("the mesh ") && w.ends_with("bunny00.obj"))
        .unwrap_or_else(|| panic!("the mesh not in {:?}", s.budget.ledger()))
        .1;
    let m = bvh.mesh();
    assert!(m.uvs.is_none());
    assert_eq!(mesh, 75_408 * 12 + m.positions.len() as u64 * 48);
    assert_eq!(
        charged("the packet data of the mesh"),
        fray_mesh::PacketBvh::bytes_for(bvh)
    );

    let dir = std::env::temp_dir().join(format!("fray-scene-mesh-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let obj = dir.join("face.obj");
    let corners = 200_000;
    let face: String = (0..corners)
        .map(|i| [" 1", " 2", " 3", " 4"][i % 4])
        .collect();
    std::fs::write(
        &obj,
        format!("v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nf{face}\n"),
    )
    .unwrap();
    let budget = 32 << 20;
    let build = fray_mesh::MeshBvh::build_bytes(corners - 2);
    assert!(build > budget, "{build}");
    let options = fray_scene::BuildOptions {
        budget: fray_core::MemoryBudget::new(budget),
        ..Default::default()
    };
    let e = fray_scene::parse_with(
        &format!(
            "(objects: [(shape: Mesh(path: {:?}))])",
            obj.display().to_string()
        ),
        &file.display().to_string(),
        &options,
    )
    .unwrap_err()
    .to_string();
    assert!(
        e.contains("objects[0].shape.path:")
            && e.contains("building the BVH of the mesh")
            && e.contains("face.obj (199998 triangles)")
            && e.contains(&format!("({build} bytes)")),
        "{e}"
    );
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn textures_load_once_and_bad_ones_are_located_errors() {
    let s = parse(
        "(materials: {
            \"a\": (texture: (path: \"../textures/brick.png\")),
            \"b\": (texture: (path: \"../textures/../textures/brick.png\", mapping: Triplanar(scale: 2), wrap: Mirror)),
            \"r\": (ramp: (height: [(0, (0, 0, 1)), (100, (1, 1, 1))], slope: [(30, (0.5, 0.4, 0.3, 1))])),
          })",
    )
    .unwrap();
    let named = |n: &str| s.materials.iter().find(|m| m.name == n).unwrap();
    let (a, b) = (
        named("a").texture.as_ref().unwrap(),
        named("b").texture.as_ref().unwrap(),
    );
    assert!(Arc::ptr_eq(&a.texture, &b.texture), "one image per file");
    assert_eq!((a.texture.width(), a.texture.height()), (512, 512));
    assert!(a.mapping.is_none() && b.mapping.is_some());
    assert!(named("r").ramp.is_some());
    let e = parse("(materials: {\n \"a\": (texture: (path: \"nowhere.png\")) })").unwrap_err();
    assert!(
        e.contains(":2:") && e.contains("materials.a.texture.path:") && e.contains("nowhere.png"),
        "{e}"
    );
    let e = parse(
        "(materials: {\n \"a\": (texture: (path: \"../textures/brick.png\", mapping: Planar(u_axis: (1, 0, 0), v_axis: (2, 0, 0)))) })",
    )
    .unwrap_err();
    assert!(e.contains("materials.a.texture.mapping.v_axis:"), "{e}");
    let e = parse("(materials: {\n \"a\": (ramp: (height: [(5, (1, 1, 1)), (1, (0, 0, 0))])) })")
        .unwrap_err();
    assert!(e.contains("materials.a.ramp.height:"), "{e}");
    let e = parse("(materials: {\n \"a\": (ramp: (height: [(0, (1, 1, 1))], slope: [(120, (0, 0, 0, 1))])) })")
        .unwrap_err();
    assert!(
        e.contains("materials.a.ramp.slope: slopes are degrees in [0, 90]"),
        "{e}"
    );
}

#[test]
fn textures_feature_is_set_only_by_a_used_textured_material() {
    let ramp = "\"r\": (ramp: (height: [(0, (0, 0, 1)), (1, (1, 1, 1))]))";
    let used = parse(&format!(
        "(materials: {{ {ramp} }}, objects: [(material: \"r\", shape: Sphere(radius: 1))])"
    ))
    .unwrap();
    assert!(used.features.textures && used.features.names().contains(&"textures"));
    let unused = parse(&format!(
        "(materials: {{ {ramp} }}, objects: [(shape: Sphere(radius: 1))])"
    ))
    .unwrap();
    assert!(!unused.features.textures, "{:?}", unused.features);
}

/// The polygonised turboprop (`data/meshes/turboprop_polygonised.obj`, made by `cargo xtask
/// polygonise` from `turboprop.ron`) is what its README says: closed (every edge in two
/// triangles, once each way), and every vertex on the free forms' surface with an outward
/// normal — F ≥ 0 1e-5 m behind it and F < 0 1e-5 m in front, for all 43 914 (the OBJ's six
/// decimals move a vertex by 1e-6) — in the twin scene, where it flies beside the free forms it
/// was made from.
#[test]
fn the_polygonised_turboprop_is_closed_and_on_the_free_forms_surface() {
    let s = fray_scene::load(&scenes().join("mesh_turboprop_twin.ron")).unwrap();
    assert_eq!(s.meshes.len(), 1);
    let mesh = s.meshes[0].instance.mesh.mesh();
    assert_eq!(
        (mesh.positions.len(), mesh.triangles.len()),
        (43_914, 87_780)
    );
    let mut edges = std::collections::HashMap::<(u32, u32), u32>::new();
    for t in &mesh.triangles {
        for e in 0..3 {
            *edges.entry((t[e], t[(e + 1) % 3])).or_default() += 1;
        }
    }
    assert!(
        edges
            .iter()
            .all(|(&(a, b), &n)| n == 1 && edges.get(&(b, a)) == Some(&1)),
        "not closed and consistently wound"
    );
    let field = |p: glam::DVec3| {
        s.objects
            .iter()
            .map(|o| o.solid.eval(p))
            .fold(f64::NEG_INFINITY, f64::max)
    };
    // F changes sign within 1e-5 m of every vertex along its normal: inside behind, outside in
    // front (further out, thin parts such as the cheat line, proud of the body by mm, would
    // cross F = 0 twice).
    let straddles =
        |p: glam::DVec3, n: glam::DVec3| field(p - n * 1e-5) >= 0.0 && field(p + n * 1e-5) < 0.0;
    let off = mesh
        .positions
        .iter()
        .zip(&mesh.normals)
        .filter(|&(p, n)| !straddles(*p, *n))
        .count();
    assert_eq!(off, 0, "vertices off the surface or normals inward");
}
