//! The report's two charts per scene: error against frame time, evaluations against lights.

use crate::plot::{self, Chart, Marker, Series};
use manylight::methods::{auto, METHODS};

use super::{distinct, BenchRow};

/// Colour and marker of `method` in every chart: [`plot::style`] of its place in
/// [`METHODS`] (a name not in the table gets the style after the table's), so a method looks
/// the same whichever methods a chart shows and in whatever order.
pub fn method_style(method: &str) -> ((u8, u8, u8), Marker) {
    let i = METHODS.iter().position(|m| m.name == method);
    plot::style(i.unwrap_or(METHODS.len()))
}

/// The marker of every ES 2.0 series on the error chart (the method keeps its colour).
pub(super) const ES2_MARKER: Marker = Marker::Plus;

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
