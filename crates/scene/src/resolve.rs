//! Validation and resolution: a parsed [`description::Scene`] becomes a checked [`Scene`] —
//! degrees to radians, the projector, solids with per-leaf materials, the feature set. Every
//! failure names the path of the offending field.

use crate::description::{self, Vec3};
use crate::path::FieldPath;
use crate::{FeatureSet, Light, Material, MeshObject, Object, Scene, Settings, TerrainObject};
use fray_core::{
    Aabb, Parallel, Pinhole, PixelSamples, Projector, ProjectorError, Rgb, SphereSurface,
};
use fray_geometry::{FreeForm, GeometryError, Perturbation, Quadric, Shape, Sheets, Solid};
use glam::{DAffine3, DMat3, DVec3};
use std::collections::BTreeMap;
use std::path::Path;

/// The largest accepted image side, in pixels.
pub const MAX_IMAGE_SIDE: u32 = 16384;

/// A resolution failure: the offending field and what is wrong with it.
#[derive(Clone, Debug, PartialEq)]
pub(crate) struct Invalid {
    pub(crate) path: FieldPath,
    pub(crate) message: String,
}

pub(crate) type Result<T> = std::result::Result<T, Invalid>;

pub(crate) fn invalid<T>(path: &FieldPath, message: impl Into<String>) -> Result<T> {
    Err(Invalid {
        path: path.clone(),
        message: message.into(),
    })
}

/// Checks and resolves a whole description.
/// The deepest Whitted recursion a scene may ask for.
pub const MAX_DEPTH: u32 = 64;

/// The largest `settings.max_secondary_rays` a scene may ask for: 2¹⁶, a full binary tree of
/// reflections and refractions 15 levels deep — one camera ray that may cost as much as a
/// 256 × 256 frame of camera rays; past it a pixel's sample is no longer worth its time.
pub const MAX_SECONDARY_RAYS: u32 = 1 << 16;

/// The largest index of refraction accepted (diamond is 2.42; beyond 10 is a typo).
pub const MAX_IOR: f64 = 10.0;

