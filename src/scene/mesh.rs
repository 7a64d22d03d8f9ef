//! Triangle meshes in object space.

use std::collections::HashMap;

use glam::{DVec3, Vec2, Vec3, Vec4};

pub use super::aabb::{Aabb, MIN_PLACED_SIZE};
use super::mesh_limits::{check_indices, check_per_vertex, check_positions, check_uvs};
pub use super::mesh_limits::{MAX_TEXCOORD, MAX_VERTEX_COORD};
use super::SceneError;

/// Most distinct meshes a model file, or a scene file with all its references, may make: each
/// has a fixed cost besides its data (its buffers and their GL objects, the automatic grid's
/// ray-caster hierarchy; about 4.4 KB measured with llvmpipe), so the limit holds that near
/// 300 MB. Objects placing one mesh many times cost far less ([`MAX_SCENE_OBJECTS`]).
pub const MAX_SCENE_MESHES: usize = 1 << 16;

/// Most objects a scene file may place (all its references together), the per-file limit of
/// glTF too: each costs about 0.6 KB of CPU state besides its mesh (placement, draw order,
/// the automatic grid's ray caster), so the limit holds that near 600 MB.
pub const MAX_SCENE_OBJECTS: usize = 1 << 20;

/// Most materials a scene file may make (references that recolour a model copy its materials).
pub const MAX_SCENE_MATERIALS: usize = 1 << 20;

/// An indexed triangle mesh in object space. Normals are always present (computed from the
/// faces when the source had none); texture coordinates are optional. Which sides are drawn is
/// its material's ([`Material::double_sided`](super::Material::double_sided)): a back face
/// (clockwise on screen; [`Mesh::new`] winds each triangle towards its normals,
/// [`Mesh::new_as_wound`] keeps the winding listed) is culled, or shaded with its normals
/// reversed.
#[derive(Clone, Debug, Default)]
pub struct Mesh {
    /// Vertex positions.
    pub positions: Vec<Vec3>,
    /// Unit vertex normals, one per position.
    pub normals: Vec<Vec3>,
    /// Texture coordinates, one per position, or empty.
    pub uvs: Vec<Vec2>,
    /// A second set of texture coordinates (glTF `TEXCOORD_1`: a baked occlusion or light
    /// map's own unwrap), one per position, or empty. Read by the textures whose
    /// [`TextureTransform::uv_set`](super::surface_maps::TextureTransform::uv_set) is 1.
    pub second_uvs: Vec<Vec2>,
    /// Triangle list, three indices per triangle. Its front face, the side `normals` point to,
    /// is counter-clockwise: [`Mesh::new`] turns a triangle listed the other way round; a mesh
    /// built or edited through these fields is drawn as listed.
    pub indices: Vec<u32>,
    /// Linear RGBA vertex colours (glTF `COLOR_0`), one per position, or empty. Their RGB
    /// multiplies the base colour; alpha takes part in the opacity only where the material
    /// says so ([`Material::alpha_vertex`](super::Material::alpha_vertex)).
    pub colors: Vec<Vec4>,
    /// Unit tangents with the bitangent sign in `w` (glTF `TANGENT`, or generated for a
    /// normal-mapped material), one per position, or empty.
    pub tangents: Vec<Vec4>,
}

impl Mesh {
    /// Builds a mesh and checks it: indices in range, a multiple of three, finite values,
    /// normals and texture coordinates each empty or one per position. Missing normals
    /// (`normals` empty) are computed as area-weighted face normals; given ones turn each
    /// triangle whose winding faces away from them round (its front face is the side its
    /// normals point to).
    pub fn new(
        positions: Vec<Vec3>,
        normals: Vec<Vec3>,
        uvs: Vec<Vec2>,
        indices: Vec<u32>,
    ) -> Result<Mesh, SceneError> {
        Self::checked(positions, normals, uvs, indices, false)
    }

