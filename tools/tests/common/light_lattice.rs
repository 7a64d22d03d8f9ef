//! More lights than tiled and clustered can index, all in view of the `plane` scene's camera:
//! the frames `auto` must render some other way.

use manylight::cluster::pack::MAX_INDEXED_LIGHTS;
use manylight::scene::{self, Light, Scene};

/// The built-in `plane` with one light past [`MAX_INDEXED_LIGHTS`] on a lattice just above
/// it (256 a row), each dim and small.
pub fn plane_past_the_index_limit() -> Scene {
    let mut s = scene::builtin::build("plane", None).unwrap();
    s.lights = (0..MAX_INDEXED_LIGHTS + 1)
        .map(|i| {
            let x = (i % 256) as f64 / 64.0 - 2.0;
            let y = (i / 256) as f64 / 107.0 - 1.2;
            Light::point(glam::DVec3::new(x, y, 0.2), 0.3, glam::Vec3::ONE, 1e-3)
        })
        .collect();
    s
}