pub(crate) fn resolve(
    d: &description::Scene,
    base: &Path,
    options: &crate::BuildOptions,
    assets: &mut crate::assets::LoadedAssets,
) -> Result<Scene> {
    let budget = &options.budget;
    let root = FieldPath::root();
    let mut features = FeatureSet::default();

    let image = root.field("image");
    let width = image_side(&image.field("width"), d.image.width)?;
    let height = image_side(&image.field("height"), d.image.height)?;
    let camera = camera(&root.field("camera"), &d.camera)?;
    let background = radiance(&root.field("background"), d.background)?;
    let ambient = radiance(&root.field("ambient"), d.ambient)?;

    let lights_path = root.field("lights");
    let mut lights = Vec::with_capacity(d.lights.len());
    for (i, l) in d.lights.iter().enumerate() {
        let light = light(&lights_path.index(i), l)?;
        match light {
            Light::Sun { .. } => features.sun = true,
            Light::Point { .. } => features.point_lights = true,
        }
        lights.push(light);
    }

    let materials_path = root.field("materials");
    let mut materials = vec![Material::default()];
    let mut material_index = BTreeMap::new();
    for (name, m) in &d.materials {
        let path = materials_path.field(name);
        if name == "default" {
            return invalid(
                &path,
                "the name `default` is reserved for the built-in default material",
            );
        }
        material_index.insert(name.as_str(), materials.len() as u32);
        let mut m = material(&path, name, m)?;
        if let Some(t) = &d.materials[name].texture {
            m.texture = Some(crate::texture::slot(
                &path.field("texture"),
                t,
                base,
                budget,
                assets,
            )?);
        }
        if let Some(r) = &d.materials[name].ramp {
            m.ramp = Some(crate::texture::ramp(&path.field("ramp"), r)?);
        }
        materials.push(m);
    }

    let objects_path = root.field("objects");
    let mut objects = Vec::with_capacity(d.objects.len());
    let mut terrains = Vec::new();
    let mut meshes = Vec::new();
    for (i, o) in d.objects.iter().enumerate() {
        let path = objects_path.index(i);
        let name = || o.name.clone().unwrap_or_else(|| format!("object{i}"));
        if let description::Shape::Terrain(t) = &o.shape {
            let material = match &o.material {
                Some(m) => ShapeContext {
                    materials: &material_index,
                    leaf_materials: Vec::new(),
                    features: &mut features,
                }
                .material(&path.field("material"), m)?,
                None => 0,
            };
            let file = base.join(&t.path);
            let key = (
                std::fs::canonicalize(&file).unwrap_or(file),
                format!("{t:?}"),
            );
            let terrain = assets.terrains.get_or_build(
                key,
                budget,
                || format!("the terrain {}", t.path),
                || crate::terrain::terrain(&path.field("shape"), t, base, budget),
                |e| Invalid {
                    path: path.field("shape").field("path"),
                    message: e.to_string(),
                },
            )?;
            features.terrain = true;
            terrains.push(TerrainObject {
                name: name(),
                terrain,
                material,
                lod: t.lod,
            });
            continue;
        }
        if let description::Shape::Mesh(m) = &o.shape {
            let material = match &o.material {
                Some(name) => ShapeContext {
                    materials: &material_index,
                    leaf_materials: Vec::new(),
                    features: &mut features,
                }
                .material(&path.field("material"), name)?,
                None => 0,
            };
            let instance = crate::mesh::instance(&path.field("shape"), m, base, budget, assets)?;
            features.meshes = true;
            meshes.push(MeshObject {
                name: name(),
                instance,
                material,
                smooth: m.smooth,
            });
            continue;
        }
        let mut ctx = ShapeContext {
            materials: &material_index,
            leaf_materials: Vec::new(),
            features: &mut features,
        };
        let object_material = match &o.material {
            Some(name) => ctx.material(&path.field("material"), name)?,
            None => 0,
        };
        let shape = ctx.shape(
            &path.field("shape"),
            &o.shape,
            DAffine3::IDENTITY,
            object_material,
        )?;
        let leaf_materials = ctx.leaf_materials;
        let solid = Solid::new(shape).or_else(|e| invalid(&path.field("shape"), e.to_string()))?;
        features.free_forms = true;
        objects.push(Object {
            name: name(),
            solid,
            leaf_materials,
        });
    }

    let settings_path = root.field("settings");
    let epsilon = match d.settings.epsilon {
        Some(e) => Some(positive(&settings_path.field("epsilon"), e)?),
        None => None,
    };
    let samples = match d.settings.samples {
        None => PixelSamples::ONE,
        Some(n) => {
            let path = settings_path.field("samples");
            let max = fray_core::samples::MAX_SAMPLES;
            match PixelSamples::new(n as u32) {
                Ok(samples) if n.fract() == 0.0 && n >= 1.0 && n <= f64::from(max) => samples,
                _ => {
                    return invalid(
                        &path,
                        format!("must be a whole number in 1..={max}, got {n}"),
                    );
                }
            }
        }
    };
    let max_depth = match d.settings.max_depth {
        None => Settings::default().max_depth,
        Some(n) if n.fract() == 0.0 && (0.0..=f64::from(MAX_DEPTH)).contains(&n) => n as u32,
        Some(n) => {
            return invalid(
                &settings_path.field("max_depth"),
                format!("must be a whole number in 0..={MAX_DEPTH}, got {n}"),
            );
        }
    };
    let min_contribution = match d.settings.min_contribution {
        None => Settings::default().min_contribution,
        Some(c) if (0.0..1.0).contains(&c) => c,
        Some(c) => {
            return invalid(
                &settings_path.field("min_contribution"),
                format!("must be in [0, 1), got {c}"),
            );
        }
    };
    let max_secondary_rays = match d.settings.max_secondary_rays {
        None => Settings::default().max_secondary_rays,
        Some(n) if n.fract() == 0.0 && (0.0..=f64::from(MAX_SECONDARY_RAYS)).contains(&n) => {
            n as u32
        }
        Some(n) => {
            return invalid(
                &settings_path.field("max_secondary_rays"),
                format!("must be a whole number in 0..={MAX_SECONDARY_RAYS}, got {n}"),
            );
        }
    };
    let settings = Settings {
        epsilon,
        shadows: d.settings.shadows,
        samples,
        max_depth,
        min_contribution,
        max_secondary_rays,
    };
    // Secondary rays only where a primitive's material sends them (an unused material costs
    // nothing).
    let used = objects
        .iter()
        .flat_map(|o: &Object| o.leaf_materials.iter().copied())
        .chain(terrains.iter().map(|t: &TerrainObject| t.material))
        .chain(meshes.iter().map(|m: &MeshObject| m.material));
    for m in used {
        if let Some(m) = materials.get(m as usize) {
            features.reflection |= m.reflects();
            features.transmission |= m.transmits();
            features.textures |= m.texture.is_some() || m.ramp.is_some();
        }
    }
    features.shadows = settings.shadows && !lights.is_empty();
    let atmosphere =
        crate::atmosphere::resolve(&root.field("atmosphere"), &d.atmosphere, &lights, budget)?;
    features.fog = atmosphere.fog.is_some();
    features.sky = atmosphere.sky.is_some();
    let clouds = match &d.clouds {
        Some(c) => Some(std::sync::Arc::new(crate::clouds::resolve(
            &root.field("clouds"),
            c,
            base,
            options,
        )?)),
        None => None,
    };
    features.clouds = clouds.is_some();

    Ok(Scene {
        width,
        height,
        camera,
        background,
        ambient,
        lights,
        materials,
        objects,
        terrains,
        meshes,
        atmosphere,
        clouds,
        settings,
        features,
        budget: budget.clone(),
    })
}

