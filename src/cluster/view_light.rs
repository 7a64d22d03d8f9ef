//! [`GpuLight`]: a light as the assignment and the shaders see it, in view space. Below both
//! the assignment and the texture packing, which take it as input.

use glam::{DMat4, DVec3, Vec3};

use crate::scene::direction::unit;
use crate::scene::{Light, LightKind};

/// Largest radius a light near the eye is given on the GPU. The shader divides by the radius,
/// and past about 10¹⁹ times the distance to a surface the quotient's square underflows f32 and
/// the light vanishes (a radius of 10²⁰ lit nothing); capped here, the window term
/// `1 − (d/r)⁴` still differs from 1 by under 10⁻¹² anywhere within 1 000 km of the light. A
/// light farther from the eye than that keeps [`FAR_RADIUS_FACTOR`] times its distance: capped
/// at 10¹² it would lie outside its own sphere and light nothing in view.
pub const MAX_EFFECTIVE_RADIUS: f32 = 1e12;

/// A light's radius is capped at no less than this many times its distance from the eye: the
/// window term then differs from 1 by under 10⁻²⁴ at the eye, and `d/r` stays far above what
/// underflows f32 for anything in view.
pub const FAR_RADIUS_FACTOR: f32 = 1e6;

/// A light as the shader sees it: view space, radiance premultiplied, spot terms precomputed.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct GpuLight {
    /// View-space position (the camera subtracted in `f64` first).
    pub position: Vec3,
    /// Radius of influence.
    pub radius: f32,
    /// Radius the light is culled with (CPU only, never uploaded): `radius` unless a light
    /// cut-off trims the faint tail (`RenderOptions::light_cutoff`), trading error for time.
    pub cull_radius: f32,
    /// `color × intensity`.
    pub radiance: Vec3,
    /// Spot smoothstep scale (0 for point lights).
    pub spot_scale: f32,
    /// Unit view-space spot axis (zero for point lights).
    pub direction: Vec3,
    /// Spot smoothstep offset (1 for point lights).
    pub spot_offset: f32,
    /// Spot half-angles in degrees (outer, inner); `(180, 180)` for point lights. Only the
    /// Rgba8 encoding stores these.
    pub cone_deg: (f32, f32),
}

impl GpuLight {
    /// Converts a world-space light with the camera's view matrix (`f64`, so lights far from the
    /// origin keep their precision relative to the camera).
    pub fn from_light(light: &Light, view: &DMat4) -> GpuLight {
        let (spot_scale, spot_offset) = light.spot_scale_offset();
        let (direction, cone_deg) = match light.kind {
            LightKind::Point => (Vec3::ZERO, (180.0, 180.0)),
            LightKind::Spot {
                direction,
                inner_deg,
                outer_deg,
            } => (
                // Unit before and after the turn, so no length overflows (a validated light's
                // axis has a direction; zero stands for one that has not).
                unit(direction)
                    .and_then(|d| unit(view.transform_vector3(d)))
                    .unwrap_or(DVec3::ZERO)
                    .as_vec3(),
                (outer_deg as f32, inner_deg as f32),
            ),
        };
        let position = view.transform_point3(light.position).as_vec3();
        // The length is infinite for lights beyond about 10¹⁹ (f32 squares it), where `min`
        // then keeps the radius as it is.
        let cap = MAX_EFFECTIVE_RADIUS.max(position.length() * FAR_RADIUS_FACTOR);
        GpuLight {
            position,
            radius: light.radius.min(cap),
            cull_radius: light.radius.min(cap),
            radiance: light.radiance(),
            spot_scale,
            direction,
            spot_offset,
            cone_deg,
        }
    }

    /// Whether `other` holds the same bits in every field: what an assignment and the packed
    /// records are functions of (`==` would take `-0.0` for `0.0` and no NaN for itself).
    pub fn same_bits(&self, other: &GpuLight) -> bool {
        self.bits() == other.bits()
    }

    fn bits(&self) -> [u32; 15] {
        let [px, py, pz] = self.position.to_array();
        let [rx, ry, rz] = self.radiance.to_array();
        let [dx, dy, dz] = self.direction.to_array();
        let (outer, inner) = self.cone_deg;
        [
            px,
            py,
            pz,
            self.radius,
            self.cull_radius,
            rx,
            ry,
            rz,
            self.spot_scale,
            dx,
            dy,
            dz,
            self.spot_offset,
            outer,
            inner,
        ]
        .map(f32::to_bits)
    }
}
