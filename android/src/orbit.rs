//! An orbit camera for touch input: a one-finger drag turns the eye around the scene centre at
//! a fixed distance. GL- and Android-free, so it is unit-tested on the host.

use manylight::glam::DVec3;
use manylight::Camera;

/// Largest angle above or below the horizon, radians (just under 90°, so `up` stays valid).
const MAX_PITCH: f64 = 1.5;

/// The eye on a sphere around `center`: `yaw` around +Y, `pitch` above the horizon.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Orbit {
    center: DVec3,
    distance: f64,
    yaw: f64,
    pitch: f64,
}

impl Orbit {
    /// An orbit around `center` that starts where `camera` is (a camera at the centre gets a
    /// unit distance along +Z).
    pub fn around(center: DVec3, camera: &Camera) -> Orbit {
        let offset = camera.position - center;
        let distance = offset.length();
        let (dir, distance) = match offset.try_normalize() {
            Some(d) if distance.is_finite() => (d, distance),
            _ => (DVec3::Z, 1.0),
        };
        Orbit {
            center,
            distance,
            yaw: dir.x.atan2(dir.z),
            pitch: dir.y.clamp(-1.0, 1.0).asin().clamp(-MAX_PITCH, MAX_PITCH),
        }
    }

    /// Turns by a drag of `(dx, dy)` pixels on a screen `width` pixels wide: a full-width swipe
    /// is half a turn. Dragging right swings the scene right, dragging down looks from higher.
    pub fn drag(&mut self, dx: f64, dy: f64, width: f64) {
        let radians_per_pixel = std::f64::consts::PI / width.max(1.0);
        if !(dx.is_finite() && dy.is_finite()) {
            return;
        }
        self.yaw -= dx * radians_per_pixel;
        self.pitch = (self.pitch + dy * radians_per_pixel).clamp(-MAX_PITCH, MAX_PITCH);
    }

    /// Places `camera` on the orbit, looking at the centre with +Y up.
    pub fn apply(&self, camera: &mut Camera) {
        let dir = DVec3::new(
            self.pitch.cos() * self.yaw.sin(),
            self.pitch.sin(),
            self.pitch.cos() * self.yaw.cos(),
        );
        camera.position = self.center + dir * self.distance;
        camera.target = self.center;
        camera.up = DVec3::Y;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn camera_at(position: DVec3) -> Camera {
        Camera::perspective(position, DVec3::ZERO, 60.0, 0.1, 100.0)
    }

    #[test]
    fn starts_where_the_camera_is() {
        let mut cam = camera_at(DVec3::new(3.0, 4.0, 12.0));
        let before = cam.position;
        Orbit::around(DVec3::ZERO, &cam).apply(&mut cam);
        assert!((cam.position - before).length() < 1e-9, "{}", cam.position);
        assert_eq!(cam.target, DVec3::ZERO);
    }

    #[test]
    fn drag_keeps_distance_and_clamps_pitch() {
        let center = DVec3::new(1.0, 2.0, 3.0);
        let mut cam = camera_at(center + DVec3::new(0.0, 0.0, 5.0));
        let mut orbit = Orbit::around(center, &cam);
        orbit.drag(500.0, 0.0, 1000.0); // half a screen: a quarter turn
        orbit.apply(&mut cam);
        let d = cam.position - center;
        assert!((d.length() - 5.0).abs() < 1e-9);
        assert!((d.x + 5.0).abs() < 1e-9, "a quarter turn to -X, got {d}");
        orbit.drag(0.0, 1e6, 1000.0);
        orbit.apply(&mut cam);
        let d = (cam.position - center).normalize();
        assert!((d.y - MAX_PITCH.sin()).abs() < 1e-9);
        orbit.drag(f64::NAN, 1.0, 0.0);
        orbit.apply(&mut cam);
        assert!(cam.position.is_finite());
    }

    #[test]
    fn camera_at_the_centre_gets_a_valid_orbit() {
        let mut cam = camera_at(DVec3::ZERO);
        Orbit::around(DVec3::ZERO, &cam).apply(&mut cam);
        assert_eq!(cam.position, DVec3::Z);
    }
}
