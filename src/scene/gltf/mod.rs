//! glTF 2.0 loading: `.gltf` (JSON with external or `data:` URI buffers) and `.glb`.
//!
//! The `gltf` crate parses and validates the JSON; everything it would read from disk
//! (buffers, images) is read here through [`crate::scene::input::read_bounded`], so the
//! size limits of OBJ files and textures hold for glTF too. What a file holds maps onto a
//! [`Scene`] as follows (details in `docs/gltf.md` and in each submodule):
//!
//! - the default scene (or scene 0; with no scene, the nodes without a parent), its node
//!   hierarchy composed in `f64` ([`nodes`]);
//! - each triangle primitive of each placed mesh → one [`Object`] sharing its [`Mesh`] with
//!   every other node that places it ([`mesh`]); points and lines are skipped with a warning;
//! - materials → Lambert + Blinn-Phong ([`material`]), their textures ([`texture`]) and
//!   surface maps (normal, emissive, occlusion, metallic-roughness, texture transforms);
//! - the first camera a node instances (depth first, in order) ([`camera`]);
//! - `KHR_lights_punctual` point, spot and directional lights, on one photometric scale
//!   ([`lights`]).
//!
//! A required extension the loader lacks, or a file with nothing to draw, is a
//! [`SceneError::GltfUnsupported`] naming it; features that change the picture but are not
//! drawn are warned once per file each (`ignored.rs`, which lists [`SUPPORTED_EXTENSIONS`]).
//!
//! Malformed files are [`SceneError::Gltf`] errors naming the file and the glTF path
//! (`meshes[2].primitives[0].indices (accessors[5]): element 7 is out of range for 4
//! vertices`); no message shows the bytes of a buffer. A transform that places the file
//! badly is blamed on the caller's field (`objects[2].transform` of a scene file). Buffer and
//! image URIs may name only files inside the glTF file's folder unless [`LoadOptions`] allows
//! more. The crate runs under `catch_unwind` as a last guard: a panic inside it becomes such
//! an error, never an abort of the caller.

mod accessor;
mod buffers;
pub mod camera;
mod fault;
mod glb;
mod ignored;
mod instances;
mod integers;
mod json_size;
pub mod lights;
mod maps;
pub mod material;
pub mod mesh;
pub mod nodes;
mod schema_path;
pub mod texture;
mod uri;

use std::collections::hash_map::Entry;
use std::collections::HashMap;
use std::path::Path;
use std::sync::Arc;

use glam::DMat4;

pub use lights::{
    unbounded_radius, CANDELA_TO_INTENSITY, LUX_TO_INTENSITY, PHOTOMETRIC_SCALE, UNBOUNDED_CUTOFF,
};
pub use material::{shininess, DIELECTRIC_SPECULAR};

use fault::{Fault, PARSER_FAILED};
pub(crate) use instances::Instanced;
use instances::Instances;

use super::access::LoadOptions;
use super::input::{self, read_bounded, FileKind};
use super::mesh::MAX_SCENE_MESHES;
use super::texture_budget::TextureBudget;
use super::LoadReport;
use super::{
    random, Aabb, Camera, DirectionalLight, Light, Material, Mesh, Object, Scene, SceneError,
};

/// Most vertices one glTF file may decode into (33.5 M, about 1 GiB of vertex data: what
/// the largest OBJ file allowed holds). Checked before each accessor is allocated.
pub const MAX_VERTICES: usize = 1 << 25;

pub use buffers::MAX_UNBACKED_ELEMENTS;

/// Most indices one glTF file may decode into (three per vertex of [`MAX_VERTICES`]).
pub const MAX_INDICES: usize = 3 << 25;

/// Most objects (placed primitives) one glTF file may make.
pub const MAX_OBJECTS: usize = super::mesh::MAX_SCENE_OBJECTS;

pub use ignored::SUPPORTED_EXTENSIONS;

/// What a glTF load produced besides what went into the scene.
#[derive(Debug, Default)]
pub struct GltfLoad {
    /// Warnings (unsupported features, missing textures, skipped lights), also logged.
    pub report: LoadReport,
    /// The first camera a node instances, in world space (the caller's transform applied).
    pub camera: Option<Camera>,
}

