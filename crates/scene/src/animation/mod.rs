//! Motion over time: a scene's camera path, object tracks and sun track, and the still a scene is
//! at a time ([`Scene::at_time`]).

mod curve;
mod heights;
mod resolve;

pub use curve::Curve;
pub use heights::{Heights, MAX_WAVES, Sequence};
pub use resolve::MAX_FRAMES;
pub(crate) use resolve::resolve;

use crate::{Light, Scene, SceneError};
use fray_core::{Pinhole, Projector};
use glam::{DAffine3, DMat3, DQuat, DVec3};

/// A scene's animation, checked: every frame's camera is a valid projector, every track names an
/// object that can move that way.
#[derive(Clone, Debug, PartialEq)]
pub struct Animation {
    /// Frames per second.
    pub fps: f64,
    /// Frames in the animation: frame `n` is the scene at time `n / fps`.
    pub frames: u32,
    /// Time wraps at `frames / fps` and the tracks close on themselves.
    pub looped: bool,
    pub camera: Option<CameraPath>,
    pub objects: Vec<ObjectTrack>,
    pub sun: Option<Curve<3>>,
}

/// The camera's path: eye, look-at point (or along the path), up and vertical field of view.
#[derive(Clone, Debug, PartialEq)]
pub struct CameraPath {
    pub eye: Curve<3>,
    /// `None`: the camera looks where the eye is heading.
    pub look_at: Option<Curve<3>>,
    pub up: Curve<3>,
    /// Radians.
    pub fov_y: Curve<1>,
    /// The scene camera's near distance, kept.
    pub near: f64,
}

/// Where an object (of `kind`, at `index` in that kind's storage) is moved to over time.
#[derive(Clone, Debug, PartialEq)]
pub struct ObjectTrack {
    pub name: String,
    pub target: TrackTarget,
    pub translate: Curve<3>,
    /// The keys' rotations, interpolated per segment along the shortest arc.
    pub rotations: Vec<DQuat>,
}

/// The objects a track can move.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum TrackTarget {
    /// `Scene::objects[i]` (a free form or CSG solid).
    Solid(usize),
    /// `Scene::meshes[i]`.
    Mesh(usize),
}

impl Animation {
    /// The animation's length in seconds: `frames / fps`.
    pub fn duration(&self) -> f64 {
        f64::from(self.frames) / self.fps
    }

    /// The time of frame `n`.
    pub fn frame_time(&self, n: u32) -> f64 {
        f64::from(n) / self.fps
    }
}

impl CameraPath {
    /// The camera at time `t`.
    pub fn at(&self, t: f64) -> Result<Pinhole, fray_core::ProjectorError> {
        let eye = DVec3::from_array(self.eye.at(t));
        let look_at = match &self.look_at {
            Some(c) => DVec3::from_array(c.at(t)),
            None => eye + DVec3::from_array(self.eye.tangent(t)),
        };
        Pinhole::new(
            eye,
            look_at,
            DVec3::from_array(self.up.at(t)),
            self.fov_y.at(t)[0],
            self.near,
        )
    }
}

impl ObjectTrack {
    /// The motion at time `t`: the interpolated rotation (about the world origin), then the
    /// translation.
    pub fn at(&self, t: f64) -> DAffine3 {
        let (i, j, s) = self.translate.segment(t);
        let (a, b) = (self.rotations[i], self.rotations[j]);
        // A key's own time and equal keys give the key's rotation exactly (no rounding turns a
        // still object's clipping box).
        let q = if a == b || s == 0.0 {
            a
        } else if s == 1.0 {
            b
        } else {
            a.slerp(b, s)
        };
        DAffine3::from_mat3_translation(
            DMat3::from_quat(q),
            DVec3::from_array(self.translate.at(t)),
        )
    }
}

