//! The glTF 2.0 metallic-roughness BRDF (spec Appendix B) in `f64`: the CPU twin of
//! `metallicRoughness` in `glsl/light_model.glsl`, clamps included, so the oracle is the model
//! the shaders evaluate (why each clamp is there: docs/precision.md).
//!
//! With `x⁵ = (1 − V·H)⁵`, `α = max(roughness, MIN_ROUGHNESS)²`:
//!
//! ```text
//! D        = α² / (π ((N·H)²(α² − 1) + 1)²)            GGX / Trowbridge-Reitz
//! Vis      = 0.5 / (N·L √((N·V)²(1 − α²) + α²) + N·V √((N·L)²(1 − α²) + α²))
//!                                                        height-correlated Smith, N·V ≥ 10⁻⁴
//! F        = F0 + (1 − F0) x⁵,  F0 = mix(0.04, min(base, 1), metallic)
//! c_diff   = mix(base, 0, metallic),  F_d = 0.04 + 0.96 x⁵   (the dielectric's Fresnel)
//! π f N·L  = (1 − F_d) c_diff N·L + F min(π D Vis N·L, MAX_SPECULAR_LOBE)
//! ```
//!
//! The spec's `mix(dielectric_brdf, metal_brdf, metallic)` expands to exactly this (its base
//! colour lies in [0, 1]; past 1, which the loaders allow up to `MAX_COLOR_FACTOR`, F0 stays 1:
//! a reflectance above 1 times the capped lobe overflowed fp16 into Inf, then NaN). The result
//! is multiplied by π like the Blinn-Phong model's Lambert term (`albedo·N·L`, no 1/π): a light
//! of radiance 1 at distance 0 makes a white rough dielectric as bright as a white Lambert
//! surface, so both models share the lights' units.

use glam::DVec3;

/// Smallest perceptual roughness shaded (α ≥ 0.0079, α² ≥ 6.3·10⁻⁵, the smallest normal fp16
/// number): the GGX lobe's peak `1/α` stays representable in fp16 (Filament's mobile floor).
pub const MIN_ROUGHNESS: f64 = 0.089;

/// Smallest N·V the visibility term sees: at grazing view the term is finite.
pub const MIN_N_DOT_V: f64 = 1e-4;

/// Cap on the specular lobe `π·D·Vis·N·L` (a near-mirror's peak reaches 10⁶ at grazing
/// angles): fp16 colour factors hold the sum, and no real display tells it apart.
pub const MAX_SPECULAR_LOBE: f64 = 16384.0;

/// Dielectric reflectance at normal incidence (4 %).
pub const DIELECTRIC_F0: f64 = 0.04;

