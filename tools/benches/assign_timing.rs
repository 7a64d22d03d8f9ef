//! Quick assignment timings for development: `cargo bench --bench assign_timing`.
use manylight_tools::workload::AssignWorkload;

fn main() {
    for count in [1usize, 64, 1024, 16_384, 65_536, 1_048_576] {
        let w = AssignWorkload::default_view(count, 1);
        let (ms, indices) = w.time(if count > 100_000 { 5 } else { 50 });
        println!("{count:>8} lights: {ms:8.3} ms, {indices} indices");
    }
    for count in [64usize, 1024, 65_536] {
        let mut w = AssignWorkload::default_view(count, 1);
        w.grid.coverage = manylight::cluster::grid::Coverage::CascadeBox;
        let (ms, indices) = w.time(50);
        println!("{count:>8} lights, cascade box: {ms:8.3} ms, {indices} indices");
    }
    for count in [1024usize, 4096] {
        let w = AssignWorkload::fine_grid(count, 1);
        let (ms, indices) = w.time(50);
        println!(
            "{count:>8} lights, fine grid ({} cells): {ms:8.3} ms, {indices} indices",
            w.grid.total_cells
        );
    }
}
