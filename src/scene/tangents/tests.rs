use std::f64::consts::PI;

use super::*;
use crate::scene::Mesh;

fn geometry(m: &Mesh) -> Geometry<'_> {
    Geometry {
        positions: &m.positions,
        normals: &m.normals,
        uvs: &m.uvs,
        indices: &m.indices,
    }
}

/// The unit square in z = 0 facing +Z, texture coordinates `uv(x, y)` at its corners.
fn square(uv: impl Fn(f32, f32) -> Vec2) -> Mesh {
    let positions = vec![Vec3::ZERO, Vec3::X, Vec3::new(1.0, 1.0, 0.0), Vec3::Y];
    let uvs = positions.iter().map(|p| uv(p.x, p.y)).collect();
    Mesh::new(positions, vec![], uvs, vec![0, 1, 2, 0, 2, 3]).unwrap()
}

fn assert_all(tangents: &[Vec4], want: Vec4) {
    for t in tangents {
        assert!((*t - want).length() < 1e-6, "{t} is not {want}");
    }
}

#[test]
fn a_plane_gets_the_u_direction_and_gltf_handedness_mirrors_flip_w() {
    // u along +x, v down the image (−y): unmirrored, so B = N × T = +y points up the image
    // (the normal map's +Y) and w = +1.
    let upright = generate_corners(geometry(&square(|x, y| Vec2::new(x, 1.0 - y))));
    assert_eq!(upright.fallbacks, 0);
    assert_all(&upright.tangents, Vec4::new(1.0, 0.0, 0.0, 1.0));
    // v mirrored (down the image is +y): the same tangent, the other hand.
    let v_mirrored = generate_corners(geometry(&square(Vec2::new)));
    assert_all(&v_mirrored.tangents, Vec4::new(1.0, 0.0, 0.0, -1.0));
    // u mirrored: the tangent turns to −x and the hand flips.
    let u_mirrored = generate_corners(geometry(&square(|x, y| Vec2::new(1.0 - x, 1.0 - y))));
    assert_all(&u_mirrored.tangents, Vec4::new(-1.0, 0.0, 0.0, -1.0));
    // Stretched and shifted, still upright: the direction and hand do not change.
    let stretched = generate_corners(geometry(&square(|x, y| {
        Vec2::new(3.0 * x + 7.0, 0.5 - 2.0 * y)
    })));
    assert_all(&stretched.tangents, Vec4::new(1.0, 0.0, 0.0, 1.0));
}

#[test]
fn given_tangents_are_repaired_and_unusable_ones_generated() {
    let m = square(|x, y| Vec2::new(x, 1.0 - y));
    let given = vec![
        Vec4::new(2.0, 0.0, 5.0, 3.0),
        Vec4::ZERO,
        Vec4::NAN,
        Vec4::Z,
    ];
    let repaired = repair(geometry(&m), given);
    assert_eq!(repaired[0], Vec4::new(1.0, 0.0, 0.0, 1.0));
    assert_eq!(repaired[1], Vec4::new(1.0, 0.0, 0.0, 1.0));
    assert_eq!(repaired[2], Vec4::new(1.0, 0.0, 0.0, 1.0));
    assert_eq!(repaired[3], Vec4::new(1.0, 0.0, 0.0, 1.0));
}

/// A unit UV sphere: u = longitude φ / 2π (eastwards), v = colatitude θ / π (down the image is
/// southwards), seen from outside unmirrored; the seam's vertices doubled, triangles
/// counter-clockwise from outside.
fn uv_sphere(segments: usize, rings: usize) -> Mesh {
    let (mut positions, mut uvs) = (Vec::new(), Vec::new());
    for i in 0..=rings {
        for j in 0..=segments {
            let (u, v) = (j as f64 / segments as f64, i as f64 / rings as f64);
            let (theta, phi) = (PI * v, 2.0 * PI * u);
            let p = DVec3::new(
                theta.sin() * phi.cos(),
                theta.sin() * phi.sin(),
                theta.cos(),
            );
            positions.push(p.as_vec3());
            uvs.push(Vec2::new(u as f32, v as f32));
        }
    }
    let mut indices = Vec::new();
    for i in 0..rings as u32 {
        for j in 0..segments as u32 {
            let a = i * (segments as u32 + 1) + j;
            let (b, c) = (a + 1, a + segments as u32 + 1);
            indices.extend([a, c, c + 1, a, c + 1, b]);
        }
    }
    let normals = positions.iter().map(|p| p.normalize()).collect();
    Mesh::new(positions, normals, uvs, indices).unwrap()
}