fn image_side(path: &FieldPath, v: u32) -> Result<u32> {
    if (1..=MAX_IMAGE_SIDE).contains(&v) {
        Ok(v)
    } else {
        invalid(
            path,
            format!("must be in 1..={MAX_IMAGE_SIDE} pixels, got {v}"),
        )
    }
}

fn show(v: Vec3) -> String {
    format!("({}, {}, {})", v[0], v[1], v[2])
}

pub(crate) fn finite(path: &FieldPath, x: f64) -> Result<f64> {
    if x.is_finite() {
        Ok(x)
    } else {
        invalid(path, format!("must be a finite number, got {x}"))
    }
}

pub(crate) fn point(path: &FieldPath, v: Vec3) -> Result<DVec3> {
    if v.iter().all(|c| c.is_finite()) {
        Ok(DVec3::from_array(v))
    } else {
        invalid(path, format!("must be finite, got {}", show(v)))
    }
}

fn direction(path: &FieldPath, v: Vec3) -> Result<DVec3> {
    let d = point(path, v)?;
    let len = d.length();
    if len > 0.0 && len.is_finite() {
        Ok(d)
    } else {
        invalid(path, format!("must be a non-zero vector, got {}", show(v)))
    }
}

pub(crate) fn positive(path: &FieldPath, x: f64) -> Result<f64> {
    if !x.is_finite() {
        invalid(path, format!("must be a finite number > 0, got {x}"))
    } else if x > 0.0 {
        Ok(x)
    } else {
        invalid(path, format!("must be > 0, got {x}"))
    }
}

pub(crate) fn non_negative(path: &FieldPath, x: f64) -> Result<f64> {
    if x >= 0.0 && x.is_finite() {
        Ok(x)
    } else {
        invalid(path, format!("must be ≥ 0, got {x}"))
    }
}

/// An angle in degrees, checked against `(lo, hi)` (or `(lo, hi]` when `hi_closed`), in radians.
fn angle(path: &FieldPath, degrees: f64, lo: f64, hi: f64, hi_closed: bool) -> Result<f64> {
    let ok = degrees > lo && (degrees < hi || (hi_closed && degrees == hi));
    if ok {
        Ok(degrees.to_radians())
    } else {
        let close = if hi_closed { ']' } else { ')' };
        invalid(
            path,
            format!("must be in ({lo}, {hi}{close} degrees, got {degrees}"),
        )
    }
}

