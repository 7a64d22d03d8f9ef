//! Consistent winding for a mesh without normals (an OBJ without `vn`): the renderer tells
//! the side seen by the winding, so a triangle listed against its neighbours would be shaded
//! as a back face. Neighbours across an edge that two triangles share must run along it in
//! opposite directions; each connected part keeps the winding most of its triangles have.

use std::collections::HashMap;

use glam::Vec3;

/// Turns round the triangles of `indices` that run along a shared edge the same way as their
/// neighbour, keeping in each connected part the winding the majority has; returns how many
/// were turned. Vertices at one position are one vertex here (a texture seam splits them),
/// and an edge of three or more triangles joins none of them.
pub(super) fn orient_consistently(positions: &[Vec3], indices: &mut [u32]) -> usize {
    let triangles = indices.len() / 3;
    let corner = welded_vertices(positions);
    // Every edge as (its welded ends, lower first; its triangle times 2, plus 1 where that
    // runs from the lower end to the higher): 12 bytes an edge. Sorted, so that a shared
    // edge's triangles lie together.
    let mut edges: Vec<[u32; 3]> = Vec::with_capacity(indices.len());
    for t in 0..triangles {
        let v = [0, 1, 2].map(|k| corner[indices[3 * t + k] as usize]);
        for k in 0..3 {
            let (a, b) = (v[k], v[(k + 1) % 3]);
            if a != b {
                edges.push([a.min(b), a.max(b), 2 * t as u32 + u32::from(a < b)]);
            }
        }
    }
    edges.sort_unstable_by_key(|&[a, b, _]| (a, b));
    // Up to one neighbour per edge: (triangle, whether it runs the same way), `NONE` for none.
    const NONE: (u32, bool) = (u32::MAX, false);
    let mut neighbours = vec![[NONE; 3]; triangles];
    let mut link = |t: u32, n: (u32, bool)| {
        if let Some(slot) = neighbours[t as usize].iter_mut().find(|s| s.0 == u32::MAX) {
            *slot = n;
        }
    };
    for along in edges.chunk_by(|x, y| x[..2] == y[..2]) {
        // An edge of one triangle is a border; of three or more, it joins none of them.
        if let [[_, _, s], [_, _, t]] = *along {
            // Consistent neighbours run along the edge in opposite directions.
            let same_way = (s & 1) == (t & 1);
            link(s / 2, (t / 2, same_way));
            link(t / 2, (s / 2, same_way));
        }
    }
    drop(edges);
    let mut turn: Vec<Option<bool>> = vec![None; triangles];
    let mut part = Vec::new();
    let mut turned = 0;
    for start in 0..triangles {
        if turn[start].is_some() {
            continue;
        }
        turn[start] = Some(false);
        part.clear();
        part.push(start as u32);
        let mut next = 0;
        while next < part.len() {
            let t = part[next] as usize;
            next += 1;
            let flipped = turn[t] == Some(true);
            for &(n, same_way) in neighbours[t].iter().filter(|n| n.0 != u32::MAX) {
                if turn[n as usize].is_none() {
                    turn[n as usize] = Some(flipped ^ same_way);
                    part.push(n);
                }
            }
        }
        let flips = part
            .iter()
            .filter(|&&t| turn[t as usize] == Some(true))
            .count();
        // The majority's winding stays.
        let turn_these = flips * 2 > part.len();
        for &t in &part {
            if (turn[t as usize] == Some(true)) != turn_these {
                indices.swap(3 * t as usize + 1, 3 * t as usize + 2);
                turned += 1;
            }
        }
    }
    turned
}

/// One number per vertex, equal for vertices at the same position (bit for bit).
fn welded_vertices(positions: &[Vec3]) -> Vec<u32> {
    let mut first: HashMap<[u32; 3], u32> = HashMap::with_capacity(positions.len());
    positions
        .iter()
        .enumerate()
        .map(|(i, p)| {
            *first
                .entry(p.to_array().map(f32::to_bits))
                .or_insert(i as u32)
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// An octahedron, its faces counter-clockwise seen from outside; vertex 6 repeats vertex
    /// 0's position (a texture seam) and the last face uses it.
    fn octahedron() -> (Vec<Vec3>, Vec<u32>) {
        let positions = vec![
            Vec3::X,
            -Vec3::X,
            Vec3::Y,
            -Vec3::Y,
            Vec3::Z,
            -Vec3::Z,
            Vec3::X,
        ];
        #[rustfmt::skip]
        let indices = vec![
            0, 2, 4, 2, 1, 4, 1, 3, 4, 3, 0, 4,
            2, 0, 5, 1, 2, 5, 3, 1, 5, 6, 3, 5,
        ];
        (positions, indices)
    }

    fn outward(positions: &[Vec3], indices: &[u32]) -> usize {
        indices
            .chunks_exact(3)
            .filter(|t| {
                let [a, b, c] = [t[0], t[1], t[2]].map(|i| positions[i as usize]);
                (b - a).cross(c - a).dot(a + b + c) > 0.0
            })
            .count()
    }

    #[test]
    fn a_triangle_listed_against_its_neighbours_is_turned_round() {
        let (positions, mut indices) = octahedron();
        for reversed in [0, 7] {
            let mut listed = indices.clone();
            listed.swap(3 * reversed + 1, 3 * reversed + 2);
            assert_eq!(orient_consistently(&positions, &mut listed), 1);
            assert_eq!(outward(&positions, &listed), 8, "face {reversed}");
        }
        // Consistent already: nothing turns, also inside out.
        assert_eq!(orient_consistently(&positions, &mut indices), 0);
        for t in indices.chunks_exact_mut(3) {
            t.swap(1, 2);
        }
        assert_eq!(orient_consistently(&positions, &mut indices), 0);
        assert_eq!(outward(&positions, &indices), 0);
    }

    #[test]
    fn the_majority_of_a_part_keeps_its_winding_and_parts_are_apart() {
        let (positions, indices) = octahedron();
        // Five faces listed inside out: those five stay, the other three turn.
        let mut listed = indices.clone();
        for t in 0..5 {
            listed.swap(3 * t + 1, 3 * t + 2);
        }
        assert_eq!(orient_consistently(&positions, &mut listed), 3);
        assert_eq!(outward(&positions, &listed), 0);
        // A second octahedron elsewhere, reversed whole, is a part of its own.
        let mut both_positions = positions.clone();
        both_positions.extend(positions.iter().map(|p| *p + Vec3::splat(5.0)));
        let mut both = indices.clone();
        let far = positions.len() as u32;
        both.extend(
            indices
                .chunks_exact(3)
                .flat_map(|t| [t[0] + far, t[2] + far, t[1] + far]),
        );
        assert_eq!(orient_consistently(&both_positions, &mut both), 0);
    }
}
