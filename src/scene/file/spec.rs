//! The scene file's JSON shape (serde types, unknown fields refused) and what each part
//! becomes in a [`Scene`](super::super::Scene): a camera, a light, a motion, a transform.

use std::path::PathBuf;

use glam::{DMat4, DVec3, Vec3};
use serde::Deserialize;

use super::super::camera::Projection;
use super::super::motion::{Bob, Flicker, Motion, Orbit, OrbitAbout, Sweep, Wander};
use super::super::{Camera, DirectionalLight, Light, LightKind, SceneError};
use super::map_only::map_only;

map_only!(SceneFile, "a scene: a JSON object");
map_only!(CameraSpec, "a camera object");
map_only!(ObjectSpec, "an object");
map_only!(TransformSpec, "a transform object");
map_only!(LightSpec, "a light object");
map_only!(DirectionalSpec, "a directional light object");
map_only!(MotionSpec, "a motion object");
map_only!(OrbitSpec, "an orbit object");
map_only!(BobSpec, "a bob object");
map_only!(WanderSpec, "a wander object");
map_only!(FlickerSpec, "a flicker object");
map_only!(SweepSpec, "a sweep object");
map_only!(RandomLightsSpec, "a random lights object");

#[derive(Deserialize)]
#[serde(deny_unknown_fields, remote = "Self")]
pub(super) struct SceneFile {
    pub(super) camera: Option<CameraSpec>,
    #[serde(default)]
    pub(super) objects: Vec<ObjectSpec>,
    pub(super) ambient: Option<[f64; 3]>,
    #[serde(default)]
    pub(super) lights: Vec<LightSpec>,
    #[serde(default)]
    pub(super) directional_lights: Vec<DirectionalSpec>,
    pub(super) random_lights: Option<RandomLightsSpec>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields, remote = "Self")]
pub(super) struct CameraSpec {
    position: [f64; 3],
    target: [f64; 3],
    up: Option<[f64; 3]>,
    #[serde(default)]
    projection: ProjectionKind,
    fov_y_deg: Option<f64>,
    height: Option<f64>,
    near: Option<f64>,
    far: Option<f64>,
}

#[derive(Deserialize, Default)]
#[serde(rename_all = "snake_case")]
enum ProjectionKind {
    #[default]
    Perspective,
    Orthographic,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields, remote = "Self")]
pub(super) struct ObjectSpec {
    pub(super) builtin: Option<String>,
    pub(super) obj: Option<PathBuf>,
    /// A `.gltf` or `.glb` file: its meshes, materials and lights (placed by `transform`),
    /// and its camera when it is the file's only object and the file names no camera.
    pub(super) gltf: Option<PathBuf>,
    pub(super) texture: Option<PathBuf>,
    pub(super) transform: Option<TransformSpec>,
    pub(super) color: Option<[f64; 3]>,
    /// With `roughness`: the object's materials become metallic-roughness (glTF BRDF).
    pub(super) metallic: Option<f64>,
    pub(super) roughness: Option<f64>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields, remote = "Self")]
pub(super) struct TransformSpec {
    #[serde(default)]
    translate: [f64; 3],
    #[serde(default)]
    rotate_y_deg: f64,
    scale: Option<ScaleSpec>,
}

#[derive(Deserialize)]
#[serde(untagged, expecting = "expected a number or three numbers [x, y, z]")]
enum ScaleSpec {
    Uniform(f64),
    PerAxis([f64; 3]),
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields, remote = "Self")]
pub(super) struct LightSpec {
    pub(super) kind: LightKindSpec,
    position: [f64; 3],
    radius: f64,
    color: [f64; 3],
    #[serde(default = "one")]
    intensity: f64,
    direction: Option<[f64; 3]>,
    inner_deg: Option<f64>,
    outer_deg: Option<f64>,
    pub(super) motion: Option<MotionSpec>,
}

/// A sun: `direction` is the way the light travels (from it towards the scene).
#[derive(Deserialize)]
#[serde(deny_unknown_fields, remote = "Self")]
pub(super) struct DirectionalSpec {
    direction: [f64; 3],
    color: [f64; 3],
    #[serde(default = "one")]
    intensity: f64,
}

fn one() -> f64 {
    1.0
}

fn up() -> [f64; 3] {
    [0.0, 1.0, 0.0]
}

