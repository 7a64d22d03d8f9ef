//! The overflow warning (said once a renderer) is kept for a frame that draws: a frame refused
//! for more visible lights than the lists can number used to spend it, and a later frame
//! that really dropped light references then went unsaid.

use crate::common;

use common::warnings::warnings_containing;
use common::Gpu;
use manylight::cluster::grid::GridConfig;
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

/// The warning names the limit that left references out and the way round it for that
/// limit: a cell's cap wants smaller cells (or tiles), a full index list a coarser grid (or
/// larger tiles). It advised a coarser grid for both, which makes a cell's cap drop more.
#[test]
fn the_overflow_warning_advises_for_the_limit_that_bound() {
    let warning = "light references left out";
    common::warnings::install();
    let crowded = scene::builtin::build("plane", Some((1024, 3))).unwrap();
    let limited = |cell_cap, max_indices| RenderOptions {
        grid: GridConfig::fixed(16.0),
        measure: manylight::MeasureOptions {
            cell_cap,
            max_indices,
            ..Default::default()
        },
        ..Default::default()
    };
    let cases = [
        ("clustered", Some(4), None, "smaller cells", "coarser grid"),
        ("clustered", None, Some(64), "coarser grid", "smaller cells"),
        ("tiled", Some(4), None, "smaller tiles", "larger tiles"),
        ("tiled", None, Some(64), "larger tiles", "smaller tiles"),
    ];
    for (method, cap, indices, advised, not_advised) in cases {
        let mut gpu = Gpu::new(EsVersion::Es3);
        gpu.r().set_method_named(method).unwrap();
        let options = limited(cap, indices);
        let (_, stats) = gpu
            .r()
            .render_offscreen(&crowded, 32, 18, &options)
            .unwrap();
        assert!(stats.lights.overflowed > 0, "{method}: nothing overflowed");
        let said = warnings_containing(warning);
        let last = said.last().expect("warned");
        let full = indices.is_some();
        assert!(
            last.contains(advised)
                && !last.contains(not_advised)
                && last.contains("the index list was full") == full,
            "{method}, cap {cap:?}, indices {indices:?}: {last}"
        );
    }
}

/// Under a per-cell cap the automatic grid weighs what the picture loses (the references a
/// sampled surface point misses), not how many references go: a coarser grid can drop fewer,
/// each from a larger part of the frame. With the courtyard's 64 lights at most 16 a cell, the
/// search, going finer, stopped at 32 pixels, which dropped more references (95) than 54 (71),
/// and took 54 (94/255 from forward; helper-161's bench row). It now goes on to grids that
/// drop fewer a pixel, and its picture loses far less than a 54-pixel grid's.
#[test]
fn under_a_cell_cap_the_automatic_grid_keeps_what_the_picture_needs() {
    let s = scene::builtin::build("courtyard", Some((64, 1))).unwrap();
    let capped = |grid: GridConfig| RenderOptions {
        measure: manylight::MeasureOptions {
            cell_cap: Some(16),
            ..Default::default()
        },
        grid,
        ..Default::default()
    };
    let (w, h) = (64, 36);
    let mut gpu = Gpu::new(EsVersion::Es3);
    gpu.r().set_method_named("forward").unwrap();
    let (reference, _) = gpu
        .r()
        .render_offscreen(&s, w, h, &RenderOptions::default())
        .unwrap();
    gpu.r().set_method_named("clustered").unwrap();
    let (coarse, _) = gpu
        .r()
        .render_offscreen(&s, w, h, &capped(GridConfig::fixed(54.0)))
        .unwrap();
    let mut fresh = Gpu::new(EsVersion::Es3);
    fresh.r().set_method_named("clustered").unwrap();
    let (auto, stats) = fresh
        .r()
        .render_offscreen(&s, w, h, &capped(GridConfig::default()))
        .unwrap();
    let coarse_error = manylight::metrics::diff(&reference, &coarse);
    let auto_error = manylight::metrics::diff(&reference, &auto);
    assert!(
        auto_error.rmse * 4.0 < coarse_error.rmse,
        "automatic grid {auto_error:?}, the coarse one {coarse_error:?}: {:?}",
        stats.grid.reason
    );
}
