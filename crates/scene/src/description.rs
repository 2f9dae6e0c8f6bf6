//! The scene description: serde types that mirror a RON scene file field for field, before
//! validation (see `docs/scene-format.md` for the reference).
//!
//! Vectors and colours are RON tuples `(x, y, z)`, angles are in degrees, every optional field has
//! a default, and unknown fields are rejected. Nothing here is checked beyond its type: ranges,
//! finiteness, names and boundedness are checked when the description is resolved into a
//! [`crate::Scene`].

use serde::de::Error as _;
use serde::{Deserialize, Deserializer};
use std::collections::BTreeMap;

/// A 3-vector or linear RGB colour, written `(x, y, z)`.
pub type Vec3 = [f64; 3];

/// The whole scene file: `Scene(image: …, camera: …, …)` (the `Scene` name is optional).
#[derive(Clone, Debug, PartialEq, Deserialize)]
#[serde(deny_unknown_fields, rename = "Scene")]
pub struct Scene {
    /// Other scene files (relative to this one) whose `materials` and `objects` this scene
    /// uses, as if written here (their other fields are ignored). Each is checked as a scene of
    /// its own first, so its errors name it; a material name defined differently in two files
    /// is an error.
    #[serde(default)]
    pub include: Vec<String>,
    #[serde(default)]
    pub image: Image,
    #[serde(default)]
    pub camera: Camera,
    /// More cameras by name (`fray render --camera NAME`, the viewer's number keys in name
    /// order); `camera` stays the default.
    #[serde(default)]
    pub cameras: BTreeMap<String, Camera>,
    /// Motion over time: a camera path, object tracks, the sun's direction (default: a still).
    #[serde(default)]
    pub animation: Option<Animation>,
    /// Radiance of rays that hit nothing (linear RGB).
    #[serde(default = "default_background")]
    pub background: Vec3,
    /// Uniform ambient radiance.
    #[serde(default = "default_ambient")]
    pub ambient: Vec3,
    #[serde(default)]
    pub lights: Vec<Light>,
    /// Named materials; resolved in sorted-name order after the built-in default material.
    #[serde(default)]
    pub materials: BTreeMap<String, Material>,
    #[serde(default)]
    pub objects: Vec<Object>,
    /// Fog and sky: media between the camera and what it sees (default: none).
    #[serde(default)]
    pub atmosphere: Atmosphere,
    /// A volume of cloud (or any density grid) marched with sun rays (default: none).
    #[serde(default)]
    pub clouds: Option<Clouds>,
    #[serde(default)]
    pub settings: Settings,
}

fn default_background() -> Vec3 {
    [0.05, 0.05, 0.08]
}

fn default_ambient() -> Vec3 {
    [0.03, 0.03, 0.03]
}

/// Output size in pixels, each in `1..=16384`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Image {
    #[serde(default = "default_width", deserialize_with = "pixels")]
    pub width: u32,
    #[serde(default = "default_height", deserialize_with = "pixels")]
    pub height: u32,
}

/// A pixel count: any number is read, so `1.5` or `-3` gets a clear message instead of a syntax
/// error.
fn pixels<'de, D: Deserializer<'de>>(d: D) -> Result<u32, D::Error> {
    let v = f64::deserialize(d)?;
    let max = crate::MAX_IMAGE_SIDE;
    if v.fract() == 0.0 && v >= 1.0 && v <= f64::from(max) {
        Ok(v as u32)
    } else {
        Err(D::Error::custom(format!(
            "must be a whole number of pixels in 1..={max}, got {v}"
        )))
    }
}

fn default_width() -> u32 {
    640
}

fn default_height() -> u32 {
    480
}

impl Default for Image {
    fn default() -> Self {
        Self {
            width: default_width(),
            height: default_height(),
        }
    }
}

/// The projector. Angles in degrees.
#[derive(Clone, Debug, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub enum Camera {
    /// A pinhole camera with a planar picture `near` in front of the eye.
    Pinhole {
        eye: Vec3,
        look_at: Vec3,
        #[serde(default = "default_up")]
        up: Vec3,
        /// Vertical field of view in degrees, in `(0, 180)`.
        #[serde(default = "default_fov_y")]
        fov_y: f64,
        /// Distance to the picture plane (the near clip), `> 0`.
        #[serde(default = "default_near")]
        near: f64,
    },
    /// A parallel projection; the picture is `height` world units tall.
    Parallel {
        eye: Vec3,
        look_at: Vec3,
        #[serde(default = "default_up")]
        up: Vec3,
        height: f64,
        #[serde(default)]
        near: f64,
    },
    /// A spherical (optionally rippled) picture surface around `centre`, seen from `eye`.
    Sphere {
        eye: Vec3,
        /// Defaults to `eye`.
        #[serde(default)]
        centre: Option<Vec3>,
        look_at: Vec3,
        #[serde(default = "default_up")]
        up: Vec3,
        /// Degrees, in `(0, 360]`.
        #[serde(default = "default_sphere_fov_x")]
        fov_x: f64,
        /// Degrees, in `(0, 180]`.
        #[serde(default = "default_sphere_fov_y")]
        fov_y: f64,
        #[serde(default = "one")]
        radius: f64,
        #[serde(default)]
        ripple_amplitude: f64,
        #[serde(default)]
        ripple_frequency: f64,
    },
}

