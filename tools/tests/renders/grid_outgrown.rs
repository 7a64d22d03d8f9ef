//! The automatic grid chosen for a few small lights, when the lights jump to many that each
//! cover the view: the grid's lists no longer fit, and a fresh renderer would choose a coarse
//! grid at once. The warm renderer used to keep its fine grid until the re-choice after a
//! change was due (up to 30 frames), dropping light references in every one of them (on ES
//! 3.0 with 25 000 such lights each frame failed: more references than an assignment builds).
//! The index budget is lowered (`MeasureOptions::max_indices`) to reach the same state with
//! few lights.

use crate::common;

use common::Gpu;
use glam::{DVec3, Vec3};
use manylight::{Camera, EsVersion, Light, MeasureOptions, RenderOptions, Scene};

const SIZE: (u32, u32) = (96, 54);

/// References the frame's lists may hold: the 200 lights in every cell of the coarsest
/// grids fit, in the fine grid 60 small lights get, they do not.
const BUDGET: usize = 40_000;

fn floor_lit_by(count: usize, radius: f32) -> Scene {
    let mut s = common::floor_12m();
    let side = (count as f64).sqrt().ceil() as usize;
    s.lights = (0..count)
        .map(|i| {
            let (x, z) = ((i % side) as f64, (i / side) as f64);
            let at = DVec3::new(
                -4.0 + 8.0 * x / side as f64,
                0.3,
                -4.0 + 8.0 * z / side as f64,
            );
            Light::point(at, radius, Vec3::new(0.5, 0.4, 0.3), 2.0 / count as f32)
        })
        .collect();
    s.camera = Camera::perspective(
        DVec3::new(0.0, 4.0, 8.0),
        DVec3::new(0.0, 0.5, 0.0),
        55.0,
        0.1,
        100.0,
    );
    s
}

#[test]
fn a_grid_the_lights_outgrow_is_chosen_again_in_the_same_frame() {
    let options = RenderOptions {
        measure: MeasureOptions {
            max_indices: Some(BUDGET),
            ..Default::default()
        },
        ..Default::default()
    };
    let (w, h) = SIZE;
    for es in [EsVersion::Es3, EsVersion::Es2] {
        let mut warm = Gpu::new(es);
        warm.r().set_method_named("clustered").unwrap();
        let mut few = floor_lit_by(60, 0.6);
        let mut fine = 0;
        for k in 0..12 {
            few.lights[0].position.x += 0.01 * k as f64;
            let (_, s) = warm.r().render_offscreen(&few, w, h, &options).unwrap();
            assert_eq!(s.lights.overflowed, 0, "{es}: the few lights fit");
            fine = s.grid.cells;
        }
        let many = floor_lit_by(200, 100.0);
        let mut fresh = Gpu::new(es);
        fresh.r().set_method_named("clustered").unwrap();
        let (want, chosen) = fresh.r().render_offscreen(&many, w, h, &options).unwrap();
        assert_eq!(
            chosen.lights.overflowed, 0,
            "{es}: a fresh renderer's grid fits"
        );
        assert!(
            200 * fine as usize > BUDGET,
            "{es}: the few lights' grid of {fine} cells cannot hold 200 lights a cell"
        );
        let (got, s) = warm.r().render_offscreen(&many, w, h, &options).unwrap();
        assert_eq!(
            s.lights.overflowed,
            0,
            "{es}: the warm renderer kept its {} cells: {}",
            s.grid.cells,
            s.grid.reason.unwrap_or_default()
        );
        let worst = got
            .pixels()
            .zip(want.pixels())
            .flat_map(|(a, b)| (0..3).map(|c| a[c].abs_diff(b[c])))
            .max()
            .unwrap();
        assert!(
            worst <= 2,
            "{es}: {worst}/255 from a fresh renderer's frame"
        );
    }
}

/// A grid chosen under a tight index budget is chosen again in the first frame without it: a
/// renderer kept its coarse grid for 16 to 249 frames after the limit was lifted, where a
/// fresh one chose cells a sixth the size.
#[test]
fn a_grid_chosen_under_a_tight_budget_is_chosen_again_once_it_is_lifted() {
    let tight = RenderOptions {
        measure: MeasureOptions {
            max_indices: Some(64),
            ..Default::default()
        },
        ..Default::default()
    };
    let (w, h) = SIZE;
    let mut gpu = Gpu::new(EsVersion::Es3);
    gpu.r().set_method_named("clustered").unwrap();
    let mut lights = floor_lit_by(60, 0.6);
    let mut coarse = 0;
    for k in 0..12 {
        lights.lights[0].position.x += 0.01 * k as f64;
        let (_, s) = gpu.r().render_offscreen(&lights, w, h, &tight).unwrap();
        coarse = s.grid.cells;
    }
    let (_, s) = (gpu.r())
        .render_offscreen(&lights, w, h, &RenderOptions::default())
        .unwrap();
    assert!(
        s.grid.cells > coarse,
        "the grid of {coarse} cells chosen under the budget was kept: {}",
        s.grid.reason.unwrap_or_default()
    );
}
