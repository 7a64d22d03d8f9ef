//! Which cells one light can touch: the per-light half of the assignment (`assign` does the
//! sorting). All in view space and `f64`.
//!
//! 1. The light's depth range `[d − r, d + r]` is clipped to `[near, far]` **before** anything
//!    is projected, so lights behind or around the camera never flip to the wrong side; a light
//!    whose range misses the frustum touches nothing.
//! 2. The clipped range gives the first and last (cascade, slice).
//! 3. Per cascade, the sphere's screen extent (box projection over the cascade's depth slab,
//!    tightened by the exact tangent bounds when the sphere is in front of the eye) gives a
//!    column and row range, whose ends are then tested against the tile planes.
//! 4. Spot lights start from the bounding sphere of their cone's reach instead of their whole
//!    sphere, and each cell is then tested cone-vs-cell (against the cell's bounding sphere).
//!
//! The cells come out as **runs**: a run is consecutive columns of one row of one slice, which
//! are consecutive cell numbers. Emitting runs instead of single cells lets the counting sort
//! touch its per-cell counters in tight loops and keeps the per-cell cost to a few instructions.
//!
//! The radius is padded by a relative 10⁻⁴ so a fragment that float rounding puts in the
//! neighbouring cell still finds every light that reaches it: the assignment is conservative.

use super::grid::{ClusterGrid, GridProjection};
use super::pack::GpuLight;

/// Relative padding of light radii (see the module docs).
const RADIUS_PAD: f64 = 1e-4;

/// Calls `emit(first_cell, cells)` for every run of consecutive cells `light` may touch, in
/// ascending cell order.
pub fn for_each_run(
    grid: &ClusterGrid,
    light: &GpuLight,
    camera_far: f64,
    emit: &mut impl FnMut(u32, u32),
) {
    let p = light.position.as_dvec3();
    let r0 = light.cull_radius as f64;
    if r0 <= 0.0 || !p.is_finite() {
        return;
    }
    let range = r0 + RADIUS_PAD * (p.z.abs() + r0);
    let cone = Cone::of(light, range);
    // The sphere every cell test starts from: the light's, or the tighter bound of a spot's
    // cone.
    let c = cone.as_ref().map_or(p, |cone| cone.bound.0);
    let r = cone.as_ref().map_or(range, |cone| cone.bound.1);
    let d = -c.z;
    // 1. Clip the depth range before projecting.
    let dmin = (d - r).max(grid.near);
    let dmax = (d + r).min(camera_far);
    if dmin > dmax {
        return;
    }
    let ((k0, s0), (k1, s1)) = grid.depth_range_to_slices(dmin, dmax);
    // Exact tangent slopes (view x/d and y/d) of the whole sphere, when it is in front of the
    // eye; computed once per light, intersected with each cascade's box bounds below.
    let tangents = (d > r).then(|| {
        let inv_den = 1.0 / (d * d - r * r);
        let tangent = |center: f64| {
            let root = r * (d * d + center * center - r * r).sqrt();
            ((center * d - root) * inv_den, (center * d + root) * inv_den)
        };
        [tangent(c.x), tangent(c.y)]
    });
    let sphere = Sphere { d, r, tangents };
    for k in k0..=k1 {
        let cascade = &grid.cascades[k as usize];
        let za = if k == 0 {
            dmin
        } else {
            dmin.max(cascade.z_near)
        };
        let zb = if k as usize == grid.cascades.len() - 1 {
            dmax
        } else {
            dmax.min(cascade.z_far)
        };
        // Reciprocal depths of the slab (0 for an infinite end: its slope is 0) for the box
        // projection; none needed when the slab is the whole sphere in front of the eye, whose
        // tangent bounds are then exact on their own (the common case: one call in three).
        let slab = (k0 != k1 || sphere.tangents.is_none())
            .then(|| (1.0 / za, if zb.is_infinite() { 0.0 } else { 1.0 / zb }));
        let x_range = axis_range(grid, &sphere, c.x, slab, 0, cascade.tiles_x);
        let Some((x0, x1)) = x_range else {
            continue;
        };
        let y_range = axis_range(grid, &sphere, c.y, slab, 1, cascade.tiles_y);
        let Some((y0, y1)) = y_range else {
            continue;
        };
        let sa = if k == k0 { s0 } else { 0 };
        let sb = if k == k1 { s1 } else { cascade.slices - 1 };
        let width = x1 - x0 + 1;
        for s in sa..=sb {
            for y in y0..=y1 {
                let row = cascade.first_cell + (s * cascade.tiles_y + y) * cascade.tiles_x;
                match &cone {
                    None => emit(row + x0, width),
                    Some(cone) => cone.emit_runs(grid, row + x0, width, emit),
                }
            }
        }
    }
}

/// The sphere the cell tests start from, in view space: its depth `d` (= −z), radius, and its
/// exact tangent slopes (x, y) when it lies in front of the eye.
struct Sphere {
    d: f64,
    r: f64,
    tangents: Option<[(f64, f64); 2]>,
}