impl Default for Camera {
    /// `Pinhole(eye: (0, 1, -5), look_at: (0, 0, 0))` with the other defaults.
    fn default() -> Self {
        Camera::Pinhole {
            eye: [0.0, 1.0, -5.0],
            look_at: [0.0, 0.0, 0.0],
            up: default_up(),
            fov_y: default_fov_y(),
            near: default_near(),
        }
    }
}

fn default_up() -> Vec3 {
    [0.0, 1.0, 0.0]
}

fn default_fov_y() -> f64 {
    45.0
}

fn default_near() -> f64 {
    0.01
}

fn default_sphere_fov_x() -> f64 {
    360.0
}

fn default_sphere_fov_y() -> f64 {
    180.0
}

fn one() -> f64 {
    1.0
}

fn ones() -> Vec3 {
    [1.0, 1.0, 1.0]
}

fn zeros() -> Vec3 {
    [0.0, 0.0, 0.0]
}

fn y_axis() -> Vec3 {
    [0.0, 1.0, 0.0]
}

/// A light source in radiometric units.
#[derive(Clone, Debug, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub enum Light {
    /// A distant light; `direction` points *toward* the sun (normalised when resolved).
    Sun {
        direction: Vec3,
        /// W/m² on a surface facing the sun.
        #[serde(default = "default_irradiance")]
        irradiance: Vec3,
    },
    /// A point light of radiant intensity `intensity` (W/sr).
    Point {
        position: Vec3,
        #[serde(default = "default_intensity")]
        intensity: Vec3,
    },
}

fn default_irradiance() -> Vec3 {
    [3.0, 3.0, 3.0]
}

fn default_intensity() -> Vec3 {
    [50.0, 50.0, 50.0]
}

/// A named material; every field is optional (defaults: [`crate::Material::default`]).
#[derive(Clone, Debug, Default, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Material {
    /// Lambertian albedo in `[0, 1]`; default `(0.8, 0.8, 0.8)`.
    #[serde(default)]
    pub diffuse: Option<Vec3>,
    /// Specular reflectance in `[0, 1]`; default `(0, 0, 0)`.
    #[serde(default)]
    pub specular: Option<Vec3>,
    /// Phong exponent `≥ 0`; default 32.
    #[serde(default)]
    pub shininess: Option<f64>,
    /// Reflectance to the ambient radiance in `[0, 1]`; default: the diffuse albedo.
    #[serde(default)]
    pub ambient: Option<Vec3>,
    /// Mirror reflectance `kr` in `[0, 1]`: the weight of the reflected ray's radiance;
    /// default `(0, 0, 0)`.
    #[serde(default)]
    pub reflect: Option<Vec3>,
    /// Transmittance `kt` in `[0, 1]`: the weight of the refracted ray's radiance, and what a
    /// shadow ray keeps per surface of this material it crosses; default `(0, 0, 0)` (opaque).
    #[serde(default)]
    pub transmit: Option<Vec3>,
    /// Index of refraction of the inside (the outside is vacuum, 1), `≥ 1`; default 1.5.
    #[serde(default)]
    pub ior: Option<f64>,
    /// Weight reflection and transmission by the dielectric Fresnel reflectance `F(θ)`:
    /// reflected `kr + F·kt`, transmitted `(1 − F)·kt`; default `false` (`kr` and `kt` as given).
    #[serde(default)]
    pub fresnel: bool,
    /// An image whose colour multiplies `diffuse` and `ambient` (Whitted's `C`).
    #[serde(default)]
    pub texture: Option<MaterialTexture>,
    /// A terrain colour by height (world y) and slope, multiplying `diffuse` and `ambient`.
    #[serde(default)]
    pub ramp: Option<ColourRamp>,
}

/// A material's texture: the image, how surfaces map to it and how it is read.
#[derive(Clone, Debug, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct MaterialTexture {
    /// A `.png` (8/16-bit) or `.exr` image, relative to the scene file.
    pub path: String,
    /// How a surface point finds its texture coordinates; default `Uv` (the surface's own:
    /// a mesh's file UVs, a terrain's map — the image draped over it).
    #[serde(default)]
    pub mapping: TextureMapping,
    /// Outside `[0, 1]`: `Repeat` (default), `Clamp` or `Mirror`.
    #[serde(default)]
    pub wrap: TextureWrap,
    /// `Trilinear` (default: mipmapped by the pixel's footprint), `Bilinear` or `Nearest`
    /// (point samples of the full image: they alias when minified).
    #[serde(default)]
    pub filter: TextureFilter,
    /// `false` (default): the PNG is sRGB colour, decoded to linear; `true`: linear data.
    #[serde(default)]
    pub linear: bool,
}

