//! OBJ + MTL loading (tobj) with textures (image; found and decoded in `obj/textures.rs`).
//!
//! A model reads only files in its own folder (the OBJ's), as a glTF does (`access.rs`):
//! an `mtllib` or texture named by `..` or an absolute path, or a link leading out, is refused
//! with a warning unless [`LoadOptions::allow_outside_files`]. A texture that is missing,
//! refused or does not decode is a warning and the material keeps its flat `Kd` colour — the
//! load never aborts for a texture.

use std::path::{Component, Path};
use std::sync::Arc;

use glam::{DMat4, DVec3, Vec2, Vec3};

use super::access::{self, LoadOptions};
use super::input::{read_bounded, read_bounded_within, FileKind};
use super::material::{MAX_COLOR_FACTOR, MAX_SHININESS};
use super::surface_maps::{SurfaceMaps, TextureTransform};
use super::texture::{Sampling, Texture, Wrap};
use super::texture_budget::TextureBudget;
use super::{short3, shown, Aabb, LoadReport, Material, Mesh, Object, Scene, SceneError};
use map_options::MapStatement;

mod corners;
#[cfg(test)]
mod hostile_tests;
mod lines;
mod map_options;
mod parse_memory;
#[cfg(test)]
mod tests;
mod text;
mod textures;

pub use super::texture_names::resolve_texture;
use super::texture_names::{resolve_in as resolve_texture_in, Listings};
use super::texture_names::{within_folder, TextureFinder};
pub use lines::{MAX_OBJ_CORNERS, MAX_OBJ_MATERIALS};
use text::text_of;
use textures::TextureCache;

