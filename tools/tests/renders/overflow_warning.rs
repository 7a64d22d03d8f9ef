//! The overflow warning (said once a renderer) is kept for a frame that draws: a frame refused
//! for more visible lights than the lists can number used to spend it, and a later frame
//! that really dropped light references then went unsaid.

use crate::common;

use common::warnings::warnings_containing;
use common::Gpu;
use manylight::scene;
use manylight::{EsVersion, RenderOptions};

#[test]
fn a_refused_frame_keeps_the_overflow_warning_for_one_that_draws() {
    let warning = "light references left out";
    common::warnings::install();
    let mut gpu = Gpu::new(EsVersion::Es2);
    gpu.r().set_method_named("tiled").unwrap();
    let crowd = scene::builtin::build("plane", Some((100_000, 3))).unwrap();
    let err = gpu
        .r()
        .render_offscreen(&crowd, 32, 18, &RenderOptions::default())
        .unwrap_err();
    assert!(err.to_string().contains("lights are visible"), "{err}");
    assert!(
        warnings_containing(warning).is_empty(),
        "the refused frame warned"
    );
    // 1 024 lights over cells of at most 4 each: references dropped, and said.
    let crowded = scene::builtin::build("plane", Some((1024, 3))).unwrap();
    let capped = RenderOptions {
        measure: manylight::MeasureOptions {
            cell_cap: Some(4),
            ..Default::default()
        },
        ..Default::default()
    };
    let (_, stats) = gpu.r().render_offscreen(&crowded, 32, 18, &capped).unwrap();
    assert!(stats.lights.overflowed > 0, "nothing overflowed");
    assert_eq!(warnings_containing(warning).len(), 1);
}