/// A radiance or radiometric quantity: finite and non-negative on every channel.
fn radiance(path: &FieldPath, v: Vec3) -> Result<Rgb> {
    if v.iter().all(|c| c.is_finite() && *c >= 0.0) {
        Ok(Rgb::new(v[0] as f32, v[1] as f32, v[2] as f32))
    } else {
        invalid(
            path,
            format!("must be finite and ≥ 0 on every channel, got {}", show(v)),
        )
    }
}

/// A reflectance: in `[0, 1]` on every channel.
fn reflectance(path: &FieldPath, v: Vec3) -> Result<Rgb> {
    if v.iter().all(|c| (0.0..=1.0).contains(c)) {
        Ok(Rgb::new(v[0] as f32, v[1] as f32, v[2] as f32))
    } else {
        invalid(
            path,
            format!("must be in [0, 1] on every channel, got {}", show(v)),
        )
    }
}

fn camera(path: &FieldPath, c: &description::Camera) -> Result<Projector> {
    let projector = |e: ProjectorError| -> Invalid {
        let field = match &e {
            ProjectorError::NotFinite { field } | ProjectorError::OutOfRange { field, .. } => field,
            ProjectorError::LookAtIsEye => "look_at",
            ProjectorError::UpParallelToView => "up",
            ProjectorError::EyeOutsideSurface { .. } => "eye",
        };
        Invalid {
            path: path.field(field),
            message: e.to_string(),
        }
    };
    match *c {
        description::Camera::Pinhole {
            eye,
            look_at,
            up,
            fov_y,
            near,
        } => {
            let eye = point(&path.field("eye"), eye)?;
            let look_at = point(&path.field("look_at"), look_at)?;
            let up = direction(&path.field("up"), up)?;
            let fov_y = angle(&path.field("fov_y"), fov_y, 0.0, 180.0, false)?;
            let near = positive(&path.field("near"), near)?;
            Pinhole::new(eye, look_at, up, fov_y, near)
                .map(Projector::Pinhole)
                .map_err(projector)
        }
        description::Camera::Parallel {
            eye,
            look_at,
            up,
            height,
            near,
        } => {
            let eye = point(&path.field("eye"), eye)?;
            let look_at = point(&path.field("look_at"), look_at)?;
            let up = direction(&path.field("up"), up)?;
            let height = positive(&path.field("height"), height)?;
            let near = non_negative(&path.field("near"), near)?;
            Parallel::new(eye, look_at, up, height, near)
                .map(Projector::Parallel)
                .map_err(projector)
        }
        description::Camera::Sphere {
            eye,
            centre,
            look_at,
            up,
            fov_x,
            fov_y,
            radius,
            ripple_amplitude,
            ripple_frequency,
        } => {
            let eye = point(&path.field("eye"), eye)?;
            let centre = match centre {
                Some(c) => point(&path.field("centre"), c)?,
                None => eye,
            };
            let look_at = point(&path.field("look_at"), look_at)?;
            let up = direction(&path.field("up"), up)?;
            let fov_x = angle(&path.field("fov_x"), fov_x, 0.0, 360.0, true)?;
            let fov_y = angle(&path.field("fov_y"), fov_y, 0.0, 180.0, true)?;
            let radius = positive(&path.field("radius"), radius)?;
            let amplitude = finite(&path.field("ripple_amplitude"), ripple_amplitude)?;
            let frequency = finite(&path.field("ripple_frequency"), ripple_frequency)?;
            SphereSurface::new(
                eye, centre, look_at, up, fov_x, fov_y, radius, amplitude, frequency,
            )
            .map(Projector::Sphere)
            .map_err(projector)
        }
    }
}

