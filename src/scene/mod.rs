//! GL-free scene description: camera, lights, meshes, materials, OBJ loading, built-in
//! procedural scenes, seeded random lights, JSON scene files and a ray caster over the
//! triangles (`raycast`).
//!
//! Positions that can be far from the origin (camera, lights, object transforms) are `f64`;
//! the renderer subtracts the camera in `f64` before anything reaches the GPU as `f32`, so a
//! scene 10 km from the origin loses no precision on the device.

mod aabb;
pub mod access;
pub mod alloc_probe;
pub mod brdf;
pub mod builtin;
pub mod camera;
mod dark_frame;
pub mod direction;
pub mod directional;
mod duplicates;
pub mod error;
pub mod features;
#[cfg(feature = "scene-files")]
pub mod file;
pub mod framing;
mod gif_frame;
#[cfg(feature = "gltf")]
pub mod gltf;
pub mod input;
mod jpeg_frame;
mod jpeg_metadata;
mod json_count;
#[cfg(test)]
mod left_out_tests;
pub mod light;
mod light_list;
mod load_report;
mod loaders;
pub mod material;
pub mod mesh;
mod mesh_limits;
pub mod meshbuild;
#[cfg(feature = "scene-files")]
mod model_cache;
pub mod motion;
pub mod normal_matrix;
#[cfg(feature = "obj")]
pub mod obj;
mod one_way;
mod orientation;
mod png_metadata;
pub mod random;
pub mod raycast;
mod repeated_objects;
mod said;
pub mod shading;
pub mod shown;
pub mod surface_maps;
pub mod tangents;
pub mod texture;
pub mod texture_budget;
#[cfg(any(feature = "obj", feature = "gltf"))]
mod texture_names;
mod texture_sets;
pub(crate) mod triangle_reach;

use std::ops::Range;
use std::sync::Arc;

use glam::{DMat4, DVec4, Vec3};

use loaders::Loader;

pub use access::LoadOptions;
pub use camera::{Camera, Projection};
pub use directional::{DirectionalLight, MAX_DIRECTIONAL_LIGHTS};
pub use error::SceneError;
pub use light::{Cone, Light, LightKind};
pub use load_report::LoadReport;
pub use material::{Material, MaterialModel, Texture, MAX_DEPTH_BIAS};
pub use mesh::{Aabb, Mesh};
pub use mesh::{MAX_SCENE_MATERIALS, MAX_SCENE_MESHES, MAX_SCENE_OBJECTS};
pub use motion::Motion;
pub(crate) use shown::{short3, Short};

/// Most a transform's last row may differ from `0 0 0 1` (exporters and inverses round) before
/// it is refused as not affine.
const AFFINE_TOLERANCE: f64 = 1e-6;

/// Where `m`'s last row is not `0 0 0 1` (within [`AFFINE_TOLERANCE`]), the refusal's reason:
/// `last row … , must be 0 0 0 1`. A projective transform puts vertices at w ≠ 1 (a last row
/// of zeros, at infinity): a wrong picture or none.
pub(crate) fn not_affine(m: &DMat4) -> Option<String> {
    let last = m.row(3);
    ((last - DVec4::W).abs().max_element() > AFFINE_TOLERANCE).then(|| {
        format!(
            "last row {} {} {} {}, must be 0 0 0 1",
            Short(last.x),
            Short(last.y),
            Short(last.z),
            Short(last.w)
        )
    })
}

/// One placed mesh: shared geometry, its material and a model transform (`f64`, so objects
/// can be placed far from the origin).
#[derive(Clone, Debug)]
pub struct Object {
    /// Geometry in object space.
    pub mesh: Arc<Mesh>,
    /// Index into [`Scene::materials`].
    pub material: usize,
    /// Object space → world space.
    pub transform: DMat4,
}

