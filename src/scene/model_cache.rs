//! Models a scene file names more than once, kept once. A built-in scene is built once; an
//! OBJ file (with the same texture override) and a glTF file are read on their first
//! reference only: later ones place the same `Arc<Mesh>`es and reuse the materials (copied
//! when the reference recolours them), and a glTF file's lights and camera, which move with
//! the placing transform, are placed again from that read. An OBJ is read again for another
//! texture override, but its meshes are swapped for those of its first read when equal, and
//! every texture for an equal one of the same name loaded before, so memory holds one copy.
//! Repeats add none of the warnings the first load said; a glTF file's later reference says
//! only which of its lights and camera its transform leaves out.

use std::collections::HashMap;
use std::path::{Path, PathBuf};
use std::sync::Arc;

use glam::DMat4;

use super::access::LoadOptions;
#[cfg(not(all(feature = "obj", feature = "gltf")))]
use super::loaders::Loader;
use super::mesh::{MAX_SCENE_MATERIALS, MAX_SCENE_MESHES, MAX_SCENE_OBJECTS};
#[cfg(feature = "obj")]
use super::obj;
use super::texture::Sampling;
use super::texture_budget::TextureBudget;
use super::LoadReport;
use super::{Aabb, Camera, Material, Mesh, Object, Scene, SceneError, Texture};

/// A model as loaded, to be placed again without reading it.
struct Loaded {
    /// Each object's mesh, material index relative to the model's first material, transform
    /// relative to the placing one, and object-space bounds when placements must be checked.
    objects: Vec<(Arc<Mesh>, usize, DMat4, Option<Aabb>)>,
    /// The model's materials before any recolouring.
    materials: Vec<Material>,
    /// Where an unrecoloured copy of `materials` starts in the scene, once there is one.
    uncoloured_at: Option<usize>,
}

impl Loaded {
    /// What `scene` holds from `first_object` and `first_material` on; `relative` gives the
    /// model's `i`th object's transform relative to the placing one and `checked` whether to
    /// keep bounds.
    fn record(
        scene: &Scene,
        (first_object, first_material): (usize, usize),
        relative: impl Fn(usize, &Object) -> DMat4,
        checked: bool,
    ) -> Loaded {
        // Bounds once a mesh: a file may place one large mesh many times.
        let mut bounds = HashMap::new();
        let objects = scene.objects[first_object..]
            .iter()
            .enumerate()
            .map(|(i, o)| {
                let b = checked
                    .then(|| {
                        *bounds
                            .entry(Arc::as_ptr(&o.mesh))
                            .or_insert_with(|| o.mesh.bounds())
                    })
                    .flatten();
                (
                    o.mesh.clone(),
                    o.material - first_material,
                    relative(i, o),
                    b,
                )
            })
            .collect();
        Loaded {
            objects,
            materials: scene.materials[first_material..].to_vec(),
            uncoloured_at: None,
        }
    }

    /// Places the model again with `transform`, reusing an unrecoloured copy of its materials
    /// unless the caller will `recolour` them. Errors (from `path`) where a placed object's
    /// transform is not finite or its bounds cannot be placed (`Aabb::placement_refusal`),
    /// as the glTF loader's own check says.
    fn place(
        &mut self,
        scene: &mut Scene,
        transform: DMat4,
        recolour: bool,
        transform_field: &str,
    ) -> Result<(), SceneError> {
        self.check(transform, transform_field)?;
        self.place_checked(scene, transform, recolour);
        Ok(())
    }

    /// The refusal [`Self::place`] gives `transform`, if any.
    fn check(&self, transform: DMat4, transform_field: &str) -> Result<(), SceneError> {
        for (_, _, relative, bounds) in &self.objects {
            let world = transform * *relative;
            if let Some(reason) = Aabb::placement_refusal_of(bounds.as_ref(), &world) {
                return Err(SceneError::invalid(transform_field, reason));
            }
        }
        Ok(())
    }