/// Loads what `--scene file.gltf|file.glb` names: the file's objects, materials and lights,
/// its camera (or one framing its bounds, as for OBJ), and `lights` = `Some((count, seed))`
/// seeded random lights added to the file's own (`count` 0: the file's lights only). A file
/// with nothing to draw is an error; one that leaves the scene without lights gets a hint.
pub fn load(
    path: &Path,
    lights: Option<(usize, u64)>,
    options: &LoadOptions,
) -> Result<(Scene, LoadReport), SceneError> {
    load_source(Source::File(path), lights, options)
}

/// [`load`] from `source`.
pub(crate) fn load_source(
    source: Source,
    lights: Option<(usize, u64)>,
    options: &LoadOptions,
) -> Result<(Scene, LoadReport), SceneError> {
    let path = source.name();
    if let Some((count, _)) = lights {
        input::check_light_count(count, "lights")?;
    }
    let mut scene = Scene::empty();
    let mut textures = TextureBudget::default();
    let (mut loaded, _) = load_source_into(
        &mut scene,
        source,
        DMat4::IDENTITY,
        "transform",
        options,
        &mut textures,
    )?;
    if scene.objects.is_empty() {
        // Its lights alone would render a black frame.
        return Err(SceneError::GltfUnsupported {
            path: path.to_path_buf(),
            reason: "nothing to draw: no node of the scene places a triangle mesh (only \
                     lights)"
                .into(),
        });
    }
    match loaded.camera {
        Some(camera) => scene.camera = camera,
        None => scene.frame_camera(),
    }
    if let (Some((count, seed)), Some(bounds)) = (lights, scene.bounds()) {
        input::check_light_count(count.saturating_add(scene.lights.len()), "lights")?;
        let volume = random::model_light_volume(&bounds);
        scene.lights.extend(random::lights(
            &volume,
            count,
            seed,
            random::LightSetStyle::Mixed,
        ));
    }
    // A sun lights the scene too: only a file with neither gets the hint.
    if scene.lights.is_empty() && scene.directional_lights.is_empty() {
        let hint = format!(
            "no lights in {}: ambient only; add lights (`Scene::lights`; `--lights N` on the command line)",
            path.display()
        );
        loaded.report.say(hint);
    }
    scene.validate()?;
    Ok((scene, loaded.report))
}

/// Loads a glTF file into `scene`, placing it with `transform`: objects and materials are
/// appended, lights appended in world space (moved and turned by `transform`; their radius is
/// not scaled). The scene's camera is left alone: the file's own comes back in the result.
/// A transform that puts what the file holds out of range is an [`SceneError::Invalid`] of
/// `transform_field` (what the caller calls it, e.g. `objects[2].transform`). On error
/// `scene` is unchanged. The textures kept take their part of `textures` (the whole scene's
/// budget; an error leaves none of it).
pub fn load_into(
    scene: &mut Scene,
    path: &Path,
    transform: DMat4,
    transform_field: &str,
    options: &LoadOptions,
    textures: &mut TextureBudget,
) -> Result<GltfLoad, SceneError> {
    let source = Source::File(path);
    load_source_into(scene, source, transform, transform_field, options, textures)
        .map(|(load, _)| load)
}

/// How a load placed the file, for placing it again without reading it.
pub(crate) struct Placement {
    /// Each object's transform before the placing one, in the order the objects were added.
    pub relative: Vec<DMat4>,
    /// The lights and camera the file instances (valid in the file's own space), when it
    /// instances any: they move with the placing transform, so another placement places
    /// them again.
    pub instanced: Option<Instanced>,
}

/// Where a glTF's bytes come from.
#[derive(Clone, Copy)]
pub(crate) enum Source<'a> {
    /// A file, whose folder its file URIs are read from.
    File(&'a Path),
    /// Memory: no file is read; `name` names it in messages.
    Memory { bytes: &'a [u8], name: &'a Path },
}

impl Source<'_> {
    /// What messages call it.
    fn name(&self) -> &Path {
        match self {
            Source::File(path) => path,
            Source::Memory { name, .. } => name,
        }
    }
}