/// Everything one frame needs: geometry, materials, lights, ambient light and the camera.
#[derive(Clone, Debug)]
pub struct Scene {
    /// Placed meshes.
    pub objects: Vec<Object>,
    /// Materials referenced by [`Object::material`].
    pub materials: Vec<Material>,
    /// Point and spot lights (validated with [`Scene::validate`] before rendering).
    pub lights: Vec<Light>,
    /// Lights from infinitely far away (a sun), evaluated for every pixel outside the light
    /// lists; at most [`MAX_DIRECTIONAL_LIGHTS`] are shown (the brightest, with a warning).
    pub directional_lights: Vec<DirectionalLight>,
    /// Ambient radiance in linear RGB, multiplied by the albedo.
    pub ambient: Vec3,
    /// The viewpoint.
    pub camera: Camera,
    /// Lights that move: [`Scene::set_time`] poses them (empty: a still scene). A track names
    /// its light by index, so replacing `lights` calls for clearing (or rebuilding) this.
    pub animation: Vec<motion::LightTrack>,
}

impl Scene {
    /// An empty scene with a default camera and a dim ambient term.
    pub fn empty() -> Self {
        Scene {
            objects: Vec::new(),
            materials: Vec::new(),
            lights: Vec::new(),
            directional_lights: Vec::new(),
            ambient: Vec3::splat(0.02),
            camera: Camera::default(),
            animation: Vec::new(),
        }
    }

    /// World-space bounds of all objects (`None` for a scene without geometry). Each distinct
    /// mesh's vertices are walked once, however many objects place it.
    pub fn bounds(&self) -> Option<Aabb> {
        let mut meshes = std::collections::HashMap::new();
        self.objects
            .iter()
            .filter_map(|o| {
                let b = meshes
                    .entry(Arc::as_ptr(&o.mesh))
                    .or_insert_with(|| o.mesh.bounds());
                b.map(|b| b.transformed(&o.transform))
            })
            .reduce(|a, b| a.union(&b))
    }

    /// Whether any object has a triangle of non-zero area as its transform places it (each
    /// distinct mesh read once): a node scaled by zero on an axis, or by 10⁻³⁰⁰, flattens its
    /// mesh into lines, which draw nothing.
    pub fn has_visible_area(&self) -> bool {
        let mut spans = std::collections::HashMap::new();
        self.objects.iter().any(|o| {
            let span = spans
                .entry(Arc::as_ptr(&o.mesh))
                .or_insert_with(|| o.mesh.normal_span());
            keeps_an_area(&o.transform, span)
        })
    }

    /// Places `mesh` (a [`Mesh`], or an `Arc` of one to share it between objects) with
    /// material `material` (an index from [`Scene::add_material`]) at `transform` (object
    /// space to world space); returns the object's index.
    pub fn add_object(
        &mut self,
        mesh: impl Into<Arc<Mesh>>,
        material: usize,
        transform: DMat4,
    ) -> usize {
        self.objects.push(Object {
            mesh: mesh.into(),
            material,
            transform,
        });
        self.objects.len() - 1
    }

    /// Adds a material and returns its index.
    pub fn add_material(&mut self, material: Material) -> usize {
        self.materials.push(material);
        self.materials.len() - 1
    }

    /// True when some light moves.
    pub fn is_animated(&self) -> bool {
        !self.animation.is_empty()
    }

    /// Gives light `index` a motion starting from its current state (a later track wins over
    /// an earlier one for the same light). Does nothing for a still motion or a missing light.
    pub fn animate_light(&mut self, index: usize, motion: motion::Motion) {
        if let (false, Some(rest)) = (motion.is_still(), self.lights.get(index)) {
            self.animation.push(motion::LightTrack {
                first: index,
                rest: vec![*rest],
                motion,
                vary: None,
                variation_start: 0,
            });
        }
    }

