//! Tangents for normal mapping when a mesh has none: MikkTSpace (glTF 2.0 asks for it, as normal
//! maps are baked against it) through `bevy_mikktspace`, one tangent per triangle corner, the
//! bitangent's handedness in `w` as glTF defines it: `B = w·(N × T)` points up the image (−v).
//! Corners MikkTSpace cannot serve get the fallback of [`per_vertex_fallback`].

use std::collections::HashMap;

use glam::{DVec2, DVec3, Vec2, Vec3, Vec4};

/// Most triangles handed to MikkTSpace at once (its working memory is some hundred bytes a
/// corner); a larger mesh gets the fallback tangents.
pub const MAX_TRIANGLES: usize = 1 << 20;

/// Most triangle corners at one position handed to MikkTSpace: its vertex welding and grouping
/// cost grows with the square of that count, and its grouping recurses once per triangle around
/// a vertex; triangles touching a busier position get the fallback.
pub const MAX_CORNERS_AT_A_POSITION: usize = 256;

/// Largest coordinate (position or texture) handed to MikkTSpace, so its f32 products stay finite.
const MAX_COORD: f32 = 1e9;

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

/// Generated tangents, one per triangle corner (per index of [`Geometry::indices`]).
pub struct CornerTangents {
    /// Unit tangents orthogonal to their vertex normals, `w` ±1.
    pub tangents: Vec<Vec4>,
    /// How many corners got the fallback tangent instead of MikkTSpace's.
    pub fallbacks: usize,
}

/// MikkTSpace tangents for every triangle corner. Two corners sharing a vertex may differ
/// (a mirrored UV seam through shared vertices): the caller splits such vertices.
pub fn generate_corners(mesh: Geometry<'_>) -> CornerTangents {
    let faces = served_triangles(mesh);
    let mut mikk = Mikk {
        mesh,
        faces: &faces,
        out: vec![None; mesh.indices.len()],
    };
    if !faces.is_empty() {
        // The crate's error type has no variants yet; a future one leaves corners unserved.
        let _ = bevy_mikktspace::generate_tangents(&mut mikk);
    }
    let mut fallback: Option<Vec<Vec4>> = None;
    let mut fallbacks = 0;
    let tangents = mikk
        .out
        .iter()
        .zip(mesh.indices)
        .map(|(t, &i)| {
            t.unwrap_or_else(|| {
                fallbacks += 1;
                let per_vertex = fallback.get_or_insert_with(|| per_vertex_fallback(mesh));
                per_vertex
                    .get(i as usize)
                    .copied()
                    .unwrap_or(Vec4::new(1.0, 0.0, 0.0, 1.0))
            })
        })
        .collect();
    CornerTangents {
        tangents,
        fallbacks,
    }
}

