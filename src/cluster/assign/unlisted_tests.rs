//! Lists too long to build are refused (`Assignment::unlisted`) on every path, not allocated:
//! a fine fixed grid under many overlapping lights asked for 4 bytes a cell per light, gigabytes
//! (an allocation failure, an abort), and past 2³² entries misnumbered offsets and a panic.

use glam::{DMat4, DVec3, Vec3};

use super::{AssignLimits, Assigner, MAX_UNTRIMMED_INDICES};
use crate::cluster::grid::{ClusterGrid, GridConfig, GridProjection};
use crate::cluster::view_light::GpuLight;
use crate::scene::Light;

/// `n` lights each covering every cell of a grid in front of the eye out to depth 80.
fn covering(n: usize) -> Vec<GpuLight> {
    let light = Light::point(DVec3::new(0.0, 0.0, -40.0), 1000.0, Vec3::ONE, 1.0);
    vec![GpuLight::from_light(&light, &DMat4::IDENTITY); n]
}

fn grid(footprint_px: f64) -> ClusterGrid {
    let config = GridConfig {
        footprint_px,
        ..GridConfig::default()
    };
    ClusterGrid::new(320, 180, GridProjection::test_view(), 0.1, 80.0, &config)
}

/// Assigns on a pool of `threads`, with the pool taken from the first light when `threads` >
/// 1; whether the lists were refused, and the same assigner's next, small assignment.
fn refused_then_listed(grid: &ClusterGrid, lights: usize, threads: usize) {
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .unwrap();
    let limits = AssignLimits {
        parallel_threshold: if threads > 1 { 1 } else { usize::MAX },
        ..AssignLimits::default()
    };
    let cells = grid.total_cells as usize;
    let what = format!("{cells} cells, {lights} lights, {threads} threads");
    // In u64: the product passes a 32-bit usize.
    assert!(
        cells as u64 * lights as u64 > MAX_UNTRIMMED_INDICES as u64,
        "{what}: too small a case"
    );
    pool.install(|| {
        let mut assigner = Assigner::new();
        let a = assigner.assign(grid, &covering(lights), 80.0, &limits);
        let listed = a
            .unlisted
            .unwrap_or_else(|| panic!("{what}: listed {:?}", a.stats));
        assert!(listed > MAX_UNTRIMMED_INDICES, "{what}: {listed}");
        assert_eq!(a.stats.threads, threads, "{what}");
        assert!(a.indices.is_empty(), "{what}");
        assert_eq!((a.counts.len(), a.offsets.len()), (cells, cells), "{what}");
        assert!(a.counts.iter().all(|&n| n == 0), "{what}");
        assert_eq!(a.stats.overflowed_lights, a.visible.len() as u64, "{what}");
        // The next frame, within bounds, is listed whole.
        let a = assigner.assign(grid, &covering(3), 80.0, &limits);
        assert_eq!(a.unlisted, None, "{what}");
        assert!(a.counts.iter().all(|&n| n == 3), "{what}");
        assert_eq!(a.indices.len(), 3 * cells, "{what}");
    });
}

#[test]
fn lists_past_the_bound_are_refused_on_every_path() {
    let fine = grid(2.0);
    // One band (one thread) and bands shared by two threads: more cells than lights.
    assert!(fine.total_cells as usize > 2_000);
    refused_then_listed(&fine, 2_000, 1);
    refused_then_listed(&fine, 2_000, 2);
    // Chunks of lights (two threads, fewer cells than lights).
    let coarse = grid(64.0);
    let lights = MAX_UNTRIMMED_INDICES / coarse.total_cells as usize + 1;
    assert!(lights > coarse.total_cells as usize);
    refused_then_listed(&coarse, lights, 2);
}
