//! Forward's light cap: where one draw can loop over fewer lights than the scene has (ES 2.0
//! without fragment highp: the loop bound must fit a mediump `int`, and mediump texture
//! coordinates address no more rows), forward keeps the lights that matter most for this view
//! and leaves the rest out — the same policy the cluster grid's overflow applies per cell.

use crate::cluster::grid::{GridProjection, ViewVolume};
use crate::cluster::view_light::GpuLight;

/// The view the cap ranks lights for: its side planes and near plane (a light beside or
/// behind the camera is near the eye but reaches no pixel).
#[derive(Clone, Copy, Debug)]
pub struct CapView(ViewVolume);

impl CapView {
    /// The view of the projection matrix `projection` with its near plane at `near`.
    pub fn new(projection: &glam::Mat4, near: f64) -> CapView {
        let projection = GridProjection::from_matrix(&projection.as_dmat4());
        CapView(ViewVolume::new(projection, near, f64::INFINITY))
    }

    /// Whether any of the light's sphere (the radius forward shades with) lies in the view.
    fn sees(&self, light: &GpuLight) -> bool {
        !self
            .0
            .excludes(light.position.as_dvec3(), f64::from(light.radius))
    }
}

/// How much a light can matter to this view: its brightest channel over one plus the squared
/// distance from the eye to its sphere (lights around the eye come first), and nothing for a
/// light whose sphere lies wholly outside the view (behind the eye or beside it).
pub fn importance(light: &GpuLight, view: &CapView) -> f32 {
    if !view.sees(light) {
        return 0.0;
    }
    let gap = (light.position.length() - light.cull_radius).max(0.0);
    light.radiance.max_element() / (1.0 + gap * gap)
}

/// The `limit` most important lights of `lights` for `view`, in their original order (the
/// order forward adds them in, so the image is forward's over exactly those lights). Ties
/// keep the earlier.
pub fn keep_most_important(lights: &[GpuLight], limit: usize, view: &CapView) -> Vec<GpuLight> {
    let mut kept = Vec::new();
    keep_most_important_into(lights, limit, view, &mut Vec::new(), &mut kept);
    kept
}

/// [`keep_most_important`] into `kept`, with `order` as the selection's buffer: both reused,
/// so a frame allocates nothing once they have grown.
pub fn keep_most_important_into(
    lights: &[GpuLight],
    limit: usize,
    view: &CapView,
    order: &mut Vec<usize>,
    kept: &mut Vec<GpuLight>,
) {
    most_important_indices_into(lights, limit, view, order);
    kept.clear();
    kept.extend(order.iter().map(|&i| lights[i]));
}

/// The positions in `lights` that [`keep_most_important`] keeps, ascending.
pub fn most_important_indices(lights: &[GpuLight], limit: usize, view: &CapView) -> Vec<usize> {
    let mut order = Vec::new();
    most_important_indices_into(lights, limit, view, &mut order);
    order
}

/// [`most_important_indices`] into `order` (cleared first).
pub fn most_important_indices_into(
    lights: &[GpuLight],
    limit: usize,
    view: &CapView,
    order: &mut Vec<usize>,
) {
    order.clear();
    order.extend(0..lights.len());
    if lights.len() > limit {
        // Descending importance; the index breaks ties so the choice is deterministic.
        order.select_nth_unstable_by(limit, |&a, &b| {
            importance(&lights[b], view)
                .total_cmp(&importance(&lights[a], view))
                .then(a.cmp(&b))
        });
        order.truncate(limit);
        order.sort_unstable();
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::Vec3;

    fn light(position: Vec3, radius: f32, brightness: f32) -> GpuLight {
        GpuLight {
            position,
            radius,
            cull_radius: radius,
            radiance: Vec3::splat(brightness),
            spot_scale: 0.0,
            direction: Vec3::ZERO,
            spot_offset: 1.0,
            cone_deg: (180.0, 180.0),
        }
    }

    /// A 60° vertical field of view at 16:9, near plane 0.1.
    fn view() -> CapView {
        let f = 1.0 / 30f32.to_radians().tan();
        let (near, far) = (0.1, 100.0);
        // OpenGL's perspective matrix, column by column.
        #[rustfmt::skip]
        let projection = glam::Mat4::from_cols_array(&[
            f * 9.0 / 16.0, 0.0, 0.0, 0.0,
            0.0, f, 0.0, 0.0,
            0.0, 0.0, (far + near) / (near - far), -1.0,
            0.0, 0.0, 2.0 * far * near / (near - far), 0.0,
        ]);
        CapView::new(&projection, f64::from(near))
    }

    #[test]
    fn keeps_the_near_and_bright_in_their_original_order() {
        let lights = [
            light(Vec3::new(0.0, 0.0, -50.0), 1.0, 1.0), // far
            light(Vec3::new(0.0, 0.0, -2.0), 1.0, 1.0),  // near
            light(Vec3::new(0.0, 0.0, 30.0), 5.0, 9.0),  // bright but behind the eye
            light(Vec3::new(1.0, 0.0, -1.0), 3.0, 0.5),  // around the eye
            light(Vec3::new(0.0, 0.0, -50.0), 1.0, 9.0), // far but bright
        ];
        let kept = keep_most_important(&lights, 3, &view());
        let positions: Vec<Vec3> = kept.iter().map(|l| l.position).collect();
        assert_eq!(
            positions,
            vec![lights[1].position, lights[3].position, lights[4].position]
        );
    }

    #[test]
    fn a_light_reaching_past_the_eye_from_behind_still_counts() {
        let behind_but_reaching = light(Vec3::new(0.0, 0.0, 2.0), 3.0, 1.0);
        assert!(importance(&behind_but_reaching, &view()) > 0.0);
        assert_eq!(
            importance(&light(Vec3::new(0.0, 0.0, 4.0), 3.0, 1.0), &view()),
            0.0
        );
    }

    /// A light just beside the camera, outside a side plane, is near the eye but reaches no
    /// pixel: it must not take the place of one in view (it did, ranked by distance alone).
    #[test]
    fn lights_beside_the_view_matter_not_at_all() {
        // The right plane is x = d·tan(30°)·16/9 ≈ 1.026·d: the centre (25, depth 2) lies
        // (25 − 2.05)/√(1 + 1.026²) ≈ 16.0 from it, so a sphere of radius 15 stays outside.
        // Ranked by distance alone it beats the light ahead (gap 10.1 against 27).
        let beside = light(Vec3::new(25.0, 0.0, -2.0), 15.0, 1.0);
        let ahead = light(Vec3::new(0.0, 0.0, -30.0), 3.0, 1.0);
        assert_eq!(importance(&beside, &view()), 0.0);
        let mut lights = vec![beside; 8];
        lights.push(ahead);
        let kept = keep_most_important(&lights, 1, &view());
        assert_eq!(kept[0].position, ahead.position);
    }

    #[test]
    fn under_the_limit_everything_is_kept() {
        let lights = [light(Vec3::Z * -3.0, 1.0, 1.0); 4];
        assert_eq!(keep_most_important(&lights, 4, &view()).len(), 4);
        assert_eq!(keep_most_important(&lights, 9, &view()).len(), 4);
        assert_eq!(keep_most_important(&lights, 0, &view()).len(), 0);
    }
}