/// Loads an OBJ file (and its MTL) into `scene`, placing it with `transform`. Returns the
/// warnings. `texture_override` binds a diffuse texture to every material (for models that
/// ship a texture but no MTL; the caller's own file, so not confined to the model's folder).
/// The textures kept take their part of `budget` (the whole scene's).
pub fn load_into(
    scene: &mut Scene,
    path: &Path,
    transform: DMat4,
    texture_override: Option<&Path>,
    options: &LoadOptions,
    budget: &mut TextureBudget,
) -> Result<LoadReport, SceneError> {
    let mut report = LoadReport::default();
    let allow_outside = options.allow_outside_files;
    let (models, materials, not_utf8, mtl_warnings, mtl_folders) = parse_obj(path, allow_outside)?;
    for warning in mtl_warnings {
        report.warn(warning);
    }
    if not_utf8 {
        report.warn(format!(
            "{}: not UTF-8 text; bytes that are not (in names) were replaced by U+FFFD",
            path.display()
        ));
    }
    if models.is_empty() || models.iter().all(|m| m.mesh.indices.is_empty()) {
        return Err(SceneError::Obj {
            path: path.to_path_buf(),
            reason: "no faces".into(),
        });
    }
    let base_dir = path.parent().unwrap_or(Path::new("."));
    let within = access::confinement(base_dir, allow_outside);
    let mut textures = TextureCache::default();
    let mut finder = TextureFinder::default();
    let override_tex =
        texture_override.and_then(|p| textures.load(p, None, budget, &mut |w| report.warn(w)));
    let mtl = match materials {
        Ok(m) => m,
        Err(e) => {
            report.warn(format!(
                "{}: materials not loaded ({e}); using a default grey",
                path.display()
            ));
            Vec::new()
        }
    };
    // A library's materials no face uses are not kept, nor their textures decoded: a shared
    // library may define hundreds, and every material kept costs each frame.
    let mut used = vec![false; mtl.len()];
    let drawn = models.iter().filter(|m| !m.mesh.indices.is_empty());
    for id in drawn.filter_map(|m| m.mesh.material_id) {
        if let Some(u) = used.get_mut(id) {
            *u = true;
        }
    }
    let mut material_of = vec![None; mtl.len()];
    for (id, m) in mtl.iter().enumerate() {
        if !used[id] {
            continue;
        }
        // The name as messages (and the renderer's stats) show it.
        let material_name = shown::name(&m.name);
        // The caller's texture replaces the MTL's, which is then not even decoded (it would
        // take its part of the budget for nothing).
        let statement = m.diffuse_texture.as_deref().map(MapStatement::parse);
        // Its names are relative to its library's folder.
        let mtl_folder = mtl_folders.get(id).map_or("", String::as_str);
        let texture = match &statement {
            _ if override_tex.is_some() => None,
            Some(MapStatement { file: name, .. }) if !name.is_empty() => {
                match finder.find(base_dir, mtl_folder, name, allow_outside) {
                    Ok(Some(p)) => textures.load(&p, within, budget, &mut |w| report.warn(w)),
                    Ok(None) => {
                        // Something there that is not a file (`/dev/zero`, a folder) is named so.
                        let from = base_dir.join(mtl_folder);
                        let what = if from.join(name).exists() {
                            "is not a regular file"
                        } else {
                            "not found"
                        };
                        let next_to = match mtl_folder {
                            "" => path.display().to_string(),
                            _ => format!("its library in {}", from.display()),
                        };
                        report.warn(format!(
                            "material `{material_name}`: texture `{}` {what} next to {next_to}; \
                             using its flat colour",
                            shown::name(name),
                        ));
                        None
                    }
                    Err(refusal) => {
                        report.warn(format!(
                            "material `{material_name}`: texture {refusal}; using its flat colour"
                        ));
                        None
                    }
                }
            }
            _ => None,
        };
        let mut factor = |key: &str, value: Option<[f64; 3]>, default: f32| {
            let written = value.unwrap_or([default.into(); 3]);
            let v = DVec3::from(written).as_vec3();
            // A NaN component takes the default's, as `Ns` and `d` do.
            let known = Vec3::select(v.is_nan_mask(), Vec3::splat(default), v);
            let clamped = known.max(Vec3::ZERO).min(Vec3::splat(MAX_COLOR_FACTOR));
            if clamped != v {
                report.warn(format!(
                    "material `{material_name}`: {key} {} taken as {} (factors are \
                     limited to [0, {MAX_COLOR_FACTOR}], the range the fp16 colour tier holds)",
                    short3(written),
                    short3(clamped)
                ));
            }
            clamped
        };
        let diffuse = factor("Kd", m.diffuse, 0.8);
        let specular = factor("Ks", m.specular, 0.0);
        // NaN takes the default, the rest their range (an exponent past f32 its largest
        // used); a warning names the MTL statement, not the library's field.
        let mut number = |key: &str, value: Option<f64>, default: f32, range: (f32, f32)| {
            let written = value.unwrap_or(f64::from(default));
            let kept = if written.is_nan() {
                default
            } else {
                written.clamp(range.0.into(), range.1.into()) as f32
            };
            // Compared in f32: a value written with more digits than f32 keeps is not changed.
            if kept != written as f32 {
                report.warn(format!(
                    "material `{material_name}`: {key} {written:?} taken as {kept} (its range is \
                     [{}, {}])",
                    range.0, range.1
                ));
            }
            kept
        };
        let shininess = number("Ns", m.shininess, 1.0, (0.0, MAX_SHININESS));
        let alpha = number("d", m.dissolve, 1.0, (0.0, 1.0));
        let mut maps = SurfaceMaps::default();
        let texture = match (texture, &statement) {
            (Some(texture), Some(statement)) => {
                let (texture, transform) =
                    apply_map_options(texture, statement, &material_name, &mut report);
                maps.base_transform = transform;
                Some(texture)
            }
            (texture, _) => texture,
        };
        material_of[id] = Some(scene.materials.len());
        scene.materials.push(Material {
            name: material_name,
            diffuse,
            diffuse_texture: override_tex.clone().or(texture),
            specular,
            shininess,
            alpha,
            maps,
            ..Material::default()
        });
    }
    let kept = mtl.iter().zip(&used).filter(|(_, &u)| u).map(|(m, _)| m);
    warn_unapplied_mtl(kept, path, &mut report);
    let fallback = scene.add_material(Material {
        diffuse_texture: override_tex.clone(),
        ..Material::flat("obj-default", Vec3::splat(0.8))
    });
    // Materials whose texture a mesh without `vt` was warned of, once each.
    let mut unmapped = std::collections::HashSet::new();
    for model in models {
        let m = model.mesh;
        if m.indices.is_empty() {
            continue;
        }
        // Read in f64 and stored about the object's own centre, which joins its transform: a
        // model far from its origin keeps detail that f32 coordinates there would round away.
        let positions: Vec<DVec3> = m.positions.chunks_exact(3).map(DVec3::from_slice).collect();
        // Past the object-space limit (or not finite) they stay where they are, and
        // `Mesh::new` refuses them by index.
        let limit = f64::from(super::mesh::MAX_VERTEX_COORD);
        let centre = Aabb::from_points(positions.iter().copied())
            .filter(|b| b.min.abs().max(b.max.abs()).max_element() <= limit)
            .map_or(DVec3::ZERO, |b| b.center());
        let positions: Vec<Vec3> = positions.iter().map(|p| (*p - centre).as_vec3()).collect();
        let normals: Vec<Vec3> = m
            .normals
            .chunks_exact(3)
            .map(|n| DVec3::from_slice(n).as_vec3())
            .collect();
        // OBJ's v axis points up; images store row 0 at the top: flip once here.
        let uvs: Vec<Vec2> = m
            .texcoords
            .chunks_exact(2)
            .map(|t| Vec2::new(t[0] as f32, 1.0 - t[1] as f32))
            .collect();
        let computed_normals = normals.is_empty();
        let mesh = Mesh::new(positions, normals, uvs, m.indices).map_err(|e| SceneError::Obj {
            path: path.to_path_buf(),
            reason: format!("object `{}`: {e}", shown::name(&model.name)),
        })?;
        let material = m
            .material_id
            .and_then(|id| material_of.get(id).copied().flatten())
            .unwrap_or(fallback);
        let textured = scene.materials[material].diffuse_texture.is_some();
        if textured && mesh.uvs.is_empty() && unmapped.insert(material) {
            report.warn(format!(
                "{}: object `{}` has no texture coordinates (`vt`), so material `{}`'s texture \
                 is not applied there (its Kd draws it)",
                path.display(),
                shown::name(&model.name),
                shown::name(&scene.materials[material].name)
            ));
        }
        let (mut mesh, dropped) =
            super::duplicates::drop_from_opaque(mesh, &scene.materials[material], || {
                format!("{}: object `{}`", path.display(), shown::name(&model.name))
            });
        if let Some(warning) = dropped {
            report.warn(warning);
            // Normals the faces gave, copies included: a sheet listed in both windings
            // cancelled to nothing.
            if computed_normals {
                mesh.recompute_normals();
            }
        }
        scene.objects.push(Object {
            mesh: Arc::new(mesh),
            material,
            transform: transform * DMat4::from_translation(centre),
        });
    }
    Ok(report)
}