    /// [`Self::place`] with a transform [`Self::check`] passed.
    fn place_checked(&mut self, scene: &mut Scene, transform: DMat4, recolour: bool) {
        let base = match self.uncoloured_at {
            Some(base) if !recolour => base,
            _ => {
                let base = scene.materials.len();
                scene.materials.extend(self.materials.iter().cloned());
                if !recolour {
                    self.uncoloured_at = Some(base);
                }
                base
            }
        };
        scene.objects.extend(
            self.objects
                .iter()
                .map(|(mesh, material, relative, _)| Object {
                    mesh: mesh.clone(),
                    material: base + material,
                    transform: transform * *relative,
                }),
        );
    }
}

/// A glTF file as its first reference read it: its objects, and the lights and camera it
/// instances, to be placed again by each later reference's transform.
#[cfg(feature = "gltf")]
struct GltfModel {
    objects: Loaded,
    instanced: Option<super::gltf::Instanced>,
}

#[cfg(feature = "gltf")]
impl GltfModel {
    /// Places the file (`path`) again with `transform`, as reading it there would (its
    /// objects checked first, then its lights): on error `scene` is unchanged. Returns the
    /// warnings for lights and a camera the transform leaves out, and the file's camera.
    fn place(
        &mut self,
        scene: &mut Scene,
        path: &Path,
        transform: DMat4,
        recolour: bool,
        transform_field: &str,
    ) -> Result<(LoadReport, Option<Camera>), SceneError> {
        if !transform.is_finite() {
            return Err(SceneError::invalid(transform_field, "must be finite"));
        }
        self.objects.check(transform, transform_field)?;
        let placed = match &self.instanced {
            Some(instanced) => {
                let most = instanced.most_lights();
                let field = format!("{} lights", path.display());
                super::input::check_lights_added(scene, most, &field)?;
                super::gltf::place_again(instanced, path, transform, transform_field)?
            }
            None => Default::default(),
        };
        let lights = placed.lights.len() + placed.directional_lights.len();
        if self.objects.objects.is_empty() && lights == 0 {
            // As a read at this transform says.
            return Err(SceneError::GltfUnsupported {
                path: path.to_path_buf(),
                reason: format!(
                    "nothing to show: the file places no triangle mesh, and {transform_field} \
                     leaves out its lights"
                ),
            });
        }
        self.objects.place_checked(scene, transform, recolour);
        scene.lights.extend(placed.lights);
        scene.directional_lights.extend(placed.directional_lights);
        let mut report = LoadReport::default();
        for w in placed.warnings {
            report.warn(format!("{}: {w}", path.display()));
        }
        Ok((report, placed.camera))
    }
}

/// Most bytes a scene file's load reads and decodes again for OBJ files read more than once
/// (for each other texture override): the files, their textures, and the images' decoded
/// pixels count (a small image may decode to 512 MiB). Many references to a large file would
/// keep a load busy without end.
pub const MAX_REREAD_BYTES: u64 = 1 << 30;

/// Bytes read and pixel bytes decoded on this thread so far: what a re-read costs.
fn work_so_far() -> u64 {
    super::input::bytes_read().saturating_add(super::texture_budget::pixel_bytes_decoded())
}

/// The models one scene file has loaded, by canonical path (and texture override for OBJ).
#[derive(Default)]
pub(super) struct ModelCache {
    /// How the models' own references are read.
    options: LoadOptions,
    /// What is left of the scene's texture memory.
    texture_budget: TextureBudget,
    /// Bytes read and decoded again for models read more than once ([`MAX_REREAD_BYTES`]).
    reread_bytes: u64,
    obj: HashMap<(PathBuf, Option<PathBuf>), Loaded>,
    /// glTF files as their first reference read them.
    #[cfg(feature = "gltf")]
    gltf: HashMap<PathBuf, GltfModel>,
    /// The distinct meshes of each model file's first load, in first-use order.
    meshes: HashMap<PathBuf, Vec<Arc<Mesh>>>,
    /// Every image loaded so far, by name (its path): the pixels every later copy shares.
    images: HashMap<String, Arc<image::RgbaImage>>,
    /// Every texture kept so far, by name and sampling (one image read through several).
    textures: HashMap<(String, Sampling), Arc<Texture>>,
    /// Built-in scenes as first built (`None`: no such name), with their cameras.
    builtin: HashMap<String, Option<(Loaded, Camera)>>,
}

