//! Mesh primitives → [`Mesh`]: positions, normals (flat ones computed when the primitive has
//! none, as glTF asks), `TEXCOORD_0` (and `TEXCOORD_1` where a drawn texture reads it),
//! indices (u8, u16, u32 or none), triangle strips and fans unrolled into lists. Every index
//! is checked against the vertex count and every position against [`MAX_VERTEX_COORD`], with
//! the glTF path and the element's position in the message (never its value: buffer bytes are
//! not shown).

use glam::{Vec2, Vec3, Vec4};
use gltf::accessor::{DataType, Dimensions};
use gltf::mesh::Mode;

use super::accessor::{self, describe};
use super::buffers::Buffers;
use crate::scene::mesh::MAX_VERTEX_COORD;
use crate::scene::texture_sets::TextureSets;
use crate::scene::Mesh;

/// How many vertices and indices the file's primitives may still decode into.
#[derive(Debug)]
pub(super) struct Budget {
    /// Vertices left.
    pub vertices: usize,
    /// Indices left.
    pub indices: usize,
}

impl Budget {
    fn take(&mut self, what: &str, n: usize, field: &str) -> Result<(), String> {
        let (left, limit) = match what {
            "vertices" => (&mut self.vertices, super::MAX_VERTICES),
            _ => (&mut self.indices, super::MAX_INDICES),
        };
        let before = *left;
        *left = left.checked_sub(n).ok_or_else(|| {
            let taken = limit.saturating_sub(before);
            format!(
                "{field}: {n} {what} more than the file's {taken} before would pass the limit \
                 of {limit} {what} per file"
            )
        })?;
        Ok(())
    }

    /// Gives back `n` vertices a primitive no longer keeps.
    fn give_back_vertices(&mut self, n: usize) {
        self.vertices = (self.vertices + n).min(super::MAX_VERTICES);
    }
}

/// What a primitive's mesh is built from: its attributes' accessors, its indices' accessor,
/// its mode and its material (sidedness, tangents and duplicate removal follow it). Two
/// primitives alike in these build the same mesh.
#[derive(Clone, PartialEq, Eq, Hash)]
pub(super) struct ContentKey {
    attributes: Vec<(String, usize)>,
    indices: Option<usize>,
    mode: u32,
    material: Option<usize>,
}

/// [`ContentKey`] of `p`.
pub(super) fn content_key(p: &gltf::Primitive) -> ContentKey {
    let mut attributes: Vec<(String, usize)> = p
        .attributes()
        .map(|(semantic, a)| (semantic.to_string(), a.index()))
        .collect();
    attributes.sort();
    ContentKey {
        attributes,
        indices: p.indices().map(|a| a.index()),
        mode: p.mode().as_gl_enum(),
        material: p.material().index(),
    }
}

/// The outcome for one primitive.
pub(super) enum Built {
    /// A triangle mesh.
    Mesh(Mesh),
    /// Nothing to draw (points, lines, no triangles); the reason for a warning.
    Skipped(String),
}

/// The coordinate sets a primitive's material's textures read, asked once the primitive has
/// triangles (its material is converted then, not for a primitive that is skipped).
pub(super) type AskSets<'a> =
    &'a mut dyn FnMut(&mut Buffers, &mut Vec<String>) -> Result<TextureSets, String>;