/// `π·f·(N·L)` for unit `l` (to the light), `n`, `v` (to the eye) with `N·L > 0`: what the
/// light's radiance × falloff × spot is multiplied by.
pub fn reflectance(
    l: DVec3,
    n: DVec3,
    v: DVec3,
    base: DVec3,
    metallic: f64,
    roughness: f64,
) -> DVec3 {
    let n_dot_l = n.dot(l);
    if n_dot_l <= 0.0 {
        return DVec3::ZERO;
    }
    let h = (l + v).normalize_or_zero();
    let n_dot_v = n.dot(v).max(MIN_N_DOT_V);
    let n_dot_h = n.dot(h).clamp(0.0, 1.0);
    let v_dot_h = v.dot(h).clamp(0.0, 1.0);
    let r = roughness.clamp(MIN_ROUGHNESS, 1.0);
    let a = r * r;
    let a2 = a * a;
    // (N·H)²(α² − 1) + 1 = α²(N·H)² + |N×H|², at least α² for a unit H.
    let denom = (a2 * n_dot_h * n_dot_h + n.cross(h).length_squared()).max(a2);
    // π·D = k², k = α / denom.
    let k = a / denom;
    let lambda_v = (n_dot_v * n_dot_v * (1.0 - a2) + a2).sqrt();
    let lambda_l = (n_dot_l * n_dot_l * (1.0 - a2) + a2).sqrt();
    // Vis·N·L, without forming Vis (which grows without bound as N·L, N·V → 0).
    let vis_cos = 0.5 / (lambda_v + n_dot_v * lambda_l / n_dot_l);
    let lobe = (k * k * vis_cos).min(MAX_SPECULAR_LOBE);
    let x5 = (1.0 - v_dot_h).powi(5);
    let f0 = DVec3::splat(DIELECTRIC_F0).lerp(base.min(DVec3::ONE), metallic);
    let fresnel = f0 + (DVec3::ONE - f0) * x5;
    let dielectric = DIELECTRIC_F0 + (1.0 - DIELECTRIC_F0) * x5;
    let c_diff = base * (1.0 - metallic);
    c_diff * ((1.0 - dielectric) * n_dot_l) + fresnel * lobe
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The spec's Appendix B written out directly: `mix(dielectric_brdf, metal_brdf,
    /// metallic)`, times π·N·L, with GGX and the height-correlated Smith visibility (the form
    /// the Khronos Sample Viewer evaluates); no rewriting, no clamps.
    fn textbook(l: DVec3, n: DVec3, v: DVec3, base: DVec3, metallic: f64, roughness: f64) -> DVec3 {
        let pi = std::f64::consts::PI;
        let h = (l + v).normalize();
        let (nl, nv, nh, vh) = (n.dot(l), n.dot(v), n.dot(h), v.dot(h));
        let a2 = roughness.powi(4);
        let d = a2 / (pi * (nh * nh * (a2 - 1.0) + 1.0).powi(2));
        let vis = 0.5
            / (nl * (nv * nv * (1.0 - a2) + a2).sqrt() + nv * (nl * nl * (1.0 - a2) + a2).sqrt());
        let specular = DVec3::splat(d * vis);
        let x5 = (1.0 - vh).powi(5);
        let metal = specular * (base + (DVec3::ONE - base) * x5);
        let dielectric = (base / pi).lerp(specular, 0.04 + 0.96 * x5);
        dielectric.lerp(metal, metallic) * (pi * nl)
    }

    #[test]
    fn matches_the_spec_formulas_where_no_clamp_bites() {
        let n = DVec3::Z;
        let l = DVec3::new(0.3, 0.2, 1.0).normalize();
        let v = DVec3::new(-0.5, 0.1, 1.0).normalize();
        for (base, metallic, roughness) in [
            (DVec3::new(0.8, 0.5, 0.2), 0.0, 0.5),
            (DVec3::new(0.8, 0.5, 0.2), 1.0, 0.3),
            (DVec3::new(0.9, 0.9, 0.9), 0.4, 1.0),
        ] {
            let got = reflectance(l, n, v, base, metallic, roughness);
            let want = textbook(l, n, v, base, metallic, roughness);
            assert!((got - want).abs().max_element() < 1e-6, "{got} vs {want}");
        }
    }

    #[test]
    fn stiff_cases_stay_finite_and_capped() {
        let n = DVec3::Z;
        let grazing = DVec3::new(1.0, 0.0, 1e-9).normalize();
        let mirror = DVec3::new(-1.0, 0.0, 1e-9).normalize();
        for (l, v) in [(n, n), (grazing, mirror), (mirror, n), (n, grazing)] {
            for roughness in [0.0, 1e-4, 0.05, 0.5, 1.0] {
                for metallic in [0.0, 1.0] {
                    for base in [DVec3::ZERO, DVec3::ONE, DVec3::splat(1024.0)] {
                        let c = reflectance(l, n, v, base, metallic, roughness);
                        assert!(c.is_finite() && c.min_element() >= 0.0, "{c}");
                        // fp16 holds it: the lobe's cap, plus the diffuse term's base colour.
                        let most = MAX_SPECULAR_LOBE + base.max_element();
                        assert!(c.max_element() <= most, "{base} {c}");
                    }
                }
            }
        }
        // The mirror-like peak is capped, not infinite.
        let peak = reflectance(n, n, n, DVec3::ONE, 1.0, 0.0);
        assert!(peak.x > 1000.0, "{peak}");
    }
}