/// [`load_into`] from `source`, with how the file was placed.
pub(crate) fn load_source_into(
    scene: &mut Scene,
    source: Source,
    transform: DMat4,
    transform_field: &str,
    options: &LoadOptions,
    textures: &mut TextureBudget,
) -> Result<(GltfLoad, Placement), SceneError> {
    if !transform.is_finite() {
        return Err(SceneError::invalid(transform_field, "must be finite"));
    }
    let path = source.name();
    let read;
    let bytes = match source {
        Source::File(path) => {
            read = read_bounded(path, FileKind::Gltf)?;
            &read[..]
        }
        Source::Memory { bytes, .. } => bytes,
    };
    let error = |reason: String| SceneError::Gltf {
        path: path.to_path_buf(),
        reason,
    };
    let imported = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| {
        import(bytes, source, transform, options, textures)
    }));
    let imported = match imported {
        Ok(imported) => imported.map_err(|fault| fault.into_error(path, transform_field))?,
        Err(_) => return Err(error(PARSER_FAILED.into())),
    };
    let added = imported.lights.len() + imported.directional_lights.len();
    input::check_lights_added(scene, added, &format!("{} lights", path.display()))?;
    let first_material = scene.materials.len();
    scene.materials.extend(imported.materials);
    scene
        .objects
        .extend(imported.objects.into_iter().map(|mut o| {
            o.material += first_material;
            o
        }));
    scene.lights.extend(imported.lights);
    scene.directional_lights.extend(imported.directional_lights);
    let mut report = LoadReport::default();
    for w in imported.warnings {
        report.warn(format!("{}: {w}", path.display()));
    }
    let load = GltfLoad {
        report,
        camera: imported.camera,
    };
    let placement = Placement {
        relative: imported.relative,
        instanced: imported.instanced,
    };
    Ok((load, placement))
}

/// A JSON error said by its kind and place: serde's own text quotes the offending value,
/// which may be any file's bytes (a scene file can name any file as its glTF).
fn json_error(e: &serde_json::Error, json: &[u8]) -> String {
    use serde_json::error::Category;
    let valid_json = || serde_json::from_slice::<serde::de::IgnoredAny>(json).is_ok();
    let what = match e.classify() {
        Category::Io => "could not be read".to_string(),
        Category::Eof => "ends early".to_string(),
        // The crate reports some misfits (an array too long) as syntax.
        Category::Syntax if !valid_json() => "is not valid JSON".to_string(),
        Category::Syntax | Category::Data => {
            let message = e.to_string();
            let at = schema_path::misfit(json).unwrap_or_else(|| "a value".into());
            match message.split_once(" at line") {
                // A missing field is named by the glTF schema, not by the file.
                Some((missing, _)) if missing.starts_with("missing field") => {
                    format!("is not glTF ({at}: {missing})")
                }
                // serde names the field by the schema's name (from the type, not the file).
                _ if message.starts_with("duplicate field") => {
                    let name = message
                        .split('`')
                        .nth(1)
                        .filter(|n| schema_path::is_schema_name(n));
                    let name = name.map_or("a field".to_string(), |n| format!("`{n}`"));
                    format!("is not glTF ({at}: {name} given twice)")
                }
                _ => format!("is not glTF ({at}: the wrong type or form)"),
            }
        }
    };
    format!("JSON {what} at line {}, column {}", e.line(), e.column())
}

/// Places the lights and camera of a file loaded before (`instanced`, from its
/// [`Placement`]) again with `transform` (finite: the caller checks it first, as a read
/// does), as reading `path` again there would.
pub(crate) fn place_again(
    instanced: &Instanced,
    path: &Path,
    transform: DMat4,
    transform_field: &str,
) -> Result<instances::Placed, SceneError> {
    // The parser's accessors, which the first read went through without failing.
    let placed =
        std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| instanced.place(transform)));
    match placed {
        Ok(placed) => placed.map_err(|fault| fault.into_error(path, transform_field)),
        Err(_) => Err(SceneError::Gltf {
            path: path.to_path_buf(),
            reason: PARSER_FAILED.into(),
        }),
    }
}

/// A built primitive, its object-space bounds, and whether some vertex colour is not opaque.
type BuiltMesh = (Arc<Mesh>, Option<Aabb>, bool);

