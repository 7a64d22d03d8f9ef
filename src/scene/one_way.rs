//! Whether a mesh's triangles lie in one plane and face one way (a glass pane, a particle or
//! foliage card): from any eye they all show the same side, which lets a transparent one that
//! shows both sides be drawn once without culling instead of once a side.

use glam::DVec3;

use super::Mesh;

/// Farthest a vertex may lie off the plane, as a part of the mesh's extent.
const OFF_PLANE: f64 = 1e-7;

/// Least cosine between a triangle's normal and the first one's.
const SAME_WAY: f64 = 1.0 - 1e-9;

impl Mesh {
    /// True when the mesh has a triangle, and every triangle of nonzero area lies in the first
    /// one's plane and faces the same way. A near-degenerate triangle whose rounded normal
    /// strays makes it false: the caller then draws it as any other mesh.
    pub fn faces_one_way(&self) -> bool {
        let Some(bounds) = self.bounds() else {
            return false;
        };
        let tolerance = OFF_PLANE * (bounds.max - bounds.min).length();
        let at = |i: u32| self.positions[i as usize].as_dvec3();
        let mut plane: Option<(DVec3, f64)> = None;
        for t in self.indices.chunks_exact(3) {
            let [a, b, c] = [at(t[0]), at(t[1]), at(t[2])];
            let normal = (b - a).cross(c - a).normalize_or_zero();
            if normal == DVec3::ZERO {
                continue;
            }
            let Some((n, offset)) = plane else {
                plane = Some((normal, normal.dot(a)));
                continue;
            };
            let off = |p: DVec3| (n.dot(p) - offset).abs() > tolerance;
            if normal.dot(n) < SAME_WAY || [a, b, c].into_iter().any(off) {
                return false;
            }
        }
        plane.is_some()
    }
}

#[cfg(test)]
mod tests {
    use glam::{Vec2, Vec3};

    use crate::scene::Mesh;

    /// A mesh of the quads `z` gives the heights of (each two triangles), wound `flip`ped or
    /// not.
    fn quads(zs: &[(f32, bool)]) -> Mesh {
        let (mut positions, mut indices) = (Vec::new(), Vec::new());
        for &(z, flip) in zs {
            let base = positions.len() as u32;
            positions
                .extend([[0., 0.], [1., 0.], [1., 1.], [0., 1.]].map(|[x, y]| Vec3::new(x, y, z)));
            let mut tris = [[0, 1, 2], [0, 2, 3]];
            if flip {
                tris.iter_mut().for_each(|t| t.swap(1, 2));
            }
            indices.extend(tris.iter().flatten().map(|i| base + i));
        }
        let n = positions.len();
        Mesh::new_as_wound(positions, vec![Vec3::Z; n], vec![Vec2::ZERO; n], indices).unwrap()
    }

    #[test]
    fn one_plane_one_way_is_told_apart_from_two_sides_and_two_planes() {
        assert!(quads(&[(0.0, false)]).faces_one_way());
        assert!(
            quads(&[(0.0, false), (0.0, false)]).faces_one_way(),
            "coplanar"
        );
        assert!(
            !quads(&[(0.0, false), (0.0, true)]).faces_one_way(),
            "back to back"
        );
        assert!(
            !quads(&[(0.0, false), (0.5, false)]).faces_one_way(),
            "stacked"
        );
        let mut degenerate = quads(&[(0.0, false)]);
        degenerate.positions.push(Vec3::new(0.0, 0.0, 9.0));
        degenerate.normals.push(Vec3::Z);
        degenerate.uvs.push(Vec2::ZERO);
        degenerate.indices.extend([0, 4, 4]);
        assert!(
            degenerate.faces_one_way(),
            "a triangle of no area draws nothing"
        );
        let empty = Mesh::new(vec![], vec![], vec![], vec![]).unwrap();
        assert!(!empty.faces_one_way());
    }
}
