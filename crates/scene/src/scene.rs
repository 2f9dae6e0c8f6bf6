//! The resolved scene: what a scene file means once parsed and validated, ready for a backend.

use crate::FeatureSet;
use crate::description::TerrainLod;
use fray_core::{MemoryBudget, PixelSamples, Projector, Rgb};
use fray_geometry::Solid;
use fray_mesh::Instance;
use fray_terrain::Terrain;
use glam::DVec3;
use std::sync::Arc;

/// A validated scene. Every field holds checked values; backends never re-validate.
#[derive(Clone, Debug)]
pub struct Scene {
    /// Output size in pixels.
    pub width: u32,
    pub height: u32,
    pub camera: Projector,
    /// The file's named cameras, in name order ([`Scene::with_camera`]).
    pub cameras: Vec<NamedCamera>,
    /// Motion over time ([`Scene::at_time`]); `None` for a still, and in the scenes `at_time`
    /// returns (a frame of an animation is a still).
    pub animation: Option<Arc<crate::Animation>>,
    /// Radiance of rays that hit nothing (linear RGB).
    pub background: Rgb,
    /// Uniform ambient radiance that lights every surface through its `ambient` reflectance.
    pub ambient: Rgb,
    pub lights: Vec<Light>,
    pub materials: Vec<Material>,
    pub objects: Vec<Object>,
    /// Height-map terrains, built once (pyramids included) and shared by the backends.
    pub terrains: Vec<TerrainObject>,
    /// Triangle meshes: instances of meshes loaded and built (BVH) once per file.
    pub meshes: Vec<MeshObject>,
    /// Fog (and later sky) between the camera and the surfaces; empty by default.
    pub atmosphere: crate::Atmosphere,
    /// A cloud volume, baked or loaded once and shared by the backends; `None` by default.
    pub clouds: Option<Arc<crate::Clouds>>,
    pub settings: Settings,
    /// What this scene uses; backends build only what is listed.
    pub features: FeatureSet,
    /// The render's memory account: what the scene built is charged to it, and the backends
    /// charge their frames, work lists and device buffers to it too.
    pub budget: MemoryBudget,
}

/// A camera the file names (`cameras: {"side": Pinhole(…)}`).
#[derive(Clone, Debug, PartialEq)]
pub struct NamedCamera {
    pub name: String,
    pub camera: Projector,
}

/// Render settings stored in the scene (command-line options override them).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Settings {
    /// Ray-casting tolerance in world units; `None` = `1e-10 ×` the scene's size.
    pub epsilon: Option<f64>,
    /// Whether lights cast shadows (shadow rays).
    pub shadows: bool,
    /// Anti-aliasing: stratified samples per pixel, box-filtered (depth and normals still come
    /// from the pixel centre). One sample is the pixel centre.
    pub samples: PixelSamples,
    /// Whitted recursion: the most reflections/refractions after the camera ray.
    pub max_depth: u32,
    /// Whitted recursion: secondary rays whose weight (largest channel) is below this are not
    /// traced.
    pub min_contribution: f64,
    /// Whitted recursion: the most secondary rays one camera ray (sample) traces, whatever the
    /// depth. Each ray's allowance is shared between its children (the reflected ray first), so
    /// the rule is the same depth first (CPU) and level by level (GPU); a tree of `max_depth`
    /// levels fits whole when this is at least `2^(max_depth + 1) − 2`
    /// ([`Settings::secondary_rays_per_camera_ray`]).
    pub max_secondary_rays: u32,
}

/// The default [`Settings::max_secondary_rays`]: 256 holds a full binary tree of reflections
/// and refractions 7 levels deep (254 rays), every tree the default depth (5) or the data
/// scenes (at most 6) can grow, so it changes none of their images; it bounds a deep scene's
/// camera ray to 256 secondary rays where the depth alone would allow `2^(max_depth + 1) − 2`.
pub const DEFAULT_MAX_SECONDARY_RAYS: u32 = 256;

impl Settings {
    /// The most secondary rays one camera ray can trace under these settings: the budget, or
    /// the full binary tree of `max_depth` levels (`2^(max_depth + 1) − 2`) where that is fewer.
    pub fn secondary_rays_per_camera_ray(&self) -> u32 {
        let full_tree = 1u64
            .checked_shl(self.max_depth + 1)
            .map_or(u64::MAX, |n| n - 2);
        full_tree.min(u64::from(self.max_secondary_rays)) as u32
    }
}

impl Default for Settings {
    fn default() -> Self {
        Self {
            epsilon: None,
            shadows: true,
            samples: PixelSamples::ONE,
            max_depth: 5,
            min_contribution: 1e-3,
            max_secondary_rays: DEFAULT_MAX_SECONDARY_RAYS,
        }
    }
}

/// A light source in radiometric units.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Light {
    /// A distant light: `direction` is the unit vector *toward* the sun; `irradiance` (W/m²) is
    /// measured on a surface facing it.
    Sun { direction: DVec3, irradiance: Rgb },
    /// A point light of radiant `intensity` (W/sr): irradiance `I cosθ / r²`.
    Point { position: DVec3, intensity: Rgb },
}