    /// Gives each light of `lights` (indices into [`Scene::lights`], e.g. `0..n`) its own
    /// variation of `motion` (seeded: phases, periods within ±25 %, wander and flicker seeds),
    /// starting from its current state. Does nothing for a still motion or a range past the
    /// lights.
    pub fn animate_lights(&mut self, lights: Range<usize>, motion: motion::Motion, seed: u64) {
        let rest = self
            .lights
            .get(lights.clone())
            .filter(|rest| !rest.is_empty());
        if let (false, Some(rest)) = (motion.is_still(), rest) {
            self.animation.push(motion::LightTrack {
                first: lights.start,
                rest: rest.to_vec(),
                motion,
                vary: Some(seed),
                variation_start: 0,
            });
        }
    }

    /// Removes light `index` and its place in the track that moves it, the other lights
    /// keeping their motions (later indices shift with the lights): what a game does when a
    /// light goes out for good. Removing it from `lights` alone would leave its track to pose
    /// the next light in its place. `None` past the end.
    pub fn remove_light(&mut self, index: usize) -> Option<Light> {
        if index >= self.lights.len() {
            return None;
        }
        let mut tracks = Vec::with_capacity(self.animation.len() + 1);
        for mut track in std::mem::take(&mut self.animation) {
            if index < track.first {
                track.first -= 1;
            } else if index - track.first < track.rest.len() {
                // Split round the removed light: the part after it keeps its variations.
                let k = index - track.first;
                let after = motion::LightTrack {
                    first: index,
                    rest: track.rest.split_off(k + 1),
                    // Variation numbers only seed a generator: wrapping is harmless.
                    variation_start: track.variation_start.wrapping_add(k + 1),
                    ..track
                };
                track.rest.truncate(k);
                tracks.extend([track, after].into_iter().filter(|t| !t.rest.is_empty()));
                continue;
            }
            tracks.push(track);
        }
        self.animation = tracks;
        Some(self.lights.remove(index))
    }

    /// Poses every animated light at time `t` (seconds; 0 is the scene as built). A pure
    /// function of `t`: frames can be rendered in any order. Allocates nothing; the part of a
    /// track past the end of `lights` is skipped. A motion moving 4 096 lights or more poses
    /// them in parallel on rayon's global pool (see [`Scene::set_time_on_this_thread`]).
    pub fn set_time(&mut self, t: f64) {
        self.pose(t, true);
    }

    /// [`Scene::set_time`] on the calling thread alone, never entering rayon: for a game whose
    /// own jobs fill rayon's global pool, where `set_time` would wait for one of them to end
    /// (as `RenderOptions::max_assign_threads` of 1 does for the light assignment).
    pub fn set_time_on_this_thread(&mut self, t: f64) {
        self.pose(t, false);
    }

    fn pose(&mut self, t: f64, parallel: bool) {
        /// Below this many lights a thread hand-off costs more than it saves.
        const PARALLEL_FROM: usize = 4096;
        for track in &self.animation {
            let Some(lights) = self.lights.get_mut(track.first..) else {
                continue;
            };
            let n = track.rest.len().min(lights.len());
            let lights = &mut lights[..n];
            if !parallel || lights.len() < PARALLEL_FROM {
                track.pose(lights, t);
            } else {
                use rayon::prelude::*;
                const CHUNK: usize = 1024;
                lights
                    .par_chunks_mut(CHUNK)
                    .enumerate()
                    .for_each(|(c, chunk)| {
                        for (j, light) in chunk.iter_mut().enumerate() {
                            let k = c * CHUNK + j;
                            *light = track.motion_of(k).apply(&track.rest[k], t);
                        }
                    });
            }
        }
    }

