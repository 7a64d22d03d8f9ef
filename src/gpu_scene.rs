//! The scene's meshes and textures on the GPU, uploaded once and shared by every shading
//! method. Below the methods and the renderer.

use std::collections::hash_map::Entry;
use std::collections::{HashMap, HashSet};
use std::sync::{Arc, Weak};

use glam::{DMat4, DVec3};

use crate::gl::mesh::GpuMesh;
use crate::gl::texture::ImageTexture;
use crate::gl::uv_sets::UvSets;
use crate::gl::Device;
use crate::scene::{triangle_reach, Aabb, Camera, Material, Mesh, Scene, SceneError, Texture};
use crate::Error;

/// Meshes and textures of scenes, uploaded once and found again by identity. The cache holds
/// an `Arc` of each source, so a key can never be reused by another allocation, and frees an
/// upload once it holds the last one.
#[derive(Default)]
pub struct GpuScene {
    /// Uploaded meshes by their source's address.
    meshes: HashMap<usize, CachedMesh>,
    /// Per image (the textures reading it share it): its upload as linear data and as sRGB
    /// colour (each made when a material
    /// first samples it so: a base colour or emission is colour, a normal map data).
    textures: HashMap<usize, (Arc<image::RgbaImage>, [Option<ImageTexture>; 2])>,
    /// 1×1 white texture for the inputs a shared variant samples and an object lacks (made on
    /// first use).
    white: Option<ImageTexture>,
    /// Colour textures are uploaded as sRGB textures, in their own slot of `textures`
    /// (`texture::hardware_srgb`; set by each upload).
    srgb_textures: bool,
    /// This frame's stand-ins for objects with triangles too long for their distance from the
    /// eye: object index → the split mesh and its model matrix (see
    /// `scene::triangle_reach`).
    splits: HashMap<usize, (GpuMesh, DMat4)>,
    /// What `splits` were made for.
    split_for: SplitInputs,
    /// A frame's splits ran out of triangles and said so (once a renderer).
    warned_split_budget: bool,
    /// Per material of this frame's scene, which of its textures an object samples (bit
    /// `slot` of [`slotted_textures_of`]; kept to reuse its memory).
    drawn_slots: Vec<u8>,
    /// This frame's meshes whose coordinate sets some object's material reads, and which
    /// (kept to reuse its memory).
    uv_sets_read: HashMap<usize, UvSets>,
    /// An image past the context's texture size was said (once a renderer: a game replacing
    /// one every frame would say it every frame).
    warned_shrunk: bool,
}

/// A mesh's upload and what is measured of it once, not every frame.
struct CachedMesh {
    source: Arc<Mesh>,
    /// Uploaded about its bounds' centre (see [`GpuScene::model`]).
    gpu: GpuMesh,
    /// Object-space bounds.
    bounds: Option<Aabb>,
    /// Longest triangle edge, object space.
    longest_edge: f64,
    /// Its triangles lie in one plane and face one way ([`Mesh::faces_one_way`]).
    faces_one_way: bool,
}

/// Everything a frame's split copies depend on: the camera, the frame's size and each
/// object's mesh and transform. A frame with the same keeps the last frame's copies.
#[derive(Default)]
struct SplitInputs {
    camera: Option<Camera>,
    frame: (u32, u32),
    /// Each object's mesh, weakly (the allocation stays, so no other mesh takes its address),
    /// and transform bits.
    objects: Vec<(Weak<Mesh>, [u64; 16])>,
}

impl SplitInputs {
    fn object_key(o: &crate::scene::Object) -> [u64; 16] {
        o.transform.to_cols_array().map(f64::to_bits)
    }

    fn same(&self, scene: &Scene, frame: (u32, u32)) -> bool {
        self.camera == Some(scene.camera)
            && self.frame == frame
            && self.objects.len() == scene.objects.len()
            && (self.objects.iter().zip(&scene.objects)).all(|((mesh, transform), o)| {
                std::ptr::eq(mesh.as_ptr(), Arc::as_ptr(&o.mesh))
                    && *transform == Self::object_key(o)
            })
    }