fn light(path: &FieldPath, l: &description::Light) -> Result<Light> {
    Ok(match *l {
        description::Light::Sun {
            direction: d,
            irradiance,
        } => Light::Sun {
            direction: direction(&path.field("direction"), d)?.normalize(),
            irradiance: radiance(&path.field("irradiance"), irradiance)?,
        },
        description::Light::Point {
            position,
            intensity,
        } => Light::Point {
            position: point(&path.field("position"), position)?,
            intensity: radiance(&path.field("intensity"), intensity)?,
        },
    })
}

fn material(path: &FieldPath, name: &str, m: &description::Material) -> Result<Material> {
    let default = Material::default();
    let diffuse = match m.diffuse {
        Some(v) => reflectance(&path.field("diffuse"), v)?,
        None => default.diffuse,
    };
    let specular = match m.specular {
        Some(v) => reflectance(&path.field("specular"), v)?,
        None => default.specular,
    };
    let shininess = match m.shininess {
        Some(s) => non_negative(&path.field("shininess"), s)?,
        None => default.shininess,
    };
    let ambient = match m.ambient {
        Some(v) => reflectance(&path.field("ambient"), v)?,
        None => diffuse,
    };
    let reflect = match m.reflect {
        Some(v) => reflectance(&path.field("reflect"), v)?,
        None => default.reflect,
    };
    let transmit = match m.transmit {
        Some(v) => reflectance(&path.field("transmit"), v)?,
        None => default.transmit,
    };
    let ior = match m.ior {
        Some(n) if n.is_finite() && (1.0..=MAX_IOR).contains(&n) => n,
        Some(n) => {
            return invalid(
                &path.field("ior"),
                format!("must be in [1, {MAX_IOR}], got {n}"),
            );
        }
        None => default.ior,
    };
    Ok(Material {
        name: name.to_owned(),
        ambient,
        diffuse,
        specular,
        shininess,
        reflect,
        transmit,
        ior,
        fresnel: m.fresnel,
        texture: None,
        ramp: None,
    })
}

/// An affine map from its description: scale, then rotate about x, y, z (degrees), then translate.
pub(crate) fn transform(path: &FieldPath, t: &description::Transform) -> Result<DAffine3> {
    let translate = point(&path.field("translate"), t.translate)?;
    let rotate = point(&path.field("rotate"), t.rotate)?;
    let scale = point(&path.field("scale"), t.scale)?;
    if scale.abs().min_element() == 0.0 {
        return invalid(
            &path.field("scale"),
            format!("must be non-zero on every axis, got {}", show(t.scale)),
        );
    }
    let r = DMat3::from_rotation_z(rotate.z.to_radians())
        * DMat3::from_rotation_y(rotate.y.to_radians())
        * DMat3::from_rotation_x(rotate.x.to_radians());
    Ok(DAffine3::from_mat3_translation(
        r * DMat3::from_diagonal(scale),
        translate,
    ))
}

/// Per-object state while a shape tree is resolved.
struct ShapeContext<'a> {
    materials: &'a BTreeMap<&'a str, u32>,
    /// One material per leaf, in leaf order (depth first, left to right).
    leaf_materials: Vec<u32>,
    features: &'a mut FeatureSet,
}

