//! A driver that ends long shader loops early (llvmpipe: 65 535 iterations for all the loops
//! of a shader) must not drop lights silently. 65 535 dim lights and one bright green one,
//! listed last, all reach the middle of a plane: past the loop's end the green light was lost
//! by forward, tiled and clustered alike, with no warning and no count, and forward is the
//! reference every other method is checked against. Now the light loop is capped below the
//! driver's limit: the lights that matter most stay (the green one), the rest are counted as
//! overflowed, as any cap of this renderer's.

use crate::common;

use common::Gpu;
use glam::{DVec3, Vec3};
use manylight::scene::{self, Light};
use manylight::{EsVersion, RenderOptions};

const W: u32 = 16;
const H: u32 = 9;

#[test]
fn the_last_of_65_536_lights_on_one_spot_still_shows() {
    let mut s = scene::builtin::build("plane", None).unwrap();
    s.ambient = Vec3::ZERO;
    let spot = DVec3::new(0.0, 0.0, 0.5);
    s.lights = vec![Light::point(spot, 4.0, Vec3::new(1.0, 0.0, 0.0), 1e-6); 65_535];
    s.lights
        .push(Light::point(spot, 4.0, Vec3::new(0.0, 1.0, 0.0), 2.0));
    let opts = RenderOptions {
        linear: true,
        ..Default::default()
    };
    let mut gpu = Gpu::new(EsVersion::Es3);
    let budget = gpu.r().caps().light_loop_budget();
    for method in ["forward", "tiled", "clustered", "deferred"] {
        gpu.r().set_method_named(method).unwrap();
        let (img, stats) = gpu.r().render_offscreen(&s, W, H, &opts).unwrap();
        let centre = img.get_pixel(W / 2, H / 2);
        assert!(
            centre[1] > 100,
            "{method}: the green light is missing from the middle: {centre:?}"
        );
        if method != "deferred" && budget < 65_536 {
            assert!(
                stats.lights.overflowed > 0,
                "{method}: a driver loop of {budget} lights dropped none"
            );
        }
    }
}
