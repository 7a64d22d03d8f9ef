//! Tangents for normal mapping when a mesh has none: per-vertex sums of the triangles' UV
//! gradients (Lengyel's method), made orthogonal to the vertex normal, the bitangent's
//! handedness in `w`. glTF recommends MikkTSpace; for a triangle whose texture coordinates
//! are an affine map of its positions (every planar, unstretched mapping) the two agree, and
//! they differ only in how sharp UV seams share a vertex (see `docs/gltf.md`).

use glam::{DVec2, DVec3, Vec2, Vec3, Vec4};

/// The vertex data tangents are made from (a mesh's, borrowed).
#[derive(Clone, Copy)]
pub struct Geometry<'a> {
    /// Vertex positions.
    pub positions: &'a [Vec3],
    /// Unit vertex normals, one per position.
    pub normals: &'a [Vec3],
    /// Texture coordinates, one per position (or empty: every tangent is a fallback one).
    pub uvs: &'a [Vec2],
    /// Triangle list.
    pub indices: &'a [u32],
}

/// One tangent per vertex.
pub fn generate(mesh: Geometry<'_>) -> Vec<Vec4> {
    let n = mesh.positions.len();
    let (mut tan, mut bit) = (vec![DVec3::ZERO; n], vec![DVec3::ZERO; n]);
    for tri in mesh.indices.chunks_exact(3) {
        let [a, b, c] = [tri[0], tri[1], tri[2]].map(|i| i as usize);
        let uv = |i: usize| mesh.uvs.get(i).map_or(DVec2::ZERO, |t| t.as_dvec2());
        let p = |i: usize| mesh.positions[i].as_dvec3();
        let (e1, e2) = (p(b) - p(a), p(c) - p(a));
        let (d1, d2) = (uv(b) - uv(a), uv(c) - uv(a));
        let det = d1.x * d2.y - d2.x * d1.y;
        if det == 0.0 || !det.is_finite() {
            continue;
        }
        // (e1·d2.y − e2·d1.y) / det, times |det|: each triangle weighs by its position area
        // (as normals do), not by the inverse of its UV area.
        let sign = det.signum();
        let t = (e1 * d2.y - e2 * d1.y) * sign;
        let bt = (e2 * d1.x - e1 * d2.x) * sign;
        for i in [a, b, c] {
            tan[i] += t;
            bit[i] += bt;
        }
    }
    (0..n)
        .map(|i| orthogonal(mesh.normals[i].as_dvec3(), tan[i], bit[i]))
        .collect()
}

/// Given tangents made unit and orthogonal to their normals; unusable ones (zero, parallel
/// to the normal, not finite) replaced by generated ones, and `w` made ±1.
pub fn repair(mesh: Geometry<'_>, given: Vec<Vec4>) -> Vec<Vec4> {
    let mut generated: Option<Vec<Vec4>> = None;
    given
        .into_iter()
        .enumerate()
        .map(|(i, t)| {
            let normal = mesh.normals[i].as_dvec3();
            let v = t.truncate().as_dvec3();
            let v = v - normal * normal.dot(v);
            match v.try_normalize().filter(|_| t.is_finite()) {
                Some(v) => v.as_vec3().extend(if t.w < 0.0 { -1.0 } else { 1.0 }),
                None => generated.get_or_insert_with(|| generate(mesh))[i],
            }
        })
        .collect()
}

/// The tangent orthogonal to `normal` from summed gradients; any direction orthogonal to the
/// normal when the sums have none.
fn orthogonal(normal: DVec3, t: DVec3, b: DVec3) -> Vec4 {
    let v = (t - normal * normal.dot(t)).try_normalize().unwrap_or_else(|| {
        // Any axis not parallel to the normal.
        let axis = if normal.x.abs() < 0.9 { DVec3::X } else { DVec3::Y };
        (axis - normal * normal.dot(axis)).normalize()
    });
    let w = if normal.cross(v).dot(b) < 0.0 { -1.0 } else { 1.0 };
    Vec3::new(v.x as f32, v.y as f32, v.z as f32).extend(w)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::Mesh;

    #[test]
    fn a_plane_mapped_along_its_axes_gets_the_u_direction_and_its_handedness() {
        let positions = vec![Vec3::ZERO, Vec3::X, Vec3::new(1.0, 1.0, 0.0), Vec3::Y];
        // v grows downwards on the image: along −Y here, so the bitangent is −(N × T).
        let uvs = vec![
            Vec2::new(0.0, 1.0),
            Vec2::new(1.0, 1.0),
            Vec2::new(1.0, 0.0),
            Vec2::new(0.0, 0.0),
        ];
        let m = Mesh::new(positions, vec![], uvs, vec![0, 1, 2, 0, 2, 3]).unwrap();
        let m = Geometry {
            positions: &m.positions,
            normals: &m.normals,
            uvs: &m.uvs,
            indices: &m.indices,
        };
        for t in generate(m) {
            assert!((t.truncate() - Vec3::X).length() < 1e-6, "{t}");
            assert_eq!(t.w, -1.0);
        }
        let repaired = repair(m, vec![Vec4::new(2.0, 0.0, 5.0, 3.0), Vec4::ZERO, Vec4::NAN, Vec4::X]);
        assert_eq!(repaired[0], Vec4::new(1.0, 0.0, 0.0, 1.0));
        assert_eq!(repaired[1], Vec4::new(1.0, 0.0, 0.0, -1.0));
        assert_eq!(repaired[2], Vec4::new(1.0, 0.0, 0.0, -1.0));
    }
}