    /// [`Mesh::new`] keeping every triangle wound as listed, for a single-sided surface, whose
    /// front is its winding's side (glTF `doubleSided: false`): missing normals are the faces'
    /// (area-weighted, no triangle turned to agree with its neighbours), and given ones turn
    /// no triangle round (a front face whose normals point away is lit from behind).
    pub fn new_as_wound(
        positions: Vec<Vec3>,
        normals: Vec<Vec3>,
        uvs: Vec<Vec2>,
        indices: Vec<u32>,
    ) -> Result<Mesh, SceneError> {
        Self::checked(positions, normals, uvs, indices, true)
    }

    fn checked(
        positions: Vec<Vec3>,
        normals: Vec<Vec3>,
        uvs: Vec<Vec2>,
        indices: Vec<u32>,
        as_wound: bool,
    ) -> Result<Mesh, SceneError> {
        let mut indices = indices;
        let n = positions.len();
        check_indices(&indices, n, "mesh.indices")?;
        check_positions(&positions, "mesh")?;
        if !uvs.is_empty() && uvs.len() != n {
            return Err(SceneError::invalid(
                "mesh.uvs",
                format!("{} texture coordinates for {n} vertices", uvs.len()),
            ));
        }
        check_uvs(&uvs, "mesh.uvs")?;
        if !normals.is_empty() && normals.len() != n {
            return Err(SceneError::invalid(
                "mesh.normals",
                format!("{} normals for {n} vertices", normals.len()),
            ));
        }
        let normals = if normals.len() == n {
            let normals = repair_normals(normals, &positions, &indices);
            if !as_wound {
                wind_to_normals(&positions, &normals, &mut indices);
            }
            normals
        } else if as_wound {
            compute_normals(&positions, &indices)
        } else {
            consistent_face_normals(&positions, &mut indices)
        };
        Ok(Mesh {
            positions,
            normals,
            uvs,
            second_uvs: Vec::new(),
            indices,
            colors: Vec::new(),
            tangents: Vec::new(),
        })
    }

    /// Normals computed again from the faces, after a consistent winding (as [`Mesh::new`]
    /// gives a mesh without normals): for a mesh whose triangles changed since.
    pub(crate) fn recompute_normals(&mut self) {
        self.normals = consistent_face_normals(&self.positions, &mut self.indices);
    }

    /// The mesh with vertex colours (one per position, finite; values are clamped to [0, 1]).
    pub fn with_colors(mut self, colors: Vec<Vec4>) -> Result<Mesh, SceneError> {
        check_per_vertex("mesh.colors", colors.len(), self.positions.len())?;
        if let Some(i) = colors.iter().position(|c| !c.is_finite()) {
            return Err(SceneError::invalid(
                format!("mesh.colors[{i}]"),
                "must be finite",
            ));
        }
        self.colors = colors
            .into_iter()
            .map(|c| c.clamp(Vec4::ZERO, Vec4::ONE))
            .collect();
        Ok(self)
    }

    /// The mesh with a second set of texture coordinates (one per position, finite, within
    /// ±`MAX_TEXCOORD`), which textures of `uv_set` 1 read.
    pub fn with_second_uvs(mut self, uvs: Vec<Vec2>) -> Result<Mesh, SceneError> {
        check_per_vertex("mesh.second_uvs", uvs.len(), self.positions.len())?;
        check_uvs(&uvs, "mesh.second_uvs")?;
        self.second_uvs = uvs;
        Ok(self)
    }

    /// The mesh with tangents (one per position). Each is made orthogonal to its vertex's
    /// normal and unit, `w` made ±1; one with no usable direction is replaced by the
    /// generated one (MikkTSpace, see `docs/gltf.md`).
    pub fn with_tangents(mut self, tangents: Vec<Vec4>) -> Result<Mesh, SceneError> {
        self.validate()?;
        check_per_vertex("mesh.tangents", tangents.len(), self.positions.len())?;
        self.tangents = super::tangents::repair(self.geometry(), tangents);
        Ok(self)
    }