/// What [`load_into`] asks of the allocator for an OBJ whose text is `text`, before it
/// rewrites the text (where it does) and before tobj parses it, besides the text: the parse
/// bounded from the corners written or (where that is refused) from the distinct ones
/// counted (`lab`: the tests hold loads to both).
#[cfg(feature = "lab")]
pub fn load_memory_bounds(text: &str, distinct_counted: bool) -> (u64, u64) {
    let mut counts = parse_memory::ObjCounts::of(text);
    if distinct_counted {
        counts.count_distinct(text);
        assert!(counts.distinct.is_some(), "no room to count the corners");
    }
    (counts.rewrite_bytes(), counts.parse_bytes())
}

/// `texture` as `map_Kd`'s options read it (`-clamp`), and the base colour's transform
/// (`-o`, `-s`); a warning names the options that are not applied and a transform that is
/// not usable (left out).
fn apply_map_options(
    texture: Arc<Texture>,
    statement: &MapStatement,
    material_name: &str,
    report: &mut LoadReport,
) -> (Arc<Texture>, TextureTransform) {
    let texture = if statement.clamp {
        Arc::new(texture.with_sampling(Sampling {
            wrap_u: Wrap::ClampToEdge,
            wrap_v: Wrap::ClampToEdge,
            ..Sampling::default()
        }))
    } else {
        texture
    };
    if !statement.unapplied.is_empty() {
        report.warn(format!(
            "material `{material_name}`: map_Kd options not applied: {}",
            statement.unapplied.join(", ")
        ));
    }
    let transform = statement.transform().unwrap_or_else(|| {
        report.warn(format!(
            "material `{material_name}`: map_Kd -o {:?} -s {:?} left out (texture coordinate \
             offsets and scales must be finite and within ±{:e})",
            statement.offset,
            statement.scale,
            super::mesh::MAX_TEXCOORD
        ));
        TextureTransform::IDENTITY
    });
    (texture, transform)
}

/// Most material libraries one OBJ's `mtllib` lines may name (distinct names; a model uses
/// one or a few). Each is read within its own limit, so this bounds what they read together.
const MAX_MTL_LIBRARIES: usize = 64;