/// How a surface point maps to texture coordinates.
#[derive(Clone, Debug, Default, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub enum TextureMapping {
    /// The surface's own coordinates (meshes' UVs, terrains' map); surfaces without them (free
    /// forms) take the image's mean colour.
    #[default]
    Uv,
    /// Onto a plane: `u = (p − origin)·u_axis · scale.0`, `v = (p − origin)·v_axis · scale.1`.
    Planar {
        #[serde(default = "zeros")]
        origin: Vec3,
        #[serde(default = "x_axis")]
        u_axis: Vec3,
        #[serde(default = "z_axis")]
        v_axis: Vec3,
        /// uv per world unit along each axis (1 / the tile's size).
        #[serde(default = "unit_spacing")]
        scale: [f64; 2],
    },
    /// Longitude and latitude about `centre`, `repeat` times around and up.
    Spherical {
        #[serde(default = "zeros")]
        centre: Vec3,
        #[serde(default = "y_axis")]
        pole: Vec3,
        #[serde(default = "x_axis")]
        seam: Vec3,
        #[serde(default = "unit_spacing")]
        repeat: [f64; 2],
    },
    /// The angle around `axis` (`repeat` times) and the height along it (`scale` uv per unit).
    Cylindrical {
        #[serde(default = "zeros")]
        origin: Vec3,
        #[serde(default = "y_axis")]
        axis: Vec3,
        #[serde(default = "x_axis")]
        seam: Vec3,
        #[serde(default = "one")]
        repeat: f64,
        #[serde(default = "one")]
        scale: f64,
    },
    /// Three axis-aligned planar projections blended by the normal (`|n|^sharpness`).
    Triplanar {
        #[serde(default = "zeros")]
        origin: Vec3,
        /// uv per world unit.
        #[serde(default = "one")]
        scale: f64,
        #[serde(default = "four")]
        sharpness: f64,
    },
}

/// Texture wrap modes (both axes).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Deserialize)]
pub enum TextureWrap {
    #[default]
    Repeat,
    Clamp,
    Mirror,
}

/// Texture filters.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Deserialize)]
pub enum TextureFilter {
    #[default]
    Trilinear,
    Bilinear,
    Nearest,
}

/// A colour ramp for terrain: piecewise-linear colours by world height, and optionally by slope
/// (degrees from flat) laid over them by each stop's alpha.
#[derive(Clone, Debug, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ColourRamp {
    /// `(height, (r, g, b))` stops, heights increasing.
    pub height: Vec<(f64, Vec3)>,
    /// `(degrees, (r, g, b, alpha))` stops, slopes increasing in `[0, 90]`.
    #[serde(default)]
    pub slope: Vec<(f64, [f64; 4])>,
}

fn x_axis() -> Vec3 {
    [1.0, 0.0, 0.0]
}

fn z_axis() -> Vec3 {
    [0.0, 0.0, 1.0]
}

fn four() -> f64 {
    4.0
}

/// One top-level object.
#[derive(Clone, Debug, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Object {
    /// Default: `object<i>`, `i` the object's index.
    #[serde(default)]
    pub name: Option<String>,
    /// A key of `materials`; default: the built-in default material.
    #[serde(default)]
    pub material: Option<String>,
    pub shape: Shape,
}

/// A CSG tree of free-form objects. In a file, any [`Quadric`] variant may stand for a shape
/// directly (a free-form object with no perturbations), e.g. `shape: Sphere(radius: 1)`.
#[derive(Clone, Debug, PartialEq, Deserialize)]
#[serde(from = "ShapeRepr")]
pub enum Shape {
    FreeForm(FreeForm),
    /// Shorthand for a [`FreeForm`] with only a base quadric.
    Quadric(Quadric),
    Union(Vec<Shape>),
    Intersection(Vec<Shape>),
    Difference(Box<Shape>, Box<Shape>),
    /// `shape` with `transform` applied to every quadric below it (not to explicit `bounds`).
    Transformed {
        shape: Box<Shape>,
        transform: Transform,
    },
    /// A height-map terrain (only as an object's whole shape, never inside CSG).
    Terrain(Terrain),
    /// A triangle mesh from an OBJ file (only as an object's whole shape, never inside CSG).
    Mesh(Mesh),
}

impl Shape {
    /// The kind of primitive an object of this shape is (everything but a whole-shape kind is a
    /// free form's CSG tree).
    pub(crate) fn kind(&self) -> crate::PrimitiveKind {
        match self {
            Shape::Terrain(_) => crate::PrimitiveKind::Terrain,
            Shape::Mesh(_) => crate::PrimitiveKind::Mesh,
            _ => crate::PrimitiveKind::FreeForm,
        }
    }

    /// Why this shape cannot be part of a CSG tree or a `Transformed` shape (the kinds other
    /// than free forms are only ever an object's whole shape).
    pub(crate) fn whole_shape_only(&self) -> &'static str {
        match self {
            Shape::Terrain(_) => {
                "a Terrain can only be an object's whole shape, not part of a CSG tree or a \
                 Transformed shape (place it with its `origin` and `rotate`)"
            }
            Shape::Mesh(_) => {
                "a Mesh can only be an object's whole shape, not part of a CSG tree or a \
                 Transformed shape (place it with its `transform`)"
            }
            _ => "a free form is part of a CSG tree",
        }
    }

    /// The files this shape reads, relative to the scene file (none for a CSG tree: its leaves
    /// read none).
    pub(crate) fn asset_paths_mut(&mut self) -> Vec<&mut String> {
        match self {
            Shape::Terrain(t) => {
                let mut paths = vec![&mut t.path];
                if let Some(TerrainAnimate::Sequence { paths: frames, .. }) = &mut t.animate {
                    paths.extend(frames.iter_mut());
                }
                paths
            }
            Shape::Mesh(m) => vec![&mut m.path],
            _ => Vec::new(),
        }
    }
}