/// `"motion"` of a light or a random set (see [`super::super::motion`]).
#[derive(Deserialize)]
#[serde(deny_unknown_fields, remote = "Self")]
pub(super) struct MotionSpec {
    orbit: Option<OrbitSpec>,
    bob: Option<BobSpec>,
    wander: Option<WanderSpec>,
    flicker: Option<FlickerSpec>,
    sweep: Option<SweepSpec>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields, remote = "Self")]
struct OrbitSpec {
    center: Option<[f64; 3]>,
    radius: Option<f64>,
    #[serde(default = "up")]
    axis: [f64; 3],
    period_s: f64,
    phase_deg: Option<f64>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields, remote = "Self")]
struct BobSpec {
    amplitude: [f64; 3],
    period_s: f64,
    #[serde(default)]
    phase_deg: f64,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields, remote = "Self")]
struct WanderSpec {
    radius: f64,
    period_s: f64,
    #[serde(default)]
    seed: u64,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields, remote = "Self")]
struct FlickerSpec {
    amount: f64,
    rate_hz: f64,
    #[serde(default)]
    seed: u64,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields, remote = "Self")]
struct SweepSpec {
    axis: [f64; 3],
    angle_deg: f64,
    period_s: f64,
    #[serde(default)]
    phase_deg: f64,
}

#[derive(Deserialize)]
#[serde(rename_all = "snake_case")]
pub(super) enum LightKindSpec {
    Point,
    Spot,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields, remote = "Self")]
pub(super) struct RandomLightsSpec {
    pub(super) count: usize,
    #[serde(default)]
    pub(super) seed: u64,
    pub(super) motion: Option<MotionSpec>,
}

/// `v` as the `f32` a scene keeps it in, or an error naming `field` where it is finite but
/// past `f32`'s range (read straight into an `f32` it would become infinite, and an error
/// would say `inf` of a number the file wrote finite).
pub(super) fn narrow(field: &str, v: f64) -> Result<f32, SceneError> {
    if v.is_finite() && v.abs() > f64::from(f32::MAX) {
        return Err(SceneError::invalid(
            field,
            format!(
                "{v:e} is past the largest number a scene keeps ({:e})",
                f32::MAX
            ),
        ));
    }
    Ok(v as f32)
}

/// [`narrow`] of each of three values (`field[i]` names the one at fault).
pub(super) fn narrow3(field: &str, v: [f64; 3]) -> Result<Vec3, SceneError> {
    let mut out = [0.0; 3];
    for (i, (o, v)) in out.iter_mut().zip(v).enumerate() {
        *o = narrow(&format!("{field}[{i}]"), v)?;
    }
    Ok(Vec3::from(out))
}

impl TransformSpec {
    pub(super) fn matrix(&self, field: &str) -> Result<DMat4, SceneError> {
        let scale = match self.scale {
            None => DVec3::ONE,
            Some(ScaleSpec::Uniform(s)) => DVec3::splat(s),
            Some(ScaleSpec::PerAxis(s)) => DVec3::from(s),
        };
        if !scale.is_finite() || scale.cmpeq(DVec3::ZERO).any() {
            return Err(SceneError::invalid(
                format!("{field}.transform.scale"),
                format!(
                    "must be finite and non-zero, got {}",
                    super::super::short3(scale)
                ),
            ));
        }
        Ok(DMat4::from_translation(DVec3::from(self.translate))
            * DMat4::from_rotation_y(self.rotate_y_deg.to_radians())
            * DMat4::from_scale(scale))
    }
}