impl ShapeContext<'_> {
    fn material(&self, path: &FieldPath, name: &str) -> Result<u32> {
        if name == "default" {
            return Ok(0);
        }
        match self.materials.get(name) {
            Some(&i) => Ok(i),
            None => {
                let known: Vec<String> = self.materials.keys().map(|k| format!("`{k}`")).collect();
                let known = if known.is_empty() {
                    "none are defined".to_owned()
                } else {
                    known.join(", ")
                };
                invalid(
                    path,
                    format!("unknown material `{name}` (defined: {known})"),
                )
            }
        }
    }

    /// Resolves `s`, with `outer` the transform of the enclosing `Transformed` shapes and
    /// `material` the material its leaves inherit.
    fn shape(
        &mut self,
        path: &FieldPath,
        s: &description::Shape,
        outer: DAffine3,
        material: u32,
    ) -> Result<Shape> {
        use description::Shape as S;
        match s {
            S::Quadric(q) => self.free_form(path, path, q, &[], None, outer, material),
            S::FreeForm(f) => {
                let material = match &f.material {
                    Some(name) => self.material(&path.field("material"), name)?,
                    None => material,
                };
                let t = match &f.transform {
                    Some(t) => outer * transform(&path.field("transform"), t)?,
                    None => outer,
                };
                let bounds = match &f.bounds {
                    Some(b) => Some(bounds(&path.field("bounds"), b)?),
                    None => None,
                };
                self.free_form(
                    path,
                    &path.field("base"),
                    &f.base,
                    &f.perturbations,
                    bounds,
                    t,
                    material,
                )
            }
            S::Union(children) | S::Intersection(children) => {
                let op = if matches!(s, S::Union(_)) {
                    "Union"
                } else {
                    "Intersection"
                };
                if children.len() < 2 {
                    return invalid(
                        path,
                        format!("a {op} needs at least 2 shapes, got {}", children.len()),
                    );
                }
                self.features.csg = true;
                let mut out = Vec::with_capacity(children.len());
                for (i, c) in children.iter().enumerate() {
                    out.push(self.shape(&path.index(i), c, outer, material)?);
                }
                Ok(if op == "Union" {
                    Shape::Union(out)
                } else {
                    Shape::Intersection(out)
                })
            }
            S::Difference(a, b) => {
                self.features.csg = true;
                let a = self.shape(&path.index(0), a, outer, material)?;
                let b = self.shape(&path.index(1), b, outer, material)?;
                Ok(Shape::Difference(Box::new(a), Box::new(b)))
            }
            S::Transformed {
                shape,
                transform: t,
            } => {
                let inner = outer * transform(&path.field("transform"), t)?;
                self.shape(&path.field("shape"), shape, inner, material)
            }
            S::Terrain(_) => invalid(
                path,
                "a Terrain can only be an object's whole shape, not part of a CSG tree or a \
                 Transformed shape (place it with its `origin` and `rotate`)",
            ),
            S::Mesh(_) => invalid(
                path,
                "a Mesh can only be an object's whole shape, not part of a CSG tree or a \
                 Transformed shape (place it with its `transform`)",
            ),
        }
    }

    #[allow(clippy::too_many_arguments)]
    fn free_form(
        &mut self,
        path: &FieldPath,
        base_path: &FieldPath,
        base: &description::Quadric,
        perturbations: &[description::Perturbation],
        bounds: Option<Aabb>,
        t: DAffine3,
        material: u32,
    ) -> Result<Shape> {
        let base = placed(path, quadric(base_path, base)?, t)?;
        let perts_path = path.field("perturbations");
        let mut perts = Vec::with_capacity(perturbations.len());
        for (i, p) in perturbations.iter().enumerate() {
            let pp = perts_path.index(i);
            let form_factor = finite(&pp.field("form_factor"), p.form_factor)?;
            if form_factor != 0.0 {
                self.features.perturbations = true;
            }
            let own = match &p.transform {
                Some(own) => transform(&pp.field("transform"), own)?,
                None => DAffine3::IDENTITY,
            };
            let q = placed(&pp, quadric(&pp.field("quadric"), &p.quadric)?, t * own)?;
            perts.push(Perturbation::new(form_factor, q));
        }
        let f = FreeForm::new(base, perts, bounds).map_err(|e| {
            let at = match e {
                GeometryError::InvalidBounds => path.field("bounds"),
                _ => path.clone(),
            };
            Invalid {
                path: at,
                message: e.to_string(),
            }
        })?;
        self.leaf_materials.push(material);
        Ok(Shape::FreeForm(f))
    }
}

