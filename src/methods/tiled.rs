//! Tiled forward: the same engine as clustered with 2D screen tiles (`cluster::tiles`), so a
//! tile's list holds every light crossing its frustum column at any depth.

use super::clustered::culled_support;
use super::culled::{CulledForward, Culling};
use super::{FrameContext, MethodDesc, MethodStats, ShadingMethod};
use crate::gl::{Device, EsVersion};
use crate::Error;

/// The table row.
pub const DESC: MethodDesc = MethodDesc {
    name: "tiled",
    summary: "tiled forward: each fragment loops over its 2D screen tile's lights",
    min_es: EsVersion::Es2,
    required_extensions: &[],
    supported: culled_support,
    create: |_| Ok(Box::new(Tiled(CulledForward::new(Culling::Tiled)))),
};

/// Tiled forward.
pub struct Tiled(CulledForward);

impl ShadingMethod for Tiled {
    fn name(&self) -> &'static str {
        DESC.name
    }
    fn render(&mut self, ctx: &mut FrameContext) -> Result<MethodStats, Error> {
        self.0.render(ctx)
    }
    fn gpu_bytes(&self) -> usize {
        self.0.gpu_bytes()
    }
    fn destroy(&mut self, dev: &Device) {
        self.0.destroy(dev)
    }
}
