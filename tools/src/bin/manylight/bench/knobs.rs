//! The knobs `manylight bench` varies from the defaults, each on one method.

use manylight::cluster::grid::{Coverage, GridConfig};
use manylight::RenderOptions;

/// A knob varied from the defaults, on one method.
pub(super) struct Knob {
    pub(super) name: String,
    pub(super) method: &'static str,
    pub(super) apply: fn(&mut RenderOptions, f64),
    pub(super) value: f64,
    /// Run on every scene of the plan (the grid knobs), not only the first.
    pub(super) every_scene: bool,
    /// Drops lights on purpose (a cap per cell): its rows count them, so the renderer's
    /// overflow warning is silenced for it.
    pub(super) drops_lights: bool,
}

pub(super) fn knobs(quick: bool) -> Vec<Knob> {
    let mut k = Vec::new();
    let mut add = |name: &str, method, apply: fn(&mut RenderOptions, f64), values: &[f64]| {
        for &value in values {
            k.push(Knob {
                name: format!("{name}={value}"),
                method,
                apply,
                value,
                every_scene: name.starts_with("footprint_px")
                    || name == "coverage"
                    || name == "slice_depth"
                    || name == "assign_budget",
                drops_lights: name == "cell_cap",
            });
        }
    };
    let pick = |full: &'static [f64], q: &'static [f64]| if quick { q } else { full };
    add(
        "cutoff",
        "clustered",
        |o, v| o.light_cutoff = Some(v as f32),
        pick(&[0.001, 0.01, 0.05], &[0.01]),
    );
    add(
        "cutoff",
        "tiled",
        |o, v| o.light_cutoff = Some(v as f32),
        pick(&[0.01], &[]),
    );
    add(
        "cell_cap",
        "clustered",
        |o, v| o.measure.cell_cap = Some(v as u32),
        pick(&[64.0, 16.0], &[16.0]),
    );
    // Fixed grids against the automatic one (the default rows), on every scene.
    add(
        "footprint_px",
        "clustered",
        |o, v| o.grid = GridConfig::fixed(v),
        pick(&[8.0, 16.0, 32.0, 64.0], &[16.0, 64.0]),
    );
    // The automatic grid without its CPU budget (the frame time alone decides): what the
    // budget's share of the frame costs in frame time and buys in assignment time.
    add(
        "assign_budget",
        "clustered",
        |o, v| o.grid.mode = manylight::GridMode::Auto { assign_budget: v },
        pick(&[1.0], &[]),
    );
    // Slices half as deep as a cell is wide: on the automatic grid, and on the finest fixed
    // one (what the finest cells can get out of a grazing floor).
    add(
        "slice_depth",
        "clustered",
        |o, v| o.grid.slice_depth = v,
        pick(&[0.5], &[]),
    );
    add(
        "footprint_px=8,slice_depth",
        "clustered",
        |o, v| {
            o.grid = GridConfig {
                slice_depth: v,
                ..GridConfig::fixed(8.0)
            }
        },
        pick(&[0.5], &[]),
    );
    // The per-cascade rectangle (1 = cascade box), automatic grid: what the tight bound saves.
    add(
        "coverage",
        "clustered",
        |o, _| o.grid.measure.coverage = Coverage::CascadeBox,
        pick(&[1.0], &[]),
    );
    // 4× MSAA against none: cost against edge error (ES 3.0; skipped where unsupported).
    add(
        "msaa",
        "clustered",
        |o, v| o.samples = v as u32,
        pick(&[4.0], &[]),
    );
    add(
        "cascades",
        "clustered",
        |o, v| o.grid.cascades = v as u32,
        pick(&[4.0, 8.0, 16.0], &[4.0]),
    );
    add(
        "rgba8_lights",
        "clustered",
        |o, _| o.measure.force_rgba8_lights = true,
        &[1.0],
    );
    k
}
