//! Render options the frame cannot be made from are refused as `Error::InvalidOption` naming
//! the field, where they drew a wrong picture with `Ok` (a NaN cut-off culled lights, a NaN
//! clear colour cleared to transparent black, a NaN tile size rebuilt the tiles every frame).

use crate::common;

use common::Gpu;
use manylight::{CountKind, EsVersion, RenderOptions};

#[test]
fn every_unusable_option_is_refused_naming_its_field() {
    let scene = manylight::scene::builtin::build("plane", Some((8, 1))).unwrap();
    let mut gpu = Gpu::new(EsVersion::Es3);
    let cases: Vec<(&str, &str, RenderOptions)> = vec![
        (
            "clustered",
            "light_cutoff",
            RenderOptions {
                light_cutoff: Some(f32::NAN),
                ..Default::default()
            },
        ),
        (
            "clustered",
            "light_cutoff",
            RenderOptions {
                light_cutoff: Some(f32::INFINITY),
                ..Default::default()
            },
        ),
        (
            "tiled",
            "light_cutoff",
            RenderOptions {
                light_cutoff: Some(-1.0),
                ..Default::default()
            },
        ),
        (
            "forward",
            "clear_color",
            RenderOptions {
                clear_color: [f32::NAN, 0.0, 0.0, 1.0],
                ..Default::default()
            },
        ),
        (
            "tiled",
            "tile_px",
            RenderOptions {
                tile_px: f64::NAN,
                ..Default::default()
            },
        ),
        (
            "tiled",
            "tile_px",
            RenderOptions {
                tile_px: 0.0,
                ..Default::default()
            },
        ),
        (
            "tiled",
            "tile_px",
            RenderOptions {
                tile_px: -16.0,
                ..Default::default()
            },
        ),
        (
            "clustered",
            "heat_scale",
            RenderOptions {
                heat_scale: f32::NAN,
                ..Default::default()
            },
        ),
        (
            "clustered",
            "heat_scale",
            RenderOptions {
                heat_scale: 0.5,
                ..Default::default()
            },
        ),
        (
            "forward",
            "exposure_ev",
            RenderOptions {
                exposure_ev: f32::NAN,
                ..Default::default()
            },
        ),
        (
            "clustered",
            "grid.first_split",
            RenderOptions {
                grid: manylight::GridConfig {
                    first_split: Some(f64::NAN),
                    ..Default::default()
                },
                ..Default::default()
            },
        ),
        (
            "tiled",
            "grid.measure.min_cell_size",
            RenderOptions {
                grid: manylight::GridConfig {
                    measure: manylight::GridMeasure {
                        min_cell_size: Some(f64::INFINITY),
                        ..Default::default()
                    },
                    ..Default::default()
                },
                ..Default::default()
            },
        ),
    ];
    // MSAA asked for on a method without it: the option's error still comes first.
    let mut cases = cases;
    cases.push((
        "deferred",
        "exposure_ev",
        RenderOptions {
            exposure_ev: f32::INFINITY,
            samples: 4,
            ..Default::default()
        },
    ));
    for (method, field, options) in cases {
        gpu.r().set_method_named(method).unwrap();
        let err = gpu
            .r()
            .render_offscreen(&scene, 32, 18, &options)
            .unwrap_err();
        match &err {
            manylight::Error::InvalidOption { field: named, .. } => {
                assert_eq!(*named, field, "{err}")
            }
            other => panic!("{method} {field}: not InvalidOption: {other}"),
        }
        assert!(err.to_string().contains(field), "{err}");
    }
    // The limits themselves are usable: a cut-off of 0 is the radius, exactly.
    let zero = RenderOptions {
        light_cutoff: Some(0.0),
        ..Default::default()
    };
    gpu.r().set_method_named("clustered").unwrap();
    gpu.r().render_offscreen(&scene, 32, 18, &zero).unwrap();
}