    /// The mesh with MikkTSpace tangents when it has texture coordinates and none yet, and how
    /// many triangle corners got the fallback tangent (see `docs/gltf.md`). MikkTSpace works
    /// per corner: a vertex whose corners get different tangents (a mirrored UV seam through
    /// shared vertices) is split, one copy per tangent, so adds at most one vertex per index.
    /// A mesh that fails [`Mesh::validate`] is that error.
    pub fn with_generated_tangents(self) -> Result<(Mesh, usize), SceneError> {
        self.with_tangents_along(0)
    }

    /// [`Mesh::with_generated_tangents`] along the coordinate set `uv_set` (0: `uvs`, 1:
    /// `second_uvs`): the one its normal map reads, as glTF asks. Nothing is generated where
    /// the mesh lacks that set.
    pub fn with_tangents_along(mut self, uv_set: u32) -> Result<(Mesh, usize), SceneError> {
        self.validate()?;
        if !self.tangents.is_empty() || self.coordinate_set(uv_set).is_none() {
            return Ok((self, 0));
        }
        let uvs = self.coordinate_set(uv_set).unwrap_or_default();
        let geometry = self.geometry_along(uvs);
        let corners = super::tangents::generate_corners(geometry);
        // Vertices no triangle uses keep the fallback tangent.
        let mut tangents = super::tangents::per_vertex_fallback(geometry);
        let mut taken = vec![false; tangents.len()];
        let mut copies: HashMap<(u32, [u32; 4]), u32> = HashMap::new();
        for (k, &t) in corners.tangents.iter().enumerate() {
            let v = self.indices[k] as usize;
            if !taken[v] {
                (tangents[v], taken[v]) = (t, true);
            } else if tangents[v] != t {
                let key = (v as u32, t.to_array().map(f32::to_bits));
                let copy = *copies.entry(key).or_insert_with(|| {
                    self.positions.push(self.positions[v]);
                    self.normals.push(self.normals[v]);
                    for set in [&mut self.uvs, &mut self.second_uvs] {
                        if !set.is_empty() {
                            set.push(set[v]);
                        }
                    }
                    if !self.colors.is_empty() {
                        self.colors.push(self.colors[v]);
                    }
                    tangents.push(t);
                    (tangents.len() - 1) as u32
                });
                self.indices[k] = copy;
            }
        }
        self.tangents = tangents;
        Ok((self, corners.fallbacks))
    }

    /// Texture coordinate set `set` (0: `uvs`, 1: `second_uvs`), where the mesh has it.
    pub(crate) fn coordinate_set(&self, set: u32) -> Option<&[Vec2]> {
        let coordinates = match set {
            0 => &self.uvs,
            1 => &self.second_uvs,
            _ => return None,
        };
        (!coordinates.is_empty()).then_some(coordinates.as_slice())
    }

    fn geometry(&self) -> super::tangents::Geometry<'_> {
        self.geometry_along(&self.uvs)
    }

    fn geometry_along<'m>(&'m self, uvs: &'m [Vec2]) -> super::tangents::Geometry<'m> {
        super::tangents::Geometry {
            positions: &self.positions,
            normals: &self.normals,
            uvs,
            indices: &self.indices,
        }
    }

    /// Whether any triangle has a non-zero area (all points or lines: nothing to draw).
    pub fn has_area(&self) -> bool {
        self.triangle_normals().any(|n| n != DVec3::ZERO)
    }

    /// Unit vectors spanning the directions of the triangles' normals (none: no triangle has
    /// an area; one: the mesh is flat). A linear map `A` gives a triangle of normal `n` the
    /// normal `cof(A)·n`, so the mesh keeps an area under `A` exactly when `cof(A)` keeps one
    /// of these. Stops reading the triangles once it has three.
    pub fn normal_span(&self) -> Vec<glam::DVec3> {
        let mut basis: Vec<glam::DVec3> = Vec::new();
        for n in self.triangle_normals() {
            let mut n = n.normalize_or_zero();
            for b in &basis {
                n -= *b * n.dot(*b);
            }
            // What is left of a unit normal once the span's part is taken away.
            if n.length() > 1e-6 {
                basis.push(n.normalize());
                if basis.len() == 3 {
                    break;
                }
            }
        }
        basis
    }

    /// The triangles' (unnormalised) normals, out-of-range corners at the origin. In f64: an
    /// f32 cross product of edges near 10⁻²³ underflows to zero, a real triangle to none. The
    /// corners as a GPU reads them: subnormal coordinates (below 1.2·10⁻³⁸) are zero there.
    fn triangle_normals(&self) -> impl Iterator<Item = DVec3> + '_ {
        let read = |p: Vec3| {
            let normal = p.abs().cmpge(Vec3::splat(f32::MIN_POSITIVE));
            Vec3::select(normal, p, Vec3::ZERO).as_dvec3()
        };
        self.indices.chunks_exact(3).map(move |t| {
            let p = |k: usize| {
                self.positions
                    .get(t[k] as usize)
                    .map_or(DVec3::ZERO, |p| read(*p))
            };
            (p(1) - p(0)).cross(p(2) - p(0))
        })
    }

    /// Object-space bounds (`None` for an empty mesh).
    pub fn bounds(&self) -> Option<Aabb> {
        Aabb::from_points(self.positions.iter().map(|p| p.as_dvec3()))
    }

    /// Number of triangles.
    pub fn triangle_count(&self) -> usize {
        self.indices.len() / 3
    }
}

