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
    let (color, marker) = style(i);
    Series {
        label: format!("method {i}"),
        points,
        color,
        marker,
        line,
        hollow: false,
        point_labels: Vec::new(),
    }
}

/// The faces to test: the bitmap font always, the system font where there is one.
fn faces() -> Vec<Face> {
    let mut f = vec![Face::Bitmap];
    if Face::system() == Face::TrueType {
        f.push(Face::TrueType);
    }
    f
}

fn count_color(img: &RgbImage, c: (u8, u8, u8)) -> usize {
    img.pixels().filter(|p| p.0 == [c.0, c.1, c.2]).count()
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
    let cases = [
        (ordinary, (800, 500)),
        (log_zeros, (640, 400)),
        (single, (300, 200)),
        (empty_series, (400, 300)),
        (none, (800, 500)),
        (Chart::default(), (200, 120)),
    ];
    for face in faces() {
        for (c, (w, h)) in &cases {
            let img = render_with(c, *w, *h, face).unwrap();
            assert_eq!(img.dimensions(), (*w, *h));
        }
        assert!(render_with(&chart(vec![]), 20, 20, face).is_err());
    }
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
    // Zeros alone: nothing is drawn below the "0" (a bench whose every error was 0 read
    // `2e-6`, `0`, `5e-7` down its axis).
    let zeros = Axis::new([0.0, 0.0].into_iter(), true, None);
    let f = zeros.floor.unwrap().log10();
    let (major, minor) = zeros.ticks(20, 400, 16);
    assert!(major.iter().any(|t| t.1 == "0"), "{major:?}");
    assert!(major.iter().all(|t| t.0 >= f), "{major:?}");
    assert!(minor.iter().all(|&t| t > f), "{minor:?}");
}

fn dark_pixels(img: &RgbImage, rows: std::ops::Range<u32>) -> usize {
    rows.flat_map(|y| (0..img.width()).map(move |x| (x, y)))
        .filter(|&(x, y)| img.get_pixel(x, y)[0] < 100)
        .count()
}

#[test]
fn title_and_axis_text_are_drawn() {
    for face in faces() {
        title_and_axis_text_are_drawn_in(face);
    }
}

fn title_and_axis_text_are_drawn_in(face: Face) {
    let render = |c: &Chart| render_with(c, 640, 400, face).unwrap();
    let data = vec![series(0, vec![(1.0, 1.0), (2.0, 2.0)], true)];
    let mut short = chart(data.clone());
    short.title = "A".into();
    let mut long = chart(data);
    long.title = "Quite a different title".into();
    let (a, b) = (render(&short), render(&long));
    // The title band is the top PAD + 3 lines at scale 3; more text, more dark pixels there.
    let title = PAD..PAD + face.line(3);
    assert!(dark_pixels(&a, title.clone()) > 0, "no title glyphs");
    assert!(dark_pixels(&b, title.clone()) > 3 * dark_pixels(&a, title));
    // Axis descriptions: same layout, longer text, more dark pixels in the bottom rows
    // (x) and the left columns (y).
    let mut longer = short.clone();
    longer.x_label = "a much longer x axis description".into();
    longer.y_label = "longer y description".into();
    let c = render(&longer);
    let band = 400 - PAD - face.line(2)..400 - PAD;
    assert!(dark_pixels(&a, band.clone()) > 0, "no x axis description");
    assert!(dark_pixels(&c, band.clone()) > 2 * dark_pixels(&a, band));
    let left_cols = |img: &RgbImage| {
        let rows = 40..400 - 60;
        let cols = PAD..PAD + face.line(2);
        rows.flat_map(|y| cols.clone().map(move |x| (x, y)))
            .filter(|&(x, y)| img.get_pixel(x, y)[0] < 100)
            .count()
    };
    assert!(left_cols(&a) > 0, "no y axis description");
    assert!(left_cols(&c) > 2 * left_cols(&a));
}

#[test]
fn truetype_text_is_used_when_the_system_has_a_font() {
    // Where DejaVu Sans (or another listed font) is installed, the chart text is anti-aliased:
    // grey levels between the text colour and white that the bitmap font never draws.
    if Face::system() != Face::TrueType {
        eprintln!("no system font: the bitmap font is used (tested above)");
        return;
    }
    let mut c = chart(vec![series(0, vec![(1.0, 1.0), (2.0, 2.0)], true)]);
    c.title = "Antialiased title".into();
    let grey_levels = |face| {
        let img = render_with(&c, 640, 400, face).unwrap();
        let mut levels: Vec<u8> = (PAD..PAD + face.line(3))
            .flat_map(|y| (0..640).map(move |x| (x, y)))
            .map(|(x, y)| img.get_pixel(x, y))
            .filter(|p| p[0] == p[1] && p[1] == p[2])
            .map(|p| p[0])
            .collect();
        levels.sort_unstable();
        levels.dedup();
        levels.len()
    };
    assert!(grey_levels(Face::Bitmap) <= 3);
    assert!(grey_levels(Face::TrueType) > 10);
}