impl Scene {
    /// The scene at time `t` (seconds) of its animation: the camera on its path, each tracked
    /// object moved from where the file places it, the first sun (and the sky's) turned, each
    /// terrain with moving heights given its heights at `t` (with or without an `animation:`
    /// block). The result is a still (`animation: None`, no terrain `heights`); a scene with
    /// nothing that moves is returned as it is. Every frame is computed from the file's
    /// placement and heights, never from an earlier frame, so a frame is the same whether
    /// rendered alone or in a sequence.
    pub fn at_time(&self, t: f64) -> Result<Scene, SceneError> {
        let mut scene = self.clone();
        let moving_terrains = scene.terrains.iter().any(|o| o.heights.is_some());
        let animation = scene.animation.take();
        if animation.is_none() && !moving_terrains {
            return Ok(scene);
        }
        let fail = |what: &str, message: String| SceneError::Animation {
            time: t,
            what: what.to_owned(),
            message,
        };
        if !t.is_finite() {
            return Err(fail("time", "must be finite".into()));
        }
        for object in &mut scene.terrains {
            let Some(heights) = object.heights.take() else {
                continue;
            };
            let (terrain, held) = heights
                .terrain_at(&object.terrain, t, &scene.budget, &object.name)
                .map_err(|m| fail(&format!("the terrain {}'s heights", object.name), m))?;
            object.terrain = terrain;
            object.frame_memory = Some(held);
        }
        let Some(animation) = animation else {
            return Ok(scene);
        };
        if let Some(path) = &animation.camera {
            let camera = path
                .at(t)
                .map_err(|e| fail("animation.camera", e.to_string()))?;
            scene.camera = Projector::Pinhole(camera);
        }
        for track in &animation.objects {
            let motion = track.at(t);
            let what = format!("animation.objects.{}", track.name);
            match track.target {
                TrackTarget::Solid(i) => {
                    let object = &mut scene.objects[i];
                    let (solid, origins) = object
                        .solid
                        .moved(&motion)
                        .map_err(|e| fail(&what, e.to_string()))?;
                    // A turned clipping box adds leaves: each takes its origin's material.
                    let materials = &object.leaf_materials;
                    object.leaf_materials = origins
                        .iter()
                        .map(|&o| materials.get(o as usize).copied().unwrap_or(0))
                        .collect();
                    object.solid = solid;
                }
                TrackTarget::Mesh(i) => {
                    let mesh = &mut scene.meshes[i];
                    mesh.instance = mesh
                        .instance
                        .moved(&motion)
                        .map_err(|e| fail(&what, e.to_string()))?;
                }
            }
        }
        if let Some(sun) = &animation.sun {
            let direction = DVec3::from_array(sun.at(t)).normalize_or_zero();
            if direction == DVec3::ZERO {
                return Err(fail(
                    "animation.sun",
                    "the interpolated direction vanishes (two keys point opposite ways)".into(),
                ));
            }
            let first = scene
                .lights
                .iter()
                .position(|l| matches!(l, Light::Sun { .. }));
            if let Some(Light::Sun { direction: d, .. }) = first.map(|i| &mut scene.lights[i]) {
                *d = direction;
            }
            if let Some(sky) = &mut scene.atmosphere.sky {
                let mut sun = *sky.sky.sun();
                sun.direction = direction;
                // The base scene shares its sky: turn a copy (the tables stay shared).
                std::sync::Arc::make_mut(&mut sky.sky)
                    .set_sun(sun)
                    .map_err(|e| fail("animation.sun", e.to_string()))?;
            }
        }
        Ok(scene)
    }

    /// Frame `n` of the scene's animation ([`Scene::at_time`] at `n / fps`); without one (no
    /// frame rate), the scene at time 0.
    pub fn at_frame(&self, n: u32) -> Result<Scene, SceneError> {
        match &self.animation {
            Some(a) => self.at_time(a.frame_time(n)),
            None => self.at_time(0.0),
        }
    }

    /// The scene seen from its camera named `name` (`cameras` in the file): a still, whatever the
    /// animation's camera path says.
    pub fn with_camera(&self, name: &str) -> Result<Scene, SceneError> {
        let Some(named) = self.cameras.iter().find(|c| c.name == name) else {
            let names: Vec<&str> = self.cameras.iter().map(|c| c.name.as_str()).collect();
            return Err(SceneError::NoSuchCamera {
                name: name.to_owned(),
                known: if names.is_empty() {
                    "the scene names no cameras".to_owned()
                } else {
                    format!("the scene's cameras: {}", names.join(", "))
                },
            });
        };
        let mut scene = self.clone();
        scene.camera = named.camera;
        if let Some(animation) = &mut scene.animation {
            let mut still_camera = (**animation).clone();
            still_camera.camera = None;
            *animation = std::sync::Arc::new(still_camera);
        }
        Ok(scene)
    }
}
