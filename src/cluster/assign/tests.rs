//! Assignment against a brute-force reference: for many random fragment positions, every light
//! that really reaches the position must be in the list of the cell the shader would pick.

use glam::{DVec3, Vec3};
use rand::{Rng, SeedableRng};
use rand_pcg::Pcg64Mcg;

use super::{assign, AssignLimits, Assignment};
use crate::cluster::grid::{ClusterGrid, Coverage, GridConfig, GridProjection};
use crate::cluster::view_light::GpuLight;
use crate::scene::Light;

pub(super) struct Case {
    pub(super) name: &'static str,
    pub(super) projection: GridProjection,
    pub(super) near: f64,
    pub(super) far: f64,
    pub(super) config: GridConfig,
}

pub(super) fn cases() -> Vec<Case> {
    let persp = GridProjection::test_view();
    vec![
        Case {
            name: "default",
            projection: persp,
            near: 0.1,
            far: 80.0,
            config: GridConfig::default(),
        },
        Case {
            name: "tiny near",
            projection: persp,
            near: 1e-4,
            far: 1e5,
            config: GridConfig::default(),
        },
        Case {
            name: "narrow fov",
            projection: GridProjection::Perspective {
                tan_x: 0.02,
                tan_y: 0.01,
            },
            near: 1.0,
            far: 500.0,
            config: GridConfig::default(),
        },
        Case {
            name: "ortho near 0",
            projection: GridProjection::Orthographic {
                half_x: 16.0,
                half_y: 9.0,
            },
            near: 0.0,
            far: 60.0,
            config: GridConfig::default(),
        },
        Case {
            name: "tiles",
            projection: persp,
            near: 0.1,
            far: 80.0,
            config: GridConfig::tiles(16.0),
        },
        Case {
            name: "half-depth slices",
            projection: persp,
            near: 0.1,
            far: 80.0,
            config: GridConfig {
                slice_depth: 0.5,
                ..GridConfig::fixed(16.0)
            },
        },
        Case {
            name: "fine",
            projection: persp,
            near: 0.05,
            far: 30.0,
            config: GridConfig {
                footprint_px: 8.0,
                ..GridConfig::default()
            },
        },
    ]
}

/// `got` lists what `expected` lists: the same visible lights, per-cell offsets and counts and
/// index list (compared without printing it on failure: it is long). `what` names the case.
pub(super) fn assert_same_lists(got: &Assignment, expected: &Assignment, what: &str) {
    assert_eq!(got.visible, expected.visible, "{what}");
    assert_eq!(got.offsets, expected.offsets, "{what}");
    assert_eq!(got.counts, expected.counts, "{what}");
    assert!(got.indices == expected.indices, "{what}: other indices");
}

/// The test view at 640×360, near 0.1 and far 80, with the grid `config` makes.
pub(super) fn view_grid(config: &GridConfig) -> ClusterGrid {
    ClusterGrid::new(640, 360, GridProjection::test_view(), 0.1, 80.0, config)
}

/// Random lights around, behind and beyond the camera, point and spot, many sizes.
pub(super) fn random_lights(rng: &mut Pcg64Mcg, n: usize, scale: f64) -> Vec<GpuLight> {
    (0..n)
        .map(|i| {
            let p = DVec3::new(
                rng.random_range(-1.0..1.0),
                rng.random_range(-1.0..1.0),
                rng.random_range(-1.2..0.3),
            ) * scale;
            let r = (scale * rng.random_range(0.005..0.3)) as f32;
            let light = if i % 3 == 0 {
                let dir = DVec3::new(
                    rng.random_range(-1.0..1.0),
                    rng.random_range(-1.0..1.0),
                    rng.random_range(-1.0..1.0),
                );
                let dir = if dir.length() < 1e-3 { DVec3::Z } else { dir };
                let outer = rng.random_range(0.5..100.0);
                Light::spot(
                    p,
                    r,
                    Vec3::ONE,
                    1.0,
                    crate::scene::Cone {
                        direction: dir,
                        inner_deg: outer * 0.5,
                        outer_deg: outer,
                    },
                )
            } else {
                Light::point(p, r, Vec3::ONE, 1.0)
            };
            // Identity view: positions are already in view space.
            GpuLight::from_light(&light, &glam::DMat4::IDENTITY)
        })
        .collect()
}

