//! Deferred's light proxy: a closed unit sphere around each light, its poles on the view's z
//! axis.
//!
//! Closed means each corner is one vertex, whatever triangles meet there: a UV sphere's pole
//! and first meridian repeated (one copy per segment, a little apart in `f32`: `sin π` is not
//! 0) left slivers and overlaps along its seams, which a narrow view magnifies, and additive
//! blending then counted the light twice along lines (a head lamp in an orthographic view
//! 0.82 high: 47/255 from forward).

use std::f64::consts::PI;

use glam::Vec3;

use crate::scene::Mesh;

/// Segments around the axis.
const SEGMENTS: u32 = 16;

/// Bands from pole to pole. Odd, so no corner lies on the plane through the centre across the
/// view (the nearest lie 0.17 of the radius off it): a light at the eye, a head lamp, would put
/// such corners at clip w = 0, and SwiftShader then dropped the triangles they start
/// (docs/drivers.md).
const BANDS: u32 = 9;

/// The proxy sphere, counter-clockwise seen from outside: a pole at +z, a pole at −z, and
/// `BANDS − 1` rings of `SEGMENTS` corners between them.
pub(super) fn unit_sphere() -> Mesh {
    let rings = BANDS - 1;
    let mut positions = vec![Vec3::Z, Vec3::NEG_Z];
    for ring in 1..=rings {
        let theta = f64::from(ring) * PI / f64::from(BANDS);
        for segment in 0..SEGMENTS {
            let phi = f64::from(segment) * 2.0 * PI / f64::from(SEGMENTS);
            let p = [
                theta.sin() * phi.cos(),
                theta.sin() * phi.sin(),
                theta.cos(),
            ];
            positions.push(Vec3::from(p.map(|c| c as f32)));
        }
    }
    let corner = |ring: u32, segment: u32| 2 + (ring - 1) * SEGMENTS + segment % SEGMENTS;
    let (north, south) = (0, 1);
    let mut indices = Vec::new();
    for s in 0..SEGMENTS {
        indices.extend([north, corner(1, s), corner(1, s + 1)]);
        for ring in 1..rings {
            let (a, b) = (corner(ring, s), corner(ring, s + 1));
            let (c, d) = (corner(ring + 1, s), corner(ring + 1, s + 1));
            indices.extend([a, c, b, b, c, d]);
        }
        indices.extend([south, corner(rings, s + 1), corner(rings, s)]);
    }
    let normals = positions.clone();
    Mesh::new(positions, normals, vec![], indices).expect("a valid sphere")
}

#[cfg(test)]
mod tests {
    use std::collections::HashMap;

    use super::*;

    /// Every edge is two triangles', once each way (closed, consistently wound); every
    /// triangle faces outwards; no corner lies within 0.17 of the plane z = 0.
    #[test]
    fn the_proxy_is_closed_faces_outwards_and_keeps_off_the_middle_plane() {
        let sphere = unit_sphere();
        let mut edges: HashMap<(u32, u32), u32> = HashMap::new();
        for t in sphere.indices.chunks_exact(3) {
            for k in 0..3 {
                *edges.entry((t[k], t[(k + 1) % 3])).or_default() += 1;
            }
            let [a, b, c] = [t[0], t[1], t[2]].map(|i| sphere.positions[i as usize]);
            let centre = (a + b + c) / 3.0;
            assert!(
                (b - a).cross(c - a).dot(centre) > 0.0,
                "{t:?} faces inwards"
            );
        }
        for (&(a, b), &n) in &edges {
            assert_eq!((n, edges.get(&(b, a))), (1, Some(&1)), "edge {a}–{b}");
        }
        let triangles = sphere.indices.len() / 3;
        assert_eq!(triangles as u32, 2 * SEGMENTS * (BANDS - 1));
        for p in &sphere.positions {
            assert!((p.length() - 1.0).abs() < 1e-6, "{p}");
            assert!(p.z.abs() > 0.17, "{p} lies near the middle plane");
        }
    }
}