/// Column (`axis` 0, centre `center` = view x) or row (`axis` 1, view y) range a sphere can
/// touch within the depth slab whose reciprocal depths are `slab = (1/za, 1/zb)`, or `None`.
/// Without `slab` (perspective only), the sphere's tangent bounds alone.
fn axis_range(
    grid: &ClusterGrid,
    sphere: &Sphere,
    center: f64,
    slab: Option<(f64, f64)>,
    axis: usize,
    tiles: u32,
) -> Option<(u32, u32)> {
    let (d, r) = (sphere.d, sphere.r);
    let scale = grid.ndc_scale[axis];
    let (vmin, vmax) = (center - r, center + r);
    let (lo, hi) = match (grid.projection, slab) {
        (GridProjection::Perspective { .. }, Some((inv_za, inv_zb))) => {
            // Box projection: extreme slopes of the sphere's bounding box within the slab.
            let mut lo = (vmin * inv_za).min(vmin * inv_zb);
            let mut hi = (vmax * inv_za).max(vmax * inv_zb);
            if let Some(tangents) = &sphere.tangents {
                let (tlo, thi) = tangents[axis];
                lo = lo.max(tlo);
                hi = hi.min(thi);
            }
            (lo * scale, hi * scale)
        }
        (GridProjection::Perspective { .. }, None) => {
            let (tlo, thi) = sphere.tangents.expect("no slab only with tangent bounds")[axis];
            (tlo * scale, thi * scale)
        }
        (GridProjection::Orthographic { .. }, _) => (vmin * scale, vmax * scale),
    };
    if lo.is_nan() || hi.is_nan() || hi < -1.0 || lo > 1.0 || lo > hi {
        return None;
    }
    let to_tile = |ndc: f64| (((ndc + 1.0) * 0.5 * tiles as f64).max(0.0) as u32).min(tiles - 1);
    let (mut t0, mut t1) = (to_tile(lo), to_tile(hi));
    // Tighten the ends against the tile planes where the tangent bounds do not apply (sphere
    // reaching behind the eye; with `d > r` they are exact already, as is orthographic).
    if let (GridProjection::Perspective { .. }, true) = (grid.projection, d <= r) {
        let tan = 1.0 / scale;
        // Signed distance of the centre to the plane through the eye at NDC `u`, positive on
        // the +u side.
        let dist = |u: f64| (center - u * tan * d) / (1.0 + u * u * tan * tan).sqrt();
        let ndc = |i: u32| -1.0 + 2.0 * i as f64 / tiles as f64;
        let touches = |i: u32| dist(ndc(i)) >= -r && dist(ndc(i + 1)) <= r;
        while t0 < t1 && !touches(t0) {
            t0 += 1;
        }
        while t1 > t0 && !touches(t1) {
            t1 -= 1;
        }
        if !touches(t0) {
            return None;
        }
    }
    Some((t0, t1))
}

/// A spot light's cone, for the cone-vs-cell test (Wronski's "cull that cone"), and the
/// bounding sphere of the part of the light's sphere inside the cone.
struct Cone {
    apex: glam::DVec3,
    axis: glam::DVec3,
    cos: f64,
    sin: f64,
    /// The light's (padded) radius.
    range: f64,
    /// Bounding sphere (centre, radius) of the spherical sector the light reaches.
    bound: (glam::DVec3, f64),
}

impl Cone {
    /// The cone of a spot light of (padded) radius `range`; `None` for point lights and cones
    /// too wide to be worth testing.
    fn of(light: &GpuLight, range: f64) -> Option<Cone> {
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
            cos,
            sin,
            range,
            bound: (apex + axis * along, radius),
        })
    }

    /// Emits the part of the run `[start, start + len)` the cone may touch: from the first
    /// cell that may touch it to the last. The cone is convex, so along a row the cells it
    /// touches are (nearly) one interval; a gap inside would only be assigned too, which is
    /// conservative. Scanning in from both ends tests few cells where the cone fills the row.
    fn emit_runs(&self, grid: &ClusterGrid, start: u32, len: u32, emit: &mut impl FnMut(u32, u32)) {
        let spheres = &grid.cell_spheres()[start as usize..(start + len) as usize];
        let Some(first) = spheres.iter().position(|s| self.may_touch(s)) else {
            return;
        };
        let last = spheres
            .iter()
            .rposition(|s| self.may_touch(s))
            .unwrap_or(first);
        emit(start + first as u32, (last - first + 1) as u32);
    }

    /// False only when the cell's bounding sphere is certainly outside the cone (up to the
    /// light's range).
    fn may_touch(&self, &[x, y, z, radius]: &[f64; 4]) -> bool {
        if radius.is_infinite() {
            return true;
        }
        let v = glam::DVec3::new(x, y, z) - self.apex;
        let v1 = v.dot(self.axis);
        if v1 > radius + self.range || v1 < -radius {
            return false;
        }
        // Distance of the sphere's centre outside the cone: cos·√(|v|² − v1²) − v1·sin; the
        // cell is outside when that exceeds its radius. Squared (both sides are then ≥ 0) so
        // the hot loop has no square root.
        let bound = radius + v1 * self.sin;
        bound >= 0.0 && self.cos * self.cos * (v.length_squared() - v1 * v1) <= bound * bound
    }
}