/// A triangle mesh: the OBJ file and its placement. Objects naming the same file share one
/// loaded mesh and BVH (instances).
#[derive(Clone, Debug, PartialEq)]
pub struct Mesh {
    /// The `.obj` file, relative to the scene file.
    pub path: String,
    /// Scale, rotate, translate from the file's coordinates to the world.
    pub transform: Transform,
    /// Shade with the vertex normals interpolated (the file's, or computed angle-weighted);
    /// `false`: each triangle's own normal (facets). Default `true`.
    pub smooth: bool,
}

/// A height-map terrain: the file, its placement and how it is searched.
#[derive(Clone, Debug, PartialEq)]
pub struct Terrain {
    /// The height map (`.png` 8/16-bit greyscale, `.exr`, `.npy`), relative to the scene file.
    pub path: String,
    /// World distance between samples along `x` (columns) and `z` (rows), `> 0`.
    pub spacing: [f64; 2],
    /// World units per raw height unit, `> 0`.
    pub vertical_scale: f64,
    /// World position of sample `(0, 0)` at raw height 0 (the base plane).
    pub origin: Vec3,
    /// Degrees about x, y, z (in that order) about `origin`.
    pub rotate: Vec3,
    pub interpolation: TerrainInterpolation,
    /// How the camera's rays choose the level of detail (default: the pixel footprint).
    pub lod: TerrainLod,
    /// Whole pyramid levels coarser than the `lod` rule's level (0 = the rule's own level).
    pub lod_bias: u32,
    /// Raw samples below this are no surface (cut out); default: keep everything.
    pub threshold: Option<f64>,
    /// How the heights change with time ([`crate::Scene::at_time`]); default: they do not.
    pub animate: Option<TerrainAnimate>,
}

/// How a terrain's heights change with time.
#[derive(Clone, Debug, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub enum TerrainAnimate {
    /// A sum of travelling sine waves added to a rectangle of samples (or, with `level`, a lake:
    /// the samples under the wavy water surface raised to it).
    Waves {
        /// The water's mean height, world units above the base plane; default: none (the waves
        /// are added to the ground).
        #[serde(default)]
        level: Option<f64>,
        waves: Vec<TerrainWave>,
        /// `(first column, first row, columns, rows)` of the samples that move; default: all.
        #[serde(default)]
        region: Option<[u64; 4]>,
    },
    /// A sequence of height maps of the terrain's size, one a frame: frame `k` shows from
    /// `k / fps` seconds (the first before 0, the last after the end).
    Sequence {
        /// The maps, relative to the scene file, in order.
        paths: Vec<String>,
        /// Frames per second, `> 0`.
        fps: f64,
    },
}

/// One travelling wave of [`TerrainAnimate::Waves`], in world units.
#[derive(Clone, Debug, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct TerrainWave {
    pub amplitude: f64,
    /// `> 0`.
    pub wavelength: f64,
    /// Along the map's columns and rows (normalised; not zero); default `(1, 0)`.
    #[serde(default = "column_axis")]
    pub direction: [f64; 2],
    /// World units per second along `direction`.
    pub speed: f64,
}

fn column_axis() -> [f64; 2] {
    [1.0, 0.0]
}

/// How a terrain's level of detail is chosen for camera rays.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Deserialize)]
pub enum TerrainLod {
    /// Every ray descends to the finest level: the exact surface (with `lod_bias` 0).
    Exact,
    /// A segment stops at the level whose cells cover the camera pixel at its distance and hits
    /// that level's max-column tops (docs/methods.md §4): cost follows the screen, not the map size.
    #[default]
    Pixel,
}

/// How a terrain's surface is interpolated between samples.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Deserialize)]
pub enum TerrainInterpolation {
    #[default]
    Bilinear,
    /// Uniform cubic B-spline over the 4 × 4 neighbouring samples.
    Bicubic,
}

fn unit_spacing() -> [f64; 2] {
    [1.0, 1.0]
}

/// A free-form object: a base quadric deformed by perturbations.
#[derive(Clone, Debug, PartialEq)]
pub struct FreeForm {
    pub base: Quadric,
    pub perturbations: Vec<Perturbation>,
    /// World-space clipping box (never transformed).
    pub bounds: Option<Bounds>,
    /// Overrides the object's material for this leaf.
    pub material: Option<String>,
    /// Applied to the base and the perturbations' quadrics.
    pub transform: Option<Transform>,
}

/// One perturbation term `f · Q³` (where `Q > 0`).
#[derive(Clone, Debug, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Perturbation {
    pub form_factor: f64,
    pub quadric: Quadric,
    /// Applied to this perturbation's quadric alone, before the free form's own transform
    /// (e.g. to tilt an ellipsoidal bump).
    #[serde(default)]
    pub transform: Option<Transform>,
}

/// An axis-aligned box in world space.
#[derive(Clone, Copy, Debug, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Bounds {
    pub min: Vec3,
    pub max: Vec3,
}

/// Which hyperboloid.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Deserialize)]
pub enum Sheets {
    #[default]
    One,
    Two,
}

/// An affine transform: scale, then rotate (about x, then y, then z, degrees, world axes), then
/// translate.
#[derive(Clone, Copy, Debug, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Transform {
    #[serde(default = "zeros")]
    pub translate: Vec3,
    /// Degrees about x, y, z, applied in that order.
    #[serde(default = "zeros")]
    pub rotate: Vec3,
    #[serde(default = "ones")]
    pub scale: Vec3,
}

