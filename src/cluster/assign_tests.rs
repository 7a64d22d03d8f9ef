//! Assignment against a brute-force reference: for many random fragment positions, every light
//! that really reaches the position must be in the list of the cell the shader would pick.

use glam::{DVec3, Vec3};
use rand::{Rng, SeedableRng};
use rand_pcg::Pcg64Mcg;

use super::assign::{assign, AssignLimits, Assignment};
use super::grid::{ClusterGrid, Coverage, GridConfig, GridProjection};
use super::pack::GpuLight;
use crate::scene::Light;

struct Case {
    name: &'static str,
    projection: GridProjection,
    near: f64,
    far: f64,
    config: GridConfig,
}

fn cases() -> Vec<Case> {
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
                min_cell_size: Some(0.0),
                ..GridConfig::default()
            },
        },
    ]
}

/// Random lights around, behind and beyond the camera, point and spot, many sizes.
fn random_lights(rng: &mut Pcg64Mcg, n: usize, scale: f64) -> Vec<GpuLight> {
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
                Light::spot(p, dir, outer * 0.5, outer, r, Vec3::ONE, 1.0)
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
        let cos = (to / dist).dot(light.direction.as_dvec3());
        return cos >= (light.cone_deg.0 as f64).to_radians().cos() - 1e-9;
    }
    true
}

