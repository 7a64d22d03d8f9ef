//! Tests of the report's charts, tables and file names.

use super::charts::ES2_MARKER;
use super::markdown::table_row;
use super::*;
use crate::plot::Chart;
use manylight::methods::METHODS;

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

/// A scene's file name is text in the Markdown, not syntax: `a|b.json` gave its table rows
/// one cell too many, and a backtick in the command line ended its code span.
#[test]
fn scene_names_and_the_command_line_are_shown_literally() {
    let named = "x|y*[z]";
    let mut r = report();
    r.command = "manylight bench --scenes `x|y*[z]`.json".into();
    for row in &mut r.rows {
        row.scene = named.into();
        row.grid_reason = Some("why".into());
    }
    r.pictures[0].scene = named.into();
    let spread = manylight::metrics::spread::Spread::of([1.0, 2.0]).unwrap();
    r.animated.push(crate::animated::AnimatedRow {
        scene: named.into(),
        method: "clustered".into(),
        es: "3.0".into(),
        lights: 64,
        width: 64,
        height: 36,
        frames: 2,
        fps: 30.0,
        frame_ms: spread,
        assign_ms: spread,
        upload_bytes: spread,
        p99_over_p50: 1.0,
        max_abs_err_vs_forward: Some(0),
    });
    let md = markdown(&r);
    // Every row of a table has its header's cells: `|` not escaped by a backslash.
    let cells = |line: &str| {
        line.split("\\|")
            .map(|p| p.matches('|').count())
            .sum::<usize>()
    };
    let mut header = None;
    for line in md.lines() {
        match (line.starts_with('|'), header) {
            (true, None) => header = Some(cells(line)),
            (true, Some(n)) => assert_eq!(cells(line), n, "{line}\n{md}"),
            (false, _) => header = None,
        }
    }
    assert!(md.contains("x\\|y\\*\\[z\\]"), "{md}");
    assert!(
        md.contains("`` manylight bench --scenes `x|y*[z]`.json ``"),
        "{md}"
    );
}