impl Default for Transform {
    fn default() -> Self {
        Self {
            translate: zeros(),
            rotate: zeros(),
            scale: ones(),
        }
    }
}

/// Keyframed motion: `fps` frames per second, `frames` frames (default: to the last key), and
/// tracks whose keys are at times in seconds. With `loop`, time wraps at the animation's length
/// and every track closes on itself (its last key runs on into its first).
#[derive(Clone, Debug, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Animation {
    #[serde(default = "default_fps")]
    pub fps: f64,
    /// A whole number ≥ 1, read as any number so a bad value gets a clear message.
    #[serde(default)]
    pub frames: Option<f64>,
    #[serde(default, rename = "loop")]
    pub looped: bool,
    /// The camera's path (the scene's `camera` must be a `Pinhole`).
    #[serde(default)]
    pub camera: Option<CameraPath>,
    /// Object tracks by object `name` (free forms and meshes): each key moves the object from
    /// where the file places it.
    #[serde(default)]
    pub objects: BTreeMap<String, ObjectTrack>,
    /// The direction of the scene's first `Sun` light over time (the sky's sun with it).
    #[serde(default)]
    pub sun: Option<SunTrack>,
}

fn default_fps() -> f64 {
    24.0
}

/// How a track passes through its keys.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Deserialize)]
pub enum Interpolation {
    /// Straight from key to key.
    Linear,
    /// A Catmull–Rom spline through the keys (tangents from the neighbouring keys, for keys at
    /// any spacing in time): smooth positions, continuous velocity.
    #[default]
    CatmullRom,
}

/// How a track's time runs between its first and last key.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Deserialize)]
pub enum Ease {
    #[default]
    Linear,
    /// Starts slowly.
    In,
    /// Ends slowly.
    Out,
    /// Starts and ends slowly (smoothstep).
    InOut,
}

/// A camera path: keys of eye, look-at point, up and field of view.
#[derive(Clone, Debug, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CameraPath {
    pub keys: Vec<CameraKey>,
    #[serde(default)]
    pub interpolation: Interpolation,
    #[serde(default)]
    pub ease: Ease,
}

/// One key of a camera path. A key without `look_at` looks along the path (where the eye is
/// heading); then no key has one.
#[derive(Clone, Debug, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CameraKey {
    pub time: f64,
    pub eye: Vec3,
    #[serde(default)]
    pub look_at: Option<Vec3>,
    #[serde(default = "default_up")]
    pub up: Vec3,
    /// Degrees; default: the scene camera's.
    #[serde(default)]
    pub fov_y: Option<f64>,
}

/// An object's track: keys of a translation and a rotation applied after the object's own
/// placement (rotation about the world origin, then translation).
#[derive(Clone, Debug, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ObjectTrack {
    pub keys: Vec<ObjectKey>,
    #[serde(default)]
    pub interpolation: Interpolation,
    #[serde(default)]
    pub ease: Ease,
}

/// One key of an object track; rotations are interpolated along the shortest arc.
#[derive(Clone, Debug, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ObjectKey {
    pub time: f64,
    #[serde(default = "zeros")]
    pub translate: Vec3,
    /// Degrees about x, then y, then z (world axes), as in `Transform`.
    #[serde(default = "zeros")]
    pub rotate: Vec3,
}

/// The sun's direction (toward the sun) over time.
#[derive(Clone, Debug, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SunTrack {
    pub keys: Vec<SunKey>,
    #[serde(default)]
    pub interpolation: Interpolation,
    #[serde(default)]
    pub ease: Ease,
}

/// One key of the sun's track.
#[derive(Clone, Debug, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SunKey {
    pub time: f64,
    pub direction: Vec3,
}

/// The atmosphere: a fog layer, a physically based sky, and how their terms are evaluated.
#[derive(Clone, Debug, Default, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Atmosphere {
    #[serde(default)]
    pub fog: Option<Fog>,
    /// A physically based sky (Rayleigh + Mie + ozone over a spherical Earth): the radiance of
    /// rays that hit nothing (instead of `background`), the air in front of surfaces, and the
    /// sunlight it lets through. Its sun is the scene's first `Sun` light, whose irradiance is
    /// then read as at the top of the atmosphere.
    #[serde(default)]
    pub sky: Option<Sky>,
    /// The method's "per vertex" evaluation: the media's terms on a grid of pixels this many
    /// apart, interpolated where the depths agree (a whole number in `2..=64`, read as any
    /// number so a bad value gets a clear message); default: every pixel.
    #[serde(default)]
    pub grid: Option<f64>,
}

/// Klassen's horizontal fog layer (docs/methods.md §5).
#[derive(Clone, Debug, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Fog {
    /// Height of the layer's bottom; default 0.
    #[serde(default)]
    pub base: f64,
    /// Height of the layer's top, above `base`.
    pub top: f64,
    /// Extinction coefficient `B` in 1/m (at `base` with a falloff), `≥ 0`; default 1e-3.
    #[serde(default = "default_extinction")]
    pub extinction: f64,
    /// Single-scattering albedo in `[0, 1]`; default `(0.95, 0.95, 0.95)`.
    #[serde(default = "default_fog_albedo")]
    pub albedo: Vec3,
    /// Scale height (m) of an exponential falloff of the extinction with height; default none.
    #[serde(default)]
    pub falloff: Option<f64>,
    #[serde(default)]
    pub phase: Phase,
    /// Which formula: `Exact` single scattering (default) or the `Method`'s.
    #[serde(default)]
    pub model: FogModel,
}

