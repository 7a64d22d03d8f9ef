//! [`Renderer::free_unused_uploads`]: a game that keeps its meshes and images in an asset cache
//! of its own frees the GPU copies of those no scene draws any more.

use super::Renderer;
use crate::scene::Scene;
use crate::Error;

impl Renderer {
    /// Frees the GPU copies of meshes and images that none of `scenes` uses, and returns the
    /// bytes freed. An image is used where an object samples it: a material the scene lists
    /// but no object draws with keeps none of its textures. An upload is otherwise kept as long as the game holds the mesh's or
    /// image's `Arc` (so a scene that comes back costs no upload): a game that keeps its assets
    /// in a cache of its own calls this when it leaves a level, passing every scene it still
    /// draws. A scene that uses a freed one again uploads it in its next frame.
    /// [`MemoryStats::scene_gpu_bytes`](crate::MemoryStats::scene_gpu_bytes) says what is held.
    pub fn free_unused_uploads(&mut self, scenes: &[&Scene]) -> Result<usize, Error> {
        self.hosted(|r| {
            let freed = r.gpu_scene.free_unused(&r.dev, scenes);
            r.dev.check("freeing unused uploads")?;
            Ok(freed)
        })
    }
}
