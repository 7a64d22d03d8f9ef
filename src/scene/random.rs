//! Seeded random light sets inside a volume (PCG, so a seed gives the same lights on every
//! platform and crate version).

use glam::{DVec3, Vec3};
use rand::{Rng, SeedableRng};
use rand_pcg::Pcg64Mcg;

use super::mesh::Aabb;
use super::Light;

/// Which kinds of lights a random set contains.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum LightSetStyle {
    /// Point lights only.
    PointsOnly,
    /// Three point lights to one spot light, spots aimed mostly downwards.
    Mixed,
}

/// Average number of light spheres covering a point of the volume that the radius is chosen
/// for: enough overlap to look lit, few enough that culling pays.
const TARGET_OVERLAP: f64 = 6.0;

/// `count` lights inside `volume`. Radii shrink as the count grows so that the average
/// overlap stays near `TARGET_OVERLAP` (6); intensity grows with the radius so each light is
/// visible.
pub fn lights(volume: &Aabb, count: usize, seed: u64, style: LightSetStyle) -> Vec<Light> {
    let mut rng = Pcg64Mcg::seed_from_u64(seed);
    let volume = &thickened(volume);
    let size = volume.size();
    let diag = size.length();
    let vol = size.x.max(1e-6) * size.y.max(1e-6) * size.z.max(1e-6);
    let sphere = |r: f64| 4.0 / 3.0 * std::f64::consts::PI * r * r * r;
    let radius = if count == 0 {
        1.0
    } else {
        (TARGET_OVERLAP * vol / (count as f64 * sphere(1.0))).cbrt()
    }
    .clamp(diag * 0.02, diag * 0.35);
    (0..count)
        .map(|i| {
            let p = DVec3::new(rng.random(), rng.random(), rng.random());
            let position = volume.min + p * size;
            let r = (radius * rng.random_range(0.7..1.3)) as f32;
            let color = hue(rng.random::<f32>());
            let intensity = 0.6 * (1.0 + r * r / 6.0);
            let is_spot = style == LightSetStyle::Mixed && i % 4 == 3;
            if is_spot {
                let dir = DVec3::new(
                    rng.random_range(-0.6..0.6),
                    -1.0,
                    rng.random_range(-0.6..0.6),
                );
                let outer = rng.random_range(20.0..60.0);
                let inner = outer * rng.random_range(0.3..0.9);
                Light::spot(
                    position,
                    r * 1.5,
                    color,
                    intensity * 2.0,
                    crate::scene::Cone {
                        direction: dir,
                        inner_deg: inner,
                        outer_deg: outer,
                    },
                )
            } else {
                Light::point(position, r, color, intensity)
            }
        })
        .collect()
}

/// Share of a model's bounds diagonal that `--lights N` pads its light volume by on every
/// side ([`model_light_volume`]).
pub const MODEL_LIGHT_PAD: f64 = 0.15;

/// Where `--lights N` places random lights around a model (OBJ and glTF files): its bounds
/// padded on every side by [`MODEL_LIGHT_PAD`] of their diagonal. Around the model as well as
/// inside it (lights inside a closed model light nothing), and as far above and below a flat
/// model (a plane, a terrain tile) as beside it, so that lights leave its plane.
pub fn model_light_volume(bounds: &Aabb) -> Aabb {
    let pad = DVec3::splat(bounds.size().length() * MODEL_LIGHT_PAD);
    Aabb {
        min: bounds.min - pad,
        max: bounds.max + pad,
    }
}

/// Least thickness of a light volume along any axis, as a fraction of its largest edge.
const MIN_THICKNESS: f64 = 0.05;

/// `volume` grown about its centre to at least [`MIN_THICKNESS`] of its largest edge along
/// every axis: the bounds of a flat scene (a plane, or an object scaled to 0 along its normal)
/// have no thickness, and lights placed in the plane itself light nothing (N·L = 0).
fn thickened(volume: &Aabb) -> Aabb {
    let size = volume.size();
    let least = size.max_element() * MIN_THICKNESS;
    let pad = (DVec3::splat(least) - size).max(DVec3::ZERO) * 0.5;
    Aabb {
        min: volume.min - pad,
        max: volume.max + pad,
    }
}

/// A saturated but not garish colour from a hue in [0, 1).
fn hue(h: f32) -> Vec3 {
    let k = |n: f32| {
        let k = (n + h * 6.0) % 6.0;
        1.0 - (k.min(4.0 - k).clamp(0.0, 1.0))
    };
    let c = Vec3::new(k(5.0), k(3.0), k(1.0));
    (c * 0.7 + Vec3::splat(0.3)).clamp(Vec3::ZERO, Vec3::ONE)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn lights_of_a_flat_volume_leave_its_plane() {
        let flat = Aabb {
            min: DVec3::new(-8.0, -8.0, 0.0),
            max: DVec3::new(8.0, 8.0, 1e-20),
        };
        let ls = lights(&flat, 64, 5, LightSetStyle::PointsOnly);
        let off = ls.iter().filter(|l| l.position.z.abs() > 0.05).count();
        assert!(off > 48, "only {off} of 64 lights off the plane");
        assert!(ls.iter().all(|l| l.position.z.abs() <= 0.4 + 1e-9));
    }

    #[test]
    fn a_flat_models_light_volume_is_padded_by_a_share_of_its_diagonal() {
        let plane = Aabb {
            min: DVec3::new(-3.0, 0.0, -4.0),
            max: DVec3::new(3.0, 0.0, 4.0),
        };
        let v = model_light_volume(&plane);
        // Diagonal 10: 1.5 on every side, the flat axis included.
        assert_eq!(v.min, DVec3::new(-4.5, -1.5, -5.5));
        assert_eq!(v.max, DVec3::new(4.5, 1.5, 5.5));
    }

    #[test]
    fn lights_stay_inside_the_volume_and_validate() {
        let v = Aabb {
            min: DVec3::new(-1.0, 0.0, -2.0),
            max: DVec3::new(3.0, 1.0, 2.0),
        };
        let ls = lights(&v, 500, 3, LightSetStyle::Mixed);
        assert_eq!(ls.len(), 500);
        for (i, l) in ls.iter().enumerate() {
            l.validate(&format!("lights[{i}]")).unwrap();
            assert!(l.position.cmpge(v.min).all() && l.position.cmple(v.max).all());
        }
        assert!(ls
            .iter()
            .any(|l| matches!(l.kind, crate::scene::LightKind::Spot { .. })));
    }
}
