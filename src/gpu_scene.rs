//! The scene's meshes and textures on the GPU, uploaded once and shared by every shading
//! method. Below the methods and the renderer.

use std::collections::HashMap;
use std::sync::Arc;

use crate::gl::mesh::GpuMesh;
use crate::gl::texture::ImageTexture;
use crate::gl::Device;
use crate::scene::{Aabb, Material, Mesh, Scene, Texture};
use crate::Error;

/// Meshes and textures of scenes, uploaded once and found again by identity. The cache holds
/// an `Arc` of each source, so a key can never be reused by another allocation.
#[derive(Default)]
pub struct GpuScene {
    /// Uploaded meshes with their object-space bounds (computed once, not every frame).
    meshes: HashMap<usize, (Arc<Mesh>, GpuMesh, Option<Aabb>)>,
    textures: HashMap<usize, (Arc<Texture>, ImageTexture)>,
    /// 1×1 white texture for full variants on untextured materials (made on first use).
    white: Option<ImageTexture>,
}

impl GpuScene {
    pub(crate) fn upload(
        &mut self,
        dev: &Device,
        scene: &Scene,
        full_variants: bool,
    ) -> Result<(), Error> {
        if full_variants && self.white.is_none() {
            let white = image::RgbaImage::from_pixel(1, 1, image::Rgba([255, 255, 255, 255]));
            self.white = Some(ImageTexture::new(dev, &white)?);
        }
        for o in &scene.objects {
            let key = Arc::as_ptr(&o.mesh) as usize;
            if let std::collections::hash_map::Entry::Vacant(e) = self.meshes.entry(key) {
                e.insert((o.mesh.clone(), GpuMesh::new(dev, &o.mesh)?, o.mesh.bounds()));
            }
        }
        for m in &scene.materials {
            if let Some(t) = &m.diffuse_texture {
                let key = Arc::as_ptr(t) as usize;
                if let std::collections::hash_map::Entry::Vacant(e) = self.textures.entry(key) {
                    e.insert((t.clone(), ImageTexture::new(dev, &t.image)?));
                }
            }
        }
        Ok(())
    }

    /// The uploaded mesh of an object (the scene must have been uploaded).
    pub fn mesh(&self, object: &crate::scene::Object) -> &GpuMesh {
        &self.meshes[&(Arc::as_ptr(&object.mesh) as usize)].1
    }

    /// World-space bounds of an object, from its mesh's cached bounds (the scene must have
    /// been uploaded).
    pub fn world_bounds(&self, object: &crate::scene::Object) -> Option<Aabb> {
        let (_, _, bounds) = &self.meshes[&(Arc::as_ptr(&object.mesh) as usize)];
        bounds.map(|b| b.transformed(&object.transform))
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
        let t = material.diffuse_texture.as_ref()?;
        self.textures
            .get(&(Arc::as_ptr(t) as usize))
            .map(|(_, g)| g)
    }

    /// The white stand-in texture (only after an upload with full variants).
    pub fn white(&self) -> Option<&ImageTexture> {
        self.white.as_ref()
    }

    pub(crate) fn destroy(&mut self, dev: &Device) {
        for (_, (_, mut m, _)) in self.meshes.drain() {
            m.destroy(dev);
        }
        for (_, (_, mut t)) in self.textures.drain() {
            t.destroy(dev);
        }
        if let Some(mut w) = self.white.take() {
            w.destroy(dev);
        }
    }
}