    /// Refilled in place (no allocation once the list has grown).
    fn set(&mut self, scene: &Scene, frame: (u32, u32)) {
        self.camera = Some(scene.camera);
        self.frame = frame;
        self.objects.clear();
        let objects = scene.objects.iter();
        (self.objects).extend(objects.map(|o| (Arc::downgrade(&o.mesh), Self::object_key(o))));
    }

    fn clear(&mut self) {
        self.camera = None;
        self.objects.clear();
    }
}

/// Slots of [`slotted_textures_of`] sampled as colour (sRGB-encoded); the others are data.
const BASE_SLOT: u8 = 0;
const EMISSIVE_SLOT: u8 = 2;

/// The textures a material samples, each with its slot (its bit in [`GpuScene::drawn_slots`]:
/// [`BASE_SLOT`] the base colour, then the maps), whether a mesh can sample it (it has the
/// coordinate set the texture reads, and tangents for a normal map), and that set.
fn slotted_textures_of(
    m: &Material,
) -> impl Iterator<Item = (u8, &Texture, impl Fn(&Mesh) -> bool + '_, u32)> {
    let base = (m.diffuse_texture.iter()).map(|t| (BASE_SLOT, &**t, &m.maps.base_transform, false));
    let maps = m.sampled_map_textures().map(|(name, t)| {
        let slot = match name {
            "normal" => 1,
            "emissive_texture" => EMISSIVE_SLOT,
            "occlusion" => 3,
            _ => 4,
        };
        (slot, &*t.texture, &t.transform, slot == 1)
    });
    base.chain(maps).map(|(slot, t, transform, tangents)| {
        let samples = move |mesh: &Mesh| {
            transform.coordinates(mesh).is_some() && !(tangents && mesh.tangents.is_empty())
        };
        (slot, t, samples, transform.uv_set)
    })
}

/// Warns (once, `warned`) that `texture` is past the context's `GL_MAX_TEXTURE_SIZE`, and so
/// uploaded smaller (each side within it: its coordinates still span it whole). A loaded
/// file's image is already within 4 096; one a game made is not.
fn warn_if_shrunk(dev: &Device, texture: &Texture, warned: &mut bool) {
    let max = dev.caps().max_texture_size.max(1) as u32;
    let (w, h) = texture.image.dimensions();
    if (w > max || h > max) && !std::mem::replace(warned, true) {
        let power_of_two = !dev.caps().npot_textures;
        let (pw, ph) = crate::gl::texture::upload_size((w, h), max, power_of_two);
        log::warn!(
            "texture `{}` is {w}×{h}, past this context's GL_MAX_TEXTURE_SIZE of {max}: \
             uploaded at {pw}×{ph}, finer detail lost",
            texture.name
        );
    }
}

