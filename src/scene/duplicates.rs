//! Exact duplicate triangles: the same three corners (position, normal and texture coordinate
//! alike) as an earlier triangle of the mesh, in any rotation or winding (in any rotation
//! alone on a single-sided surface, whose two windings are its two sides). On an opaque
//! surface they add nothing to the picture, only overdraw (a 16 MB OBJ can repeat one
//! triangle 2 M times). Transparent surfaces keep them (each copy blends once more).

use super::{Material, Mesh};

/// One corner as bits: position, normal, texture coordinate, colour, tangent (zero without
/// them).
type Corner = [u32; 18];

/// `mesh` without its duplicate triangles when `material` is opaque, and a warning giving
/// their count when there were any (`what` names the object).
pub fn drop_from_opaque(
    mut mesh: Mesh,
    material: &Material,
    what: impl FnOnce() -> String,
) -> (Mesh, Option<String>) {
    if material.is_transparent() {
        return (mesh, None);
    }
    let dropped = drop_duplicate_triangles(&mut mesh, material.double_sided);
    let warning = (dropped > 0).then(|| {
        format!(
            "{}: {dropped} duplicate triangles dropped (the same corners as an earlier one; \
             they add nothing to the picture)",
            what()
        )
    });
    (mesh, warning)
}

/// Drops every triangle whose corners equal an earlier one's (in the same winding unless
/// `double_sided`), keeping the order of the rest; returns how many were dropped. Needs 16
/// bytes a triangle of scratch.
pub fn drop_duplicate_triangles(mesh: &mut Mesh, double_sided: bool) -> usize {
    let triangles = mesh.triangle_count();
    if triangles < 2 {
        return 0;
    }
    // Randomly keyed, so no file can be made to collide.
    use std::hash::BuildHasher;
    let state = std::collections::hash_map::RandomState::new();
    let mut keyed: Vec<(u64, u32)> = (0..triangles as u32)
        .map(|t| (state.hash_one(canonical(mesh, t, double_sided)), t))
        .collect();
    keyed.sort_unstable();
    let mut dropped = vec![false; triangles];
    // The distinct triangles of one hash (one, unless hashes collide), earliest first.
    let mut kept: Vec<[Corner; 3]> = Vec::new();
    for run in keyed.chunk_by(|a, b| a.0 == b.0) {
        kept.clear();
        for &(_, t) in run {
            let corners = canonical(mesh, t, double_sided);
            if kept.contains(&corners) {
                dropped[t as usize] = true;
            } else {
                kept.push(corners);
            }
        }
    }
    let count = dropped.iter().filter(|&&d| d).count();
    if count > 0 {
        let mut t = 0;
        mesh.indices.retain(|_| {
            let keep = !dropped[t / 3];
            t += 1;
            keep
        });
        mesh.indices.shrink_to_fit();
    }
    count
}

/// The triangle's corners, rotated (and with `any_winding` mirrored) to the smallest of its
/// three (six) orders, so equal triangles compare equal whichever corner (and winding) they
/// start with.
fn canonical(mesh: &Mesh, triangle: u32, any_winding: bool) -> [Corner; 3] {
    let i = 3 * triangle as usize;
    let corner = |k: usize| -> Corner {
        let v = mesh.indices[i + k] as usize;
        let p = mesh.positions[v];
        let n = mesh.normals.get(v).copied().unwrap_or_default();
        let uv = mesh.uvs.get(v).copied().unwrap_or_default();
        let uv1 = mesh.second_uvs.get(v).copied().unwrap_or_default();
        let c = mesh.colors.get(v).copied().unwrap_or_default();
        let t = mesh.tangents.get(v).copied().unwrap_or_default();
        [
            p.x, p.y, p.z, n.x, n.y, n.z, uv.x, uv.y, uv1.x, uv1.y, c.x, c.y, c.z, c.w, t.x, t.y,
            t.z, t.w,
        ]
        .map(f32::to_bits)
    };
    let [a, b, c] = [corner(0), corner(1), corner(2)];
    let orders = [
        [a, b, c],
        [b, c, a],
        [c, a, b],
        [a, c, b],
        [c, b, a],
        [b, a, c],
    ];
    let orders = if any_winding {
        &orders[..]
    } else {
        &orders[..3]
    };
    orders.iter().copied().min().expect("three orders")
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::Vec3;

    #[test]
    fn exact_duplicates_in_any_order_go_and_the_rest_stay_in_order() {
        let p = vec![
            Vec3::ZERO,
            Vec3::X,
            Vec3::Y,
            Vec3::Z,
            Vec3::X, // the same position as vertex 1 under another index
        ];
        let normals = vec![Vec3::Z; 5];
        #[rustfmt::skip]
        let indices = vec![
            0, 1, 2, // kept
            1, 2, 0, // rotated: dropped
            0, 3, 1, // kept
            2, 1, 0, // reversed winding: dropped
            0, 4, 2, // other index, same corners: dropped
            0, 1, 3, // the third one reversed: dropped
            3, 2, 1, // kept
        ];
        // Built as a struct: `Mesh::new` would wind each triangle towards its normals.
        let mesh = Mesh {
            positions: p,
            normals,
            indices,
            ..Mesh::default()
        };
        let mut both = mesh.clone();
        assert_eq!(drop_duplicate_triangles(&mut both, true), 4);
        assert_eq!(both.indices, [0, 1, 2, 0, 3, 1, 3, 2, 1]);
        assert_eq!(drop_duplicate_triangles(&mut both, true), 0);
        // Single-sided: a reversed copy is the other side, and stays.
        let mut front = mesh;
        assert_eq!(drop_duplicate_triangles(&mut front, false), 2);
        assert_eq!(front.indices, [0, 1, 2, 0, 3, 1, 2, 1, 0, 0, 1, 3, 3, 2, 1]);
    }

    #[test]
    fn another_normal_or_texture_coordinate_is_another_triangle() {
        let p = vec![Vec3::ZERO, Vec3::X, Vec3::Y, Vec3::ZERO];
        let normals = vec![Vec3::Z, Vec3::Z, Vec3::Z, Vec3::X];
        let mut mesh = Mesh::new(p, normals, vec![], vec![0, 1, 2, 3, 1, 2]).unwrap();
        assert_eq!(drop_duplicate_triangles(&mut mesh, true), 0);
        let uvs = vec![
            glam::Vec2::ZERO,
            glam::Vec2::X,
            glam::Vec2::Y,
            glam::Vec2::ONE,
        ];
        let p = vec![Vec3::ZERO, Vec3::X, Vec3::Y, Vec3::ZERO];
        let mut mesh = Mesh::new(p, vec![Vec3::Z; 4], uvs, vec![0, 1, 2, 3, 1, 2]).unwrap();
        assert_eq!(drop_duplicate_triangles(&mut mesh, true), 0);
    }
}
