//! Unit tests of the grid layout and its depth / pixel lookups.

use super::*;

fn persp(near: f64, far: f64) -> ClusterGrid {
    persp_with(near, far, &GridConfig::default())
}

fn persp_with(near: f64, far: f64, config: &GridConfig) -> ClusterGrid {
    ClusterGrid::new(1280, 720, GridProjection::test_view(), near, far, config)
}

#[test]
fn depth_ranges_never_miss_a_slice() {
    // Cascades of one slice from 0.1 to 100: the second slice starts at exactly 1.0, the
    // first depth of one of the slice table's buckets, where depths before it once fell in
    // the second slice.
    let one_slice = GridConfig {
        cascades: 3,
        max_slices: 1,
        ..GridConfig::default()
    };
    let on_bucket = persp_with(0.1, 100.0, &one_slice);
    assert_eq!(on_bucket.slice_depth_range(1, 0).0, 1.0);
    for g in [
        persp(1e-4, 1e5),
        persp(0.1, 80.0),
        persp(0.5, 0.6),
        on_bucket,
    ] {
        let mut d = g.near;
        while d < g.far * 2.0 {
            // Around `d`, and on every slice boundary too.
            let (k, s) = g.view_z_to_cascade_slice(d);
            let (z0, _) = g.slice_depth_range(k, s);
            for x in [
                d,
                d.next_up(),
                d.next_down(),
                z0,
                z0.next_up(),
                z0.next_down(),
            ] {
                let exact = g.view_z_to_cascade_slice(x);
                let (lo, hi) = g.depth_range_to_slices(x, x);
                assert!(
                    lo <= exact && exact <= hi,
                    "{x}: {exact:?} not in {lo:?}..{hi:?}"
                );
            }
            d *= 1.013;
        }
    }
}

#[test]
fn cells_are_contiguous_and_counted() {
    let g = persp(0.1, 80.0);
    let mut next = 0;
    for c in &g.cascades {
        assert_eq!(c.first_cell, next);
        next += c.cells();
        assert!(c.tiles_x >= 1 && c.tiles_y >= 1 && c.slices >= 1);
    }
    assert_eq!(next, g.total_cells);
    assert_eq!(g.cascades.len(), 12);
}

#[test]
fn depth_mapping_is_monotonic_and_covers_near_to_infinity() {
    for g in [persp(1e-4, 1e5), persp(0.1, 80.0), persp(0.5, 0.6)] {
        let mut last = (0, 0);
        let mut d = g.near;
        while d < g.far * 4.0 {
            let cs = g.view_z_to_cascade_slice(d);
            assert!(cs >= last, "not monotonic at {d}");
            let (z0, z1) = g.slice_depth_range(cs.0, cs.1);
            assert!(
                z0 <= d * (1.0 + 1e-9) && d <= z1 * (1.0 + 1e-9),
                "{d} outside slice {cs:?} [{z0}, {z1}]"
            );
            last = cs;
            d *= 1.01;
        }
        assert_eq!(g.view_z_to_cascade_slice(g.near * 0.5).0, 0);
        let lastc = g.cascades.len() as u32 - 1;
        assert_eq!(g.view_z_to_cascade_slice(f64::INFINITY).0, lastc);
    }
}