    /// Checks the scene's values the GPU will see besides its meshes: lights (finite,
    /// non-negative radius, valid cones), ambient colour, camera, material indices, material
    /// values and object transforms. Errors name the field. It runs every frame, so it stays
    /// cheap: a mesh, whose check is a pass over its vertices, is checked when it is uploaded
    /// (its first frame), or beforehand with [`Mesh::validate`].
    pub fn validate(&self) -> Result<(), SceneError> {
        self.camera.validate()?;
        if !self.ambient.is_finite() || self.ambient.min_element() < 0.0 {
            return Err(SceneError::invalid(
                "ambient",
                format!("must be finite and >= 0, got {:?}", self.ambient),
            ));
        }
        // Motions before lights: a bad motion poses its lights at NaN, which is its fault.
        for track in &self.animation {
            let field = || format!("lights[{}].motion", track.first);
            // Lights removed without their tracks: a track would pose whatever lights take
            // their places (lights pushed later included).
            if track.first.saturating_add(track.rest.len()) > self.lights.len() {
                return Err(SceneError::invalid(
                    field(),
                    format!(
                        "moves lights {}..{} but the scene has {}: remove lights with \
                         Scene::remove_light, retain_lights or truncate_lights, which remove \
                         them from their motions too",
                        track.first,
                        track.first.saturating_add(track.rest.len()),
                        self.lights.len()
                    ),
                ));
            }
            // A set's sweep applies to its spots only; a single light's must have a cone.
            let is_spot = track.vary.is_some()
                || track
                    .rest
                    .iter()
                    .all(|l| matches!(l.kind, LightKind::Spot { .. }));
            if track.motion.validate("", is_spot).is_err() {
                track.motion.validate(&field(), is_spot)?;
            }
            // Where its lights can go, so a light does not leave the lights' range at some
            // frame of a sequence, named by a position the file never wrote.
            for (k, rest) in track.rest.iter().enumerate() {
                // A motion moves a light by at most `MAX_DISPLACEMENT` (1e9): one within a
                // quarter of the limit stays inside it, and costs no roots every frame.
                if rest.position.abs().max_element() <= light::MAX_LIGHT_COORD / 4.0 {
                    continue;
                }
                let farthest = track.motion.farthest_coordinate(rest.position);
                // With room for the rotation's rounding (a light at the limit stays there).
                if farthest * (1.0 + 1e-12) > light::MAX_LIGHT_COORD {
                    return Err(SceneError::invalid(
                        field(),
                        format!(
                            "can carry lights[{}] to a coordinate of {farthest:e}, past the \
                             ±{:e} a light may be at",
                            track.first.saturating_add(k),
                            light::MAX_LIGHT_COORD
                        ),
                    ));
                }
            }
        }
        // Checked without a name first and named only on failure: a scene is validated every
        // frame, and a valid one costs no allocation.
        for (i, light) in self.lights.iter().enumerate() {
            if light.validate("").is_err() {
                light.validate(&format!("lights[{i}]"))?;
            }
        }
        for (i, light) in self.directional_lights.iter().enumerate() {
            if light.validate("").is_err() {
                light.validate(&format!("directional_lights[{i}]"))?;
            }
        }
        for (i, m) in self.materials.iter().enumerate() {
            if m.validate("").is_err() {
                m.validate(&format!("materials[{i}] ({})", m.name))?;
            }
        }
        for (i, o) in self.objects.iter().enumerate() {
            if o.material >= self.materials.len() {
                return Err(SceneError::invalid(
                    format!("objects[{i}].material"),
                    format!(
                        "index {} but the scene has {} materials",
                        o.material,
                        self.materials.len()
                    ),
                ));
            }
            if !o.transform.is_finite() {
                return Err(SceneError::invalid(
                    format!("objects[{i}].transform"),
                    "must be finite",
                ));
            }
            if let Some(row) = not_affine(&o.transform) {
                return Err(SceneError::invalid(
                    format!("objects[{i}].transform"),
                    format!("must be affine ({row})"),
                ));
            }
        }
        Ok(())
    }

    /// Points the camera at the scene bounds from a three-quarter view that keeps all of them
    /// in the picture, with a margin, at any aspect (width / height) of at least 1: square
    /// and landscape pictures. A scene without geometry keeps its camera. A scene so large
    /// (placed up to 10¹² out, as objects may be) that the eye would lie past
    /// the camera's ±10¹² gets that eye all the same, and a frame refuses it naming
    /// `camera.position`: such a scene takes a camera of its own.
    pub fn frame_camera(&mut self) {
        if let Some(b) = self.bounds() {
            self.camera = framing::framing(&b);
        }
    }
}

