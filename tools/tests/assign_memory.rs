//! The assignment asks the allocator before a frame's lights grow its buffers: where it refuses
//! (an address-space limit, a 32-bit process), nothing is listed and the assignment says so
//! (`Assignment::unallocated`, which the renderer turns into an error naming the size), where
//! a buffer grown without asking would abort the process.
//!
//! This program's allocator refuses every allocation past a size the test sets
//! (`common/refusing_allocator.rs`): a buffer that grows without asking aborts the program, so
//! the test fails.

use manylight::cluster::assign::{AssignLimits, Assigner, Assignment};
use manylight::cluster::grid::GridConfig;
use manylight_tools::workload::AssignWorkload;

#[path = "common/refusing_allocator.rs"]
mod refusing_allocator;
use refusing_allocator::{refusing_past, serial, Refusing};

#[global_allocator]
static ALLOCATOR: Refusing = Refusing;

/// Every light listed, on up to `threads` threads, parallel from the first light.
fn limits(threads: usize) -> AssignLimits {
    AssignLimits {
        cell_cap: u32::MAX,
        parallel_threshold: 0,
        max_threads: threads,
        ..AssignLimits::default()
    }
}

/// `workload` assigned by a fresh assigner (no buffers grown by an earlier frame) on a pool of
/// `threads`, no allocation past `largest` bytes granted meanwhile.
fn assigned(workload: &AssignWorkload, threads: usize, largest: usize) -> Assignment {
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .unwrap();
    pool.install(|| {
        let mut assigner = Assigner::new();
        let limits = limits(threads);
        refusing_past(largest, || {
            assigner.assign(&workload.grid, &workload.lights, workload.far, &limits)
        });
        assigner.into_assignment()
    })
}

/// A few lights wide on the screen over a grid of 4-pixel cells and 4 slices: long runs, so
/// the list takes far more bytes than the runs and the per-cell arrays.
fn long_runs() -> AssignWorkload {
    AssignWorkload::view_with(1024, 1, (1280, 720), |_, _| GridConfig {
        max_slices: 4,
        cascades: 1,
        ..GridConfig::fixed(4.0)
    })
}

/// Refused where its runs or its list outgrow what the allocator gives, on one thread (one
/// band), on bands of slices and on chunks of lights: nothing listed, every cell empty, every
/// visible light counted as dropped, and the size said. Given the memory, a fresh assigner
/// lists as before.
#[test]
fn lists_the_allocator_refuses_are_not_built_and_say_so() {
    let _serial = serial();
    // Bands of slices where the cells outnumber the lights, chunks of lights where not.
    let cases = [
        ("one band", AssignWorkload::fine_grid(4096, 1), 1),
        ("bands", AssignWorkload::fine_grid(4096, 1), 2),
        ("chunks", AssignWorkload::default_view(200_000, 1), 2),
        ("one band, long runs", long_runs(), 1),
        ("bands, long runs", long_runs(), 2),
    ];
    let mut lists_refused = 0;
    for (what, workload, threads) in cases {
        let whole = assigned(&workload, threads, usize::MAX);
        assert!(
            whole.unallocated.is_none() && whole.unlisted.is_none(),
            "{what}"
        );
        let (runs, indices) = (whole.stats.runs, whole.indices.len());
        let cells = workload.grid.total_cells as usize;
        assert!(runs > 10_000, "{what}: {runs} runs");
        // A quarter of the runs' bytes (8 a run) refuses their growth. Where the list (2 bytes
        // an entry while the visible lights fit 16 bits) is larger than the runs grow to
        // (twice them) and the per-cell arrays (half again their 4 bytes a cell, twice),
        // only the list is refused.
        let mut caps = vec![("runs", runs * 8 / 4)];
        let all_but_the_list = (runs * 8 * 2).max(cells * 12);
        if indices * 2 > all_but_the_list {
            caps.push(("list", all_but_the_list));
            lists_refused += 1;
        }
        for (refused, largest) in caps {
            let a = assigned(&workload, threads, largest);
            let bytes = a
                .unallocated
                .unwrap_or_else(|| panic!("{what}, {refused}: listed"));
            assert!(
                bytes as usize > largest,
                "{what}, {refused}: {bytes} bytes refused"
            );
            assert!(a.unlisted.is_some(), "{what}, {refused}");
            assert_eq!(a.indices.len(), 0, "{what}, {refused}");
            // Empty cells, or none where even they could not be allocated.
            assert!(a.counts.iter().all(|&n| n == 0), "{what}, {refused}");
            assert!([0, cells].contains(&a.counts.len()), "{what}, {refused}");
            assert_eq!(
                a.stats.overflowed_lights,
                a.visible.len() as u64,
                "{what}, {refused}"
            );
        }
        let again = assigned(&workload, threads, usize::MAX);
        assert_eq!(again.indices, whole.indices, "{what}");
        assert_eq!(again.counts, whole.counts, "{what}");
    }
    assert_eq!(lists_refused, 2, "the long runs' lists were refused alone");
}

/// The texels a frame uploads are packed into buffers that ask the allocator: refused, the
/// size comes back (the renderer's error), where growing them aborted.
#[test]
fn texels_the_allocator_refuses_are_said() {
    use manylight::cluster::pack::{pack_grid_into, pack_indices_into, GridEncoding, PackedTexels};
    let _serial = serial();
    let workload = long_runs();
    let a = assigned(&workload, 1, usize::MAX);
    let encoding = GridEncoding::Rgba8;
    let (mut grid, mut indices) = (PackedTexels::empty(), PackedTexels::empty());
    // Half the list's bytes: the grid's texels (4 bytes a cell) fit, the list's do not.
    let largest = a.indices.len();
    assert!(workload.grid.total_cells as usize * 4 * 2 < largest);
    let (packed_grid, packed_list) = refusing_past(largest, || {
        (
            pack_grid_into(&workload.grid, &a, encoding, &mut grid),
            pack_indices_into(&a.indices, encoding, &mut indices),
        )
    });
    assert_eq!(packed_grid, Ok(()));
    let bytes = packed_list.expect_err("the list's texels were allocated");
    assert!(bytes as usize > largest, "{bytes}");
    assert_eq!(
        pack_indices_into(&a.indices, encoding, &mut indices),
        Ok(())
    );
    assert!(indices.bytes.len() >= 2 * a.indices.len());
}
