//! The text of scenes that more than one crate's tests render (each test parses it with
//! `fray_scene::parse`): the CPU's tests and the GPU's parity tests then see the same scene.

/// Two glass plates (400 × 210 × 0.25, 2 apart, `kr = kt = 0.5`, no Fresnel,
/// `min_contribution: 0`) under a sun, seen from between them: nearly every hit spawns two rays.
pub fn two_plates(width: u32, height: u32, depth: u32, budget: u32) -> String {
    format!(
        "Scene(image: (width: {width}, height: {height}),
           camera: Pinhole(eye: (0, 0, 0), look_at: (0, 0.2, 10), fov_y: 70),
           background: (0.3, 0.45, 0.7), ambient: (0.05, 0.05, 0.05),
           lights: [Sun(direction: (0.2, 1, -0.3), irradiance: (2, 2, 2))],
           materials: {{ \"plate\": (diffuse: (0.1, 0.1, 0.1), specular: (0.2, 0.2, 0.2), shininess: 50,
                                     reflect: (0.5, 0.5, 0.5), transmit: (0.5, 0.5, 0.5), ior: 1.5) }},
           objects: [
             (material: \"plate\", shape: FreeForm(base: HalfSpace(point: (0, -1, 0), normal: (0, 1, 0)),
                bounds: (min: (-200, -1.25, -10), max: (200, -1, 200)))),
             (material: \"plate\", shape: FreeForm(base: HalfSpace(point: (0, 1, 0), normal: (0, -1, 0)),
                bounds: (min: (-200, 1, -10), max: (200, 1.25, 200)))),
           ],
           settings: (max_depth: {depth}, min_contribution: 0, max_secondary_rays: {budget}))"
    )
}

/// Two concentric glass shells (radii 1.8–2 and 3–3.2, `kr = kt = 0.5`) round the camera,
/// 16 × 12 pixels: every secondary ray of the first three levels meets a surface that reflects
/// and transmits, so each camera ray's tree at depth 4 is full, `2⁵ − 2 = 30` rays.
pub fn shells(depth: u32, budget: u32) -> String {
    format!(
        "Scene(image: (width: 16, height: 12),
           camera: Pinhole(eye: (0, 0, 0), look_at: (0.3, 0.2, 1), fov_y: 60, near: 0.05),
           background: (0.3, 0.45, 0.7), ambient: (0.05, 0.05, 0.05),
           lights: [Point(position: (0.5, 0.5, 0.2), intensity: (1, 1, 1))],
           materials: {{ \"glass\": (diffuse: (0.1, 0.1, 0.1), reflect: (0.5, 0.5, 0.5), transmit: (0.5, 0.5, 0.5), ior: 1.5) }},
           objects: [
             (material: \"glass\", shape: Difference(Sphere(radius: 2), Sphere(radius: 1.8))),
             (material: \"glass\", shape: Difference(Sphere(radius: 3.2), Sphere(radius: 3))),
           ],
           settings: (max_depth: {depth}, min_contribution: 0, max_secondary_rays: {budget}))"
    )
}
