//! The matrix that carries normals through a transform.

use glam::DMat3;

/// The normal matrix of `m`: its cofactor matrix (`det(m) · m⁻ᵀ`, up to a positive scale),
/// scaled so its largest entry is 1. Unlike the inverse transpose it exists for a singular `m`
/// — a flat object scaled to 0 along its own normal keeps that normal (`diag(2, 2, 0)` maps
/// `z` to `z`) instead of becoming NaN — and the scaling keeps huge or tiny transforms within
/// `f32` (the shaders normalise per fragment, so a uniform scale changes nothing). A transform
/// that collapses a whole plane (rank < 2) has no normal directions: the identity stands in
/// (its triangles have no area anyway).
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
        cofactor * (sign / largest)
    } else {
        DMat3::IDENTITY
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

    #[test]
    fn huge_and_degenerate_transforms_stay_finite() {
        let huge = DMat3::from_diagonal(DVec3::splat(1e200));
        assert!(normal_matrix(&huge).as_mat3().is_finite());
        let line = DMat3::from_diagonal(DVec3::new(1.0, 0.0, 0.0));
        assert_eq!(normal_matrix(&line), DMat3::IDENTITY);
        assert_eq!(normal_matrix(&DMat3::ZERO), DMat3::IDENTITY);
    }
}
