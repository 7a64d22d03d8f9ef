//! Tiled forward: the same engine as clustered with 2D screen tiles (`cluster::tiles`), so a
//! tile's list holds every light crossing its frustum column at any depth.

use super::culled::{CulledForward, Culling};
use super::culled_support::culled_support;
use super::MethodDesc;
use crate::gl::EsVersion;

/// The table row.
pub const DESC: MethodDesc = MethodDesc {
    name: "tiled",
    summary: "tiled forward: each fragment loops over its 2D screen tile's lights",
    min_es: EsVersion::Es2,
    required_extensions: &[],
    supported: culled_support,
    multisample: true,
    create: |_| Ok(Box::new(CulledForward::new(Culling::Tiled))),
};
