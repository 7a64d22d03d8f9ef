//! The error-against-run-time report of `manylight bench`: one row per configuration (scene,
//! method, ES version, light count, knob), the tables a person reads, and the two charts.
//!
//! Every row carries the machine facts its figures depend on (renderer string,
//! `LP_NUM_THREADS`), so a figure is never quoted without them.

use std::fmt::Write as _;
use std::path::Path;

use serde::Serialize;

use super::plot::{self, Chart, Series};

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
    /// GPU time from a timer query (median), where the context has one.
    pub gpu_ms: Option<f64>,
    /// CPU light-assignment time (median; 0 for methods without one).
    pub assign_ms: f64,
    /// Bytes uploaded per frame.
    pub upload_bytes: usize,
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
}

/// Writes `report.json`, `report.md`, `error_vs_time.png` and `evals_vs_lights.png` into `dir`.
pub fn write(report: &Report, dir: &Path) -> Result<(), String> {
    let io = |what: &str, e: &dyn std::fmt::Display| format!("cannot write {what}: {e}");
    std::fs::create_dir_all(dir).map_err(|e| io(&dir.display().to_string(), &e))?;
    let json = serde_json::to_string_pretty(report).map_err(|e| e.to_string())? + "\n";
    std::fs::write(dir.join("report.json"), json).map_err(|e| io("report.json", &e))?;
    std::fs::write(dir.join("report.md"), markdown(report)).map_err(|e| io("report.md", &e))?;
    for (name, chart) in [
        ("error_vs_time.png", error_vs_time(&report.rows)),
        ("evals_vs_lights.png", evals_vs_lights(&report.rows)),
    ] {
        plot::render(&chart, 960, 640)?
            .save(dir.join(name))
            .map_err(|e| io(name, &e))?;
    }
    Ok(())
}

/// Error against frame time on the knob workload (the run's first scene at the light count
/// its knobs ran at, every ES version): one point per configuration — each method, each knob —
/// coloured by method, with the Pareto front (no other configuration both faster and more
/// accurate) drawn through them. Other workloads differ in what they render, so their points
/// would not trade against these; they are in the tables.
pub fn error_vs_time(rows: &[BenchRow]) -> Chart {
    let workload = rows
        .iter()
        .find(|r| r.knob != "default")
        .or_else(|| {
            rows.iter()
                .filter(|r| r.lights > 0)
                .max_by_key(|r| r.lights)
        })
        .map(|r| (r.scene.clone(), r.lights));
    let rows: Vec<&BenchRow> = rows
        .iter()
        .filter(|r| workload.as_ref() == Some(&(r.scene.clone(), r.lights)))
        .collect();
    let methods = distinct(rows.iter().map(|r| r.method.as_str()));
    let series = methods
        .iter()
        .enumerate()
        .map(|(i, m)| Series {
            label: m.to_string(),
            points: rows
                .iter()
                .filter(|r| r.method == *m)
                .map(|r| (r.frame_ms, r.rmse))
                .collect(),
            color: plot::palette(i),
            line: false,
        })
        .collect();
    let all: Vec<(f64, f64)> = rows.iter().map(|r| (r.frame_ms, r.rmse)).collect();
    let front = plot::pareto_front(&all)
        .into_iter()
        .map(|i| all[i])
        .collect();
    let (scene, lights) = workload.unwrap_or_default();
    Chart {
        title: format!("Error against frame time: {scene}, {lights} lights"),
        x_label: "frame time (ms, log)".into(),
        y_label: "RMSE vs reference (log)".into(),
        x_log: true,
        y_log: true,
        series,
        front: Some(front),
        y_floor: None,
    }
}

/// Light evaluations per pixel against the light count, one line per method on the run's
/// first scene (the default scene, unless the run names others) at ES 3.0 where the run has
/// it, with the lower bound.
pub fn evals_vs_lights(rows: &[BenchRow]) -> Chart {
    let base: Vec<&BenchRow> = rows
        .iter()
        .filter(|r| r.knob == "default" && r.lights > 0)
        .collect();
    let scene = base.first().map(|r| r.scene.as_str());
    let es = base
        .iter()
        .map(|r| r.es.as_str())
        .find(|&e| e == "3.0")
        .or_else(|| base.first().map(|r| r.es.as_str()));
    let base: Vec<&BenchRow> = base
        .into_iter()
        .filter(|r| Some(r.scene.as_str()) == scene && Some(r.es.as_str()) == es)
        .collect();
    let methods = distinct(base.iter().map(|r| r.method.as_str()));
    let line = |points: Vec<(f64, f64)>, label: String, color| Series {
        label,
        points,
        color,
        line: true,
    };
    let mut series: Vec<Series> = methods
        .iter()
        .enumerate()
        .map(|(i, m)| {
            line(
                base.iter()
                    .filter(|r| r.method == *m)
                    .map(|r| (r.lights as f64, r.evals_per_pixel))
                    .collect(),
                m.to_string(),
                plot::palette(i),
            )
        })
        .collect();
    let mut bound: Vec<(f64, f64)> = Vec::new();
    for r in &base {
        let point = (r.lights as f64, r.lower_bound_per_pixel);
        if !bound.iter().any(|p| p.0 == point.0) {
            bound.push(point);
        }
    }
    series.push(line(bound, "lower bound".into(), (0, 0, 0)));
    Chart {
        title: format!(
            "Light evaluations per pixel ({}, ES {})",
            scene.unwrap_or("-"),
            es.unwrap_or("-")
        ),
        x_label: "lights (log)".into(),
        y_label: "evaluations per pixel (log)".into(),
        x_log: true,
        y_log: true,
        series,
        front: None,
        y_floor: None,
    }
}