/// The physically based sky (`docs/sky.md`).
#[derive(Clone, Debug, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Sky {
    /// The scene `y` of the planet's surface (sea level); default 0.
    #[serde(default)]
    pub ground_elevation: f64,
    /// Aerosols: a factor on the Mie (haze) scattering and absorption, `≥ 0`; default 1 (a
    /// clear day); 3–10 is hazy.
    #[serde(default = "one")]
    pub haze: f64,
    /// Ozone absorption (what keeps the twilight sky blue); default true.
    #[serde(default = "yes")]
    pub ozone: bool,
    /// Draw the sun's disc; default true.
    #[serde(default = "yes")]
    pub sun_disc: bool,
    /// The air between the camera and surfaces (aerial perspective); default true.
    #[serde(default = "yes")]
    pub aerial_perspective: bool,
    /// Steps of the aerial-perspective march, a whole number in `1..=256`; default 16.
    #[serde(default = "default_sky_steps")]
    pub steps: f64,
}

fn default_sky_steps() -> f64 {
    16.0
}

fn default_extinction() -> f64 {
    1e-3
}

fn default_fog_albedo() -> Vec3 {
    [0.95, 0.95, 0.95]
}

/// A phase function; `g` in `(−1, 1)`.
#[derive(Clone, Copy, Debug, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub enum Phase {
    Isotropic,
    /// The normalised Henyey–Greenstein function (the default, `g = 0.76`).
    HenyeyGreenstein {
        g: f64,
    },
    /// The source's printed form `(1 − g)² / (1 + g² − 2g cos θ)^{3/2}` (not normalised).
    Printed {
        g: f64,
    },
}

impl Default for Phase {
    fn default() -> Self {
        Phase::HenyeyGreenstein { g: 0.76 }
    }
}

/// How fog light is evaluated.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Deserialize)]
pub enum FogModel {
    /// Exact single scattering (the sun's path from each point to the layer's top).
    #[default]
    Exact,
    /// The method's formulas (14) and (15): the sun through the whole layer everywhere.
    Method,
}

/// A cloud volume (docs/methods.md §6, `docs/clouds.md`): a density over a world box, marched in equal
/// steps with a sun ray at each sample.
#[derive(Clone, Debug, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Clouds {
    /// The world box the volume fills; a `Layer`'s base and top are its `y` range.
    pub region: Bounds,
    /// Where the density comes from.
    pub density: CloudDensity,
    /// Scattering coefficient (1/m) at density 1, `≥ 0`; default 0.02.
    #[serde(default = "default_cloud_scattering")]
    pub scattering: f64,
    /// Absorption coefficient (1/m) at density 1, `≥ 0`; default 0.0002 (droplets barely
    /// absorb).
    #[serde(default = "default_cloud_absorption")]
    pub absorption: f64,
    #[serde(default)]
    pub phase: CloudPhase,
    /// A factor on the scene's `ambient` radiance for the light scattered in from the sky;
    /// default 1.
    #[serde(default = "one")]
    pub ambient: f64,
    /// The view ray's step length (world units), `> 0`; default: the region's smallest side / 32.
    #[serde(default)]
    pub step: Option<f64>,
    /// Steps of each sun ray, a whole number in `1..=256`; default 6.
    #[serde(default = "default_sun_steps")]
    pub sun_steps: f64,
    /// The march stops once the transmittance is below this, in `[0, 1)`; default 1e-3.
    #[serde(default = "default_min_transmittance")]
    pub min_transmittance: f64,
    /// Offsets each pixel's samples by interleaved gradient noise against banding; default true.
    #[serde(default = "yes")]
    pub jitter: bool,
    /// Empty-space skipping: the cells per side of a max-grid block, a whole number in
    /// `1..=64`; `0` turns skipping off; default 4.
    #[serde(default = "default_skip_block")]
    pub skip_block: f64,
}

fn default_cloud_scattering() -> f64 {
    0.02
}

fn default_cloud_absorption() -> f64 {
    0.0002
}

fn default_sun_steps() -> f64 {
    6.0
}

fn default_min_transmittance() -> f64 {
    1e-3
}

fn default_skip_block() -> f64 {
    4.0
}

/// The density of a cloud volume.
#[derive(Clone, Debug, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub enum CloudDensity {
    /// A cloud layer baked from improved Perlin noise.
    Layer(Box<CloudLayer>),
    /// A density grid from a file (INRIMAGE-4 `.inr`, one float channel), stretched over the
    /// region; its values above `threshold`, less the threshold, times `scale` are the density
    /// (a CT scan's bone above its iso-value, say).
    Volume {
        /// Relative to the scene file.
        path: String,
        /// `≥ 0`; default 1.
        #[serde(default = "one")]
        scale: f64,
        /// Finite; default 0 (every value ≥ 0 kept as it is).
        #[serde(default)]
        threshold: f64,
    },
}

