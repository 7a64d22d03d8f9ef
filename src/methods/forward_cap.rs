//! Forward's light cap: where one draw can loop over fewer lights than the scene has (ES 2.0
//! without fragment highp: the loop bound must fit a mediump `int`, and mediump texture
//! coordinates address no more rows), forward keeps the lights that matter most for this view
//! and leaves the rest out — the same policy the cluster grid's overflow applies per cell.

use crate::cluster::view_light::GpuLight;

/// How much a light can matter to this view: its brightest channel over one plus the squared
/// distance from the eye to its sphere (lights around the eye come first), and nothing for a
/// light whose sphere lies wholly behind the eye (view space looks down −Z).
pub fn importance(light: &GpuLight) -> f32 {
    if light.position.z > light.cull_radius {
        return 0.0;
    }
    let gap = (light.position.length() - light.cull_radius).max(0.0);
    light.radiance.max_element() / (1.0 + gap * gap)
}

/// The `limit` most important lights of `lights`, in their original order (the order forward
/// adds them in, so the image is forward's over exactly those lights). Ties keep the earlier.
pub fn keep_most_important(lights: &[GpuLight], limit: usize) -> Vec<GpuLight> {
    let mut kept = Vec::new();
    keep_most_important_into(lights, limit, &mut Vec::new(), &mut kept);
    kept
}

/// [`keep_most_important`] into `kept`, with `order` as the selection's buffer: both reused,
/// so a frame allocates nothing once they have grown.
pub fn keep_most_important_into(
    lights: &[GpuLight],
    limit: usize,
    order: &mut Vec<usize>,
    kept: &mut Vec<GpuLight>,
) {
    most_important_indices_into(lights, limit, order);
    kept.clear();
    kept.extend(order.iter().map(|&i| lights[i]));
}

/// The positions in `lights` that [`keep_most_important`] keeps, ascending.
pub fn most_important_indices(lights: &[GpuLight], limit: usize) -> Vec<usize> {
    let mut order = Vec::new();
    most_important_indices_into(lights, limit, &mut order);
    order
}

/// [`most_important_indices`] into `order` (cleared first).
pub fn most_important_indices_into(lights: &[GpuLight], limit: usize, order: &mut Vec<usize>) {
    order.clear();
    order.extend(0..lights.len());
    if lights.len() > limit {
        // Descending importance; the index breaks ties so the choice is deterministic.
        order.select_nth_unstable_by(limit, |&a, &b| {
            importance(&lights[b])
                .total_cmp(&importance(&lights[a]))
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

    #[test]
    fn keeps_the_near_and_bright_in_their_original_order() {
        let lights = [
            light(Vec3::new(0.0, 0.0, -50.0), 1.0, 1.0), // far
            light(Vec3::new(0.0, 0.0, -2.0), 1.0, 1.0),  // near
            light(Vec3::new(0.0, 0.0, 30.0), 5.0, 9.0),  // bright but behind the eye
            light(Vec3::new(1.0, 0.0, -1.0), 3.0, 0.5),  // around the eye
            light(Vec3::new(0.0, 0.0, -50.0), 1.0, 9.0), // far but bright
        ];
        let kept = keep_most_important(&lights, 3);
        let positions: Vec<Vec3> = kept.iter().map(|l| l.position).collect();
        assert_eq!(
            positions,
            vec![lights[1].position, lights[3].position, lights[4].position]
        );
    }

    #[test]
    fn a_light_reaching_past_the_eye_from_behind_still_counts() {
        let behind_but_reaching = light(Vec3::new(0.0, 0.0, 2.0), 3.0, 1.0);
        assert!(importance(&behind_but_reaching) > 0.0);
        assert_eq!(importance(&light(Vec3::new(0.0, 0.0, 4.0), 3.0, 1.0)), 0.0);
    }

    #[test]
    fn under_the_limit_everything_is_kept() {
        let lights = [light(Vec3::Z * -3.0, 1.0, 1.0); 4];
        assert_eq!(keep_most_important(&lights, 4).len(), 4);
        assert_eq!(keep_most_important(&lights, 9).len(), 4);
        assert_eq!(keep_most_important(&lights, 0).len(), 0);
    }
}
