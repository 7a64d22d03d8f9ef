//! The camera: right-handed, looking down −Z in view space, with a perspective (vertical field
//! of view) or orthographic projection. Clip space follows GL conventions (z in [−1, 1]).

mod placed;

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

/// How far from orthonormal the rotation of [`Camera::from_view_matrix`]'s matrix may be
/// (largest entry of `RᵀR − I`): `f32` matrices a game builds are off by about 10⁻⁷.
pub const VIEW_RIGID_TOLERANCE: f64 = 1e-4;

/// How far from 1 the last entry of [`Camera::from_view_matrix`]'s matrix may be (an `f32`
/// rounding), and from 0 the rest of its last row (exactly 0 in an inverted transform).
const LAST_ROW_W_ROUNDING: f64 = 1e-6;
const LAST_ROW_XYZ_ROUNDING: f64 = 1e-12;

/// A perspective far plane this many near planes away or more is treated as infinite.
pub const FAR_AS_INFINITE: f64 = 1e20;

/// Relative error of a clip-space depth the GPU computes in `f32`: eight roundings of 2⁻²⁴
/// (the projection's terms, the view position, the clip test) — a bound, not a measurement.
const FAR_ROUNDING: f64 = 1.0 / (1u64 << 21) as f64;

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

    /// The camera a game's own view matrix (world → view, right-handed, looking down −Z, as
    /// [`Camera::view_matrix`] gives) describes, with `projection`: an engine keeps its camera
    /// as a transform, not as a look-at. The matrix must be rigid (a rotation and a
    /// translation, to within `f32` rounding: its last row (0, 0, 0, 1) but for 10⁻⁶ in w and
    /// 10⁻¹² in x, y and z, which it is then taken as, and its rotation orthonormal within
    /// 10⁻⁴): one that scales, shears, mirrors or projects is refused, naming `camera.view`,
    /// since the light assignment works in its view space.
    pub fn from_view_matrix(view: DMat4, projection: Projection) -> Result<Camera, SceneError> {
        let invalid = |reason: String| SceneError::invalid("camera.view", reason);
        if !view.is_finite() {
            return Err(invalid("must be finite".into()));
        }
        // An inverted transform's last row comes out a rounding off in w: 0.9999999999999999
        // in f64 for one random camera in sixteen, 1.0000001 in f32 (x, y and z stay 0; one
        // of 10⁻⁴ would put a point 10⁴ away at half its depth).
        let bottom = view.row(3);
        let off = (bottom - glam::DVec4::W).abs();
        if off.truncate().max_element() > LAST_ROW_XYZ_ROUNDING || off.w > LAST_ROW_W_ROUNDING {
            return Err(invalid(format!(
                "must be rigid: its last row is {bottom:?}, not (0, 0, 0, 1) (a projection \
                 goes in the camera's projection)"
            )));
        }
        let mut view = view;
        for (column, w) in [
            (&mut view.x_axis, 0.0),
            (&mut view.y_axis, 0.0),
            (&mut view.z_axis, 0.0),
            (&mut view.w_axis, 1.0),
        ] {
            column.w = w;
        }
        let rotation = glam::DMat3::from_mat4(view);
        // f32 rounding of a game's matrix leaves errors near 1e-7; a scale or shear leaves more.
        let gram = rotation.transpose() * rotation;
        let off = (gram - glam::DMat3::IDENTITY).to_cols_array();
        let worst = off.iter().fold(0.0_f64, |m, v| m.max(v.abs()));
        if worst > VIEW_RIGID_TOLERANCE {
            return Err(invalid(format!(
                "must be rigid (a rotation and a translation): its 3 × 3 part is off \
                 orthonormal by {worst:.2e}, past {VIEW_RIGID_TOLERANCE:e} (a scale or a shear; \
                 a rotation built up from many small ones drifts: renormalize it, e.g. through \
                 a normalized quaternion)"
            )));
        }
        if rotation.determinant() < 0.0 {
            return Err(invalid(
                "mirrors (its determinant is negative): the view space is right-handed".into(),
            ));
        }
        let world_from_view = view.inverse();
        let position = world_from_view.w_axis.truncate();
        let camera = Camera {
            position,
            target: position - world_from_view.z_axis.truncate(),
            up: world_from_view.y_axis.truncate(),
            projection,
        };
        camera.validate()?;
        Ok(camera)
    }

    /// World → view transform (right-handed, looking down −Z).
    pub fn view_matrix(&self) -> DMat4 {
        glam::dcamera::rh::view::look_at_mat4(self.position, self.target, self.up_direction())
    }

    /// [`Camera::view_matrix`] without its translation, for positions already relative to the
    /// camera (formed in f64, exact for scenes far from the origin).
    pub(crate) fn view_rotation(&self) -> DMat4 {
        let forward = self.target - self.position;
        glam::dcamera::rh::view::look_at_mat4(DVec3::ZERO, forward, self.up_direction())
    }

    /// `up` scaled to a largest component of 1: any finite non-zero length gives a direction
    /// (the view maths squares it, which overflowed past 1e154 and underflowed below 1e-154).
    fn up_direction(&self) -> DVec3 {
        self.up / self.up.abs().max_element()
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

    /// The view distances between which the GPU's `f32` projection clips at the far plane:
    /// rounding moves that plane by up to about 2⁻²² · far / near of its distance, and past
    /// 2²² (4·10⁶) near planes it may clip nothing (docs/precision.md).
    /// Lights are culled against the farther bound, proxies kept inside the nearer one.
    pub fn far_clip_range(&self) -> (f64, f64) {
        match self.projection {
            Projection::Perspective { near, far, .. } => {
                if far.is_infinite() || far / near > FAR_AS_INFINITE {
                    return (f64::INFINITY, f64::INFINITY);
                }
                let spread = FAR_ROUNDING * far / (2.0 * near);
                let farthest = if spread < 1.0 {
                    far / (1.0 - spread)
                } else {
                    f64::INFINITY
                };
                (far / (1.0 + spread), farthest)
            }
            Projection::Orthographic { near, far, .. } => {
                let spread = FAR_ROUNDING * (far.abs() + near.abs());
                (far - spread, far + spread)
            }
        }
    }

    /// Whether a finite far plane was asked for that the GPU's `f32` projection cannot clip
    /// at ([`Camera::far_clip_range`] unbounded): geometry past it is drawn.
    pub fn has_unclipped_far(&self) -> bool {
        self.near_far().1.is_finite() && self.far_clip_range().1.is_infinite()
    }

    /// How far apart in depth two surfaces `distance` from the eye must be for the depth
    /// test of a `bits`-bit depth buffer to tell them apart: one step, `distance² / (near ·
    /// 2^bits)` in perspective (any far plane), the depth range over `2^bits` in orthographic
    /// (24 bits: as `f32` window depth, which has as many). `docs/precision.md` gives figures.
    pub(crate) fn depth_step_at(&self, distance: f64, bits: u32) -> f64 {
        let steps = 2f64.powi(bits.min(32) as i32);
        match self.projection {
            Projection::Perspective { near, .. } => distance * distance / (near * steps),
            Projection::Orthographic { near, far, .. } => (far - near) / steps,
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
        // `up` is a direction: its length is not a coordinate.
        for (name, v) in [
            ("camera.position", self.position),
            ("camera.target", self.target),
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
        // Unit vectors first: the squared lengths of raw ones can overflow or underflow.
        if forward
            .normalize()
            .cross(self.up_direction().normalize())
            .length_squared()
            <= 1e-24
        {
            return Err(SceneError::invalid(
                "camera.up",
                "is parallel to the view direction",
            ));
        }
        let (near, far) = self.near_far();
        // A near plane past every coordinate a scene may hold sees nothing (and was blamed on
        // `camera.far`, "must be > near").
        if near > MAX_CAMERA_COORD {
            return Err(SceneError::invalid(
                "camera.near",
                format!(
                    "must be at most {MAX_CAMERA_COORD:e} (the coordinate limit), got {near:e}"
                ),
            ));
        }
        match self.projection {
            Projection::Perspective { fov_y_deg, .. } => {
                if !(MIN_FOV_Y_DEG..180.0).contains(&fov_y_deg) {
                    return Err(SceneError::invalid(
                        "camera.fov_y_deg",
                        format!("must be in [{MIN_FOV_Y_DEG:e}, 180), got {fov_y_deg:?}"),
                    ));
                }
                if !(near > 0.0 && near.is_finite()) {
                    return Err(SceneError::invalid(
                        "camera.near",
                        format!("must be finite and > 0 for a perspective camera, got {near:?}"),
                    ));
                }
            }
            Projection::Orthographic { height, .. } => {
                if !(height >= MIN_ORTHO_HEIGHT && height.is_finite()) {
                    return Err(SceneError::invalid(
                        "camera.height",
                        format!(
                            "must be finite and >= {MIN_ORTHO_HEIGHT:e} (smaller views fall \
                             between f32 view-space values), got {height:?}"
                        ),
                    ));
                }
                // Wider than the coordinates a scene may span: its f32 projection scale was 0
                // and drew nothing.
                if height > 2.0 * MAX_CAMERA_COORD {
                    return Err(SceneError::invalid(
                        "camera.height",
                        format!(
                            "must be at most {:e} (twice the coordinate limit), got {height:e}",
                            2.0 * MAX_CAMERA_COORD
                        ),
                    ));
                }
                if !(near >= 0.0 && near.is_finite()) {
                    return Err(SceneError::invalid(
                        "camera.near",
                        format!("must be finite and >= 0, got {near:?}"),
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
                format!("must be > near ({near:?}), got {far:?}"),
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

    /// Where the `f32` matrix itself puts the far plane (`m32 / (m22 + 1)`) lies inside
    /// `far_clip_range`, whose upper end is infinite once `m22` rounds to −1.
    #[test]
    fn the_far_clip_range_holds_the_f32_projections_far_plane() {
        for exponent in 1..=90 {
            let ratio = 10f64.powf(f64::from(exponent) / 10.0);
            for far in [1e-3, 0.7, 10.0, 3e4] {
                let near = far / ratio;
                let cam = Camera::perspective(DVec3::ZERO, -DVec3::Z, 60.0, near, far);
                let p = cam.projection_matrix(1.5).as_mat4();
                let (m22, m32) = (f64::from(p.z_axis.z), f64::from(p.w_axis.z));
                let (low, high) = cam.far_clip_range();
                assert!(low <= far && far <= high, "{near:e}..{far:e}");
                if m22 + 1.0 >= 0.0 {
                    assert_eq!(high, f64::INFINITY, "{near:e}..{far:e}: no far plane");
                } else {
                    let placed = m32 / (m22 + 1.0);
                    assert!(
                        low <= placed && placed <= high,
                        "{near:e}..{far:e}: {placed:e}"
                    );
                }
            }
        }
        let infinite = Camera::perspective(DVec3::ZERO, -DVec3::Z, 60.0, 0.1, f64::INFINITY);
        assert_eq!(infinite.far_clip_range(), (f64::INFINITY, f64::INFINITY));
        // Orthographic depth is linear: the range is a few f32 steps of its largest distance.
        let mut ortho = Camera::perspective(DVec3::ZERO, -DVec3::Z, 60.0, 0.1, 1.0);
        for (near, far) in [(0.0, 100.0), (-5.0, 1e7), (1e6, 1e6 + 1.0)] {
            ortho.projection = Projection::Orthographic {
                height: 2.0,
                near,
                far,
            };
            let (low, high) = ortho.far_clip_range();
            let spread = 1e-5 * (f64::abs(far) + f64::abs(near));
            assert!(low < far && far < high, "{near}..{far}");
            assert!(far - low <= spread && high - far <= spread, "{near}..{far}");
        }
    }

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
    fn a_rigid_view_matrix_gives_the_camera_that_makes_it() {
        let projection = Camera::default().projection;
        let poses = [
            (glam::DQuat::IDENTITY, DVec3::ZERO),
            (
                glam::DQuat::from_rotation_x(-1.57),
                DVec3::new(3.0, 40.0, -2.0),
            ),
            (
                glam::DQuat::from_euler(glam::EulerRot::YXZ, 2.5, -0.7, 0.4),
                DVec3::new(-1e6, 2.0, 5e5),
            ),
            (
                glam::DQuat::from_rotation_z(3.1),
                DVec3::new(0.5, -0.25, 8.0),
            ),
        ];
        for (rotation, position) in poses {
            let view = DMat4::from_rotation_translation(rotation, position).inverse();
            let camera = Camera::from_view_matrix(view, projection).unwrap();
            let back = camera.view_matrix();
            let scale = 1.0 + position.abs().max_element();
            for (a, b) in back.to_cols_array().iter().zip(view.to_cols_array()) {
                assert!((a - b).abs() <= 1e-9 * scale, "{back:?} against {view:?}");
            }
            // A game's f32 matrix is rigid to its rounding, and accepted.
            let rounded = DMat4::from_cols_array(&view.to_cols_array().map(|v| v as f32 as f64));
            assert!(Camera::from_view_matrix(rounded, projection).is_ok());
        }
    }

    /// A camera's world transform inverted, in f64 or in f32, has a last row a rounding off
    /// (0, 0, 0, 1): accepted, as the same camera. Before, one pose in sixteen was refused.
    #[test]
    fn an_inverted_camera_transform_is_accepted_whatever_its_rounding() {
        use rand::{Rng, SeedableRng};
        let projection = Camera::default().projection;
        let mut rng = rand_pcg::Pcg64Mcg::seed_from_u64(7);
        let mut off_in_last_row = 0;
        for _ in 0..1000 {
            let axis = glam::Vec3::new(rng.random(), rng.random(), rng.random()) - 0.5;
            let rotation = glam::Quat::from_axis_angle(axis.normalize(), rng.random::<f32>() * 6.3);
            let position = glam::Vec3::new(rng.random(), rng.random(), rng.random()) * 20.0 - 10.0;
            let world = glam::Mat4::from_rotation_translation(rotation, position);
            for view in [world.as_dmat4().inverse(), world.inverse().as_dmat4()] {
                off_in_last_row += usize::from(view.row(3) != glam::DVec4::W);
                let camera = Camera::from_view_matrix(view, projection).unwrap();
                let back = camera.view_matrix();
                for (a, b) in back
                    .to_cols_array()
                    .iter()
                    .zip(view.to_cols_array())
                    .take(15)
                {
                    assert!((a - b).abs() <= 1e-5, "{back:?} against {view:?}");
                }
            }
        }
        assert!(off_in_last_row > 0, "no pose had a rounded last row");
    }

    #[test]
    fn a_view_matrix_that_is_not_rigid_is_refused_naming_it() {
        let projection = Camera::default().projection;
        let view = DMat4::from_rotation_y(0.3) * DMat4::from_translation(DVec3::new(1.0, 2.0, 3.0));
        let mut nan = view;
        nan.w_axis.x = f64::NAN;
        // A trace of perspective: a point 10⁴ away would be drawn at half its depth.
        let mut near_projective = view;
        near_projective.z_axis.w = -1e-4;
        let refused = [
            (view * DMat4::from_scale(DVec3::splat(1.01)), "rigid"),
            (
                DMat4::from_scale(DVec3::new(1.0, 1.0, -1.0)) * view,
                "mirrors",
            ),
            (Camera::default().projection_matrix(1.5) * view, "last row"),
            (near_projective, "last row"),
            (nan, "finite"),
        ];
        for (matrix, why) in refused {
            let err = Camera::from_view_matrix(matrix, projection)
                .unwrap_err()
                .to_string();
            assert!(err.contains("camera.view") && err.contains(why), "{err}");
        }
        // The projection is still checked.
        let bad = Projection::Perspective {
            fov_y_deg: 60.0,
            near: 0.0,
            far: 1.0,
        };
        let err = Camera::from_view_matrix(view, bad).unwrap_err().to_string();
        assert!(err.contains("camera.near"), "{err}");
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
        // Numbers in messages are short: -1e308 once printed as 309 digits.
        let cam = Camera {
            projection: Projection::Orthographic {
                height: 2.0,
                near: -1e308,
                far: 10.0,
            },
            ..Camera::default()
        };
        let err = cam.validate().unwrap_err().to_string();
        assert!(
            err.contains("camera.near") && err.contains("got -1e308"),
            "{err}"
        );
    }
}
