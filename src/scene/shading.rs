//! The light model evaluated on the CPU in `f64`: the oracle the GPU methods are checked
//! against. It mirrors `glsl/light_model.glsl` term by term.
//!
//! For a surface point `P` with unit normal `N`, unit direction to the eye `V`, and a light at
//! `Lp` with radius `r` and radiance `c = color × intensity`:
//!
//! ```text
//! d        = |Lp − P|,  L = (Lp − P) / d
//! falloff  = clamp(1 − (d/r)⁴, 0, 1)² / (d² + 1)          exactly 0 for d ≥ r
//! spot     = smoothstep over t = clamp(offset − scale·(1 − dot(−L, dir)), 0, 1)   (1 for points)
//! diffuse  = albedo · max(N·L, 0)
//! specular = Ks · max(N·H, 0)^Ns · max(N·L, 0)   with H = normalize(L + V)
//! out      = ambient · albedo + Σ c · falloff · spot · (diffuse + specular)
//!                             + Σ suns c · (diffuse + specular)  with L = −direction
//! ```
//!
//! That is the Blinn-Phong model; a metallic-roughness material replaces `diffuse + specular`
//! with the glTF BRDF times π·N·L ([`super::brdf::reflectance`]); `albedo` is its base colour.
//!
//! A double-sided surface's back face is shaded with its normals reversed ([`seen_side`]),
//! a front face with them as they are, even where one leans away from the eye (a
//! single-sided surface has no back face: it is culled). In view space, `V` is
//! `normalize(−P)` for perspective cameras and `+Z` for orthographic ones.
//!
//! The shaders compute the same quantities in forms that survive fp16 (the distance as
//! `r·|u|`, `1 − cos` as half a squared chord; see `glsl/light_model.glsl`); here, in `f64`,
//! the direct forms are exact enough.

use glam::{DVec3, Vec3};

use super::directional::{shown_directional_lights, DirectionalLight};
use super::light::{Light, LightKind};
use super::material::{Material, MaterialModel};

/// Surface attributes at one shading point, in linear RGB.
#[derive(Clone, Copy, Debug)]
pub struct Surface {
    /// World position.
    pub position: DVec3,
    /// Unit normal.
    pub normal: DVec3,
    /// Diffuse albedo (material colour × decoded texture).
    pub albedo: DVec3,
    /// Specular colour.
    pub specular: DVec3,
    /// Blinn-Phong exponent, already clamped (see `Material::shading_exponent`).
    pub exponent: f64,
    /// Which BRDF shades it.
    pub model: MaterialModel,
    /// Metalness (metallic-roughness only).
    pub metallic: f64,
    /// Perceptual roughness (metallic-roughness only; clamped by the BRDF).
    pub roughness: f64,
}

impl Surface {
    /// The surface of `material` at `position` with unit `normal`; `albedo` is the material's
    /// diffuse (base) colour times its decoded texture, where it has one.
    pub fn of(material: &Material, position: DVec3, normal: DVec3, albedo: DVec3) -> Surface {
        Surface {
            position,
            normal,
            albedo,
            specular: material.specular.as_dvec3(),
            exponent: material.shading_exponent() as f64,
            model: material.model,
            metallic: material.metallic as f64,
            roughness: material.roughness as f64,
        }
    }
}

/// `clamp(1 − (d/r)⁴, 0, 1)² / (d² + 1)`; zero for `r <= 0`.
pub fn falloff(d: f64, r: f64) -> f64 {
    if r <= 0.0 {
        return 0.0;
    }
    let q = (d / r).powi(4);
    let w = (1.0 - q).clamp(0.0, 1.0);
    w * w / (d * d + 1.0)
}