impl Mesh {
    /// Whether the mesh's arrays fit together as [`Mesh::new`] and the `with_*` methods make
    /// them: whole triangles of indices in range, one normal per position, and texture
    /// coordinates, colours and tangents either none or one per position; and whether their
    /// values are what [`Mesh::new`] keeps (positions and texture coordinates within their
    /// limits, normals of some length, every number finite, colours within [0, 1]). The
    /// fields are public, so a mesh built or edited in code is checked again before it is
    /// uploaded; errors name the field (`mesh.normals`).
    pub fn validate(&self) -> Result<(), SceneError> {
        self.check_shape("mesh")
    }

    /// [`Mesh::validate`] with errors named under `field` (`objects[3].mesh`).
    pub(crate) fn check_shape(&self, field: &str) -> Result<(), SceneError> {
        let n = self.positions.len();
        let at = |what: &str| format!("{field}.{what}");
        check_indices(&self.indices, n, &at("indices"))?;
        check_per_vertex(&at("normals"), self.normals.len(), n)?;
        let optional = [
            ("uvs", self.uvs.len()),
            ("second_uvs", self.second_uvs.len()),
            ("colors", self.colors.len()),
            ("tangents", self.tangents.len()),
        ];
        for (name, len) in optional {
            if len != 0 {
                check_per_vertex(&at(name), len, n)?;
            }
        }
        check_positions(&self.positions, field)?;
        check_uvs(&self.uvs, &at("uvs"))?;
        check_uvs(&self.second_uvs, &at("second_uvs"))?;
        // A zero normal normalises to NaN in the shader (`Mesh::new` puts the face's there).
        let unusable = |v: Vec3| !(v.is_finite() && v.length_squared() > 0.0);
        if let Some(i) = self.normals.iter().position(|&v| unusable(v)) {
            return Err(SceneError::invalid(
                format!("{field}.normals[{i}]"),
                "must be finite and not zero".to_string(),
            ));
        }
        // They multiply the albedo and alpha: a negative one would draw black, one past 1
        // escape the colour factors' cap.
        let unit = |c: &Vec4| c.cmpge(Vec4::ZERO).all() && c.cmple(Vec4::ONE).all();
        if let Some(i) = self.colors.iter().position(|c| !unit(c)) {
            return Err(SceneError::invalid(
                format!("{field}.colors[{i}]"),
                "must be within [0, 1]".to_string(),
            ));
        }
        if let Some(i) = self.tangents.iter().position(|t| !t.is_finite()) {
            return Err(SceneError::invalid(
                format!("{field}.tangents[{i}]"),
                "must be finite".to_string(),
            ));
        }
        Ok(())
    }
}