impl GpuScene {
    /// Uploads what the scene's objects draw with and no earlier frame uploaded; `needs_white`:
    /// the white stand-in texture too, for shared or full variants. Returns the GPU bytes it
    /// uploaded.
    pub(crate) fn upload(
        &mut self,
        dev: &Device,
        scene: &Scene,
        needs_white: bool,
    ) -> Result<usize, Error> {
        let mut bytes = 0;
        self.forget_unreferenced(dev);
        self.srgb_textures = crate::gl::texture::hardware_srgb(dev.caps());
        if needs_white && self.white.is_none() {
            let white = image::RgbaImage::from_pixel(1, 1, image::Rgba([255, 255, 255, 255]));
            self.white = Some(ImageTexture::new(dev, &white, false, false)?);
        }
        self.note_what_objects_sample(scene);
        for (i, o) in scene.objects.iter().enumerate() {
            let key = Arc::as_ptr(&o.mesh) as usize;
            let read = self.uv_sets_read.get(&key).copied().unwrap_or_default();
            match self.meshes.entry(key) {
                Entry::Vacant(e) => {
                    o.mesh.check_shape(&format!("objects[{i}].mesh"))?;
                    let bounds = o.mesh.bounds();
                    let origin = bounds.map_or(DVec3::ZERO, |b| b.center());
                    let gpu = GpuMesh::new_about(dev, &o.mesh, origin, read)?;
                    bytes += gpu.gpu_bytes();
                    e.insert(CachedMesh {
                        source: o.mesh.clone(),
                        gpu,
                        bounds,
                        longest_edge: triangle_reach::longest_edge(&o.mesh),
                        faces_one_way: o.mesh.faces_one_way(),
                    });
                }
                // A material reads a set of a mesh uploaded without it: again, with.
                Entry::Occupied(mut e) if !e.get().gpu.uv_sets().contains(read) => {
                    let cached = e.get_mut();
                    let origin = cached.bounds.map_or(DVec3::ZERO, |b| b.center());
                    let sets = cached.gpu.uv_sets().union(read);
                    let with = GpuMesh::new_about(dev, &cached.source, origin, sets)?;
                    bytes += with.gpu_bytes();
                    std::mem::replace(&mut cached.gpu, with).destroy(dev);
                }
                Entry::Occupied(_) => {}
            }
        }
        for (m, &drawn) in scene.materials.iter().zip(&self.drawn_slots) {
            for (slot, t, _, _) in slotted_textures_of(m) {
                if drawn & 1 << slot == 0 {
                    continue;
                }
                let colour = slot == BASE_SLOT || slot == EMISSIVE_SLOT;
                let srgb = self.upload_slot(colour);
                let key = Arc::as_ptr(&t.image) as usize;
                let (_, uploads) = self
                    .textures
                    .entry(key)
                    .or_insert_with(|| (t.image.clone(), [None, None]));
                let mipmaps = t.sampling.mipmap.is_some();
                match &uploads[srgb as usize] {
                    None => {
                        warn_if_shrunk(dev, t, &mut self.warned_shrunk);
                        let texture = ImageTexture::new(dev, &t.image, srgb, mipmaps)?;
                        bytes += texture.gpu_bytes();
                        uploads[srgb as usize] = Some(texture);
                    }
                    // An image first sampled without mipmaps, now through them.
                    Some(texture) if mipmaps => bytes += texture.make_mipmaps(dev),
                    Some(_) => {}
                }
            }
        }
        Ok(bytes)
    }

    /// Notes, in one pass over the objects, what they sample: which textures of each
    /// material an object draws with on a mesh that can sample them, and the coordinate sets
    /// of each mesh those textures read. Only those are uploaded (a material palette's
    /// textures, a texture on a mesh without coordinates, a set no texture reads are not).
    fn note_what_objects_sample(&mut self, scene: &Scene) {
        self.drawn_slots.clear();
        self.drawn_slots.resize(scene.materials.len(), 0);
        self.uv_sets_read.clear();
        for o in &scene.objects {
            let Some(m) = scene.materials.get(o.material) else {
                continue;
            };
            let mut read = UvSets::default();
            for (slot, _, samples, set) in slotted_textures_of(m) {
                if samples(&o.mesh) {
                    self.drawn_slots[o.material] |= 1 << slot;
                    read.first |= set == 0;
                    read.second |= set == 1;
                }
            }
            if read != UvSets::default() {
                let key = Arc::as_ptr(&o.mesh) as usize;
                let sets = self.uv_sets_read.entry(key).or_default();
                *sets = sets.union(read);
            }
        }
    }

    /// Frees the uploads of meshes and textures the application no longer holds: the cache's
    /// `Arc` is the last one, so no scene can draw them again (a game that rebuilds a mesh, or
    /// changes one through `Arc::make_mut`, makes a new one each time).
    fn forget_unreferenced(&mut self, dev: &Device) {
        let held = |_: usize, count: usize| count > 1;
        self.free_where(dev, held, held);
    }

    /// Frees the uploads of meshes and images no scene of `scenes` uses, whether or not the
    /// application still holds them; the bytes freed.
    pub(crate) fn free_unused(&mut self, dev: &Device, scenes: &[&Scene]) -> usize {
        let meshes: HashSet<usize> = (scenes.iter())
            .flat_map(|s| s.objects.iter().map(|o| Arc::as_ptr(&o.mesh) as usize))
            .collect();
        let images: HashSet<usize> = (scenes.iter())
            .flat_map(|s| s.objects.iter().map(|o| (o, s.materials.get(o.material))))
            .flat_map(|(o, m)| {
                let textures = m.into_iter().flat_map(slotted_textures_of);
                textures.filter_map(|(_, t, samples, _)| samples(&o.mesh).then_some(t))
            })
            .map(|t| Arc::as_ptr(&t.image) as usize)
            .collect();
        let mesh_used = |key, _| meshes.contains(&key);
        let image_used = |key, _| images.contains(&key);
        self.free_where(dev, mesh_used, image_used)
    }

