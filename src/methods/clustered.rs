//! Clustered forward (the default): lights assigned on the CPU every frame to the dense,
//! cascaded cluster grid (`cluster::grid`), uploaded as textures, one geometry pass.

use super::culled::{CulledForward, Culling};
use super::{MethodDesc, Support};
use crate::gl::{Caps, EsVersion};

/// The table row.
pub const DESC: MethodDesc = MethodDesc {
    name: "clustered",
    summary: "cascaded clustered forward: each fragment loops over its 3D cell's lights",
    min_es: EsVersion::Es2,
    required_extensions: &[],
    supported: culled_support,
    multisample: true,
    create: |_| Ok(Box::new(CulledForward::new(Culling::Clustered))),
};

/// Support of both culled methods: ES 2.0 needs highp fragments (cell lookup and texel
/// addressing), and without float textures lights are RGBA8-packed.
pub fn culled_support(caps: &Caps) -> Support {
    if let Some(why) = super::forward::data_textures_unfit(caps) {
        return Support::Unsupported(why);
    }
    if caps.es == EsVersion::Es2 && !caps.fragment_has_highp() {
        return Support::Unsupported(
            "the fragment stage has no highp floats, needed to find cells and address data textures exactly".into(),
        );
    }
    if !caps.float_textures {
        return Support::Fallback(
            "lights packed as RGBA8 (lossy) because GL_OES_texture_float is missing".into(),
        );
    }
    Support::Supported
}