/// Parses an OBJ read within its size limit, its MTL libraries read the same way and checked
/// first for what tobj would panic on. tobj runs under `catch_unwind` as a last guard: a panic
/// inside it becomes an error naming the file, never an abort of the caller. The last value
/// is true when the OBJ was not UTF-8 (read lossily, see [`text_of`]).
/// The warnings are the material libraries' (each refused, unreadable or malformed one).
type Parsed = (
    Vec<tobj::Model>,
    Result<Vec<tobj::Material>, tobj::LoadError>,
    bool,
    Vec<String>,
    Vec<String>,
);

/// Asks the allocator for the `bytes` an OBJ's `step` may take: an error naming the file and
/// its counts where they cannot be had.
fn ask_for(
    path: &Path,
    step: &str,
    counts: &parse_memory::ObjCounts,
    bytes: u64,
) -> Result<(), SceneError> {
    if super::alloc_probe::can_allocate(bytes) {
        return Ok(());
    }
    let reason = format!(
        "{step} it (faces: {}, vertices: {}) may take up to {} MiB, more than this process can \
         allocate now",
        counts.faces,
        counts.positions,
        bytes.div_ceil(1 << 20)
    );
    Err(SceneError::Io {
        path: path.to_path_buf(),
        source: std::io::Error::new(std::io::ErrorKind::OutOfMemory, reason),
    })
}

