//! Models a scene file names more than once, kept once. A built-in scene is built once; an
//! OBJ file (with the same texture override) is loaded on its first reference only, later
//! ones place the same `Arc<Mesh>`es and reuse its materials (copied when the reference
//! recolours them). A glTF file is read again for each reference (its lights, camera and
//! checks depend on the placing transform), an OBJ again for another texture override, but
//! their meshes are swapped for those of the file's first load when equal, and every texture
//! for an equal one of the same name loaded before, so memory holds one copy. Repeats add no
//! warnings: the first load said them.

use std::collections::HashMap;
use std::path::{Path, PathBuf};
use std::sync::Arc;

use glam::DMat4;

use super::obj::{self, LoadReport};
use super::{Material, Mesh, Object, Scene, SceneError, Texture};

/// Most objects a scene file may place (all its references together), the per-file limit of
/// glTF too: each costs about 0.6 KB of CPU state besides its mesh (placement, draw order,
/// the automatic grid's ray caster), so the limit holds that near 600 MB.
pub const MAX_SCENE_OBJECTS: usize = super::gltf::MAX_OBJECTS;

/// Most materials a scene file may make (references that recolour a model copy its materials).
pub const MAX_SCENE_MATERIALS: usize = 1 << 20;

/// An OBJ load as it came from the file.
struct LoadedObj {
    /// Each object's mesh and material index relative to the file's first material.
    objects: Vec<(Arc<Mesh>, usize)>,
    /// The file's materials before any recolouring.
    materials: Vec<Material>,
    /// Where an unrecoloured copy of `materials` starts in the scene, once there is one.
    uncoloured_at: Option<usize>,
}

/// The models one scene file has loaded, by canonical path (and texture override for OBJ).
#[derive(Default)]
pub(super) struct ModelCache {
    obj: HashMap<(PathBuf, Option<PathBuf>), LoadedObj>,
    /// The distinct meshes of each model file's first load, in first-use order.
    meshes: HashMap<PathBuf, Vec<Arc<Mesh>>>,
    /// Every texture loaded so far, by name (its path).
    textures: HashMap<String, Arc<Texture>>,
    builtin: HashMap<String, Option<Scene>>,
}

impl ModelCache {
    /// A built-in scene's geometry, built on first use (later ones share its meshes).
    pub fn builtin(&mut self, name: &str) -> Option<Scene> {
        self.builtin
            .entry(name.to_string())
            .or_insert_with(|| super::builtin::geometry(name))
            .clone()
    }

    /// Places an OBJ file with `transform`, loading it on first use. `recolour`: the caller
    /// will recolour the materials appended from `scene.materials.len()` on.
    pub fn place_obj(
        &mut self,
        scene: &mut Scene,
        path: &Path,
        transform: DMat4,
        texture: Option<&Path>,
        recolour: bool,
    ) -> Result<LoadReport, SceneError> {
        let key = std::fs::canonicalize(path).ok().map(|p| {
            let texture = texture.map(|t| std::fs::canonicalize(t).unwrap_or(t.to_path_buf()));
            (p, texture)
        });
        if let Some(loaded) = key.as_ref().and_then(|k| self.obj.get_mut(k)) {
            let base = match loaded.uncoloured_at {
                Some(base) if !recolour => base,
                _ => {
                    let base = scene.materials.len();
                    scene.materials.extend(loaded.materials.iter().cloned());
                    if !recolour {
                        loaded.uncoloured_at = Some(base);
                    }
                    base
                }
            };
            scene
                .objects
                .extend(loaded.objects.iter().map(|(mesh, material)| Object {
                    mesh: mesh.clone(),
                    material: base + material,
                    transform,
                }));
            return Ok(LoadReport::default());
        }
        let (first_object, first_material) = (scene.objects.len(), scene.materials.len());
        let report = obj::load_into(scene, path, transform, texture)?;
        self.share(scene, first_object, first_material, key.as_ref().map(|k| &k.0));
        if let Some(key) = key {
            let objects = scene.objects[first_object..]
                .iter()
                .map(|o| (o.mesh.clone(), o.material - first_material))
                .collect();
            self.obj.insert(
                key,
                LoadedObj {
                    objects,
                    materials: scene.materials[first_material..].to_vec(),
                    uncoloured_at: (!recolour).then_some(first_material),
                },
            );
        }
        Ok(report)
    }

    /// Places a glTF file with `transform`, sharing the meshes and textures of earlier loads.
    pub fn place_gltf(
        &mut self,
        scene: &mut Scene,
        path: &Path,
        transform: DMat4,
    ) -> Result<super::gltf::GltfLoad, SceneError> {
        let (first_object, first_material) = (scene.objects.len(), scene.materials.len());
        let mut loaded = super::gltf::load_into(scene, path, transform)?;
        let key = std::fs::canonicalize(path).ok();
        if self.share(scene, first_object, first_material, key.as_ref()) {
            loaded.report.warnings.clear();
        }
        Ok(loaded)
    }

    /// Swaps the meshes of the objects from `first_object` on for those of an earlier load of
    /// the same file (`path`, canonical) when they are equal — the file may have changed
    /// between reads — and the textures of the materials from `first_material` on for equal
    /// ones loaded before. Returns whether the file was loaded before with the same meshes.
    fn share(
        &mut self,
        scene: &mut Scene,
        first_object: usize,
        first_material: usize,
        path: Option<&PathBuf>,
    ) -> bool {
        for t in scene.materials[first_material..]
            .iter_mut()
            .filter_map(|m| m.diffuse_texture.as_mut())
        {
            match self.textures.get(&t.name) {
                Some(known) if known.image == t.image => *t = known.clone(),
                Some(_) => {}
                None => {
                    self.textures.insert(t.name.clone(), t.clone());
                }
            }
        }
        let Some(path) = path else {
            return false;
        };
        let objects = &mut scene.objects[first_object..];
        let meshes = distinct(objects.iter().map(|o| &o.mesh));
        let Some(earlier) = self.meshes.get(path) else {
            self.meshes.insert(path.clone(), meshes);
            return false;
        };
        let same = earlier.len() == meshes.len()
            && earlier.iter().zip(&meshes).all(|(a, b)| same_mesh(a, b));
        if same {
            for o in objects.iter_mut() {
                let i = meshes.iter().position(|m| Arc::ptr_eq(m, &o.mesh));
                o.mesh = earlier[i.expect("listed above")].clone();
            }
        }
        same
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
    a.positions == b.positions && a.normals == b.normals && a.uvs == b.uvs && a.indices == b.indices
}

/// Checks the scene's objects and materials against the scene-file limits after object
/// `field` was placed.
pub(super) fn check_budget(scene: &Scene, field: &str) -> Result<(), SceneError> {
    check_counts(scene.objects.len(), scene.materials.len(), field)
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

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn counts_past_the_budget_are_errors_naming_the_object() {
        assert!(check_counts(MAX_SCENE_OBJECTS, MAX_SCENE_MATERIALS, "objects[3]").is_ok());
        let err = check_counts(MAX_SCENE_OBJECTS + 1, 1, "objects[3]").unwrap_err();
        let text = err.to_string();
        assert!(text.contains("objects[3]") && text.contains("1048577 objects"), "{text}");
        let err = check_counts(1, MAX_SCENE_MATERIALS + 1, "objects[9]").unwrap_err();
        assert!(err.to_string().contains("materials"), "{err}");
    }
}
