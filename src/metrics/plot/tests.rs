//! Tests of the charts.

use super::*;

#[test]
fn pareto_front_keeps_only_undominated_points() {
    let pts = [
        (3.0, 1.0), // front
        (1.0, 5.0), // front
        (2.0, 2.0), // front
        (2.5, 2.0), // dominated by (2, 2): same y, larger x
        (4.0, 4.0), // dominated
        (1.0, 6.0), // dominated by (1, 5): same x, larger y
        (2.0, 2.0), // duplicate of a front point: kept
        (f64::NAN, 0.0),
    ];
    assert_eq!(pareto_front(&pts), vec![1, 2, 6, 0]);
    assert_eq!(pareto_front(&[(7.0, 7.0)]), vec![0]);
    assert!(pareto_front(&[]).is_empty());
}

fn chart(series: Vec<Series>) -> Chart {
    Chart {
        title: "Error vs time".into(),
        x_label: "time (ms)".into(),
        y_label: "max error".into(),
        series,
        ..Default::default()
    }
}

fn series(i: usize, points: Vec<(f64, f64)>, line: bool) -> Series {
    Series {
        label: format!("method {i}"),
        points,
        color: palette(i),
        line,
    }
}

#[test]
fn renders_the_requested_size_in_awkward_cases() {
    let ordinary = chart(vec![
        series(0, vec![(1.0, 3.0), (2.0, 1.5), (4.0, 1.0)], true),
        series(1, vec![(1.5, 2.0), (3.0, 0.5)], false),
    ]);
    let mut log_zeros = chart(vec![
        series(
            0,
            vec![(0.0, 0.0), (1.0, 1e-3), (100.0, 0.2), (-1.0, -5.0)],
            true,
        ),
        series(1, vec![(0.5, 0.0), (1e4, 1e-7)], false),
    ]);
    log_zeros.x_log = true;
    log_zeros.y_log = true;
    log_zeros.front = Some(vec![(0.0, 0.0), (1.0, 1e-3)]);
    let mut single = chart(vec![series(0, vec![(5.0, 5.0)], true)]);
    single.front = Some(vec![(5.0, 5.0)]);
    let mut empty_series = chart(vec![series(0, vec![], true)]);
    empty_series.y_log = true;
    let none = chart(vec![]);
    for (c, (w, h)) in [
        (ordinary, (800, 500)),
        (log_zeros, (640, 400)),
        (single, (300, 200)),
        (empty_series, (400, 300)),
        (none, (800, 500)),
        (Chart::default(), (200, 120)),
    ] {
        let img = render(&c, w, h).unwrap();
        assert_eq!(img.dimensions(), (w, h));
    }
    assert!(render(&chart(vec![]), 20, 20).is_err());
}

#[test]
fn log_axis_over_decades_has_decade_ticks_and_a_zero_floor() {
    let ya = Axis::new([0.0, 1e-6, 0.5].into_iter(), true, None);
    assert_eq!(ya.floor, Some(1e-7));
    let (major, minor) = ya.ticks(20, 400, 16);
    let labels: Vec<&str> = major.iter().map(|t| t.1.as_str()).collect();
    // The 5% margin above 0.5 reaches 10^0; the floor decade 1e-7 is relabelled "0".
    assert_eq!(
        labels,
        ["1e-6", "1e-5", "1e-4", "0.001", "0.01", "0.1", "1", "0"]
    );
    assert!(!minor.is_empty());
    // A chart's own floor wins; without zeros there is no floor at all.
    let own = Axis::new([0.0, 1.0].into_iter(), true, Some(0.01));
    assert_eq!(own.floor, Some(0.01));
    assert_eq!(
        Axis::new([1.0, 2.0].into_iter(), true, Some(0.01)).floor,
        None
    );
}

fn dark_pixels(img: &RgbImage, rows: std::ops::Range<u32>) -> usize {
    rows.flat_map(|y| (0..img.width()).map(move |x| (x, y)))
        .filter(|&(x, y)| img.get_pixel(x, y)[0] < 100)
        .count()
}