/// Given normals made unit; those with no direction (zero, NaN or infinite) replaced by the
/// area-weighted normal of the faces around their vertex, as a mesh without normals gets.
fn repair_normals(normals: Vec<Vec3>, positions: &[Vec3], indices: &[u32]) -> Vec<Vec3> {
    let mut faces: Option<Vec<Vec3>> = None;
    normals
        .into_iter()
        .enumerate()
        .map(|(i, v)| {
            super::direction::unit_f32(v).unwrap_or_else(|| {
                faces.get_or_insert_with(|| compute_normals(positions, indices))[i]
            })
        })
        .collect()
}

/// Reverses each triangle whose winding points away from its vertex normals (their sum), so
/// that its front face (counter-clockwise on screen) is the side they point to: the shaders
/// tell the side seen by the winding (`gl_FrontFacing`), and OBJ files follow no winding rule.
/// Returns how many were reversed.
fn wind_to_normals(positions: &[Vec3], normals: &[Vec3], indices: &mut [u32]) -> usize {
    let mut reversed = 0;
    for tri in indices.chunks_exact_mut(3) {
        let [a, b, c] = [tri[0], tri[1], tri[2]].map(|i| i as usize);
        let [pa, pb, pc] = [a, b, c].map(|i| positions[i].as_dvec3());
        let winding = (pb - pa).cross(pc - pa);
        let normal = normals[a].as_dvec3() + normals[b].as_dvec3() + normals[c].as_dvec3();
        if winding.dot(normal) < 0.0 {
            tri.swap(1, 2);
            reversed += 1;
        }
    }
    reversed
}

/// The normals of a mesh that has none: a triangle listed against its neighbours (an OBJ
/// without `vn`) is turned round first, since it would be shaded as a back face and weigh
/// against theirs in their normals; then [`compute_normals`].
fn consistent_face_normals(positions: &[Vec3], indices: &mut [u32]) -> Vec<Vec3> {
    super::orientation::orient_consistently(positions, indices);
    compute_normals(positions, indices)
}