/// Builds primitive `p` of its mesh; `field` is its glTF path (`meshes[2].primitives[0]`);
/// `sets`: the coordinate sets its material's textures read.
pub(super) fn build(
    p: &gltf::Primitive,
    sets: AskSets<'_>,
    field: &str,
    buffers: &mut Buffers,
    budget: &mut Budget,
    warnings: &mut Vec<String>,
) -> Result<Built, String> {
    let mode = p.mode();
    if !matches!(
        mode,
        Mode::Triangles | Mode::TriangleStrip | Mode::TriangleFan
    ) {
        return Ok(Built::Skipped(format!(
            "{field}: mode {mode:?} is not drawn (only triangles are)"
        )));
    }
    let position = p
        .get(&gltf::Semantic::Positions)
        .ok_or_else(|| format!("{field}: has no POSITION attribute"))?;
    let attr = |name: &str, a: &gltf::Accessor| {
        format!("{field}.attributes.{name} (accessors[{}])", a.index())
    };
    let pos_field = attr("POSITION", &position);
    if position.dimensions() != Dimensions::Vec3 || position.data_type() != DataType::F32 {
        return Err(format!(
            "{pos_field}: is {}; positions must be VEC3 of FLOAT",
            describe(&position)
        ));
    }
    let n = position.count();
    budget.take("vertices", n, &pos_field)?;
    let raw = accessor::read_f32(&position, buffers, n).map_err(|e| format!("{pos_field}: {e}"))?;
    let positions: Vec<Vec3> = raw.chunks_exact(3).map(Vec3::from_slice).collect();
    for (i, v) in positions.iter().enumerate() {
        if !v.is_finite() {
            return Err(format!(
                "{pos_field}: element {i} is not finite; positions must be finite"
            ));
        }
        if v.abs().max_element() > MAX_VERTEX_COORD {
            return Err(format!(
                "{pos_field}: element {i} lies past ±{MAX_VERTEX_COORD:e} (object space is \
                 f32; place far objects with their node's transform)"
            ));
        }
    }
    let normals: Vec<Vec3> = read_vectors(p, &NORMAL, n, buffers, warnings, &attr)?
        .chunks_exact(3)
        .map(Vec3::from_slice)
        .collect();
    let uvs = read_uvs(p, 0, n, buffers, warnings, &attr)?;
    let colors = read_colors(p, n, buffers, warnings, &attr)?;
    let tangents: Vec<Vec4> = read_vectors(p, &TANGENT, n, buffers, warnings, &attr)?
        .chunks_exact(4)
        .map(Vec4::from_slice)
        .collect();
    let listed: Vec<u32> = match p.indices() {
        Some(a) => {
            let ifield = format!("{field}.indices (accessors[{}])", a.index());
            let integer = matches!(a.data_type(), DataType::U8 | DataType::U16 | DataType::U32);
            if a.dimensions() != Dimensions::Scalar || !integer {
                return Err(format!(
                    "{ifield}: is {}; indices must be SCALAR of UNSIGNED_BYTE, SHORT or INT",
                    describe(&a)
                ));
            }
            budget.take("indices", a.count(), &ifield)?;
            let indices =
                accessor::read_u32(&a, buffers, a.count()).map_err(|e| format!("{ifield}: {e}"))?;
            if let Some(k) = indices.iter().position(|&i| i as usize >= n) {
                return Err(format!(
                    "{ifield}: element {k} is out of range for {n} vertices"
                ));
            }
            indices
        }
        None => {
            budget.take("indices", n, field)?;
            (0..n as u32).collect()
        }
    };
    // Strips and fans unroll into up to three indices per listed one: counted before.
    if mode != Mode::Triangles {
        let unrolled = listed.len().saturating_sub(2).saturating_mul(3);
        budget.take("indices", unrolled.saturating_sub(listed.len()), field)?;
    }
    let listing = if p.indices().is_some() {
        "indices"
    } else {
        "vertices (it has no indices)"
    };
    let indices = triangles(mode, &listed, listing).map_err(|e| format!("{field}: {e}"))?;
    if indices.is_empty() {
        return Ok(Built::Skipped(format!("{field}: has no triangles")));
    }
    let sets = sets(buffers, warnings)?;
    let second_uvs = if sets.second() {
        read_uvs(p, 1, n, buffers, warnings, &attr)?
    } else {
        Vec::new()
    };
    let flat = normals.is_empty();
    // glTF asks for flat normals when a primitive has none: each triangle gets its own
    // three vertices, and the mesh's area-weighted normals are then the face normals.
    let unshare = |v: Vec<Vec4>| -> Vec<Vec4> {
        if !flat || v.is_empty() {
            return v;
        }
        indices.iter().map(|&i| v[i as usize]).collect()
    };
    // Without normals the file's tangents are ignored (glTF 2.0 §3.7.2.1): they were made for
    // normals the file does not give, so a normal map takes generated ones.
    let tangents = if flat { Vec::new() } else { tangents };
    if flat {
        // The unshared vertices replace the file's, counted before any is made.
        budget.give_back_vertices(n);
        budget.take("vertices", indices.len(), field)?;
    }
    let (colors, tangents) = (unshare(colors), unshare(tangents));
    let (positions, uvs, second_uvs, indices) = if flat {
        let pick = |i: &u32| positions[*i as usize];
        let flat_uvs = |uvs: Vec<Vec2>| -> Vec<Vec2> {
            match uvs.is_empty() {
                true => uvs,
                false => indices.iter().map(|&i| uvs[i as usize]).collect(),
            }
        };
        (
            indices.iter().map(pick).collect(),
            flat_uvs(uvs),
            flat_uvs(second_uvs),
            (0..indices.len() as u32).collect(),
        )
    } else {
        (positions, uvs, second_uvs, indices)
    };
    // A single-sided surface's front is its winding's side: kept as listed.
    let double_sided = p.material().double_sided();
    let mesh = if double_sided {
        Mesh::new(positions, normals, uvs, indices)
    } else {
        Mesh::new_as_wound(positions, normals, uvs, indices)
    };
    let mut mesh = mesh.map_err(|e| format!("{field}: {e}"))?;
    if !colors.is_empty() {
        mesh = mesh
            .with_colors(colors)
            .map_err(|e| format!("{field}: {e}"))?;
    }
    if !second_uvs.is_empty() {
        mesh = mesh
            .with_second_uvs(second_uvs)
            .map_err(|e| format!("{field}: {e}"))?;
    }
    for (set, coordinates) in [(0, &mesh.uvs), (1, &mesh.second_uvs)] {
        let textures = sets.named_on(set);
        if coordinates.is_empty() && !textures.is_empty() {
            warnings.push(format!(
                "{field}: its material has textures ({}) on TEXCOORD_{set}, which the \
                 primitive has not; they are not applied (its factors draw it)",
                textures.join(", ")
            ));
        }
    }
    let normal_set = sets
        .normal()
        .filter(|&set| mesh.coordinate_set(set).is_some());
    // Tangents only where a normal map will use them (they cost a vertex attribute), along
    // the set it reads.
    if let Some(set) = normal_set {
        if !tangents.is_empty() {
            mesh = mesh
                .with_tangents(tangents)
                .map_err(|e| format!("{field}: {e}"))?;
        } else {
            let (with, fallbacks) = mesh
                .with_tangents_along(set)
                .map_err(|e| format!("{field}: {e}"))?;
            mesh = with;
            if fallbacks > 0 {
                warnings.push(format!(
                    "{field}: {fallbacks} of {} triangle corners have no MikkTSpace tangent \
                     (degenerate or non-finite data, over {} triangles, or over {} corners at \
                     one position); they get the fallback tangent",
                    mesh.indices.len(),
                    crate::scene::tangents::MAX_TRIANGLES,
                    crate::scene::tangents::MAX_CORNERS_AT_A_POSITION,
                ));
            }
        }
    }
    // Exact copies of a triangle add only overdraw (a file listing one a million times took
    // seconds a frame); a blended surface keeps them, as its copies do blend.
    if p.material().alpha_mode() != gltf::material::AlphaMode::Blend {
        let dropped = crate::scene::duplicates::drop_duplicate_triangles(&mut mesh, double_sided);
        if dropped > 0 {
            warnings.push(format!(
                "{field}: {dropped} duplicate triangles dropped (the same corners as an earlier \
                 one; they add nothing to the picture)"
            ));
        }
    }
    Ok(Built::Mesh(mesh))
}