/// A file's contents, converted; material indices start at 0.
struct Imported {
    objects: Vec<Object>,
    materials: Vec<Material>,
    lights: Vec<Light>,
    directional_lights: Vec<DirectionalLight>,
    camera: Option<Camera>,
    warnings: Vec<String>,
    /// Each object's transform before the placing one.
    relative: Vec<DMat4>,
    /// The lights and camera instanced, valid in the file's own space, if any.
    instanced: Option<Instanced>,
}

/// Everything is converted and checked in the file's own space first (faults are the file's),
/// then placed by `transform` and checked again (faults are the transform's).
fn import(
    bytes: &[u8],
    source: Source,
    transform: DMat4,
    options: &LoadOptions,
    textures: &mut TextureBudget,
) -> Result<Imported, Fault> {
    let path = source.name();
    let (json, bin) = if bytes.starts_with(glb::MAGIC) {
        let g = glb::split(bytes)?;
        (g.json, g.bin)
    } else {
        (bytes, None)
    };
    // The glTF specification lets a reader ignore a byte order mark, which some editors write.
    let json = json.strip_prefix(b"\xEF\xBB\xBF").unwrap_or(json);
    json_size::check(json)?
        .check_memory()
        .map_err(Fault::Memory)?;
    let root = gltf::json::deserialize::from_slice(json).map_err(|e| {
        // An integer past u32 fails the crate's parse as a wrong type: named as what it is.
        integers::check(json)
            .err()
            .unwrap_or_else(|| json_error(&e, json))
    })?;
    integers::check(json)?;
    if let Some(reason) = ignored::unsupported_required(&root) {
        return Err(Fault::Unsupported(reason));
    }
    validate(&root)?;
    let document = gltf::Document::from_json_without_validation(root);
    let locals = nodes::local_transforms(json)?;
    if locals.len() != document.nodes().len() {
        return Err(format!(
            "nodes: {} read in f64 but {} parsed",
            locals.len(),
            document.nodes().len()
        )
        .into());
    }
    let mut warnings = Vec::new();
    let base_dir = match source {
        Source::File(path) => Some(path.parent().unwrap_or(Path::new("."))),
        Source::Memory { .. } => {
            if let Some(reason) = buffers::file_buffer(&document) {
                return Err(Fault::Unsupported(reason));
            }
            None
        }
    };
    let mut buffers = buffers::Buffers::new(&document, bin, base_dir, options.allow_outside_files);
    let (roots, from) = nodes::roots(&document);
    let placed = nodes::walk(&document, &roots, &locals, DMat4::IDENTITY)?;

    let mut budget = mesh::Budget {
        vertices: MAX_VERTICES,
        indices: MAX_INDICES,
    };
    // Each primitive is built once, with its object-space bounds, however many nodes place it.
    let mut meshes: HashMap<(usize, usize), Option<BuiltMesh>> = HashMap::new();
    // Primitives of other meshes naming the same accessors, mode and material build the same
    // mesh: built once.
    let mut by_content: HashMap<mesh::ContentKey, Option<BuiltMesh>> = HashMap::new();
    // Lent to the materials' textures, handed back at the end (an error keeps none of it).
    let lent = std::mem::replace(textures, TextureBudget::spent());
    let mut materials = material::Materials::new(json, lent, &mut warnings);
    let mut out = Imported {
        objects: Vec::new(),
        materials: Vec::new(),
        lights: Vec::new(),
        directional_lights: Vec::new(),
        camera: None,
        warnings: Vec::new(),
        relative: Vec::new(),
        instanced: None,
    };
    let mut instances = Instances::default();
    let mut camera_nodes = 0;
    let mut mesh_count = 0;
    // Primitives placed, drawn or skipped: a skipped one makes no object, but N nodes placing
    // a mesh of P of them would otherwise be walked N·P times.
    let mut placements = 0usize;
    for p in &placed {
        let Some(node) = document.nodes().nth(p.node) else {
            continue;
        };
        let field = format!("nodes[{}]", p.node);
        let world = transform * p.world;
        let placing = |e: String| Fault::Placing(format!("placing {field}: {e}"));
        if let Some(m) = node.mesh() {
            for prim in m.primitives() {
                placements += 1;
                if placements > MAX_OBJECTS {
                    return Err(format!(
                        "{field}: more than {MAX_OBJECTS} placed primitives, drawn or skipped \
                         (the limit per file)"
                    )
                    .into());
                }
                let key = (m.index(), prim.index());
                let pfield = format!("meshes[{}].primitives[{}]", key.0, key.1);
                let cached = match meshes.entry(key) {
                    Entry::Occupied(e) => e.into_mut(),
                    Entry::Vacant(e) => {
                        let content = mesh::content_key(&prim);
                        let built = match by_content.get(&content) {
                            Some(built) => built.clone(),
                            None => {
                                let built = build_primitive(
                                    &prim,
                                    &mut |buffers, warnings| {
                                        materials.sets_read(
                                            &prim.material(),
                                            buffers,
                                            path,
                                            warnings,
                                        )
                                    },
                                    &pfield,
                                    &mut buffers,
                                    &mut budget,
                                    &mut warnings,
                                    &mut mesh_count,
                                )?;
                                by_content.insert(content, built.clone());
                                built
                            }
                        };
                        e.insert(built)
                    }
                };
                let Some((mesh, bounds, vertex_alpha)) = cached.clone() else {
                    continue;
                };
                check_placement(bounds, &p.world)
                    .map_err(|e| format!("{field} placing {pfield}: {e}"))?;
                check_placement(bounds, &world).map_err(|e| placing(format!("{pfield}: {e}")))?;
                let material = if vertex_alpha {
                    materials.get_with_vertex_alpha(
                        &prim.material(),
                        &mut buffers,
                        path,
                        &mut warnings,
                    )?
                } else {
                    materials.get(&prim.material(), &mut buffers, path, &mut warnings)?
                };
                out.objects.push(Object {
                    mesh,
                    material,
                    transform: world,
                });
                out.relative.push(p.world);
            }
        }
        if let Some(light) = node.light() {
            let lfield = format!(
                "{field} (extensions.KHR_lights_punctual.lights[{}])",
                light.index()
            );
            if let gltf::khr_lights_punctual::Kind::Spot {
                outer_cone_angle, ..
            } = light.kind()
            {
                if outer_cone_angle > std::f32::consts::FRAC_PI_2 {
                    warnings.push(format!(
                        "{lfield}: spot.outerConeAngle ({outer_cone_angle}) is past π/2, glTF's \
                         maximum: drawn as given"
                    ));
                }
            }
            instances.add_light(&light, p.node, p.world, &mut warnings)?;
        }
        if let Some(cam) = node.camera() {
            camera_nodes += 1;
            if camera_nodes == 1 {
                // The file's view is a suggestion: one the renderer cannot take (or that the
                // caller's transform puts out of range) gives way to the framed view.
                instances.add_camera(&document, &cam, p.node, p.world, &mut warnings);
            }
        }
    }
    // Lights and the camera placed after the objects, in node order, as a later reference
    // to the file places them again (`Instances::place`).
    let placed_instances = instances.place(&document, transform)?;
    out.lights = placed_instances.lights;
    out.directional_lights = placed_instances.directional_lights;
    out.camera = placed_instances.camera;
    warnings.extend(placed_instances.warnings);
    if out.objects.is_empty() && out.lights.is_empty() && out.directional_lights.is_empty() {
        return Err(Fault::Unsupported(format!(
            "nothing to show: {from} place no triangle mesh and no light"
        )));
    }
    (out.materials, *textures) = materials.finish();
    // Features first, then what the parts said, each once.
    out.warnings = ignored::unused_features(&document, camera_nodes);
    out.warnings.extend(ignored::once_per_feature(warnings));
    out.instanced = instances
        .any()
        .then(|| Instanced::new(&document, instances));
    Ok(out)
}