    /// Frees every mesh upload `keep_mesh` and every image's uploads `keep_image` refuse, each
    /// asked with the entry's key and its source's `Arc` count; the bytes freed.
    fn free_where(
        &mut self,
        dev: &Device,
        keep_mesh: impl Fn(usize, usize) -> bool,
        keep_image: impl Fn(usize, usize) -> bool,
    ) -> usize {
        let mut freed = 0;
        self.meshes.retain(|&key, cached| {
            let keep = keep_mesh(key, Arc::strong_count(&cached.source));
            if !keep {
                freed += cached.gpu.gpu_bytes();
                cached.gpu.destroy(dev);
            }
            keep
        });
        self.textures.retain(|&key, (source, uploads)| {
            let keep = keep_image(key, Arc::strong_count(source));
            if !keep {
                for gpu in uploads.iter_mut().flatten() {
                    freed += gpu.gpu_bytes();
                    gpu.destroy(dev);
                }
            }
            keep
        });
        freed
    }

    /// GPU bytes of the uploaded meshes and images (a frame's split copies aside).
    pub(crate) fn gpu_bytes(&self) -> usize {
        let meshes = self.meshes.values().map(|m| m.gpu.gpu_bytes());
        let images = (self.textures.values())
            .flat_map(|(_, uploads)| uploads.iter().flatten().map(ImageTexture::gpu_bytes));
        meshes.sum::<usize>() + images.sum::<usize>()
    }

    /// Replaces last frame's split meshes with this frame's: objects of `scene` with triangles
    /// too long for their distance from its camera, or spanning too many of the `frame`'s
    /// pixels, are drawn from a copy split near the eye. Keeps them when neither the camera,
    /// the frame's size nor any object changed. Returns the bytes it uploaded.
    pub(crate) fn split_for_frame(
        &mut self,
        dev: &Device,
        scene: &Scene,
        frame: (u32, u32),
    ) -> Result<usize, Error> {
        if self.split_for.same(scene, frame) {
            return Ok(0);
        }
        self.split_for.clear();
        for (_, (mut m, _)) in self.splits.drain() {
            m.destroy(dev);
        }
        let model = DMat4::from_translation(scene.camera.position);
        let splits = triangle_reach::split_objects(scene, frame, |o| {
            (self.longest_edge(o), self.world_bounds(o))
        });
        if let Some(i) = splits.cut_short {
            if !self.warned_split_budget {
                self.warned_split_budget = true;
                log::warn!(
                    "objects[{i}] and any after it: triangles far longer than their distance \
                     from the camera need more than {} splits this frame, so the rest are \
                     drawn unsplit and may be off by f32 rounding near the eye (a huge mesh \
                     seen from close by, or many such objects)",
                    triangle_reach::MAX_SPLIT_TRIANGLES
                );
            }
        }
        let mut uploaded = 0;
        for (i, mesh) in splits.meshes {
            let gpu = GpuMesh::new(dev, &mesh)?;
            uploaded += gpu.gpu_bytes();
            self.splits.insert(i, (gpu, model));
        }
        self.split_for.set(scene, frame);
        Ok(uploaded)
    }

    /// The mesh object `index` is drawn with this frame, and its model matrix: its uploaded
    /// mesh and [`GpuScene::model`], or the frame's split copy.
    pub(crate) fn drawn(&self, index: usize, object: &crate::scene::Object) -> (&GpuMesh, DMat4) {
        match self.splits.get(&index) {
            Some((mesh, model)) => (mesh, *model),
            None => (self.mesh(object), self.model(object)),
        }
    }

    /// The uploaded mesh of an object (the scene must have been uploaded).
    pub fn mesh(&self, object: &crate::scene::Object) -> &GpuMesh {
        &self.cached(object).gpu
    }

