//! The keys and buttons held down, and how they move the camera each frame.

use crate::camera::FlyCamera;
use glam::DVec3;
use winit::keyboard::KeyCode;

/// Radians per pixel of mouse motion (look and orbit).
pub const TURN_PER_PIXEL: f64 = 0.004;
/// The speed's factor per wheel notch.
pub const SPEED_PER_NOTCH: f64 = 1.25;

/// What is held down.
#[derive(Clone, Debug, Default)]
pub struct Held {
    keys: Vec<KeyCode>,
    /// Mouse look (right button).
    pub looking: bool,
    /// Orbit (left button): the picked point and the eye's distance from it.
    pub orbit: Option<(DVec3, f64)>,
}

/// The movement keys: W/S forward/back, A/D left/right, Q/E down/up.
const MOVES: [KeyCode; 6] = [
    KeyCode::KeyW,
    KeyCode::KeyS,
    KeyCode::KeyA,
    KeyCode::KeyD,
    KeyCode::KeyQ,
    KeyCode::KeyE,
];

impl Held {
    /// Records a key going down (`pressed`) or up; returns whether it is a movement key.
    pub fn key(&mut self, key: KeyCode, pressed: bool) -> bool {
        if !MOVES.contains(&key) {
            return false;
        }
        self.keys.retain(|k| *k != key);
        if pressed {
            self.keys.push(key);
        }
        true
    }

    /// Lets go of everything (the window lost focus).
    pub fn release_all(&mut self) {
        *self = Self::default();
    }

    /// Whether the camera is being moved.
    pub fn moving(&self) -> bool {
        !self.keys.is_empty() || self.looking || self.orbit.is_some()
    }

    /// Flies `camera` for `seconds` at `speed` (world units per second) along the held keys.
    pub fn fly(&self, camera: &mut FlyCamera, speed: f64, seconds: f64) {
        let (forward, right) = (camera.forward(), camera.right());
        let mut d = DVec3::ZERO;
        for key in &self.keys {
            d += match key {
                KeyCode::KeyW => forward,
                KeyCode::KeyS => -forward,
                KeyCode::KeyA => -right,
                KeyCode::KeyD => right,
                KeyCode::KeyQ => DVec3::NEG_Y,
                KeyCode::KeyE => DVec3::Y,
                _ => DVec3::ZERO,
            };
        }
        camera.translate(d * (speed * seconds));
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use fray_core::{Pinhole, Projector};

    #[test]
    fn held_keys_fly_the_camera_and_released_keys_stop_it() {
        let p = Pinhole::new(DVec3::ZERO, DVec3::Z, DVec3::Y, 0.8, 0.01).unwrap();
        let mut camera = FlyCamera::of(&Projector::Pinhole(p));
        let mut held = Held::default();
        assert!(held.key(KeyCode::KeyW, true));
        assert!(!held.key(KeyCode::KeyX, true), "not a movement key");
        assert!(held.moving());
        held.fly(&mut camera, 2.0, 0.5);
        assert!((camera.eye - DVec3::Z).length() < 1e-12, "{:?}", camera.eye);
        held.key(KeyCode::KeyE, true);
        held.key(KeyCode::KeyW, false);
        held.fly(&mut camera, 1.0, 1.0);
        assert!((camera.eye - DVec3::new(0.0, 1.0, 1.0)).length() < 1e-12);
        held.key(KeyCode::KeyE, false);
        assert!(!held.moving());
    }
}
