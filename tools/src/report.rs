//! The error-against-run-time report of `manylight bench`: one row per configuration (scene,
//! method, ES version, light count, knob), the tables a person reads, and two charts per
//! scene.
//!
//! Every row carries the machine facts its figures depend on (renderer string,
//! `LP_NUM_THREADS`), so a figure is never quoted without them.
//!
//! Each method has one colour and marker in every chart, from its place in
//! [`METHODS`] (see [`method_style`]).

use std::fmt::Write as _;
use std::path::Path;

use serde::Serialize;

use crate::output;
use crate::plot::{self, Chart, Marker, Series};
use manylight::methods::{auto, METHODS};

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

/// `name` (a scene or method) as it appears in file names: ASCII letters, digits, `-`, `_`
/// and `.` kept, anything else (spaces, slashes, non-ASCII) becomes `_`.
pub fn file_tag(name: &str) -> String {
    let keep = |c: char| c.is_ascii_alphanumeric() || matches!(c, '-' | '_' | '.');
    let tag: String = name
        .chars()
        .map(|c| if keep(c) { c } else { '_' })
        .collect();
    if tag.is_empty() {
        "scene".to_string()
    } else {
        tag
    }
}

/// "3.0" → "es3".
fn es_tag(es: &str) -> String {
    format!("es{}", es.split('.').next().unwrap_or(es))
}

/// A chart of `scene`: `error_vs_time-<scene>.png`, say.
pub fn chart_file(chart: &str, scene: &str) -> String {
    format!("{chart}-{}.png", file_tag(scene))
}

/// The light-evaluation heatmap of `what` (a method or "lower-bound") on `scene`, ES `es`.
pub fn heatmap_file(scene: &str, es: &str, what: &str) -> String {
    format!(
        "heatmap-{}-{}-{}.png",
        file_tag(scene),
        es_tag(es),
        file_tag(what)
    )
}

/// The difference of `method` from the reference on `scene`, ES `es`.
pub fn diff_file(scene: &str, es: &str, method: &str) -> String {
    format!(
        "diff-{}-{}-{}.png",
        file_tag(scene),
        es_tag(es),
        file_tag(method)
    )
}

/// The reference image of `scene`, ES `es`.
pub fn reference_file(scene: &str, es: &str) -> String {
    format!("reference-{}-{}.png", file_tag(scene), es_tag(es))
}

/// The two charts of every scene, by base name.
const CHARTS: [&str; 2] = ["error_vs_time", "evals_vs_lights"];

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

/// Colour and marker of `method` in every chart: [`plot::style`] of its place in
/// [`METHODS`] (a name not in the table gets the style after the table's), so a method looks
/// the same whichever methods a chart shows and in whatever order.
pub fn method_style(method: &str) -> ((u8, u8, u8), Marker) {
    let i = METHODS.iter().position(|m| m.name == method);
    plot::style(i.unwrap_or(METHODS.len()))
}

/// The marker of every ES 2.0 series on the error chart (the method keeps its colour).
const ES2_MARKER: Marker = Marker::Plus;

/// The series of `method`. `auto` usually picks clustered, so its points lie on clustered's:
/// it is drawn hollow (a larger outline around clustered's filled marker, its line dashed)
/// so that both stay visible.
fn method_series(method: &str, points: Vec<(f64, f64)>, line: bool) -> Series {
    let (color, marker) = method_style(method);
    Series {
        label: method.to_string(),
        points,
        color,
        marker,
        line,
        hollow: method == auto::DESC.name,
        point_labels: Vec::new(),
    }
}

