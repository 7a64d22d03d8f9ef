//! Clustered forward (the default): lights assigned on the CPU every frame to the dense,
//! cascaded cluster grid (`cluster::grid`), uploaded as textures, one geometry pass.

use super::culled::{CulledForward, Culling};
use super::culled_support::culled_support;
use super::MethodDesc;
use crate::gl::EsVersion;

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