#[test]
fn title_and_axis_text_are_drawn() {
    let data = vec![series(0, vec![(1.0, 1.0), (2.0, 2.0)], true)];
    let mut short = chart(data.clone());
    short.title = "A".into();
    let mut long = chart(data);
    long.title = "Quite a different title".into();
    let (a, b) = (
        render(&short, 640, 400).unwrap(),
        render(&long, 640, 400).unwrap(),
    );
    // The title band is the top 6 + 24 rows; more text means more dark pixels there.
    assert!(dark_pixels(&a, 6..30) > 0, "no title glyphs");
    assert!(dark_pixels(&b, 6..30) > 3 * dark_pixels(&a, 6..30));
    // Axis descriptions: same layout, longer text, more dark pixels in the bottom rows
    // (x) and the left columns (y).
    let mut longer = short.clone();
    longer.x_label = "a much longer x axis description".into();
    longer.y_label = "longer y description".into();
    let c = render(&longer, 640, 400).unwrap();
    let band = 400 - 22..400 - 6;
    assert!(dark_pixels(&a, band.clone()) > 0, "no x axis description");
    assert!(dark_pixels(&c, band.clone()) > 2 * dark_pixels(&a, band));
    let left_cols = |img: &RgbImage| {
        let rows = 40..400 - 60;
        rows.flat_map(|y| (6..22).map(move |x| (x, y)))
            .filter(|&(x, y)| img.get_pixel(x, y)[0] < 100)
            .count()
    };
    assert!(left_cols(&a) > 0, "no y axis description");
    assert!(left_cols(&c) > 2 * left_cols(&a));
}

#[test]
#[ignore = "writes /tmp/manylight_plot_*.png for a person to look at"]
fn write_example_charts() {
    let mut c = chart(
        (0..4)
            .map(|i| {
                let pts = (0..8)
                    .map(|k| {
                        let t = 0.5 * (k + 1) as f64 * (i + 1) as f64;
                        let e = if k == 7 && i == 2 {
                            0.0
                        } else {
                            0.3 / t.powi(3)
                        };
                        (t, e)
                    })
                    .collect();
                series(i, pts, i % 2 == 0)
            })
            .collect(),
    );
    c.title = "Max error vs frame time, 1024 lights".into();
    c.x_log = true;
    c.y_log = true;
    let all: Vec<(f64, f64)> = c.series.iter().flat_map(|s| s.points.clone()).collect();
    c.front = Some(pareto_front(&all).into_iter().map(|i| all[i]).collect());
    let img = render(&c, 900, 560).unwrap();
    img.save("/tmp/manylight_plot_loglog.png").unwrap();
    let mut zeros = chart(vec![
        series(
            0,
            vec![(0.0, 0.0), (1.0, 1e-3), (100.0, 0.2), (-1.0, -5.0)],
            true,
        ),
        series(1, vec![(0.5, 0.0), (1e4, 1e-7)], false),
    ]);
    (zeros.x_log, zeros.y_log) = (true, true);
    zeros.front = Some(vec![(0.0, 0.0), (1.0, 1e-3)]);
    let img = render(&zeros, 640, 400).unwrap();
    img.save("/tmp/manylight_plot_zeros.png").unwrap();
    let single = chart(vec![series(0, vec![(5.0, 5.0)], true)]);
    let img = render(&single, 480, 300).unwrap();
    img.save("/tmp/manylight_plot_single.png").unwrap();
    let mut lin = chart(vec![
        series(
            0,
            (0..20)
                .map(|k| (k as f64 * 50.0, (k as f64).sqrt()))
                .collect(),
            true,
        ),
        series(
            1,
            (0..20).map(|k| (k as f64 * 50.0, 0.2 * k as f64)).collect(),
            false,
        ),
    ]);
    lin.x_label = "lights".into();
    render(&lin, 640, 400)
        .unwrap()
        .save("/tmp/manylight_plot_linear.png")
        .unwrap();
    render(&lin, 400, 260)
        .unwrap()
        .save("/tmp/manylight_plot_small.png")
        .unwrap();
}