/// Error against frame time on `scene`'s knob workload (`lights` lights, every ES version):
/// one point per configuration (each method, each knob), with the Pareto front (no other
/// configuration both faster and more accurate) drawn through those of one ES version, the
/// highest: each version's error is against its own context's reference, so its points do
/// not trade against another's. Other workloads differ in what they render likewise; they
/// are in the tables.
pub fn error_vs_time(rows: &[BenchRow], scene: &str, lights: usize) -> Chart {
    let rows: Vec<&BenchRow> = rows
        .iter()
        .filter(|r| r.scene == scene && r.lights == lights)
        .collect();
    let methods = distinct(rows.iter().map(|r| r.method.as_str()));
    let versions = distinct(rows.iter().map(|r| r.es.as_str()));
    let mut series = Vec::new();
    for m in &methods {
        for es in &versions {
            let these: Vec<&&BenchRow> = rows
                .iter()
                .filter(|r| r.method == *m && r.es == *es)
                .collect();
            if these.is_empty() {
                continue;
            }
            let mut s = method_series(
                m,
                these.iter().map(|r| (r.frame_ms, r.rmse)).collect(),
                false,
            );
            // ES 2.0 in the method's colour with its own marker: the versions differ in
            // what they cost and round.
            if versions.len() > 1 {
                s.label = format!("{m}, ES {es}");
                if *es == "2.0" {
                    s.marker = ES2_MARKER;
                }
            }
            s.point_labels = these
                .iter()
                .map(|r| {
                    if r.knob == "default" {
                        String::new()
                    } else {
                        r.knob.clone()
                    }
                })
                .collect();
            series.push(s);
        }
    }
    let front_es = versions.iter().max().copied().unwrap_or_default();
    let all: Vec<(f64, f64)> = (rows.iter())
        .filter(|r| r.es == front_es)
        .map(|r| (r.frame_ms, r.rmse))
        .collect();
    let front = plot::pareto_front(&all)
        .into_iter()
        .map(|i| all[i])
        .collect();
    let front_of = if versions.len() > 1 {
        format!(", front of ES {front_es}")
    } else {
        String::new()
    };
    Chart {
        title: format!("Error against frame time: {scene}, {lights} lights{front_of}"),
        x_label: "frame time (ms, log)".into(),
        y_label: "RMSE vs reference (of 255, log)".into(),
        x_log: true,
        y_log: true,
        series,
        // Left out of the chart when it has fewer than two points (see `Chart::front`).
        front: Some(front),
        y_floor: None,
    }
}

/// Light evaluations per pixel against the light count on `scene`, one line per method at
/// ES 3.0 where the run has it, with the lower bound (black).
pub fn evals_vs_lights(rows: &[BenchRow], scene: &str) -> Chart {
    let base: Vec<&BenchRow> = rows
        .iter()
        .filter(|r| r.scene == scene && r.knob == "default" && r.lights > 0)
        .collect();
    let es = base
        .iter()
        .map(|r| r.es.as_str())
        .find(|&e| e == "3.0")
        .or_else(|| base.first().map(|r| r.es.as_str()));
    let base: Vec<&BenchRow> = base
        .into_iter()
        .filter(|r| Some(r.es.as_str()) == es)
        .collect();
    let methods = distinct(base.iter().map(|r| r.method.as_str()));
    let mut series: Vec<Series> = methods
        .iter()
        .map(|m| {
            let these = base.iter().filter(|r| r.method == *m);
            let points = these.map(|r| (r.lights as f64, r.evals_per_pixel));
            method_series(m, points.collect(), true)
        })
        .collect();
    let mut bound: Vec<(f64, f64)> = Vec::new();
    for r in &base {
        let point = (r.lights as f64, r.lower_bound_per_pixel);
        if !bound.iter().any(|p| p.0 == point.0) {
            bound.push(point);
        }
    }
    series.push(Series {
        label: "lower bound".into(),
        points: bound,
        color: (0, 0, 0),
        marker: Marker::Circle,
        line: true,
        hollow: false,
        point_labels: Vec::new(),
    });
    Chart {
        title: match es {
            Some(es) => format!("Light evaluations per pixel ({scene}, ES {es})"),
            None => format!("Light evaluations per pixel ({scene}): no run with lights"),
        },
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
    s += COLUMNS;
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
            s += "| method | lights | frame ms | assign ms | draws | evals/px | × bound | RMSE | max | f64 max |\n\
                  |---|---|---|---|---|---|---|---|---|---|\n";
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
              again here as `auto`, whose assignment keeps within 5 % of its predicted frame); \
              `assign_budget=1` is the automatic grid without that budget.\n\n\
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
                r.grid_footprint_px.map_or("—".into(), |px| px.to_string()),
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
    s += &crate::animated::markdown(&report.animated);
    s += "## Charts and pictures\n\n\
          Each method has the same colour and marker in every chart; `auto`, which usually \
          picks clustered, is a larger hollow marker (and a dashed line) around clustered's. \
          The error chart of a scene has every configuration run at its knobs' light count; \
          the Pareto front joins those no other is both faster and more accurate than.\n\n";
    if !report.pictures.is_empty() {
        s += "Heatmaps of one scene and ES version share a logarithmic colour scale up to the \
              largest count of any of them (forward's: every light at every pixel), so \
              forward's does not clip and the culling methods' stay readable. Difference \
              images show the largest RGB difference from the reference per pixel, amplified \
              as their caption says; black is identical. The lower bound is a count, not an \
              image: it has no difference image (—).\n\n";
    }
    for scene in distinct(rows.iter().map(|r| r.scene.as_str())) {
        s += &pictures_section(report, scene);
    }
    s
}