impl ModelCache {
    /// An empty cache whose models read their references by `options`.
    pub fn new(options: LoadOptions) -> ModelCache {
        ModelCache {
            options,
            ..ModelCache::default()
        }
    }

    /// A built-in scene's camera, its geometry built on first use; `None` for an unknown name.
    pub fn builtin_camera(&mut self, name: &str) -> Option<Camera> {
        self.builtin_model(name).map(|(_, camera)| *camera)
    }

    /// Places the built-in scene `name` with `transform`, sharing the meshes of every
    /// placement and, unless the caller will `recolour` them, the materials too; nothing for
    /// an unknown name ([`ModelCache::builtin_camera`] says which).
    pub fn place_builtin(
        &mut self,
        scene: &mut Scene,
        name: &str,
        transform: DMat4,
        recolour: bool,
    ) {
        if let Some((model, _)) = self.builtin_model(name) {
            model.place_checked(scene, transform, recolour);
        }
    }

    /// The built-in scene `name` as first built.
    fn builtin_model(&mut self, name: &str) -> Option<&mut (Loaded, Camera)> {
        self.builtin
            .entry(name.to_string())
            .or_insert_with(|| {
                super::builtin::geometry(name).map(|built| {
                    let model = Loaded::record(&built, (0, 0), |_, o| o.transform, false);
                    (model, built.camera)
                })
            })
            .as_mut()
    }

    /// Places an OBJ file with `transform`, loading it on first use. `recolour`: the caller
    /// will recolour the materials appended from `scene.materials.len()` on.
    #[cfg(feature = "obj")]
    pub fn place_obj(
        &mut self,
        scene: &mut Scene,
        path: &Path,
        transform: DMat4,
        texture: Option<&Path>,
        recolour: bool,
        transform_field: &str,
    ) -> Result<LoadReport, SceneError> {
        let key = std::fs::canonicalize(path).ok().map(|p| {
            let texture = texture.map(|t| std::fs::canonicalize(t).unwrap_or(t.to_path_buf()));
            (p, texture)
        });
        if let Some(loaded) = key.as_ref().and_then(|k| self.obj.get_mut(k)) {
            loaded.place(scene, transform, recolour, transform_field)?;
            return Ok(LoadReport::default());
        }
        // Read again for another texture override (its meshes are kept from the first read):
        // bounded in total.
        let reread = key.as_ref().is_some_and(|k| self.meshes.contains_key(&k.0));
        if reread && self.reread_bytes > MAX_REREAD_BYTES {
            return Err(SceneError::Obj {
                path: path.to_path_buf(),
                reason: format!(
                    "an OBJ file is read again for each other `texture`, and this scene \
                     file's re-reads (the files, their textures and the pixels decoded) passed \
                     {} MiB before {transform_field}'s (fewer distinct textures)",
                    MAX_REREAD_BYTES >> 20
                ),
            });
        }
        let first = (scene.objects.len(), scene.materials.len());
        let work_before = work_so_far();
        // Loaded at the identity: each object's transform is then its own (its mesh is stored
        // about its centre), recorded once and placed below.
        let loaded = obj::load_into(
            scene,
            path,
            DMat4::IDENTITY,
            texture,
            &self.options,
            &mut self.texture_budget,
        );
        if reread {
            let work = work_so_far().wrapping_sub(work_before);
            self.reread_bytes = self.reread_bytes.saturating_add(work);
        }
        let report = loaded?;
        self.share(scene, first.0, first.1, key.as_ref().map(|k| &k.0));
        if let Some(key) = key {
            let mut loaded = Loaded::record(scene, first, |_, o| o.transform, false);
            loaded.uncoloured_at = (!recolour).then_some(first.1);
            self.obj.insert(key, loaded);
        }
        for o in &mut scene.objects[first.0..] {
            o.transform = transform * o.transform;
        }
        Ok(report)
    }

