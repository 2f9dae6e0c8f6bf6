//! The viewer's camera: a pinhole that flies (position, yaw, pitch) and orbits a picked point,
//! printed as the scene snippet that renders it again.

use fray_core::{Pinhole, Projector};
use glam::DVec3;

/// The steepest the camera looks up or down (radians): short of ±90°, where `up = +Y` would be
/// parallel to the view direction.
const MAX_PITCH: f64 = 1.55;

/// A pinhole camera the viewer moves. Until it moves it shows the scene's own projector, so the
/// first frame is the frame `fray render` makes; once moved it is the pinhole through `eye`
/// looking along `yaw`/`pitch` with `up = +Y`, built exactly as the scene loader builds
/// `Pinhole(eye, look_at, up, fov_y, near)` from the snippet [`FlyCamera::snippet`] prints.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FlyCamera {
    pub eye: DVec3,
    /// Angle about +Y from +Z toward +X (radians).
    pub yaw: f64,
    /// Angle above the horizon (radians).
    pub pitch: f64,
    /// The vertical field of view in degrees, as the scene format writes it.
    pub fov_y_degrees: f64,
    pub near: f64,
    /// What is rendered: the scene's projector until the first move, then the pinhole above.
    projector: Projector,
    moved: bool,
}

impl FlyCamera {
    /// The camera at `projector`'s eye looking where it looks (a parallel or sphere projector
    /// becomes a 45° pinhole once moved).
    pub fn of(projector: &Projector) -> Self {
        let (eye, forward, fov_y_degrees, near) = match projector {
            Projector::Pinhole(p) => (
                p.eye,
                p.basis.forward,
                (2.0 * p.tan_half_fov_y.atan()).to_degrees(),
                p.near,
            ),
            Projector::Parallel(p) => (p.eye, p.basis.forward, 45.0, p.near.max(0.01)),
            Projector::Sphere(s) => (s.eye, s.basis.forward, 45.0, 0.01),
        };
        Self {
            eye,
            yaw: forward.x.atan2(forward.z),
            pitch: forward
                .y
                .clamp(-1.0, 1.0)
                .asin()
                .clamp(-MAX_PITCH, MAX_PITCH),
            fov_y_degrees,
            near,
            projector: *projector,
            moved: false,
        }
    }

    /// The unit view direction.
    pub fn forward(&self) -> DVec3 {
        let (sy, cy) = self.yaw.sin_cos();
        let (sp, cp) = self.pitch.sin_cos();
        DVec3::new(cp * sy, sp, cp * cy)
    }

    /// The unit right vector (horizontal), as the projector's basis has it: `forward × up`.
    pub fn right(&self) -> DVec3 {
        self.forward().cross(DVec3::Y).normalize()
    }

    /// Whether the camera has moved from the scene's own projector.
    pub fn moved(&self) -> bool {
        self.moved
    }

    /// The point the snippet's `look_at` names: one unit ahead of the eye.
    pub fn look_at(&self) -> DVec3 {
        self.eye + self.forward()
    }

    /// Moves the eye by `delta` (world units).
    pub fn translate(&mut self, delta: DVec3) {
        if delta != DVec3::ZERO {
            self.change(|c| c.eye += delta);
        }
    }

    /// Turns the view by `d_yaw` and `d_pitch` radians (the pitch kept short of straight up or
    /// down).
    pub fn turn(&mut self, d_yaw: f64, d_pitch: f64) {
        if d_yaw != 0.0 || d_pitch != 0.0 {
            self.change(|c| c.rotate(d_yaw, d_pitch));
        }
    }

    /// Turns the view by `d_yaw`, `d_pitch` about `pivot`, keeping the eye `distance` from it
    /// and looking at it.
    pub fn orbit(&mut self, pivot: DVec3, distance: f64, d_yaw: f64, d_pitch: f64) {
        self.change(|c| {
            c.rotate(d_yaw, d_pitch);
            c.eye = pivot - c.forward() * distance;
        });
    }

    fn rotate(&mut self, d_yaw: f64, d_pitch: f64) {
        self.yaw += d_yaw;
        self.pitch = (self.pitch + d_pitch).clamp(-MAX_PITCH, MAX_PITCH);
    }