/// One tangent per vertex: the MikkTSpace tangent of the vertex's first corner (a vertex used
/// by no triangle, the fallback one).
pub fn generate(mesh: Geometry<'_>) -> Vec<Vec4> {
    let corners = generate_corners(mesh);
    let mut out = per_vertex_fallback(mesh);
    let mut set = vec![false; out.len()];
    for (&i, &t) in mesh.indices.iter().zip(&corners.tangents) {
        let i = i as usize;
        if i < out.len() && !set[i] {
            (out[i], set[i]) = (t, true);
        }
    }
    out
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

/// The fallback, per vertex: the triangles' UV gradients summed (each weighted by its area) and
/// made orthogonal to the vertex normal (Lengyel's method; MikkTSpace's answer for unstretched
/// planar mappings); where they sum to nothing (zero-area UVs, no triangles, non-finite data),
/// any unit direction orthogonal to the normal, `w` = +1.
pub fn per_vertex_fallback(mesh: Geometry<'_>) -> Vec<Vec4> {
    let n = mesh.positions.len();
    let (mut tan, mut bit) = (vec![DVec3::ZERO; n], vec![DVec3::ZERO; n]);
    for tri in mesh.indices.chunks_exact(3) {
        let [a, b, c] = [tri[0], tri[1], tri[2]].map(|i| i as usize);
        if a.max(b).max(c) >= n {
            continue;
        }
        let uv = |i: usize| {
            mesh.uvs
                .get(i)
                .map_or(DVec2::ZERO, |&t| mikk_uv(t).as_dvec2())
        };
        let p = |i: usize| mesh.positions[i].as_dvec3();
        let (e1, e2) = (p(b) - p(a), p(c) - p(a));
        let (d1, d2) = (uv(b) - uv(a), uv(c) - uv(a));
        let det = d1.x * d2.y - d2.x * d1.y;
        // (e1·d2.y − e2·d1.y) / det, times |det|: weighted by the position area, not the UV's.
        let sign = det.signum();
        let t = (e1 * d2.y - e2 * d1.y) * sign;
        let bt = (e2 * d1.x - e1 * d2.x) * sign;
        if det == 0.0 || !(t.is_finite() && bt.is_finite()) {
            continue;
        }
        for i in [a, b, c] {
            tan[i] += t;
            bit[i] += bt;
        }
    }
    (0..n)
        .map(|i| {
            let normal = mesh.normals.get(i).map_or(DVec3::Z, |v| v.as_dvec3());
            orthogonal(normal, tan[i], bit[i])
        })
        .collect()
}

/// glTF's texture coordinates as MikkTSpace takes them: v turned to point up the image, so
/// that its bitangent is the direction of the normal map's +Y ("up", glTF says). Negation is
/// exact, unlike `1 − v`.
fn mikk_uv(uv: Vec2) -> Vec2 {
    Vec2::new(uv.x, -uv.y)
}

/// The unit tangent along `t` orthogonal to `normal`, `w` = the sign of `b` against N × T; any
/// direction orthogonal to the normal when `t` has none (and any unit one when the normal is
/// unusable).
fn orthogonal(normal: DVec3, t: DVec3, b: DVec3) -> Vec4 {
    let normal = normal.try_normalize().unwrap_or(DVec3::Z);
    let v = (t - normal * normal.dot(t))
        .try_normalize()
        .unwrap_or_else(|| {
            // Any axis not parallel to the normal.
            let axis = if normal.x.abs() < 0.9 {
                DVec3::X
            } else {
                DVec3::Y
            };
            (axis - normal * normal.dot(axis)).normalize()
        });
    let w = if normal.cross(v).dot(b) < 0.0 {
        -1.0
    } else {
        1.0
    };
    v.as_vec3().extend(w)
}

/// The triangles MikkTSpace gets (indices into the triangle list): all when the mesh is within
/// [`MAX_TRIANGLES`], less those with an index out of range, a non-finite or huge position or
/// texture coordinate, a normal that is not unit, or a corner at a position more than
/// [`MAX_CORNERS_AT_A_POSITION`] corners share.
fn served_triangles(mesh: Geometry<'_>) -> Vec<u32> {
    let n = mesh.positions.len();
    let count = mesh.indices.len() / 3;
    if count > MAX_TRIANGLES || mesh.normals.len() != n || mesh.uvs.len() != n {
        return Vec::new();
    }
    let usable = |i: u32| {
        let i = i as usize;
        let (p, normal, uv) = match (mesh.positions.get(i), mesh.normals.get(i), mesh.uvs.get(i)) {
            (Some(p), Some(normal), Some(uv)) => (p, normal, uv),
            _ => return false,
        };
        let len = normal.length();
        p.is_finite()
            && p.abs().max_element() <= MAX_COORD
            && uv.is_finite()
            && uv.abs().max_element() <= MAX_COORD
            && (0.5..2.0).contains(&len)
    };
    let corners = |t: u32| &mesh.indices[3 * t as usize..3 * t as usize + 3];
    let mut faces: Vec<u32> = (0..count as u32)
        .filter(|&t| corners(t).iter().all(|&i| usable(i)))
        .collect();
    // Positions compared as MikkTSpace welds them (−0 and +0 alike: adding +0 makes −0 +0).
    let key = |i: u32| {
        (mesh.positions[i as usize] + Vec3::ZERO)
            .to_array()
            .map(f32::to_bits)
    };
    let mut at_position: HashMap<[u32; 3], usize> = HashMap::new();
    for &t in &faces {
        for &i in corners(t) {
            *at_position.entry(key(i)).or_default() += 1;
        }
    }
    faces.retain(|&t| {
        corners(t)
            .iter()
            .all(|&i| at_position[&key(i)] <= MAX_CORNERS_AT_A_POSITION)
    });
    faces
}

/// The mesh as MikkTSpace reads it (the served triangles only) and the corners it writes.
struct Mikk<'a> {
    mesh: Geometry<'a>,
    faces: &'a [u32],
    /// One per index of the mesh; `None` where MikkTSpace gave nothing usable.
    out: Vec<Option<Vec4>>,
}

impl Mikk<'_> {
    fn vertex(&self, face: usize, vert: usize) -> usize {
        self.mesh.indices[3 * self.faces[face] as usize + vert] as usize
    }
}

impl bevy_mikktspace::Geometry for Mikk<'_> {
    fn num_faces(&self) -> usize {
        self.faces.len()
    }

    fn num_vertices_of_face(&self, _face: usize) -> usize {
        3
    }

    fn position(&self, face: usize, vert: usize) -> [f32; 3] {
        self.mesh.positions[self.vertex(face, vert)].to_array()
    }

    fn normal(&self, face: usize, vert: usize) -> [f32; 3] {
        self.mesh.normals[self.vertex(face, vert)].to_array()
    }

    fn tex_coord(&self, face: usize, vert: usize) -> [f32; 2] {
        mikk_uv(self.mesh.uvs[self.vertex(face, vert)]).to_array()
    }

    fn set_tangent(
        &mut self,
        space: Option<bevy_mikktspace::TangentSpace>,
        face: usize,
        vert: usize,
    ) {
        let normal = self.mesh.normals[self.vertex(face, vert)]
            .as_dvec3()
            .normalize();
        // Made exactly orthogonal in f64; a zero or non-finite one is left to the fallback.
        let tangent = space.and_then(|s| {
            let t = Vec3::from_array(s.tangent()).as_dvec3();
            let w = if s.is_orientation_preserving() {
                1.0
            } else {
                -1.0
            };
            let t = (t - normal * normal.dot(t)).try_normalize()?;
            Some(t.as_vec3().extend(w))
        });
        self.out[3 * self.faces[face] as usize + vert] = tangent;
    }
}

#[cfg(test)]
mod tests;
