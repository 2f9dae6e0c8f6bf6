//! Parts of a scene switched off for a look without them (the viewer's toggles): the fog, the
//! sky, the clouds, Whitted's reflected and refracted rays.

use crate::Scene;

/// Which of a scene's optional parts stay on ([`Scene::switched`]). A part the scene lacks is
/// absent whatever its switch says.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct Switches {
    /// The fog layer.
    pub fog: bool,
    /// The physically based sky: without it, rays that hit nothing take the scene's
    /// `background`, nothing dims the air in front of surfaces, and the sun's light arrives as
    /// given (not through the atmosphere).
    pub sky: bool,
    /// The cloud volume.
    pub clouds: bool,
    /// Whitted's reflected and refracted rays (`max_depth` 0 when off). Shadow rays still pass
    /// through transmissive surfaces, dimmed.
    pub reflections: bool,
}

impl Switches {
    /// Everything the scene has stays on.
    pub const ALL_ON: Self = Self {
        fog: true,
        sky: true,
        clouds: true,
        reflections: true,
    };
}

impl Default for Switches {
    fn default() -> Self {
        Self::ALL_ON
    }
}

impl Scene {
    /// This scene with the parts `on` leaves off removed, and its [`crate::FeatureSet`] saying
    /// so: a backend given the result builds, compiles and computes nothing of them — the
    /// image a file without those parts makes.
    pub fn switched(&self, on: Switches) -> Scene {
        let mut scene = self.clone();
        if !on.fog {
            scene.atmosphere.fog = None;
            scene.features.fog = false;
        }
        if !on.sky {
            scene.atmosphere.sky = None;
            scene.features.sky = false;
        }
        if !on.clouds {
            scene.clouds = None;
            scene.features.clouds = false;
        }
        if !on.reflections {
            scene.settings.max_depth = 0;
            // Transmission stays: it also dims shadow rays, which are not Whitted's.
            scene.features.reflection = false;
        }
        scene
    }
}