/// A shape that is not drawn but bounds something (a cloud's envelope): its CSG solid, with no
/// materials and no effect on the scene's features.
pub(crate) fn bounding_solid(path: &FieldPath, shape: &description::Shape) -> Result<Solid> {
    let materials = BTreeMap::new();
    let mut features = FeatureSet::default();
    let mut ctx = ShapeContext {
        materials: &materials,
        leaf_materials: Vec::new(),
        features: &mut features,
    };
    let shape = ctx.shape(path, shape, DAffine3::IDENTITY, 0)?;
    Solid::new(shape).or_else(|e| invalid(path, e.to_string()))
}

/// `q` moved by `t` (skipped for the identity, so plain quadrics keep their exact coefficients).
fn placed(path: &FieldPath, q: Quadric, t: DAffine3) -> Result<Quadric> {
    if t == DAffine3::IDENTITY {
        return Ok(q);
    }
    match q.transformed(&t) {
        Some(q) if q.is_finite() => Ok(q),
        _ => invalid(
            path,
            "the accumulated transform is singular or too large for this shape",
        ),
    }
}

pub(crate) fn bounds(path: &FieldPath, b: &description::Bounds) -> Result<Aabb> {
    let min = point(&path.field("min"), b.min)?;
    let max = point(&path.field("max"), b.max)?;
    if min.cmple(max).all() {
        Ok(Aabb::new(min, max))
    } else {
        invalid(
            path,
            format!(
                "`min` must be ≤ `max` on every axis, got min {} and max {}",
                show(b.min),
                show(b.max)
            ),
        )
    }
}

fn quadric(path: &FieldPath, q: &description::Quadric) -> Result<Quadric> {
    use description::Quadric as Q;
    Ok(match *q {
        Q::Sphere { center, radius } => Quadric::sphere(
            point(&path.field("center"), center)?,
            positive(&path.field("radius"), radius)?,
        ),
        Q::Ellipsoid { center, radii } => {
            let center = point(&path.field("center"), center)?;
            if !radii.iter().all(|r| r.is_finite() && *r > 0.0) {
                return invalid(
                    &path.field("radii"),
                    format!("must be > 0 on every axis, got {}", show(radii)),
                );
            }
            Quadric::ellipsoid(center, DVec3::from_array(radii))
        }
        Q::HalfSpace { point: p, normal } => Quadric::half_space(
            point(&path.field("point"), p)?,
            direction(&path.field("normal"), normal)?,
        ),
        Q::Cylinder {
            point: p,
            axis,
            radius,
        } => Quadric::cylinder(
            point(&path.field("point"), p)?,
            direction(&path.field("axis"), axis)?,
            positive(&path.field("radius"), radius)?,
        ),
        Q::Cone {
            apex,
            axis,
            half_angle,
        } => Quadric::cone(
            point(&path.field("apex"), apex)?,
            direction(&path.field("axis"), axis)?,
            angle(&path.field("half_angle"), half_angle, 0.0, 90.0, false)?,
        ),
        Q::Paraboloid {
            vertex,
            axis,
            focal_length,
        } => Quadric::paraboloid(
            point(&path.field("vertex"), vertex)?,
            direction(&path.field("axis"), axis)?,
            positive(&path.field("focal_length"), focal_length)?,
        ),
        Q::Hyperboloid {
            center,
            axis,
            radius,
            height,
            sheets,
        } => Quadric::hyperboloid(
            point(&path.field("center"), center)?,
            direction(&path.field("axis"), axis)?,
            positive(&path.field("radius"), radius)?,
            positive(&path.field("height"), height)?,
            match sheets {
                description::Sheets::One => Sheets::One,
                description::Sheets::Two => Sheets::Two,
            },
        ),
        Q::General {
            origin,
            coefficients,
        } => {
            let origin = point(&path.field("origin"), origin)?;
            let cpath = path.field("coefficients");
            if let Some(i) = coefficients.iter().position(|c| !c.is_finite()) {
                return invalid(
                    &cpath.index(i),
                    format!("must be a finite number, got {}", coefficients[i]),
                );
            }
            if coefficients.iter().all(|c| *c == 0.0) {
                return invalid(&cpath, "must not all be zero");
            }
            Quadric::new(origin, coefficients)
        }
    })
}
