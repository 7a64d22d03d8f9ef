//! A fly camera for `manylight view`: held movement keys translate the eye, a mouse drag turns
//! it. Window-system free — the viewer maps key codes and cursor positions onto it — so it is
//! unit-tested without a window.
//!
//! It edits a [`Camera`]'s `position` and `target` only: moving shifts both by the same offset
//! (the look-at distance is kept), looking rotates the target around the eye, with the pitch
//! kept short of straight up or down so the camera's `up` never lines up with the view.

use glam::{DQuat, DVec3};
use manylight::scene::camera::MAX_CAMERA_COORD;
use manylight::scene::Camera;

/// Radians turned per pixel of mouse drag.
const LOOK_RADIANS_PER_PIXEL: f64 = 0.004;
/// Largest pitch above or below the horizon, radians (just under 90°).
const MAX_PITCH: f64 = 1.55;
/// Speed factor while Shift is held.
const FAST_FACTOR: f64 = 4.0;

/// A direction the keyboard can move the camera in.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Move {
    /// Along the view direction (W).
    Forward,
    /// Against the view direction (S).
    Back,
    /// To the left (A).
    Left,
    /// To the right (D).
    Right,
    /// Down along the camera's up axis (Q).
    Down,
    /// Up along the camera's up axis (E).
    Up,
}

/// Input state of the fly camera: held keys, the drag in progress and look motion not yet
/// applied.
#[derive(Clone, Debug)]
pub struct FlyCamera {
    /// World units per second.
    speed: f64,
    /// Held state of each [`Move`], indexed by `Move as usize`.
    held: [bool; 6],
    fast: bool,
    dragging: bool,
    /// Last cursor position seen, in pixels.
    cursor: Option<(f64, f64)>,
    /// Drag motion since the last [`FlyCamera::update`], in pixels.
    pending_look: (f64, f64),
}

impl FlyCamera {
    /// A fly camera moving `speed` world units per second (non-finite or negative: 1).
    pub fn new(speed: f64) -> Self {
        FlyCamera {
            speed: if speed.is_finite() && speed > 0.0 {
                speed
            } else {
                1.0
            },
            held: [false; 6],
            fast: false,
            dragging: false,
            cursor: None,
            pending_look: (0.0, 0.0),
        }
    }

    /// A speed that crosses a scene of this bounding-box diagonal in about four seconds.
    pub fn speed_for_extent(extent: f64) -> f64 {
        (extent / 4.0).max(1e-3)
    }

    /// Presses or releases a movement key.
    pub fn set_key(&mut self, m: Move, pressed: bool) {
        self.held[m as usize] = pressed;
    }

    /// Shift held: move faster.
    pub fn set_fast(&mut self, fast: bool) {
        self.fast = fast;
    }

    /// Starts or ends a look drag (left mouse button).
    pub fn set_dragging(&mut self, dragging: bool) {
        self.dragging = dragging;
    }

    /// Forgets every held key and drag, e.g. when the window loses focus (release events then
    /// go elsewhere).
    pub fn release_all(&mut self) {
        self.held = [false; 6];
        self.fast = false;
        self.dragging = false;
    }

    /// The cursor moved to `(x, y)` pixels; while dragging, the motion turns the camera.
    pub fn cursor_moved(&mut self, x: f64, y: f64) {
        if let (true, Some((px, py))) = (self.dragging, self.cursor) {
            self.pending_look.0 += x - px;
            self.pending_look.1 += y - py;
        }
        self.cursor = Some((x, y));
    }

    /// Applies `dt` seconds of held keys and the pending look motion to `camera`.
    pub fn update(&mut self, dt: f64, camera: &mut Camera) {
        let up = camera.up.try_normalize().unwrap_or(DVec3::Y);
        let offset = camera.target - camera.position;
        let distance = offset.length();
        let (mut forward, distance) = match offset.try_normalize() {
            Some(f) => (f, distance),
            None => (-DVec3::Z, 1.0),
        };
        let unturned = forward;
        let (dx, dy) = std::mem::take(&mut self.pending_look);
        if dx != 0.0 || dy != 0.0 {
            forward = turn(
                forward,
                up,
                -dx * LOOK_RADIANS_PER_PIXEL,
                -dy * LOOK_RADIANS_PER_PIXEL,
            );
        }
        let right = forward.cross(up).try_normalize().unwrap_or(DVec3::X);
        let axis = |plus: Move, minus: Move| {
            f64::from(u8::from(self.held[plus as usize]))
                - f64::from(u8::from(self.held[minus as usize]))
        };
        let direction = forward * axis(Move::Forward, Move::Back)
            + right * axis(Move::Right, Move::Left)
            + up * axis(Move::Up, Move::Down);
        let step = if dt.is_finite() && dt > 0.0 {
            self.speed * dt * if self.fast { FAST_FACTOR } else { 1.0 }
        } else {
            0.0
        };
        // The eye and its target stay within the coordinates the view maths holds (past them
        // the next frame refuses the camera): at the edge the camera slides along it (each axis
        // of the step taken where it stays within), and does not turn where its target would
        // leave it.
        let within = |v: DVec3| v.abs().max_element() <= MAX_CAMERA_COORD;
        let turned = camera.position + forward * distance;
        if !within(turned) {
            forward = unturned;
        }
        let step = direction * step;
        for k in 0..3 {
            let mut moved = camera.position;
            moved[k] += step[k];
            if within(moved) && within(moved + forward * distance) {
                camera.position = moved;
            }
        }
        camera.target = camera.position + forward * distance;
    }
}