/// `slice_depth` sets how deep a slice is against a cell's width (below the slice cap), and
/// thinner slices make proportionally more of them.
#[test]
fn slice_depth_sets_the_depth_to_width_ratio() {
    let cubical = persp_with(0.1, 80.0, &GridConfig::fixed(32.0));
    for ratio in [0.5, 2.0] {
        let config = GridConfig {
            slice_depth: ratio,
            ..GridConfig::fixed(32.0)
        };
        let g = persp_with(0.1, 80.0, &config);
        for (k, c) in g.cascades.iter().enumerate() {
            let (z0, z1) = g.slice_depth_range(k as u32, 0);
            let z0 = z0.max(c.z_near);
            // The footprint's width (the tiles round it down a little).
            let width = 2.0 * z0 * (30f64).to_radians().tan() / g.height as f64 * 32.0;
            let r = (z1 - z0) / width;
            if c.slices > 1 && c.slices < config.max_slices {
                assert!(
                    (0.45 * ratio..=1.01 * ratio).contains(&r),
                    "slice_depth {ratio}, cascade {k}: depth / width = {r}"
                );
            }
        }
        let slices = |g: &ClusterGrid| g.cascades.iter().map(|c| c.slices).sum::<u32>() as f64;
        let more = slices(&g) / slices(&cubical);
        assert!(
            (0.7 / ratio..=1.3 / ratio).contains(&more),
            "slice_depth {ratio}: {more}× the slices"
        );
    }
    // Hostile values read as 1 (not finite) or clamp to 1/16 (zero, negative, tiny): never
    // zero-depth slices or a division by zero.
    let slices_with = |slice_depth: f64| {
        let config = GridConfig {
            slice_depth,
            ..GridConfig::fixed(32.0)
        };
        let g = persp_with(0.1, 80.0, &config);
        g.cascades.iter().map(|c| c.slices).collect::<Vec<_>>()
    };
    for hostile in [f64::NAN, f64::INFINITY, f64::NEG_INFINITY] {
        assert_eq!(slices_with(hostile), slices_with(1.0), "{hostile}");
    }
    for hostile in [0.0, -1.0, 1e-300] {
        assert_eq!(slices_with(hostile), slices_with(1.0 / 16.0), "{hostile}");
    }
}

/// However many slices the settings ask for, a cascade has at most 255: the ES 2.0 grid
/// texture stores the count in a byte.
#[test]
fn a_cascade_never_has_more_slices_than_a_byte_holds() {
    let config = GridConfig {
        cascades: 1,
        slice_depth: 1.0 / 16.0,
        max_slices: 100_000,
        ..GridConfig::fixed(1.0)
    };
    let g = persp_with(0.1, 1e4, &config);
    assert_eq!(g.cascades[0].slices, 255);
}

#[test]
fn cells_are_roughly_cubical_or_clamped_to_the_minimum() {
    let g = persp(0.1, 80.0);
    for (k, c) in g.cascades.iter().enumerate() {
        let (z0, z1) = g.slice_depth_range(k as u32, 0);
        let z0 = z0.max(c.z_near);
        let width = 2.0 * z0 * (30f64).to_radians().tan() / c.tiles_y as f64;
        let depth = z1 - z0;
        if c.slices < GridConfig::default().max_slices {
            assert!(
                depth / width < 2.5 && width / depth < 2.5,
                "cascade {k}: {width} × {depth}"
            );
        }
    }
    // Without a minimum cell size every cascade has the footprint's tiles; with one, the
    // near cascades are coarser.
    assert!(g
        .cascades
        .iter()
        .all(|c| c.tiles_y == g.cascades[0].tiles_y));
    let coarse = persp_with(
        0.1,
        80.0,
        &GridConfig {
            measure: GridMeasure {
                min_cell_size: Some(80.0 / 64.0),
                ..GridMeasure::default()
            },
            ..GridConfig::default()
        },
    );
    assert!(coarse.cascades[0].tiles_y < coarse.cascades[11].tiles_y);
}

#[test]
fn orthographic_uses_linear_slices_and_allows_near_zero() {
    let g = ClusterGrid::new(
        256,
        144,
        GridProjection::Orthographic {
            half_x: 8.0,
            half_y: 4.5,
        },
        0.0,
        20.0,
        &GridConfig::default(),
    );
    assert_eq!(g.mapping, DepthMapping::Linear);
    assert_eq!(g.view_z_to_cascade_slice(0.0), (0, 0));
    let (k, _) = g.view_z_to_cascade_slice(10.0);
    assert_eq!(k, 6);
}

#[test]
fn tiles_config_gives_one_slice_spanning_everything() {
    let t = (30f64).to_radians().tan();
    let g = ClusterGrid::new(
        256,
        144,
        GridProjection::Perspective { tan_x: t, tan_y: t },
        0.1,
        50.0,
        &GridConfig::tiles(16.0),
    );
    assert_eq!(g.cascades.len(), 1);
    assert_eq!(g.cascades[0].slices, 1);
    assert_eq!((g.cascades[0].tiles_x, g.cascades[0].tiles_y), (16, 9));
    assert_eq!(g.slice_depth_range(0, 0), (0.1, f64::INFINITY));
}

