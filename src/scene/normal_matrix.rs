//! The matrix that carries normals through a transform.

use glam::DMat3;

/// The normal matrix of `m`: its cofactor matrix (`det(m) · m⁻ᵀ`, up to a positive scale),
/// scaled so its largest entry is 1, or, where its entries spread past 10³⁰, so the
/// smallest lies as far below 1 as the largest above (f32 would flush it to zero). Unlike
/// the inverse transpose it exists for a singular `m` — a flat object scaled to 0 along its
/// own normal keeps that normal (`diag(2, 2, 0)` maps `z` to `z`) instead of becoming NaN —
/// and the scaling keeps huge or tiny transforms within `f32` (the shaders normalise per
/// fragment, so a uniform scale changes nothing). A transform that collapses a whole plane
/// (rank < 2) has no normal directions: the identity stands in (its triangles have no area
/// anyway).
pub fn normal_matrix(m: &DMat3) -> DMat3 {
    let cofactor = DMat3::from_cols(
        m.y_axis.cross(m.z_axis),
        m.z_axis.cross(m.x_axis),
        m.x_axis.cross(m.y_axis),
    );
    // A mirroring transform keeps its normals' orientation as the inverse transpose does.
    let sign = if mirrors(m) { -1.0 } else { 1.0 };
    let largest = cofactor
        .abs()
        .to_cols_array()
        .into_iter()
        .fold(0.0, f64::max);
    if largest > 0.0 && largest.is_finite() {
        let unit = cofactor * (sign / largest);
        unit * f32_scale(&unit)
    } else {
        DMat3::IDENTITY
    }
}

/// Entries at most this far below the largest stay as they are: even times a normal's
/// component of 10⁻⁸ they stay above f32's subnormal numbers.
const SPREAD_KEPT: f64 = 1e-30;

/// What to scale `unit` (largest entry 1) by so that the GPU, which reads f32's subnormal
/// numbers as zero, keeps its small entries: 1 where none is below [`SPREAD_KEPT`], else the
/// factor that puts the smallest and the largest as far below 1 as above (at most 10³⁰, so
/// a normal's three products still sum within f32).
fn f32_scale(unit: &DMat3) -> f64 {
    let smallest = unit
        .abs()
        .to_cols_array()
        .into_iter()
        .filter(|v| *v > 0.0)
        .fold(1.0, f64::min);
    if smallest >= SPREAD_KEPT {
        1.0
    } else {
        smallest.recip().sqrt().min(1e30)
    }
}

/// Whether `m` mirrors what it places (a negative determinant; −0 does not), turning its
/// triangles' winding round: the one test the normals, the GPU's front side and the CPU twin
/// share.
pub fn mirrors(m: &DMat3) -> bool {
    m.determinant() < 0.0
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::DVec3;

    fn direction(m: &DMat3, n: DVec3) -> DVec3 {
        (normal_matrix(m) * n).normalize()
    }

    #[test]
    fn matches_the_inverse_transpose_where_it_exists() {
        let m = DMat3::from_cols(
            DVec3::new(2.0, 0.3, -0.5),
            DVec3::new(0.1, -1.5, 0.7),
            DVec3::new(0.4, 0.2, 3.0),
        );
        for n in [
            DVec3::X,
            DVec3::Y,
            DVec3::Z,
            DVec3::new(1.0, -2.0, 0.5).normalize(),
        ] {
            let want = (m.inverse().transpose() * n).normalize();
            assert!((direction(&m, n) - want).length() < 1e-12, "{n}");
        }
        let mirror = DMat3::from_diagonal(DVec3::new(-1.0, 1.0, 1.0));
        let n = DVec3::new(0.6, 0.8, 0.0);
        assert!((direction(&mirror, n) - mirror.inverse().transpose() * n).length() < 1e-12);
    }

    #[test]
    fn a_flat_object_scaled_to_zero_along_its_normal_keeps_it() {
        let flat = DMat3::from_diagonal(DVec3::new(2.0, 2.0, 0.0));
        assert_eq!(direction(&flat, DVec3::Z), DVec3::Z);
        let thin = DMat3::from_diagonal(DVec3::new(1.0, 1.0, 1e-20));
        assert!((direction(&thin, DVec3::Z) - DVec3::Z).length() < 1e-12);
        assert!(normal_matrix(&thin).is_finite());
    }

    /// The f32 matrix as a GPU reads it (subnormal entries as zero) turns the normal of a
    /// plane stretched along it as f64 does, and turned aside too.
    #[test]
    fn a_plane_stretched_along_its_normal_keeps_it_in_f32() {
        let flushed = |m: DMat3| {
            let m = m.as_mat3();
            let keep = |c: glam::Vec3| {
                glam::Vec3::select(
                    c.abs().cmpge(glam::Vec3::splat(f32::MIN_POSITIVE)),
                    c,
                    glam::Vec3::ZERO,
                )
            };
            glam::Mat3::from_cols(keep(m.x_axis), keep(m.y_axis), keep(m.z_axis)).as_dmat3()
        };
        for stretch in [1e20, 1e37, 1e38, 3e38] {
            for turn in [0.0, 0.3, 1.5] {
                let m = DMat3::from_rotation_y(turn)
                    * DMat3::from_diagonal(DVec3::new(1.0, 1.0, stretch));
                let normal = normal_matrix(&m);
                let want = (normal * DVec3::Z).normalize();
                let got = (flushed(normal) * DVec3::Z).normalize_or_zero();
                assert!((got - want).length() < 1e-6, "{stretch:e} {turn}: {got}");
                assert!(normal.as_mat3().is_finite());
            }
        }
    }

    #[test]
    fn huge_and_degenerate_transforms_stay_finite() {
        let huge = DMat3::from_diagonal(DVec3::splat(1e200));
        assert!(normal_matrix(&huge).as_mat3().is_finite());
        let line = DMat3::from_diagonal(DVec3::new(1.0, 0.0, 0.0));
        assert_eq!(normal_matrix(&line), DMat3::IDENTITY);
        assert_eq!(normal_matrix(&DMat3::ZERO), DMat3::IDENTITY);
    }
}