/// `TEXCOORD_{set}` of `p` (`n` vertices): VEC2 of FLOAT or normalized UNSIGNED_BYTE/SHORT,
/// every value finite; empty where it has none, or one of another type (with a warning).
fn read_uvs(
    p: &gltf::Primitive,
    set: u32,
    n: usize,
    buffers: &mut Buffers,
    warnings: &mut Vec<String>,
    attr: &dyn Fn(&str, &gltf::Accessor) -> String,
) -> Result<Vec<Vec2>, String> {
    let Some(a) = p.get(&gltf::Semantic::TexCoords(set)) else {
        return Ok(Vec::new());
    };
    let afield = attr(&format!("TEXCOORD_{set}"), &a);
    same_count(&afield, &a, n)?;
    let ok_type = match a.data_type() {
        DataType::F32 => true,
        DataType::U8 | DataType::U16 => a.normalized(),
        _ => false,
    };
    if a.dimensions() != Dimensions::Vec2 || !ok_type {
        warnings.push(format!(
            "{afield}: is {}, not VEC2 of FLOAT or normalized UNSIGNED_BYTE/SHORT; ignored",
            describe(&a)
        ));
        return Ok(Vec::new());
    }
    let raw = accessor::read_f32(&a, buffers, n).map_err(|e| format!("{afield}: {e}"))?;
    // glTF's (0, 0) is the image's top-left corner, as the renderer's is: no flip.
    let uvs: Vec<Vec2> = raw.chunks_exact(2).map(Vec2::from_slice).collect();
    if let Some(i) = uvs.iter().position(|t| !t.is_finite()) {
        return Err(format!(
            "{afield}: element {i} is not finite; texture coordinates must be finite"
        ));
    }
    Ok(uvs)
}