fn reaches(light: &GpuLight, p: DVec3) -> bool {
    let to = p - light.position.as_dvec3();
    let dist = to.length();
    if dist >= light.radius as f64 {
        return false;
    }
    if light.spot_scale != 0.0 && dist > 0.0 {
        // Where the spot term is above 0 (the shader's test): up to the outer angle, or just
        // past it for an edge sharper than the smallest fade width.
        let cos = (to / dist).dot(light.direction.as_dvec3());
        let edge = 1.0 - light.spot_offset as f64 / light.spot_scale as f64;
        return cos >= edge - 1e-9;
    }
    true
}

pub(super) fn cell_lights(a: &Assignment, cell: u32) -> Vec<u32> {
    let (o, n) = (
        a.offsets[cell as usize] as usize,
        a.counts[cell as usize] as usize,
    );
    a.indices
        .range(o..o + n)
        .into_iter()
        .map(|i| a.visible[i as usize])
        .collect()
}

fn check_points(
    grid: &ClusterGrid,
    lights: &[GpuLight],
    a: &Assignment,
    points: &[(f64, f64, f64)],
    name: &str,
) -> usize {
    let mut checked = 0;
    for &(px, py, d) in points {
        let (hx, hy) = grid.projection.half_extent(d);
        let ndc_x = 2.0 * px / grid.width as f64 - 1.0;
        let ndc_y = 2.0 * py / grid.height as f64 - 1.0;
        let p = DVec3::new(ndc_x * hx, ndc_y * hy, -d);
        let cell = grid.cell_index(grid.cell_of_fragment(px, py, d));
        let list = cell_lights(a, cell);
        for (i, l) in lights.iter().enumerate() {
            if reaches(l, p) {
                checked += 1;
                assert!(list.contains(&(i as u32)), "{name}: light {i} {l:?} reaches {p:?} (pixel {px},{py}, depth {d}) but is not in cell {cell}");
            }
        }
    }
    checked
}

#[test]
fn never_misses_a_light_that_reaches_a_fragment() {
    let mut rng = Pcg64Mcg::seed_from_u64(42);
    for case in cases() {
        let grid = ClusterGrid::new(320, 180, case.projection, case.near, case.far, &case.config);
        let scale = case.far.min(200.0) * 0.5;
        let lights = random_lights(&mut rng, 1500, scale);
        let a = assign(
            &grid,
            &lights,
            case.far,
            &AssignLimits {
                cell_cap: u32::MAX,
                ..Default::default()
            },
        );
        assert_eq!(a.stats.overflowed_lights, 0);
        let log_range = (case.near.max(1e-4).ln(), case.far.min(scale * 3.0).ln());
        let points: Vec<_> = (0..6000)
            .map(|_| {
                let d = if case.near == 0.0 {
                    rng.random_range(0.0..case.far)
                } else {
                    rng.random_range(log_range.0..log_range.1).exp()
                };
                (
                    rng.random_range(0.0..320.0),
                    rng.random_range(0.0..180.0),
                    d,
                )
            })
            .collect();
        let checked = check_points(&grid, &lights, &a, &points, case.name);
        assert!(
            checked > 500,
            "{}: only {checked} light-fragment pairs checked",
            case.name
        );
    }
}

