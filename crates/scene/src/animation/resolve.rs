//! Checks a scene file's `animation` against the resolved scene, with located errors.

use super::{Animation, CameraPath, Curve, ObjectTrack, TrackTarget};
use crate::checks::{Result, angle, direction, invalid, point, positive};
use crate::description::{self, Interpolation};
use crate::path::FieldPath;
use crate::{Light, Scene};
use fray_core::Projector;
use glam::DQuat;

/// The most frames an animation may have (a day at 24 frames per second is 2 073 600): every
/// frame's camera is checked when the scene is loaded.
pub const MAX_FRAMES: u32 = 10_000_000;

/// Checks `d` (the file's `animation`, at `path`) against `scene` (resolved, without it).
pub(crate) fn resolve(
    path: &FieldPath,
    d: &description::Animation,
    scene: &Scene,
) -> Result<Animation> {
    let fps = positive(&path.field("fps"), d.fps)?;
    // The last key of any track: the default length.
    let last_key = d
        .camera
        .iter()
        .flat_map(|c| c.keys.iter().map(|k| k.time))
        .chain(
            d.objects
                .values()
                .flat_map(|o| o.keys.iter().map(|k| k.time)),
        )
        .chain(d.sun.iter().flat_map(|s| s.keys.iter().map(|k| k.time)))
        .fold(0.0_f64, f64::max);
    let frames = match d.frames {
        Some(n) if n.fract() == 0.0 && n >= 1.0 && n <= f64::from(MAX_FRAMES) => n as u32,
        Some(n) => {
            return invalid(
                &path.field("frames"),
                format!("must be a whole number in 1..={MAX_FRAMES}, got {n}"),
            );
        }
        None if d.looped => {
            return invalid(
                &path.field("frames"),
                "a looping animation needs its length: give `frames`",
            );
        }
        None => {
            let n = (last_key * fps).floor() + 1.0;
            if !(n.is_finite() && n <= f64::from(MAX_FRAMES)) {
                return invalid(
                    &path.field("fps"),
                    format!("the last key at {last_key} s makes more than {MAX_FRAMES} frames"),
                );
            }
            n as u32
        }
    };
    let period = d.looped.then(|| f64::from(frames) / fps);
    let camera = match &d.camera {
        None => None,
        Some(c) => Some(camera_path(&path.field("camera"), c, scene, period)?),
    };
    let objects_path = path.field("objects");
    let mut objects = Vec::with_capacity(d.objects.len());
    for (name, track) in &d.objects {
        let at = objects_path.field(name);
        objects.push(object_track(&at, name, track, scene, period)?);
    }
    let sun = match &d.sun {
        None => None,
        Some(s) => {
            let at = path.field("sun");
            if !scene.lights.iter().any(|l| matches!(l, Light::Sun { .. })) {
                return invalid(&at, "the scene has no `Sun` light to turn");
            }
            let keys_path = at.field("keys");
            let times = times(&keys_path, s.keys.iter().map(|k| k.time), period)?;
            let mut keys = Vec::with_capacity(times.len());
            for (k, (key, t)) in s.keys.iter().zip(times).enumerate() {
                let d = direction(&keys_path.index(k).field("direction"), key.direction)?;
                keys.push((t, d.normalize().to_array()));
            }
            Some(Curve::new(keys, s.interpolation, s.ease, period))
        }
    };
    let animation = Animation {
        fps,
        frames,
        looped: d.looped,
        camera,
        objects,
        sun,
    };
    // Every frame's camera is a camera (a path whose look-at point meets the eye, or whose up
    // turns along the view, is refused here rather than at frame 1 000).
    if let Some(c) = &animation.camera {
        for n in 0..frames {
            if let Err(e) = c.at(animation.frame_time(n)) {
                return invalid(
                    &path.field("camera"),
                    format!("frame {n} (at {} s): {e}", animation.frame_time(n)),
                );
            }
        }
    }
    Ok(animation)
}

/// The keys' times: finite, strictly increasing, and within one period of a loop.
fn times(
    path: &FieldPath,
    times: impl Iterator<Item = f64>,
    period: Option<f64>,
) -> Result<Vec<f64>> {
    let times: Vec<f64> = times.collect();
    if times.is_empty() {
        return invalid(path, "needs at least one key");
    }
    for (k, &t) in times.iter().enumerate() {
        let at = path.index(k).field("time");
        if !t.is_finite() || t < 0.0 {
            return invalid(&at, format!("must be a finite time ≥ 0 s, got {t}"));
        }
        if k > 0 && t <= times[k - 1] {
            return invalid(
                &at,
                format!(
                    "keys must be in increasing time: {t} s follows {} s",
                    times[k - 1]
                ),
            );
        }
        if let Some(p) = period
            && t >= p
        {
            return invalid(
                &at,
                format!("a looping animation's keys lie before its end at {p} s, got {t} s"),
            );
        }
    }
    Ok(times)
}