/// What the table columns hold, and what a "—" in one means.
const COLUMNS: &str = "Columns: *frame ms* and *assign ms* (CPU light assignment) are medians; \
    *draws* is the frame's draw calls, each of which costs a GPU driver CPU time that a software \
    rasterizer's frame time hides; *evals/px* is light evaluations per covered pixel and \
    *× bound* its ratio to the lower bound (1 is perfect culling); *RMSE* and *max* are against the reference image and \
    *f64 max* the largest error against the f64 light model at sampled pixels, all in 8-bit \
    steps; *grid px* and *cells* (knob table) are the cell grid the frame used.\n\n\
    A \"—\" means the figure does not exist for that row, not that it is zero: in *× bound*, \
    no light reaches any covered pixel (a lower bound of 0, as at 0 lights), so there is no \
    ratio; in *f64 max*, no sampled pixel could be checked against the f64 reference (every \
    sample fell on a triangle edge, a textured or transparent surface or the background, or \
    `--cpu-samples 0`); in *grid px*, the frame used no cell grid.\n\n";

/// The charts of `scene` and, per ES version, its reference image, heatmaps and difference
/// images.
fn pictures_section(report: &Report, scene: &str) -> String {
    let mut s = String::new();
    let _ = writeln!(
        s,
        "### {scene}\n\n\
         ![Error against frame time, {scene}]({})\n\n\
         ![Light evaluations per pixel, {scene}]({})\n",
        chart_file(CHARTS[0], scene),
        chart_file(CHARTS[1], scene),
    );
    for p in report.pictures.iter().filter(|p| p.scene == scene) {
        let _ = writeln!(
            s,
            "{scene}, ES {}, {} lights. Reference (plain forward over all lights, light model \
             at highp): [{}]({})\n\n\
             | method | light evaluations per pixel | difference from the reference |\n\
             |---|---|---|",
            p.es, p.lights, p.reference, p.reference
        );
        for (what, heatmap) in &p.heatmaps {
            let diff = p.diffs.iter().find(|d| d.0 == *what);
            let diff = diff.map_or("—".to_string(), |d| format!("[{}]({})", d.1, d.1));
            let what = what.replace('-', " ");
            let _ = writeln!(s, "| {what} | [{heatmap}]({heatmap}) | {diff} |");
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
        "| {} | {} | {:.1} | {:.2} | {} | {:.1} | {} | {:.3} | {} | {} |\n",
        r.method,
        r.lights,
        r.frame_ms,
        r.assign_ms,
        r.draw_calls,
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

#[cfg(test)]
mod tests {
    use super::*;

    fn row(scene: &str, method: &str, lights: usize, knob: &str, ms: f64, rmse: f64) -> BenchRow {
        BenchRow {
            scene: scene.into(),
            method: method.into(),
            es: "3.0".into(),
            lights,
            width: 64,
            height: 36,
            knob: knob.into(),
            frame_ms: ms,
            timed_frames: 1,
            auto_choice: None,
            gpu_ms: None,
            assign_ms: 0.0,
            upload_bytes: 0,
            draw_calls: 0,
            light_evals: 0,
            evals_per_pixel: lights as f64 / 4.0 + 1.0,
            max_evals: 0,
            lower_bound_evals: 0,
            lower_bound_per_pixel: 1.0,
            evals_ratio: None,
            max_abs_err: 0,
            rmse,
            psnr_db: None,
            over_1: 0.0,
            over_2: 0.0,
            cpu_max_abs_err: None,
            cpu_samples: 0,
            overflowed_lights: 0,
            grid_footprint_px: None,
            grid_cells: 0,
            grid_reason: None,
            renderer: "llvmpipe".into(),
            lp_num_threads: None,
        }
    }

    /// Two scenes: "a" with every method, "b" with a few in another order.
    fn rows() -> Vec<BenchRow> {
        let mut rows = Vec::new();
        for lights in [8, 64] {
            for (i, m) in ["forward", "tiled", "clustered", "deferred", "auto"]
                .iter()
                .enumerate()
            {
                rows.push(row(
                    "a",
                    m,
                    lights,
                    "default",
                    10.0 + i as f64,
                    0.1 * i as f64,
                ));
            }
            for (i, m) in ["auto", "clustered"].iter().enumerate() {
                rows.push(row("b", m, lights, "default", 5.0 + i as f64, 0.2));
            }
        }
        rows.push(row("a", "clustered", 64, "cutoff=0.01", 9.0, 0.5));
        rows.push(row("b", "clustered", 64, "footprint_px=16", 4.0, 0.3));
        rows
    }

    fn report() -> Report {
        Report {
            command: "manylight bench".into(),
            cpus: 1,
            seconds: 1.0,
            rows: rows(),
            animated: Vec::new(),
            pictures: vec![Pictures {
                scene: "a".into(),
                es: "3.0".into(),
                lights: 64,
                reference: reference_file("a", "3.0"),
                heatmaps: vec![
                    (
                        "lower-bound".into(),
                        heatmap_file("a", "3.0", "lower-bound"),
                    ),
                    ("clustered".into(), heatmap_file("a", "3.0", "clustered")),
                ],
                diffs: vec![("clustered".into(), diff_file("a", "3.0", "clustered"))],
            }],
        }
    }

    #[test]
    fn the_error_chart_tells_es_versions_and_knobs_apart() {
        let mut rows = rows();
        let mut es2 = row("a", "clustered", 64, "default", 12.0, 0.4);
        es2.es = "2.0".into();
        rows.push(es2);
        let chart = error_vs_time(&rows, "a", 64);
        let find = |label: &str| chart.series.iter().find(|s| s.label == label).unwrap();
        let (es2, es3) = (find("clustered, ES 2.0"), find("clustered, ES 3.0"));
        assert_eq!(es2.color, es3.color);
        assert_eq!((es2.marker, es3.marker), (ES2_MARKER, plot::style(2).1));
        // Each knob point says which knob; default points carry no text.
        let labelled: Vec<&str> = es3
            .point_labels
            .iter()
            .map(String::as_str)
            .filter(|l| !l.is_empty())
            .collect();
        assert_eq!(labelled, ["cutoff=0.01"]);
        assert_eq!(es3.point_labels.len(), es3.points.len());
        assert!(chart.y_label.contains("of 255"), "{}", chart.y_label);
    }

    /// Each version's error is against its own reference: an ES 2.0 point faster and closer
    /// than every ES 3.0 one does not make the front (it alone made it).
    #[test]
    fn the_error_charts_front_is_one_es_versions() {
        let mut rows = rows();
        let mut es2 = row("a", "clustered", 64, "default", 0.1, 0.001);
        es2.es = "2.0".into();
        rows.push(es2);
        let chart = error_vs_time(&rows, "a", 64);
        let front = chart.front.clone().unwrap();
        assert!(front.len() >= 2, "{front:?}");
        assert!(!front.contains(&(0.1, 0.001)), "{front:?}");
        assert!(chart.title.ends_with("front of ES 3.0"), "{}", chart.title);
    }

    /// A run at 0 lights alone has no evaluations to chart: the title says so, where it read
    /// "ES -" over empty axes.
    #[test]
    fn an_evals_chart_without_lights_says_so() {
        let rows = vec![
            row("a", "forward", 0, "default", 1.0, 0.0),
            row("a", "clustered", 0, "default", 1.2, 0.0),
        ];
        let chart = evals_vs_lights(&rows, "a");
        assert!(
            chart.title.ends_with("no run with lights"),
            "{}",
            chart.title
        );
        assert!(chart.series.iter().all(|s| s.points.is_empty()));
    }

    #[test]
    fn a_method_looks_the_same_in_every_chart() {
        let rows = rows();
        let charts = [
            error_vs_time(&rows, "a", 64),
            evals_vs_lights(&rows, "a"),
            error_vs_time(&rows, "b", 64),
            evals_vs_lights(&rows, "b"),
        ];
        for chart in &charts {
            for s in chart.series.iter().filter(|s| s.label != "lower bound") {
                // Its place in METHODS, not in the chart.
                let i = METHODS.iter().position(|m| m.name == s.label).unwrap();
                assert_eq!((s.color, s.marker), plot::style(i), "{}", s.label);
                assert_eq!(s.hollow, s.label == "auto", "{}", s.label);
            }
        }
        // "b" lists auto first, yet clustered keeps its look.
        assert_eq!(charts[2].series[0].label, "auto");
        let clustered = |c: &Chart| {
            let s = c.series.iter().find(|s| s.label == "clustered").unwrap();
            (s.color, s.marker)
        };
        assert!(charts.iter().all(|c| clustered(c) == clustered(&charts[0])));
        let (forward, tiled) = (method_style("forward"), method_style("tiled"));
        assert!(forward.0 != tiled.0 && forward.1 != tiled.1);
        let bound = charts[1].series.last().unwrap();
        assert_eq!(
            (bound.label.as_str(), bound.color),
            ("lower bound", (0, 0, 0))
        );
    }

    #[test]
    fn each_scene_gets_its_own_charts_from_its_own_rows() {
        let rows = rows();
        let b = error_vs_time(&rows, "b", 64);
        let points: usize = b.series.iter().map(|s| s.points.len()).sum();
        assert_eq!(points, 3, "b's two methods and its knob row at 64 lights");
        assert!(b.title.contains("b, 64 lights"), "{}", b.title);
        let evals = evals_vs_lights(&rows, "b");
        let labels: Vec<&str> = evals.series.iter().map(|s| s.label.as_str()).collect();
        assert_eq!(labels, ["auto", "clustered", "lower bound"]);
        // The picture workload, else the knobs', else the largest light count.
        let mut r = report();
        assert_eq!(workload_lights(&r, "a"), 64);
        assert_eq!(workload_lights(&r, "b"), 64);
        r.rows.retain(|r| r.knob == "default");
        r.pictures.clear();
        assert_eq!(workload_lights(&r, "b"), 64);
        r.rows.retain(|r| r.lights == 8);
        assert_eq!(workload_lights(&r, "b"), 8);
    }

    #[test]
    fn a_rows_draw_calls_are_in_its_table_row() {
        let mut r = row("a", "deferred", 64, "default", 2.0, 0.5);
        r.draw_calls = 9;
        assert!(table_row(&r).starts_with("| deferred | 64 | 2.0 | 0.00 | 9 | 17.0 |"));
    }

    #[test]
    fn the_knob_table_writes_half_pixel_grids_unrounded() {
        let mut r = report();
        for (row, px) in r
            .rows
            .iter_mut()
            .filter(|r| r.knob != "default")
            .zip([13.5, 16.0])
        {
            row.grid_footprint_px = Some(px);
        }
        let md = markdown(&r);
        assert!(md.contains("| cutoff=0.01 | 13.5 |"), "{md}");
        assert!(md.contains("| footprint_px=16 | 16 |"), "{md}");
    }

    #[test]
    fn file_names_carry_the_scene_sanitised() {
        assert_eq!(file_tag("courtyard"), "courtyard");
        assert_eq!(file_tag("my scene/ü"), "my_scene__");
        assert_eq!(file_tag(""), "scene");
        assert_eq!(chart_file("error_vs_time", "a b"), "error_vs_time-a_b.png");
        assert_eq!(
            heatmap_file("x", "3.0", "lower-bound"),
            "heatmap-x-es3-lower-bound.png"
        );
        assert_eq!(diff_file("x", "2.0", "tiled"), "diff-x-es2-tiled.png");
        assert_eq!(reference_file("x", "3.0"), "reference-x-es3.png");
    }

    #[test]
    fn markdown_lists_every_picture_and_explains_the_dashes() {
        let md = markdown(&report());
        for file in [
            "error_vs_time-a.png",
            "evals_vs_lights-a.png",
            "error_vs_time-b.png",
            "evals_vs_lights-b.png",
            "reference-a-es3.png",
            "heatmap-a-es3-lower-bound.png",
            "heatmap-a-es3-clustered.png",
            "diff-a-es3-clustered.png",
        ] {
            assert!(
                md.contains(&format!("]({file})")),
                "{file} not linked:\n{md}"
            );
        }
        assert!(md.contains("### a\n") && md.contains("### b\n"), "{md}");
        assert!(
            md.contains("| lower bound | [heatmap-a-es3-lower-bound.png]"),
            "{md}"
        );
        // The rows have no ratio and no f64 figure: their "—" is explained.
        assert!(md.contains("| — | 0.000 | 0 | — |"), "{md}");
        assert!(md.contains("A \"—\" means"), "{md}");
        for column in ["*× bound*", "*f64 max*", "*grid px*"] {
            let why = md.split("A \"—\" means").nth(1).unwrap();
            assert!(why.contains(column), "{column} not explained");
        }
    }
}