/// A FLOAT vector attribute that the loader replaces when it has another type.
struct VectorAttribute {
    semantic: gltf::Semantic,
    /// Its name in the file (`NORMAL`).
    name: &'static str,
    dimensions: Dimensions,
    /// What the loader does instead, for the warning.
    fallback: &'static str,
}

const NORMAL: VectorAttribute = VectorAttribute {
    semantic: gltf::Semantic::Normals,
    name: "NORMAL",
    dimensions: Dimensions::Vec3,
    fallback: "normals computed instead",
};

const TANGENT: VectorAttribute = VectorAttribute {
    semantic: gltf::Semantic::Tangents,
    name: "TANGENT",
    dimensions: Dimensions::Vec4,
    fallback: "tangents generated instead",
};

/// The attribute `what` of `p` as its floats, or empty when absent; another type is a
/// warning and empty.
fn read_vectors(
    p: &gltf::Primitive,
    what: &VectorAttribute,
    n: usize,
    buffers: &mut Buffers,
    warnings: &mut Vec<String>,
    attr: &dyn Fn(&str, &gltf::Accessor) -> String,
) -> Result<Vec<f32>, String> {
    let Some(a) = p.get(&what.semantic) else {
        return Ok(Vec::new());
    };
    let field = attr(what.name, &a);
    same_count(&field, &a, n)?;
    if a.dimensions() != what.dimensions || a.data_type() != DataType::F32 {
        warnings.push(format!(
            "{field}: is {}, not VEC{} of FLOAT; {}",
            describe(&a),
            what.dimensions.multiplicity(),
            what.fallback
        ));
        return Ok(Vec::new());
    }
    accessor::read_f32(&a, buffers, n).map_err(|e| format!("{field}: {e}"))
}

/// An attribute (`field`, its glTF path) must have one element per position (`n`).
fn same_count(field: &str, a: &gltf::Accessor, n: usize) -> Result<(), String> {
    if a.count() != n {
        return Err(format!(
            "{field}: {} elements but POSITION has {n}",
            a.count()
        ));
    }
    Ok(())
}

