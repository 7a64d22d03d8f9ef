//! A spot light's cone as the assignment tests it against cells (see [`super::cells`]): the
//! bounding sphere of the part of the light's sphere inside the cone, and a square-root-free
//! cone-vs-cell-sphere test that trims each row of cells to those the cone may touch.

use super::pack::GpuLight;

/// A spot light's cone, for the cone-vs-cell test (Wronski's "cull that cone"), and the
/// bounding sphere of the part of the light's sphere inside the cone.
pub(crate) struct Cone {
    apex: glam::DVec3,
    axis: glam::DVec3,
    /// cos² and sin of the (padded) outer half-angle.
    cos_sq: f64,
    sin: f64,
    /// The light's (padded) radius.
    range: f64,
    /// Bounding sphere (centre, radius) of the spherical sector the light reaches.
    pub bound: (glam::DVec3, f64),
}

impl Cone {
    /// The cone of a spot light of (padded) radius `range`; `None` for point lights and cones
    /// too wide to be worth testing.
    pub fn of(light: &GpuLight, range: f64) -> Option<Cone> {
        // 1 − cos(outer) = offset / scale (see `Light::spot_scale_offset`): no trigonometry
        // per light. Cones of 89° and wider are not worth testing.
        if light.spot_scale == 0.0 || light.direction.length_squared() == 0.0 {
            return None;
        }
        let cos_outer = 1.0 - light.spot_offset as f64 / light.spot_scale as f64;
        // Pad the angle a little: the shader evaluates the cone edge in f32.
        let cos = cos_outer - 2e-4;
        if cos.is_nan() || cos < 0.0175 {
            return None;
        }
        let sin = (1.0 - cos * cos).max(0.0).sqrt();
        let apex = light.position.as_dvec3();
        let axis = light.direction.as_dvec3().normalize();
        // The sector {apex + t·u : u·axis ≥ cos, 0 ≤ t ≤ range}. Up to 45°, the sphere through
        // the apex and the rim circle (centre range / (2 cos) along the axis) holds it; wider,
        // the sphere on the rim circle (centre range·cos along the axis, radius range·sin)
        // does, the apex and the cap's tip lying inside it.
        let (along, radius) = if cos >= std::f64::consts::FRAC_1_SQRT_2 {
            let h = range / (2.0 * cos);
            (h, h)
        } else {
            (range * cos, range * sin)
        };
        Some(Cone {
            apex,
            axis,
            cos_sq: cos * cos,
            sin,
            range,
            bound: (apex + axis * along, radius),
        })
    }

    /// Emits the part of the run `[start, start + len)` the cone may touch (`sphere_of(i)`:
    /// the bounding sphere of its cell `start + i`): from the first
    /// cell that may touch it to the last. The cone is convex, so along a row the cells it
    /// touches are (nearly) one interval; a gap inside would only be assigned too, which is
    /// conservative. Scanning in from both ends tests few cells where the cone fills the row.
    pub fn emit_runs(
        &self,
        sphere_of: impl Fn(u32) -> [f64; 4],
        start: u32,
        len: u32,
        emit: &mut impl FnMut(u32, u32),
    ) {
        let Some(first) = (0..len).find(|&i| self.may_touch(&sphere_of(i))) else {
            return;
        };
        let last = (first + 1..len)
            .rev()
            .find(|&i| self.may_touch(&sphere_of(i)))
            .unwrap_or(first);
        emit(start + first, last - first + 1);
    }

    /// False only when the cell's bounding sphere is certainly outside the cone (up to the
    /// light's range).
    /// A cell reaching infinity (radius +∞) passes every comparison below by IEEE rules.
    fn may_touch(&self, &[x, y, z, radius]: &[f64; 4]) -> bool {
        let v = glam::DVec3::new(x, y, z) - self.apex;
        let v1 = v.dot(self.axis);
        if v1 > radius + self.range || v1 < -radius {
            return false;
        }
        // Distance of the sphere's centre outside the cone: cos·√(|v|² − v1²) − v1·sin; the
        // cell is outside when that exceeds its radius. Squared (both sides are then ≥ 0) so
        // the hot loop has no square root.
        let bound = radius + v1 * self.sin;
        bound >= 0.0 && self.cos_sq * (v.length_squared() - v1 * v1) <= bound * bound
    }
}
