//! The report's tables (`report.md`).

use std::fmt::Write as _;

use super::files::chart_file;
use super::{distinct, BenchRow, Report, CHARTS};

/// The tables: per scene and ES version, frame time and evaluations by method and light
/// count; then every row in full.
pub fn markdown(report: &Report) -> String {
    let rows = &report.rows;
    let mut s = String::from("# manylight bench\n\n");
    let _ = writeln!(
        s,
        "{} — {} rows in {:.0} s on {} logical CPUs, renderer `{}`, LP_NUM_THREADS {}.\n",
        md_code(&report.command),
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
            let _ = writeln!(s, "## {}, ES {es}\n", md_text(scene));
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
                md_text(&r.scene),
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
                md_text(&r.scene),
                r.es,
                r.lights
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
    let shown = md_text(scene);
    let _ = writeln!(
        s,
        "### {shown}\n\n\
         ![Error against frame time, {shown}]({})\n\n\
         ![Light evaluations per pixel, {shown}]({})\n",
        chart_file(CHARTS[0], scene),
        chart_file(CHARTS[1], scene),
    );
    for p in report.pictures.iter().filter(|p| p.scene == scene) {
        let _ = writeln!(
            s,
            "{shown}, ES {}, {} lights. Reference (plain forward over all lights, light model \
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

/// `text` (a scene's file name) as Markdown shows it literally in a heading, table cell or
/// image's alt text: control characters escaped, and the characters Markdown reads as
/// syntax (a `|` ended a table's cell) escaped with a backslash.
pub(crate) fn md_text(text: &str) -> String {
    let mut out = String::new();
    for c in manylight::scene::shown::text(text).chars() {
        if "\\`*_[]<>|~#!".contains(c) {
            out.push('\\');
        }
        out.push(c);
    }
    out
}

/// `text` (a command line) as a Markdown code span: control characters escaped, fenced by
/// more backticks than any run of them inside it.
fn md_code(text: &str) -> String {
    let text = manylight::scene::shown::text(text);
    let mut longest = 0;
    for run in text.split(|c| c != '`') {
        longest = longest.max(run.len());
    }
    let fence = "`".repeat(longest + 1);
    if longest == 0 {
        format!("{fence}{text}{fence}")
    } else {
        format!("{fence} {text} {fence}")
    }
}

/// A figure with `digits` decimals, or "—" when there is none.
fn opt(v: Option<f64>, digits: usize) -> String {
    v.map_or("—".into(), |v| format!("{v:.digits$}"))
}

pub(super) fn table_row(r: &BenchRow) -> String {
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