/// A cloud layer: fractal noise cut by coverage and a threshold, shaped by a height profile,
/// bounded by an envelope, baked into a grid over the region.
#[derive(Clone, Debug, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CloudLayer {
    /// Grid samples along x, y, z, each a whole number in `1..=1024`; default (128, 32, 128).
    #[serde(default = "default_cloud_resolution")]
    pub resolution: Vec3,
    /// The size (world units) of the largest noise features, `> 0`; default 2000.
    #[serde(default = "default_feature_size")]
    pub feature_size: f64,
    /// Octaves of the fractal sum, a whole number in `1..=12`; default 5.
    #[serde(default = "default_octaves")]
    pub octaves: f64,
    /// Frequency factor between octaves, `> 0`; default 2.
    #[serde(default = "default_lacunarity")]
    pub lacunarity: f64,
    /// Amplitude factor between octaves, in `[0, 1]`; default 0.5.
    #[serde(default = "default_gain")]
    pub gain: f64,
    /// Which noise (deterministic per seed); default 0.
    #[serde(default)]
    pub seed: u32,
    /// The fraction of the sky covered, in `[0, 1]`; default 0.5.
    #[serde(default = "default_coverage")]
    pub coverage: f64,
    /// Shaped densities below this are cut, in `[0, 1)`; default 0.05.
    #[serde(default = "default_cloud_threshold")]
    pub threshold: f64,
    #[serde(default)]
    pub profile: CloudProfile,
    /// Free forms the cloud is confined to (their union): density is zero outside, fading in
    /// over `envelope_fade` from their surface; default: the whole layer.
    #[serde(default)]
    pub envelope: Option<Shape>,
    /// World units, `≥ 0`; default 100.
    #[serde(default = "default_envelope_fade")]
    pub envelope_fade: f64,
    /// The share of Worley billows (cellular noise, `1 − F1`) mixed into the Perlin sum, in
    /// `[0, 1]`: puffier, cauliflower tops; default 0 (Perlin alone).
    #[serde(default)]
    pub worley: f64,
}

fn default_cloud_resolution() -> Vec3 {
    [128.0, 32.0, 128.0]
}

fn default_feature_size() -> f64 {
    2000.0
}

fn default_octaves() -> f64 {
    5.0
}

fn default_lacunarity() -> f64 {
    2.0
}

fn default_gain() -> f64 {
    0.5
}

fn default_coverage() -> f64 {
    0.5
}

fn default_cloud_threshold() -> f64 {
    0.05
}

fn default_envelope_fade() -> f64 {
    100.0
}

/// How a layer's density is distributed over its height.
#[derive(Clone, Copy, Debug, Default, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub enum CloudProfile {
    /// Flat bases, rounded tops (the default).
    #[default]
    Cumulus,
    /// A flat sheet.
    Stratus,
    /// Flat bases, towering tops.
    Cumulonimbus,
    /// Full density from `base_ramp` to `top_start` (fractions of the layer), smooth ramps to 0
    /// at the base and the top.
    Custom { base_ramp: f64, top_start: f64 },
}

/// The cloud droplets' phase: `(1 − back_weight)·HG(g) + back_weight·HG(back_g)`.
#[derive(Clone, Copy, Debug, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CloudPhase {
    /// The forward lobe's asymmetry, in `(−1, 1)`; default 0.8.
    #[serde(default = "default_cloud_g")]
    pub g: f64,
    /// The second lobe's asymmetry, in `(−1, 1)`; default −0.3.
    #[serde(default = "default_back_g")]
    pub back_g: f64,
    /// The second lobe's weight, in `[0, 1]`; default 0.2 (0: a single lobe).
    #[serde(default = "default_back_weight")]
    pub back_weight: f64,
}

fn default_cloud_g() -> f64 {
    0.8
}

fn default_back_g() -> f64 {
    -0.3
}

fn default_back_weight() -> f64 {
    0.2
}

impl Default for CloudPhase {
    fn default() -> Self {
        Self {
            g: default_cloud_g(),
            back_g: default_back_g(),
            back_weight: default_back_weight(),
        }
    }
}

/// Render settings stored in the scene.
#[derive(Clone, Copy, Debug, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Settings {
    /// Ray-casting tolerance in world units, `> 0`; default `1e-10 ×` the scene's size.
    #[serde(default)]
    pub epsilon: Option<f64>,
    #[serde(default = "yes")]
    pub shadows: bool,
    /// Anti-aliasing samples per pixel, a whole number in `1..=1024` (read as any number so a
    /// bad value gets a clear message); default 1 (the pixel centre).
    #[serde(default)]
    pub samples: Option<f64>,
    /// Whitted recursion: the most reflections and refractions after the camera ray, a whole
    /// number in `0..=64`; default 5.
    #[serde(default)]
    pub max_depth: Option<f64>,
    /// Whitted recursion: a secondary ray whose weight (the product of `kr`/`kt` on its way,
    /// largest channel) is below this is not traced, in `[0, 1)`; default `1e-3`.
    #[serde(default)]
    pub min_contribution: Option<f64>,
    /// Whitted recursion: the most secondary rays one camera ray (sample) may trace, its
    /// allowance shared down the tree (`Settings::max_secondary_rays`), a whole number in
    /// `0..=65536`; default 256.
    #[serde(default)]
    pub max_secondary_rays: Option<f64>,
}

impl Default for Settings {
    fn default() -> Self {
        Self {
            epsilon: None,
            shadows: true,
            samples: None,
            max_depth: None,
            min_contribution: None,
            max_secondary_rays: None,
        }
    }
}

fn yes() -> bool {
    true
}

