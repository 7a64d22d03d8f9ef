//! The error-against-run-time report of `manylight bench`: one row per configuration (scene,
//! method, ES version, light count, knob), the tables a person reads, and two charts per
//! scene.
//!
//! Every row carries the machine facts its figures depend on (renderer string,
//! `LP_NUM_THREADS`), so a figure is never quoted without them.
//!
//! Each method has one colour and marker in every chart, from its place in
//! [`METHODS`](manylight::methods::METHODS) (see [`method_style`]).

mod charts;
mod files;
mod markdown;
#[cfg(test)]
mod tests;

use std::path::Path;

use serde::Serialize;

use crate::output;
use crate::plot;

pub use charts::{error_vs_time, evals_vs_lights, method_style};
pub use files::{chart_file, diff_file, file_tag, heatmap_file, reference_file};
pub use markdown::markdown;
pub(crate) use markdown::md_text;

/// One configuration's measurements.
#[derive(Clone, Debug, Serialize)]
pub struct BenchRow {
    /// Scene name (built-in or file).
    pub scene: String,
    /// Shading method.
    pub method: String,
    /// Feature level, "2.0" or "3.0".
    pub es: String,
    /// Lights in the scene.
    pub lights: usize,
    /// Image width.
    pub width: u32,
    /// Image height.
    pub height: u32,
    /// The knob varied from the defaults ("default" when none), e.g. "cutoff=0.01".
    pub knob: String,
    /// Frame time: median of the timed frames, wall clock around the frame and `glFinish`.
    pub frame_ms: f64,
    /// The timed frames the medians are of (`--frames`, or 9 or 3 as the row's pace).
    pub timed_frames: u32,
    /// For `auto`, the method it drew the timed frames with (the last one's); `None` else, and
    /// for a frame without lights (ambient only, no method).
    pub auto_choice: Option<String>,
    /// GPU time from a timer query (median), where the context has one.
    pub gpu_ms: Option<f64>,
    /// CPU light-assignment time (median; 0 for methods without one).
    pub assign_ms: f64,
    /// Bytes uploaded per frame.
    pub upload_bytes: usize,
    /// Draw calls of a frame, every pass's.
    pub draw_calls: u64,
    /// Light evaluations summed over the covered pixels.
    pub light_evals: u64,
    /// Mean light evaluations per covered pixel.
    pub evals_per_pixel: f64,
    /// Most light evaluations at one pixel.
    pub max_evals: u32,
    /// Lights that really reach the covered pixels, summed: the lower bound of `light_evals`.
    pub lower_bound_evals: u64,
    /// `lower_bound_evals` per covered pixel.
    pub lower_bound_per_pixel: f64,
    /// `light_evals / lower_bound_evals` (1 is perfect culling; `None` when the bound is 0).
    pub evals_ratio: Option<f64>,
    /// Largest channel difference from the reference image, in 8-bit steps.
    pub max_abs_err: u8,
    /// Root mean square channel difference from the reference (8-bit steps).
    pub rmse: f64,
    /// Peak signal-to-noise ratio in dB (`None` for an image identical to the reference).
    pub psnr_db: Option<f64>,
    /// Fraction of pixels more than 1/255 off.
    pub over_1: f64,
    /// Fraction of pixels more than 2/255 off.
    pub over_2: f64,
    /// Against the light model on the CPU in f64 at sampled pixels: largest error (8-bit
    /// steps, outside the sub-pixel interval) and the number of samples; `None` when no pixel
    /// could be sampled (textured or transparent surfaces only).
    pub cpu_max_abs_err: Option<f64>,
    /// Samples of the CPU reference.
    pub cpu_samples: usize,
    /// Light references dropped by the overflow policy.
    pub overflowed_lights: u64,
    /// Cell footprint of the grid the frame used (tiled, clustered).
    pub grid_footprint_px: Option<f64>,
    /// Cells of that grid (0 without one).
    pub grid_cells: u32,
    /// Why the grid is what it is (the automatic choice's prediction, or the fixed setting).
    pub grid_reason: Option<String>,
    /// `GL_RENDERER`.
    pub renderer: String,
    /// `LP_NUM_THREADS`, when set.
    pub lp_num_threads: Option<String>,
}