/// Seeded random lights to put in a scene: `count` of them, placed, coloured and moving by the
/// random generator seeded with `seed` (the same seed gives the same lights).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct RandomLights {
    /// How many (at most 4 194 304).
    pub count: usize,
    /// The generator's seed.
    pub seed: u64,
}

/// A built-in scene by name (`BUILTIN_SCENES`): `Some` lights replaces its own with seeded
/// random ones (which wander, flicker and sweep; [`Scene::set_time`] poses them), `None`
/// keeps the scene's own.
pub fn builtin_scene(name: &str, lights: Option<RandomLights>) -> Result<Scene, SceneError> {
    builtin::build(name, lights.map(|l| (l.count, l.seed)))
}

/// A scene as `manylight --scene` names it: a built-in name, an `.obj`, `.gltf`/`.glb` or
/// `.json` scene file, with `lights` random lights added (for a file's own lights, `None`),
/// and what the loader warned about.
pub fn load_scene(
    spec: &str,
    lights: Option<RandomLights>,
) -> Result<(Scene, LoadReport), SceneError> {
    load(spec, lights.map(|l| (l.count, l.seed)))
}

/// [`load_scene`] with `options` (e.g. letting a trusted glTF file read files outside its
/// folder, which [`load_scene`] refuses).
pub fn load_scene_with(
    spec: &str,
    lights: Option<RandomLights>,
    options: &LoadOptions,
) -> Result<(Scene, LoadReport), SceneError> {
    load_with(spec, lights.map(|l| (l.count, l.seed)), options)
}

/// A glTF 2.0 model held in memory — a GLB, or glTF JSON whose buffers and images are
/// embedded (`data:` URIs) — such as an Android game's APK asset or a download; `name` names
/// it in messages. Loaded as [`load_scene`] loads a `.glb` file (its camera or one framing
/// it, its lights, and `lights` random ones added), but it reads no file: a buffer whose URI
/// names one is an error, an image a warning (its material keeps its flat colour).
#[cfg(feature = "gltf")]
pub fn load_gltf_from_memory(
    bytes: &[u8],
    name: &str,
    lights: Option<RandomLights>,
) -> Result<(Scene, LoadReport), SceneError> {
    let name = std::path::Path::new(name);
    said::once_each(|| {
        let source = gltf::Source::Memory { bytes, name };
        let lights = lights.map(|l| (l.count, l.seed));
        let loaded = gltf::load_source(source, lights, &LoadOptions::default())?;
        finish_load(loaded, name, "glb")
    })
}

/// True when `spec` names a file that brings its own lights (a `.json` scene file, a `.gltf`
/// or `.glb` file): the CLI then adds random lights only when asked to.
pub fn brings_own_lights(spec: &str) -> bool {
    let spec = spec.to_lowercase();
    [".json", ".gltf", ".glb"].iter().any(|e| spec.ends_with(e))
}

/// Loads what the CLI's `--scene` names: a built-in name, an `.obj` file (camera framed on its
/// bounds), a `.gltf` or `.glb` file (its own camera and lights; see `gltf::load`) or a
/// `.json` scene file. `lights` = `Some((count, seed))` sets seeded random lights
/// (for scene files, it replaces their `random_lights` count but keeps explicit lights).
pub fn load(spec: &str, lights: Option<(usize, u64)>) -> Result<(Scene, LoadReport), SceneError> {
    load_with(spec, lights, &LoadOptions::default())
}

/// [`load`] with `options`. Its warnings are logged once each when it ends (also when it
/// fails) and kept in the report.
pub fn load_with(
    spec: &str,
    lights: Option<(usize, u64)>,
    options: &LoadOptions,
) -> Result<(Scene, LoadReport), SceneError> {
    let (loaded, files) =
        input::recording_files_read(|| said::once_each(|| load_held(spec, lights, options)));
    loaded.map(|(scene, mut report)| {
        report.files = files;
        (scene, report)
    })
}