fn parse_obj(path: &Path, allow_outside: bool) -> Result<Parsed, SceneError> {
    let (text, not_utf8) = text_of(read_bounded(path, FileKind::Model)?).map_err(|bytes| {
        let reason = format!(
            "reading it as text (bytes that are not UTF-8 replaced by U+FFFD) may take up to {} \
             MiB, more than this process can allocate now",
            bytes.div_ceil(1 << 20)
        );
        SceneError::Io {
            path: path.to_path_buf(),
            source: std::io::Error::new(std::io::ErrorKind::OutOfMemory, reason),
        }
    })?;
    let rewrites = lines::check_obj(&text).map_err(|reason| SceneError::Obj {
        path: path.to_path_buf(),
        reason,
    })?;
    // Every step after the read asks for its most first: a failed allocation in tobj (or in
    // a copy of the text) would abort the process.
    let mut counts = parse_memory::ObjCounts::of(&text);
    let text = if rewrites.needed() {
        ask_for(path, "rewriting", &counts, counts.rewrite_bytes())?;
        lines::rewrite(&text, &rewrites)
    } else {
        text
    };
    let mixed = corners::mixed(&text);
    if mixed.contains(&true) {
        ask_for(path, "rewriting", &counts, counts.rewrite_bytes())?;
    }
    let filled = corners::fill_missing(&text, mixed);
    // The bound from the corners written first; where that is refused, from the distinct
    // ones, counted (real meshes share each vertex among about six triangles).
    if !super::alloc_probe::can_allocate(counts.parse_bytes()) {
        counts.count_distinct(&text);
        ask_for(path, "loading", &counts, counts.parse_bytes())?;
    }
    let filled_corners = filled.is_some();
    let text = filled.unwrap_or(text);
    let base_dir = path.parent().unwrap_or(Path::new(".")).to_path_buf();
    let options = tobj::LoadOptions {
        triangulate: true,
        single_index: true,
        ignore_points: true,
        ignore_lines: true,
    };
    // Each library is read once: tobj reads and merges one again for every `mtllib` line, so
    // a file repeating the line millions of times would exhaust memory. Each name is looked
    // up once, and at most `MAX_MTL_LIBRARIES` of them (each looks at the disk and may warn).
    let named = std::cell::RefCell::new(std::collections::HashSet::new());
    let seen = std::cell::RefCell::new(std::collections::HashSet::new());
    let past_libraries = std::cell::Cell::new(false);
    // Materials the libraries read so far define (within `lines::MAX_OBJ_MATERIALS`).
    let defined = std::cell::Cell::new(0);
    let warnings = std::cell::RefCell::new(Vec::new());
    if filled_corners {
        warnings.borrow_mut().push(format!(
            "{}: some face corners name a texture coordinate or normal and others do not; \
             those without take texture coordinate (0, 0) and their faces' normal",
            path.display()
        ));
    }
    warnings.borrow_mut().extend(rewrites.warnings(path));
    let warn = |w: String| warnings.borrow_mut().push(w);
    // Each material's library's folder, in the materials' order.
    let mtl_folders = std::cell::RefCell::new(Vec::new());
    let load_mtl = |name: &Path| -> tobj::MTLLoadResult {
        let name = name.to_string_lossy().replace('\\', "/");
        {
            let mut named = named.borrow_mut();
            if named.contains(&name) {
                return Ok(Default::default());
            }
            if named.len() >= MAX_MTL_LIBRARIES {
                if !past_libraries.replace(true) {
                    warn(format!(
                        "{}: more than {MAX_MTL_LIBRARIES} material libraries named; the rest \
                         are not read",
                        path.display()
                    ));
                }
                return Ok(Default::default());
            }
            named.insert(name.clone());
        }
        // Found as written or in another letter case (an exporter on Windows), as textures
        // are, or by its bare file name; else read as joined, which says it is missing:
        // there is always a path.
        let listings = &mut Listings::default();
        let in_any_case = |joined, relative: &str, listings: &mut Listings| {
            resolve_texture_in(&base_dir, relative, allow_outside, listings).or(Some(joined))
        };
        let mtl_path = within_folder(&base_dir, &name, allow_outside, listings, in_any_case)
            .map(|found| found.unwrap_or_default())
            .map_err(|refusal| {
                warn(format!("{}: mtllib {refusal}", path.display()));
                tobj::LoadError::OpenFileFailed
            })?;
        // By the file it is (a link in the folder or another letter case may name it again).
        let file = std::fs::canonicalize(&mtl_path).unwrap_or_else(|_| mtl_path.clone());
        if !seen.borrow_mut().insert(file) {
            return Ok(Default::default());
        }
        let within = access::confinement(&base_dir, allow_outside);
        let bytes = read_bounded_within(&mtl_path, FileKind::Materials, within).map_err(|e| {
            warn(library_unread(path, &name, e));
            tobj::LoadError::OpenFileFailed
        })?;
        let (text, not_utf8) = text_of(bytes).map_err(|bytes| {
            warn(format!(
                "{}: not read: as text (bytes that are not UTF-8 replaced by U+FFFD) it may \
                 take up to {} MiB, more than this process can allocate now",
                mtl_path.display(),
                bytes.div_ceil(1 << 20)
            ));
            tobj::LoadError::OpenFileFailed
        })?;
        if not_utf8 {
            warn(format!(
                "{}: not UTF-8 text; bytes that are not (in names) were replaced by U+FFFD",
                mtl_path.display()
            ));
        }
        let kept = match lines::check_mtl(&text, defined.get(), &UNAPPLIED_MTL) {
            Ok((materials, kept)) => {
                defined.set(defined.get() + materials);
                kept
            }
            Err(line) => {
                warn(format!("{}: {line}", mtl_path.display()));
                return Err(tobj::LoadError::MaterialParseError);
            }
        };
        let library = tobj::load_mtl_buf(&mut std::io::BufReader::new(kept.as_bytes()));
        // Its materials' texture names start from its folder (tobj appends the libraries'
        // materials in the order they are read).
        if let Ok((materials, _)) = &library {
            let folder = folder_in(&base_dir, &mtl_path);
            mtl_folders
                .borrow_mut()
                .extend(std::iter::repeat_n(folder, materials.len()));
        }
        library
    };
    // tobj passes an `mtllib` line's rest as one name: one library whose name has spaces, or
    // several libraries (`mtllib a.mtl b.mtl`, as the format has it), each read in turn.
    let load_line = |line: &Path| -> tobj::MTLLoadResult {
        let whole = line.to_string_lossy();
        let names: Vec<&str> = whole.split_whitespace().collect();
        let plain = line.components().all(|c| matches!(c, Component::Normal(_)));
        if names.len() < 2 || (plain && base_dir.join(line).is_file()) {
            return load_mtl(line);
        }
        let mut merged = None;
        let mut failed = None;
        for name in names {
            match load_mtl(Path::new(name)) {
                Ok(library) => match &mut merged {
                    None => merged = Some(library),
                    Some((materials, by_name)) => {
                        let (more, more_names) = library;
                        for (material, i) in more_names {
                            by_name.entry(material).or_insert(i + materials.len());
                        }
                        materials.extend(more);
                    }
                },
                Err(e) => failed = Some(e),
            }
        }
        match (merged, failed) {
            (Some(merged), _) => Ok(merged),
            (None, Some(e)) => Err(e),
            (None, None) => Ok(Default::default()),
        }
    };
    let parsed = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| {
        tobj::load_obj_buf(
            &mut std::io::BufReader::new(text.as_bytes()),
            &options,
            load_line,
        )
    }));
    let obj_error = |reason: String| SceneError::Obj {
        path: path.to_path_buf(),
        reason,
    };
    let mut warnings = warnings.into_inner();
    match parsed {
        Ok(result) => result
            .map(|(models, materials)| {
                // A library that failed was warned of already.
                if let Ok(materials) = &materials {
                    let defined = materials.iter().map(|m| m.name.as_str()).collect();
                    if let Some(w) = lines::undefined_materials(&text, &defined) {
                        warnings.push(format!("{}: {w}", path.display()));
                    }
                }
                let folders = mtl_folders.into_inner();
                (models, materials, not_utf8, warnings, folders)
            })
            .map_err(|e| obj_error(lines::located(&text, &e))),
        Err(_) => Err(obj_error(
            "the OBJ parser (tobj) failed on this file; it is malformed".into(),
        )),
    }
}