/// Fragments exactly on column, row and slice boundaries, and one ulp either side.
#[test]
fn never_misses_on_cell_boundaries() {
    let mut rng = Pcg64Mcg::seed_from_u64(7);
    for case in cases() {
        let grid = ClusterGrid::new(320, 180, case.projection, case.near, case.far, &case.config);
        let scale = case.far.min(200.0) * 0.5;
        let lights = random_lights(&mut rng, 800, scale);
        let a = assign(
            &grid,
            &lights,
            case.far,
            &AssignLimits {
                cell_cap: u32::MAX,
                ..Default::default()
            },
        );
        let mut points = Vec::new();
        for (k, c) in grid.cascades.iter().enumerate() {
            for s in 0..c.slices {
                let (z0, _) = grid.slice_depth_range(k as u32, s);
                if z0 > scale * 3.0 || z0 <= 0.0 {
                    continue;
                }
                for _ in 0..20 {
                    let i = rng.random_range(0..=c.tiles_x);
                    let j = rng.random_range(0..=c.tiles_y);
                    let px = (i as f64 * 320.0 / c.tiles_x as f64).min(319.999);
                    let py = (j as f64 * 180.0 / c.tiles_y as f64).min(179.999);
                    for z in [z0, z0.next_up(), z0.next_down()] {
                        for (x, y) in [
                            (px, py),
                            (px.next_up(), py),
                            (px.next_down(), py.next_down()),
                        ] {
                            points.push((
                                x.clamp(0.0, 319.999),
                                y.clamp(0.0, 179.999),
                                z.max(case.near),
                            ));
                        }
                    }
                }
            }
        }
        let checked = check_points(&grid, &lights, &a, &points, case.name);
        assert!(
            checked > 500,
            "{}: {checked} point-light pairs checked",
            case.name
        );
    }
}

#[test]
fn lights_behind_the_camera_or_beyond_far_are_culled() {
    let t = (30f64).to_radians().tan();
    let grid = ClusterGrid::new(
        320,
        180,
        GridProjection::Perspective { tan_x: t, tan_y: t },
        0.1,
        50.0,
        &GridConfig::default(),
    );
    let mk = |z: f64, r: f32| {
        GpuLight::from_light(
            &Light::point(DVec3::new(0.0, 0.0, z), r, Vec3::ONE, 1.0),
            &glam::DMat4::IDENTITY,
        )
    };
    let lights = vec![
        mk(5.0, 2.0),   // entirely behind
        mk(-60.0, 5.0), // entirely beyond far
        mk(0.5, 1.0),   // centre behind, sphere crosses the near plane: visible
        mk(-10.0, 1.0), // in front
        GpuLight::from_light(
            &Light::point(DVec3::new(100.0, 0.0, -10.0), 1.0, Vec3::ONE, 1.0),
            &glam::DMat4::IDENTITY,
        ), // far off to the side
    ];
    let a = assign(&grid, &lights, 50.0, &AssignLimits::default());
    assert_eq!(a.visible, vec![2, 3]);
    // The light around the eye covers every column of the nearest slice.
    let c0 = &grid.cascades[0];
    let near_cells: Vec<u32> = (0..c0.tiles_x * c0.tiles_y).collect();
    for cell in near_cells {
        assert!(
            cell_lights(&a, cell).contains(&2),
            "cell {cell} lacks the light around the eye"
        );
    }
}

#[test]
fn overflow_keeps_the_cap_counts_the_rest_and_stays_in_range() {
    let t = (30f64).to_radians().tan();
    let grid = ClusterGrid::new(
        256,
        144,
        GridProjection::Perspective { tan_x: t, tan_y: t },
        0.1,
        50.0,
        &GridConfig::default(),
    );
    // 300 small lights in one spot: one cell gets all of them.
    let lights: Vec<GpuLight> = (0..300)
        .map(|i| {
            GpuLight::from_light(
                &Light::point(
                    DVec3::new(0.001 * i as f64, 0.0, -20.0),
                    0.01,
                    Vec3::splat(1.0 + i as f32),
                    1.0,
                ),
                &glam::DMat4::IDENTITY,
            )
        })
        .collect();
    let a = assign(
        &grid,
        &lights,
        50.0,
        &AssignLimits {
            cell_cap: 255,
            ..Default::default()
        },
    );
    assert!(a.stats.max_lights_per_cluster >= 300);
    assert!(a.counts.iter().all(|&n| n <= 255));
    assert!(a.stats.overflowed_lights >= 45);
    let kept = a.indices.len() as u64;
    let total: u64 = a.counts.iter().map(|&n| n as u64).sum();
    assert_eq!(kept, total);
    for (o, n) in a.offsets.iter().zip(&a.counts) {
        assert!((*o + *n) as usize <= a.indices.len());
    }
    assert!(a
        .indices
        .to_vec()
        .iter()
        .all(|&i| (i as usize) < a.visible.len()));
    // The brightest lights are the ones kept.
    let full = a.counts.iter().position(|&n| n == 255).unwrap() as u32;
    let kept_lights = cell_lights(&a, full);
    assert!(kept_lights.contains(&299) && !kept_lights.contains(&0));

    // An index budget smaller than the lists lowers the cap until it fits.
    let b = assign(
        &grid,
        &lights,
        50.0,
        &AssignLimits {
            cell_cap: 255,
            max_indices: 100,
            ..Default::default()
        },
    );
    assert!(b.indices.len() <= 100);
    assert_eq!(
        b.stats.overflowed_lights as usize + b.indices.len(),
        a.stats.overflowed_lights as usize + a.indices.len()
    );
}

