//! The camera: right-handed, looking down −Z in view space, with a perspective (vertical field
//! of view) or orthographic projection. Clip space follows GL conventions (z in [−1, 1]).

use glam::{DMat4, DVec3};
use serde::{Deserialize, Serialize};

use super::SceneError;

/// How view space maps to clip space.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(tag = "type", rename_all = "snake_case", deny_unknown_fields)]
pub enum Projection {
    /// Perspective with a vertical field of view in degrees. `far` may be `f64::INFINITY`.
    Perspective {
        /// Vertical field of view, degrees, in (0, 180).
        fov_y_deg: f64,
        /// Near plane distance, > 0.
        near: f64,
        /// Far plane distance, > near (may be infinite).
        far: f64,
    },
    /// Orthographic with the visible height in world units.
    Orthographic {
        /// Visible height in world units, > 0.
        height: f64,
        /// Near plane distance, >= 0.
        near: f64,
        /// Far plane distance, > near.
        far: f64,
    },
}

/// Largest camera position or target coordinate, in world units: f64 keeps 10⁻⁴ there, and
/// positions relative to the camera are formed in f64 before they become f32.
pub const MAX_CAMERA_COORD: f64 = 1e12;

/// Smallest orthographic view height: a pixel of a smaller view is finer than f32 view-space
/// coordinates resolve (10⁻⁹ rendered half the frame black).
pub const MIN_ORTHO_HEIGHT: f64 = 1e-6;

/// Narrowest perspective field of view, in degrees: a narrower one puts a scene's triangles
/// millions of NDC units wide, past what rasterizers clip exactly (llvmpipe drew half the
/// frame black).
pub const MIN_FOV_Y_DEG: f64 = 1e-3;

/// A perspective far plane this many near planes away or more is treated as infinite.
pub const FAR_AS_INFINITE: f64 = 1e20;

/// A look-at camera. World positions are `f64` so scenes far from the origin keep precision.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Camera {
    /// Eye position in world space.
    pub position: DVec3,
    /// Point looked at.
    pub target: DVec3,
    /// Approximate up direction.
    pub up: DVec3,
    /// Projection.
    pub projection: Projection,
}

impl Default for Camera {
    fn default() -> Self {
        Camera::perspective(DVec3::new(0.0, 0.0, 5.0), DVec3::ZERO, 60.0, 0.1, 100.0)
    }
}

impl Camera {
    /// A perspective camera at `position` looking at `target` with +Y up.
    pub fn perspective(
        position: DVec3,
        target: DVec3,
        fov_y_deg: f64,
        near: f64,
        far: f64,
    ) -> Self {
        Camera {
            position,
            target,
            up: DVec3::Y,
            projection: Projection::Perspective {
                fov_y_deg,
                near,
                far,
            },
        }
    }

    /// World → view transform (right-handed, looking down −Z).
    pub fn view_matrix(&self) -> DMat4 {
        glam::dcamera::rh::view::look_at_mat4(self.position, self.target, self.up)
    }

    /// View → clip transform for a viewport of the given aspect ratio (width / height).
    pub fn projection_matrix(&self, aspect: f64) -> DMat4 {
        match self.projection {
            Projection::Perspective {
                fov_y_deg,
                near,
                far,
            } => {
                // Past 10²⁰ near planes the finite formula's terms round to the infinite
                // projection's, or overflow (far near f64::MAX gave an all-black frame).
                if far.is_infinite() || far / near > FAR_AS_INFINITE {
                    perspective_infinite_gl(fov_y_deg.to_radians(), aspect, near)
                } else {
                    glam::dcamera::rh::proj::opengl::perspective(
                        fov_y_deg.to_radians(),
                        aspect,
                        near,
                        far,
                    )
                }
            }
            Projection::Orthographic { height, near, far } => {
                let h = height * 0.5;
                let w = h * aspect;
                glam::dcamera::rh::proj::opengl::orthographic(-w, w, -h, h, near, far)
            }
        }
    }

    /// Near and far plane distances.
    pub fn near_far(&self) -> (f64, f64) {
        match self.projection {
            Projection::Perspective { near, far, .. }
            | Projection::Orthographic { near, far, .. } => (near, far),
        }
    }

    /// How far apart in depth two surfaces `distance` from the eye must be for the depth
    /// test to tell them apart: one step of a 24-bit depth buffer (and of `f32` window depth,
    /// which has as many bits), `distance² / (near · 2²⁴)` in perspective (any far plane), the
    /// depth range over 2²⁴ in orthographic. `docs/precision.md` gives figures.
    pub(crate) fn depth_step_at(&self, distance: f64) -> f64 {
        const STEPS: f64 = (1u32 << 24) as f64;
        match self.projection {
            Projection::Perspective { near, .. } => distance * distance / (near * STEPS),
            Projection::Orthographic { near, far, .. } => (far - near) / STEPS,
        }
    }

