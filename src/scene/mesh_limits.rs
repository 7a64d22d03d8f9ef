//! The limits a mesh's values keep, and the checks that name the first value past them.

use glam::{Vec2, Vec3};

use super::SceneError;

/// Largest object-space vertex coordinate. Vertices are f32 (their spacing there is 64 units)
/// and a model framed at that size still leaves the camera inside its own limit
/// ([`super::camera::MAX_CAMERA_COORD`]); coordinates near f32's limit made lights overflow
/// and were reported as a bad light intensity.
pub const MAX_VERTEX_COORD: f32 = 1e9;

/// Largest texture coordinate, and texture-transform offset or scale: far past any tiling (an
/// f32 there has no fraction left), and small enough that a transformed coordinate and its
/// differences across a triangle stay finite (past ±1.7e38 they overflowed, the texture
/// lookup gave NaN and the whole surface drew black).
pub const MAX_TEXCOORD: f32 = 1e9;

/// Positions finite and within [`MAX_VERTEX_COORD`]; errors name `{field}.positions[i]`.
pub(super) fn check_positions(positions: &[Vec3], field: &str) -> Result<(), SceneError> {
    if let Some(i) = positions.iter().position(|p| !p.is_finite()) {
        return Err(SceneError::invalid(
            format!("{field}.positions[{i}]"),
            "must be finite".to_string(),
        ));
    }
    if let Some(i) = positions
        .iter()
        .position(|p| p.abs().max_element() > MAX_VERTEX_COORD)
    {
        return Err(SceneError::invalid(
            format!("{field}.positions[{i}]"),
            format!(
                "must be within ±{MAX_VERTEX_COORD:e} (object space is f32; place far objects \
                 with their transform, which is f64)"
            ),
        ));
    }
    Ok(())
}

/// Texture coordinates finite and within [`MAX_TEXCOORD`]; errors name `{field}[i]`.
pub(super) fn check_uvs(uvs: &[Vec2], field: &str) -> Result<(), SceneError> {
    if let Some(i) = uvs
        .iter()
        .position(|t| !(t.is_finite() && t.abs().max_element() <= MAX_TEXCOORD))
    {
        return Err(SceneError::invalid(
            format!("{field}[{i}]"),
            format!("must be finite and within ±{MAX_TEXCOORD:e}"),
        ));
    }
    Ok(())
}

/// Whole triangles of indices, each below `n` (the vertex count); errors name `field`.
pub(super) fn check_indices(indices: &[u32], n: usize, field: &str) -> Result<(), SceneError> {
    if !indices.len().is_multiple_of(3) {
        return Err(SceneError::invalid(
            field,
            format!(
                "{} indices is not a whole number of triangles",
                indices.len()
            ),
        ));
    }
    if let Some(bad) = indices.iter().find(|&&i| i as usize >= n) {
        return Err(SceneError::invalid(
            field,
            format!("index {bad} out of range for {n} vertices"),
        ));
    }
    Ok(())
}

pub(super) fn check_per_vertex(field: &str, got: usize, n: usize) -> Result<(), SceneError> {
    if got != n {
        return Err(SceneError::invalid(
            field,
            format!("{got} values for {n} vertices"),
        ));
    }
    Ok(())
}