fn cell_lights(a: &Assignment, cell: u32) -> Vec<u32> {
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
        check_points(&grid, &lights, &a, &points, case.name);
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

#[test]
fn parallel_and_sequential_assignment_agree() {
    let mut rng = Pcg64Mcg::seed_from_u64(3);
    let grid = ClusterGrid::new(
        640,
        360,
        GridProjection::test_view(),
        0.1,
        80.0,
        &GridConfig::default(),
    );
    let lights = random_lights(&mut rng, 5000, 40.0);
    let seq = assign(
        &grid,
        &lights,
        80.0,
        &AssignLimits {
            parallel_threshold: usize::MAX,
            ..Default::default()
        },
    );
    let par = assign(
        &grid,
        &lights,
        80.0,
        &AssignLimits {
            parallel_threshold: 1,
            ..Default::default()
        },
    );
    assert_eq!(seq.visible, par.visible);
    assert_eq!(seq.offsets, par.offsets);
    assert_eq!(seq.counts, par.counts);
    assert_eq!(seq.indices, par.indices);
    assert_eq!(seq.stats, par.stats);
    check_stats(&seq, None);
    // Capped, on both paths: the figures describe the lists after the cap, the largest count
    // the lists before it.
    for parallel_threshold in [usize::MAX, 1] {
        let limits = AssignLimits {
            cell_cap: 3,
            parallel_threshold,
            ..Default::default()
        };
        let capped = assign(&grid, &lights, 80.0, &limits);
        assert!(capped.stats.overflowed_lights > 0);
        check_stats(&capped, Some(seq.stats.max_lights_per_cluster));
    }
}

/// The figures of an assignment against counts taken from its lists here; `uncapped_max` is
/// the largest count before a cap (`None`: no cap applied).
fn check_stats(a: &Assignment, uncapped_max: Option<u32>) {
    let nonempty = a.counts.iter().filter(|&&n| n > 0).count() as u32;
    let max = a.counts.iter().copied().max().unwrap();
    assert!(nonempty > 0);
    assert_eq!(a.stats.nonempty_clusters, nonempty);
    assert_eq!(a.stats.max_lights_per_cluster, uncapped_max.unwrap_or(max));
    assert_eq!(a.stats.indices, a.indices.len());
    assert_eq!(a.stats.clusters as usize, a.counts.len());
    assert_eq!(a.stats.visible_lights, a.visible.len());
    let avg = a.indices.len() as f64 / nonempty as f64;
    assert!((a.stats.avg_lights_per_nonempty - avg).abs() < 1e-12);
}

/// One assigner over frames of different sizes, grids and light sets gives what fresh buffers
/// give (nothing stale survives from an earlier frame).
#[test]
fn reused_buffers_match_fresh_ones() {
    let mut rng = Pcg64Mcg::seed_from_u64(11);
    let mut assigner = super::assign::Assigner::new();
    let cases = cases();
    for (frame, case) in cases.iter().cycle().take(12).enumerate() {
        let grid = ClusterGrid::new(320, 180, case.projection, case.near, case.far, &case.config);
        let n = [5000, 0, 700, 9000][frame % 4];
        let lights = random_lights(&mut rng, n, case.far.min(200.0) * 0.5);
        let limits = AssignLimits {
            cell_cap: if frame % 3 == 0 { 40 } else { u32::MAX },
            parallel_threshold: if frame % 2 == 0 { 1 } else { usize::MAX },
            ..Default::default()
        };
        let fresh = assign(&grid, &lights, case.far, &limits);
        let reused = assigner.assign(&grid, &lights, case.far, &limits);
        assert_eq!(fresh.visible, reused.visible, "{}", case.name);
        assert_eq!(fresh.offsets, reused.offsets, "{}", case.name);
        assert_eq!(fresh.counts, reused.counts, "{}", case.name);
        assert_eq!(fresh.indices, reused.indices, "{}", case.name);
        assert_eq!(fresh.stats, reused.stats, "{}", case.name);
    }
}

#[test]
fn zero_lights_do_no_work() {
    let t = (30f64).to_radians().tan();
    let grid = ClusterGrid::new(
        64,
        64,
        GridProjection::Perspective { tan_x: t, tan_y: t },
        0.1,
        10.0,
        &GridConfig::default(),
    );
    let a = assign(&grid, &[], 10.0, &AssignLimits::default());
    assert!(a.indices.is_empty() && a.visible.is_empty());
    assert!(a.counts.iter().all(|&n| n == 0));
}

/// Many lights on a grid with fewer cells than threads' worth of blocks: the parallel fill must
/// not hand out empty or out-of-range cell blocks (a panic seen from the viewer).
#[test]
fn parallel_fill_on_a_tiny_grid() {
    let t = (30f64).to_radians().tan();
    let grid = ClusterGrid::new(
        32,
        24,
        GridProjection::Perspective { tan_x: t, tan_y: t },
        0.1,
        10.0,
        &GridConfig::default(),
    );
    assert!(grid.total_cells < 64);
    let mut rng = Pcg64Mcg::seed_from_u64(9);
    let lights = random_lights(&mut rng, 20_000, 5.0);
    let par = assign(
        &grid,
        &lights,
        10.0,
        &AssignLimits {
            parallel_threshold: 1,
            ..Default::default()
        },
    );
    let seq = assign(
        &grid,
        &lights,
        10.0,
        &AssignLimits {
            parallel_threshold: usize::MAX,
            ..Default::default()
        },
    );
    assert_eq!(par.indices, seq.indices);
    assert_eq!(par.offsets, seq.offsets);
}

/// The parallel paths (bands of slices, one per thread of the pool, or chunks of lights) give
/// what one band gives, for pools of 2 to 8 threads, and when the bands are balanced by an
/// earlier assignment to the same grid (measured times) or to another (cells).
#[test]
fn any_number_of_bands_gives_what_one_band_gives() {
    let mut rng = Pcg64Mcg::seed_from_u64(21);
    let sequential = AssignLimits {
        parallel_threshold: usize::MAX,
        cell_cap: 24,
        ..Default::default()
    };
    let parallel = AssignLimits {
        parallel_threshold: 1,
        ..sequential
    };
    for threads in [2, 3, 5, 8] {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .expect("a thread pool");
        let mut assigner = super::assign::Assigner::new();
        for case in cases() {
            let grid = ClusterGrid::new(96, 54, case.projection, case.near, case.far, &case.config);
            // Fewer lights than cells: bands; more: chunks of lights (see `Assigner::assign`).
            // Each count twice: the second split follows the first one's measured times.
            let counts = [grid.total_cells as usize / 4, grid.total_cells as usize * 2];
            let mut listed = 0;
            for count in counts.into_iter().flat_map(|n| [n, n]) {
                let lights = random_lights(&mut rng, count, case.far.min(200.0) * 0.5);
                let one = assign(&grid, &lights, case.far, &sequential);
                let bands =
                    pool.install(|| assigner.assign(&grid, &lights, case.far, &parallel).clone());
                let what = format!("{threads} threads, {}, {count} lights", case.name);
                assert_eq!(one.visible, bands.visible, "{what}");
                assert_eq!(one.offsets, bands.offsets, "{what}");
                assert_eq!(one.counts, bands.counts, "{what}");
                assert_eq!(one.indices, bands.indices, "{what}");
                assert_eq!(one.stats, bands.stats, "{what}");
                listed += one.stats.indices;
            }
            assert!(listed > 0, "{}", case.name);
        }
    }
}

/// Chunks of lights when lights are few for the threads (49 lights on 8 threads make 7 chunks
/// of 7): after a frame with more lights, no chunk keeps that frame's runs.
#[test]
fn fewer_chunks_than_threads_keep_nothing_stale() {
    let t = (30f64).to_radians().tan();
    let grid = ClusterGrid::new(
        32,
        16,
        GridProjection::Perspective { tan_x: t, tan_y: t },
        0.1,
        10.0,
        &GridConfig::tiles(16.0),
    );
    assert!(
        grid.total_cells < 49,
        "{} cells: not the chunk path",
        grid.total_cells
    );
    let mut rng = Pcg64Mcg::seed_from_u64(5);
    let parallel = AssignLimits {
        parallel_threshold: 1,
        ..Default::default()
    };
    let sequential = AssignLimits {
        parallel_threshold: usize::MAX,
        ..Default::default()
    };
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(8)
        .build()
        .expect("a thread pool");
    let mut assigner = super::assign::Assigner::new();
    for count in [400, 49, 9, 400] {
        let lights = random_lights(&mut rng, count, 5.0);
        let one = assign(&grid, &lights, 10.0, &sequential);
        let chunks = pool.install(|| assigner.assign(&grid, &lights, 10.0, &parallel).clone());
        assert_eq!(one.visible, chunks.visible, "{count} lights");
        assert_eq!(one.counts, chunks.counts, "{count} lights");
        assert_eq!(one.indices, chunks.indices, "{count} lights");
    }
}

/// Past 65 536 visible lights the list is 32-bit, on both parallel paths and one thread,
/// with and without the overflow policy trimming it, and every cell lists exactly the lights
/// whose runs cover it, ascending; at most 65 536 it is 16-bit with the same lists.
#[test]
fn past_65536_visible_lights_the_list_is_32_bit_and_the_same() {
    let t = (30f64).to_radians().tan();
    let projection = GridProjection::test_view();
    let mut rng = Pcg64Mcg::seed_from_u64(65_537);
    // Small lights spread over the view, nearly all visible.
    let lights: Vec<GpuLight> = (0..70_000)
        .map(|_| {
            let d = rng.random_range(1.0..40.0);
            let p = DVec3::new(
                rng.random_range(-0.9..0.9) * t * 16.0 / 9.0 * d,
                rng.random_range(-0.9..0.9) * t * d,
                -d,
            );
            let light = Light::point(p, rng.random_range(0.05..0.4) as f32, Vec3::ONE, 1.0);
            GpuLight::from_light(&light, &glam::DMat4::IDENTITY)
        })
        .collect();
    // A grid with more cells than lights (bands) and one with fewer (chunks of lights).
    for footprint in [8.0, 64.0] {
        let config = GridConfig::fixed(footprint);
        let grid = ClusterGrid::new(640, 360, projection, 0.1, 50.0, &config);
        let mut reference = vec![Vec::new(); grid.total_cells as usize];
        for (i, light) in lights.iter().enumerate() {
            super::cells::for_each_run(&grid, light, 50.0, &mut |start, len| {
                for cell in start..start + len {
                    reference[cell as usize].push(i as u32);
                }
            });
        }
        for (threshold, cap) in [(1, u32::MAX), (usize::MAX, u32::MAX), (1, 3)] {
            let limits = AssignLimits {
                parallel_threshold: threshold,
                cell_cap: cap,
                max_indices: usize::MAX,
            };
            let a = assign(&grid, &lights, 50.0, &limits);
            let what = format!(
                "{footprint} px, threshold {threshold}, cap {cap}, {:?}",
                a.stats
            );
            assert!(a.visible.len() > 65_536, "{what}: {}", a.visible.len());
            assert!(
                a.indices.as_u32().is_some() && a.indices.as_u16().is_none(),
                "{what}"
            );
            for (cell, listed) in reference.iter().enumerate() {
                let got = cell_lights(&a, cell as u32);
                if cap == u32::MAX {
                    assert_eq!(&got, listed, "{what}: cell {cell}");
                } else {
                    assert_eq!(got.len(), listed.len().min(cap as usize), "{what}");
                    assert!(got.windows(2).all(|w| w[0] < w[1]), "{what}: {got:?}");
                    assert!(got.iter().all(|l| listed.contains(l)), "{what}: {got:?}");
                }
            }
        }
        // The same grid with the first 60 000 lights: 16-bit, the same lists.
        let few = &lights[..60_000];
        let limits = AssignLimits {
            cell_cap: u32::MAX,
            max_indices: usize::MAX,
            ..Default::default()
        };
        let a = assign(&grid, few, 50.0, &limits);
        assert!(
            a.indices.as_u16().is_some(),
            "{footprint} px, 60 000 lights"
        );
        for (cell, listed) in reference.iter().enumerate() {
            let expected: Vec<u32> = listed.iter().copied().filter(|&l| l < 60_000).collect();
            assert_eq!(cell_lights(&a, cell as u32), expected, "cell {cell}");
        }
    }
}

#[test]
fn split_cells_never_returns_empty_or_out_of_range_blocks() {
    for (offsets, total, parts) in [
        (vec![0u32; 12], 0usize, 4usize),
        (vec![0, 0, 0, 5], 9, 3),
        (vec![0, 100], 200, 8),
        (vec![], 0, 2),
    ] {
        let blocks = super::assign_chunks::split_cells(&offsets, total, parts);
        let mut next = 0;
        for (a, b) in &blocks {
            assert!(a < b && *b <= offsets.len(), "{blocks:?}");
            assert_eq!(*a, next);
            next = *b;
        }
        assert_eq!(next, offsets.len());
    }
}

/// Points just inside each light's reach, where a loose bound is most tempting to cut: on its
/// sphere's surface in every direction and, for spots, on the cone's edge. Every grid mode,
/// both coverages.
#[test]
fn never_misses_where_a_light_barely_reaches() {
    let mut rng = Pcg64Mcg::seed_from_u64(99);
    for case in cases() {
        for coverage in [Coverage::SliceRows, Coverage::CascadeBox] {
            let config = GridConfig {
                coverage,
                ..case.config.clone()
            };
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
            let config = GridConfig {
                coverage,
                ..case.config.clone()
            };
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
