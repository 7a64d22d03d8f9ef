//! Whether tiled and clustered run on a context: the support both culled methods share, below
//! their capacities and `auto`'s choice, which ask it too.

use super::Support;
use crate::gl::{Caps, EsVersion};

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