/// A Whitted material. Outgoing radiance at a point lit by irradiance `E` from direction `L`:
/// `ambient · A + E · (diffuse / π + specular · (shininess + 2) / (2π) · max(0, R·V)^shininess)`,
/// the normalised Phong lobe so that `diffuse + specular ≤ 1` conserves energy; plus
/// `kr · I_reflected + kt · I_transmitted` (the Whitted sum), Fresnel-weighted if asked.
#[derive(Clone, Debug, PartialEq)]
pub struct Material {
    pub name: String,
    /// Reflectance to the scene's ambient radiance.
    pub ambient: Rgb,
    /// Lambertian albedo in `[0, 1]`.
    pub diffuse: Rgb,
    /// Specular reflectance in `[0, 1]`.
    pub specular: Rgb,
    /// Phong exponent (≥ 0).
    pub shininess: f64,
    /// Mirror reflectance `kr` in `[0, 1]`.
    pub reflect: Rgb,
    /// Transmittance `kt` in `[0, 1]` (refraction; shadow rays keep `kt` per surface crossed).
    pub transmit: Rgb,
    /// The inside's index of refraction (the outside is 1).
    pub ior: f64,
    /// Reflection `kr + F·kt` and transmission `(1 − F)·kt` with the Fresnel reflectance `F`.
    pub fresnel: bool,
    /// An image whose colour `C` multiplies `diffuse` and `ambient`.
    pub texture: Option<crate::TextureSlot>,
    /// A colour by height and slope (terrains) multiplying `diffuse` and `ambient`.
    pub ramp: Option<fray_mesh::texture::TerrainRamp>,
}

impl Material {
    /// Whether the material sends reflected rays.
    pub fn reflects(&self) -> bool {
        self.reflect != Rgb::ZERO || (self.fresnel && self.transmit != Rgb::ZERO)
    }

    /// Whether light passes through it (refracted rays, shadow rays dimmed rather than stopped).
    pub fn transmits(&self) -> bool {
        self.transmit != Rgb::ZERO
    }
}

impl Default for Material {
    fn default() -> Self {
        Self {
            name: "default".into(),
            ambient: Rgb::splat(0.8),
            diffuse: Rgb::splat(0.8),
            specular: Rgb::ZERO,
            shininess: 32.0,
            reflect: Rgb::ZERO,
            transmit: Rgb::ZERO,
            ior: 1.5,
            fresnel: false,
            texture: None,
            ramp: None,
        }
    }
}

/// One top-level object: a CSG solid with a material per leaf.
#[derive(Clone, Debug)]
pub struct Object {
    pub name: String,
    pub solid: Solid,
    /// Index into [`Scene::materials`] for each leaf of `solid`, in leaf order.
    pub leaf_materials: Vec<u32>,
}

/// A height-map terrain object: one material for all of it.
#[derive(Clone, Debug)]
pub struct TerrainObject {
    pub name: String,
    pub terrain: Arc<Terrain>,
    /// Index into [`Scene::materials`].
    pub material: u32,
    /// How camera rays choose the level of detail ([`TerrainLod::Pixel`]: from the camera's
    /// pixel footprint, coarser by the terrain's LOD bias; [`TerrainLod::Exact`]: the finest
    /// level, or the fixed level `n − lod_bias`). Shadow rays are always exact.
    pub lod: TerrainLod,
    /// How its heights change with time: [`Scene::at_time`] gives the still the terrain at `t`
    /// (and `None` here). `None`: the heights are the file's.
    pub heights: Option<Arc<crate::animation::Heights>>,
    /// What a still's terrain at a time holds on the scene's budget, released with the last
    /// copy of the still; `None` for the file's terrain.
    pub frame_memory: Option<Arc<fray_core::Reservation>>,
}

/// A triangle-mesh object: an instance of a loaded mesh, one material for all of it.
#[derive(Clone, Debug)]
pub struct MeshObject {
    pub name: String,
    /// The mesh (shared with every object naming the same file) and its placement.
    pub instance: Instance,
    /// Index into [`Scene::materials`].
    pub material: u32,
    /// Shade with interpolated vertex normals (`false`: facets).
    pub smooth: bool,
}

// What a scene answers per primitive kind (`count`, `primitive_bounds`, `material_of`, …) is
// in `kinds/mod.rs`, which asks each kind.
impl Scene {
    /// A scene with no primitives yet (each kind's storage empty), default settings, no
    /// atmosphere or clouds, and no features: what resolution starts from.
    #[allow(clippy::too_many_arguments)]
    pub(crate) fn empty(
        width: u32,
        height: u32,
        camera: Projector,
        background: Rgb,
        ambient: Rgb,
        lights: Vec<Light>,
        materials: Vec<Material>,
        budget: MemoryBudget,
    ) -> Self {
        Self {
            width,
            height,
            camera,
            cameras: Vec::new(),
            animation: None,
            background,
            ambient,
            lights,
            materials,
            // The kinds' storage: one line per kind.
            objects: Vec::new(),
            terrains: Vec::new(),
            meshes: Vec::new(),
            atmosphere: crate::Atmosphere::default(),
            clouds: None,
            settings: Settings::default(),
            features: FeatureSet::default(),
            budget,
        }
    }

    /// The tolerance to use: the setting, or `1e-10 ×` the scene's diagonal (1e-10 if empty).
    pub fn epsilon(&self) -> f64 {
        self.settings.epsilon.unwrap_or_else(|| {
            let d = self.bounds().diagonal();
            if d > 0.0 && d.is_finite() {
                1e-10 * d
            } else {
                1e-10
            }
        })
    }
}