/// [`load_with`], its warnings held back by the caller.
#[cfg_attr(
    not(any(feature = "obj", feature = "gltf", feature = "scene-files")),
    allow(unused_variables)
)]
fn load_held(
    spec: &str,
    lights: Option<(usize, u64)>,
    options: &LoadOptions,
) -> Result<(Scene, LoadReport), SceneError> {
    let path = std::path::Path::new(spec);
    let ext = path
        .extension()
        .map(|e| e.to_string_lossy().to_lowercase())
        .unwrap_or_default();
    if let Some(loader) = Loader::for_extension(&ext).filter(|l| !l.built()) {
        return Err(loader.left_out(path));
    }
    let loaded: (Scene, LoadReport) = match ext.as_str() {
        #[cfg(feature = "obj")]
        "obj" => {
            if let Some((count, _)) = lights {
                input::check_light_count(count, "lights")?;
            }
            let mut scene = Scene::empty();
            let mut textures = texture_budget::TextureBudget::default();
            let report = obj::load_into(
                &mut scene,
                path,
                DMat4::IDENTITY,
                None,
                options,
                &mut textures,
            )?;
            scene.frame_camera();
            if let (Some((count, seed)), Some(bounds)) = (lights, scene.bounds()) {
                let volume = random::model_light_volume(&bounds);
                scene.lights = random::lights(&volume, count, seed, random::LightSetStyle::Mixed);
            }
            scene.validate()?;
            Ok((scene, report))
        }
        #[cfg(feature = "gltf")]
        "gltf" | "glb" => gltf::load(path, lights, options),
        #[cfg(feature = "scene-files")]
        "json" => file::load(path, lights, options),
        // Built-in names have no extension: anything else that looks like a file is one (a
        // file without an extension named like a built-in could not be read as a scene anyway).
        _ if !ext.is_empty()
            || (path.is_file() && !builtin::NAMES.contains(&spec))
            || spec.contains(std::path::MAIN_SEPARATOR) =>
        {
            Err(SceneError::UnsupportedFile {
                path: path.to_path_buf(),
            })
        }
        _ => return Ok((builtin::build(spec, lights)?, LoadReport::default())),
    }?;
    finish_load(loaded, path, &ext)
}

/// A model or scene file's load (`ext` its extension) checked for something to draw and for
/// a dark frame, each warning once.
fn finish_load(
    loaded: (Scene, LoadReport),
    path: &std::path::Path,
    ext: &str,
) -> Result<(Scene, LoadReport), SceneError> {
    // Triangles that are all points or lines draw nothing: refused as an empty file is, not
    // rendered as a black frame.
    if !loaded.0.objects.is_empty() && !loaded.0.has_visible_area() {
        let reason = "nothing to draw: every triangle has zero area".to_string();
        return Err(match ext {
            "obj" => SceneError::Obj {
                path: path.to_path_buf(),
                reason,
            },
            "json" => SceneError::in_scene_file(path, SceneError::invalid("objects", reason)),
            _ => SceneError::GltfUnsupported {
                path: path.to_path_buf(),
                reason,
            },
        });
    }
    let (mut scene, mut report) = loaded;
    let repeated = repeated_objects::drop_repeated_objects(&mut scene);
    if repeated > 0 {
        report.say(format!(
            "{}: {repeated} objects repeat an earlier one exactly (the same mesh, material and \
             placement) and are dropped: each added only overdraw",
            shown::path(path)
        ));
    }
    for warning in dark_frame::warnings(&scene, path) {
        report.say(warning);
    }
    // Each once: an OBJ named again with another texture is read again and says its own again.
    let mut seen = std::collections::HashSet::new();
    report.warnings.retain(|w| seen.insert(w.clone()));
    Ok((scene, report))
}