/// The `gltf` crate's validation (every index in range, every enum value known), except
/// required extensions (checked before, by [`ignored::unsupported_required`]), and that accessors may lack `min` and `max` or have malformed
/// ones: the spec asks exporters for them on positions, many omit them, and the loader does
/// not use them.
fn validate(root: &gltf::json::Root) -> Result<(), String> {
    use gltf::json::validation::{Checked, Error, Validate};
    // A major version past 2 (or a minimum past 2.0) may mean anything: refused, as the
    // specification asks (§3.2), without showing the file's string.
    if root.asset.version.split('.').next().map(str::trim) != Some("2") {
        return Err("asset.version: not a glTF 2.x version; this loader reads glTF 2.0".into());
    }
    if let Some(min) = &root.asset.min_version {
        let mut parts = min.trim().split('.').map(|p| p.parse::<u32>().ok());
        let (major, minor) = (parts.next().flatten(), parts.next().flatten());
        let at_most_2_0 =
            matches!((major, minor), (Some(m), _) if m < 2) || (major, minor) == (Some(2), Some(0));
        if !at_most_2_0 {
            return Err(
                "asset.minVersion: asks for more than glTF 2.0, which this loader reads".into(),
            );
        }
    }
    // The crate's own check of `min`/`max` indexes the accessors with POSITION's index
    // before it checks that index: checked here first.
    for (m, mesh) in root.meshes.iter().enumerate() {
        for (p, primitive) in mesh.primitives.iter().enumerate() {
            let position = primitive
                .attributes
                .get(&Checked::Valid(gltf::Semantic::Positions));
            if let Some(index) = position.filter(|i| i.value() >= root.accessors.len()) {
                return Err(format!(
                    "meshes[{m}].primitives[{p}].attributes.POSITION: accessors[{}] does not \
                     exist ({} accessors)",
                    index.value(),
                    root.accessors.len()
                ));
            }
        }
    }
    let mut errors = Vec::new();
    root.validate(root, gltf::json::Path::new, &mut |path, error| {
        // The crate spells the extension's key in camelCase; name it as the file does.
        let path = schema_path::without_made_up_keys(&path().to_string())
            .replace("khrLightsPunctual", "KHR_lights_punctual");
        let bounds = path.ends_with(".min") || path.ends_with(".max");
        let ignored_bounds = bounds && matches!(error, Error::Missing | Error::Invalid);
        // Required extensions are checked against the loader's own list, not the crate's.
        let required = path.starts_with("extensionsRequired");
        if !(required || ignored_bounds) {
            errors.push(format!("{path}: {error}"));
        }
    });
    if errors.is_empty() {
        return Ok(());
    }
    let shown = errors.len().min(8);
    let more = match errors.len() - shown {
        0 => String::new(),
        n => format!("; and {n} more"),
    };
    Err(format!(
        "invalid glTF: {}{more}",
        errors[..shown].join("; ")
    ))
}