impl MotionSpec {
    pub(super) fn to_motion(&self, field: &str, is_spot: bool) -> Result<Motion, SceneError> {
        let orbit = match &self.orbit {
            None => None,
            Some(o) => Some(Orbit {
                about: match (o.center, o.radius) {
                    // The turn starts where the light is placed: a phase would be ignored.
                    (Some(_), None) if o.phase_deg.is_some() => {
                        return Err(SceneError::invalid(
                            format!("{field}.orbit.phase_deg"),
                            "an orbit about a `center` starts where the light is placed; a \
                             start angle is for an orbit by `radius`",
                        ))
                    }
                    (Some(c), None) => OrbitAbout::Point(DVec3::from(c)),
                    (None, Some(r)) => OrbitAbout::Radius(r),
                    _ => {
                        return Err(SceneError::invalid(
                            format!("{field}.orbit"),
                            "needs exactly one of `center` (go round a point) or `radius` \
                             (a circle through the light)",
                        ))
                    }
                },
                axis: DVec3::from(o.axis),
                period_s: o.period_s,
                phase_deg: o.phase_deg.unwrap_or(0.0),
            }),
        };
        let motion = Motion {
            orbit,
            bob: self.bob.as_ref().map(|b| Bob {
                amplitude: DVec3::from(b.amplitude),
                period_s: b.period_s,
                phase_deg: b.phase_deg,
            }),
            wander: self.wander.as_ref().map(|w| Wander {
                radius: w.radius,
                period_s: w.period_s,
                seed: w.seed,
            }),
            flicker: self
                .flicker
                .as_ref()
                .map(|f| {
                    Ok::<_, SceneError>(Flicker {
                        amount: narrow(&format!("{field}.flicker.amount"), f.amount)?,
                        rate_hz: f.rate_hz,
                        seed: f.seed,
                    })
                })
                .transpose()?,
            sweep: self.sweep.as_ref().map(|s| Sweep {
                axis: DVec3::from(s.axis),
                angle_deg: s.angle_deg,
                period_s: s.period_s,
                phase_deg: s.phase_deg,
            }),
        };
        motion.validate(field, is_spot)?;
        Ok(motion)
    }
}

impl CameraSpec {
    pub(super) fn to_camera(&self) -> Result<Camera, SceneError> {
        // The other projection's field would be ignored without a word, as a light's cone on
        // a point light would: an error, as that is.
        let (stray, wanted, article) = match self.projection {
            ProjectionKind::Perspective => (self.height.map(|_| "height"), "orthographic", "an"),
            ProjectionKind::Orthographic => {
                (self.fov_y_deg.map(|_| "fov_y_deg"), "perspective", "a")
            }
        };
        if let Some(name) = stray {
            return Err(SceneError::invalid(
                format!("camera.{name}"),
                format!("only {article} {wanted} camera has one; use \"projection\": \"{wanted}\""),
            ));
        }
        let near = self.near.unwrap_or(0.1);
        let far = self.far.unwrap_or(1000.0);
        Ok(Camera {
            position: DVec3::from(self.position),
            target: DVec3::from(self.target),
            up: DVec3::from(self.up.unwrap_or([0.0, 1.0, 0.0])),
            projection: match self.projection {
                ProjectionKind::Perspective => Projection::Perspective {
                    fov_y_deg: self.fov_y_deg.unwrap_or(60.0),
                    near,
                    far,
                },
                ProjectionKind::Orthographic => Projection::Orthographic {
                    height: self.height.unwrap_or(10.0),
                    near,
                    far,
                },
            },
        })
    }
}

impl LightSpec {
    pub(super) fn to_light(&self, field: &str) -> Result<Light, SceneError> {
        let kind = match self.kind {
            LightKindSpec::Point => {
                for (name, present) in [
                    ("direction", self.direction.is_some()),
                    ("inner_deg", self.inner_deg.is_some()),
                    ("outer_deg", self.outer_deg.is_some()),
                ] {
                    if present {
                        return Err(SceneError::invalid(
                            format!("{field}.{name}"),
                            "only spot lights have a cone; use \"kind\": \"spot\"",
                        ));
                    }
                }
                LightKind::Point
            }
            LightKindSpec::Spot => {
                let need = |v: Option<f64>, name: &str| {
                    v.ok_or_else(|| {
                        SceneError::invalid(format!("{field}.{name}"), "required for a spot light")
                    })
                };
                LightKind::Spot {
                    direction: DVec3::from(self.direction.ok_or_else(|| {
                        SceneError::invalid(
                            format!("{field}.direction"),
                            "required for a spot light",
                        )
                    })?),
                    inner_deg: need(self.inner_deg, "inner_deg")?,
                    outer_deg: need(self.outer_deg, "outer_deg")?,
                }
            }
        };
        let light = Light {
            kind,
            position: DVec3::from(self.position),
            radius: narrow(&format!("{field}.radius"), self.radius)?,
            color: narrow3(&format!("{field}.color"), self.color)?,
            intensity: narrow(&format!("{field}.intensity"), self.intensity)?,
        };
        light.validate(field)?;
        Ok(light)
    }
}

impl DirectionalSpec {
    pub(super) fn to_light(&self, field: &str) -> Result<DirectionalLight, SceneError> {
        let color = narrow3(&format!("{field}.color"), self.color)?;
        let intensity = narrow(&format!("{field}.intensity"), self.intensity)?;
        let light = DirectionalLight::new(DVec3::from(self.direction), color, intensity);
        light.validate(field)?;
        Ok(light)
    }
}
