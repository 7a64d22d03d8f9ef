//! [`Renderer::free_unused_programs`]: the shader variants a game's recent frames no longer
//! draw with, freed when it asks.

use super::Renderer;
use crate::Error;

impl Renderer {
    /// Frees the shader variants that none of the last `frames` frames drew with, nor a
    /// [`Renderer::warm_up`] since them (a warm-up counts as the frame after it), and returns
    /// how many it freed. A frame is a call that drew: [`Renderer::render`],
    /// [`Renderer::render_reusing`] or an offscreen render; one refused before it drew (an
    /// empty viewport, an invalid option) is none, and a game drawing two views a displayed
    /// frame (split screen) makes two.
    ///
    /// Variants are otherwise kept for the renderer's life, so that a material, light kind or
    /// option that comes back costs no compile: a game that has drawn many kinds of content
    /// (levels, options menus, methods switched) calls this once it has moved to the next
    /// level: right after that level's warm-up with `frames` 0, or after its first displayed
    /// frame with `frames` covering it (1, or 2 for two views). Each variant held costs the driver memory for its code (a few
    /// hundred KB on llvmpipe); [`MemoryStats::shader_programs`](crate::MemoryStats::shader_programs)
    /// counts them. A frame that needs a freed one builds it again, a hitch
    /// ([`FrameStats::programs_built`](crate::FrameStats::programs_built)).
    pub fn free_unused_programs(&mut self, frames: u32) -> Result<usize, Error> {
        self.hosted(|r| {
            let freed = r.programs.free_unused(&r.dev, u64::from(frames));
            r.dev.check("freeing unused shader programs")?;
            Ok(freed)
        })
    }
}