#[test]
fn a_front_of_fewer_than_two_points_is_neither_drawn_nor_listed() {
    let front_entries = |c: &Chart| {
        let legend = Legend::new(c, 2, Face::Bitmap);
        legend.entries.iter().filter(|e| e.marker.is_none()).count()
    };
    let front_pixels = |c: &Chart| {
        let img = render_with(c, 640, 400, Face::Bitmap).unwrap();
        count_color(&img, (FRONT_COLOR.0, FRONT_COLOR.1, FRONT_COLOR.2))
    };
    let mut c = chart(vec![series(
        0,
        vec![(1.0, 1.0), (2.0, 3.0), (3.0, 2.0)],
        false,
    )]);
    for none in [vec![], vec![(1.0, 1.0)], vec![(1.0, 1.0), (1.0, 1.0)]] {
        c.front = Some(none);
        assert_eq!(front_entries(&c), 0, "{:?}", c.front);
        assert_eq!(front_pixels(&c), 0, "{:?}", c.front);
    }
    c.front = Some(vec![(1.0, 1.0), (3.0, 0.5)]);
    assert_eq!(front_entries(&c), 1);
    assert!(front_pixels(&c) > 100);
}

#[test]
fn markers_differ_and_the_legend_shows_them() {
    // Every shape covers a different set of pixels.
    let shape = |m: Marker, hollow: bool| {
        let mut buf = vec![255u8; 40 * 40 * 3];
        {
            let root = BitMapBackend::with_buffer(&mut buf, (40, 40)).into_drawing_area();
            draw_marker(&root, (20, 20), m, RGBColor(0, 0, 0), 5, hollow).unwrap();
            root.present().unwrap();
        }
        buf
    };
    for (i, a) in Marker::ALL.iter().enumerate() {
        for b in &Marker::ALL[i + 1..] {
            assert_ne!(shape(*a, false), shape(*b, false), "{a:?} vs {b:?}");
        }
        assert_ne!(shape(*a, false), shape(*a, true), "{a:?} hollow");
    }
    // A labelled series adds its marker to the legend: more pixels of its colour.
    let mut c = chart(vec![series(2, vec![(1.0, 1.0), (2.0, 3.0)], false)]);
    let color = c.series[0].color;
    let labelled = count_color(&render_with(&c, 640, 400, Face::Bitmap).unwrap(), color);
    c.series[0].label.clear();
    let unlabelled = count_color(&render_with(&c, 640, 400, Face::Bitmap).unwrap(), color);
    assert!(labelled > unlabelled, "{labelled} vs {unlabelled}");
}

#[test]
fn a_hollow_series_stays_visible_around_a_filled_one_on_the_same_points() {
    let points = vec![(1.0, 1.0), (2.0, 3.0), (4.0, 2.0)];
    let filled = series(2, points.clone(), true);
    let mut hollow = series(4, points, true);
    hollow.hollow = true;
    // Even with the same shape (which a filled marker would hide exactly) and whichever comes
    // first in the chart, both colours show, in the markers and the lines.
    hollow.marker = filled.marker;
    for order in [
        vec![filled.clone(), hollow.clone()],
        vec![hollow.clone(), filled.clone()],
    ] {
        let mut c = chart(order);
        c.series.iter_mut().for_each(|s| s.label.clear()); // no legend: only the data
        let img = render_with(&c, 640, 400, Face::Bitmap).unwrap();
        let (a, b) = (
            count_color(&img, filled.color),
            count_color(&img, hollow.color),
        );
        assert!(a > 200 && b > 200, "filled {a}, hollow {b}");
    }
}

#[test]
fn dashes_follow_the_path_across_corners() {
    let d = dashes(&[(0, 0), (20, 0), (20, 20)], 8.0, 6.0);
    assert_eq!(d[0], vec![(0, 0), (8, 0)]);
    assert_eq!(d[1], vec![(14, 0), (20, 0), (20, 2)]);
    assert_eq!(d.len(), 3);
    assert!(dashes(&[(5, 5)], 8.0, 6.0).is_empty());
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
    // A hollow series on a filled one's points (auto on clustered in the bench charts), in
    // each marker shape, and the same chart in the bitmap font.
    let shapes: Vec<Series> = Marker::ALL
        .iter()
        .enumerate()
        .flat_map(|(i, &marker)| {
            let pts = vec![(1.0, i as f64), (2.0, i as f64 + 0.5), (3.0, i as f64)];
            let filled = Series {
                marker,
                ..series(2, pts.clone(), true)
            };
            let hollow = Series {
                label: format!("{marker:?} hollow"),
                marker,
                hollow: true,
                ..series(4, pts, true)
            };
            [filled, hollow]
        })
        .collect();
    let hollow = chart(shapes);
    for (face, name) in [(Face::system(), "hollow"), (Face::Bitmap, "bitmap")] {
        render_with(&hollow, 900, 560, face)
            .unwrap()
            .save(format!("/tmp/manylight_plot_{name}.png"))
            .unwrap();
    }
}
