//! Validation and resolution: a parsed [`description::Scene`] becomes a checked [`Scene`] —
//! degrees to radians, the projector, solids with per-leaf materials, the feature set. Every
//! failure names the path of the offending field.

use crate::checks::{
    Invalid, Result, angle, direction, finite, invalid, non_negative, point, positive, show,
};
use crate::description::{self, Vec3};
use crate::kinds::{self, ObjectContext};
use crate::path::FieldPath;
use crate::{FeatureSet, Light, Material, PrimitiveKind, Scene, Settings};
use fray_core::{Parallel, Pinhole, PixelSamples, Projector, ProjectorError, Rgb, SphereSurface};
use std::collections::BTreeMap;
use std::path::Path;

/// The largest accepted image side, in pixels.
pub const MAX_IMAGE_SIDE: u32 = 16384;

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

    let mut scene = Scene::empty(
        width,
        height,
        camera,
        background,
        ambient,
        lights,
        materials,
        budget.clone(),
    );
    scene.features = features;
    let mut cx = ObjectContext {
        materials: &material_index,
        base,
        budget,
        assets,
    };
    let objects_path = root.field("objects");
    for (i, o) in d.objects.iter().enumerate() {
        let path = objects_path.index(i);
        let name = o.name.clone().unwrap_or_else(|| format!("object{i}"));
        kinds::of(o.shape.kind()).resolve(&mut cx, &mut scene, &path, o, name)?;
    }
    for kind in PrimitiveKind::ALL {
        if scene.count(kind) > 0 {
            kinds::of(kind).mark(&mut scene.features);
        }
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
    let mut features = scene.features;
    for m in scene.used_materials() {
        if let Some(m) = scene.materials.get(m as usize) {
            features.reflection |= m.reflects();
            features.transmission |= m.transmits();
            features.textures |= m.texture.is_some() || m.ramp.is_some();
        }
    }
    features.shadows = settings.shadows && !scene.lights.is_empty();
    let atmosphere = crate::atmosphere::resolve(
        &root.field("atmosphere"),
        &d.atmosphere,
        &scene.lights,
        budget,
    )?;
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

    scene.atmosphere = atmosphere;
    scene.clouds = clouds;
    scene.settings = settings;
    scene.features = features;
    let cameras_path = root.field("cameras");
    for (name, c) in &d.cameras {
        scene.cameras.push(crate::NamedCamera {
            name: name.clone(),
            camera: self::camera(&cameras_path.field(name), c)?,
        });
    }
    if let Some(a) = &d.animation {
        let animation = crate::animation::resolve(&root.field("animation"), a, &scene)?;
        scene.animation = Some(std::sync::Arc::new(animation));
    }
    Ok(scene)
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
