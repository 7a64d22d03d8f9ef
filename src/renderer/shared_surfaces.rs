//! Whether a frame's objects take the shared surface variants (`methods::surface_variants`),
//! with a warning the first time a scene needs them.

use crate::gl::Caps;
use crate::methods::surface_variants::{VariantCount, MAX_SURFACE_VARIANTS};
use crate::scene::Scene;

/// The count's buffers and whether the warning was given.
#[derive(Default)]
pub(super) struct SharedSurfaces {
    count: VariantCount,
    warned: bool,
}

impl SharedSurfaces {
    /// True when `scene`'s objects ask for more than [`MAX_SURFACE_VARIANTS`] surface variants
    /// on this context; warns (once a renderer) the first time.
    pub(super) fn needed(&mut self, scene: &Scene, caps: &Caps) -> bool {
        let units = caps.max_texture_image_units;
        let needed = self.count.more_than(scene, units, MAX_SURFACE_VARIANTS);
        if needed && !self.warned {
            self.warned = true;
            log::warn!(
                "the scene's materials ask for more than {MAX_SURFACE_VARIANTS} shader \
                 variants: its objects share superset variants, with neutral values for the \
                 inputs a material lacks (the same picture; more texture reads a pixel, far \
                 fewer programs to build)"
            );
        }
        needed
    }
}