fn camera_path(
    path: &FieldPath,
    d: &description::CameraPath,
    scene: &Scene,
    period: Option<f64>,
) -> Result<CameraPath> {
    let Projector::Pinhole(pinhole) = scene.camera else {
        return invalid(
            path,
            "a camera path moves a `Pinhole` camera: make `camera` one",
        );
    };
    let keys_path = path.field("keys");
    let times = times(&keys_path, d.keys.iter().map(|k| k.time), period)?;
    let looks = d.keys.iter().filter(|k| k.look_at.is_some()).count();
    if looks != 0 && looks != d.keys.len() {
        let k = d.keys.iter().position(|k| k.look_at.is_none()).unwrap_or(0);
        return invalid(
            &keys_path.index(k).field("look_at"),
            "give every key a `look_at`, or none (the camera then looks along its path)",
        );
    }
    let scene_fov = 2.0 * pinhole.tan_half_fov_y.atan();
    let (mut eye, mut look_at, mut up, mut fov) = (vec![], vec![], vec![], vec![]);
    for (k, (key, &t)) in d.keys.iter().zip(&times).enumerate() {
        let at = keys_path.index(k);
        eye.push((t, point(&at.field("eye"), key.eye)?.to_array()));
        if let Some(l) = key.look_at {
            look_at.push((t, point(&at.field("look_at"), l)?.to_array()));
        }
        up.push((t, direction(&at.field("up"), key.up)?.to_array()));
        let fov_y = match key.fov_y {
            Some(f) => angle(&at.field("fov_y"), f, 0.0, 180.0, false)?,
            None => scene_fov,
        };
        fov.push((t, [fov_y]));
    }
    if looks == 0 && d.keys.len() < 2 {
        return invalid(
            &keys_path,
            "a camera that looks along its path needs two keys or more",
        );
    }
    let curve = |keys| Curve::new(keys, d.interpolation, d.ease, period);
    Ok(CameraPath {
        eye: curve(eye),
        look_at: (looks > 0).then(|| curve(look_at)),
        up: curve(up),
        // The field of view eases between keys without overshooting past a key's value.
        fov_y: Curve::new(fov, Interpolation::Linear, d.ease, period),
        near: pinhole.near,
    })
}

fn object_track(
    path: &FieldPath,
    name: &str,
    d: &description::ObjectTrack,
    scene: &Scene,
    period: Option<f64>,
) -> Result<ObjectTrack> {
    let solids = scene
        .objects
        .iter()
        .enumerate()
        .filter(|(_, o)| o.name == name);
    let meshes = scene
        .meshes
        .iter()
        .enumerate()
        .filter(|(_, m)| m.name == name);
    let targets: Vec<TrackTarget> = solids
        .map(|(i, _)| TrackTarget::Solid(i))
        .chain(meshes.map(|(i, _)| TrackTarget::Mesh(i)))
        .collect();
    let target = match targets.as_slice() {
        [one] => *one,
        [] if scene.terrains.iter().any(|t| t.name == name) => {
            return invalid(path, "a terrain does not move (place it with `origin`)");
        }
        [] => {
            return invalid(
                path,
                format!("no free-form or mesh object is named {name:?}"),
            );
        }
        many => {
            return invalid(
                path,
                format!("{} objects are named {name:?}: name each once", many.len()),
            );
        }
    };
    let keys_path = path.field("keys");
    let times = times(&keys_path, d.keys.iter().map(|k| k.time), period)?;
    let mut translate = Vec::with_capacity(times.len());
    let mut rotations = Vec::with_capacity(times.len());
    for (k, (key, &t)) in d.keys.iter().zip(&times).enumerate() {
        let at = keys_path.index(k);
        translate.push((t, point(&at.field("translate"), key.translate)?.to_array()));
        let r = point(&at.field("rotate"), key.rotate)?;
        let q = DQuat::from_rotation_z(r.z.to_radians())
            * DQuat::from_rotation_y(r.y.to_radians())
            * DQuat::from_rotation_x(r.x.to_radians());
        rotations.push(q);
    }
    Ok(ObjectTrack {
        name: name.to_owned(),
        target,
        translate: Curve::new(translate, d.interpolation, d.ease, period),
        rotations,
    })
}