    /// A build without the OBJ loader refuses an OBJ file.
    #[cfg(not(feature = "obj"))]
    pub fn place_obj(
        &mut self,
        _: &mut Scene,
        path: &Path,
        _: DMat4,
        _: Option<&Path>,
        _: bool,
        _: &str,
    ) -> Result<LoadReport, SceneError> {
        Err(Loader::Obj.left_out(path))
    }

    /// Places a glTF file with `transform`, reading it at its first reference only: later ones
    /// place its objects, and its lights (suns included) and first camera, which move with
    /// the transform, from that read. Returns the load's warnings (a later reference's:
    /// only lights and a camera that its transform leaves out) and the first camera the file
    /// instances.
    #[cfg(feature = "gltf")]
    pub fn place_gltf(
        &mut self,
        scene: &mut Scene,
        path: &Path,
        transform: DMat4,
        recolour: bool,
        transform_field: &str,
    ) -> Result<(LoadReport, Option<Camera>), SceneError> {
        let key = std::fs::canonicalize(path).ok();
        if let Some(model) = key.as_ref().and_then(|k| self.gltf.get_mut(k)) {
            return model.place(scene, path, transform, recolour, transform_field);
        }
        let (first_object, first_material) = (scene.objects.len(), scene.materials.len());
        let (loaded, placement) = super::gltf::load_source_into(
            scene,
            super::gltf::Source::File(path),
            transform,
            transform_field,
            &self.options,
            &mut self.texture_budget,
        )?;
        if let Some(k) = key {
            // Placed from this read from now on: its objects' own transforms are kept.
            self.share(scene, first_object, first_material, Some(&k));
            let first = (first_object, first_material);
            let relative = |i: usize, _: &Object| placement.relative[i];
            let mut objects = Loaded::record(scene, first, relative, true);
            objects.uncoloured_at = (!recolour).then_some(first_material);
            let instanced = placement.instanced;
            self.gltf.insert(k, GltfModel { objects, instanced });
        }
        Ok((loaded.report, loaded.camera))
    }

    /// A build without the glTF loader refuses a glTF file.
    #[cfg(not(feature = "gltf"))]
    pub fn place_gltf(
        &mut self,
        _: &mut Scene,
        path: &Path,
        _: DMat4,
        _: bool,
        _: &str,
    ) -> Result<(LoadReport, Option<Camera>), SceneError> {
        Err(Loader::Gltf.left_out(path))
    }