/// Declares [`Quadric`] and the private shape representation that also accepts every quadric
/// variant as a shape, from one list of variants.
macro_rules! quadrics {
    ($( $(#[$vm:meta])* $name:ident { $( $(#[$fm:meta])* $field:ident : $ty:ty ),* $(,)? } ),* $(,)?) => {
        /// A quadric. Positions default to the origin and axes to `(0, 1, 0)`; angles in degrees.
        #[derive(Clone, Debug, PartialEq, Deserialize)]
        #[serde(deny_unknown_fields)]
        pub enum Quadric {
            $( $(#[$vm])* $name { $( $(#[$fm])* $field: $ty ),* } ),*
        }

        /// What a `Shape` looks like in a file: the CSG variants plus every quadric variant.
        #[derive(Deserialize)]
        #[serde(deny_unknown_fields, rename = "Shape")]
        enum ShapeRepr {
            FreeForm {
                base: Quadric,
                #[serde(default)]
                perturbations: Vec<Perturbation>,
                #[serde(default)]
                bounds: Option<Bounds>,
                #[serde(default)]
                material: Option<String>,
                #[serde(default)]
                transform: Option<Transform>,
            },
            Union(Vec<Shape>),
            Intersection(Vec<Shape>),
            Difference(Box<Shape>, Box<Shape>),
            Transformed {
                shape: Box<Shape>,
                #[serde(default)]
                transform: Transform,
            },
            Terrain {
                path: String,
                #[serde(default = "unit_spacing")]
                spacing: [f64; 2],
                #[serde(default = "one")]
                vertical_scale: f64,
                #[serde(default = "zeros")]
                origin: Vec3,
                #[serde(default = "zeros")]
                rotate: Vec3,
                #[serde(default)]
                interpolation: TerrainInterpolation,
                #[serde(default)]
                lod: TerrainLod,
                #[serde(default)]
                lod_bias: u32,
                #[serde(default)]
                threshold: Option<f64>,
                #[serde(default)]
                animate: Option<TerrainAnimate>,
            },
            Mesh {
                path: String,
                #[serde(default)]
                transform: Transform,
                #[serde(default = "yes")]
                smooth: bool,
            },
            $( $name { $( $(#[$fm])* $field: $ty ),* } ),*
        }

        impl From<ShapeRepr> for Shape {
            fn from(r: ShapeRepr) -> Self {
                match r {
                    ShapeRepr::FreeForm { base, perturbations, bounds, material, transform } => {
                        Shape::FreeForm(FreeForm { base, perturbations, bounds, material, transform })
                    }
                    ShapeRepr::Union(v) => Shape::Union(v),
                    ShapeRepr::Intersection(v) => Shape::Intersection(v),
                    ShapeRepr::Difference(a, b) => Shape::Difference(a, b),
                    ShapeRepr::Transformed { shape, transform } => Shape::Transformed { shape, transform },
                    ShapeRepr::Terrain { path, spacing, vertical_scale, origin, rotate, interpolation, lod, lod_bias, threshold, animate } => {
                        Shape::Terrain(Terrain { path, spacing, vertical_scale, origin, rotate, interpolation, lod, lod_bias, threshold, animate })
                    }
                    ShapeRepr::Mesh { path, transform, smooth } => Shape::Mesh(Mesh { path, transform, smooth }),
                    $( ShapeRepr::$name { $( $field ),* } => Shape::Quadric(Quadric::$name { $( $field ),* }) ),*
                }
            }
        }
    };
}

quadrics! {
    /// Solid ball.
    Sphere {
        #[serde(default = "zeros")]
        center: Vec3,
        radius: f64,
    },
    /// Solid axis-aligned ellipsoid with semi-axes `radii`.
    Ellipsoid {
        #[serde(default = "zeros")]
        center: Vec3,
        radii: Vec3,
    },
    /// The half-space below the plane through `point`; `normal` points out of the solid.
    HalfSpace {
        #[serde(default = "zeros")]
        point: Vec3,
        #[serde(default = "y_axis")]
        normal: Vec3,
    },
    /// Infinite solid cylinder around the line through `point` along `axis`.
    Cylinder {
        #[serde(default = "zeros")]
        point: Vec3,
        #[serde(default = "y_axis")]
        axis: Vec3,
        radius: f64,
    },
    /// Infinite solid double cone; `half_angle` in degrees, in `(0, 90)`.
    Cone {
        #[serde(default = "zeros")]
        apex: Vec3,
        #[serde(default = "y_axis")]
        axis: Vec3,
        half_angle: f64,
    },
    /// Solid paraboloid opening along `axis` from `vertex`.
    Paraboloid {
        #[serde(default = "zeros")]
        vertex: Vec3,
        #[serde(default = "y_axis")]
        axis: Vec3,
        focal_length: f64,
    },
    /// Solid hyperboloid of one or two sheets.
    Hyperboloid {
        #[serde(default = "zeros")]
        center: Vec3,
        #[serde(default = "y_axis")]
        axis: Vec3,
        radius: f64,
        height: f64,
        #[serde(default)]
        sheets: Sheets,
    },
    /// Ten coefficients `(A11, A22, A33, A12, A13, A23, A14, A24, A34, A44)` about `origin`.
    General {
        #[serde(default = "zeros")]
        origin: Vec3,
        coefficients: [f64; 10],
    },
}