/// Points just inside each light's reach, where a loose bound is most tempting to cut: on its
/// sphere's surface in every direction and, for spots, on the cone's edge. Every grid mode,
/// both coverages.
#[test]
fn never_misses_where_a_light_barely_reaches() {
    let mut rng = Pcg64Mcg::seed_from_u64(99);
    for case in cases() {
        for coverage in [Coverage::SliceRows, Coverage::CascadeBox] {
            let mut config = case.config.clone();
            config.measure.coverage = coverage;
            let grid = ClusterGrid::new(320, 180, case.projection, case.near, case.far, &config);
            let lights = lights_in_view(&mut rng, &grid, 300);
            let limits = AssignLimits {
                cell_cap: u32::MAX,
                ..Default::default()
            };
            let a = assign(&grid, &lights, case.far, &limits);
            let mut points = Vec::new();
            for l in &lights {
                let c = l.position.as_dvec3();
                let r = l.radius as f64 * (1.0 - 1e-7);
                for _ in 0..40 {
                    let u = random_unit(&mut rng);
                    let dir = if l.spot_scale != 0.0 && rng.random_bool(0.5) {
                        cone_edge(l, u)
                    } else {
                        u
                    };
                    let t = if rng.random_bool(0.5) {
                        r
                    } else {
                        r * rng.random_range(0.0..1.0)
                    };
                    if let Some(p) = to_window(&grid, c + dir * t) {
                        points.push(p);
                    }
                }
            }
            let checked = check_points(&grid, &lights, &a, &points, case.name);
            assert!(checked > 1000, "{}: only {checked} pairs", case.name);
        }
    }
}

/// The per-slice, per-row bound only removes cells from the per-cascade rectangle, and removes
/// many of them.
#[test]
fn slice_rows_are_a_subset_of_the_cascade_box() {
    let mut rng = Pcg64Mcg::seed_from_u64(5);
    let (mut tight_total, mut loose_total) = (0, 0);
    for case in cases() {
        let view = ClusterGrid::new(320, 180, case.projection, case.near, case.far, &case.config);
        let lights = lights_in_view(&mut rng, &view, 400);
        let limits = AssignLimits {
            cell_cap: u32::MAX,
            ..Default::default()
        };
        let build = |coverage| {
            let mut config = case.config.clone();
            config.measure.coverage = coverage;
            let grid = ClusterGrid::new(320, 180, case.projection, case.near, case.far, &config);
            assign(&grid, &lights, case.far, &limits)
        };
        let (tight, loose) = (build(Coverage::SliceRows), build(Coverage::CascadeBox));
        for cell in 0..tight.counts.len() as u32 {
            let loose_list = cell_lights(&loose, cell);
            for light in cell_lights(&tight, cell) {
                assert!(
                    loose_list.contains(&light),
                    "{}: light {light} in cell {cell} only with the tight bound",
                    case.name
                );
            }
        }
        let (t, l) = (tight.indices.len(), loose.indices.len());
        assert!(t < l, "{}: {t} indices against {l}", case.name);
        tight_total += t;
        loose_total += l;
    }
    assert!(
        tight_total * 4 < loose_total * 3,
        "{tight_total} indices against {loose_total}"
    );
}

