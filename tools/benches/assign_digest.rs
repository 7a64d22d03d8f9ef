//! Development aid: a digest of the cell lists of a battery of assignments, to show that a
//! change to the assignment's code left every list as it was (`cargo bench --bench
//! assign_digest`, before and after, and compare the output). The battery: the benchmark's
//! default view and finer grids with the default scene's lights, both coverages, an
//! orthographic and a tiny-near-plane grid, hostile lights (NaN, infinite and huge values,
//! lights behind and around the eye, degenerate spot axes), one to several threads (bands and
//! chunks) and the overflow policy.
use std::hash::{Hash, Hasher};

use glam::Vec3;
use manylight::cluster::assign::{AssignLimits, Assigner};
use manylight::cluster::grid::{ClusterGrid, Coverage, GridConfig, GridProjection};
use manylight::cluster::view_light::GpuLight;
use manylight_tools::workload::AssignWorkload;
use rand::{Rng, SeedableRng};
use rand_pcg::Pcg64Mcg;

/// Now and then an extreme value, else uniform in `[-scale, scale)`.
fn value(rng: &mut Pcg64Mcg, scale: f32) -> f32 {
    match rng.random_range(0..50) {
        0 => f32::NAN,
        1 => f32::INFINITY,
        2 => f32::NEG_INFINITY,
        3 => 0.0,
        4 => 1e30,
        5 => -1e30,
        6 => 1e7,
        _ => rng.random_range(-scale..scale),
    }
}

/// Lights anywhere around the eye (`scale` m), some hostile.
fn hostile_lights(seed: u64, n: usize, scale: f32) -> Vec<GpuLight> {
    let mut rng = Pcg64Mcg::seed_from_u64(seed);
    (0..n)
        .map(|_| {
            let position = Vec3::new(
                value(&mut rng, scale),
                value(&mut rng, scale),
                value(&mut rng, scale),
            );
            let radius = match rng.random_range(0..12) {
                0 => value(&mut rng, scale).abs(),
                1 => 1e12,
                2 => rng.random_range(1e-6..1e-3),
                3..=5 => rng.random_range(0.01..scale * 0.3),
                _ => rng.random_range(0.01..scale * 0.03),
            };
            let spot = rng.random_range(0..3) == 0;
            let (spot_scale, spot_offset, direction) = if spot {
                let cos_outer = rng.random_range(-0.2..1.0);
                let scale = match rng.random_range(0..20) {
                    0 => value(&mut rng, 10.0),
                    _ => 1.0 / rng.random_range(0.01..0.5),
                };
                let direction = match rng.random_range(0..15) {
                    0 => Vec3::ZERO,
                    1 => Vec3::new(
                        value(&mut rng, 1.0),
                        value(&mut rng, 1.0),
                        value(&mut rng, 1.0),
                    ),
                    _ => Vec3::new(
                        rng.random_range(-1.0..1.0),
                        rng.random_range(-1.0..1.0),
                        rng.random_range(-1.0..1.0),
                    )
                    .normalize_or_zero(),
                };
                (scale, (1.0 - cos_outer) * scale, direction)
            } else {
                (0.0, 1.0, Vec3::ZERO)
            };
            GpuLight {
                position,
                radius,
                cull_radius: radius,
                radiance: Vec3::new(rng.random_range(0.0..5.0), rng.random_range(0.0..5.0), 1.0),
                spot_scale,
                direction,
                spot_offset,
                cone_deg: (60.0, 30.0),
            }
        })
        .collect()
}

/// The digest of one assignment's lists and its index count.
fn digest(
    grid: &ClusterGrid,
    lights: &[GpuLight],
    far: f64,
    limits: &AssignLimits,
) -> (u64, usize) {
    let mut assigner = Assigner::new();
    // Twice: the second reuses the buffers (and may take the pool after a slow first).
    assigner.assign(grid, lights, far, limits);
    let a = assigner.assign(grid, lights, far, limits);
    let mut h = std::collections::hash_map::DefaultHasher::new();
    a.visible.hash(&mut h);
    a.offsets.hash(&mut h);
    a.counts.hash(&mut h);
    for i in 0..a.indices.len() {
        a.indices.get(i).hash(&mut h);
    }
    a.stats.overflowed_lights.hash(&mut h);
    (h.finish(), a.indices.len())
}

fn main() {
    let limit_sets = [
        (
            "one thread",
            AssignLimits {
                cell_cap: u32::MAX,
                parallel_threshold: usize::MAX,
                ..AssignLimits::default()
            },
        ),
        (
            "all threads",
            AssignLimits {
                cell_cap: u32::MAX,
                parallel_threshold: 0,
                ..AssignLimits::default()
            },
        ),
        (
            "cap 6",
            AssignLimits {
                cell_cap: 6,
                ..AssignLimits::default()
            },
        ),
    ];
    let bench = |count, seed| AssignWorkload::default_view(count, seed);
    let fine = |count, seed| AssignWorkload::fine_grid(count, seed);
    let at16 = |count, seed| {
        AssignWorkload::view_with(count, seed, (1280, 720), |_, _| GridConfig::fixed(16.0))
    };
    let mut workloads: Vec<(String, AssignWorkload)> = Vec::new();
    for (count, seed) in [(256, 1), (1024, 1), (1024, 2), (16384, 3)] {
        workloads.push((
            format!("bench grid, {count} lights seed {seed}"),
            bench(count, seed),
        ));
    }
    workloads.push(("fine grid, 1024 lights".into(), fine(1024, 1)));
    workloads.push(("16 px 1280x720, 1024 lights".into(), at16(1024, 1)));
    let mut boxed = at16(1024, 1);
    boxed.grid.coverage = Coverage::CascadeBox;
    workloads.push(("16 px 1280x720 cascade box, 1024 lights".into(), boxed));
    let ortho = ClusterGrid::new(
        320,
        180,
        GridProjection::Orthographic {
            half_x: 16.0,
            half_y: 9.0,
        },
        0.1,
        60.0,
        &GridConfig::fixed(12.0),
    );
    let near = ClusterGrid::new(
        320,
        180,
        GridProjection::Perspective {
            tan_x: 1.0264,
            tan_y: 0.5774,
        },
        1e-4,
        f64::INFINITY,
        &GridConfig::fixed(14.0),
    );
    for (name, grid, far, scale) in [
        ("orthographic", ortho, 60.0, 20.0),
        ("near 1e-4, far infinite", near, f64::INFINITY, 30.0),
        ("bench grid", bench(1, 1).grid, bench(1, 1).far, 40.0),
        ("fine grid", fine(1, 1).grid, fine(1, 1).far, 20.0),
    ] {
        for (seed, n) in [(1u64, 500usize), (2, 3000)] {
            workloads.push((
                format!("{name}, {n} hostile lights seed {seed}"),
                AssignWorkload {
                    grid: grid.clone(),
                    lights: hostile_lights(seed, n, scale),
                    far,
                },
            ));
        }
    }
    let mut all = std::collections::hash_map::DefaultHasher::new();
    for (name, w) in &workloads {
        for (limits_name, limits) in &limit_sets {
            let (d, indices) = digest(&w.grid, &w.lights, w.far, limits);
            println!("{d:016x} {indices:>9} indices  {name}, {limits_name}");
            d.hash(&mut all);
        }
    }
    println!("{:016x} all", all.finish());
}