/// The folder of `library` (a material library found from `base_dir`) relative to
/// `base_dir`, `/` separating, as texture names are written: empty for `base_dir` itself, and
/// where it cannot be spelled so (not UTF-8).
fn folder_in(base_dir: &Path, library: &Path) -> String {
    let folder = library.parent().and_then(|f| f.strip_prefix(base_dir).ok());
    let parts: Option<Vec<&str>> = folder.and_then(|f| f.iter().map(|c| c.to_str()).collect());
    parts.map(|p| p.join("/")).unwrap_or_default()
}

/// A material library that could not be read, as its warning says it: the OBJ, the name its
/// `mtllib` line gives (cut as a name from a file is) and why.
fn library_unread(obj: &Path, name: &str, error: SceneError) -> String {
    let why = match error {
        SceneError::Io { source, .. } => source.to_string(),
        other => other.to_string(),
    };
    format!(
        "{}: mtllib `{}` cannot be read: {why}",
        obj.display(),
        shown::name(name)
    )
}

/// MTL statements the Blinn-Phong OBJ material does not read but warns of (normal maps, the
/// PBR extension's `Pr`/`Pm`, emission maps): tobj keeps them as unknown statements.
const UNAPPLIED_MTL: [&str; 9] = [
    "norm", "Pr", "Pm", "map_Pr", "map_Pm", "map_Ke", "Ps", "Pc", "aniso",
];

/// [`UNAPPLIED_MTL`] statements and the others the material does not read: one warning per
/// file naming them and how many materials use each, so a model that relies on them is not
/// silently drawn flat.
fn warn_unapplied_mtl<'a>(
    mtl: impl Iterator<Item = &'a tobj::Material>,
    path: &Path,
    report: &mut LoadReport,
) {
    let mut used: Vec<(&str, usize)> = Vec::new();
    let mut count = |name: &'static str| match used.iter_mut().find(|(n, _)| *n == name) {
        Some((_, k)) => *k += 1,
        None => used.push((name, 1)),
    };
    for m in mtl {
        if m.normal_texture.is_some() {
            count("bump/map_Bump");
        }
        if m.emissive.is_some_and(|e| e.iter().any(|&c| c != 0.0)) {
            count("Ke");
        }
        for key in UNAPPLIED_MTL {
            // `Ke 0 0 0` and the like change nothing (exporters write them for every material).
            let zero = |v: &str| v.split_whitespace().all(|x| x.parse() == Ok(0.0f64));
            if m.unknown_param.get(key).is_some_and(|v| !zero(v)) {
                count(key);
            }
        }
    }
    if used.is_empty() {
        return;
    }
    let list: Vec<String> = used
        .iter()
        .map(|(n, k)| format!("{n} ({k} material{})", if *k == 1 { "" } else { "s" }))
        .collect();
    report.warn(format!(
        "{}: MTL statements not applied: {} (OBJ materials are Lambert + Blinn-Phong from Kd, \
         map_Kd, Ks, Ns and d; normal maps and metallic-roughness are read from glTF)",
        path.display(),
        list.join(", ")
    ));
}

/// Largest texture side decoded, in pixels (the largest `GL_MAX_TEXTURE_SIZE` common on phones;
/// the image is then kept within [`super::texture_budget::MAX_STORED_TEXTURE_SIDE`]).
pub const MAX_TEXTURE_SIDE: u32 = super::texture_budget::MAX_DECODED_SIDE;