#[test]
fn a_uv_sphere_gets_unit_orthogonal_tangents_along_the_longitude() {
    let m = uv_sphere(32, 16);
    let got = generate_corners(geometry(&m));
    // Cosines to the analytic direction: off the seam, and on it (where each side sees only
    // its own faces, half a segment away).
    let (mut inner, mut seam): (f64, f64) = (1.0, 1.0);
    for (&i, t) in m.indices.iter().zip(&got.tangents) {
        let (p, n) = (
            m.positions[i as usize].as_dvec3(),
            m.normals[i as usize].as_dvec3(),
        );
        let v = t.truncate().as_dvec3();
        assert!((v.length() - 1.0).abs() < 1e-5, "{t} is not unit");
        assert!(v.dot(n).abs() < 1e-5, "{t} is not orthogonal to {n}");
        assert!(t.w == 1.0 || t.w == -1.0, "{t}");
        if p.z.abs() > 0.999 {
            continue; // the poles: no longitude direction
        }
        // dP/du ∝ (−sin φ, cos φ, 0); unmirrored, so w = +1.
        let want = DVec3::new(-p.y, p.x, 0.0).normalize();
        let u = m.uvs[i as usize].x;
        let worst = if u == 0.0 || u == 1.0 {
            &mut seam
        } else {
            &mut inner
        };
        *worst = worst.min(v.dot(want));
        assert_eq!(t.w, 1.0, "at {p}");
    }
    // A 32 × 16 sphere's faces span 11.25° of longitude.
    assert!(
        inner > 1f64.to_radians().cos(),
        "worst cosine {inner} off the seam"
    );
    assert!(
        seam > 5.625f64.to_radians().cos(),
        "worst cosine {seam} on the seam"
    );
}

/// True when `t` is finite, unit, `w` ±1 and orthogonal to `normal` (when that is unit).
fn sound(t: Vec4, normal: Option<&Vec3>) -> bool {
    let v = t.truncate();
    let orthogonal = match normal {
        Some(n) if n.is_finite() && (n.length() - 1.0).abs() < 1e-3 => v.dot(*n).abs() < 1e-5,
        _ => true,
    };
    t.is_finite() && (v.length() - 1.0).abs() < 1e-5 && t.w.abs() == 1.0 && orthogonal
}

#[test]
fn degenerate_and_non_finite_input_gives_finite_unit_tangents() {
    let positions = vec![
        Vec3::ZERO,
        Vec3::X,
        Vec3::Y,
        Vec3::NAN,
        Vec3::splat(f32::INFINITY),
        Vec3::splat(3e38),
        Vec3::new(-3e38, 3e38, 0.0),
        Vec3::X,
    ];
    let normals = vec![
        Vec3::Z,
        Vec3::Z,
        Vec3::Z,
        Vec3::Z,
        Vec3::NAN,
        Vec3::ZERO,
        Vec3::X,
        Vec3::new(0.0, 0.0, 1e30),
    ];
    let uvs = vec![
        Vec2::ZERO,
        Vec2::ZERO,
        Vec2::ZERO,
        Vec2::X,
        Vec2::NAN,
        Vec2::Y,
        Vec2::splat(f32::MAX),
        Vec2::ONE,
    ];
    let indices = vec![
        0, 1, 2, // zero-area texture coordinates
        0, 0, 0, // a point
        0, 1, 3, // a NaN position
        1, 2, 4, // infinite position, NaN normal and uv
        0, 5, 6, // huge positions, a zero normal
        2, 6, 7, // a huge normal, huge uv
        0, 1, 9, // an index out of range (the struct is public)
    ];
    let mesh = Geometry {
        positions: &positions,
        normals: &normals,
        uvs: &uvs,
        indices: &indices,
    };
    let got = generate_corners(mesh);
    assert_eq!(got.tangents.len(), indices.len());
    for (&i, &t) in indices.iter().zip(&got.tangents) {
        assert!(sound(t, normals.get(i as usize)), "corner of {i}: {t}");
    }
    for (i, &t) in generate(mesh).iter().enumerate() {
        assert!(sound(t, normals.get(i)), "vertex {i}: {t}");
    }
    // MikkTSpace serves only the zero-area triangle and the point, and has nothing for them.
    assert_eq!(got.fallbacks, indices.len());
}