    /// Swaps the meshes of the objects from `first_object` on for those of an earlier load of
    /// the same file (`path`, canonical) when they are equal — the file may have changed
    /// between reads — and the textures of the materials from `first_material` on for equal
    /// ones loaded before (the load's textures took their part of the scene's budget as they
    /// were decoded: a copy dropped gives it back).
    fn share(
        &mut self,
        scene: &mut Scene,
        first_object: usize,
        first_material: usize,
        path: Option<&PathBuf>,
    ) {
        // Every texture slot: a model named many times holds each image once, and a copy
        // dropped for the one held gives its memory back to the budget (once per copy of the
        // pixels, however many samplings read it); each texture keeps its own sampling.
        let mut dropped = std::collections::HashSet::new();
        for t in scene.materials[first_material..]
            .iter_mut()
            .flat_map(|m| m.diffuse_texture.iter_mut().chain(m.maps.textures_mut()))
        {
            let key = (t.name.clone(), t.sampling);
            match self.images.get(&t.name) {
                Some(known) if Arc::ptr_eq(known, &t.image) => {
                    let kept = self.textures.entry(key).or_insert_with(|| t.clone());
                    *t = kept.clone();
                }
                Some(known) if **known == *t.image => {
                    if dropped.insert(Arc::as_ptr(&t.image)) {
                        self.texture_budget.give_back(t.image.as_raw().len() as u64);
                    }
                    let image = known.clone();
                    let kept = self.textures.entry(key).or_insert_with(|| {
                        Arc::new(Texture {
                            name: t.name.clone(),
                            image,
                            sampling: t.sampling,
                        })
                    });
                    *t = kept.clone();
                }
                Some(_) => {}
                None => {
                    self.images.insert(t.name.clone(), t.image.clone());
                    self.textures.insert(key, t.clone());
                }
            }
        }
        let Some(path) = path else {
            return;
        };
        let objects = &mut scene.objects[first_object..];
        let meshes = distinct(objects.iter().map(|o| &o.mesh));
        let Some(earlier) = self.meshes.get(path) else {
            self.meshes.insert(path.clone(), meshes);
            return;
        };
        let same = earlier.len() == meshes.len()
            && earlier.iter().zip(&meshes).all(|(a, b)| same_mesh(a, b));
        if same {
            for o in objects.iter_mut() {
                let i = meshes.iter().position(|m| Arc::ptr_eq(m, &o.mesh));
                o.mesh = earlier[i.expect("listed above")].clone();
            }
        }
    }
}

/// The distinct `Arc`s of a list, in first-use order.
fn distinct<'a, T: 'a>(items: impl Iterator<Item = &'a Arc<T>>) -> Vec<Arc<T>> {
    let mut seen = std::collections::HashSet::new();
    items
        .filter(|a| seen.insert(Arc::as_ptr(a)))
        .cloned()
        .collect()
}

fn same_mesh(a: &Mesh, b: &Mesh) -> bool {
    a.positions == b.positions
        && a.normals == b.normals
        && a.uvs == b.uvs
        && a.second_uvs == b.second_uvs
        && a.indices == b.indices
        && a.colors == b.colors
        && a.tangents == b.tangents
}

/// The distinct meshes a scene file's objects have made so far, counted as they are placed.
#[derive(Default)]
pub(super) struct MeshCount {
    seen: std::collections::HashSet<*const Mesh>,
    counted_objects: usize,
}

/// Checks the scene's objects, meshes and materials against the scene-file limits after
/// object `field` was placed (`meshes` counts the objects placed since the last check).
pub(super) fn check_budget(
    scene: &Scene,
    meshes: &mut MeshCount,
    field: &str,
) -> Result<(), SceneError> {
    check_counts(scene.objects.len(), scene.materials.len(), field)?;
    let new = scene
        .objects
        .get(meshes.counted_objects..)
        .unwrap_or_default();
    meshes.seen.extend(new.iter().map(|o| Arc::as_ptr(&o.mesh)));
    meshes.counted_objects = scene.objects.len();
    if meshes.seen.len() > MAX_SCENE_MESHES {
        return Err(SceneError::invalid(
            field,
            format!(
                "the scene would hold {} distinct meshes, more than the {MAX_SCENE_MESHES} a \
                 scene file may make",
                meshes.seen.len()
            ),
        ));
    }
    Ok(())
}

fn check_counts(objects: usize, materials: usize, field: &str) -> Result<(), SceneError> {
    let over = |count: usize, what: &str, limit: usize, verb: &str| {
        SceneError::invalid(
            field,
            format!("the scene would hold {count} {what}, more than the {limit} a scene file may {verb}"),
        )
    };
    if objects > MAX_SCENE_OBJECTS {
        return Err(over(objects, "objects", MAX_SCENE_OBJECTS, "place"));
    }
    if materials > MAX_SCENE_MATERIALS {
        return Err(over(materials, "materials", MAX_SCENE_MATERIALS, "make"));
    }
    Ok(())
}

#[cfg(all(test, feature = "loaders"))]
mod tests;