/// Lights around the view frustum (a little beyond its sides, some around the eye), with radii
/// from a cell's size to much of the view: the random lights of [`random_lights`] moved so the
/// narrow and deep frusta get as many as the others.
fn lights_in_view(rng: &mut Pcg64Mcg, grid: &ClusterGrid, n: usize) -> Vec<GpuLight> {
    let mut lights = random_lights(rng, n, 1.0);
    let (near, far) = (
        grid.near.max(grid.far * 1e-4),
        grid.far.min(grid.near.max(1.0) * 1e3),
    );
    for l in &mut lights {
        let d = (rng.random_range(near.ln()..far.ln())).exp();
        let (hx, hy) = grid.projection.half_extent(d);
        let p = DVec3::new(
            rng.random_range(-1.2..1.2) * hx,
            rng.random_range(-1.2..1.2) * hy,
            -d,
        );
        let r = hy * rng.random_range(0.02..0.6);
        l.position = p.as_vec3();
        l.radius = r as f32;
        l.cull_radius = r as f32;
    }
    lights
}

fn random_unit(rng: &mut Pcg64Mcg) -> DVec3 {
    loop {
        let v = DVec3::new(
            rng.random_range(-1.0..1.0),
            rng.random_range(-1.0..1.0),
            rng.random_range(-1.0..1.0),
        );
        let n = v.length();
        if n > 0.1 && n <= 1.0 {
            return v / n;
        }
    }
}

/// A unit direction on a spot's cone edge (just inside), turned from its axis towards `u`.
fn cone_edge(light: &GpuLight, u: DVec3) -> DVec3 {
    let axis = light.direction.as_dvec3().normalize();
    let side = (u - axis * u.dot(axis)).normalize_or(axis.any_orthonormal_vector());
    let angle = (light.cone_deg.0 as f64).to_radians() * (1.0 - 1e-6);
    axis * angle.cos() + side * angle.sin()
}

/// Window position (pixels, y up) and depth of a view-space point, if it is on screen and
/// between the near and far planes.
fn to_window(grid: &ClusterGrid, p: DVec3) -> Option<(f64, f64, f64)> {
    let d = -p.z;
    if !(d >= grid.near.max(1e-9) && d <= grid.far * 3.0) {
        return None;
    }
    let (hx, hy) = grid.projection.half_extent(d);
    let (nx, ny) = (p.x / hx, p.y / hy);
    if nx.abs() >= 1.0 || ny.abs() >= 1.0 {
        return None;
    }
    Some((
        (nx + 1.0) * 0.5 * grid.width as f64,
        (ny + 1.0) * 0.5 * grid.height as f64,
        d,
    ))
}

/// The plain loops that small lights (at most 2 × 2 cells a cascade) take emit exactly what
/// the general slice loop emits for them (the cascade's rectangle, no cone), for points and
/// spots, in every grid mode, over the whole grid and over windows of slices (bands).
#[test]
fn small_lights_plain_loops_match_the_general_loop() {
    use super::cells::{for_each_run_in, SliceWindow, SMALL_PATH_OFF};
    let mut rng = Pcg64Mcg::seed_from_u64(17);
    let mut small_rects = 0;
    for case in cases() {
        let grid = ClusterGrid::new(320, 180, case.projection, case.near, case.far, &case.config);
        let slices = grid.slice_slabs.len() as u32;
        let mut lights = lights_in_view(&mut rng, &grid, 300);
        // Mostly small: radii of a few pixels to a cell or two.
        for l in &mut lights {
            let d = -l.position.z as f64;
            let (_, hy) = grid.projection.half_extent(d.max(case.near));
            let r = (hy * rng.random_range(0.002..0.08)) as f32;
            l.radius = r;
            l.cull_radius = r;
        }
        let windows = [
            SliceWindow::ALL,
            SliceWindow::of(&grid, 0, slices.div_ceil(2)),
            SliceWindow::of(&grid, slices / 3, slices),
        ];
        for light in &lights {
            for window in &windows {
                let runs = |off: bool| {
                    SMALL_PATH_OFF.with(|flag| flag.set(off));
                    let mut runs = Vec::new();
                    for_each_run_in(&grid, window, light, case.far, &mut |start, len| {
                        runs.push((start, len))
                    });
                    SMALL_PATH_OFF.with(|flag| flag.set(false));
                    runs
                };
                let (plain, general) = (runs(false), runs(true));
                assert_eq!(plain, general, "{}: {light:?}", case.name);
                small_rects += usize::from(!plain.is_empty() && plain.iter().all(|r| r.1 <= 2));
            }
        }
    }
    assert!(small_rects > 500, "only {small_rects} small lights tried");
}