/// A placed mesh's transform must be finite and place it as `Aabb::placement_refusal` says
/// (within the camera's coordinate limit, not shrunk into f32's subnormal numbers).
fn check_placement(bounds: Option<Aabb>, world: &DMat4) -> Result<(), String> {
    if let Some(reason) = Aabb::placement_refusal_of(bounds.as_ref(), world) {
        return Err(format!("the world transform {reason}"));
    }
    Ok(())
}

/// Builds primitive `p` (`pfield` names it), counting it in `mesh_count` once made: `None`
/// where it is skipped (points, lines), with a warning.
fn build_primitive(
    p: &gltf::Primitive,
    sets: mesh::AskSets<'_>,
    pfield: &str,
    buffers: &mut buffers::Buffers,
    budget: &mut mesh::Budget,
    warnings: &mut Vec<String>,
    mesh_count: &mut usize,
) -> Result<Option<BuiltMesh>, Fault> {
    mesh::check_memory(p, pfield).map_err(Fault::Memory)?;
    Ok(
        match mesh::build(p, sets, pfield, buffers, budget, warnings)? {
            mesh::Built::Mesh(mesh) => {
                // Counted once made: a skipped primitive (points, lines) holds nothing.
                *mesh_count += 1;
                if *mesh_count > MAX_SCENE_MESHES {
                    return Err(format!(
                        "{pfield}: more than {MAX_SCENE_MESHES} distinct meshes (primitives), the \
                     limit per file"
                    )
                    .into());
                }
                let bounds = mesh.bounds();
                let vertex_alpha = mesh.colors.iter().any(|c| c.w < 1.0);
                Some((Arc::new(mesh), bounds, vertex_alpha))
            }
            mesh::Built::Skipped(why) => {
                warnings.push(format!("{why}; skipped"));
                None
            }
        },
    )
}