/// `COLOR_0` as linear RGBA (VEC3 or VEC4 of FLOAT or normalized UNSIGNED_BYTE/SHORT), or
/// empty; another type is a warning and ignored.
fn read_colors(
    p: &gltf::Primitive,
    n: usize,
    buffers: &mut Buffers,
    warnings: &mut Vec<String>,
    attr: &dyn Fn(&str, &gltf::Accessor) -> String,
) -> Result<Vec<Vec4>, String> {
    let Some(a) = p.get(&gltf::Semantic::Colors(0)) else {
        return Ok(Vec::new());
    };
    let field = attr("COLOR_0", &a);
    same_count(&field, &a, n)?;
    let ok_type = match a.data_type() {
        DataType::F32 => true,
        DataType::U8 | DataType::U16 => a.normalized(),
        _ => false,
    };
    let dims = match a.dimensions() {
        Dimensions::Vec3 => 3,
        Dimensions::Vec4 => 4,
        _ => 0,
    };
    if !ok_type || dims == 0 {
        warnings.push(format!(
            "{field}: is {}, not VEC3/VEC4 of FLOAT or normalized UNSIGNED_BYTE/SHORT; ignored",
            describe(&a)
        ));
        return Ok(Vec::new());
    }
    let raw = accessor::read_f32(&a, buffers, n).map_err(|e| format!("{field}: {e}"))?;
    let colors: Vec<Vec4> = raw
        .chunks_exact(dims)
        .map(|c| Vec4::new(c[0], c[1], c[2], if dims == 4 { c[3] } else { 1.0 }))
        .collect();
    if let Some(i) = colors.iter().position(|c| !c.is_finite()) {
        return Err(format!(
            "{field}: element {i} is not finite; colours must be finite"
        ));
    }
    // The mesh clamps them: said, since a colour of −1e30 is black.
    // Exporters write float colours a rounding past 1 (1.0000001): not worth a word.
    const SLACK: f32 = 1e-5;
    let outside =
        |c: &Vec4| c.cmplt(Vec4::splat(-SLACK)).any() || c.cmpgt(Vec4::splat(1.0 + SLACK)).any();
    if let Some(i) = colors.iter().position(outside) {
        let count = colors.iter().filter(|c| outside(c)).count();
        warnings.push(format!(
            "{field}: {count} elements (the first, element {i}) have a component outside \
             [0, 1], where glTF colours lie; clamped into it"
        ));
    }
    // All white and opaque (as exporters often write it) multiplies by 1: left out, the mesh
    // uploads no colours and draws without the vertex-colour variant.
    if colors.iter().all(|c| c.cmpge(Vec4::ONE).all()) {
        return Ok(Vec::new());
    }
    Ok(colors)
}

/// Bytes a vertex takes while a primitive is built (its attributes and their copies), with
/// room to spare over what was measured (docs/gltf.md).
const VERTEX_BYTES: u64 = 128;

/// Bytes a triangle takes while a primitive is built (indices, the duplicate search).
const TRIANGLE_BYTES: u64 = 40;

/// Bytes a triangle corner takes while MikkTSpace makes tangents.
const TANGENT_CORNER_BYTES: u64 = 128;

/// Refuses a primitive whose building this process cannot allocate now: the allocations
/// happen in libraries (`bevy_mikktspace`, the standard sort) that abort where one fails.
/// Counts past the file's limits are left to [`Budget`]'s error.
pub(super) fn check_memory(p: &gltf::Primitive, field: &str) -> Result<(), String> {
    let vertices = p.get(&gltf::Semantic::Positions).map_or(0, |a| a.count());
    let listed = p.indices().map_or(vertices, |a| a.count());
    let triangles = match p.mode() {
        Mode::Triangles => listed / 3,
        Mode::TriangleStrip | Mode::TriangleFan => listed.saturating_sub(2),
        _ => return Ok(()),
    };
    if vertices > super::MAX_VERTICES || 3 * triangles > super::MAX_INDICES {
        return Ok(());
    }
    let tangents =
        p.material().normal_texture().is_some() && p.get(&gltf::Semantic::Tangents).is_none();
    let corners = if tangents { 3 * triangles } else { 0 };
    let bytes = vertices as u64 * VERTEX_BYTES
        + triangles as u64 * TRIANGLE_BYTES
        + corners as u64 * TANGENT_CORNER_BYTES;
    crate::scene::alloc_probe::ask(
        bytes,
        format_args!("{field}: building its {vertices} vertices and {triangles} triangles takes"),
    )
}