/// The tables: per scene and ES version, frame time and evaluations by method and light
/// count; then every row in full.
pub fn markdown(report: &Report) -> String {
    let rows = &report.rows;
    let mut s = String::from("# manylight bench\n\n");
    let _ = writeln!(
        s,
        "`{}` — {} rows in {:.0} s on {} logical CPUs, renderer `{}`, LP_NUM_THREADS {}.\n",
        report.command,
        rows.len(),
        report.seconds,
        report.cpus,
        rows.first().map_or("-", |r| r.renderer.as_str()),
        rows.first()
            .and_then(|r| r.lp_num_threads.as_deref())
            .unwrap_or("unset"),
    );
    s += "Frame time is the median wall time of the timed frames (CPU work and `glFinish`); \
          evaluations are light-model evaluations per covered pixel, with their ratio to the \
          lights that really reach each pixel; error is against plain forward over all lights \
          with the light model at highp on the same context (RMSE and max, 8-bit steps) and \
          against the light model in f64 at sampled pixels.\n\n";
    let defaults: Vec<&BenchRow> = rows.iter().filter(|r| r.knob == "default").collect();
    for scene in distinct(defaults.iter().map(|r| r.scene.as_str())) {
        for es in distinct(defaults.iter().map(|r| r.es.as_str())) {
            let these: Vec<&&BenchRow> = defaults
                .iter()
                .filter(|r| r.scene == scene && r.es == es)
                .collect();
            if these.is_empty() {
                continue;
            }
            let _ = writeln!(s, "## {scene}, ES {es}\n");
            s += "| method | lights | frame ms | assign ms | evals/px | × bound | RMSE | max | f64 max |\n\
                  |---|---|---|---|---|---|---|---|---|\n";
            for r in these {
                s += &table_row(r);
            }
            s += "\n";
        }
    }
    let knobs: Vec<&BenchRow> = rows.iter().filter(|r| r.knob != "default").collect();
    if !knobs.is_empty() {
        s += "## Knobs that trade error for time\n\n\
              Each knob changes one setting from the defaults; `footprint_px` rows are fixed \
              grids, to compare with the automatic grid of the default clustered rows (shown \
              again here as `auto`).\n\n\
              | scene | ES | method | lights | knob | grid px | cells | frame ms | assign ms | evals/px | × bound | RMSE | max |\n\
              |---|---|---|---|---|---|---|---|---|---|---|---|---|\n";
        let auto_rows = rows
            .iter()
            .filter(|r| r.knob == "default" && r.method == "clustered")
            .filter(|r| {
                knobs
                    .iter()
                    .any(|k| k.scene == r.scene && k.es == r.es && k.lights == r.lights)
            });
        for r in auto_rows.chain(knobs.iter().copied()) {
            let knob = if r.knob == "default" { "auto" } else { &r.knob };
            let _ = writeln!(
                s,
                "| {} | {} | {} | {} | {} | {} | {} | {:.1} | {:.2} | {:.1} | {} | {:.3} | {} |",
                r.scene,
                r.es,
                r.method,
                r.lights,
                knob,
                opt(r.grid_footprint_px, 0),
                r.grid_cells,
                r.frame_ms,
                r.assign_ms,
                r.evals_per_pixel,
                opt(r.evals_ratio, 2),
                r.rmse,
                r.max_abs_err
            );
        }
        s += "\n";
        let reasons = rows
            .iter()
            .filter(|r| r.knob == "default" && r.method == "clustered")
            .filter_map(|r| Some((r, r.grid_reason.as_deref()?)));
        s += "## Why the automatic grid is what it is\n\n";
        for (r, reason) in reasons {
            let _ = writeln!(
                s,
                "- {}, ES {}, {} lights: {reason}",
                r.scene, r.es, r.lights
            );
        }
        s += "\n";
    }
    s
}

/// A figure with `digits` decimals, or "—" when there is none.
fn opt(v: Option<f64>, digits: usize) -> String {
    v.map_or("—".into(), |v| format!("{v:.digits$}"))
}

fn table_row(r: &BenchRow) -> String {
    format!(
        "| {} | {} | {:.1} | {:.2} | {:.1} | {} | {:.3} | {} | {} |\n",
        r.method,
        r.lights,
        r.frame_ms,
        r.assign_ms,
        r.evals_per_pixel,
        opt(r.evals_ratio, 1),
        r.rmse,
        r.max_abs_err,
        opt(r.cpu_max_abs_err, 2),
    )
}

/// Distinct values in order of first appearance.
fn distinct<'a>(values: impl Iterator<Item = &'a str>) -> Vec<&'a str> {
    let mut out: Vec<&str> = Vec::new();
    for v in values {
        if !out.contains(&v) {
            out.push(v);
        }
    }
    out
}