/// Whether `transform` leaves a triangle whose normal lies in `span` ([`Mesh::normal_span`])
/// an area: the plane of some `n` in it not collapsed onto a line (or a point).
fn keeps_an_area(transform: &DMat4, span: &[glam::DVec3]) -> bool {
    let a = glam::DMat3::from_mat4(*transform);
    a.is_finite() && span.iter().any(|n| plane_keeps_an_area(&a, *n))
}

/// Whether `a` keeps an area in the plane of unit normal `n`: for an orthonormal basis `u`,
/// `v` of the plane, `|Au × Av|` not negligible next to `|Au|² + |Av|²` (a scale of 10⁻³⁰⁰ on
/// one of the plane's axes is no area in f32, whatever f64 makes of it). Measured within the
/// plane: a stretch along `n`, which moves none of its points, does not count.
fn plane_keeps_an_area(a: &glam::DMat3, n: glam::DVec3) -> bool {
    let (u, v) = n.any_orthonormal_pair();
    let (au, av) = (*a * u, *a * v);
    let largest = au.abs().max(av.abs()).max_element();
    // Where the GPU reads the image as zero, or f64 would overflow below.
    if !(largest >= f64::from(f32::MIN_POSITIVE) && largest.is_finite()) {
        return false;
    }
    let (au, av) = (au / largest, av / largest);
    au.cross(av).length() > 1e-12 * (au.length_squared() + av.length_squared())
}

#[cfg(test)]
mod area_tests {
    use super::*;
    use glam::{DVec3, DVec4};

    #[test]
    fn a_transform_that_flattens_every_triangle_leaves_nothing_to_draw() {
        let mut quad = meshbuild::MeshBuilder::default();
        quad.quad(
            Vec3::new(-1.0, -1.0, 0.0),
            Vec3::new(1.0, -1.0, 0.0),
            Vec3::new(1.0, 1.0, 0.0),
            Vec3::new(-1.0, 1.0, 0.0),
        );
        let mut cube = meshbuild::MeshBuilder::default();
        cube.cuboid(Vec3::splat(-1.0), Vec3::splat(1.0));
        let (quad, cube) = (quad.build().unwrap(), cube.build().unwrap());
        assert_eq!(quad.normal_span().len(), 1);
        assert_eq!(cube.normal_span().len(), 3);
        let scale = |x, y, z| DMat4::from_scale(DVec3::new(x, y, z));
        // y onto x: the quad's plane becomes a line.
        let shear = DMat4::from_cols(DVec4::X, DVec4::X, DVec4::Z, DVec4::W);
        let turned = DMat4::from_rotation_x(0.7) * DMat4::from_translation(DVec3::splat(5.0));
        for (mesh, transform, visible) in [
            (&quad, DMat4::IDENTITY, true),
            (&quad, turned, true),
            (&quad, scale(1.0, 1.0, 0.0), true),
            (&quad, scale(1.0, 0.0, 1.0), false),
            (&quad, scale(0.0, 0.0, 0.0), false),
            (&quad, scale(1e-300, 1.0, 1.0), false),
            (&quad, scale(1e-6, 1.0, 1.0), true),
            (&quad, shear, false),
            (&cube, scale(1.0, 0.0, 1.0), true),
            (&cube, scale(1.0, 0.0, 0.0), false),
            (&quad, scale(f64::NAN, 1.0, 1.0), false),
            // Stretched along its normal: the plane's own area is untouched.
            (&quad, scale(1.0, 1.0, 1e19), true),
            (&quad, turned * scale(1.0, 1.0, 1e300), true),
            (&cube, scale(1e300, 1e300, 1.0), true),
        ] {
            let mut scene = Scene::empty();
            let material = scene.add_material(Material::flat("m", Vec3::ONE));
            scene.add_object(mesh.clone(), material, transform);
            assert_eq!(scene.has_visible_area(), visible, "{transform}");
        }
    }
}