#[test]
fn hostile_counts_get_the_fallback_within_bounds() {
    // A fan of 20 000 triangles around one vertex: MikkTSpace's grouping would recurse once per
    // triangle; each gets the fallback instead (its UV gradient: +x, upright).
    let fan = 20_000u32;
    let mut positions = vec![Vec3::ZERO];
    let mut uvs = vec![Vec2::ZERO];
    for k in 0..=fan {
        let a = k as f32 / fan as f32 * 6.0;
        positions.push(Vec3::new(a.cos(), a.sin(), 0.0));
        uvs.push(Vec2::new(a.cos(), -a.sin()));
    }
    let indices: Vec<u32> = (1..=fan).flat_map(|k| [0, k, k + 1]).collect();
    let m = Mesh::new(positions, vec![], uvs, indices).unwrap();
    let got = generate_corners(geometry(&m));
    assert_eq!(got.fallbacks, m.indices.len());
    assert_all(&got.tangents, Vec4::new(1.0, 0.0, 0.0, 1.0));

    // More triangles than MikkTSpace is given, all on one point.
    let over = MAX_TRIANGLES + 1;
    let indices: Vec<u32> = (0..3 * over as u32).map(|k| k % 3).collect();
    let (positions, normals, uvs) = (vec![Vec3::ONE; 3], vec![Vec3::Z; 3], vec![Vec2::ONE; 3]);
    let mesh = Geometry {
        positions: &positions,
        normals: &normals,
        uvs: &uvs,
        indices: &indices,
    };
    let got = generate_corners(mesh);
    assert_eq!(got.fallbacks, indices.len());
    assert!(got.tangents.iter().all(|&t| sound(t, Some(&Vec3::Z))));
}

#[test]
fn a_mirrored_seam_through_shared_vertices_splits_them() {
    // Two unit squares side by side, u = |x| (mirrored at x = 0), v down the image; the two
    // vertices on x = 0 are shared by both halves.
    let positions = [
        (-1.0, 0.0),
        (0.0, 0.0),
        (1.0, 0.0),
        (-1.0, 1.0),
        (0.0, 1.0),
        (1.0, 1.0),
    ]
    .map(|(x, y)| Vec3::new(x, y, 0.0))
    .to_vec();
    let uvs = positions
        .iter()
        .map(|p| Vec2::new(p.x.abs(), 1.0 - p.y))
        .collect();
    let indices = vec![0, 1, 4, 0, 4, 3, 1, 2, 5, 1, 5, 4];
    let m = Mesh::new(positions, vec![], uvs, indices).unwrap();
    let (m, fallbacks) = m.with_generated_tangents().unwrap();
    assert_eq!(fallbacks, 0);
    assert_eq!(m.positions.len(), 8, "the two seam vertices are split");
    assert_eq!((m.normals.len(), m.uvs.len(), m.tangents.len()), (8, 8, 8));
    for tri in m.indices.chunks_exact(3) {
        let centre: f32 = tri.iter().map(|&i| m.positions[i as usize].x).sum();
        // Right half: upright (+x, w = +1); left half: mirrored (−x, w = −1).
        let want = if centre > 0.0 {
            Vec4::new(1.0, 0.0, 0.0, 1.0)
        } else {
            Vec4::new(-1.0, 0.0, 0.0, -1.0)
        };
        for &i in tri {
            assert!((m.tangents[i as usize] - want).length() < 1e-6);
            assert_eq!(m.uvs[i as usize].x, m.positions[i as usize].x.abs());
        }
    }
}