/// A refusal quotes the value it refused written short: `{}` writes -1e300 in 301 digits and
/// `f32::MAX` in 39, a line a log or a game's dialog cannot use.
#[test]
fn huge_and_tiny_refused_values_are_written_short() {
    let scene = manylight::scene::builtin::build("plane", Some((8, 1))).unwrap();
    let mut gpu = Gpu::new(EsVersion::Es3);
    let grid = |g: manylight::GridConfig| RenderOptions {
        grid: g,
        ..Default::default()
    };
    let cases: Vec<(&str, &str, RenderOptions)> = vec![
        (
            "light_cutoff",
            "-3.4028235e38",
            RenderOptions {
                light_cutoff: Some(f32::MIN),
                ..Default::default()
            },
        ),
        (
            "tile_px",
            "-1e300",
            RenderOptions {
                tile_px: -1e300,
                ..Default::default()
            },
        ),
        (
            "heat_scale",
            "1e-30",
            RenderOptions {
                heat_scale: 1e-30,
                ..Default::default()
            },
        ),
        (
            "exposure_ev",
            "1e30",
            RenderOptions {
                exposure_ev: 1e30,
                ..Default::default()
            },
        ),
        (
            "grid.footprint_px",
            "-1e300",
            grid(manylight::GridConfig {
                footprint_px: -1e300,
                ..Default::default()
            }),
        ),
        (
            "grid.slice_depth",
            "-1e-300",
            grid(manylight::GridConfig {
                slice_depth: -1e-300,
                ..Default::default()
            }),
        ),
        (
            "grid.assign_budget",
            "-1e300",
            grid(manylight::GridConfig {
                mode: manylight::GridMode::Auto {
                    assign_budget: -1e300,
                },
                ..Default::default()
            }),
        ),
    ];
    gpu.r().set_method_named("clustered").unwrap();
    for (field, shown, options) in cases {
        let err = gpu
            .r()
            .render_offscreen(&scene, 32, 18, &options)
            .unwrap_err()
            .to_string();
        assert!(err.contains(field), "{err}");
        assert!(err.ends_with(&format!("got {shown}")), "{field}: {err}");
        assert!(err.len() < 120, "{field}: {} bytes: {err}", err.len());
    }
}

/// `render_light_counts` counts: asked for colour (`None`, `Heatmap`) it refused nothing and
/// returned the colour image read as counts.
#[test]
fn light_counts_of_colour_kinds_are_refused() {
    let scene = manylight::scene::builtin::build("plane", Some((8, 1))).unwrap();
    let mut gpu = Gpu::new(EsVersion::Es3);
    for kind in [CountKind::None, CountKind::Heatmap] {
        let err = gpu
            .r()
            .render_light_counts(&scene, 32, 18, &RenderOptions::default(), kind)
            .unwrap_err();
        assert!(
            matches!(err, manylight::Error::InvalidOption { field: "kind", .. }),
            "{kind:?}: {err}"
        );
    }
    for kind in [CountKind::Evals, CountKind::Reaching] {
        let (counts, _) = gpu
            .r()
            .render_light_counts(&scene, 32, 18, &RenderOptions::default(), kind)
            .unwrap();
        assert!(
            counts.max() <= 8,
            "{kind:?}: {} lights at a pixel of 8",
            counts.max()
        );
    }
}

/// Sizes and HDR as a test writer meets them: an empty size is the same
/// `Error::EmptyViewport` through `render` and `render_offscreen` (the offscreen one said
/// "unsupported" by GL; both were a `Limit` string a game could not match on), and
/// `Caps::hdr_output` says beforehand whether `render_offscreen_hdr` runs.
#[test]
fn empty_sizes_are_one_error_and_hdr_support_is_asked_first() {
    let scene = manylight::scene::builtin::build("plane", Some((8, 1))).unwrap();
    for es in [EsVersion::Es2, EsVersion::Es3] {
        let mut gpu = Gpu::new(es);
        let options = RenderOptions::default();
        for (w, h) in [(0, 18), (32, 0)] {
            let offscreen = gpu
                .r()
                .render_offscreen(&scene, w, h, &options)
                .unwrap_err();
            let bound = gpu.r().render(&scene, w, h, &options).unwrap_err();
            assert!(
                matches!(
                    offscreen,
                    manylight::Error::EmptyViewport { width, height } if (width, height) == (w, h)
                ),
                "{es} {w}×{h}: {offscreen}"
            );
            assert_eq!(offscreen.to_string(), bound.to_string());
        }
        let hdr = gpu.r().render_offscreen_hdr(&scene, 32, 18, &options);
        assert_eq!(
            gpu.r().caps().hdr_output(),
            hdr.is_ok(),
            "{es}: hdr_output says otherwise than the render: {:?}",
            hdr.err()
        );
    }
}