    /// Applies `edit` if the camera it leaves is a valid pinhole; a move that would make it
    /// invalid (an eye sent to infinity by a runaway speed) is refused.
    fn change(&mut self, edit: impl FnOnce(&mut Self)) {
        let mut next = *self;
        edit(&mut next);
        if let Ok(p) = Pinhole::new(
            next.eye,
            next.look_at(),
            DVec3::Y,
            next.fov_y_degrees.to_radians(),
            next.near,
        ) {
            next.projector = Projector::Pinhole(p);
            next.moved = true;
            *self = next;
        }
    }

    /// The projector to render.
    pub fn projector(&self) -> Projector {
        self.projector
    }

    /// The camera as a scene-format line: `camera: Pinhole(eye: (…), look_at: (…), up: (…),
    /// fov_y: …, near: …)`, every number printed so that it parses back to the same `f64`
    /// (an unmoved camera's: the scene's, to rounding).
    pub fn snippet(&self) -> String {
        let v = |p: DVec3| format!("({:?}, {:?}, {:?})", p.x, p.y, p.z);
        let up = match (self.moved, self.projector) {
            (false, Projector::Pinhole(p)) => p.basis.up,
            _ => DVec3::Y,
        };
        format!(
            "camera: Pinhole(eye: {}, look_at: {}, up: {}, fov_y: {:?}, near: {:?})",
            v(self.eye),
            v(self.look_at()),
            v(up),
            self.fov_y_degrees,
            self.near
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn scene_camera() -> Projector {
        Projector::Pinhole(
            Pinhole::new(
                DVec3::new(1.0, 2.0, -6.0),
                DVec3::new(0.0, 0.5, 0.0),
                DVec3::Y,
                40f64.to_radians(),
                0.05,
            )
            .unwrap(),
        )
    }

    #[test]
    fn an_unmoved_camera_is_the_scenes_projector() {
        let c = FlyCamera::of(&scene_camera());
        assert!(!c.moved());
        assert_eq!(c.projector(), scene_camera());
        let Projector::Pinhole(p) = scene_camera() else {
            unreachable!()
        };
        // Its direction is the projector's, to rounding.
        assert!((c.forward() - p.basis.forward).length() < 1e-12);
        assert!((c.fov_y_degrees - 40.0).abs() < 1e-9);
    }

    #[test]
    fn a_moved_camera_is_the_pinhole_its_snippet_names() {
        let mut c = FlyCamera::of(&scene_camera());
        c.translate(DVec3::new(0.1, 0.0, 0.3));
        c.turn(0.2, -0.1);
        let Projector::Pinhole(p) = c.projector() else {
            panic!("a pinhole")
        };
        // The snippet's numbers, parsed back, build the same pinhole bit for bit.
        let text = c.snippet();
        let numbers: Vec<f64> = text
            .split(|ch: char| !(ch.is_ascii_digit() || ch == '.' || ch == '-' || ch == 'e'))
            .filter_map(|s| s.parse().ok())
            .collect();
        assert_eq!(numbers.len(), 11, "{text}");
        let v = |i: usize| DVec3::new(numbers[i], numbers[i + 1], numbers[i + 2]);
        let again = Pinhole::new(v(0), v(3), v(6), numbers[9].to_radians(), numbers[10]).unwrap();
        assert_eq!(p, again);
        assert!(text.starts_with("camera: Pinhole(eye: ("), "{text}");
    }

    #[test]
    fn flying_moves_along_the_view_and_orbiting_keeps_the_distance() {
        let mut c = FlyCamera::of(&scene_camera());
        let before = c.eye;
        c.translate(c.forward() * 2.0);
        assert!(((c.eye - before).length() - 2.0).abs() < 1e-12);
        assert!((c.right().dot(c.forward())).abs() < 1e-12);
        let pivot = DVec3::new(0.0, 0.5, 0.0);
        c.orbit(pivot, 3.0, 0.7, 0.2);
        assert!(((c.eye - pivot).length() - 3.0).abs() < 1e-12);
        assert!(((pivot - c.eye).normalize() - c.forward()).length() < 1e-12);
        // The pitch stays short of the pole: the pinhole still exists.
        c.turn(0.0, 10.0);
        assert!(c.pitch <= MAX_PITCH);
        assert!(matches!(c.projector(), Projector::Pinhole(_)));
    }
}