/// A whole run.
#[derive(Clone, Debug, Serialize)]
pub struct Report {
    /// The command that produced it.
    pub command: String,
    /// Logical CPUs of the machine.
    pub cpus: usize,
    /// Seconds the run took.
    pub seconds: f64,
    /// The rows.
    pub rows: Vec<BenchRow>,
    /// The animated workload's rows (frame-time spreads over moving frames).
    pub animated: Vec<crate::animated::AnimatedRow>,
    /// The pictures written beside the report, listed in report.md (not in report.json,
    /// whose fields are the rows').
    #[serde(skip)]
    pub pictures: Vec<Pictures>,
}

/// The pictures of one scene on one ES version at the light count its knobs run at: file
/// names in the report folder (see [`heatmap_file`], [`diff_file`], [`reference_file`]).
#[derive(Clone, Debug, Default)]
pub struct Pictures {
    /// Scene name, as in the rows.
    pub scene: String,
    /// Feature level, "2.0" or "3.0".
    pub es: String,
    /// Lights in the scene.
    pub lights: usize,
    /// The reference image (plain forward over all lights, light model at highp).
    pub reference: String,
    /// Light-evaluation heatmaps: (method, or "lower-bound"; file).
    pub heatmaps: Vec<(String, String)>,
    /// Differences from the reference: (method, file).
    pub diffs: Vec<(String, String)>,
}

/// The two charts of every scene, by base name.
pub(super) const CHARTS: [&str; 2] = ["error_vs_time", "evals_vs_lights"];

/// Writes `report.json`, `report.md` and, for every scene, `error_vs_time-<scene>.png` and
/// `evals_vs_lights-<scene>.png` into `dir` (the pictures are written by the caller).
pub fn write(report: &Report, dir: &Path) -> Result<(), String> {
    let io = |what: &str, e: &dyn std::fmt::Display| format!("cannot write {what}: {e}");
    std::fs::create_dir_all(dir).map_err(|e| io(&dir.display().to_string(), &e))?;
    let json = serde_json::to_string_pretty(report).map_err(|e| e.to_string())? + "\n";
    output::write_bytes(&dir.join("report.json"), json.as_bytes()).map_err(|e| e.to_string())?;
    output::write_bytes(&dir.join("report.md"), markdown(report).as_bytes())
        .map_err(|e| e.to_string())?;
    for scene in distinct(report.rows.iter().map(|r| r.scene.as_str())) {
        let lights = workload_lights(report, scene);
        let charts = [
            error_vs_time(&report.rows, scene, lights),
            evals_vs_lights(&report.rows, scene),
        ];
        for (base, chart) in CHARTS.iter().zip(charts) {
            let name = chart_file(base, scene);
            let picture = plot::render(&chart, 960, 640)?;
            output::save_png(&dir.join(&name), &picture).map_err(|e| e.to_string())?;
        }
    }
    Ok(())
}

/// The light count of `scene`'s knob workload: where its pictures were taken, else where its
/// knobs ran, else its largest light count.
fn workload_lights(report: &Report, scene: &str) -> usize {
    let pictured = report.pictures.iter().find(|p| p.scene == scene);
    let knob = || {
        report
            .rows
            .iter()
            .find(|r| r.scene == scene && r.knob != "default")
    };
    let largest = || {
        report
            .rows
            .iter()
            .filter(|r| r.scene == scene)
            .map(|r| r.lights)
            .max()
    };
    pictured
        .map(|p| p.lights)
        .or_else(|| knob().map(|r| r.lights))
        .or_else(largest)
        .unwrap_or(0)
}

/// Distinct values in order of first appearance.
pub(super) fn distinct<'a>(values: impl Iterator<Item = &'a str>) -> Vec<&'a str> {
    let mut out: Vec<&str> = Vec::new();
    for v in values {
        if !out.contains(&v) {
            out.push(v);
        }
    }
    out
}