/// A spot whose axis has no direction (zero, or an infinite or NaN component: only a caller
/// building `GpuLight`s itself can give one) is bounded by its whole sphere, as the point
/// light of the same sphere is, and every band of slices lists it where the whole grid does:
/// an axis normalised to NaN made the whole grid list such a spot everywhere while a band
/// rejected it by its apex's depth, so the lists depended on where the bands were cut.
#[test]
fn a_spot_without_an_axis_direction_is_its_sphere_in_every_band() {
    use super::cells::{for_each_run_in, SliceWindow};
    for case in cases() {
        let grid = ClusterGrid::new(320, 180, case.projection, case.near, case.far, &case.config);
        let slices = grid.slice_slabs.len() as u32;
        let cells = |light: &GpuLight, window: &SliceWindow| {
            let mut cells = Vec::new();
            for_each_run_in(&grid, window, light, case.far, &mut |start, len| {
                cells.extend(start..start + len)
            });
            cells
        };
        // Behind the eye (reaches nothing) and in front of it (reaches cells).
        for (position, radius) in [
            (Vec3::new(-6.8, -3.1, 12.7), 0.48),
            (Vec3::new(0.5, 0.2, -6.0), 1.5),
        ] {
            let point = GpuLight {
                position,
                radius,
                cull_radius: radius,
                radiance: Vec3::ONE,
                spot_scale: 0.0,
                direction: Vec3::ZERO,
                spot_offset: 1.0,
                cone_deg: (180.0, 180.0),
            };
            let sphere = cells(&point, &SliceWindow::ALL);
            // Or every comparison below would pass with no cells at all.
            assert_eq!(
                sphere.is_empty(),
                position.z > 0.0,
                "{}: the sphere at {position} reaches {} cells",
                case.name,
                sphere.len()
            );
            for direction in [
                Vec3::ZERO,
                Vec3::new(-0.24, 0.0, f32::NEG_INFINITY),
                Vec3::new(f32::NAN, 0.3, -1.0),
            ] {
                let spot = GpuLight {
                    spot_scale: 3.3,
                    spot_offset: 1.5,
                    direction,
                    cone_deg: (60.0, 30.0),
                    ..point
                };
                let what = format!("{}: axis {direction}, at {position}", case.name);
                assert_eq!(cells(&spot, &SliceWindow::ALL), sphere, "{what}");
                for split in 1..slices {
                    let mut bands = cells(&spot, &SliceWindow::of(&grid, 0, split));
                    bands.extend(cells(&spot, &SliceWindow::of(&grid, split, slices)));
                    assert_eq!(bands, sphere, "{what}, bands split at slice {split}");
                }
            }
        }
    }
}

/// A grid of more cells than an assignment takes (here 2³² − 1, saturated: a large frame with
/// one-pixel cells and raised limits) is not assigned: no per-cell arrays (four bytes a cell
/// would be 16 GiB, so allocating them would abort this test), every light counted as
/// overflowed.
#[test]
fn a_grid_past_the_table_gets_no_cell_arrays() {
    let grid = ClusterGrid::new(
        65_536,
        65_536,
        GridProjection::test_view(),
        0.1,
        60.0,
        &GridConfig {
            max_tiles: u32::MAX,
            max_slices: 255,
            ..GridConfig::fixed(1.0)
        },
    );
    assert!(grid.total_cells > super::MAX_ASSIGN_CELLS);
    let light = Light::point(DVec3::new(0.0, 0.0, -5.0), 1.0, Vec3::ONE, 1.0);
    let lights = vec![GpuLight::from_light(&light, &glam::DMat4::IDENTITY); 3];
    let a = assign(&grid, &lights, 60.0, &AssignLimits::default());
    assert!(a.counts.is_empty() && a.offsets.is_empty() && a.indices.is_empty());
    assert!(a.visible.is_empty());
    assert_eq!(a.stats.overflowed_lights, 3);
    assert_eq!(a.stats.clusters, grid.total_cells);
}