    /// What is cached of an object's mesh (the scene must have been uploaded).
    fn cached(&self, object: &crate::scene::Object) -> &CachedMesh {
        &self.meshes[&(Arc::as_ptr(&object.mesh) as usize)]
    }

    /// Whether an object's triangles lie in one plane and face one way: from any eye all show
    /// the same side, so one draw without culling shows both sides of a transparent one.
    pub(crate) fn faces_one_way(&self, object: &crate::scene::Object) -> bool {
        self.cached(object).faces_one_way
    }

    /// The object's model matrix for its uploaded mesh: the object's transform after a move
    /// to the mesh's centre. Vertices far from their mesh's own origin (an OBJ modelled at
    /// 10⁷) are stored in `f32` relative to that centre, and the offset joins the `f64`
    /// transform, from which the camera is subtracted before anything becomes `f32`.
    pub fn model(&self, object: &crate::scene::Object) -> DMat4 {
        let origin = self
            .cached(object)
            .bounds
            .map_or(DVec3::ZERO, |b| b.center());
        object.transform * DMat4::from_translation(origin)
    }

    /// World-space bounds of an object, from its mesh's cached bounds (the scene must have
    /// been uploaded).
    pub fn world_bounds(&self, object: &crate::scene::Object) -> Option<Aabb> {
        (self.cached(object).bounds).map(|b| b.transformed(&object.transform))
    }

    /// The longest triangle edge of an object's mesh, in object space (the scene must have
    /// been uploaded).
    pub fn longest_edge(&self, object: &crate::scene::Object) -> f64 {
        self.cached(object).longest_edge
    }

    /// Refuses an object its transform places past the camera's coordinate limit or shrinks
    /// into f32's subnormal numbers, naming the transform: a scale or translation past it
    /// overflowed the view matrix's `f32` form and left the object out of the frame without a
    /// word, a tiny one drew black. (The file loaders check the same.)
    pub fn check_placement(&self, scene: &Scene) -> Result<(), SceneError> {
        for (i, o) in scene.objects.iter().enumerate() {
            if let Some(b) = &self.cached(o).bounds {
                if b.check_placed_by(&o.transform, "").is_err() {
                    b.check_placed_by(&o.transform, &format!("objects[{i}]"))?;
                }
            }
        }
        Ok(())
    }

    /// World-space bounds of the whole scene ([`Scene::bounds`] without walking every vertex).
    pub fn scene_bounds(&self, scene: &Scene) -> Option<Aabb> {
        scene
            .objects
            .iter()
            .filter_map(|o| self.world_bounds(o))
            .reduce(|a, b| a.union(&b))
    }

    /// The uploaded diffuse texture of a material, if it has one.
    pub fn texture_for(&self, material: &Material) -> Option<&ImageTexture> {
        self.texture_of(material.diffuse_texture.as_ref()?, true)
    }

    /// The upload of one of the scene's textures, as colour (`colour`: an sRGB texture where
    /// the context has them) or as data.
    pub fn texture_of(&self, texture: &Texture, colour: bool) -> Option<&ImageTexture> {
        let (_, uploads) = self.textures.get(&(Arc::as_ptr(&texture.image) as usize))?;
        uploads[self.upload_slot(colour) as usize].as_ref()
    }

    /// Whether a texture sampled as colour (`colour`) or data takes the sRGB upload: one
    /// upload serves both where colour textures are plain ones (ES 2.0).
    fn upload_slot(&self, colour: bool) -> bool {
        colour && self.srgb_textures
    }

    /// The white stand-in texture (only after an upload that needed it).
    pub fn white(&self) -> Option<&ImageTexture> {
        self.white.as_ref()
    }

    pub(crate) fn destroy(&mut self, dev: &Device) {
        for (_, mut m) in self.meshes.drain() {
            m.gpu.destroy(dev);
        }
        for (_, (_, uploads)) in self.textures.drain() {
            uploads
                .into_iter()
                .flatten()
                .for_each(|mut t| t.destroy(dev));
        }
        self.split_for.clear();
        for (_, (mut m, _)) in self.splits.drain() {
            m.destroy(dev);
        }
        if let Some(mut w) = self.white.take() {
            w.destroy(dev);
        }
    }
}
