//! The feature set: which capabilities a scene uses, so backends build and run only those.

/// What a scene uses. Computed by validation; backends consult it to skip absent features.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct FeatureSet {
    /// At least one free-form object.
    pub free_forms: bool,
    /// At least one perturbation with a non-zero form factor.
    pub perturbations: bool,
    /// At least one CSG operation (union, intersection, difference).
    pub csg: bool,
    /// At least one height-map terrain.
    pub terrain: bool,
    /// Lights exist and shadows are on: shadow rays are cast.
    pub shadows: bool,
    /// At least one directional light.
    pub sun: bool,
    /// At least one point light.
    pub point_lights: bool,
    /// A fog layer.
    pub fog: bool,
    /// A physically based sky.
    pub sky: bool,
    /// A cloud volume.
    pub clouds: bool,
    /// At least one triangle mesh.
    pub meshes: bool,
    /// A primitive's material reflects (`kr`, or Fresnel with `kt`): reflected rays are traced.
    pub reflection: bool,
    /// A primitive's material transmits (`kt`): refracted rays are traced and shadow rays pass
    /// through it, dimmed.
    pub transmission: bool,
    /// A primitive's material takes its colour from an image texture or a colour ramp.
    pub textures: bool,
}

impl FeatureSet {
    /// The names of the features in use, in a fixed order (for stats and logs).
    pub fn names(&self) -> Vec<&'static str> {
        [
            (self.free_forms, "free-form"),
            (self.perturbations, "perturbations"),
            (self.csg, "csg"),
            (self.terrain, "terrain"),
            (self.shadows, "shadows"),
            (self.sun, "sun"),
            (self.point_lights, "point-lights"),
            (self.fog, "fog"),
            (self.sky, "sky"),
            (self.clouds, "clouds"),
            (self.meshes, "meshes"),
            (self.reflection, "reflection"),
            (self.transmission, "transmission"),
            (self.textures, "textures"),
        ]
        .into_iter()
        .filter_map(|(on, name)| on.then_some(name))
        .collect()
    }
}