    /// Checks the camera values; errors name the field.
    pub fn validate(&self) -> Result<(), SceneError> {
        for (name, v) in [
            ("camera.position", self.position),
            ("camera.target", self.target),
            ("camera.up", self.up),
        ] {
            if !v.is_finite() {
                return Err(SceneError::invalid(
                    name,
                    format!("must be finite, got {v:?}"),
                ));
            }
        }
        for (name, v) in [
            ("camera.position", self.position),
            ("camera.target", self.target),
            ("camera.up", self.up),
        ] {
            if v.abs().max_element() > MAX_CAMERA_COORD {
                return Err(SceneError::invalid(
                    name,
                    format!(
                        "must be within ±{MAX_CAMERA_COORD:e} (the view maths keeps \
                         centimetres only up to there), got {v:?}"
                    ),
                ));
            }
        }
        let forward = self.target - self.position;
        if forward == DVec3::ZERO {
            return Err(SceneError::invalid(
                "camera.target",
                "equals camera.position",
            ));
        }
        // Lengths whose squares underflow give no direction to the view maths.
        if forward.length_squared() == 0.0 {
            return Err(SceneError::invalid(
                "camera.target",
                format!(
                    "lies only {:?} from camera.position along an axis: too near to give a \
                     view direction",
                    forward.abs().max_element()
                ),
            ));
        }
        if self.up == DVec3::ZERO {
            return Err(SceneError::invalid("camera.up", "must be non-zero"));
        }
        if self.up.length_squared() == 0.0 {
            return Err(SceneError::invalid(
                "camera.up",
                format!(
                    "is too short to give a direction ({:?}): a unit vector is the usual",
                    self.up
                ),
            ));
        }
        // Unit vectors first: the squared lengths of raw ones can overflow or underflow.
        if forward
            .normalize()
            .cross(self.up.normalize())
            .length_squared()
            <= 1e-24
        {
            return Err(SceneError::invalid(
                "camera.up",
                "is parallel to the view direction",
            ));
        }
        let (near, far) = self.near_far();
        match self.projection {
            Projection::Perspective { fov_y_deg, .. } => {
                if !(MIN_FOV_Y_DEG..180.0).contains(&fov_y_deg) {
                    return Err(SceneError::invalid(
                        "camera.fov_y_deg",
                        format!("must be in [{MIN_FOV_Y_DEG:e}, 180), got {fov_y_deg}"),
                    ));
                }
                if !(near > 0.0 && near.is_finite()) {
                    return Err(SceneError::invalid(
                        "camera.near",
                        format!("must be finite and > 0 for a perspective camera, got {near}"),
                    ));
                }
            }
            Projection::Orthographic { height, .. } => {
                if !(height >= MIN_ORTHO_HEIGHT && height.is_finite()) {
                    return Err(SceneError::invalid(
                        "camera.height",
                        format!(
                            "must be finite and >= {MIN_ORTHO_HEIGHT:e} (smaller views fall \
                             between f32 view-space values), got {height}"
                        ),
                    ));
                }
                if !(near >= 0.0 && near.is_finite()) {
                    return Err(SceneError::invalid(
                        "camera.near",
                        format!("must be finite and >= 0, got {near}"),
                    ));
                }
                if far.is_infinite() {
                    return Err(SceneError::invalid(
                        "camera.far",
                        "must be finite for an orthographic camera",
                    ));
                }
            }
        }
        if far.is_nan() || far <= near {
            return Err(SceneError::invalid(
                "camera.far",
                format!("must be > near ({near}), got {far}"),
            ));
        }
        Ok(())
    }
}

/// Right-handed perspective with the far plane at infinity, GL depth range (z_ndc in [−1, 1]):
/// `z_ndc = 1 + 2·near / z_view`, so the near plane maps to −1 and infinity to +1. glam offers
/// this only for Vulkan/DirectX depth conventions.
fn perspective_infinite_gl(fov_y: f64, aspect: f64, near: f64) -> DMat4 {
    let f = 1.0 / (fov_y * 0.5).tan();
    DMat4::from_cols_array(&[
        f / aspect,
        0.0,
        0.0,
        0.0, //
        0.0,
        f,
        0.0,
        0.0, //
        0.0,
        0.0,
        -1.0,
        -1.0, //
        0.0,
        0.0,
        -2.0 * near,
        0.0,
    ])
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::DVec4;

    #[test]
    fn perspective_maps_near_and_far_to_gl_depth_range() {
        let cam = Camera::perspective(DVec3::ZERO, -DVec3::Z, 60.0, 0.5, 50.0);
        let p = cam.projection_matrix(16.0 / 9.0);
        let near = p * DVec4::new(0.0, 0.0, -0.5, 1.0);
        let far = p * DVec4::new(0.0, 0.0, -50.0, 1.0);
        assert!((near.z / near.w + 1.0).abs() < 1e-12);
        assert!((far.z / far.w - 1.0).abs() < 1e-12);
    }

    #[test]
    fn infinite_far_maps_near_to_minus_one() {
        let cam = Camera::perspective(DVec3::ZERO, -DVec3::Z, 60.0, 0.01, f64::INFINITY);
        let p = cam.projection_matrix(1.0);
        let near = p * DVec4::new(0.0, 0.0, -0.01, 1.0);
        let far = p * DVec4::new(0.0, 0.0, -1e12, 1.0);
        assert!((near.z / near.w + 1.0).abs() < 1e-9);
        assert!(far.z / far.w < 1.0 && far.z / far.w > 0.99);
    }

    #[test]
    fn validation_names_the_field() {
        let mut cam = Camera {
            projection: Projection::Perspective {
                fov_y_deg: 60.0,
                near: 0.0,
                far: 10.0,
            },
            ..Camera::default()
        };
        let err = cam.validate().unwrap_err().to_string();
        assert!(err.contains("camera.near"), "{err}");
        for (fov, ok) in [
            (MIN_FOV_Y_DEG, true),
            (2e-5, false),
            (1e-300, false),
            (180.0, false),
        ] {
            let cam = Camera::perspective(DVec3::ZERO, -DVec3::Z, fov, 0.1, 10.0);
            let result = cam.validate();
            assert_eq!(result.is_ok(), ok, "{fov}: {result:?}");
            if let Err(e) = result {
                assert!(e.to_string().contains("camera.fov_y_deg"), "{e}");
            }
        }
        cam.position = DVec3::new(f64::NAN, 0.0, 0.0);
        assert!(cam
            .validate()
            .unwrap_err()
            .to_string()
            .contains("camera.position"));
    }
}