/// Distance out to which a light of peak radiance `radiance` (its largest channel) and
/// radius `radius` contributes at least `cutoff` (linear radiance, before the surface's
/// reflectance): the light cut-off knob. Its falloff decreases monotonically, so a bisection
/// finds the distance; 0 when even the peak is below the cut-off, `radius` for a cut-off of
/// 0.
pub fn cutoff_distance(radiance: f64, radius: f64, cutoff: f64) -> f64 {
    if cutoff <= 0.0 {
        return radius;
    }
    if radiance * falloff(0.0, radius) < cutoff {
        return 0.0;
    }
    let (mut lo, mut hi) = (0.0, radius);
    // 32 halvings: within 2.3·10⁻¹⁰ of the radius, far below what culling can tell apart, and
    // half the CPU cost of running to an f64 ulp (it runs for every light every frame).
    for _ in 0..32 {
        let mid = 0.5 * (lo + hi);
        if radiance * falloff(mid, radius) >= cutoff {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    hi
}

/// The spot factor for a light-to-surface direction `to_surface` (unit).
pub fn spot_factor(light: &Light, to_surface: DVec3) -> f64 {
    match light.kind {
        LightKind::Point => 1.0,
        LightKind::Spot { direction, .. } => {
            let (scale, offset) = light.spot_scale_offset();
            let one_minus_cos =
                1.0 - to_surface.dot(super::direction::unit(direction).unwrap_or(DVec3::ZERO));
            let t = (offset as f64 - scale as f64 * one_minus_cos).clamp(0.0, 1.0);
            t * t * (3.0 - 2.0 * t)
        }
    }
}

/// Closer to a light than this (in the largest component of the vector to it) a surface gets
/// nothing from it: there is no direction to the light. 2⁻¹³, above fp16's smallest normal, so
/// no driver divides by a subnormal it flushes to zero (glsl/light_model.glsl).
pub const LIGHT_MIN_DISTANCE: f64 = 1.0 / 8192.0;

/// Radiance one light reflects along `v`, the unit direction from the surface to the eye
/// (no ambient). The normal is used as given (see [`seen_side`] for two-sided surfaces).
pub fn light_contribution(light: &Light, s: &Surface, v: DVec3) -> DVec3 {
    let to_light = light.position - s.position;
    if to_light.abs().max_element() <= LIGHT_MIN_DISTANCE {
        return DVec3::ZERO;
    }
    let d = to_light.length();
    let f = falloff(d, light.radius as f64);
    if f == 0.0 {
        return DVec3::ZERO;
    }
    let l = to_light / d.max(1e-6);
    let reflected = reflected(l, s, v);
    if reflected == DVec3::ZERO {
        return DVec3::ZERO;
    }
    let spot = spot_factor(light, -l);
    light.radiance().as_dvec3() * (f * spot) * reflected
}

/// What the surface reflects along `v` of unit irradiance arriving from the unit direction `l`
/// (surface → light): [`reflectance`], zero where `N·L ≤ 0`. Every kind of light scales this
/// (`surfaceReflectance` in `glsl/light_model.glsl`).
pub fn reflected(l: DVec3, s: &Surface, v: DVec3) -> DVec3 {
    let n_dot_l = s.normal.dot(l);
    if n_dot_l <= 0.0 {
        return DVec3::ZERO;
    }
    reflectance(l, s, v)
}

/// What the light's radiance × falloff × spot is multiplied by for unit `l` (to the light)
/// with N·L > 0: the BRDF times N·L (times π for metallic-roughness; see [`super::brdf`]).
pub fn reflectance(l: DVec3, s: &Surface, v: DVec3) -> DVec3 {
    match s.model {
        MaterialModel::BlinnPhong => {
            let h = (l + v).normalize_or_zero();
            let n_dot_h = s.normal.dot(h).max(0.0);
            (s.albedo + s.specular * n_dot_h.powf(s.exponent)) * s.normal.dot(l)
        }
        MaterialModel::MetallicRoughness => {
            super::brdf::reflectance(l, s.normal, v, s.albedo, s.metallic, s.roughness)
        }
    }
}

/// Radiance one directional light reflects along `v` (no falloff: it is the same everywhere).
pub fn directional_contribution(light: &DirectionalLight, s: &Surface, v: DVec3) -> DVec3 {
    light.radiance().as_dvec3() * reflected(light.to_light(), s, v)
}

/// What the directional lights a frame shows ([`shown_directional_lights`]: the brightest
/// [`MAX_DIRECTIONAL_LIGHTS`](super::MAX_DIRECTIONAL_LIGHTS)) add along `v`, with the
/// normal as given. The total a pixel shows is `shade(..) + shade_directional(..)`.
pub fn shade_directional(s: &Surface, v: DVec3, lights: &[DirectionalLight]) -> DVec3 {
    let mut shown = Vec::new();
    shown_directional_lights(lights, &mut shown);
    shown
        .iter()
        .map(|&i| directional_contribution(&lights[i], s, v))
        .sum()
}

/// The shading normal of the side the eye sees, as `shadingNormal` in `glsl/surface.glsl`:
/// `normal` on a front face (`face`, the triangle's normal on its front side, towards `v`),
/// reversed on a back face. By the face, not by `normal`: an interpolated normal leans away
/// from the eye near a smooth surface's silhouette, and turning it there lit notches of the
/// silhouette from the wrong side.
pub fn seen_side(normal: DVec3, face: DVec3, v: DVec3) -> DVec3 {
    if face.dot(v) < 0.0 {
        -normal
    } else {
        normal
    }
}

/// Total linear radiance along `v` (unit, surface → eye): ambient plus every light, with the
/// normal as given (two-sided surfaces turn it first, [`seen_side`]).
pub fn shade(s: &Surface, v: DVec3, lights: &[Light], ambient: Vec3) -> DVec3 {
    let mut c = ambient.as_dvec3() * s.albedo;
    for light in lights {
        c += light_contribution(light, s, v);
    }
    c
}

/// The curve that maps exposed linear radiance (0 to ∞) into the displayable [0, 1], applied
/// per pixel before the sRGB encode; CPU twin: `scene::shading::tone_map`.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "snake_case")]
pub enum ToneMap {
    /// None: the value is clamped to [0, 1], so bright lights clip to white.
    #[default]
    None,
    /// Reinhard, `c / (1 + c)` per channel: never clips, compresses everything.
    Reinhard,
    /// The ACES filmic curve in Narkowicz's fit, per channel: contrast and a soft shoulder.
    Aces,
    /// Khronos PBR Neutral: colours below 0.76 unchanged, highlights compressed and desaturated
    /// towards white, hue kept.
    Neutral,
}

/// The tone map of `glsl/surface.glsl` in f64: exposed linear RGB (the caller multiplies by
/// 2^EV) → [0, 1]. Inputs are capped at 1 000 as the shader caps them.
pub fn tone_map(rgb: [f64; 3], curve: ToneMap) -> [f64; 3] {
    let c = rgb.map(|v| v.clamp(0.0, 1000.0));
    match curve {
        ToneMap::None => c,
        ToneMap::Reinhard => c.map(|v| v / (1.0 + v)),
        ToneMap::Aces => c.map(|v| {
            let v = v.min(8.0);
            ((v * (2.51 * v + 0.03)) / (v * (2.43 * v + 0.59) + 0.14)).clamp(0.0, 1.0)
        }),
        ToneMap::Neutral => {
            let x = c[0].min(c[1]).min(c[2]);
            let offset = if x < 0.08 { x - 6.25 * x * x } else { 0.04 };
            let c = c.map(|v| v - offset);
            let peak = c[0].max(c[1]).max(c[2]);
            if peak < 0.76 {
                return c;
            }
            let new_peak = 1.0 - 0.24 * 0.24 / (peak - 0.52);
            let g = 1.0 - 1.0 / (0.15 * (peak - new_peak) + 1.0);
            c.map(|v| v * new_peak / peak * (1.0 - g) + new_peak * g)
        }
    }
}

/// sRGB transfer function (linear → encoded), input clamped to [0, 1].
pub fn linear_to_srgb(x: f64) -> f64 {
    let x = x.clamp(0.0, 1.0);
    if x <= 0.003_130_8 {
        12.92 * x
    } else {
        1.055 * x.powf(1.0 / 2.4) - 0.055
    }
}

/// sRGB decode (encoded → linear).
pub fn srgb_to_linear(x: f64) -> f64 {
    if x <= 0.040_45 {
        x / 12.92
    } else {
        ((x + 0.055) / 1.055).powf(2.4)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn falloff_is_exactly_zero_at_and_beyond_the_radius() {
        assert_eq!(falloff(2.0, 2.0), 0.0);
        assert_eq!(falloff(3.0, 2.0), 0.0);
        assert!(falloff(1.9, 2.0) > 0.0);
        assert_eq!(falloff(0.0, 2.0), 1.0);
        assert_eq!(falloff(0.0, 0.0), 0.0);
    }

    #[test]
    fn cutoff_distance_is_where_the_contribution_meets_the_cutoff() {
        let (c, r) = (2.0, 5.0);
        for cutoff in [1e-4, 1e-2, 0.3] {
            let d = cutoff_distance(c, r, cutoff);
            assert!(d > 0.0 && d < r, "{cutoff}: {d}");
            assert!((c * falloff(d, r) - cutoff).abs() < 1e-8, "{cutoff}: {d}");
        }
        assert_eq!(cutoff_distance(c, r, 0.0), r);
        assert_eq!(cutoff_distance(c, r, 3.0), 0.0, "peak below the cut-off");
        assert!(cutoff_distance(c, r, 1e-3) > cutoff_distance(c, r, 1e-2));
    }

    #[test]
    fn a_surface_at_a_light_gets_nothing_from_it() {
        let light = Light::point(DVec3::ZERO, 2.0, Vec3::ONE, 1.0);
        let at = |x: f64| Surface {
            position: DVec3::new(x, 0.0, 0.0),
            normal: DVec3::NEG_X,
            albedo: DVec3::ONE,
            specular: DVec3::ZERO,
            exponent: 1.0,
            model: MaterialModel::BlinnPhong,
            metallic: 0.0,
            roughness: 1.0,
        };
        let v = DVec3::NEG_X;
        assert_eq!(light_contribution(&light, &at(1e-5), v), DVec3::ZERO);
        assert_eq!(light_contribution(&light, &at(0.0), v), DVec3::ZERO);
        assert!(light_contribution(&light, &at(1e-3), v).x > 0.0);
    }

    #[test]
    fn srgb_round_trips() {
        for i in 0..=100 {
            let x = i as f64 / 100.0;
            assert!((srgb_to_linear(linear_to_srgb(x)) - x).abs() < 1e-12);
        }
    }

    #[test]
    fn light_at_the_surface_gives_no_nan() {
        let l = Light::point(DVec3::ZERO, 1.0, Vec3::ONE, 1.0);
        let s = Surface {
            specular: DVec3::ONE,
            exponent: 16.0,
            ..Surface::of(&Material::default(), DVec3::ZERO, DVec3::Z, DVec3::ONE)
        };
        let c = shade(&s, DVec3::Z, &[l], Vec3::ZERO);
        assert!(c.is_finite());
    }
}