/// `forward` turned by `yaw` around `up` and pitched by `pitch`, with the pitch clamped to
/// ±[`MAX_PITCH`] from the plane perpendicular to `up` (both unit vectors).
fn turn(forward: DVec3, up: DVec3, yaw: f64, pitch: f64) -> DVec3 {
    let height = forward.dot(up).clamp(-1.0, 1.0);
    // The horizontal heading; looking straight along `up` has none, so pick any.
    let heading = (forward - up * height)
        .try_normalize()
        .unwrap_or_else(|| up.any_orthonormal_vector());
    let heading = DQuat::from_axis_angle(up, yaw) * heading;
    let new_pitch = (height.asin() + pitch).clamp(-MAX_PITCH, MAX_PITCH);
    (heading * new_pitch.cos() + up * new_pitch.sin()).normalize()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn camera() -> Camera {
        Camera::perspective(
            DVec3::new(0.0, 1.0, 5.0),
            DVec3::new(0.0, 1.0, 0.0),
            60.0,
            0.1,
            100.0,
        )
    }

    #[test]
    fn forward_moves_eye_and_target_together() {
        let mut fly = FlyCamera::new(2.0);
        let mut cam = camera();
        fly.set_key(Move::Forward, true);
        fly.update(0.5, &mut cam);
        assert!((cam.position - DVec3::new(0.0, 1.0, 4.0)).length() < 1e-12);
        assert!((cam.target - DVec3::new(0.0, 1.0, -1.0)).length() < 1e-12);
        fly.set_key(Move::Forward, false);
        fly.set_key(Move::Up, true);
        fly.set_key(Move::Right, true);
        fly.update(1.0, &mut cam);
        assert!((cam.position - DVec3::new(2.0, 3.0, 4.0)).length() < 1e-12);
    }

    #[test]
    fn drag_turns_and_pitch_is_clamped() {
        let mut fly = FlyCamera::new(1.0);
        let mut cam = camera();
        fly.set_dragging(true);
        fly.cursor_moved(100.0, 100.0);
        fly.cursor_moved(100.0, -10_000.0); // a huge drag upwards
        fly.update(0.016, &mut cam);
        let f = (cam.target - cam.position).normalize();
        assert!(
            f.y > 0.99 && f.y < 1.0,
            "pitch clamped below straight up: {f}"
        );
        assert!(((cam.target - cam.position).length() - 5.0).abs() < 1e-9);
        // Motion without a drag does nothing.
        fly.set_dragging(false);
        let before = cam;
        fly.cursor_moved(500.0, 500.0);
        fly.update(0.016, &mut cam);
        assert_eq!(before, cam);
    }

    /// Flying on past the coordinates a camera may have stops at their edge: the next frame
    /// refused the camera and ended the viewer.
    #[test]
    fn the_camera_stops_at_the_edge_of_its_range() {
        let mut fly = FlyCamera::new(1e11);
        let edge = MAX_CAMERA_COORD - 5e10;
        let mut cam = Camera::perspective(
            DVec3::new(edge, 0.0, 0.0),
            DVec3::new(edge + 1.0, 0.0, 0.0),
            60.0,
            0.1,
            100.0,
        );
        fly.set_key(Move::Forward, true);
        for _ in 0..10 {
            fly.update(1.0, &mut cam);
            cam.validate().unwrap();
        }
        assert_eq!(cam.position.x, edge, "it stopped");
        // Sideways along the edge it slides.
        fly.set_key(Move::Left, true);
        fly.update(1.0, &mut cam);
        assert_eq!(cam.position.x, edge);
        assert!(
            cam.position.y.abs() + cam.position.z.abs() > 1e10,
            "{}",
            cam.position
        );
        cam.validate().unwrap();
        fly.set_key(Move::Left, false);
        // Back in it moves again.
        fly.set_key(Move::Forward, false);
        fly.set_key(Move::Back, true);
        fly.update(1.0, &mut cam);
        assert!(cam.position.x < edge);
        cam.validate().unwrap();
    }

    #[test]
    fn degenerate_camera_stays_finite() {
        let mut fly = FlyCamera::new(f64::NAN);
        let mut cam = camera();
        cam.target = cam.position;
        fly.set_dragging(true);
        fly.cursor_moved(0.0, 0.0);
        fly.cursor_moved(10.0, 10.0);
        fly.set_key(Move::Left, true);
        fly.update(f64::INFINITY, &mut cam);
        assert!(cam.position.is_finite() && cam.target.is_finite());
        assert!(cam.target != cam.position);
    }
}