#[test]
fn fragment_cells_match_bounds() {
    let g = persp(0.1, 80.0);
    for &(x, y, d) in &[
        (0.5, 0.5, 0.1),
        (1279.5, 719.5, 79.0),
        (640.0, 360.0, 5.0),
        (100.2, 600.7, 30.0),
    ] {
        let c = g.cell_of_fragment(x, y, d);
        let b = g.cell_bounds(c);
        let nx = 2.0 * x / 1280.0 - 1.0;
        let ny = 2.0 * y / 720.0 - 1.0;
        assert!(b.ndc_x.0 <= nx && nx <= b.ndc_x.1);
        assert!(b.ndc_y.0 <= ny && ny <= b.ndc_y.1);
        assert!(b.depth.0 <= d * (1.0 + 1e-12) && d <= b.depth.1 * (1.0 + 1e-12));
    }
}

/// Every cell's bounding sphere holds the cell's eight corners (from `cell_bounds`), and is
/// not much larger than they need; cells reaching infinity get an infinite one.
#[test]
fn cell_spheres_hold_their_cells() {
    for grid in [
        persp(0.1, 80.0),
        persp_with(0.5, 300.0, &GridConfig::fixed(11.0)),
        persp(0.1, f64::INFINITY),
    ] {
        let mut first_slice = 0;
        for (k, c) in grid.cascades.iter().enumerate() {
            for slice in 0..c.slices {
                for y in 0..c.tiles_y {
                    for x in 0..c.tiles_x {
                        let cell = CellCoord {
                            cascade: k as u32,
                            slice,
                            x,
                            y,
                        };
                        let [sx, sy, sz, r] =
                            grid.row_spheres(k as u32, first_slice + slice, y).cell(x);
                        let b = grid.cell_bounds(cell);
                        if b.depth.1.is_infinite() {
                            assert!(r.is_infinite());
                            continue;
                        }
                        let mut farthest: f64 = 0.0;
                        for z in [b.depth.0, b.depth.1] {
                            let (hx, hy) = grid.projection.half_extent(z);
                            for nx in [b.ndc_x.0, b.ndc_x.1] {
                                for ny in [b.ndc_y.0, b.ndc_y.1] {
                                    let d = glam::DVec3::new(nx * hx - sx, ny * hy - sy, -z - sz)
                                        .length();
                                    farthest = farthest.max(d);
                                }
                            }
                        }
                        assert!(farthest <= r * (1.0 + 1e-12), "{cell:?}: {farthest} > {r}");
                        assert!(r <= farthest * (1.0 + 1e-9), "{cell:?}: {r} ≫ {farthest}");
                    }
                }
            }
            first_slice += c.slices;
        }
    }
}

#[test]
fn a_grid_rebuilt_finer_keeps_its_buffers() {
    // Coarse to fine, first splits near and far, as the automatic grid's candidates come.
    let mut grid = persp_with(0.1, 80.0, &GridConfig::fixed(64.0));
    let buffers = |g: &ClusterGrid| {
        (
            g.slice_slabs.capacity(),
            g.slice_frusta.capacity(),
            g.cascade_constants.capacity(),
            g.slice_lookup.capacities(),
        )
    };
    let before = buffers(&grid);
    let slices = grid.slice_slabs.len();
    for (px, split) in [
        (32.0, None),
        (16.0, Some(4.0)),
        (8.0, Some(0.2)),
        (4.0, Some(0.1)),
    ] {
        let config = GridConfig {
            first_split: split,
            ..GridConfig::fixed(px)
        };
        grid.rebuild(1280, 720, GridProjection::test_view(), 0.1, 80.0, &config);
        assert_eq!(buffers(&grid), before, "{px} px, first split {split:?}");
    }
    assert!(
        grid.slice_slabs.len() > 2 * slices,
        "the finest grid has more slices"
    );
}
