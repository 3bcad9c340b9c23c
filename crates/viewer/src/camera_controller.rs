//! Fly-camera input: WASD to move, Q/E down/up, right mouse button held to look, scroll
//! wheel to change speed, Shift to go faster.

use glam::Vec3;
use manylights::Camera;
use winit::keyboard::KeyCode;

/// Radians of turn per pixel of mouse motion.
const LOOK_SENSITIVITY: f32 = 0.003;
/// Speed multiplier while Shift is held.
const FAST_FACTOR: f32 = 4.0;

#[derive(Debug)]
pub struct CameraController {
    /// Metres per second.
    pub speed: f32,
    pressed: [bool; 7],
    looking: bool,
}

const KEYS: [KeyCode; 7] = [
    KeyCode::KeyW,
    KeyCode::KeyS,
    KeyCode::KeyA,
    KeyCode::KeyD,
    KeyCode::KeyQ,
    KeyCode::KeyE,
    KeyCode::ShiftLeft,
];

impl CameraController {
    pub fn new(speed: f32) -> Self {
        Self {
            speed,
            pressed: [false; 7],
            looking: false,
        }
    }

    /// Returns true if the key is one of the movement keys.
    pub fn key(&mut self, code: KeyCode, pressed: bool) -> bool {
        let code = if code == KeyCode::ShiftRight {
            KeyCode::ShiftLeft
        } else {
            code
        };
        match KEYS.iter().position(|k| *k == code) {
            Some(i) => {
                self.pressed[i] = pressed;
                true
            }
            None => false,
        }
    }

    pub fn set_looking(&mut self, looking: bool) {
        self.looking = looking;
    }

    pub fn mouse_motion(&mut self, camera: &mut Camera, dx: f64, dy: f64) {
        if self.looking {
            camera.yaw -= dx as f32 * LOOK_SENSITIVITY;
            camera.pitch = (camera.pitch - dy as f32 * LOOK_SENSITIVITY)
                .clamp(-std::f32::consts::FRAC_PI_2, std::f32::consts::FRAC_PI_2);
        }
    }

    /// Scroll: each notch changes speed by 20%.
    pub fn scroll(&mut self, notches: f32) {
        self.speed = (self.speed * 1.2f32.powf(notches)).clamp(0.01, 1000.0);
    }

    /// Moves the camera for `dt` seconds of held keys.
    pub fn update(&self, camera: &mut Camera, dt: f32) {
        let rotation = camera.rotation();
        let forward = rotation * Vec3::NEG_Z;
        let right = rotation * Vec3::X;
        let axes = [forward, -forward, -right, right, Vec3::NEG_Y, Vec3::Y];
        let direction: Vec3 = axes
            .iter()
            .zip(&self.pressed)
            .filter(|(_, p)| **p)
            .map(|(a, _)| *a)
            .sum();
        let speed = if self.pressed[6] {
            self.speed * FAST_FACTOR
        } else {
            self.speed
        };
        camera.position += direction.normalize_or_zero() * speed * dt;
    }
}