/// A triangle list from the primitive's mode and its (checked) vertex sequence.
/// `listing` names what `v` lists, for the error: indices, or the vertices themselves.
fn triangles(mode: Mode, v: &[u32], listing: &str) -> Result<Vec<u32>, String> {
    match mode {
        Mode::Triangles => {
            if !v.len().is_multiple_of(3) {
                return Err(format!(
                    "{} {listing} is not a whole number of triangles",
                    v.len()
                ));
            }
            Ok(v.to_vec())
        }
        // Triangle i is (i, i+1, i+2) for even i and (i, i+2, i+1) for odd i: every one keeps
        // the strip's winding.
        Mode::TriangleStrip => Ok((0..v.len().saturating_sub(2))
            .flat_map(|i| {
                if i % 2 == 0 {
                    [v[i], v[i + 1], v[i + 2]]
                } else {
                    [v[i], v[i + 2], v[i + 1]]
                }
            })
            .collect()),
        Mode::TriangleFan => Ok((0..v.len().saturating_sub(2))
            .flat_map(|i| [v[i + 1], v[i + 2], v[0]])
            .collect()),
        _ => Ok(Vec::new()),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn strips_and_fans_unroll_with_their_winding() {
        assert_eq!(
            triangles(Mode::TriangleStrip, &[0, 1, 2, 3, 4], "indices").unwrap(),
            [0, 1, 2, 1, 3, 2, 2, 3, 4]
        );
        assert_eq!(
            triangles(Mode::TriangleFan, &[0, 1, 2, 3], "indices").unwrap(),
            [1, 2, 0, 2, 3, 0]
        );
        assert!(triangles(Mode::TriangleStrip, &[0, 1], "indices")
            .unwrap()
            .is_empty());
        assert!(triangles(Mode::Triangles, &[0, 1, 2, 3], "indices")
            .unwrap_err()
            .contains("4 indices"));
        // A primitive without indices lists its vertices: the error says so.
        let listing = "vertices (it has no indices)";
        assert!(triangles(Mode::Triangles, &[0, 1, 2, 3], listing)
            .unwrap_err()
            .contains("4 vertices (it has no indices) is not a whole number"));
    }

    /// A non-indexed primitive without normals unshares nothing more than its own vertices:
    /// they replace the file's in the budget instead of counting twice.
    #[test]
    fn flat_normals_count_their_vertices_once() {
        let floats: Vec<u8> = [0f32, 0., 0., 1., 0., 0., 0., 1., 0.]
            .iter()
            .flat_map(|v| v.to_le_bytes())
            .collect();
        let uri = format!(
            "data:application/octet-stream;base64,{}",
            base64::Engine::encode(&base64::engine::general_purpose::STANDARD, &floats)
        );
        let json = serde_json::json!({
            "asset": {"version": "2.0"},
            "buffers": [{"byteLength": 36, "uri": uri}],
            "bufferViews": [{"buffer": 0, "byteLength": 36}],
            "accessors": [{"bufferView": 0, "componentType": 5126, "type": "VEC3", "count": 3}],
            "meshes": [{"primitives": [{"attributes": {"POSITION": 0}}]}]
        });
        let root: gltf::json::Root = serde_json::from_value(json).unwrap();
        let document = gltf::Document::from_json_without_validation(root);
        let dir = std::env::temp_dir();
        let mut buffers = Buffers::new(&document, None, Some(&dir), false);
        let primitive = document
            .meshes()
            .next()
            .unwrap()
            .primitives()
            .next()
            .unwrap();
        let mut budget = Budget {
            vertices: 5,
            indices: 10,
        };
        let built = build(
            &primitive,
            &mut |_, _| Ok(TextureSets::default()),
            "m",
            &mut buffers,
            &mut budget,
            &mut Vec::new(),
        );
        assert!(matches!(built, Ok(Built::Mesh(_))), "{:?}", built.err());
        assert_eq!(budget.vertices, 2);
    }

    #[test]
    fn the_budget_refuses_past_the_limit() {
        let mut b = Budget {
            vertices: 10,
            indices: 10,
        };
        assert!(b.take("vertices", 10, "m").is_ok());
        let err = b.take("vertices", 1, "meshes[0]").unwrap_err();
        assert!(
            err.starts_with("meshes[0]") && err.contains("limit"),
            "{err}"
        );
    }
}