/// Area-weighted vertex normals from the faces; vertices on no face (or only degenerate ones)
/// get +Y. Summed in `f64`, so faces too small or too large for an `f32` cross product keep
/// their direction.
pub fn compute_normals(positions: &[Vec3], indices: &[u32]) -> Vec<Vec3> {
    let mut acc = vec![DVec3::ZERO; positions.len()];
    for tri in indices.chunks_exact(3) {
        let [a, b, c] = [tri[0], tri[1], tri[2]].map(|i| i as usize);
        let [pa, pb, pc] = [a, b, c].map(|i| positions[i].as_dvec3());
        // The cross product's length is twice the area: larger faces weigh more.
        let n = (pb - pa).cross(pc - pa);
        acc[a] += n;
        acc[b] += n;
        acc[c] += n;
    }
    acc.into_iter()
        .map(|n| super::direction::unit(n).map_or(Vec3::Y, |n| n.as_vec3()))
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A mesh whose public fields were set in code to values `Mesh::new` refuses or repairs
    /// is refused before upload, naming the field (it drew black or not at all).
    #[test]
    fn values_set_in_code_are_checked_before_upload() {
        let good = Mesh::new(
            vec![Vec3::ZERO, Vec3::X, Vec3::Y],
            vec![],
            vec![Vec2::ZERO; 3],
            vec![0, 1, 2],
        )
        .unwrap();
        assert!(good.check_shape("objects[1].mesh").is_ok());
        type Change = dyn Fn(&mut Mesh);
        let cases: [(&Change, &str); 8] = [
            (
                &|m| m.positions[1].x = f32::NAN,
                "objects[1].mesh.positions[1]",
            ),
            (&|m| m.positions[2].y = 3e38, "objects[1].mesh.positions[2]"),
            (&|m| m.uvs[0] = Vec2::splat(3e38), "objects[1].mesh.uvs[0]"),
            (
                &|m| m.second_uvs = vec![Vec2::ZERO, Vec2::NAN, Vec2::ZERO],
                "objects[1].mesh.second_uvs[1]",
            ),
            (
                &|m| m.second_uvs = vec![Vec2::ZERO; 2],
                "objects[1].mesh.second_uvs",
            ),
            (&|m| m.normals[2] = Vec3::ZERO, "objects[1].mesh.normals[2]"),
            (
                &|m| m.tangents = vec![Vec4::NAN; 3],
                "objects[1].mesh.tangents[0]",
            ),
            (
                &|m| m.colors = vec![Vec4::INFINITY; 3],
                "objects[1].mesh.colors[0]",
            ),
        ];
        for (change, field) in cases {
            let mut m = good.clone();
            change(&mut m);
            let err = m.check_shape("objects[1].mesh").unwrap_err().to_string();
            assert!(err.contains(field), "{field}: {err}");
            // The value is not shown: a model file's numbers never reach a message.
            for value in ["Vec", "e38", "NaN", "inf"] {
                assert!(!err.contains(value), "{field}: {err}");
            }
        }
    }

    #[test]
    fn a_second_set_is_one_finite_coordinate_a_vertex_and_tangents_can_follow_it() {
        let tri = || {
            let p = vec![Vec3::ZERO, Vec3::X, Vec3::Y];
            Mesh::new(p, vec![], vec![Vec2::ZERO, Vec2::X, Vec2::Y], vec![0, 1, 2]).unwrap()
        };
        let short = tri().with_second_uvs(vec![Vec2::ZERO; 2]).unwrap_err();
        assert!(short.to_string().contains("mesh.second_uvs"), "{short}");
        let far = vec![Vec2::ZERO, Vec2::splat(2e9), Vec2::ZERO];
        let far = tri().with_second_uvs(far).unwrap_err();
        assert!(far.to_string().contains("mesh.second_uvs[1]"), "{far}");
        // The second set's u runs along +y (the first's along +x): tangents follow the set
        // asked for, and none are made along a set the mesh lacks.
        let second = vec![Vec2::ZERO, Vec2::Y, Vec2::X];
        let mesh = tri().with_second_uvs(second).unwrap();
        let (along_first, _) = mesh.clone().with_tangents_along(0).unwrap();
        let (along_second, _) = mesh.with_tangents_along(1).unwrap();
        assert!((along_first.tangents[0].truncate() - Vec3::X).length() < 1e-5);
        assert!((along_second.tangents[0].truncate() - Vec3::Y).length() < 1e-5);
        let (none, _) = tri().with_tangents_along(1).unwrap();
        assert!(none.tangents.is_empty());
    }

    #[test]
    fn computes_face_normals_when_missing() {
        let m = Mesh::new(
            vec![Vec3::ZERO, Vec3::X, Vec3::Y],
            vec![],
            vec![],
            vec![0, 1, 2],
        )
        .unwrap();
        for n in &m.normals {
            assert!((*n - Vec3::Z).length() < 1e-6);
        }
    }

    #[test]
    fn unusable_normals_are_recomputed_from_the_faces_and_huge_ones_kept() {
        let positions = vec![Vec3::ZERO, Vec3::X, Vec3::Y, Vec3::new(1.0, 1.0, 0.0)];
        let huge = Vec3::new(3e30, 0.0, 4e30);
        let normals = vec![
            Vec3::ZERO,
            Vec3::NAN,
            Vec3::new(f32::INFINITY, 0.0, 0.0),
            huge,
        ];
        let m = Mesh::new(positions, normals, vec![], vec![0, 1, 2, 1, 3, 2]).unwrap();
        for n in &m.normals[..3] {
            assert!((*n - Vec3::Z).length() < 1e-6, "{n}");
        }
        assert!((m.normals[3] - Vec3::new(0.6, 0.0, 0.8)).length() < 1e-6);
    }

    #[test]
    fn face_normals_of_tiny_and_huge_triangles_keep_their_direction() {
        for scale in [1e-25f32, 1e-15, 1.0, 1e9] {
            let positions = vec![Vec3::ZERO, Vec3::X * scale, Vec3::Y * scale];
            let normals = compute_normals(&positions, &[0, 1, 2]);
            assert!(
                normals.iter().all(|n| (*n - Vec3::Z).length() < 1e-6),
                "{scale:e}"
            );
        }
    }

    /// Every triangle's winding normal, in f64.
    fn windings(m: &Mesh) -> Vec<DVec3> {
        m.indices
            .chunks_exact(3)
            .map(|t| {
                let [a, b, c] = [t[0], t[1], t[2]].map(|i| m.positions[i as usize].as_dvec3());
                (b - a).cross(c - a)
            })
            .collect()
    }

    #[test]
    fn triangles_are_wound_towards_their_normals() {
        // Two triangles of the plane z = 0, the first counter-clockwise seen from +Z, the
        // second clockwise; every normal is +Z.
        let positions = vec![Vec3::ZERO, Vec3::X, Vec3::Y, Vec3::new(1.0, 1.0, 0.0)];
        let m = Mesh::new(
            positions.clone(),
            vec![Vec3::Z; 4],
            vec![],
            vec![0, 1, 2, 1, 2, 3],
        )
        .unwrap();
        assert_eq!(
            &m.indices[..3],
            &[0, 1, 2],
            "a triangle already wound stays"
        );
        for w in windings(&m) {
            assert!(w.z > 0.0, "{w}");
        }
        // Normals tilted far from the face still pick its side by their sum.
        let tilted = vec![
            Vec3::new(-0.9, 0.0, -0.2).normalize(),
            Vec3::new(0.9, 0.0, 0.5).normalize(),
            Vec3::Z,
            Vec3::Z,
        ];
        let m = Mesh::new(positions.clone(), tilted, vec![], vec![0, 2, 1]).unwrap();
        assert!(windings(&m)[0].z > 0.0);
        // Normals facing -Z turn the first triangle round instead.
        let m = Mesh::new(positions, vec![-Vec3::Z; 4], vec![], vec![0, 1, 2, 1, 2, 3]).unwrap();
        for w in windings(&m) {
            assert!(w.z < 0.0, "{w}");
        }
    }

    #[test]
    fn a_single_sided_mesh_keeps_every_winding_as_listed() {
        // The two triangles of `triangles_are_wound_towards_their_normals`, wound oppositely.
        let positions = vec![Vec3::ZERO, Vec3::X, Vec3::Y, Vec3::new(1.0, 1.0, 0.0)];
        let listed = vec![0, 1, 2, 1, 2, 3];
        let m = Mesh::new_as_wound(positions.clone(), vec![Vec3::Z; 4], vec![], listed.clone())
            .unwrap();
        assert_eq!(m.indices, listed, "normals turn no triangle round");
        assert_eq!(m.normals, vec![Vec3::Z; 4]);
        // Without normals (vertices unshared, as glTF's flat case makes them): each face's
        // own, no triangle turned to agree with its neighbour across their common edge.
        let mut unshared = positions.clone();
        unshared.extend([Vec3::X, Vec3::Y, Vec3::new(1.0, 1.0, 0.0)]);
        let m = Mesh::new_as_wound(unshared, vec![], vec![], vec![0, 1, 2, 4, 5, 6]).unwrap();
        assert_eq!(m.indices, [0, 1, 2, 4, 5, 6]);
        assert_eq!(m.normals[0], Vec3::Z);
        assert_eq!(m.normals[4], -Vec3::Z);
        let w = windings(&m);
        assert!(w[0].z > 0.0 && w[1].z < 0.0, "{w:?}");
    }

    #[test]
    fn a_triangle_listed_against_its_neighbours_is_turned_round_without_normals_too() {
        // An octahedron (its faces counter-clockwise seen from outside) with one face listed
        // the other way, and no normals (an OBJ without `vn`).
        let positions = vec![Vec3::X, -Vec3::X, Vec3::Y, -Vec3::Y, Vec3::Z, -Vec3::Z];
        #[rustfmt::skip]
        let mut indices = vec![
            0, 2, 4, 2, 1, 4, 1, 3, 4, 3, 0, 4,
            2, 0, 5, 1, 2, 5, 3, 1, 5, 0, 3, 5,
        ];
        indices.swap(1, 2);
        let m = Mesh::new(positions, vec![], vec![], indices).unwrap();
        for (t, w) in m.indices.chunks_exact(3).zip(windings(&m)) {
            let centre: DVec3 = t.iter().map(|&i| m.positions[i as usize].as_dvec3()).sum();
            assert!(w.dot(centre) > 0.0, "triangle {t:?} faces inwards");
        }
        // The normals, recomputed, have no reversed face in them: each points outwards.
        for (p, n) in m.positions.iter().zip(&m.normals) {
            assert!(p.dot(*n) > 0.99, "{p}: {n}");
        }
    }

    #[test]
    fn a_tiny_triangle_has_an_area() {
        let tiny = |s: f32| {
            let m = Mesh::new(
                vec![Vec3::ZERO, Vec3::X * s, Vec3::Y * s],
                vec![],
                vec![],
                vec![0, 1, 2],
            );
            m.unwrap().has_area()
        };
        assert!(
            tiny(1e-23),
            "its f32 cross product underflows, its area does not"
        );
        assert!(tiny(1e-36));
        assert!(!tiny(0.0));
        // Subnormal coordinates, which GPUs read as zero: nothing to draw.
        assert!(!tiny(1e-38) && !tiny(1e-40));
    }

    #[test]
    fn rejects_out_of_range_indices_and_nan() {
        assert!(Mesh::new(vec![Vec3::ZERO], vec![], vec![], vec![0, 0, 1]).is_err());
        let e = Mesh::new(vec![Vec3::NAN; 3], vec![], vec![], vec![0, 1, 2]).unwrap_err();
        assert!(e.to_string().contains("positions[0]"));
    }

    /// Normals, like texture coordinates, are one per position or none: a count between is
    /// the caller's error, not normals to compute silently.
    #[test]
    fn normals_of_another_count_than_the_positions_are_refused() {
        let positions = vec![Vec3::ZERO, Vec3::X, Vec3::Y];
        for normals in [vec![Vec3::Z; 2], vec![Vec3::Z; 4]] {
            let count = normals.len();
            let e = Mesh::new(positions.clone(), normals, vec![], vec![0, 1, 2]).unwrap_err();
            assert!(e.to_string().contains("mesh.normals"), "{e}");
            assert!(
                e.to_string().contains(&format!("{count} normals for 3")),
                "{e}"
            );
        }
        let m = Mesh::new_as_wound(positions, vec![], vec![], vec![0, 1, 2]).unwrap();
        assert_eq!(m.normals, vec![Vec3::Z; 3]);
    }

    /// A mesh edited through its public fields: the tangent builders and `validate` name the
    /// field that disagrees (they indexed past the arrays and panicked).
    #[test]
    fn a_mesh_whose_fields_disagree_is_an_error_naming_the_field() {
        let good = || {
            let uvs = vec![Vec2::ZERO, Vec2::X, Vec2::Y];
            Mesh::new(
                vec![Vec3::ZERO, Vec3::X, Vec3::Y],
                vec![],
                uvs,
                vec![0, 1, 2],
            )
            .unwrap()
        };
        assert!(good().validate().is_ok());
        let mut index_past = good();
        index_past.indices[2] = 3;
        let e = index_past.with_generated_tangents().unwrap_err();
        assert!(e.to_string().contains("mesh.indices"), "{e}");
        let mut no_normals = good();
        no_normals.normals.clear();
        let e = no_normals.with_tangents(vec![Vec4::X; 3]).unwrap_err();
        assert!(e.to_string().contains("mesh.normals"), "{e}");
        let mut short_colours = good();
        short_colours.colors = vec![Vec4::ONE; 2];
        let e = short_colours.with_generated_tangents().unwrap_err();
        assert!(e.to_string().contains("mesh.colors"), "{e}");
        let mut negative = good();
        negative.colors = vec![Vec4::ONE, Vec4::new(-1.0, 0.5, 0.5, 1.0), Vec4::ONE];
        let e = negative.validate().unwrap_err();
        assert!(e.to_string().contains("mesh.colors[1]"), "{e}");
    }
}
